"""Geometrically exact beams on SE(3): sections and materials, the element, its kernel.

* :mod:`~drivedyn.elements.beams.se3`: exponential, logarithm and tangent operators of SE(3);
* :mod:`~drivedyn.elements.beams.section`: materials, cross-sections, outer-fibre stresses;
* :mod:`~drivedyn.elements.beams.kernel`: the compiled element loop;
* :mod:`~drivedyn.elements.beams.family`: :class:`GeometricallyExactBeam` and its family.
"""

from drivedyn.elements.beams.family import GeometricallyExactBeam
from drivedyn.elements.beams.section import (
    STEEL,
    GeneralSection,
    HollowCircular,
    HollowRectangular,
    Material,
    Rectangular,
    SolidCircular,
)

__all__ = ["STEEL", "GeneralSection", "GeometricallyExactBeam", "HollowCircular",
           "HollowRectangular", "Material", "Rectangular", "SolidCircular"]
