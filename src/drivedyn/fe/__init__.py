"""Meshed solid parts: meshes, linear finite elements, Craig-Bampton reduction.

No multibody knowledge here: :mod:`drivedyn.elements.flexible` turns a
:class:`~drivedyn.fe.reduction.ReducedPart` into a floating-frame body of a model.
"""

from drivedyn.fe.mesh import SolidMesh, annular_washer, box, read_mesh, tube, write_mesh
from drivedyn.fe.quadrature import annulus_quadrature
from drivedyn.fe.reduction import (
    Interface,
    ReducedPart,
    craig_bampton,
    face_load_patterns,
    frequency_check,
)
from drivedyn.fe.solid import SolidMaterial, SolidModel, principal_stresses, von_mises

__all__ = ["Interface", "ReducedPart", "SolidMaterial", "SolidMesh", "SolidModel",
           "annular_washer", "annulus_quadrature", "box", "craig_bampton", "face_load_patterns",
           "frequency_check", "principal_stresses", "read_mesh", "tube", "von_mises", "write_mesh"]
