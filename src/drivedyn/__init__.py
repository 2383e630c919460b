"""drivedyn: flexible multibody simulation of automotive drivelines.

Build a :class:`Spec`, ``compile_model`` it, ``simulate`` it::

    import drivedyn as dd
    spec = dd.Spec(gravity=(0, 0, -9.81))
    ...
    results = dd.simulate(dd.compile_model(spec), t_end=1.0)
"""

from drivedyn.config import ModelFileError, load_model
from drivedyn.elements import (
    Cylindrical,
    Fixed,
    Force,
    FrictionLaw,
    GearPair,
    Hinge,
    JointDriver,
    JournalContact,
    NormalLaw,
    ParallelAxes,
    Planar,
    PlaneContact,
    Prismatic,
    Screw,
    SpeedDifferenceDriver,
    Spherical,
    SpringDamper,
    SqueezeFilm,
    ThrustWasherContact,
    Torque,
    TorsionalSpringDamper,
    UnilateralContact,
    Universal,
)
from drivedyn.elements.beams import (
    STEEL,
    GeneralSection,
    GeometricallyExactBeam,
    HollowCircular,
    Material,
    Rectangular,
    SolidCircular,
)
from drivedyn.elements.flexible import FlexibleBody, FlexibleInterface, FlexibleWasherContact
from drivedyn.model import GROUND, Model, ModelError, Spec, State, compile_model
from drivedyn.model.beams import add_straight_beam
from drivedyn.model.flexible import add_flexible_body
from drivedyn.results import Results, load_results
from drivedyn.solver import (
    AdaptiveStep,
    FixedStep,
    GeneralizedAlpha,
    Newton,
    element_outputs,
    linear_modes,
    simulate,
    solve_static,
)
from drivedyn.timefunctions import Constant, Ramp, SmoothStep, Table

__version__ = "0.1.0"

__all__ = [
    "GROUND",
    "STEEL",
    "AdaptiveStep",
    "Constant",
    "Cylindrical",
    "Fixed",
    "FixedStep",
    "FlexibleBody",
    "FlexibleInterface",
    "FlexibleWasherContact",
    "Force",
    "FrictionLaw",
    "GearPair",
    "GeneralSection",
    "GeneralizedAlpha",
    "GeometricallyExactBeam",
    "Hinge",
    "HollowCircular",
    "JointDriver",
    "JournalContact",
    "Material",
    "Model",
    "ModelError",
    "ModelFileError",
    "Newton",
    "NormalLaw",
    "ParallelAxes",
    "Planar",
    "PlaneContact",
    "Prismatic",
    "Ramp",
    "Rectangular",
    "Results",
    "Screw",
    "SmoothStep",
    "SolidCircular",
    "Spec",
    "SpeedDifferenceDriver",
    "Spherical",
    "SpringDamper",
    "SqueezeFilm",
    "State",
    "Table",
    "ThrustWasherContact",
    "Torque",
    "TorsionalSpringDamper",
    "UnilateralContact",
    "Universal",
    "add_flexible_body",
    "add_straight_beam",
    "compile_model",
    "element_outputs",
    "linear_modes",
    "load_model",
    "load_results",
    "simulate",
    "solve_static",
]
