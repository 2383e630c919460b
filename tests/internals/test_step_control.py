"""Step-size control (``solver/step_control.py``): how steps reach the output times.

Adaptive steps divide each output interval evenly, so that a run at its ``h_max`` keeps one
step size (every change of size costs a factorisation); fixed steps keep their size and
shorten or stretch the one that reaches an output time.
"""

from __future__ import annotations

import numpy as np
import pytest

import drivedyn as dd
from drivedyn.solver.step_control import (
    CS_H,
    accept_step,
    control_arrays,
    next_step,
    reject_step,
)


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
    step's error estimate when that allows more than the current size, else unchanged
    (each case from fresh arrays: the error envelope of earlier steps stays out)."""
    touts = np.array([1.0])
    step = dd.AdaptiveStep(h0=1e-3, h_max=1.0, rtol=1e-3)
    for t, h, err, expected in [(0.5e-3, 0.5e-3, 1.0, 1e-3),    # error at tolerance: keep
                                (1.0e-3, 0.5e-3, 1e-6, 1e-3),   # 2 x 0.5 ms is not more
                                (1.9e-3, 0.9e-3, 1e-6, 1.8e-3)]:
        ctl, cs = control_arrays(step, 0.25, 1.0)
        cs[CS_H] = 1e-3
        accept_step(cs, ctl, t, h, err, 2, touts)
        assert cs[CS_H] == pytest.approx(expected)


def _controlled_run(error, n_steps: int, h0: float = 1e-4) -> tuple[int, list[float]]:
    """Rejections and accepted step sizes of the adaptive controller alone over ``n_steps``
    accepted steps (1 ms output times), with the error estimate ``error(t, h)`` standing in
    for a model's."""
    touts = 1e-3 * np.arange(1, 100_000)
    ctl, cs = control_arrays(dd.AdaptiveStep(h0=h0, h_max=1e-2, rtol=1e-3), 0.25, 100.0)
    t, rejected, sizes = 0.0, 0, []
    while len(sizes) < n_steps:
        h = next_step(cs, ctl, t, touts)
        err = error(t, h)
        if err <= 1.0:
            t, _ = accept_step(cs, ctl, t + h, h, err, 2, touts)
            sizes.append(h)
        else:
            rejected += 1
            assert not reject_step(cs, ctl, t, h, err, True)
    return rejected, sizes


def test_a_steeper_error_law_seen_at_a_rejection_stops_the_cycle():
    """An estimate that grows as h^6 (0.3 at 250 us, 1.7 at 333 us, a lightly damped mode
    near the step's resolution): after the first rejection the controller uses the exponent
    it measured, and 2 000 steps take at most 2 % of rejections (measured: 16, one every
    ~120 steps once the exponent has relaxed towards 3). With the h^3 law throughout
    (``ERROR_EXPONENT_MAX = 3``) the step grows back to 333 us every few steps: 250
    rejections."""
    rejected, _ = _controlled_run(lambda t, h: 0.3 * (h / 250e-6) ** 6, 2000)
    assert rejected <= 40


def test_the_step_follows_the_crests_of_an_oscillating_estimate():
    """An estimate that rises and falls with a vibration's phase (crests every 1 ms, as the
    RWD vehicle's frame gave; between 0.1 and 1.1 of the tolerance at 250 us, as h^3): grown
    at a trough, the step meets the next crest above the tolerance. The controller grows
    from the envelope of the recent estimates: at most 2 % of 2 000 steps rejected
    (measured: 0). Without the envelope (``ENVELOPE_DECAY = 0``) it grows at every trough:
    400 rejections. Crests 2 ms apart (10 steps) outlast the envelope: 199 rejections,
    the limit stated at ``ENVELOPE_DECAY``."""
    def error(t: float, h: float) -> float:
        return (0.6 + 0.5 * np.cos(2 * np.pi * t / 1e-3)) * (h / 250e-6) ** 3

    rejected, _ = _controlled_run(error, 2000)
    assert rejected <= 40
