"""``simulate``: time integration from a consistent initial state to ``t_end``.

Only this top level decides to stop: a step that fails is retried smaller; when the step
would fall below ``h_min`` (or too many consecutive rejections happen) the run stops, and the
results up to that time are returned with ``success = False`` and a message naming the time,
the worst equation (element and dof) and its residual.

The steps run in the compiled loop of :mod:`~drivedyn.solver.step_loop` (drivedyn's one
stepping engine), which returns to Python after a batch of output times; its step sizes come
from :mod:`~drivedyn.solver.step_control`.
"""

from __future__ import annotations

import inspect
import logging
import time as _time
from collections.abc import Callable, Sequence

import numpy as np

from drivedyn.elements.framework.contract import MODE_ACC, MODE_DYN, MODE_VEL
from drivedyn.model.model import Model, State
from drivedyn.results.recorder import EnergyAccount, Recorder
from drivedyn.results.results import Results, RunStats
from drivedyn.solver.linear import LinearSolver, default_linear_solver
from drivedyn.solver.newton_kernel import FLOOR_REL, residual_norms
from drivedyn.solver.settings import (
    AdaptiveStep,
    FixedStep,
    GeneralizedAlpha,
    Newton,
    StepOutcome,
    StepStatus,
)
from drivedyn.solver.step_control import (
    CS_IOUT,
    control_arrays,
)
from drivedyn.solver.step_loop import (
    RUN_END,
    RUN_FAILED,
    RUN_OUTPUT,
    StepLoop,
    precompile_loop,
)
from drivedyn.solver.stepper import Stepper
from drivedyn.solver.system import System

log = logging.getLogger("drivedyn")


class InitializationError(RuntimeError):
    """The initial state cannot be made consistent (singular constraint Jacobian or mass)."""


def consistent_initial_state(model: Model, st: State, sys: System | None = None,
                             linear_solver: LinearSolver | None = None,
                             project_velocities: bool = True) -> State:
    """Make velocities satisfy the velocity constraints (M-orthogonal projection) and compute
    accelerations and multipliers from the equations of motion and the acceleration-level
    constraints ``Phi_q vd + v^T H v + Phi_tt = 0``. Modifies and returns ``st``.

    Constraint rows that are combinations of the others at ``st`` are found first and set
    aside (:meth:`~drivedyn.solver.system.System.detect_redundancy`): their multipliers are
    zero, the motion is that of the full set."""
    sys = sys or System(model)
    lin = linear_solver or default_linear_solver(model.neq)
    nd = model.nd
    sys.detect_redundancy(st)
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
            f"constraint Jacobian is singular ({exc}); check for massless nodes or bodies "
            "without stiffness and for free rotations (redundant constraint rows are set "
            "aside)") from None
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


#: most recorded samples of a run (each holds every output variable of the model)
MAX_OUTPUTS = 10_000_000


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
    if n > MAX_OUTPUTS:
        raise ValueError(f"output_dt = {output_dt:g} s records {n:.3g} samples over "
                         f"{t_end - t0:g} s (at most {MAX_OUTPUTS:.0e}): choose a longer "
                         "output interval")
    ts = t0 + output_dt * np.arange(n + 1)
    ts = ts[ts <= t_end * (1 + 1e-12) + 1e-15]
    if ts[-1] < t_end - 1e-12 * max(1.0, abs(t_end)):
        ts = np.append(ts, t_end)
    return ts


def _set_up(model: Model, st: State, integrator: GeneralizedAlpha, newton: Newton,
            linear_solver: LinearSolver | None, initialize: bool,
            ) -> tuple[Stepper, LinearSolver, EnergyAccount]:
    """The stepper, linear solver and energy account of a run from ``st``, with every
    compiled function the run calls handed to the System's first-evaluation precompile."""
    lin = linear_solver or default_linear_solver(model.neq)
    stepper = Stepper(model, integrator, newton, lin)
    sys = stepper.sys
    energy = EnergyAccount(model)
    precompile_loop(stepper, st, energy)
    if initialize:  # the consistent initial state calls the linear solver from Python
        sys.precompile_also.extend(lin.compiled_calls(model.indices, model.indptr))
    return stepper, lin, energy


