"""drivedyn's stepping engine (the compiled loop of drivedyn.solver.step_loop with the Newton
iterations of drivedyn.solver.newton_kernel) against its oracle, the same algorithm in Python
(reference_stepper.py): every run must give the same statistics, messages and recorded
outputs (states, element outputs, energy account) bit for bit, since both call the same
element kernels and the same LAPACK routines in the same order. Cases: a TORSEN bench with
rejections (adaptive steps, dense LU, three output batchings), the same on the sparse LU
(refactorisations in the loop, pivot searches in Python between calls) and on AutoLU gone
dense, a slider-crank at a dead centre (round-off stagnation test) with modified and full
Newton, a tyre (a commit of the step's time), runs that fail down to h_min with fixed and
adaptive steps, and the step-by-step mode of DEBUG logging (the same log lines). A
deliberate change to either side
(e.g. REFACTOR_AFTER = 4 in the reference only, or the predictor's weight capped at 0.5 in
newton_kernel.predict) makes these fail."""

from __future__ import annotations

import logging

import numpy as np
import pytest
from same_runs import assert_identical, run_both

import drivedyn as dd
from drivedyn.solver import step_loop
from drivedyn.solver.settings import StepStatus


def _run_both(monkeypatch, run):
    """``run()`` with the oracle and with the engine; returns both Results and the number of
    calls of the compiled loop."""
    return run_both(monkeypatch, run, step_loop, "run_steps")


def _torsen_c_bench(side: str):
    from drivedyn.config import read_library_file
    from drivedyn.library.differentials import of
    from drivedyn.library.differentials.scenarios import bench_spec

    p = read_library_file("torsen-c")[0]
    return p, dd.compile_model(bench_spec(of(p), p, side)[0])


def _batches(monkeypatch, batching: str) -> None:
    """Outputs per return of the compiled loop: ``"none"`` (it returns at every output time
    and simulate records), ``"one"`` (batches of one after the first of four), ``"largest"``
    (BATCH_MAX after the first)."""
    from drivedyn.results.recorder import Recorder

    if batching == "none":
        monkeypatch.setattr(Recorder, "extendable", property(lambda self: False))
    else:
        monkeypatch.setattr(step_loop, "BATCH_WALL", 0.0 if batching == "one" else np.inf)


# calls of the compiled loop for 30 output intervals: one per output time (the return at the
# last one, t_end, ends the run); the first batch of 4, then 26 of one; the first batch, then
# the other 26 outputs in one that ends at the end
@pytest.mark.parametrize(("batching", "calls"), [("none", 30), ("one", 27), ("largest", 2)])
def test_torsen_c_bench_is_the_same_step_for_step(monkeypatch, batching, calls) -> None:
    p, model = _torsen_c_bench("front")
    _batches(monkeypatch, batching)

    def run():
        return dd.simulate(model, 0.06, **p.solver.settings(), output_dt=2e-3)

    slow, fast, ncalls = _run_both(monkeypatch, run)
    assert slow.success and slow.stats.rejected > 0  # rejections are part of the case
    assert ncalls == calls and fast.stats.steps > 10 * 31
    assert_identical(slow, fast)
    # the energy account is part of the recorded outputs
    assert np.any(fast.dataset["energy.dissipated"].values > 0)


