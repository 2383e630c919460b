"""The engine torque map (``EngineTorque``): the torque at the table's points is the table's,
between them the PCHIP curve's, beyond them the end value; the throttle blends the
zero-throttle and full-load curves linearly; the engine speed and torque go through the
ratio; the speed tangent is the map's slope; bad tables are refused naming the key and the
value, from Python, from a model file (exit 2) and from the vehicle's file."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.interpolate import PchipInterpolator

import drivedyn as dd
from drivedyn.cli import main
from drivedyn.elements import EngineTorque
from drivedyn.errors import ModelError
from drivedyn.model.compile import compile_model
from drivedyn.solver.system import System
from fdcheck import assembled

FULL = ((0.0, 400.0), (80.0, 520.0), (105.0, 930.0), (150.0, 1300.0), (230.0, 1040.0),
        (250.0, -270.0))
ZERO = ((0.0, -2.0), (80.0, -20.0), (150.0, -30.0), (250.0, -100.0))
RATIO = 4.0
#: engine speeds [rad/s]: table points, between them, beyond both ends
SPEEDS = (0.0, 80.0, 105.0, 150.0, 250.0, 40.0, 92.5, 127.0, 190.0, 240.0, 300.0, -15.0)


def _map(table, w):
    """The table read by SciPy (the reference), clamped to its range."""
    x, y = np.array(table).T
    return PchipInterpolator(x, y)(np.clip(w, x[0], x[-1]))


def _shaft(omega: float, throttle, zero=ZERO) -> dd.Spec:
    """A shaft hinged on the ground about z, turning at ``omega`` [rad/s] (held by a speed
    driver), driven through ``RATIO`` by an engine on the ground mount."""
    spec = dd.Spec()
    spec.add_rigid_body("shaft", 2.0, np.eye(3), angular_velocity=(0.0, 0.0, omega))
    spec.add_marker("mount", "ground")
    spec.add_marker("out", "shaft")
    spec.add(dd.Hinge("bearing", "mount", "out"))
    spec.add(dd.JointDriver("drive", "bearing", omega, quantity="speed"))
    spec.add(EngineTorque("engine", "mount", "out", full_load=FULL, zero_throttle=zero,
                          throttle_function=throttle, ratio=RATIO))
    return spec


@pytest.mark.parametrize("w_engine", SPEEDS)
def test_torque_is_the_table_pchip_between_clamped_beyond_and_blended_by_the_throttle(
        w_engine: float) -> None:
    """A shaft turning at ``w_engine / RATIO`` under a throttle ramp from 0 to 1: the engine
    speed is ``RATIO`` times the shaft's, the engine torque ``T_0 + u (T_F - T_0)`` with
    SciPy's PCHIP of each table at that speed (the table's value at a point, the end value
    beyond), the shaft's torque ``RATIO`` times it and its power the torque times the
    shaft's speed.

    Deliberate mutations that fail it: the curves extrapolated straight instead of clamped;
    the throttle multiplying the whole torque (``u T_F``); the ratio left out of the engine
    speed or the shaft's torque."""
    omega = w_engine / RATIO
    res = dd.simulate(compile_model(_shaft(omega, dd.Ramp(0.0, 0.1, 0.0, 1.0))), 0.1,
                      step=dd.FixedStep(5e-3), output_dt=0.01)
    assert res.success
    u = np.clip(res.time / 0.1, 0.0, 1.0)
    tf, t0 = _map(FULL, w_engine), _map(ZERO, w_engine)
    expected = t0 + u * (tf - t0)
    np.testing.assert_allclose(res["engine.throttle"].values, u, atol=1e-12)
    np.testing.assert_allclose(res["engine.engine_speed"].values, w_engine, atol=1e-9)
    np.testing.assert_allclose(res["engine.engine_torque"].values, expected, rtol=1e-9,
                               atol=1e-9)
    np.testing.assert_allclose(res["engine.torque"].values, RATIO * expected, rtol=1e-9,
                               atol=1e-9)
    np.testing.assert_allclose(res["engine.power"].values, RATIO * expected * omega,
                               rtol=1e-9, atol=1e-9)


def test_table_points_are_exact_and_the_python_torque_matches() -> None:
    """``EngineTorque.torque`` (what the kernel computes) is the table at each point: the
    full-load table at throttle 1, the zero-throttle one at 0, and without a zero-throttle
    curve the throttle scales the full-load torque.

    Deliberate mutation that fails it: the zero-throttle curve read from the full-load
    table's slot."""
    e = EngineTorque("e", "a", "b", full_load=FULL, zero_throttle=ZERO)
    for w, t in FULL:
        assert e.torque(w, 1.0) == pytest.approx(t, abs=1e-12)
    for w, t in ZERO:
        assert e.torque(w, 0.0) == pytest.approx(t, abs=1e-12)
    f = EngineTorque("f", "a", "b", full_load=FULL)
    for w in SPEEDS:
        assert f.torque(w, 0.3) == pytest.approx(0.3 * float(_map(FULL, w)), rel=1e-12)


