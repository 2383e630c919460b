"""The compiled Newton step (drivedyn.solver.newton_kernel) against the Python Newton loop of
Stepper.step: the same algorithm, so every run must give the same steps, iterations,
factorisations and recorded outputs, bit for bit (both call the same element kernels and the
same LAPACK routines in the same order). Cases cover a TORSEN bench (contacts, gears with
stick-slip, rejections), a slider-crank at a dead centre (round-off stagnation test) and a run
that fails (Newton failures down to h_min, partial results)."""

from __future__ import annotations

import numpy as np
import pytest

import drivedyn as dd
from drivedyn.solver import newton_kernel as nk
from same_runs import assert_identical, run_both


def _run_both(monkeypatch, run):
    """``run()`` with the Python Newton loop and with the compiled step; returns both Results
    and the number of compiled step calls. One Stepper.step per attempt: the compiled loop
    (tests/test_step_loop.py) inlines the compiled step."""
    monkeypatch.setenv("DRIVEDYN_COMPILED_LOOP", "0")
    return run_both(monkeypatch, run, nk, "newton_iterations", "DRIVEDYN_COMPILED_NEWTON")


def test_torsen_c_bench_is_the_same_step_for_step(monkeypatch) -> None:
    from drivedyn.config import read_library_file
    from drivedyn.library.differentials import of
    from drivedyn.library.differentials.scenarios import bench_spec

    p = read_library_file("torsen-c")[0]
    model = dd.compile_model(bench_spec(of(p), p, "front")[0])

    def run():
        return dd.simulate(model, 0.06, **p.solver.settings(), output_dt=1e-3)

    slow, fast, ncalls = _run_both(monkeypatch, run)
    assert slow.success and slow.stats.rejected > 0  # rejections are part of the case
    assert ncalls == fast.stats.steps + fast.stats.rejected
    assert_identical(slow, fast)


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
    assert slow.success and ncalls >= 50
    assert_identical(slow, fast)


def test_a_failing_run_fails_the_same_way(monkeypatch) -> None:
    """A speed demand that jumps faster than h_min can resolve: Newton fails (iteration
    limit, diverging corrections) at every size down to h_min; message, worst equation and
    partial results are the same."""
    from small_models import speed_jump_spec

    model = dd.compile_model(speed_jump_spec())

    def run():
        return dd.simulate(model, 1.0, step=dd.AdaptiveStep(h0=1e-3, h_min=1e-4, h_max=1e-2),
                           output_dt=0.1)

    slow, fast, ncalls = _run_both(monkeypatch, run)
    assert not slow.success and "worst equation:" in slow.message
    assert ncalls == fast.stats.steps + fast.stats.rejected
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


def test_superlu_factorised_between_calls_is_the_same(monkeypatch) -> None:
    """With SuperLU the compiled iteration returns for each factorisation and resumes after
    it: the Type C bench on SparseLU (several factorisations in some steps, rejections) is
    the same step for step."""
    from drivedyn.config import read_library_file
    from drivedyn.library.differentials import of
    from drivedyn.library.differentials.scenarios import bench_spec
    from drivedyn.solver.linear import SparseLU

    p = read_library_file("torsen-c")[0]
    model = dd.compile_model(bench_spec(of(p), p, "front")[0])

    def run():
        return dd.simulate(model, 0.03, **p.solver.settings(), output_dt=1e-3,
                           linear_solver=SparseLU())

    slow, fast, ncalls = _run_both(monkeypatch, run)
    attempts = fast.stats.steps + fast.stats.rejected
    # one call per attempt, and one more per factorisation done in between
    assert slow.success and slow.stats.rejected > 0
    assert ncalls == attempts + fast.stats.factorizations
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
    state); the steps then run compiled on the dense LU and match the Python loop."""
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
    assert slow.success and ncalls == fast.stats.steps + fast.stats.rejected
    assert_identical(slow, fast)


@pytest.mark.parametrize("loop", ["1", "0"])
def test_the_step_is_precompiled_for_the_types_it_runs_with(monkeypatch, loop) -> None:
    """The Stepper hands its compiled step's signature and simulate the step-size control's
    (with ``DRIVEDYN_COMPILED_LOOP=0``), or simulate the compiled loop's (``run_steps``,
    which inlines the step and calls the control), the System its kernels' and time
    functions', to the first-evaluation precompile (parallel workers): each must be the
    signature the run then calls, or the workers would compile an overload nobody calls and
    the run would compile its own after them."""
    from drivedyn.solver import precompile
    from drivedyn.solver import step_control as sc
    from drivedyn.solver.linear import SparseLU
    from drivedyn.solver.step_loop import run_steps
    from drivedyn.solver.stepper import Stepper
    from drivedyn.timefunctions import SmoothStep, eval_time_functions
    from drivedyn.validation.engine import slider_crank_model

    monkeypatch.setenv("DRIVEDYN_COMPILED_LOOP", loop)
    handed = []

    def capture(calls, workers=None, while_waiting=None):
        handed.append(list(calls))
        return {"missing": 0, "compiled_in_workers": 0, "wall_s": 0.0}

    monkeypatch.setattr(precompile, "precompile_kernels", capture)
    model = slider_crank_model(0.0, ("speed", SmoothStep(0.0, 0.5, 0.0, 4.0 * np.pi)))
    for lin in (None, SparseLU()):
        stepper = Stepper(model, dd.GeneralizedAlpha(0.9), dd.Newton(), lin)
        assert [d for d, _ in stepper.sys.precompile_also] == [nk.newton_iterations]
        handed.clear()
        if loop == "1":
            watched, unused = (run_steps, eval_time_functions), (nk.newton_iterations,)
        else:
            watched = (nk.newton_iterations, sc.next_step, sc.step_error, sc.accept_step,
                       sc.reject_step, eval_time_functions)
            unused = (run_steps,)
        before = {d: set(d.overloads) for d in watched + unused}
        # adaptive steps, so the error norm runs too
        res = dd.simulate(model, 0.005, step=dd.AdaptiveStep(1e-3), linear_solver=lin)
        assert res.success
        (calls,) = handed
        for d in watched:
            sigs = {sig for disp, sig in calls if disp is d}
            assert len(sigs) == 1, d.py_func.__name__
            # the run compiled (or loaded) exactly the handed signature, no other
            assert set(d.overloads) == before[d] | sigs, d.py_func.__name__
        for d in unused:  # neither handed nor compiled
            assert not any(disp is d for disp, _ in calls), d.py_func.__name__
            assert set(d.overloads) == before[d], d.py_func.__name__
