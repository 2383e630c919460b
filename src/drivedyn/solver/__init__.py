"""Time integration, Newton iterations, linear solvers, step control and statics."""

from drivedyn.solver.assembly import System, element_outputs
from drivedyn.solver.linear import DenseLU, LinearSolver, SparseLU
from drivedyn.solver.settings import (
    AdaptiveStep,
    FixedStep,
    GeneralizedAlpha,
    Newton,
    StepOutcome,
    StepStatus,
)
from drivedyn.solver.simulate import InitializationError, consistent_initial_state, simulate
from drivedyn.solver.statics import StaticsError, solve_static

__all__ = [
    "AdaptiveStep",
    "DenseLU",
    "FixedStep",
    "GeneralizedAlpha",
    "InitializationError",
    "LinearSolver",
    "Newton",
    "SparseLU",
    "StaticsError",
    "StepOutcome",
    "StepStatus",
    "System",
    "consistent_initial_state",
    "element_outputs",
    "simulate",
    "solve_static",
]
