"""The tyre element on a wheel: static load, free rolling, the relaxation time constant of a
slip step, standstill and the energy balance."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import curve_fit

from drivedyn.elements import Hinge, JointDriver, Prismatic, TyreContact
from drivedyn.model.compile import compile_model
from drivedyn.model.spec import Spec
from drivedyn.solver import simulate
from drivedyn.solver.settings import FixedStep
from drivedyn.timefunctions import SmoothStep
from drivedyn.tyres import read_tir, shipped

TYRE = read_tir(shipped("pac2002_235_60R16"))
R0 = TYRE.unloaded_radius
CZ = TYRE.vertical_stiffness


def _rig(v: float, spin, height: float, relaxation: bool = True) -> Spec:
    """A carrier at fixed height sliding along x at ``v`` [m/s], so heavy (1e7 kg) that the
    tyre force changes its speed by < 1e-5 relative in these runs; the wheel hinged to it
    with its spin speed [rad/s] prescribed by ``spin`` (a time function)."""
    spec = Spec()
    w0 = spin.evaluate(0.0)[0] if hasattr(spin, "evaluate") else float(spin)
    spec.add_rigid_body("carrier", 1e7, np.diag([1e6, 1e6, 1e6]), position=(0, 0, height),
                        velocity=(v, 0, 0))
    spec.add_rigid_body("wheel", 20.0, np.diag([0.6, 1.0, 0.6]), position=(0, 0, height),
                        velocity=(v, 0, 0), angular_velocity=(0, w0, 0))
    spec.add_marker("g_x", "ground", position=(0, 0, height), axis=(1, 0, 0))
    spec.add_marker("c_x", "carrier", axis=(1, 0, 0))
    spec.add(Prismatic("slide", "g_x", "c_x"))
    spec.add_marker("c_hub", "carrier", axis=(0, 1, 0))
    spec.add_marker("w_hub", "wheel", axis=(0, 1, 0))
    spec.add(Hinge("axle", "c_hub", "w_hub"))
    spec.add(JointDriver("spin", "axle", function=spin, quantity="speed"))
    spec.add(TyreContact("tyre", "w_hub", TYRE, relaxation=relaxation))
    return spec


def test_free_rolling_carries_the_load_without_slip():
    height = R0 - 0.02
    fz = CZ * 0.02
    re = TYRE.effective_radius(0.02)
    v = 10.0
    res = simulate(compile_model(_rig(v, v / re, height)), 0.2, step=FixedStep(1e-3))
    assert res["tyre.fz"].values[-1] == pytest.approx(fz, rel=1e-9)
    # the carrier slows by (F_x + F_rr)/m t = 150 N / 1e7 kg * 0.2 s = 3e-6 m/s: kappa 3e-7
    assert abs(res["tyre.kappa"].values[-1]) < 4e-7
    # the shifts PHX1, PVX1 of the file make a small force at zero slip
    k = res["tyre.kappa"].values[-1]
    assert res["tyre.fx"].values[-1] == pytest.approx(TYRE.forces(fz, k, 0.0, vx=v)[0],
                                                       rel=1e-9)
    assert TYRE.forces(fz, 0.0, 0.0, vx=v)[0] > 100.0
    # rolling resistance about the tyre's y axis opposes the spin
    assert res["tyre.my"].values[-1] == pytest.approx(-0.01 * fz * R0, rel=1e-3)


def test_slip_step_relaxes_with_time_constant_sigma_over_v():
    """kappa' follows kappa (1 - exp(-t/tau)) with tau = sigma_kappa / V (within 1 %)."""
    height = R0 - 0.02
    fz = CZ * 0.02
    re = TYRE.effective_radius(0.02)
    v = 10.0
    kappa = 0.01
    w0, w1 = v / re, v * (1 + kappa) / re
    t0 = 0.05
    spin = SmoothStep(t0, t0 + 1e-4, w0, w1)
    res = simulate(compile_model(_rig(v, spin, height)), 0.5, step=FixedStep(2e-4),
                   output_dt=2e-4)
    t = res["time"].values
    k = res["tyre.kappa_transient"].values
    sig = TYRE.relaxation_lengths(fz)[0]
    tau = sig / v
    sel = t > t0 + 2e-4
    (amp, tau_fit), _ = curve_fit(lambda tt, a, ta: a * (1 - np.exp(-(tt - t0) / ta)),
                                  t[sel], k[sel], p0=(kappa, 0.1))
    assert amp == pytest.approx(kappa, rel=2e-3)
    assert tau_fit == pytest.approx(tau, rel=0.01)
    # the force is the formula's at the transient slip
    k_end = res["tyre.kappa"].values[-1]
    assert res["tyre.fx"].values[-1] == pytest.approx(TYRE.forces(fz, k_end, 0.0, vx=v)[0],
                                                       rel=1e-9)


