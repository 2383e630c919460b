"""Step-size control (``solver/step_control.py``): how steps reach the output times.

Adaptive steps divide each output interval evenly, so that a run at its ``h_max`` keeps one
step size (every change of size costs a factorisation); fixed steps keep their size and
shorten or stretch the one that reaches an output time.
"""

from __future__ import annotations

import numpy as np
import pytest

import drivedyn as dd
from drivedyn.solver.step_control import CS_H, accept_step, control_arrays, next_step


def _walk(step, touts: np.ndarray, t_end: float, t0: float = 0.0) -> list[float]:
    """Step sizes from ``t0`` to ``t_end`` with every step accepted at zero error (the
    controller would grow the size: only ``h_max`` and the output times limit it)."""
    ctl, cs = control_arrays(step, 0.25, t_end)
    t = t0
    sizes = []
    while True:
        h = next_step(cs, ctl, t, touts)
        if h == 0.0:
            return sizes
        sizes.append(h)
        t, _ = accept_step(cs, ctl, t + h, h, 0.0, 2, touts)


def test_adaptive_steps_divide_each_output_interval_evenly():
    """1.44 ms output intervals at a 0.2 ms cap (the Type C vehicle's example profile): eight
    steps of 0.18 ms in every interval, one size throughout (not six of 0.2 ms and a
    stretched one of 0.24 ms, two changes of size per interval)."""
    dt = 1.44e-3
    touts = dt * np.arange(1, 51)
    sizes = np.array(_walk(dd.AdaptiveStep(h0=0.2e-3, h_max=0.2e-3), touts, touts[-1]))
    assert len(sizes) == 8 * 50
    assert np.allclose(sizes, dt / 8, rtol=1e-9, atol=0.0)


def test_an_interval_of_exactly_n_steps_stays_n_steps_late_in_a_run():
    """At t = 2 s the time carries the round-off of its sum of steps (about 1e-12 of a 1 ms
    interval); an interval of exactly five 0.2 ms steps must not become six (the changes of
    size made a TORSEN zero-torque hold's Newton chatter)."""
    dt = 1e-3
    t0 = 2.0
    touts = t0 + dt * np.arange(1, 201)
    sizes = np.array(_walk(dd.AdaptiveStep(h0=0.2e-3, h_max=0.2e-3), touts, touts[-1], t0))
    assert len(sizes) == 5 * 200
    assert np.allclose(sizes, 0.2e-3, rtol=1e-9, atol=0.0)


def test_adaptive_steps_never_exceed_the_controllers_size():
    """A size that does not divide the interval: the fewest steps of at most that size."""
    dt = 5e-3
    touts = dt * np.arange(1, 11)
    sizes = np.array(_walk(dd.AdaptiveStep(h0=2e-3, h_max=2e-3), touts, touts[-1]))
    assert len(sizes) == 3 * 10
    assert sizes.max() <= 2e-3 * (1 + 1e-6)
    assert np.allclose(sizes, dt / 3, rtol=1e-9, atol=0.0)


def test_a_shortened_step_lets_the_size_grow_but_never_shrinks_it():
    """The controller's size after a step shortened to reach an output time: grown by the
    step's error estimate when that allows more than the current size, else unchanged."""
    touts = np.array([1.0])
    ctl, cs = control_arrays(dd.AdaptiveStep(h0=1e-3, h_max=1.0, rtol=1e-3), 0.25, 1.0)
    cs[CS_H] = 1e-3
    accept_step(cs, ctl, 0.5e-3, 0.5e-3, 1.0, 2, touts)     # error at tolerance: keep
    assert cs[CS_H] == pytest.approx(1e-3)
    accept_step(cs, ctl, 1.0e-3, 0.5e-3, 1e-6, 2, touts)    # tiny error: 2 x the step taken
    assert cs[CS_H] == pytest.approx(1e-3)                   # 2 x 0.5 ms is not more
    accept_step(cs, ctl, 1.9e-3, 0.9e-3, 1e-6, 2, touts)
    assert cs[CS_H] == pytest.approx(1.8e-3)


def test_fixed_steps_keep_their_size_and_stretch_the_last_one():
    """Fixed steps of 0.2 ms to 1.44 ms output intervals: six of 0.2 ms and one of 0.24 ms
    (stretched by 20 %, within the 25 % allowed) per interval."""
    dt = 1.44e-3
    touts = dt * np.arange(1, 11)
    sizes = np.array(_walk(dd.FixedStep(0.2e-3), touts, touts[-1]))
    assert len(sizes) == 7 * 10
    per = sizes.reshape(10, 7)
    assert np.allclose(per[:, :6], 0.2e-3, rtol=1e-9, atol=0.0)
    assert np.allclose(per[:, 6], 0.24e-3, rtol=1e-9, atol=0.0)


def test_rotation_coordinates_take_their_own_absolute_tolerance():
    """``AdaptiveStep.atol_rot`` weighs the rotation dofs (6 i + 3..5) of the nodes; the
    translations, and coordinates beyond the nodes (modal ones), keep ``atol``."""
    from drivedyn.solver.step_control import step_error

    n = 2 * 6 + 1                      # two nodes and one modal coordinate
    hdq = np.zeros(n)
    a0 = np.zeros(n)
    step = dd.AdaptiveStep(h0=1e-3, h_max=1e-3, rtol=1e-3, atol=1e-6, atol_rot=1e-5)
    ctl, _ = control_arrays(step, 0.25, 1.0, nnode=2)
    same, _ = control_arrays(dd.AdaptiveStep(h0=1e-3, h_max=1e-3, rtol=1e-3, atol=1e-6),
                             0.25, 1.0, nnode=2)
    h = 1e-3
    for i in range(n):
        a1 = np.zeros(n)
        a1[i] = 1.0
        err, where = step_error(ctl, a1, a0, a0, hdq, h, 0.0)
        ref, _ = step_error(same, a1, a0, a0, hdq, h, 0.0)
        assert where == i
        rot = i < 12 and i % 6 >= 3
        assert err == pytest.approx(ref / 10.0 if rot else ref, rel=1e-12), i


def test_atol_rot_must_be_positive():
    with pytest.raises(ValueError, match="atol_rot"):
        dd.AdaptiveStep(atol_rot=0.0)


def test_error_estimate_takes_the_change_over_two_steps():
    """With a step before (``h_prev`` > 0) the estimate is ``c h^2 |a1 - a_prev|``, the
    change of the pseudo-accelerations over the last two steps: an alternating component
    (+d, -d, +d) cancels, a steady ramp gives twice the one-step value. Fails if the
    estimate takes ``a0`` (the one-step change: 2 d on the alternating sequence, the ramp's
    value once)."""
    from drivedyn.solver.step_control import step_error

    n = 6
    hdq = np.zeros(n)
    ctl, _ = control_arrays(dd.AdaptiveStep(h0=1e-3, h_max=1e-3, rtol=0.0, atol=1e-6),
                            0.25, 1.0, nnode=1)
    h = 1e-3
    ramp_prev, ramp0, ramp1 = np.full(n, 1.0), np.full(n, 2.0), np.full(n, 3.0)
    one, _ = step_error(ctl, ramp1, ramp0, ramp0, hdq, h, 0.0)
    two, _ = step_error(ctl, ramp1, ramp0, ramp_prev, hdq, h, h)
    assert two == pytest.approx(2.0 * one, rel=1e-12)
    alt_prev, alt0, alt1 = np.full(n, 5.0), np.full(n, 7.0), np.full(n, 5.0)
    err, _ = step_error(ctl, alt1, alt0, alt_prev, hdq, h, h)
    assert err == 0.0
