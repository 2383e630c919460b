"""The compiled stepping loop (drivedyn.solver.step_loop.run_steps) against the Python loop of
simulate with the compiled Newton step: the same steps, so every run must give the same
statistics, messages and recorded outputs (states, element outputs, energy account) bit for
bit. Cases: a TORSEN bench with rejections (adaptive steps, dense LU), the same on the sparse
LU (factorisations in Python between calls), a tyre (a commit of the step's time), a run
that fails down to h_min with fixed steps (sub-steps after a failure) and with adaptive ones,
and the step-by-step mode of DEBUG logging (the same log lines)."""

from __future__ import annotations

import logging

import numpy as np
import pytest

import drivedyn as dd
from drivedyn.solver import step_loop
from same_runs import assert_identical, run_both


def _run_both(monkeypatch, run):
    """``run()`` with the Python loop and with the compiled loop; returns both Results and
    the number of compiled loop calls."""
    return run_both(monkeypatch, run, step_loop, "run_steps", "DRIVEDYN_COMPILED_LOOP")


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


# calls of the compiled loop for 30 output intervals: one per output time and one that finds
# the end; the first batch of 4, then 26 of one (and the end); the first batch, then the
# other 26 outputs in one that ends at the end
@pytest.mark.parametrize(("batching", "calls"), [("none", 31), ("one", 28), ("largest", 2)])
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


def test_sparse_lu_factorised_between_calls_is_the_same(monkeypatch) -> None:
    """With SuperLU the loop returns for each factorisation and resumes after it."""
    from drivedyn.solver.linear import SparseLU

    p, model = _torsen_c_bench("rear")

    def run():
        return dd.simulate(model, 0.02, **p.solver.settings(), output_dt=1e-3,
                           linear_solver=SparseLU())

    _batches(monkeypatch, "none")
    slow, fast, ncalls = _run_both(monkeypatch, run)
    assert slow.success and slow.stats.rejected > 0
    # one call per output interval and one at the end, and one more per factorisation done
    # in between
    assert ncalls == 21 + fast.stats.factorizations
    assert_identical(slow, fast)
    monkeypatch.undo()
    _batches(monkeypatch, "largest")
    slow, fast, ncalls = _run_both(monkeypatch, run)
    # one call per factorisation and one at the end, and at most one for the first batch
    assert 1 <= ncalls - fast.stats.factorizations <= 2
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
    progress calls of the accepted steps."""
    p, model = _torsen_c_bench("front")
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
    assert ncalls == fast.stats.steps + fast.stats.rejected + 1
    assert any("rejected" in line for line in logs[0])
    assert logs[0] == logs[1]
    assert marks[0] == marks[1] and len(marks[0]) == fast.stats.steps
    assert_identical(slow, fast)


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
    monkeypatch.setenv("DRIVEDYN_COMPILED_LOOP", "1")
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
    loop.buffered, loop._nn, loop._nd, loop._sizes = True, 2, 12, (3, 2, 5)

    class Rec:
        def extend(self, *a):
            self.n = a[0].shape[0]

    for per, k in ((0.2, 1), (0.0123, 4), (1e-6, step_loop.BATCH_MAX)):  # s per output
        loop.snaps = step_loop._snapshot_arrays(4, 2, 12, 3, 2, 5)
        loop._wall = step_loop.time.perf_counter() - 3 * per
        loop.snaps[8][0] = 3  # three outputs stored
        rec = Rec()
        assert loop.flush(rec) == 3 and rec.n == 3 and loop.snaps[8][0] == 0
        assert loop.snaps[7].shape[0] == k


def test_a_custom_commit_runs_the_python_loop(monkeypatch) -> None:
    """A family whose commit is not a copy of columns: the compiled loop refuses the model
    (it could not run that commit) and simulate runs the Python loop, which calls it after
    every accepted step."""
    from drivedyn.elements.framework.group import commit_columns
    from drivedyn.solver.step_loop import commit_table, loop_allowed

    p, model = _torsen_c_bench("front")
    assert loop_allowed(model)
    g = next(g for g in model.groups if g.commit_cols)
    committed = []

    def custom(group, state):
        committed.append(state.t)
        commit_columns(group, state)

    g.commit = custom
    g.commit_cols = ()
    assert commit_table(model) is None and not loop_allowed(model)
    calls = []
    compiled = step_loop.run_steps
    monkeypatch.setattr(step_loop, "run_steps", lambda *a: calls.append(1) or compiled(*a))
    res = dd.simulate(model, 0.004, **p.solver.settings(), output_dt=2e-3)
    assert res.success and not calls and len(committed) == res.stats.steps