def test_standstill_spinning_wheel_is_regular():
    """A wheel spun up at zero forward speed: the slip stays finite (transient slip grows
    with the slip velocity) and the force saturates at the friction limit."""
    height = R0 - 0.02
    fz = CZ * 0.02
    spin = SmoothStep(0.0, 0.1, 0.0, 5.0)
    res = simulate(compile_model(_rig(0.0, spin, height)), 1.0, step=FixedStep(1e-3))
    fx = res["tyre.fx"].values
    assert np.all(np.isfinite(fx))
    peak = TYRE.forces(fz, np.linspace(0, 1, 2001), 0.0, vx=0.0)[0].max()
    assert fx[-1] > 0.5 * peak and fx.max() <= peak * (1 + 1e-9)


def test_tyre_in_a_plain_model_file(tmp_path):
    """A wheel dropped on the road from a model file's [[elements]] table: it settles on its
    static deflection m g / Cz (a shipped tyre named by string, a road patch as a table)."""
    from drivedyn.config import load_model

    text = f"""
[model]
name = "wheel-drop"
gravity = [0.0, 0.0, -9.81]
[[bodies]]
name = "wheel"
mass = "400 kg"
inertia = [20.0, 30.0, 20.0]
position = [0.0, 0.0, {R0 - 0.005}]
[[markers]]
name = "hub"
body = "wheel"
axis = [0.0, 1.0, 0.0]
[[elements]]
type = "TyreContact"
name = "tyre"
marker = "hub"
tyre = "pac2002_235_60R16"
patches = [{{x_start = -1.0, x_end = 1.0, mu = 0.5}}]
vertical_damping = "8000 N s/m"
[solver]
t_end = 2.0
"""
    path = tmp_path / "wheel.toml"
    path.write_text(text)
    model = load_model(path)
    res = simulate(model, 2.0)
    assert res.success, res.message
    # the bounce (zeta 0.44, 3.6 Hz) has died out after 2 s: measured 4e-9
    assert res["tyre.fz"].values[-1] == pytest.approx(400 * 9.81, rel=1e-7)
    assert res["tyre.road_mu"].values[-1] == pytest.approx(0.5)
    assert res["tyre.deflection"].values[-1] == pytest.approx(400 * 9.81 / CZ, rel=1e-7)