def load_kernels(model: Model, *, integrator: GeneralizedAlpha | None = None,
                 newton: Newton | None = None, linear_solver: LinearSolver | None = None,
                 initialize: bool = True, **_run_settings) -> None:
    """Compile, or load from numba's cache, every compiled function a :func:`simulate` of
    ``model`` with these settings calls (the element kernels, the stepping loop, the linear
    solver's), without running it: the first evaluation's precompile of that run
    (:mod:`~drivedyn.solver.precompile`, parallel workers on a first run) and nothing else.

    Used before forking processes that run the same model (``drivedyn tdr``'s two bench
    sides): each inherits the loaded functions. It replaces a one-step run, which also made
    the state consistent, recorded it and built a results dataset (0.2-0.3 s on the Type C
    bench). Other keywords of :func:`simulate` (``step``,
    ``output_dt``...) are accepted and change nothing here; any other keyword is a
    TypeError."""
    unknown = sorted(set(_run_settings) - set(inspect.signature(simulate).parameters))
    if unknown:
        raise TypeError(f"load_kernels: unexpected keyword(s) {', '.join(unknown)}")
    st = model.initial_state().copy()
    stepper, _lin, _energy = _set_up(model, st, integrator or GeneralizedAlpha(),
                                     newton or Newton(), linear_solver, initialize)
    # the arguments of the run's first evaluation (consistent_initial_state's): the same
    # types, so the same kernel signatures
    stepper.sys.ensure_compiled(st, 1.0, 0.0, 0.0, MODE_VEL, True)


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
        linear_solver: :class:`DenseLU`, :class:`SparseLU` or :class:`AutoLU` (default: dense
            LU up to 150 unknowns, sparse LU above).
        progress: called as ``progress(t, h, steps)`` after accepted steps: after each batch
            of output times (about every 0.05 s of wall; :mod:`~drivedyn.solver.step_loop`),
            after every one with DEBUG logging.
        initialize: make velocities and accelerations consistent first (default True).
        variables: glob patterns of the sensors to keep (default all), e.g.
            ``["crank.*", "*.torque"]``; energy terms are always kept. Only those are stored
            during the run (the memory of a long run with dense outputs follows them).

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
    stepper, lin, energy = _set_up(model, st, integrator, newton, linear_solver, initialize)
    sys = stepper.sys
    if initialize:
        consistent_initial_state(model, st, sys, lin)
    else:
        sys.detect_redundancy(st)
    sys.reset_tangent()
    sys.evaluate(st, 0.0, 0.0, 1.0, MODE_DYN, False)
    viol = sys.constraint_violation()
    if viol.size and viol.max() > model.spec.settings.assembly_tolerance:
        i = int(np.argmax(viol))
        raise InitializationError(f"initial state violates {model.eq_labels[model.nd + i]} "
                                  f"by {viol[i]:.3g}")
    energy.start()
    rec = Recorder(model, energy, None if variables is None else list(variables))
    t0 = st.t
    touts = _output_times(t0, t_end, step, output_dt, output_times)
    iout = 0
    if touts.size and abs(touts[0] - t0) <= 1e-12 * max(1.0, abs(t0)):
        rec.record(st)
        iout = 1
    stats = RunStats()
    ctl, cs = control_arrays(step, stepper.beta, t_end, model.nn)
    cs[CS_IOUT] = iout
    debug = log.isEnabledFor(logging.DEBUG)
    loop = StepLoop.create(stepper, st, touts, ctl, cs, energy, debug, rec.extendable,
                           rec.selection.arrays)
    try:
        success, message = _run_loop(loop, model, st, rec, stats, progress, debug)
    except KeyboardInterrupt:
        # Ctrl-C: stop cleanly with what was computed (the caller writes partial results)
        loop.flush(rec)  # the outputs the loop stored before it returned
        success = False
        message = (f"interrupted by the user at t = {st.t:.9g} s; results up to "
                   f"t = {st.t:.9g} s are kept")
        log.error(message)
    loop.add_stats(stats)
    stats.factorizations = stepper.factorizations
    stats.residual_evaluations = sys.nevals
    stats.wall_s = _time.perf_counter() - wall0
    rec.drop_partial()  # a Ctrl-C within a snapshot
    if not success and (not rec.t or rec.t[-1] < st.t):
        rec.record(st, 0.0)
    attrs = {
        "integrator": f"GeneralizedAlpha(rho_inf={integrator.rho_inf})",
        "newton": repr(newton),
        "step": repr(step),
        "drivedyn_version": _version(),
        **sys.redundancy.attrs(),
    }
    return Results(rec.dataset(attrs, None if variables is None else list(variables)),
                   success, message, stats)


def _log_attempt(model: Model, t: float, h: float, out: StepOutcome) -> None:
    """DEBUG log line of a step attempt (``t``: end of an accepted step, start of a
    rejected one)."""
    if out.ok:
        log.debug("t = %.9g s  h = %.3g s  Newton iterations %d  factorizations %d",
                  t, h, out.iterations, out.factorizations)
    else:
        log.debug("t = %.9g s  h = %.3g s  rejected: %s (iterations %d, worst %s, %.3g)",
                  t, h, out.status.value, out.iterations,
                  model.eq_labels[out.worst_eq] if out.worst_eq >= 0 else "-", out.residual)


def _run_loop(loop: StepLoop, model: Model, st: State, rec: Recorder, stats: RunStats,
              progress, debug: bool) -> tuple[bool, str]:
    """The compiled stepping loop (:mod:`~drivedyn.solver.step_loop`), back in Python after
    a batch of output times (and after every attempt when ``debug``); returns (success,
    message). ``progress`` is called at each return after an accepted step (the last output
    time of a batch; after every accepted step when ``debug``)."""
    while True:
        code = loop.run()
        flushed = loop.flush(rec)
        if code == RUN_END:
            if flushed and progress is not None:
                progress(st.t, loop.pieces()[0], stats.steps + loop.steps)
            return True, ""
        h_try, accepted, _, _ = loop.pieces()
        if debug and code != RUN_FAILED:
            _log_attempt(model, st.t, h_try, loop.outcome())
        if code == RUN_OUTPUT and not loop.buffered:
            rec.record(st, h_try)
        if code == RUN_FAILED:
            out = loop.outcome()
            if debug:
                _log_attempt(model, st.t, h_try, out)
            message = _failure_message(model, st.t, h_try, out)
            log.error(message)
            return False, message
        if progress is not None and accepted:
            progress(st.t, h_try, stats.steps + loop.steps)


_HINTS = {
    StepStatus.NEWTON_MAX_ITER: "try a smaller step (solver.step.h, or an adaptive step with a "
    "lower h_min), more Newton iterations (solver.newton.max_iter), or check the parameters "
    "of the element named (stiffness, initial penetration)",
    StepStatus.NEWTON_DIVERGED: "try a smaller step or an adaptive step, or check the element "
    "named for a stiffness or load far larger than the rest of the model",
    StepStatus.NONFINITE: "the state became non-finite: check the element named for loads, "
    "stiffnesses or time functions that blow up, and bodies without mass on loaded nodes",
    StepStatus.SINGULAR: "the iteration matrix is singular: look for a massless node or body "
    "without stiffness or a free rotation around the equation named",
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
