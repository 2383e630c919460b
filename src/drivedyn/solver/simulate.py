"""``simulate``: time integration from a consistent initial state to ``t_end``.

Only this top level decides to stop: a step that fails is retried smaller; when the step
would fall below ``h_min`` (or too many consecutive rejections happen) the run stops, and the
results up to that time are returned with ``success = False`` and a message naming the time,
the worst equation (element and dof) and its residual.
"""

from __future__ import annotations

import logging
import time as _time
from collections.abc import Callable, Sequence

import numpy as np

from drivedyn.elements.base import MODE_ACC, MODE_DYN, MODE_VEL
from drivedyn.model.model import Model, State
from drivedyn.results.recorder import EnergyAccount, Recorder
from drivedyn.results.results import Results, RunStats
from drivedyn.solver.assembly import System
from drivedyn.solver.linear import LinearSolver, default_linear_solver
from drivedyn.solver.settings import (
    AdaptiveStep,
    FixedStep,
    GeneralizedAlpha,
    Newton,
    StepOutcome,
    StepStatus,
)
from drivedyn.solver.stepper import FLOOR_REL, Stepper, residual_norms

log = logging.getLogger("drivedyn")

# After a Newton failure at h the adaptive step stays below LIMIT_AFTER_FAILURE h, a cap that
# grows by LIMIT_RELAX per accepted step: the error estimate alone would double h back to the
# size that just failed (contact or flank changes) and fail again.
LIMIT_AFTER_FAILURE = 0.5
LIMIT_RELAX = 1.05


class InitializationError(RuntimeError):
    """The initial state cannot be made consistent (singular constraint Jacobian or mass)."""


def consistent_initial_state(model: Model, st: State, sys: System | None = None,
                             linear_solver: LinearSolver | None = None,
                             project_velocities: bool = True) -> State:
    """Make velocities satisfy the velocity constraints (M-orthogonal projection) and compute
    accelerations and multipliers from the equations of motion and the acceleration-level
    constraints ``Phi_q vd + v^T H v + Phi_tt = 0``. Modifies and returns ``st``."""
    sys = sys or System(model)
    lin = linear_solver or default_linear_solver(model.neq)
    nd = model.nd
    sys.reset_tangent()
    try:
        if project_velocities and model.nm:
            sys.evaluate(st, 1.0, 0.0, 0.0, MODE_VEL, True)
            rhs = np.zeros(model.neq)
            rhs[nd:] = -sys.r[nd:]
            sys.factor(lin)
            dv = lin.solve(rhs)
            st.v += dv[:nd]
        st.vd[:] = 0.0
        st.lam[:] = 0.0
        sys.evaluate(st, 1.0, 0.0, 0.0, MODE_ACC, True)
        sys.factor(lin)
        sol = lin.solve(-sys.r)
    except np.linalg.LinAlgError as exc:
        raise InitializationError(
            "cannot compute consistent initial accelerations: the mass matrix with the "
            f"constraint Jacobian is singular ({exc}); check for massless nodes without "
            "stiffness or redundant constraints") from None
    st.vd[:] = sol[:nd]
    st.lam[:] = sol[nd:]
    if any(g.extra.get("active_set", False) for g in model.groups):
        _settle_active_set(model, st, sys, lin)
    st.a[:] = st.vd
    return st


def _settle_active_set(model: Model, st: State, sys: System, lin: LinearSolver,
                       max_iter: int = 20) -> None:
    """Re-solve the acceleration-level equations while elements whose rows depend on the
    multipliers (frictional contacts choosing stick or slip) change their choice: Newton on
    these piecewise-smooth equations from the linear solution (linear rows are already
    satisfied, so for them nothing changes)."""
    nd = model.nd
    for _ in range(max_iter):
        sys.evaluate(st, 1.0, 0.0, 0.0, MODE_ACC, True)
        rq, ph, finite = residual_norms(sys.r, sys.rabs, sys.kscale, nd, FLOOR_REL,
                                        np.zeros_like(sys.r))
        if not finite or (rq <= 1e-12 and ph <= 1e-14):
            return
        try:
            sys.factor(lin)
        except np.linalg.LinAlgError:
            return
        d = lin.solve(-sys.r)
        st.vd += d[:nd]
        st.lam += d[nd:]


def _output_times(t0: float, t_end: float, step, output_dt, output_times) -> np.ndarray:
    if output_times is not None:
        ts = np.unique(np.asarray(output_times, dtype=float))
        return ts[(ts >= t0 - 1e-15) & (ts <= t_end + 1e-12)]
    if output_dt is None:
        if isinstance(step, FixedStep):
            n_steps = max(1, round((t_end - t0) / step.h))
            every = max(1, int(np.ceil(n_steps / 1000)))
            output_dt = every * step.h
        else:
            output_dt = (t_end - t0) / 1000
    n = max(1, round((t_end - t0) / output_dt))
    ts = t0 + output_dt * np.arange(n + 1)
    ts = ts[ts <= t_end * (1 + 1e-12) + 1e-15]
    if ts[-1] < t_end - 1e-12 * max(1.0, abs(t_end)):
        ts = np.append(ts, t_end)
    return ts


