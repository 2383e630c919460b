"""Small, swappable solver parts: integrator coefficients, Newton settings, step controllers,
and the outcome of a step as a value (failures are values; only the top level raises)."""

from __future__ import annotations

import enum
from dataclasses import dataclass


@dataclass(frozen=True)
class GeneralizedAlpha:
    """Chung-Hulbert generalized-alpha on the Lie group (Bruls, Cardona, Arnold 2012).

    Attributes:
        rho_inf: spectral radius at infinite frequency in [0, 1]; 1 = no numerical
            dissipation, 0 = asymptotic annihilation of the highest frequencies.

    With joints (index-3 constraints) ``rho_inf = 1`` -- the trapezoidal rule -- is only
    weakly stable: the multipliers carry a (-1)^n oscillation that can grow over long runs
    with large reactions (a heavy top diverges within a second; Cardona & Geradin 1989).
    Use ``rho_inf <= 0.95`` for constrained systems; 1 is for energy-conservation studies.
    """

    rho_inf: float = 0.8

    def __post_init__(self) -> None:
        if not (0.0 <= self.rho_inf <= 1.0):
            raise ValueError(f"GeneralizedAlpha.rho_inf must be in [0, 1], got {self.rho_inf}")

    @property
    def coefficients(self) -> tuple[float, float, float, float]:
        """(alpha_m, alpha_f, gamma, beta) from rho_inf."""
        r = self.rho_inf
        am = (2.0 * r - 1.0) / (r + 1.0)
        af = r / (r + 1.0)
        g = 0.5 + af - am
        b = 0.25 * (g + 0.5) ** 2
        return am, af, g, b


@dataclass(frozen=True)
class Newton:
    """Newton-Raphson settings.

    Attributes:
        strategy: ``"modified"`` reuses the factorisation while the contraction rate of the
            corrections stays below ``contraction``; ``"full"`` refactors every iteration.
        tol: residual tolerance, relative to the sum of absolute element contributions of
            each equation (dimensionless).
        phi_tol: constraint violation tolerance [m or rad].
        max_iter: iterations before the step is declared failed.
        contraction: largest accepted ratio |delta_k| / |delta_k-1| before refactoring
            (0.5: an iteration costs about an eighth of a factorisation, see
            :data:`drivedyn.solver.newton_kernel.H_REUSE`).
    """

    strategy: str = "modified"
    tol: float = 1e-8
    phi_tol: float = 1e-10
    max_iter: int = 12
    contraction: float = 0.5

    def __post_init__(self) -> None:
        if self.strategy not in ("modified", "full"):
            raise ValueError(f"Newton.strategy must be 'modified' or 'full', got {self.strategy!r}")


@dataclass(frozen=True)
class FixedStep:
    """Constant step ``h`` [s]; a failed step is retried with halved sub-steps down to
    ``h_min``."""

    h: float = 1e-3
    h_min: float | None = None

    def __post_init__(self) -> None:
        if not self.h > 0:
            raise ValueError(f"FixedStep.h must be > 0, got {self.h}")


@dataclass(frozen=True)
class AdaptiveStep:
    """Step size from a local error estimate and Newton convergence.

    The local error of the positions is estimated as ``|beta - 1/6| h^2 |a_n+1 - a_n-1|``,
    the change of the pseudo-accelerations over the last two steps (their numerical mode
    that alternates in sign from step to step cancels;
    :func:`~drivedyn.solver.step_control.step_error`), and weighted by
    ``atol + rtol |h dq|`` (the step's own increment), so rtol is the relative accuracy of
    the motion within a step and atol an absolute accuracy per step. After a Newton
    failure at ``h`` the step is retried at ``h / 4`` and then stays below ``h / 2``, a cap
    that grows by 5 % per accepted step
    (:data:`drivedyn.solver.step_control.LIMIT_AFTER_FAILURE`, ``LIMIT_RELAX``). The step
    grows from the envelope of the recent estimates (a vibration's estimate rises and falls
    with its phase), by the h^3 law of the estimate or by the steeper one a rejection
    measured (:data:`~drivedyn.solver.step_control.ENVELOPE_DECAY`, ``ERROR_EXPONENT_MAX``).

    Attributes:
        h0: first step [s].
        h_min, h_max: bounds [s].
        rtol, atol: relative tolerance and absolute tolerance [m or rad].
        max_rejections: consecutive rejections before the run stops.
        atol_rot: absolute tolerance of the nodes' rotation coordinates [rad]; None: ``atol``.
            One ``atol`` for both treats 1 um and 1 urad alike, 10 nm of arc on a 10 mm
            planet gear: a rotation tolerance of ``atol`` divided by the parts' radius
            weighs the two alike (the TORSEN files: 1e-5 rad for 1e-6 m).
    """

    h0: float = 1e-4
    h_min: float = 1e-10
    h_max: float = 1e-2
    rtol: float = 1e-3
    atol: float = 1e-7
    max_rejections: int = 30
    atol_rot: float | None = None

    def __post_init__(self) -> None:
        if self.atol_rot is not None and not self.atol_rot > 0:
            raise ValueError(f"AdaptiveStep needs atol_rot > 0 (or None), got {self.atol_rot}")
        if not (0 < self.h_min <= self.h0 <= self.h_max):
            raise ValueError("AdaptiveStep needs 0 < h_min <= h0 <= h_max, got "
                             f"{self.h_min}, {self.h0}, {self.h_max}")


class StepStatus(enum.Enum):
    """Outcome of one attempted step."""

    SUCCESS = "success"
    NEWTON_MAX_ITER = "Newton did not converge within the iteration limit"
    NEWTON_DIVERGED = "Newton diverged"
    NONFINITE = "non-finite values in the solution"
    SINGULAR = "singular iteration matrix"
    ERROR_TOO_LARGE = "local error estimate above tolerance"


@dataclass
class StepOutcome:
    """A step's result as a value: status, Newton statistics and, on failure, the worst
    equation (index into ``Model.eq_labels``) with its scaled residual.

    ``error`` is the weighted local error estimate of an adaptive step (1: the tolerance;
    0 for fixed steps) and ``worst_eq`` the dof where it is largest, for an accepted step
    and for one rejected for its error (``residual`` then holds the estimate too); for a
    step Newton did not converge, ``worst_eq`` is the equation with the largest scaled
    residual."""

    status: StepStatus
    iterations: int = 0
    factorizations: int = 0
    error: float = 0.0
    worst_eq: int = -1
    residual: float = 0.0
    message: str = ""

    @property
    def ok(self) -> bool:
        return self.status is StepStatus.SUCCESS
