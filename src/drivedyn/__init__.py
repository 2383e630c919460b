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
    Hinge,
    JointDriver,
    Prismatic,
    Screw,
    SpeedDifferenceDriver,
    Spherical,
    SpringDamper,
    Torque,
    TorsionalSpringDamper,
    Universal,
)
from drivedyn.model import GROUND, Model, ModelError, Spec, State, compile_model
from drivedyn.results import Results, load_results
from drivedyn.solver import (
    AdaptiveStep,
    FixedStep,
    GeneralizedAlpha,
    Newton,
    element_outputs,
    simulate,
    solve_static,
)
from drivedyn.timefunctions import Constant, Ramp, SmoothStep, Table

__version__ = "0.1.0"

__all__ = [
    "GROUND",
    "AdaptiveStep",
    "Constant",
    "Cylindrical",
    "Fixed",
    "FixedStep",
    "Force",
    "GeneralizedAlpha",
    "Hinge",
    "JointDriver",
    "Model",
    "ModelError",
    "ModelFileError",
    "Newton",
    "Prismatic",
    "Ramp",
    "Results",
    "Screw",
    "SmoothStep",
    "Spec",
    "SpeedDifferenceDriver",
    "Spherical",
    "SpringDamper",
    "State",
    "Table",
    "Torque",
    "TorsionalSpringDamper",
    "Universal",
    "compile_model",
    "element_outputs",
    "load_model",
    "load_results",
    "simulate",
    "solve_static",
]
