"""Time integration, Newton iterations, linear solvers, step control and statics."""

from drivedyn.solver.linear import DenseLU, LinearSolver, SparseLU
from drivedyn.solver.modal import Modes, linear_modes
from drivedyn.solver.settings import (
    AdaptiveStep,
    FixedStep,
    GeneralizedAlpha,
    Newton,
    StepOutcome,
    StepStatus,
)
from drivedyn.solver.simulate import InitializationError, consistent_initial_state, simulate
from drivedyn.solver.simulation import Simulation
from drivedyn.solver.statics import StaticsError, solve_static
from drivedyn.solver.system import System, element_outputs, redundant_constraints

__all__ = [
    "AdaptiveStep",
    "DenseLU",
    "FixedStep",
    "GeneralizedAlpha",
    "InitializationError",
    "LinearSolver",
    "Modes",
    "Newton",
    "Simulation",
    "SparseLU",
    "StaticsError",
    "StepOutcome",
    "StepStatus",
    "System",
    "consistent_initial_state",
    "element_outputs",
    "linear_modes",
    "redundant_constraints",
    "simulate",
    "solve_static",
]
