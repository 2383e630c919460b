"""A flexible ladder frame for the vehicle models: side rails and cross members of
geometrically exact beams with declared sections (:mod:`.schema`, the ``[chassis]`` table),
built into a spec with the body it carries lumped on the rails (:mod:`.frame`,
:mod:`.body`); the markers other parts mount on (:meth:`Frame.mount`); the static torsion
test and the closed form of a rectangular frame (:mod:`.torsion`)."""

from drivedyn.library.vehicles.chassis.body import (
    Carrier,
    MassProperties,
    carriers,
    mass_matrix,
    mass_properties,
)
from drivedyn.library.vehicles.chassis.frame import Frame, add_ladder_frame, rail_stations
from drivedyn.library.vehicles.chassis.schema import (
    BoxSection,
    CarriedBody,
    CrossMember,
    DeclaredSection,
    FrameMaterial,
    LadderFrameFile,
    Mesh,
    Rails,
    StiffnessSection,
)
from drivedyn.library.vehicles.chassis.torsion import (
    TorsionTest,
    rectangle_frame,
    rectangle_frame_stiffness,
    refined,
    torsion_test,
    torsional_stiffness,
)

__all__ = [
    "BoxSection",
    "CarriedBody",
    "Carrier",
    "CrossMember",
    "DeclaredSection",
    "Frame",
    "FrameMaterial",
    "LadderFrameFile",
    "MassProperties",
    "Mesh",
    "Rails",
    "StiffnessSection",
    "TorsionTest",
    "add_ladder_frame",
    "carriers",
    "mass_matrix",
    "mass_properties",
    "rail_stations",
    "rectangle_frame",
    "rectangle_frame_stiffness",
    "refined",
    "torsion_test",
    "torsional_stiffness",
]