def simulate(
    model: Model,
    t_end: float | None = None,
    *,
    state: State | None = None,
    integrator: GeneralizedAlpha | None = None,
    newton: Newton | None = None,
    step: FixedStep | AdaptiveStep | None = None,
    output_dt: float | None = None,
    output_times: Sequence[float] | None = None,
    linear_solver: LinearSolver | None = None,
    progress: Callable[[float, float, int], None] | None = None,
    initialize: bool = True,
    variables: Sequence[str] | None = None,
) -> Results:
    """Integrate ``model`` from ``state`` (default: its initial state) to ``t_end`` [s].

    Args:
        model: compiled model.
        t_end: final time [s]; for a model loaded from a file (``load_model``) every
            argument left at None takes the file's ``[solver]``/``[output]`` value.
        state: initial state; made consistent first unless ``initialize=False``.
        integrator: :class:`GeneralizedAlpha` (default rho_inf = 0.8).
        newton: :class:`Newton` settings.
        step: :class:`FixedStep` (default h = 1 ms) or :class:`AdaptiveStep`.
        output_dt, output_times: when to record (default about 1000 outputs); steps are
            shortened to land on output times.
        linear_solver: default: dense LU up to 150 unknowns, sparse LU above.
        progress: called as ``progress(t, h, steps)`` after every accepted step.
        initialize: make velocities and accelerations consistent first (default True).
        variables: glob patterns of the sensors to keep (default all), e.g.
            ``["crank.*", "*.torque"]``; energy terms are always kept.

    Returns:
        :class:`Results`; on failure ``success`` is False and it holds all outputs recorded
        before the failure.
    """
    scenario = model.meta.get("scenario")
    if scenario is not None:  # a model loaded from a file brings its own settings
        t_end = scenario.t_end if t_end is None else t_end
        integrator = integrator or scenario.integrator
        newton = newton or scenario.newton
        step = step or scenario.step
        if output_dt is None and output_times is None:
            output_dt, output_times = scenario.output_dt, scenario.output_times
        variables = scenario.variables if variables is None else variables
    if t_end is None:
        raise ValueError("simulate: t_end is required for a model without a scenario")
    integrator = integrator or GeneralizedAlpha()
    newton = newton or Newton()
    step = step or FixedStep()
    wall0 = _time.perf_counter()
    st = (state or model.initial_state()).copy()
    lin = linear_solver or default_linear_solver(model.neq)
    stepper = Stepper(model, integrator, newton, lin)
    sys = stepper.sys
    if initialize:
        consistent_initial_state(model, st, sys, lin)
    sys.reset_tangent()
    sys.evaluate(st, 0.0, 0.0, 1.0, MODE_DYN, False)
    viol = sys.constraint_violation()
    if viol.size and viol.max() > model.spec.settings.assembly_tolerance:
        i = int(np.argmax(viol))
        raise InitializationError(f"initial state violates {model.eq_labels[model.nd + i]} "
                                  f"by {viol[i]:.3g}")
    energy = EnergyAccount(model)
    energy.start()
    rec = Recorder(model, energy)
    t0 = st.t
    touts = _output_times(t0, t_end, step, output_dt, output_times)
    iout = 0
    if touts.size and abs(touts[0] - t0) <= 1e-12 * max(1.0, abs(t0)):
        rec.record(st)
        iout = 1
    stats = RunStats()
    adaptive = isinstance(step, AdaptiveStep)
    if adaptive:
        h = step.h0
        h_min, h_max = step.h_min, step.h_max
    else:
        h = step.h
        h_min = step.h_min if step.h_min is not None else step.h / 1024
        h_max = step.h
    success, message = True, ""
    rejections = 0
    eps_t = 1e-9 * (h_min if h_min > 0 else 1e-12)
    substep_until = -np.inf
    h_limit = np.inf  # adaptive: step cap after a Newton failure, relaxed as steps succeed
    debug = log.isEnabledFor(logging.DEBUG)
    try:
        while st.t < t_end - eps_t:
            t_next = touts[iout] if iout < touts.size else t_end
            h_try = min(h, h_max)
            if not adaptive and st.t >= substep_until:
                h_try = h_max
            # land on output times; stretch a step by up to 25 % to reach one, unless the
            # previous attempt was just rejected (stretching it again would loop)
            stretch = rejections == 0 and st.t + h_try >= t_next - 0.25 * h_try
            if st.t + h_try > t_next or stretch:
                h_try = t_next - st.t
            if h_try <= eps_t:
                iout += 1
                continue
            out: StepOutcome = stepper.step(st, h_try)
            stats.newton_iterations += out.iterations
            err = 0.0
            if out.ok and adaptive:
                err, ierr = stepper.error_estimate(st, h_try, step.rtol, step.atol)
                if err > 1.0:
                    out.status = StepStatus.ERROR_TOO_LARGE
                    out.worst_eq = ierr
                    out.residual = err
            if out.ok:
                trial = stepper.trial
                for g in model.groups:
                    if g.commit is not None:
                        g.commit(g, trial)
                energy.advance(h_try)
                stepper.accepted(st)
                st.assign(trial)
                stats.steps += 1
                stats.h_min_used = min(stats.h_min_used, h_try)
                stats.h_max_used = max(stats.h_max_used, h_try)
                rejections = 0
                if iout < touts.size and abs(st.t - touts[iout]) <= 1e-9 * h_try + eps_t:
                    st.t = float(touts[iout])
                    rec.record(st, h_try)
                    iout += 1
                if adaptive:
                    fac = 0.9 * err ** (-1.0 / 3.0) if err > 0 else 2.0
                    fac = min(2.0, max(0.2, fac))
                    if out.iterations > 6:
                        fac = min(fac, 1.0)
                    # hysteresis: a new step size costs a factorisation, so keep h unless the
                    # estimate asks for at least 25 % more
                    if fac < 1.25:
                        fac = 1.0
                    if h_try >= 0.99 * h:  # not a step shortened to land on an output time
                        h = min(h_max, max(h_min, h_try * fac))
                    h_limit *= LIMIT_RELAX
                    h = min(h, max(h_limit, h_min))
                if debug:
                    log.debug("t = %.9g s  h = %.3g s  Newton iterations %d  factorizations %d",
                              st.t, h_try, out.iterations, out.factorizations)
                if progress is not None:
                    progress(st.t, h_try, stats.steps)
                continue
            # rejected step
            if debug:
                log.debug("t = %.9g s  h = %.3g s  rejected: %s (iterations %d, worst %s, %.3g)",
                          st.t, h_try, out.status.value, out.iterations,
                          model.eq_labels[out.worst_eq] if out.worst_eq >= 0 else "-",
                          out.residual)
            stats.rejected += 1
            rejections += 1
            stepper.invalidate()
            if adaptive and out.status is StepStatus.ERROR_TOO_LARGE:
                h = max(h_min, h_try * min(0.9, max(0.2, 0.9 * err ** (-1.0 / 3.0))))
            else:
                h = h_try * 0.25
                if adaptive:
                    h_limit = LIMIT_AFTER_FAILURE * h_try
                if not adaptive:
                    substep_until = st.t + h_max
            max_rej = step.max_rejections if adaptive else 12
            if h < h_min * (1 - 1e-12) or rejections > max_rej:
                success = False
                message = _failure_message(model, st.t, h_try, out)
                log.error(message)
                break
    except KeyboardInterrupt:
        # Ctrl-C: stop cleanly with what was computed (the caller writes partial results)
        success = False
        message = (f"interrupted by the user at t = {st.t:.9g} s; results up to "
                   f"t = {st.t:.9g} s are kept")
        log.error(message)
    stats.factorizations = stepper.factorizations
    stats.residual_evaluations = sys.nevals
    stats.wall_s = _time.perf_counter() - wall0
    if not success and (not rec.t or rec.t[-1] < st.t):
        rec.record(st, 0.0)
    attrs = {
        "integrator": f"GeneralizedAlpha(rho_inf={integrator.rho_inf})",
        "newton": repr(newton),
        "step": repr(step),
        "drivedyn_version": _version(),
    }
    return Results(rec.dataset(attrs, None if variables is None else list(variables)),
                   success, message, stats)


