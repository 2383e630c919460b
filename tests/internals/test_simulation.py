"""The resumable run (drivedyn.solver.Simulation) and its held inputs (Held time functions):
a run advanced in pieces that end at output times is simulate's run bit for bit; a held
speed input steps the speed while the angle it prescribes stays continuous (the integral of
the held values); a run that failed stays failed; inputs refuse unknown names and
non-finite values; the Held time function packs, evaluates and parses like the others."""

from __future__ import annotations

import math

import numpy as np
import pytest
from same_runs import assert_identical

import drivedyn as dd
from drivedyn.solver.simulation import Simulation
from drivedyn.timefunctions import KIND_HELD, Held, TimeFunctionPool, as_time_function


def _torsen_c_bench():
    from drivedyn.config import read_library_file
    from drivedyn.library.differentials import of
    from drivedyn.library.differentials.scenarios import bench_spec

    p = read_library_file("torsen-c")[0]
    return p, dd.compile_model(bench_spec(of(p), p, "front")[0])


def test_a_run_advanced_in_pieces_is_simulate_bit_for_bit() -> None:
    """The Type C bench (adaptive steps with rejections) over 30 ms, advanced in three pieces
    ending at output times, records the same states, outputs and statistics as one
    simulate. Made to fail by StepLoop.retarget leaving the output index where the last call
    stopped (cs[CS_IOUT] not reset: the second piece skips its first output times)."""
    p, model = _torsen_c_bench()
    settings = p.solver.settings()
    ref = dd.simulate(model, 0.03, **settings, output_dt=1e-3)
    sim = Simulation(model, **settings)
    sim.record_state()
    touts = np.linspace(0.0, 0.03, 31)
    for a, b in ((1, 11), (11, 17), (17, 31)):
        assert sim.advance(touts[b - 1], touts[a:b])
        assert sim.time == touts[b - 1]
    res = sim.results()
    assert ref.stats.rejected > 0
    assert_identical(ref, res)


def _driven_disk(function) -> dd.Spec:
    spec = dd.Spec()
    spec.add_rigid_body("disk", 1.0, [0.01, 0.01, 0.02])
    spec.add_marker("g", "ground", axis=(0, 0, 1))
    spec.add_marker("m", "disk", axis=(0, 0, 1))
    spec.add(dd.Hinge("h", "g", "m"))
    spec.add(dd.JointDriver("d", "h", function, quantity="speed"))
    return spec


def test_a_held_speed_steps_and_its_angle_is_the_integral_of_the_held_values() -> None:
    """A disk driven at -2 x a held speed: after each 10 ms call with a new value, the disk
    turns at that speed (1e-3) and its angle is the sum of value x 10 ms over the calls (to
    1e-9 rad), the driver's torque is finite. Made to fail by hold_value not carrying the
    integral to the time of the change (par[k, 2] kept: the angle jumps back at each call)."""
    model = dd.compile_model(_driven_disk(-2.0 * Held("w", 1.0)))
    sim = Simulation(model, record=False, step=dd.AdaptiveStep(h0=1e-3, h_max=2e-3))
    assert sim.inputs == ("w",)
    assert sim.get_input("w") == 1.0
    angle = 0.0
    n = model.node_index["disk"]
    for i, w in enumerate((1.0, 3.0, -2.0, -2.0, 5.0)):
        sim.set_input("w", w)
        assert sim.get_input("w") == w
        assert sim.advance(0.01 * (i + 1))
        angle += -2.0 * w * 0.01
        g, e = model.group("d")
        outs = {name: g.aux[e, c] for c, name, *_ in g.outputs()}
        assert outs["angle"] == pytest.approx(angle, abs=1e-9)
        # the speed steps; the integrator's velocity settles on it within a few steps
        assert sim.state.v[6 * n + 5] == pytest.approx(-2.0 * w, rel=1e-3)
        assert math.isfinite(outs["torque"])


def test_a_failed_run_stays_failed_at_its_last_state() -> None:
    """A run that cannot follow a speed jump stops there; the next call returns False and
    the state does not move. Made to fail by advance not checking success first (it steps
    on from the failed state)."""
    from small_models import speed_jump_spec

    sim = Simulation(dd.compile_model(speed_jump_spec()), record=False,
                     step=dd.AdaptiveStep(h0=1e-3, h_min=1e-6, h_max=1e-2))
    assert not sim.advance(1.0)
    t, message = sim.time, sim.message
    assert 0.49 < t < 0.51 and "stopped at" in message
    assert not sim.advance(2.0)
    assert (sim.time, sim.message) == (t, message)


def test_inputs_refuse_unknown_names_and_non_finite_values() -> None:
    """Made to fail by set_input skipping its checks (a NaN would reach the kernels)."""
    sim = Simulation(dd.compile_model(_driven_disk(Held("w"))), record=False)
    with pytest.raises(KeyError, match=r"no input 'v'.*inputs: w"):
        sim.set_input("v", 1.0)
    for bad in (math.nan, math.inf):
        with pytest.raises(ValueError, match="finite"):
            sim.set_input("w", bad)
    with pytest.raises(ValueError, match="records nothing"):
        sim.results()


def test_held_time_function_packs_evaluates_and_parses() -> None:
    """Held terms: value start x scale, integral value x t, scaled copies keep the name, the
    dict form round-trips, the pool lays them out as KIND_HELD rows with their scale and
    finds every term of a name. Made to fail by the pool packing a Held term's value
    unscaled."""
    f = 3.0 * Held("u", 2.0)
    assert (f(0.5), f.derivative(0.5), f.integral(0.5)) == (6.0, 0.0, 3.0)
    assert as_time_function(f.to_dict()) == f
    assert as_time_function({"type": "held", "name": "u"}) == Held("u")
    with pytest.raises(ValueError, match="unknown key"):
        as_time_function({"type": "held", "name": "u", "value": 1.0})
    pool = TimeFunctionPool()
    pool.add(1.0)
    pool.add(Held("u", 2.0) + dd.Ramp(0.0, 1.0, 0.0, 1.0) + (-1.0) * Held("u", 2.0))
    packed = pool.pack()
    assert pool.held_terms() == {"u": [1, 3]}
    assert packed.kind[1] == KIND_HELD and packed.kind[3] == KIND_HELD
    assert packed.par[1].tolist() == [2.0, 0.0, 0.0, 1.0]
    assert packed.par[3].tolist() == [-2.0, 0.0, 0.0, -1.0]
    np.testing.assert_allclose(packed.evaluate(0.5)[1], [0.5, 1.0, 0.0, 0.125])