@pytest.mark.parametrize("w_engine", [40.0, 92.5, 127.0, 190.0, 240.0, 300.0, -15.0])
def test_speed_tangent_is_the_slope_of_the_map(w_engine: float) -> None:
    """The element's damping matrix on the shaft's spin is ``-RATIO^2 dT_e/domega_e``, the
    slope of the blended map at the engine speed (central differences of
    ``EngineTorque.torque``), 0 beyond the table (the speed clamped). A free shaft with an
    isotropic inertia: no other damping term.

    Deliberate mutations that fail it: the tangent without the square of the ratio; the
    slope kept beyond the table's ends."""
    omega = w_engine / RATIO
    spec = dd.Spec()
    spec.add_rigid_body("shaft", 2.0, np.eye(3), angular_velocity=(0.0, 0.0, omega))
    spec.add_marker("mount", "ground")
    spec.add_marker("out", "shaft")
    e = EngineTorque("engine", "mount", "out", full_load=FULL, zero_throttle=ZERO,
                     throttle_function=0.35, ratio=RATIO)
    spec.add(e)
    model = compile_model(spec)
    st = model.initial_state()
    C = assembled(System(model), st, 0.0, 1.0, 0.0)
    h = 1e-5
    slope = (e.torque(w_engine + h, 0.35) - e.torque(w_engine - h, 0.35)) / (2 * h)
    assert C[5, 5] == pytest.approx(-RATIO ** 2 * slope, rel=1e-6, abs=1e-8)
    off = C[:6, :6].copy()
    off[5, 5] = 0.0
    assert np.abs(off).max() < 1e-12


@pytest.mark.parametrize(("kwargs", "words"), [
    ({"full_load": ((0.0, 400.0), (100.0, 900.0), (90.0, 1000.0))},
     ["EngineTorque 'e'.full_load", "increase strictly", "100.0", "90.0"]),
    ({"zero_throttle": ((-10.0, 0.0), (100.0, -20.0))},
     ["EngineTorque 'e'.zero_throttle", ">= 0 rad/s", "-10.0"]),
    ({"full_load": ((0.0, 400.0),)}, ["EngineTorque 'e'.full_load", "at least 2 points"]),
    ({"full_load": "flat"}, ["EngineTorque 'e'.full_load", "expected a table", "'flat'"]),
    ({"ratio": 0.0}, ["EngineTorque 'e'.ratio", "must be > 0", "0.0"]),
])
def test_bad_parameters_are_refused_naming_key_and_value(kwargs, words) -> None:
    """Deliberate mutations that fail it: the speeds' order not checked (a table going back
    in speed read as a curve); negative speeds accepted."""
    params = {"full_load": FULL, "zero_throttle": ZERO, **kwargs}
    with pytest.raises(ModelError) as exc:
        EngineTorque("e", "a", "b", **params).validate()
    for w in words:
        assert w in str(exc.value), str(exc.value)


MODEL = """
[model]
name = "engine-on-a-shaft"

[[bodies]]
name = "shaft"
mass = "2 kg"
inertia = [1.0, 1.0, 1.0]
angular_velocity = [0, 0, "250 rpm"]

[[markers]]
name = "mount"
body = "ground"

[[markers]]
name = "out"
body = "shaft"

[[elements]]
type = "Hinge"
name = "bearing"
marker_a = "mount"
marker_b = "out"

[[elements]]
type = "EngineTorque"
name = "engine"
marker_a = "mount"
marker_b = "out"
full_load = [[0.0, "400 N m"], ["800 rpm", 520.0], [105.0, 930.0], [250.0, -270.0]]
zero_throttle = [[0.0, -2.0], [80.0, -20.0], [250.0, -100.0]]
throttle_function = { type = "ramp", t0 = 0.0, t1 = 0.05, v0 = 0.0, v1 = 0.2 }
ratio = 4.0

[solver]
t_end = "0.05 s"
step = { mode = "fixed", h = "1 ms" }

[output]
dt = "10 ms"
"""


def test_model_file_engine_with_units(tmp_path: Path) -> None:
    """An ``EngineTorque`` in a model file: table entries with units converted per column
    (rpm to rad/s), the throttle a time function; the shaft spins up.

    Deliberate mutation that fails it: the table's units ignored (800 rpm read as 800
    rad/s)."""
    from drivedyn.config import load_model

    path = tmp_path / "m.toml"
    path.write_text(MODEL)
    model = load_model(path)
    e = next(x for x in model.spec.elements if x.name == "engine")
    assert e.full_load[1] == pytest.approx((800 * np.pi / 30, 520.0))
    res = dd.simulate(model)
    assert res.success
    w = res["engine.engine_speed"].values
    assert w[0] == pytest.approx(4.0 * 250 * np.pi / 30) and w[-1] > w[0]


@pytest.mark.parametrize(("old", "new", "words"), [
    ('["800 rpm", 520.0], [105.0, 930.0]', '[105.0, 520.0], [90.0, 930.0]',
     ["elements[1] (engine).full_load", "increase strictly", "105.0", "90.0"]),
    ("zero_throttle = [[0.0, -2.0]", "zero_throttle = [[-5.0, -2.0]",
     ["elements[1] (engine).zero_throttle", ">= 0 rad/s", "-5.0"]),
    ('["800 rpm", 520.0]', '["800 s", 520.0]',
     ["elements[1] (engine).full_load", "'800 s' is in s, expected rad/s"]),
])
def test_bad_model_files_exit_2_with_the_message(tmp_path: Path, old: str, new: str,
                                                 words: list[str]) -> None:
    """``drivedyn run`` on a model file with a bad engine map exits with 2 and one message
    naming the entry, the key and the value, no traceback."""
    assert old in MODEL
    path = tmp_path / "m.toml"
    path.write_text(MODEL.replace(old, new))
    res = CliRunner().invoke(main, ["run", str(path), "--out", str(tmp_path / "r.nc")])
    out = res.output + (res.stderr if res.stderr_bytes is not None else "")
    assert res.exit_code == 2, f"exit {res.exit_code}: {out}\n{res.exception!r}"
    assert "Traceback" not in out, out
    for w in words:
        assert w in out, out