def test_side_slip_gives_the_formula_side_force_with_lateral_relaxation():
    """A wheel rolling at 10 m/s while drifting sideways at 0.5 m/s: the slip angle is
    atan(V_y / V_x) (ISO-W: positive, the file's negative PKY1 gives a force against the
    drift), the transient slip relaxes with sigma_alpha / V (1 %), and the side force is the
    formula's at the slip angle the element used (1e-9)."""
    from drivedyn.elements import Planar

    height = R0 - 0.02
    fz = CZ * 0.02
    re = TYRE.effective_radius(0.02)
    v, vy = 10.0, 0.5
    spec = Spec()
    spec.add_rigid_body("carrier", 1e7, np.diag([1e6, 1e6, 1e6]), position=(0, 0, height),
                        velocity=(v, vy, 0))
    spec.add_rigid_body("wheel", 20.0, np.diag([0.6, 1.0, 0.6]), position=(0, 0, height),
                        velocity=(v, vy, 0), angular_velocity=(0, v / re, 0))
    spec.add_marker("g", "ground", position=(0, 0, height), axis=(0, 0, 1))
    spec.add_marker("c", "carrier", axis=(0, 0, 1))
    spec.add(Planar("plane", "g", "c"))  # the carrier slides in the road plane
    spec.add_marker("c_hub", "carrier", axis=(0, 1, 0))
    spec.add_marker("w_hub", "wheel", axis=(0, 1, 0))
    spec.add(Hinge("axle", "c_hub", "w_hub"))
    spec.add(JointDriver("spin", "axle", function=v / re, quantity="speed"))
    spec.add(TyreContact("tyre", "w_hub", TYRE))
    res = simulate(compile_model(spec), 0.4, step=FixedStep(2e-4), output_dt=2e-4)
    assert res.success, res.message
    t = res["time"].values
    a = res["tyre.tan_alpha_transient"].values
    tau = TYRE.relaxation_lengths(fz)[1] / v
    sel = t > 1e-3
    (amp, tau_fit), _ = curve_fit(lambda tt, c, ta: c * (1 - np.exp(-tt / ta)), t[sel], a[sel],
                                  p0=(vy / v, 0.05))
    assert amp == pytest.approx(vy / v, rel=2e-3)
    assert tau_fit == pytest.approx(tau, rel=0.01)
    alpha = res["tyre.alpha"].values[-1]
    kappa = res["tyre.kappa"].values[-1]
    fy = res["tyre.fy"].values[-1]
    assert fy == pytest.approx(TYRE.forces(fz, kappa, alpha, vx=v)[1], rel=1e-9)
    assert fy < -1000.0  # against the drift


def test_aligning_moment_is_continuous_through_standstill():
    """A loaded wheel creeping forward or back at 1e-4 m/s (rolling freely): the element's
    aligning moment is the same both ways, near zero (the trail and the residual moment,
    whose sign follows that of V_x, fade with the shifts below VXLOW), where the formula at
    full shifts jumps by twice its residual moment (2 x 4.1 N m at 4.2 kN). Without the
    fade of the residual moment (``dr *= shift`` removed in ``magic_formula.evaluate``) the
    two runs differ by 5.8 N m (seen), and a vehicle's wheel at rest flipped it with each sign of
    its creep speed, a residual Newton could not converge on."""
    height = R0 - 0.02
    fz = CZ * 0.02
    re = TYRE.effective_radius(0.02)
    mz = {}
    for v in (1e-4, -1e-4):
        res = simulate(compile_model(_rig(v, v / re, height)), 0.05, step=FixedStep(1e-3))
        assert res.success, res.message
        mz[v] = res["tyre.mz"].values[-1]
    jump = TYRE.forces(fz, 0.0, 0.0, vx=1e-4)[2] - TYRE.forces(fz, 0.0, 0.0, vx=-1e-4)[2]
    assert abs(jump) > 1.0
    assert abs(mz[1e-4] - mz[-1e-4]) < 1e-6 * abs(jump)
    assert abs(mz[1e-4]) < 1e-6 * abs(jump)


def test_transient_slip_converges_at_second_order():
    """The transient slip over a spin ramp (kappa 0 -> 0.01 in 50 ms at 10 m/s, z = h V /
    sigma_kappa = 0.01-0.05 at these steps), at fixed steps of 4, 2 and 1 ms: the
    differences of successive halvings fall by 4 (second order like the rest of the step;
    ratio 3.5-4.5 asked). With backward Euler over the step (``th = 1.0`` in
    ``_tyre_state``) they fall by 1.98, and the slips' first-order error made a vehicle's window
    figures depend on the step size whatever the tolerance."""
    height = R0 - 0.02
    re = TYRE.effective_radius(0.02)
    v = 10.0
    spin = SmoothStep(0.02, 0.07, v / re, v * 1.01 / re)
    k = []
    for h in (4e-3, 2e-3, 1e-3):
        res = simulate(compile_model(_rig(v, spin, height)), 0.08, step=FixedStep(h),
                       output_times=[0.04, 0.06, 0.08])
        assert res.success, res.message
        k.append(res["tyre.kappa_transient"].values[1:])
    ratio = np.abs(k[0] - k[1]).max() / np.abs(k[1] - k[2]).max()
    assert 3.5 < ratio < 4.5