_HINTS = {
    StepStatus.NEWTON_MAX_ITER: "try a smaller step (solver.step.h, or an adaptive step with a "
    "lower h_min), more Newton iterations (solver.newton.max_iter), or check the parameters "
    "of the element named (stiffness, initial penetration)",
    StepStatus.NEWTON_DIVERGED: "try a smaller step or an adaptive step, or check the element "
    "named for a stiffness or load far larger than the rest of the model",
    StepStatus.NONFINITE: "the state became non-finite: check the element named for loads, "
    "stiffnesses or time functions that blow up, and bodies without mass on loaded nodes",
    StepStatus.SINGULAR: "the iteration matrix is singular: look for a massless node or body "
    "without stiffness, a free rotation, or redundant constraints around the equation named",
    StepStatus.ERROR_TOO_LARGE: "the local error stays above tolerance at the smallest step: "
    "loosen solver.step.rtol/atol or lower solver.step.h_min",
}


def _failure_message(model: Model, t: float, h: float, out: StepOutcome) -> str:
    where = ""
    if out.worst_eq >= 0:
        what = ("weighted error" if out.status is StepStatus.ERROR_TOO_LARGE
                else "scaled residual")
        where = f"; worst equation: {model.eq_labels[out.worst_eq]} ({what} {out.residual:.3g})"
    extra = f" ({out.message})" if out.message else ""
    hint = _HINTS.get(out.status, "")
    return (f"simulation stopped at t = {t:.9g} s: step of {h:.3g} s failed: "
            f"{out.status.value}{extra}{where}; results up to t = {t:.9g} s are kept"
            + (f"; {hint}" if hint else ""))


def _version() -> str:
    try:
        from importlib.metadata import version

        return version("drivedyn")
    except Exception:  # pragma: no cover - not installed (source checkout)
        return "unknown"
