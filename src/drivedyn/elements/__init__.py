"""Element families. Importing this package registers every family in ``REGISTRY``."""

from drivedyn.elements import (  # noqa: F401
    bodies,
    controllers,
    drivers,
    engine,
    joints,
    loads,
    nonlinear_springs,
    springs,
)
from drivedyn.elements.beams import GeometricallyExactBeam
from drivedyn.elements.bushing import (
    Bushing,
    BushingCurve,
    BushingRotationalCurve,
    MaxwellBranch,
    RotationalMaxwellBranch,
)
from drivedyn.elements.contact import (
    FrictionLaw,
    JournalContact,
    JournalFilm,
    NormalLaw,
    PlaneContact,
    SqueezeFilm,
    ThrustWasherContact,
    UnilateralContact,
)
from drivedyn.elements.controllers import SpeedController
from drivedyn.elements.drivers import JointDriver, SpeedDifferenceDriver, TravelDriver
from drivedyn.elements.engine import EngineTorque
from drivedyn.elements.flexible import FlexibleBody
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.registry import REGISTRY, ElementSpec, Family, register
from drivedyn.elements.gears import GearPair
from drivedyn.elements.joints import (
    Cylindrical,
    Fixed,
    Hinge,
    ParallelAxes,
    Planar,
    Prismatic,
    Screw,
    Spherical,
    Universal,
)
from drivedyn.elements.loads import Force, Torque
from drivedyn.elements.nonlinear_springs import BumpStop, NonlinearSpringDamper
from drivedyn.elements.springs import SpringDamper, TorsionalSpringDamper
from drivedyn.elements.tyre import RoadPatch, TyreContact

__all__ = [
    "REGISTRY",
    "BumpStop",
    "Bushing",
    "BushingCurve",
    "BushingRotationalCurve",
    "Cylindrical",
    "ElementSpec",
    "EngineTorque",
    "Family",
    "Fixed",
    "FlexibleBody",
    "Force",
    "FrictionLaw",
    "GearPair",
    "GeometricallyExactBeam",
    "Group",
    "Hinge",
    "JointDriver",
    "JournalContact",
    "JournalFilm",
    "MaxwellBranch",
    "NonlinearSpringDamper",
    "NormalLaw",
    "ParallelAxes",
    "Planar",
    "PlaneContact",
    "Prismatic",
    "RoadPatch",
    "RotationalMaxwellBranch",
    "Screw",
    "SpeedController",
    "SpeedDifferenceDriver",
    "Spherical",
    "SpringDamper",
    "SqueezeFilm",
    "ThrustWasherContact",
    "Torque",
    "TorsionalSpringDamper",
    "TravelDriver",
    "TyreContact",
    "UnilateralContact",
    "Universal",
    "register",
]