@pytest.mark.parametrize("tail", [False, True])
def test_sparse_lu_factorised_between_calls_is_the_same(monkeypatch, tail: bool) -> None:
    """With the sparse LU the loop refactorises with the last pivots itself
    (``refactor_in_place``) and returns for a factorisation with pivot search (the first,
    and those whose kept pivots are refused), resuming after it; the oracle factorises
    every time in Python (``SparseLU.factor_csc``): the same factors, so the same run. With
    every factorisation returned to Python (``I_REFACTOR`` ignored) the call counts fail.
    ``tail``: the last third of the columns as the dense tail (``sparse_lu``; the bench's
    own factors are too small for one), refactorised in the loop by ``_tail_factor``."""
    import drivedyn.solver.linear as linear
    from drivedyn.solver.linear import SparseLU

    def tails(mp) -> None:
        if tail:
            mp.setattr(linear, "tail_size", lambda Lp, Up, Ui: (Lp.shape[0] - 1) // 3)

    p, model = _torsen_c_bench("rear")
    solvers = []
    before_loop = []  # fresh factorisations of the initial state (in Python)
    create = step_loop.StepLoop.create.__func__

    def run():
        solvers.append(SparseLU())
        return dd.simulate(model, 0.02, **p.solver.settings(), output_dt=1e-3,
                           linear_solver=solvers[-1])

    def counted(cls, *args, **kw):
        before_loop.append(solvers[-1].fresh)
        return create(cls, *args, **kw)

    def in_loop() -> int:
        """Factorisations with pivot search during the engine's stepping."""
        return solvers[-1].fresh - before_loop[-1]

    _batches(monkeypatch, "none")
    tails(monkeypatch)
    monkeypatch.setattr(step_loop.StepLoop, "create", classmethod(counted))
    slow, fast, ncalls = _run_both(monkeypatch, run)
    assert solvers[-1].tail == (solvers[-1]._n // 3 if tail else 0)
    assert slow.success and slow.stats.rejected > 0
    # one call per output interval (the return at the last one ends the run), and one more
    # per factorisation with pivot search done in between
    assert 1 <= in_loop() < fast.stats.factorizations // 4
    assert ncalls == 20 + in_loop()
    assert_identical(slow, fast)
    monkeypatch.undo()
    _batches(monkeypatch, "largest")
    tails(monkeypatch)
    monkeypatch.setattr(step_loop.StepLoop, "create", classmethod(counted))
    slow, fast, ncalls = _run_both(monkeypatch, run)
    # one call per factorisation with pivot search and one at the end, and at most one for
    # the first batch
    assert 1 <= ncalls - in_loop() <= 2
    assert_identical(slow, fast)


def test_a_tyre_commits_the_step_time_the_same_way(monkeypatch) -> None:
    """The tyre's transient slips and the time they were committed at (COMMIT_TIME)."""
    from test_tyre_element import R0, TYRE, _rig

    # a driven wheel (10 % slip) 2 cm into the road
    v = 10.0
    model = dd.compile_model(_rig(v, 1.1 * v / TYRE.effective_radius(0.02), R0 - 0.02))
    assert any(-1 in g.commit_cols for g in model.groups)

    def run():
        return dd.simulate(model, 0.1, step=dd.AdaptiveStep(h0=1e-4, h_max=2e-3),
                           output_dt=5e-3)

    _batches(monkeypatch, "largest")
    slow, fast, ncalls = _run_both(monkeypatch, run)
    assert slow.success and ncalls == 2  # the first batch, the other 16 outputs
    assert_identical(slow, fast)


@pytest.mark.parametrize("step", [dd.AdaptiveStep(h0=1e-3, h_min=1e-4, h_max=1e-2),
                                  dd.FixedStep(1e-2, h_min=1e-4)])
def test_a_failing_run_fails_the_same_way(monkeypatch, step) -> None:
    """A speed demand that jumps faster than h_min can resolve: Newton fails at every size
    down to h_min; message, worst equation and partial results are the same (with fixed
    steps the sub-steps after a failure too)."""
    from small_models import speed_jump_spec

    model = dd.compile_model(speed_jump_spec())

    def run():
        return dd.simulate(model, 1.0, step=step, output_dt=0.1)

    slow, fast, _ = _run_both(monkeypatch, run)
    assert not slow.success and "worst equation:" in slow.message
    assert_identical(slow, fast)


def test_debug_logging_runs_step_by_step_with_the_same_lines(monkeypatch, caplog) -> None:
    """With DEBUG logging the loop returns after every attempt; the log lines (accepted and
    rejected steps, with the worst equation) are those of the Python loop, and so are the
    progress calls of the accepted steps. Outputs unbuffered (``_batches("none")``): the
    return at t_end then ends the run, so the loop is called once per attempt. (Buffered,
    the last step returns as an attempt or as a full batch depending on the batch size,
    which follows the wall time: one call more or not.)"""
    p, model = _torsen_c_bench("front")
    _batches(monkeypatch, "none")
    logs, marks = [], []

    def run():
        caplog.clear()
        marks.append([])
        with caplog.at_level(logging.DEBUG, logger="drivedyn"):
            res = dd.simulate(model, 0.01, **p.solver.settings(), output_dt=2e-3,
                              progress=lambda t, h, n: marks[-1].append((t, h, n)))
        logs.append([r.getMessage() for r in caplog.records if r.getMessage().startswith("t = ")])
        return res

    slow, fast, ncalls = _run_both(monkeypatch, run)
    assert ncalls == fast.stats.steps + fast.stats.rejected
    assert any("rejected" in line for line in logs[0])
    assert logs[0] == logs[1]
    assert marks[0] == marks[1] and len(marks[0]) == fast.stats.steps
    assert_identical(slow, fast)


def test_trace_reports_every_attempt_as_the_python_loop_does(monkeypatch) -> None:
    """``simulate(trace=...)`` is called after every attempt with the oracle's outcomes (the
    seeds' bouncing ball, adaptive steps: rejections at the impacts): an accepted step
    carries its error estimate (at most 1, the tolerance) and the dof where it is largest,
    a step rejected for its error an estimate above 1 at the ball's height; the calls count
    the run's steps and rejections, and tracing changes nothing in the run. It failed with
    the accepted steps' estimate left out of ``StepLoop.outcome`` (error 0, no dof; seen)."""
    from drivedyn.library import bouncing_ball as bb

    model = bb.bouncing_ball_model()
    kw = dict(integrator=dd.GeneralizedAlpha(0.8), output_dt=2e-3,
              step=dd.AdaptiveStep(h0=1e-4, h_min=1e-9, h_max=2e-3, rtol=1e-4, atol=1e-7))
    traces = []

    def run():
        traces.append([])
        return dd.simulate(model, 0.5, **kw,
                           trace=lambda t, h, out: traces[-1].append((t, h, out)))

    slow, fast, _ = _run_both(monkeypatch, run)
    assert_identical(slow, fast)
    assert [(t, h, o.status, o.error, o.worst_eq) for t, h, o in traces[0]] == \
        [(t, h, o.status, o.error, o.worst_eq) for t, h, o in traces[1]]
    ok = [o for _, _, o in traces[1] if o.ok]
    too_large = [o for _, _, o in traces[1] if o.status is StepStatus.ERROR_TOO_LARGE]
    assert len(ok) == fast.stats.steps and len(traces[1]) - len(ok) == fast.stats.rejected
    assert too_large and all(o.error > 1.0 for o in too_large)
    assert {model.eq_labels[o.worst_eq] for o in too_large} == {"node ball: uz"}
    # in free flight the pseudo-accelerations are constant: an estimate of exactly 0
    assert all(0.0 <= o.error <= 1.0 and 0 <= o.worst_eq < model.nd for o in ok)
    assert max(o.error for o in ok) > 0.5
    assert_identical(dd.simulate(model, 0.5, **kw), fast)


@pytest.mark.parametrize(("batching", "times"), [
    ("one", [0.008, 0.01, 0.012, 0.014, 0.016]),  # after the first batch of four, each
    ("largest", [0.008, 0.016]),  # the first batch, then the end
])
def test_progress_is_called_after_each_batch_of_outputs(monkeypatch, batching, times) -> None:
    """Without DEBUG logging the compiled loop reports progress at the last output time of
    each batch it returns (the end included), with the accepted steps counted so far."""
    p, model = _torsen_c_bench("front")
    _batches(monkeypatch, batching)
    marks = []
    res = dd.simulate(model, 0.016, **p.solver.settings(), output_dt=2e-3,
                      progress=lambda t, h, n: marks.append((t, n)))
    assert [t for t, _ in marks] == pytest.approx(times, abs=0)
    counts = [n for _, n in marks]
    assert counts[-1] == res.stats.steps and counts == sorted(set(counts))
    assert res.dataset.sizes["time"] == 9  # every output recorded: t = 0, 0.002, ... 0.016


def test_batches_follow_the_wall_time_between_returns() -> None:
    """The loop's batches hold about BATCH_WALL of wall time: one output when an output
    takes longer, BATCH_MAX when it is much faster."""
    loop = object.__new__(step_loop.StepLoop)  # the batch logic only
    sel = (np.arange(2), np.arange(3), np.arange(2))
    loop.buffered, loop._sel, loop._nacc = True, sel, 5

    class Rec:
        def extend(self, *a):
            self.n = a[0].shape[0]

    for per, k in ((0.2, 1), (0.0123, 4), (1e-6, step_loop.BATCH_MAX)):  # s per output
        loop.snaps = step_loop._snapshot_arrays(4, sel, 5)
        loop._wall = step_loop.time.perf_counter() - 3 * per
        loop.snaps[8][0] = 3  # three outputs stored
        rec = Rec()
        assert loop.flush(rec) == 3 and rec.n == 3 and loop.snaps[8][0] == 0
        assert loop.snaps[7].shape[0] == k



def test_a_commit_that_is_not_a_copy_is_refused(monkeypatch) -> None:
    """A family whose commit is a function (not a copy of columns) cannot run in the
    compiled loop: simulate refuses the model naming the family, before any step."""
    from drivedyn.errors import ModelError
    from drivedyn.solver.step_loop import commit_table

    p, model = _torsen_c_bench("front")
    commit_table(model)
    g = next(g for g in model.groups if g.commit_cols)
    g.commit = lambda group, state: None
    g.commit_cols = ()
    with pytest.raises(ModelError, match=g.family):
        dd.simulate(model, 0.004, **p.solver.settings(), output_dt=2e-3)


def test_dead_centre_round_off_stagnation_is_the_same(monkeypatch) -> None:
    """A slider-crank started at a dead centre stagnates at the round-off of the positions
    (the round-off levels of the residual are used): both loops decide alike."""
    from drivedyn.timefunctions import SmoothStep
    from drivedyn.validation.engine import slider_crank_model

    model = slider_crank_model(0.0, ("speed", SmoothStep(0.0, 0.5, 0.0, 4.0 * np.pi)),
                               guide_spring=(2000.0, 5.0))

    def run():
        return dd.simulate(model, 0.05, step=dd.FixedStep(1e-3),
                           integrator=dd.GeneralizedAlpha(0.9))

    slow, fast, ncalls = _run_both(monkeypatch, run)
    assert slow.success and ncalls >= 1
    assert_identical(slow, fast)


def test_full_newton_is_the_same(monkeypatch) -> None:
    """``strategy="full"`` (a factorisation every iteration) on the dead-centre case."""
    from drivedyn.timefunctions import SmoothStep
    from drivedyn.validation.engine import slider_crank_model

    model = slider_crank_model(0.0, ("speed", SmoothStep(0.0, 0.5, 0.0, 4.0 * np.pi)))

    def run():
        return dd.simulate(model, 0.02, step=dd.FixedStep(1e-3),
                           newton=dd.Newton(strategy="full"))

    slow, fast, ncalls = _run_both(monkeypatch, run)
    assert ncalls > 0 and slow.stats.factorizations >= slow.stats.newton_iterations
    assert_identical(slow, fast)


def test_kernel_table_refuses_arguments_it_cannot_pass() -> None:
    from drivedyn.solver.kernel_calls import KernelTable

    t = KernelTable([(0, (np.zeros((2, 3)), 1.5, 3, True), (np.zeros(4, np.int32),))])
    assert t.table.size == 1 + (1 + 2 + 2) + 3 + (1 + 1 + 1)
    assert t.table[1] == t.arrays[0].ctypes.data and list(t.table[2:6]) == [2, 3, 24, 8]
    assert t.table[6] == np.float64(1.5).view(np.int64) and list(t.table[7:9]) == [3, 1]
    with pytest.raises(TypeError, match="not supported"):
        KernelTable([(0, ("text",), ())])


def test_auto_lu_that_went_dense_is_the_same(monkeypatch) -> None:
    """AutoLU goes dense when the sparse LU's factors fill more than DENSE_FILL of the
    matrix, which for the Type C bench happens at its first factorisation (the initial
    state); the steps then run on the dense LU and match the oracle."""
    from drivedyn.config import read_library_file
    from drivedyn.library.differentials import of
    from drivedyn.library.differentials.scenarios import bench_spec
    from drivedyn.solver.linear import AutoLU

    p = read_library_file("torsen-c")[0]
    model = dd.compile_model(bench_spec(of(p), p, "rear")[0])
    lins = []

    def run():
        lins.append(AutoLU())
        return dd.simulate(model, 0.02, **p.solver.settings(), output_dt=1e-3,
                           linear_solver=lins[-1])

    slow, fast, ncalls = _run_both(monkeypatch, run)
    assert all(lin.dense is not None for lin in lins)
    assert slow.success and ncalls >= 1
    assert_identical(slow, fast)


def test_a_dense_lu_runs_the_loop_built_without_the_sparse_path() -> None:
    """A model on the dense LU alone hands ``sparse=None`` to the compiled loop
    (:mod:`drivedyn.solver.lu_paths`): numba builds it without the sparse solve and the
    refactorisation in place. Its run is the run of the loop built with both paths with the
    dense LU active (AutoLU gone dense at the initial state), to the bit. Fails if the
    dense-only path solves otherwise than the dense branch of the full one (seen with its
    correction's first entry scaled by 1 + 1e-12), or if the DenseLU stepper hands the
    sparse stand-ins again (no ``none`` overload)."""
    from numba import types

    from drivedyn.config import read_library_file
    from drivedyn.library.differentials import of
    from drivedyn.library.differentials.scenarios import bench_spec
    from drivedyn.solver.linear import AutoLU, DenseLU
    from drivedyn.solver.step_loop import run_steps

    p = read_library_file("torsen-c")[0]
    model = dd.compile_model(bench_spec(of(p), p, "rear")[0])
    runs = []
    for lin in (DenseLU(), AutoLU()):
        runs.append(dd.simulate(model, 0.02, **p.solver.settings(), output_dt=1e-3,
                                linear_solver=lin))
    assert runs[0].success and runs[0].stats.rejected > 0
    assert_identical(runs[0], runs[1])
    sparse_arg = [sig[6] for sig in run_steps.overloads]  # run_steps(G, ..., linear, sparse
    assert types.none in sparse_arg
    assert any(isinstance(t, types.BaseTuple) for t in sparse_arg)


def test_the_loop_is_precompiled_for_the_types_it_runs_with(monkeypatch) -> None:
    """simulate hands the compiled loop's signature (``run_steps``), the System its kernels'
    and time functions', to the first-evaluation precompile (parallel workers): each must
    be the signature the run then calls, or the workers would compile an overload nobody
    calls and the run would compile its own after them. Dense and sparse LU."""
    from drivedyn.solver import precompile
    from drivedyn.solver.linear import SparseLU
    from drivedyn.solver.step_loop import run_steps
    from drivedyn.timefunctions import SmoothStep, eval_time_functions
    from drivedyn.validation.engine import slider_crank_model

    handed = []

    def capture(calls, workers=None, while_waiting=None, progress=None):
        handed.append(list(calls))
        return {"missing": 0, "compiled_in_workers": 0, "wall_s": 0.0}

    monkeypatch.setattr(precompile, "precompile_kernels", capture)
    model = slider_crank_model(0.0, ("speed", SmoothStep(0.0, 0.5, 0.0, 4.0 * np.pi)))
    for lin in (None, SparseLU()):
        handed.clear()
        watched = (run_steps, eval_time_functions)
        before = {d: set(d.overloads) for d in watched}
        # adaptive steps, so the error norm runs too
        res = dd.simulate(model, 0.005, step=dd.AdaptiveStep(1e-3), linear_solver=lin)
        assert res.success
        (calls,) = handed
        for d in watched:
            sigs = {sig for disp, sig in calls if disp is d}
            assert len(sigs) == 1, d.py_func.__name__
            # the run compiled (or loaded) exactly the handed signature, no other
            assert set(d.overloads) == before[d] | sigs, d.py_func.__name__


def test_another_linear_solver_is_refused() -> None:
    """The engine factorises with DenseLU, SparseLU or AutoLU: another solver is refused
    with a TypeError naming it, before any step."""
    from drivedyn.solver.linear import LinearSolver
    from drivedyn.timefunctions import SmoothStep
    from drivedyn.validation.engine import slider_crank_model

    class Mine(LinearSolver):
        def factor(self, A):
            return None

        def solve(self, b):
            return b

    model = slider_crank_model(0.0, ("speed", SmoothStep(0.0, 0.5, 0.0, 4.0 * np.pi)))
    with pytest.raises(TypeError, match="Mine"):
        dd.simulate(model, 0.005, linear_solver=Mine())


def _owner_probe():
    """A compiled ``owner(a)``: the address of the array ``a``'s memory owner (0: none)."""
    from llvmlite import ir
    from numba import types
    from numba.extending import intrinsic

    @intrinsic
    def owner(typingctx, a):
        def codegen(context, builder, sig, args):
            ary = context.make_array(sig.args[0])(context, builder, value=args[0])
            return builder.ptrtoint(ary.meminfo, ir.IntType(64))
        return types.int64(a), codegen

    return owner


def test_kernels_borrow_the_state_arrays() -> None:
    """call_groups hands the kernels the state arrays without their memory owner (meminfo),
    so a view a kernel takes (``x[n]``) counts no reference: a probe kernel called through a
    KernelTable finds a null owner on ``x`` and on its view, while the caller's ``x`` has
    one. It fails if call_groups passes the caller's arrays as they are (the kernels then
    pay an atomic increment and decrement per view)."""
    from numba import njit, typeof

    from drivedyn.solver.kernel_calls import KernelTable, call_groups, entry_address

    owner = _owner_probe()

    @njit
    def probe(out, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want):
        out[0] = owner(x)
        out[1] = owner(x[0])
        out[2] = 1

    @njit
    def caller(G, out, x, R, v, vd, lam, es, tfv, t, Tn):
        call_groups(G, x, R, v, vd, lam, es, tfv, t, Tn, 1.0, 1.0, 1.0, 0, False)
        out[3] = owner(x)

    x, R, v, vd = np.ones((2, 3)), np.ones((2, 3, 3)), np.ones(12), np.ones(12)
    lam, es, tfv, Tn = np.ones(1), np.ones(1), np.ones((1, 4)), np.ones((2, 3, 3))
    out = np.zeros(4, np.int64)
    mid = (x, R, v, vd, lam, es, tfv, 0.0, Tn, 1.0, 1.0, 1.0, 0, False)
    probe(out, *mid)  # compile the overload the table calls
    sig = tuple(typeof(a) for a in (out, *mid))
    G = KernelTable([(entry_address(probe, sig), (out,), ())])
    caller(G, out, x, R, v, vd, lam, es, tfv, 0.0, Tn)
    assert out[2] == 1 and out[3] != 0
    assert out[0] == 0 and out[1] == 0


def test_borrow_leaves_out_the_owner_of_every_array_in_a_tuple() -> None:
    """``borrow`` (the stepping loop's arguments at its entry) gives every array of a nested
    tuple without its memory owner and leaves the other values as they are: a probe finds a
    null owner on each borrowed array (at two depths) and on a view of one, the same data,
    and the originals still owned. It fails if borrow passes an array as it is or skips
    nested tuples (the loop then pays an atomic increment and decrement per view and per
    call that takes the array)."""
    from numba import njit

    from drivedyn.solver.kernel_calls import borrow

    owner = _owner_probe()

    @njit
    def probe(t, out):
        b = borrow(t)
        (a, (c, k, none)) = b
        out[0] = owner(a)
        out[1] = owner(c)
        out[2] = owner(c[1:])
        out[3] = owner(t[0])
        out[4] = k
        out[5] = 1 if none is None else 0
        out[6] = a[2] + c[1, 0]

    a, c = np.arange(4.0), np.ones((2, 2), np.int64)
    out = np.zeros(7, np.int64)
    probe((a, (c, 7, None)), out)
    assert list(out[:3]) == [0, 0, 0]
    assert out[3] != 0
    assert list(out[4:]) == [7, 1, 3]
