"""``simulate``: time integration from a consistent initial state to ``t_end``.

Only this top level decides to stop: a step that fails is retried smaller; when the step
would fall below ``h_min`` (or too many consecutive rejections happen) the run stops, and the
results up to that time are returned with ``success = False`` and a message naming the time,
the worst equation (element and dof) and its residual.

A run is one :meth:`~drivedyn.solver.simulation.Simulation.advance` to ``t_end`` of a
:class:`~drivedyn.solver.simulation.Simulation`: the steps run in the compiled loop of
:mod:`~drivedyn.solver.step_loop` (drivedyn's one stepping engine), which returns to Python
after a batch of output times; its step sizes come from
:mod:`~drivedyn.solver.step_control`.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Sequence

import numpy as np

from drivedyn.elements.framework.contract import MODE_VEL
from drivedyn.model.model import Model, State
from drivedyn.results.results import Results
from drivedyn.solver.initial_state import InitializationError, consistent_initial_state
from drivedyn.solver.linear import LinearSolver
from drivedyn.solver.settings import (
    AdaptiveStep,
    FixedStep,
    GeneralizedAlpha,
    Newton,
    StepOutcome,
)
from drivedyn.solver.simulation import Simulation, _set_up

__all__ = ["MAX_OUTPUTS", "InitializationError", "consistent_initial_state", "load_kernels",
           "simulate"]


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
    trace: Callable[[float, float, StepOutcome], None] | None = None,
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
        trace: called as ``trace(t, h, outcome)`` after every step attempt (see
            :class:`~drivedyn.solver.simulation.Simulation`): where the steps go, which dof
            sets the step size, why steps are rejected (``benchmarks/step_trace.py``).

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
    sim = Simulation(model, state=state, integrator=integrator, newton=newton, step=step,
                     linear_solver=linear_solver, initialize=initialize, variables=variables,
                     trace=trace)
    t0 = sim.time
    touts = _output_times(t0, t_end, step, output_dt, output_times)
    if touts.size and abs(touts[0] - t0) <= 1e-12 * max(1.0, abs(t0)):
        sim.record_state()
        touts = touts[1:]
    sim.advance(t_end, touts, progress)
    return sim.results()
