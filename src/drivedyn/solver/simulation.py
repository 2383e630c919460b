"""A resumable run: :class:`Simulation` sets a model up once (consistent initial state, the
compiled stepping loop, the step-size controller, the recorder) and then advances it to one
time after another, keeping the state, the step size, the factorisation and the recorded
outputs between calls. Its inputs (the :class:`~drivedyn.timefunctions.Held` terms of the
model's time functions) can be written between calls; each is held constant over the next
call (zero-order hold).

:func:`~drivedyn.solver.simulate.simulate` is one :meth:`Simulation.advance` to ``t_end``;
a co-simulation (an FMU, :mod:`drivedyn.fmu`) advances by one communication step per call.

Only this level decides to stop: a step that fails is retried smaller; when the step would
fall below ``h_min`` (or too many consecutive rejections happen) the run stops with
``success`` False and a message naming the time, the worst equation (element and dof) and
its residual; a stopped run does not advance any more.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time as _time
from collections.abc import Callable, Sequence

import numpy as np

from drivedyn.elements.framework.contract import MODE_DYN
from drivedyn.model.model import Model, State
from drivedyn.results.recorder import EnergyAccount, Recorder
from drivedyn.results.results import Results, RunStats
from drivedyn.solver.initial_state import InitializationError, consistent_initial_state
from drivedyn.solver.linear import LinearSolver, default_linear_solver
from drivedyn.solver.settings import (
    AdaptiveStep,
    FixedStep,
    GeneralizedAlpha,
    Newton,
    StepOutcome,
    StepStatus,
)
from drivedyn.solver.step_control import control_arrays
from drivedyn.solver.step_loop import (
    RUN_END,
    RUN_FAILED,
    RUN_OUTPUT,
    StepLoop,
    precompile_loop,
)
from drivedyn.solver.stepper import Stepper
from drivedyn.timefunctions import hold_value

log = logging.getLogger("drivedyn")


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


class Simulation:
    """A run of ``model`` from ``state`` (default: its initial state), advanced by
    :meth:`advance`.

    Args:
        model: compiled model.
        state: initial state; made consistent first unless ``initialize=False``.
        integrator: :class:`GeneralizedAlpha` (default rho_inf = 0.8).
        newton: :class:`Newton` settings.
        step: :class:`FixedStep` (default h = 1 ms) or :class:`AdaptiveStep`; its step size
            carries over from one call of :meth:`advance` to the next.
        linear_solver: :class:`DenseLU`, :class:`SparseLU` or :class:`AutoLU` (default: dense
            LU up to 150 unknowns, sparse LU above).
        initialize: make velocities and accelerations consistent first (default True).
        variables: glob patterns of the sensors to record (default all).
        record: record outputs at the output times of each :meth:`advance` (False: keep
            only the current state, for a co-simulation that reads it after each call).
        trace: called as ``trace(t, h, outcome)`` after every step attempt, accepted or
            rejected (``t`` [s]: the end of an accepted step, the start of a rejected one;
            ``h`` [s]: the step tried; ``outcome``: its :class:`StepOutcome`, with the error
            estimate and the dof that set it). The stepping loop then returns to Python
            after every attempt, which costs wall time, not results
            (``benchmarks/step_trace.py`` uses it).

    Raises:
        InitializationError: the initial state cannot be made consistent, or violates a
            constraint beyond the model's assembly tolerance.
    """

    def __init__(self, model: Model, *, state: State | None = None,
                 integrator: GeneralizedAlpha | None = None, newton: Newton | None = None,
                 step: FixedStep | AdaptiveStep | None = None,
                 linear_solver: LinearSolver | None = None, initialize: bool = True,
                 variables: Sequence[str] | None = None, record: bool = True,
                 trace: Callable[[float, float, StepOutcome], None] | None = None) -> None:
        self.model = model
        self.integrator = integrator or GeneralizedAlpha()
        self.newton = newton or Newton()
        self.step = step or FixedStep()
        self.variables = None if variables is None else list(variables)
        self._wall0 = _time.perf_counter()
        st = (state or model.initial_state()).copy()
        stepper, lin, energy = _set_up(model, st, self.integrator, self.newton, linear_solver,
                                       initialize)
        sys = stepper.sys
        if initialize:
            consistent_initial_state(model, st, sys, lin, phi_tol=self.newton.phi_tol)
        else:
            sys.detect_redundancy(st)
        sys.reset_tangent()
        sys.evaluate(st, 0.0, 0.0, 1.0, MODE_DYN, False)
        viol = sys.constraint_violation()
        if viol.size and viol.max() > model.spec.settings.assembly_tolerance:
            i = int(np.argmax(viol))
            raise InitializationError(f"initial state violates "
                                      f"{model.eq_labels[model.nd + i]} by {viol[i]:.3g}")
        energy.start()
        self.state = st
        self.stepper = stepper
        self.recorder = Recorder(model, energy, self.variables) if record else None
        ctl, cs = control_arrays(self.step, stepper.beta, st.t, model.nn)
        self._debug = log.isEnabledFor(logging.DEBUG)
        self._trace = trace
        rec = self.recorder
        self._loop = StepLoop.create(stepper, st, np.zeros(0), ctl, cs, energy,
                                     self._debug or trace is not None,
                                     rec is not None and rec.extendable,
                                     None if rec is None else rec.selection.arrays)
        pool = model.meta.get("tf_pool")
        self._inputs: dict[str, list[int]] = {} if pool is None else pool.held_terms()
        self._changed = False  # an input changed since the last advance
        # counters that a stepping loop in Python keeps itself (the compiled one: its own)
        self._counts = RunStats()
        self.success = True
        self.message = ""

    @property
    def time(self) -> float:
        """Time of the current (accepted) state [s]."""
        return self.state.t

    @property
    def inputs(self) -> tuple[str, ...]:
        """Names of the inputs (:class:`~drivedyn.timefunctions.Held` terms) of the model."""
        return tuple(self._inputs)

    def set_input(self, name: str, value: float) -> None:
        """Hold input ``name`` at ``value`` (unit of what it drives) from the current time on.
        A change is a discontinuity of the model's forcing: the next step starts without the
        history of the steps before it (its predictor holds the accelerations, its error
        estimate compares with the current state only).

        Raises:
            KeyError: no input of that name.
            ValueError: ``value`` is not a finite number.
        """
        rows = self._inputs.get(name)
        if rows is None:
            raise KeyError(f"no input {name!r} (inputs: {', '.join(self._inputs) or 'none'})")
        v = float(value)
        if not math.isfinite(v):
            raise ValueError(f"input {name!r}: expected a finite value, got {v}")
        par = self.model.tf.par
        for k in rows:
            if par[k, 0] != par[k, 3] * v:
                hold_value(par, k, self.state.t, v)
                self._changed = True

    def discontinuity(self) -> None:
        """Tell the run that the model changed between calls otherwise than through
        :meth:`set_input` (an element parameter written in place, e.g. a road's friction):
        the next step starts afresh, as after an input change."""
        self._changed = True

    def get_input(self, name: str) -> float:
        """The value input ``name`` holds now."""
        k = self._inputs[name][0]
        par = self.model.tf.par
        return float(par[k, 0] / par[k, 3]) if par[k, 3] != 0.0 else 0.0

    def record_state(self) -> None:
        """Record the current state (the first output of a run that starts with one)."""
        if self.recorder is not None:
            self.recorder.record(self.state)

    def advance(self, t_end: float, output_times: Sequence[float] | np.ndarray | None = None,
                progress: Callable[[float, float, int], None] | None = None) -> bool:
        """Integrate from the current time to ``t_end`` [s]; returns ``success``.

        Args:
            t_end: time to reach [s]; nothing happens if it is not after the current time.
            output_times: sorted times [s] in (current time, ``t_end``] at which the steps
                land and, with ``record``, the state is recorded (default: ``t_end``, which
                the run then reaches exactly).
            progress: called as ``progress(t, h, steps)`` after accepted steps (see
                :func:`~drivedyn.solver.simulate.simulate`).

        After a failure (``success`` False, ``message`` says why) the state stays at the
        last accepted step and further calls return False.
        """
        if not self.success:
            return False
        st = self.state
        if not t_end > st.t:
            return True
        touts = (np.array([float(t_end)]) if output_times is None
                 else np.ascontiguousarray(output_times, dtype=float))
        loop = self._loop
        if self._changed:
            loop.forget_history()
            self._changed = False
        loop.retarget(touts, float(t_end))
        try:
            self.success, self.message = _run_loop(loop, self.model, st, self.recorder,
                                                   self._counts, progress, self._debug,
                                                   self._trace)
        except KeyboardInterrupt:
            # Ctrl-C: stop cleanly with what was computed (the caller writes partial results)
            loop.flush(self.recorder)  # the outputs the loop stored before it returned
            self.success = False
            self.message = (f"interrupted by the user at t = {st.t:.9g} s; results up to "
                            f"t = {st.t:.9g} s are kept")
            log.error(self.message)
        return self.success

    def stats(self) -> RunStats:
        """Counters of the run so far (steps, rejections, Newton iterations,
        factorisations, residual evaluations, step sizes, wall time since set-up)."""
        stats = dataclasses.replace(self._counts, extra=dict(self._counts.extra))
        self._loop.add_stats(stats)
        stats.factorizations = self.stepper.factorizations
        stats.residual_evaluations = self.stepper.sys.nevals
        stats.wall_s = _time.perf_counter() - self._wall0
        return stats

    def results(self) -> Results:
        """The recorded outputs as :class:`Results` (with the failure's last state when the
        run stopped after its last output).

        Raises:
            ValueError: the run records nothing (``record=False``).
        """
        rec = self.recorder
        if rec is None:
            raise ValueError("this simulation records nothing (record=False)")
        stats = self.stats()
        rec.drop_partial()  # a Ctrl-C within a snapshot
        st = self.state
        if not self.success and (not rec.t or rec.t[-1] < st.t):
            rec.record(st, 0.0)
        attrs = {
            "integrator": f"GeneralizedAlpha(rho_inf={self.integrator.rho_inf})",
            "newton": repr(self.newton),
            "step": repr(self.step),
            "drivedyn_version": _version(),
            **self.stepper.sys.redundancy.attrs(),
        }
        return Results.from_contents(rec.contents(attrs, self.variables), self.success,
                                     self.message, stats)


def _log_attempt(model: Model, t: float, h: float, out: StepOutcome) -> None:
    """DEBUG log line of a step attempt (``t``: end of an accepted step, start of a
    rejected one)."""
    if out.ok:
        log.debug("t = %.9g s  h = %.3g s  Newton iterations %d  factorizations %d  "
                  "error %.3g (%s)", t, h, out.iterations, out.factorizations, out.error,
                  model.eq_labels[out.worst_eq] if out.worst_eq >= 0 else "-")
    else:
        log.debug("t = %.9g s  h = %.3g s  rejected: %s (iterations %d, worst %s, %.3g)",
                  t, h, out.status.value, out.iterations,
                  model.eq_labels[out.worst_eq] if out.worst_eq >= 0 else "-", out.residual)


def _run_loop(loop: StepLoop, model: Model, st: State, rec: Recorder | None, stats: RunStats,
              progress, debug: bool, trace=None) -> tuple[bool, str]:
    """The compiled stepping loop (:mod:`~drivedyn.solver.step_loop`), back in Python after
    a batch of output times (and after every attempt when ``debug`` or ``trace``); returns
    (success, message). ``progress`` is called at each return after an accepted step (the
    last output time of a batch; after every accepted step when ``debug``), ``trace`` after
    every attempt. A return at an output time that is the loop's end time ends the call (no
    further call to find the end)."""
    while True:
        code = loop.run()
        flushed = loop.flush(rec)
        if code == RUN_END:
            if flushed and progress is not None:
                progress(st.t, loop.pieces()[0], stats.steps + loop.steps)
            return True, ""
        h_try, accepted, _, _ = loop.pieces()
        if debug or trace is not None:
            out = loop.outcome()
            if debug:
                _log_attempt(model, st.t, h_try, out)
            if trace is not None:
                trace(st.t, h_try, out)
        if code == RUN_OUTPUT and not loop.buffered and rec is not None:
            rec.record(st, h_try)
        if code == RUN_FAILED:
            out = loop.outcome()
            message = _failure_message(model, st.t, h_try, out)
            log.error(message)
            return False, message
        if progress is not None and accepted:
            progress(st.t, h_try, stats.steps + loop.steps)
        if code == RUN_OUTPUT and st.t >= loop.t_end:
            return True, ""


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
