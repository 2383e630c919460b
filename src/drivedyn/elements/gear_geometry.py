"""Old home of the involute geometry and the ISO 6336 mesh stiffness, kept until the last
importers move: import them from :mod:`drivedyn.elements.gears` (re-exported there from
:mod:`~drivedyn.elements.gears.geometry` and :mod:`~drivedyn.elements.gears.stiffness`)."""

from drivedyn.elements.gears.geometry import (
    CylindricalPair,
    base_helix_angle,
    effective_sliding_arm,
    inverse_involute,
    involute,
    transverse_pressure_angle,
)
from drivedyn.elements.gears.stiffness import (
    E_STEEL,
    ISO_C,
    IsoStiffness,
    iso6336_mesh_stiffness,
    iso6336_single_stiffness,
    mesh_cycle_levels,
)

__all__ = [
    "E_STEEL",
    "ISO_C",
    "CylindricalPair",
    "IsoStiffness",
    "base_helix_angle",
    "effective_sliding_arm",
    "inverse_involute",
    "involute",
    "iso6336_mesh_stiffness",
    "iso6336_single_stiffness",
    "mesh_cycle_levels",
    "transverse_pressure_angle",
]
