"""The closing correction of a converged Newton step (drivedyn.solver.newton_kernel): taken
where the residual is within the tolerance but above CLOSE_BELOW of it, skipped below. The
accuracy it buys is checked by ``tests/verification/test_squeezer.py``
(``test_second_order_with_the_default_newton``, which fails with CLOSE_BELOW = 1); here,
where it is taken and that the engine takes it where its oracle does."""

from __future__ import annotations

import numpy as np
import pytest
from reference_stepper import ReferenceStepper
from same_runs import assert_identical, run_both

import drivedyn as dd
from drivedyn.solver import step_loop


def _chain(n: int) -> dd.Spec:
    """``n`` disks on hinges about x, neighbours on torsional springs, a torque on the
    first: every step converges in one iteration to round-off (1e-15 of the force sums)."""
    spec = dd.Spec(gravity=(0.0, 0.0, 0.0))
    axis = (1.0, 0.0, 0.0)
    for i in range(n):
        pos = (0.1 * i, 0.0, 0.0)
        spec.add_rigid_body(f"d{i}", 1.0, (1e-3, 1e-3, 1e-3), position=pos)
        spec.add_marker(f"g{i}", dd.GROUND, position=pos, axis=axis)
        spec.add_marker(f"m{i}", f"d{i}", axis=axis)
        spec.add(dd.Hinge(f"h{i}", f"g{i}", f"m{i}"))
        if i:
            spec.add(dd.TorsionalSpringDamper(f"s{i}", f"m{i - 1}", f"m{i}", stiffness=1e4,
                                              damping=1.0))
    spec.add(dd.Torque("drive", "m0", vector=(100.0, 0.0, 0.0)))
    return spec


def _counted_solves(monkeypatch, model, t_end: float, **kw) -> tuple:
    """Run ``model`` with the oracle, counting its solves; returns (results, solves)."""
    from reference_stepper import reference_runs

    solves = []
    solve = ReferenceStepper._solve

    def counting(self, st):
        solves.append(1)
        return solve(self, st)

    monkeypatch.setattr(ReferenceStepper, "_solve", counting)
    with reference_runs(monkeypatch):
        res = dd.simulate(model, t_end, **kw)
    return res, len(solves)


def test_no_closing_solve_below_close_below(monkeypatch) -> None:
    """On the chain every step converges far below CLOSE_BELOW x tol: one solve per Newton
    iteration and none to close a step (a step converged on its predictor takes no solve).
    Fails with CLOSE_BELOW = 0 (a closing solve at every step: 100 more)."""
    model = dd.compile_model(_chain(4))
    res, solves = _counted_solves(monkeypatch, model, 0.01, step=dd.FixedStep(1e-4),
                                  output_dt=1e-3)
    assert res.success and res.stats.steps == 100
    assert solves == res.stats.newton_iterations


def test_closing_solve_above_close_below(monkeypatch) -> None:
    """Andrews' squeezer at the default tolerance converges within the tolerance but not
    below CLOSE_BELOW of it at most steps: those take the closing solve (solves beyond the
    Newton iterations; measured 110 of 160 steps). Fails if the correction is never taken
    (CLOSE_BELOW = 1: 0 steps) or at every step (CLOSE_BELOW = 0: 160)."""
    from drivedyn.validation import squeezer as S  # noqa: N812

    model = S.squeezer_model(scale=1.0)
    res, solves = _counted_solves(monkeypatch, model, 2e-4, step=dd.FixedStep(1.25e-6),
                                  output_dt=1e-4)
    assert res.success and res.stats.steps == 160
    closing = solves - res.stats.newton_iterations
    assert 0.5 * res.stats.steps < closing < res.stats.steps


@pytest.mark.parametrize("n", [4])
def test_the_engine_skips_where_its_oracle_does(monkeypatch, n: int) -> None:
    """The chain run by the compiled loop and by the oracle: identical to the last bit
    (a skip in one and not the other moves every velocity by the correction, 1e-15
    relative, which ``array_equal`` sees). Fails with the skip removed from either."""
    model = dd.compile_model(_chain(n))

    def run():
        return dd.simulate(model, 0.01, step=dd.FixedStep(1e-4), output_dt=1e-3)

    slow, fast, calls = run_both(monkeypatch, run, step_loop, "run_steps")
    assert calls > 0
    assert_identical(slow, fast)
    assert np.isfinite(fast["d3.angular_velocity"].values).all()
