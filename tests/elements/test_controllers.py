"""The speed controller on a flywheel: a PI loop reaches its reference with no steady
error, the gate holds the output, the limits clip the output and the integral term
(anti-windup), and the messages of bad parameters name the key and the unit. Each test's
docstring names a deliberate mutation that makes it fail."""

from __future__ import annotations

import numpy as np
import pytest

from drivedyn.elements import Hinge, SpeedController, TorsionalSpringDamper
from drivedyn.errors import ModelError
from drivedyn.model.compile import compile_model
from drivedyn.model.spec import Spec
from drivedyn.solver import simulate
from drivedyn.timefunctions import SmoothStep

RADIUS = 0.5  # [m] of the sensor on the flywheel
DRAG = 2.0  # [N m s/rad] of the flywheel's bearing


def _flywheel(sensor: str = "rim", **kw) -> Spec:
    """A flywheel (1 kg m^2 about z) hinged on the ground with a viscous drag; the sensor at
    RADIUS, its x axis along the rim (speed = omega RADIUS); the controller drives the
    flywheel against the ground."""
    sp = Spec()
    sp.add_rigid_body("wheel", 10.0, (0.6, 0.6, 1.0))
    sp.add_marker("ground_axis", "ground")
    sp.add_marker("wheel_axis", "wheel")
    sp.add_marker("rim", "wheel", position=(RADIUS, 0.0, 0.0),
                  rotation=np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]))
    sp.add(Hinge("bearing", "ground_axis", "wheel_axis"))
    sp.add(TorsionalSpringDamper("drag", "ground_axis", "wheel_axis", damping=DRAG))
    sp.add(SpeedController("control", sensor, "ground_axis", "wheel_axis", **kw))
    return sp


def _run(sp: Spec, t_end: float):
    res = simulate(compile_model(sp), t_end, output_dt=0.01)
    assert res.success, res.message
    return res


def test_pi_reaches_the_reference_with_no_steady_error():
    """From rest to 2 m/s: the speed settles on the reference (1e-4 relative) and the torque
    on the drag's (DRAG omega); the power supplied is torque times speed. Mutation: drop the
    integral term (``s = s_n``) -> a proportional loop keeps an error of
    DRAG omega / (k_p RADIUS) (0.4 %)."""
    res = _run(_flywheel(function=2.0, gain=100.0, integral_gain=200.0), 6.0)
    u = res.values("control.speed")
    T = res.values("control.torque")
    assert u[-1] == pytest.approx(2.0, rel=1e-4)
    assert T[-1] == pytest.approx(DRAG * 2.0 / RADIUS, rel=1e-3)
    omega = res.values("wheel.angular_velocity")[-1, 2]
    assert res.values("control.power")[-1] == pytest.approx(T[-1] * omega, rel=1e-9)


def test_gate_holds_the_output():
    """The gate closes at 3 s; the reference then rises to 3 m/s but the torque stays at its
    held value and the speed stays at 2 m/s. Mutation: ignore the gate (``g = 1``) -> the
    loop follows the new reference."""
    res = _run(_flywheel(function=SmoothStep(3.5, 4.0, 2.0, 3.0), gain=100.0,
                         integral_gain=200.0, gate_function=SmoothStep(2.9, 3.0, 1.0, 0.0)),
               6.0)
    t, T, u = res.time, res.values("control.torque"), res.values("control.speed")
    held = T[np.searchsorted(t, 3.0)]
    assert np.allclose(T[t >= 3.0], held, rtol=1e-9)
    assert u[-1] == pytest.approx(2.0, rel=1e-3)


def test_limits_clip_the_output_and_the_integral_term():
    """With ``torque_max`` below the drag at the reference, the torque stays at the limit,
    the integral term does not wind up beyond it, and the speed settles where the drag
    equals the limit. Mutation: clip only the output (not ``s``) -> the integral term grows
    beyond the limit."""
    res = _run(_flywheel(function=2.0, gain=100.0, integral_gain=200.0, torque_min=0.0,
                         torque_max=5.0), 6.0)
    assert res.values("control.torque")[-1] == pytest.approx(5.0)
    assert res.values("control.integral").max() <= 5.0 + 1e-12
    assert res.values("control.speed")[-1] == pytest.approx(5.0 / DRAG * RADIUS, rel=1e-3)


@pytest.mark.parametrize("kw, message", [
    ({"gain": -1.0}, "SpeedController 'c'.gain: must be >= 0 N s"),
    ({"torque_min": 2.0, "torque_max": 1.0}, "torque_max: must be >= torque_min = 2 N m"),
    ({"torque_max": 1.0, "initial_torque": 3.0}, "initial_torque: must be within [-inf, 1] N m"),
])
def test_bad_parameters_are_refused(kw, message):
    """Mutation: drop the limits' check in ``validate`` -> the inverted limits pass."""
    with pytest.raises(ModelError) as exc:
        SpeedController("c", "s", "a", "b", **kw).validate()
    assert message in str(exc.value)


def test_sensor_on_the_ground_is_refused():
    """Mutation: drop the ground check of the sensor -> the model compiles with a speed that
    is always 0."""
    sp = _flywheel("ground_axis", function=1.0)
    with pytest.raises(ModelError, match="sensor: marker 'ground_axis' is on the ground"):
        compile_model(sp)
