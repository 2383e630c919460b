"""Gear pair element against exact results: force components, deflection, ISO stiffness,
kinematic ratios over many revolutions, natural frequency, backlash, energy, friction power,
worm efficiency, bevel forces, a planetary set (Willis equation, torque split) and the model
checks. The registry tangent test (tests/elements/test_tangents.py) covers its matrices."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import trapezoid

import drivedyn as dd
from drivedyn.elements.gears import CylindricalPair, iso6336_mesh_stiffness, mesh_info
from drivedyn.model.spec import ModelError
from drivedyn.rotations import frame_from_axis

DEG = math.pi / 180.0
Z = (0.0, 0.0, 1.0)


def two_gears(za=20, zb=40, mn=3e-3, beta=0.0, internal=None, JA=2e-3, JB=8e-3, hold=None,
              torque_b=0.0, an=20 * DEG, tilt_b=0.0, centre=None, **kw):
    """Wheel A at the origin and wheel B at (a, 0, 0), both on hinges to the ground about
    global z (B's axis optionally tilted about x by ``tilt_b``); ``hold="a"`` adds an angle
    driver holding A, ``torque_b`` a torque on B about its axis."""
    z2 = -zb if internal == "b" else zb
    geo = CylindricalPair.build(za, z2, mn, an, beta)
    a = geo.centre_distance if centre is None else centre
    spec = dd.Spec()
    spec.add_rigid_body("A", 1.0, (1e-3, 1e-3, JA))
    spec.add_rigid_body("B", 2.0, (JB, JB, JB), position=(a, 0, 0))
    c, s = math.cos(tilt_b), math.sin(tilt_b)
    FB = np.array([[1, 0, 0], [0, c, -s], [0, s, c]]) @ frame_from_axis(Z)
    spec.add_marker("gA", dd.GROUND, axis=Z)
    spec.add_marker("mA", "A", axis=Z)
    spec.add_marker("gB", dd.GROUND, position=(a, 0, 0), rotation=FB)
    spec.add_marker("mB", "B", rotation=FB)
    spec.add(dd.Hinge("hA", "gA", "mA"))
    spec.add(dd.Hinge("hB", "gB", "mB"))
    spec.add(dd.GearPair("g", "mA", "mB", za, zb, mn, 0.02, pressure_angle=an, helix_angle=beta,
                         internal=internal, **kw))
    if hold == "a":
        spec.add(dd.JointDriver("hold", "hA", 0.0, quantity="angle"))
    if torque_b:
        spec.add(dd.Torque("T", "mB", vector=torque_b * FB[:, 2]))
    return spec, geo


# ---------------------------------------------------------------------------------------------
# statics: force components, deflection, ISO stiffness
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("internal", [None, "b"])
@pytest.mark.parametrize("T", [100.0, -100.0])
@pytest.mark.parametrize("beta", [0.0, 20 * DEG, -20 * DEG])
def test_helical_force_components(beta, T, internal):
    """Wheel A held, torque T on wheel B: F_t r_B = |T|, F_a = F_t tan(beta) (on B:
    -F_t tan(beta_A), so it flips with the hand and with the torque), F_r = |F_t| tan(alpha_n)
    / cos(beta) separating, F_n = F_t / (cos alpha_n cos beta), deflection = F_n / k_m; the
    global force is the gear-frame force in the frame (t, e, a)."""
    an = 20 * DEG
    spec, geo = two_gears(beta=beta, internal=internal, hold="a", torque_b=T, stiffness=3e8)
    m = dd.compile_model(spec)
    o = dd.element_outputs(m, dd.solve_static(m))["g"]
    Ft, Fr, Fa, Fn = (o[k] for k in ("tangential_force", "radial_force", "axial_force",
                                     "normal_force"))
    rB = abs(geo.r2)
    assert o["torque_b"] == pytest.approx(-T, rel=1e-11)
    assert abs(Ft) * rB == pytest.approx(abs(T), rel=1e-11)
    assert Fa == pytest.approx(-Ft * math.tan(beta), rel=1e-11, abs=1e-9)
    assert Fr == pytest.approx(abs(Ft) * math.tan(an) / math.cos(beta), rel=1e-11)
    assert Fn == pytest.approx(Ft / (math.cos(an) * math.cos(beta)), rel=1e-11)
    assert o["deflection"] == pytest.approx(Fn / 3e8, rel=1e-11)
    # A turns positively -> drive flank; an external B pushed positively loads the drive flank
    assert np.sign(Fn) == np.sign(T) * (1 if internal is None else -1)
    e = np.array([1.0, 0, 0]) * (1 if internal is None else -1)
    t = np.cross(Z, e)
    F = np.array([o["force_x"], o["force_y"], o["force_z"]])
    np.testing.assert_allclose(F, Ft * t + Fr * e + Fa * np.array(Z), rtol=1e-11, atol=1e-9)


def test_default_stiffness_is_iso6336_method_b():
    """Without ``stiffness`` the mesh stiffness is ISO 6336-1 method B of the geometry
    (helical, profile-shifted pair at its working centre distance)."""
    beta = 14 * DEG
    geo = CylindricalPair.build(21, 50, 2.5e-3, 20 * DEG, beta, x1=0.2, x2=-0.05)
    spec = dd.Spec()
    spec.add_rigid_body("A", 1.0, (1e-3, 1e-3, 1e-3))
    spec.add_rigid_body("B", 1.0, (1e-3, 1e-3, 1e-3), position=(geo.centre_distance, 0, 0))
    spec.add_marker("mA", "A", axis=Z)
    spec.add_marker("mB", "B", axis=Z)
    spec.add(dd.GearPair("g", "mA", "mB", 21, 50, 2.5e-3, 0.025, helix_angle=beta,
                         helix_angle_b=-beta, profile_shift_a=0.2, profile_shift_b=-0.05))
    info = mesh_info(dd.compile_model(spec), "g")
    iso = iso6336_mesh_stiffness(21, 50, beta, 20 * DEG, geo.eps_alpha, 0.025, 0.2, -0.05)
    assert info["stiffness"] == pytest.approx(iso.k_mesh, rel=1e-13)
    assert info["contact_ratio"] == pytest.approx(geo.eps_alpha, rel=1e-13)
    assert 14.0 < iso.c_gamma_alpha_iso < 20.0


def test_misaligned_axes_are_tolerated():
    """Wheel B's axis tilted by 0.5 deg: the static solution exists and the transmitted
    force is within the cosine of the tilt of the aligned one."""
    ref = None
    for tilt in (0.0, 0.5 * DEG):
        spec, _geo = two_gears(beta=15 * DEG, hold="a", torque_b=50.0, stiffness=2e8,
                              tilt_b=tilt)
        m = dd.compile_model(spec)
        o = dd.element_outputs(m, dd.solve_static(m))["g"]
        if ref is None:
            ref = o
        else:
            assert o["normal_force"] == pytest.approx(ref["normal_force"], rel=2e-3)
            assert o["torque_b"] == pytest.approx(-50.0, rel=1e-9)


# ---------------------------------------------------------------------------------------------
# kinematics and dynamics
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("internal", [None, "b"])
def test_kinematic_ratio_over_120_revolutions(internal):
    """A driven at 100 rev/s for 120 revolutions, B loaded: the wheel angles keep the ratio
    -z_A/z_B (external) or +z_A/z_B (internal) exactly up to the mesh deflection u:
    c_A phi_A + c_B phi_B = u; the angles relative to the mesh frame equal the hinge angles
    (fixed centre line)."""
    za, zb = 17, 43
    spec, _ = two_gears(za, zb, beta=15 * DEG, internal=internal, stiffness=2e8,
                        damping_ratio=0.05, torque_b=-5.0 if internal is None else 5.0)
    w = 2 * np.pi * 100
    spec.add(dd.JointDriver("drive", "hA", dd.SmoothStep(0.0, 0.05, 0.0, w), quantity="speed"))
    m = dd.compile_model(spec)
    res = dd.simulate(m, 1.225, step=dd.FixedStep(2e-4), integrator=dd.GeneralizedAlpha(0.9),
                      output_dt=5e-3)
    assert res.success, res.message
    info = mesh_info(m, "g")
    hA, hB = res["hA.angle"].values, res["hB.angle"].values
    assert hA[-1] / (2 * np.pi) > 120
    np.testing.assert_allclose(res["g.angle_a"].values, hA, atol=1e-12)
    np.testing.assert_allclose(res["g.angle_b"].values, hB, atol=1e-12)
    sign = -1.0 if internal is None else 1.0
    assert info["coef_a"] / info["coef_b"] == pytest.approx(-sign * za / zb, rel=1e-14)
    assert hB[-1] / hA[-1] == pytest.approx(sign * za / zb, rel=1e-7)
    u = res["g.deflection"].values
    resid = info["coef_a"] * hA + info["coef_b"] * hB - u
    assert np.abs(resid).max() < 1e-13 * np.abs(info["coef_a"] * hA).max() + 1e-15
    assert res["g.normal_force"].values[-1] == pytest.approx(5.0 / info["coef_b"] * sign,
                                                             rel=1e-4)


def _trapezoid_frequency(w: float, h: float) -> float:
    """Discrete angular frequency of the trapezoidal rule (generalized alpha, rho_inf = 1):
    tan(W h / 2) = w h / 2."""
    return 2.0 / h * math.atan(0.5 * w * h)


def test_natural_frequency_of_two_wheels():
    """Two free wheels (inertias J_A, J_B about their axes) coupled by the mesh: the normal
    force oscillates at w = sqrt(k_m (c_A^2 / J_A + c_B^2 / J_B)), c = r_b cos(beta_b)
    (= sqrt(k_m r_bA^2 cos^2 beta_b (1/J_A + r_bB^2/(r_bA^2 J_B))). With rho_inf = 1 the
    scheme's only error is the trapezoidal dispersion, which is removed exactly."""
    spec, geo = two_gears(beta=20 * DEG, stiffness=1e8)
    b = spec.bodies["A"]
    spec.bodies["A"] = type(b)(**{**b.__dict__, "angular_velocity": np.array([0, 0, 1.0])})
    m = dd.compile_model(spec)
    info = mesh_info(m, "g")
    cbb = math.cos(geo.beta_b)
    assert info["coef_a"] == pytest.approx(geo.rb1 * cbb, rel=1e-14)
    w = math.sqrt(1e8 * (info["coef_a"] ** 2 / 2e-3 + info["coef_b"] ** 2 / 8e-3))
    h = 2 * math.pi / w / 200
    res = dd.simulate(m, 40 * 2 * math.pi / w, step=dd.FixedStep(h),
                      integrator=dd.GeneralizedAlpha(1.0), output_dt=h)
    from drivedyn.validation.common import crossings

    F = res["g.normal_force"].values
    tc = crossings(res.time, F - F.mean(), 1)
    w_sim = 2 * math.pi * (len(tc) - 1) / (tc[-1] - tc[0])
    assert w_sim == pytest.approx(_trapezoid_frequency(w, h), rel=2e-6)
    assert w_sim == pytest.approx(w, rel=1e-4)  # dispersion (wh)^2/12 = 8.2e-5
    scale = res["energy.kinetic"].values[0]
    assert np.abs(res["energy.balance_error"].values).max() < 1e-8 * scale


def test_backlash_free_play_and_closing():
    """B held, A turned backwards from drive-flank contact: no force over b / r_bA, then the
    coast flank carries k_m (c_A |phi_A| - b_n); the onset is exactly b / r_bA."""
    b = 1e-4
    spec, geo = two_gears(beta=20 * DEG, stiffness=1e8, backlash=b)
    spec.add(dd.JointDriver("holdB", "hB", 0.0, quantity="angle"))
    spec.add(dd.JointDriver("turnA", "hA", dd.Ramp(0.0, 1.0, 0.0, -3 * b / geo.rb1),
                            quantity="angle"))
    m = dd.compile_model(spec)
    res = dd.simulate(m, 1.0, step=dd.FixedStep(1e-3), integrator=dd.GeneralizedAlpha(0.9),
                      output_dt=1e-3)
    ang, F = res["hA.angle"].values, res["g.normal_force"].values
    free = np.abs(ang) < 0.999 * b / geo.rb1
    assert np.all(F[free] == 0.0) and np.all(F[~free & (np.abs(ang) > 1.001 * b / geo.rb1)] < 0)
    sel = F < -1.0
    slope, icpt = np.polyfit(ang[sel], F[sel], 1)
    assert -icpt / slope == pytest.approx(-b / geo.rb1, rel=1e-10)
    assert res["g.approach"].values[-1] == pytest.approx(mesh_info(m, "g")["coef_a"] * ang[-1],
                                                         rel=1e-9)


def test_backlash_impact():
    """A spins backwards at w0 from drive-flank contact with B held: the coast flank is hit
    after (b / r_bA) / |w0|, and without damping A rebounds with its speed reversed."""
    b, w0 = 1e-4, -2.0
    spec, geo = two_gears(stiffness=1e8, backlash=b)
    spec.add(dd.JointDriver("holdB", "hB", 0.0, quantity="angle"))
    body = spec.bodies["A"]
    spec.bodies["A"] = type(body)(**{**body.__dict__, "angular_velocity": np.array([0, 0, w0])})
    m = dd.compile_model(spec)
    res = dd.simulate(m, 3e-3, step=dd.FixedStep(5e-7), integrator=dd.GeneralizedAlpha(1.0),
                      output_dt=5e-7)
    t, F = res.time, res["g.normal_force"].values
    t_hit = t[np.argmax(F < 0)]
    assert t_hit == pytest.approx(b / geo.rb1 / abs(w0), abs=6e-7)
    assert res["A.angular_velocity"].values[-1, 2] == pytest.approx(-w0, rel=1e-5)
    assert F[-1] == 0.0
    scale = res["energy.kinetic"].values[0]
    assert np.abs(res["energy.balance_error"].values).max() < 1e-5 * scale


@pytest.mark.parametrize("onset", [0.0, 2e-6])
def test_energy_conserved_without_damping_and_friction(onset):
    """Two free helical wheels with backlash, transmission error and stiffness varying over
    the mesh cycle, spinning with different speeds (repeated impacts and rolling): with
    rho_inf = 1 the energy balance closes to the integrator's accuracy; nothing is
    dissipated. With a flank onset of 2 um (impacts pass through it) the potential k W(u)
    and its stiffness-variation terms must keep the balance as well."""
    spec, _geo = two_gears(za=19, zb=31, beta=15 * DEG, stiffness=5e7, backlash=5e-5,
                          initial_gap=2e-5, transmission_error=3e-6, stiffness_variation=True,
                          variation_smoothing=0.2, flank_onset=onset)
    for name, w in (("A", 30.0), ("B", -10.0)):
        body = spec.bodies[name]
        spec.bodies[name] = type(body)(**{**body.__dict__,
                                          "angular_velocity": np.array([0, 0, w])})
    m = dd.compile_model(spec)
    res = dd.simulate(m, 0.05, step=dd.FixedStep(2e-6), integrator=dd.GeneralizedAlpha(1.0),
                      output_dt=1e-4)
    assert res.success, res.message
    F = res["g.normal_force"].values
    assert (F > 0).any() and (F == 0).any()  # contact and free flight
    scale = float(res["energy.kinetic"].values[0])
    assert np.abs(res["energy.balance_error"].values).max() < 1e-4 * scale
    assert res["energy.dissipated"].values[-1] == 0.0
    k = res["g.stiffness"].values
    assert k.min() < 5e7 < k.max()


def test_stiffness_over_the_mesh_cycle_and_transmission_error():
    """Quasi-statics over two mesh cycles of A (B held, A loaded by a torque): the
    stiffness follows the two-level law with mean k_m, and the deflection is F_n / k(phi)
    with the transmission error X (1 - cos(z_A phi_A)) entering the approach:
    c_A phi_A + c_B phi_B + X (1 - cos z_A phi_A) = u."""
    za, X, km = 20, 2e-6, 2e8
    spec, _geo = two_gears(za=za, stiffness=km, stiffness_variation=True, transmission_error=X,
                          variation_smoothing=0.1)
    spec.add(dd.JointDriver("turnB", "hB", dd.Ramp(0.0, 1.0, 0.0, -2 * 2 * np.pi / 40),
                            quantity="angle"))
    spec.add(dd.Torque("TA", "mA", vector=(0, 0, 20.0)))
    m = dd.compile_model(spec)
    info = mesh_info(m, "g")
    st = m.initial_state()
    ks, checks = [], []
    for t in np.linspace(0.0, 1.0, 401):
        st = dd.solve_static(m, st, t=t)
        o = dd.element_outputs(m, st)["g"]
        ks.append(o["stiffness"])
        pa, pb = o["angle_a"], o["angle_b"]
        xerr = X * (1 - math.cos(za * pa))
        checks.append(info["coef_a"] * pa + info["coef_b"] * pb + xerr - o["deflection"])
        assert o["deflection"] == pytest.approx(o["normal_force"] / o["stiffness"], rel=1e-10)
    ks = np.array(ks)
    assert np.abs(checks).max() < 1e-14
    eps = info["contact_ratio"]
    lo, hi = km * 1.0 / (0.75 * eps + 0.25), km * 1.75 / (0.75 * eps + 0.25)
    assert ks.min() == pytest.approx(lo, rel=1e-9) and ks.max() == pytest.approx(hi, rel=1e-9)
    assert trapezoid(ks[:201], dx=1) / 200 == pytest.approx(km, rel=1e-2)


# ---------------------------------------------------------------------------------------------
# friction
# ---------------------------------------------------------------------------------------------


def test_friction_power_is_the_dissipation():
    """Spur pair driven at constant speed against a load: the friction power is
    mu_R(v_s) |F_n| v_s with v_s = s_eff |omega_rel| (s_eff: mean contact distance from the
    pitch point; mu_R the regularised Coulomb law), the input
    minus the output power is that loss, the element's dissipated energy is the integral of
    its reported power, the energy balance closes, and the loss agrees with ISO/TR 14179-2
    (P_in mu H_V) to first order in mu."""
    mu = 0.08
    spec, geo = two_gears(stiffness=3e8, damping=2e3, friction=mu, friction_velocity=1e-3,
                          torque_b=40.0)
    spec.add(dd.JointDriver("drive", "hA", dd.SmoothStep(0.0, 0.05, 0.0, 50.0),
                            quantity="speed"))
    m = dd.compile_model(spec)
    res = dd.simulate(m, 0.3, step=dd.FixedStep(1e-5), integrator=dd.GeneralizedAlpha(0.9),
                      output_dt=1e-4)
    assert res.success, res.message
    info = mesh_info(m, "g")
    wA = res["A.angular_velocity"].values[:, 2]
    wB = res["B.angular_velocity"].values[:, 2]
    Pf = res["g.friction_power"].values
    Fn = res["g.normal_force"].values
    # the outputs are those of each step's last evaluation, the velocities those after its
    # closing Newton correction (newton_kernel): the two agree within Newton's tolerance
    # (measured 4e-9 relative), a wrong sliding arm or a lost |.| is off by order 1
    vs_state = info["sliding_arm"] * np.abs(wA - wB)
    vs = res["g.sliding_velocity"].values
    np.testing.assert_allclose(vs, vs_state, rtol=1e-7, atol=1e-12)
    eps_v = 1e-3  # regularised law: mu_R = mu (2 - v/eps) v/eps below eps
    mu_r = np.where(vs < eps_v, mu * (2 - vs / eps_v) * vs / eps_v, mu)
    np.testing.assert_allclose(Pf, mu_r * np.abs(Fn) * vs, rtol=1e-10, atol=1e-9)
    Pin = res["drive.power"].values[-1]
    Pout = -40.0 * wB[-1]
    assert Pin - Pout == pytest.approx(Pf[-1], rel=1e-3)
    D = res["g.dissipated_energy"].values
    assert D[-1] == pytest.approx(trapezoid(res["g.dissipated_power"].values, res.time),
                                  rel=1e-4)
    assert np.abs(res["energy.balance_error"].values).max() < 1e-5 * res["energy.work_in"][-1]
    u = 2.0
    HV = (math.pi * (u + 1) / (20 * u * math.cos(geo.beta_b))
          * (1 - geo.eps_alpha + geo.eps_1**2 + geo.eps_2**2))
    assert Pf[-1] == pytest.approx(mu * HV * Pin, rel=2 * mu)


def _worm(mu: float, gamma: float = 10 * DEG, za: int = 2, zb: int = 40, mn: float = 3e-3,
          load: float = 20.0, shaft_error: float = 0.0):
    """Worm (A, lead angle gamma) driving a worm wheel (B) at 90 deg (+ ``shaft_error``),
    wheel loaded."""
    bA, bB = math.pi / 2 - gamma, gamma
    rA = za * mn / (2 * math.cos(bA))
    rB = zb * mn / (2 * math.cos(bB))
    a = rA + rB
    c, s = math.cos(-(bA + bB) + shaft_error), math.sin(-(bA + bB) + shaft_error)
    FB = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])  # B's axis: A's turned about x
    spec = dd.Spec()
    spec.add_rigid_body("worm", 0.5, (1e-4, 1e-4, 1e-4))
    spec.add_rigid_body("wheel", 2.0, (5e-3, 5e-3, 5e-3), position=(a, 0, 0))
    spec.add_marker("g1", "ground", axis=Z)
    spec.add_marker("m1", "worm", axis=Z)
    spec.add_marker("g2", "ground", position=(a, 0, 0), rotation=FB)
    spec.add_marker("m2", "wheel", rotation=FB)
    spec.add(dd.Hinge("h1", "g1", "m1"))
    spec.add(dd.Hinge("h2", "g2", "m2"))
    spec.add(dd.GearPair("w", "m1", "m2", za, zb, mn, 0.02, helix_angle=bA, helix_angle_b=bB,
                         kind="crossed", stiffness=1e8, damping=500.0, friction=mu,
                         friction_velocity=1e-3))
    spec.add(dd.JointDriver("drive", "h1", dd.SmoothStep(0, 0.02, 0, 100.0), quantity="speed"))
    spec.add(dd.Torque("load", "m2", vector=load * FB[:, 2]))  # the wheel turns negatively
    return spec, FB, rA


@pytest.mark.parametrize("mu", [0.0, 0.05, 0.1])
def test_worm_efficiency(mu):
    """Crossed-axis pair as a worm (2 starts, lead angle 10 deg, 90 deg shafts): ratio
    z_A / z_B, sliding speed v_worm / cos(gamma) and efficiency
    tan(gamma) / tan(gamma + phi'), tan(phi') = mu / cos(alpha_n) (worm driving)."""
    gamma = 10 * DEG
    spec, FB, rA = _worm(mu, gamma)
    m = dd.compile_model(spec)
    res = dd.simulate(m, 0.1, step=dd.FixedStep(2e-5), integrator=dd.GeneralizedAlpha(0.9),
                      output_dt=1e-3)
    assert res.success, res.message
    wB = float(res["wheel.angular_velocity"].values[-1] @ FB[:, 2])
    assert wB / 100.0 == pytest.approx(-2 / 40, rel=1e-6)
    eta = 20.0 * abs(wB) / res["drive.power"].values[-1]
    phi = math.atan(mu / math.cos(20 * DEG))
    assert eta == pytest.approx(math.tan(gamma) / math.tan(gamma + phi), rel=1e-6)
    assert res["w.sliding_velocity"].values[-1] == pytest.approx(100 * rA / math.cos(gamma),
                                                                 rel=1e-6)


# ---------------------------------------------------------------------------------------------
# bevel and planetary sets
# ---------------------------------------------------------------------------------------------


def _bevel(za=20, zb=40, mn=3e-3, beta=0.0, flip_b=False):
    gA = math.atan2(za, zb)  # shaft angle 90 deg: tan(gamma_A) = z_A / z_B
    gB = math.pi / 2 - gA
    Rm = za * mn / (2 * math.cos(beta)) / math.sin(gA)
    ao, bo = np.array(Z), np.array([1.0, 0, 0])
    cA, cB = Rm * math.cos(gA) * ao, Rm * math.cos(gB) * bo
    FA, FB = frame_from_axis(ao), frame_from_axis(-bo if flip_b else bo)
    spec = dd.Spec()
    spec.add_rigid_body("A", 1.0, (1e-3, 1e-3, 1e-3), position=cA)
    spec.add_rigid_body("B", 2.0, (4e-3, 4e-3, 4e-3), position=cB)
    for w, c, F in (("A", cA, FA), ("B", cB, FB)):
        spec.add_marker(f"g{w}", "ground", position=c, rotation=F)
        spec.add_marker(f"m{w}", w, rotation=F)
        spec.add(dd.Hinge(f"h{w}", f"g{w}", f"m{w}"))
    spec.add(dd.GearPair("g", "mA", "mB", za, zb, mn, 0.02, helix_angle=beta, kind="bevel",
                         cone_angle_a=gA, cone_angle_b=gB, stiffness=2e8, damping_ratio=0.1))
    return spec, gA, FB


@pytest.mark.parametrize("flip_b", [False, True])
@pytest.mark.parametrize("T", [50.0, -50.0])
def test_bevel_force_components(T, flip_b):
    """Straight bevel pair (90 deg): pinion A held, torque T on B: F_t r_mB = |T|, on the
    pinion F_r = F_t tan(alpha) cos(gamma_A) towards its axis and the thrust
    F_t tan(alpha) sin(gamma_A) away from the apex (reported on B: the opposites)."""
    spec, gA, FB = _bevel(flip_b=flip_b)
    spec.add(dd.JointDriver("hold", "hA", 0.0, quantity="angle"))
    spec.add(dd.Torque("T", "mB", vector=T * FB[:, 2]))
    m = dd.compile_model(spec)
    o = dd.element_outputs(m, dd.solve_static(m))["g"]
    Ft = o["tangential_force"]
    ta = math.tan(20 * DEG)
    assert abs(Ft) * 40 * 3e-3 / 2 == pytest.approx(abs(T), rel=1e-10)
    assert o["radial_force"] == pytest.approx(abs(Ft) * ta * math.cos(gA), rel=1e-10)
    assert o["axial_force"] == pytest.approx(-abs(Ft) * ta * math.sin(gA), rel=1e-10)
    assert o["torque_b"] == pytest.approx(-T, rel=1e-10)


def test_bevel_ratio():
    """Pinion driven for 3 revolutions: the wheel turns by -z_A/z_B of it (90 deg pair,
    both axes pointing away from the apex)."""
    spec, _gA, _FB = _bevel(beta=25 * DEG)
    spec.add(dd.JointDriver("drive", "hA", dd.SmoothStep(0, 0.1, 0, 20.0), quantity="speed"))
    m = dd.compile_model(spec)
    res = dd.simulate(m, 1.0, step=dd.FixedStep(1e-4), integrator=dd.GeneralizedAlpha(0.9),
                      output_dt=1e-2)
    info = mesh_info(m, "g")
    hA, hB = res["hA.angle"].values, res["hB.angle"].values
    assert hB[-1] / hA[-1] == pytest.approx(-0.5, rel=1e-6)
    resid = info["coef_a"] * hA + info["coef_b"] * hB - res["g.deflection"].values
    assert np.abs(resid).max() < 1e-14


ZS, ZP, ZR, MN = 24, 18, 60, 2e-3


def planetary(beta: float = 15 * DEG, n_planets: int = 3) -> dd.Spec:
    """Sun, ring and carrier on hinges to the ground (global z); planets on hinges on the
    carrier; helical: sun right hand, planets and ring left hand."""
    rs, rp = ZS * MN / (2 * math.cos(beta)), ZP * MN / (2 * math.cos(beta))
    spec = dd.Spec()
    spec.add_rigid_body("sun", 1.0, (1e-3, 1e-3, 1.5e-3))
    spec.add_rigid_body("ring", 3.0, (2e-2, 2e-2, 3e-2))
    spec.add_rigid_body("carrier", 2.0, (5e-3, 5e-3, 8e-3))
    for name in ("sun", "ring", "carrier"):
        spec.add_marker(f"g_{name}", "ground", axis=Z)
        spec.add_marker(f"m_{name}", name, axis=Z)
        spec.add(dd.Hinge(f"h_{name}", f"g_{name}", f"m_{name}"))
    for k in range(n_planets):
        ang = 2 * math.pi * k / n_planets
        pos = (rs + rp) * np.array([math.cos(ang), math.sin(ang), 0.0])
        spec.add_rigid_body(f"planet{k}", 0.3, (1e-4, 1e-4, 1.5e-4), position=pos)
        spec.add_marker(f"c{k}", "carrier", position=pos, axis=Z)
        spec.add_marker(f"p{k}", f"planet{k}", axis=Z)
        spec.add(dd.Hinge(f"hp{k}", f"c{k}", f"p{k}"))
        spec.add(dd.GearPair(f"sp{k}", "m_sun", f"p{k}", ZS, ZP, MN, 0.015, helix_angle=beta,
                             damping_ratio=0.05))
        spec.add(dd.GearPair(f"pr{k}", f"p{k}", "m_ring", ZP, ZR, MN, 0.015, helix_angle=-beta,
                             internal="b", damping_ratio=0.05))
    return spec


def test_planetary_static_torque_split():
    """Carrier and ring held, torque T_s on the sun: the ring carries z_R / z_S T_s, the
    carrier the rest, and the three planets share the load equally (no friction)."""
    spec = planetary()
    spec.add(dd.JointDriver("hold_c", "h_carrier", 0.0, quantity="angle"))
    spec.add(dd.JointDriver("hold_r", "h_ring", 0.0, quantity="angle"))
    spec.add(dd.Torque("Ts", "m_sun", vector=(0, 0, 30.0)))
    m = dd.compile_model(spec)
    o = dd.element_outputs(m, dd.solve_static(m))
    t_sun = sum(o[f"sp{k}"]["torque_a"] for k in range(3))
    t_ring = sum(o[f"pr{k}"]["torque_b"] for k in range(3))
    assert t_sun == pytest.approx(-30.0, rel=1e-10)
    assert abs(t_ring) / 30.0 == pytest.approx(ZR / ZS, rel=1e-10)
    assert o["hold_r"]["torque"] == pytest.approx(-t_ring, rel=1e-10)
    assert o["hold_c"]["torque"] == pytest.approx(-(30.0 + abs(t_ring)), rel=1e-10)
    loads = [o[f"sp{k}"]["normal_force"] for k in range(3)]
    assert np.ptp(loads) < 1e-9 * abs(loads[0])


def test_planetary_willis_equation():
    """Sun and ring driven at w_s and w_r: the carrier turns at
    (z_S w_s + z_R w_r) / (z_S + z_R) and the planets at (w_p - w_c) = -z_S/z_P (w_s - w_c)
    (angles measured against the centre line make this automatic)."""
    spec = planetary()
    ws, wr = 30.0, -5.0
    spec.add(dd.JointDriver("d_s", "h_sun", dd.SmoothStep(0, 0.05, 0, ws), quantity="speed"))
    spec.add(dd.JointDriver("d_r", "h_ring", dd.SmoothStep(0, 0.05, 0, wr), quantity="speed"))
    m = dd.compile_model(spec)
    res = dd.simulate(m, 0.3, step=dd.FixedStep(1e-4), integrator=dd.GeneralizedAlpha(0.9),
                      output_dt=1e-3)
    assert res.success, res.message
    wc = res["carrier.angular_velocity"].values[-1, 2]
    wp = res["planet0.angular_velocity"].values[-1, 2]
    assert wc == pytest.approx((ZS * ws + ZR * wr) / (ZS + ZR), rel=1e-8)
    assert (wp - wc) / (ws - wc) == pytest.approx(-ZS / ZP, rel=1e-8)
    a_s, a_r, a_c = (res[f"h_{n}.angle"].values[-1] for n in ("sun", "ring", "carrier"))
    assert (a_s - a_c) / (a_r - a_c) == pytest.approx(-ZR / ZS, rel=1e-8)


# ---------------------------------------------------------------------------------------------
# model checks
# ---------------------------------------------------------------------------------------------


def _pair(**kw):
    geo = CylindricalPair.build(20, 40, 3e-3, 20 * DEG)
    spec = dd.Spec()
    spec.add_rigid_body("A", 1.0, (1e-3, 1e-3, 1e-3))
    spec.add_rigid_body("B", 1.0, (1e-3, 1e-3, 1e-3), position=(kw.pop("a", geo.aw), 0, 0))
    spec.add_marker("mA", "A", axis=Z)
    spec.add_marker("mB", "B", axis=kw.pop("axis_b", Z))
    args = {"teeth_a": 20, "teeth_b": 40, "module": 3e-3, "face_width": 0.02, **kw}
    spec.add(dd.GearPair("g", "mA", "mB", **args))
    return spec


@pytest.mark.parametrize(("kw", "match"), [
    ({"a": 0.0905}, r"GearPair 'g': centre distance of the markers 0.0905 m does not match"),
    ({"module": 0.0}, r"GearPair 'g'.module: must be > 0 m, got 0.0"),
    ({"module": -1e-3}, r"GearPair 'g'.module: must be > 0"),
    ({"teeth_a": 0}, r"GearPair 'g'.teeth_a: must be a positive whole number of teeth"),
    ({"teeth_b": 12.5}, r"GearPair 'g'.teeth_b: must be a positive whole number"),
    ({"helix_angle": math.pi / 2}, r"GearPair 'g'.helix_angle: \|beta\| must be < 90 deg"),
    ({"helix_angle": 0.3, "helix_angle_b": 0.3, "a": 0.09 / math.cos(0.3)},
     r"GearPair 'g'.helix_angle_b: external parallel helical gears need opposite hands"),
    ({"internal": "b"}, r"GearPair 'g': centre distance of the markers 0.09 m does not match "
                        r"the gear data \(\|r_B - r_A\|"),
    ({"internal": "a"}, r"GearPair 'g'.teeth_a: the ring gear needs more teeth"),
    ({"axis_b": (0.0, 0.1, 1.0)}, r"GearPair 'g': the wheel axes are not parallel"),
    ({"kind": "worm"}, r"GearPair 'g'.kind: must be one of"),
    ({"kind": "crossed", "helix_angle_b": 0.1}, r"GearPair 'g'.stiffness: crossed-axis"),
    ({"kind": "bevel"}, r"GearPair 'g'.cone_angle_a: bevel pairs need a pitch cone angle"),
    ({"backlash": 1e-4, "initial_gap": 2e-4}, r"GearPair 'g'.initial_gap: must not exceed"),
    ({"damping": 1.0, "damping_ratio": 0.1}, r"give either damping or damping_ratio"),
    ({"pressure_angle": 0.0}, r"GearPair 'g'.pressure_angle: must be in \(0, 45 deg\)"),
    ({"friction": -0.1}, r"GearPair 'g'.friction: must be >= 0, got -0.1"),
    ({"stiffness": -1.0}, r"GearPair 'g'.stiffness: must be > 0 N/m"),
])
def test_inconsistent_gear_data_refused(kw, match):
    with pytest.raises(ModelError, match=match):
        dd.compile_model(_pair(**kw))


def test_refusals_of_bevel_and_crossed_geometry():
    """Cone angles that do not fit the tooth numbers or the shaft angle, helix angles that
    do not mesh at the shaft angle of the markers."""
    spec, gA, _FB = _bevel()
    bad = spec.elements[-1]
    spec.elements[-1] = type(bad)(**{**bad.__dict__, "cone_angle_a": gA + 0.05})
    with pytest.raises(ModelError, match="cone angles do not fit the tooth numbers"):
        dd.compile_model(spec)
    spec, _FB, _rA = _worm(0.0, shaft_error=5 * DEG)
    with pytest.raises(ModelError, match="helix angles 80 and 10 deg do not mesh at the shaft "
                                         "angle 85 deg"):
        dd.compile_model(spec)


def test_same_body_and_massless_damping_ratio_refused():
    spec = dd.Spec()
    spec.add_rigid_body("A", 1.0, (1e-3, 1e-3, 1e-3))
    spec.add_marker("m1", "A", axis=Z)
    spec.add_marker("m2", "A", position=(0.09, 0, 0), axis=Z)
    spec.add(dd.GearPair("g", "m1", "m2", 20, 40, 3e-3, 0.02))
    with pytest.raises(ModelError, match="are on the same body"):
        dd.compile_model(spec)
    spec = dd.Spec()
    spec.add_node("n")
    spec.add_rigid_body("B", 1.0, (1e-3, 1e-3, 1e-3), position=(0.09, 0, 0))
    spec.add_marker("m1", "n", axis=Z)
    spec.add_marker("m2", "B", axis=Z)
    spec.add(dd.GearPair("g", "m1", "m2", 20, 40, 3e-3, 0.02, damping_ratio=0.1))
    with pytest.raises(ModelError, match="massless node 'n'"):
        dd.compile_model(spec)


def test_outputs_are_documented():
    """Every output has a unit and a description; the dissipated energy is recorded."""
    spec, _ = two_gears(stiffness=1e8)
    res = dd.simulate(dd.compile_model(spec), 1e-3, step=dd.FixedStep(1e-4))
    names = [v for v in res.dataset.data_vars if v.startswith("g.")]
    assert "g.dissipated_energy" in names and "g.normal_force" in names
    for v in names:
        assert res[v].attrs["units"] and res[v].attrs["description"]


@pytest.mark.parametrize("name", ["gear_pair", "planetary_set"])
def test_validation_cases_pass(name):
    """The gear validation cases of ``drivedyn validate`` (quick variants)."""
    from drivedyn.validation import base

    results = base.CASES[name](quick=True, figure_dir=None)
    assert results
    bad = [f"{r.quantity}: ref {r.reference!r}, sim {r.simulated!r}, error {r.error:.3g} "
           f"(tol {r.tolerance:g})" for r in results if not r.passed]
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("gap, lends", [(0.0, True), (2e-12, False), (5e-9, False)])
def test_only_a_flank_at_contact_lends_its_stiffness(gap, lends):
    """Anticipated contact: a flank exactly at contact with neither flank loaded (a
    zero-backlash pair assembled at t = 0) lends k_m c_A^2 to the iteration matrix, so that a
    factorisation made there has the mesh; a flank open by more than ``TANGENT_BAND`` (1 pm;
    planets floating a few nanometres off the sun at zero torque) enters with its true zero
    stiffness, so the matrix is the derivative of the residual (finite differences)."""
    from drivedyn.elements.gears.kernel import TANGENT_BAND
    from drivedyn.solver.system import System
    from fdcheck import assembled, perturb, residual

    assert TANGENT_BAND < 2e-12
    spec, _ = two_gears(stiffness=1e8, backlash=1e-6, initial_gap=gap)
    m = dd.compile_model(spec)
    sys = System(m)
    st = m.initial_state()
    K = assembled(sys, st, 0.0, 0.0, 1.0)
    info = mesh_info(m, "g")
    rz = 5  # rotation of wheel A about its axis (node A, body frame = global frame)
    assert m.eq_labels[rz] == "node A: rz"
    if lends:
        assert K[rz, rz] == pytest.approx(1e8 * info["coef_a"] ** 2, rel=1e-12)
    else:
        eps = 0.1 * gap / info["coef_a"]  # a turn that keeps the flank open
        fd = (residual(sys, perturb(st, rz, eps, m.nd)) -
              residual(sys, perturb(st, rz, -eps, m.nd))) / (2 * eps)
        assert K[rz, rz] == 0.0 and fd[rz] == 0.0


def test_adaptive_step_stays_below_a_size_that_failed_newton(caplog):
    """Backlash impact with an adaptive step: when Newton fails at h (the flank closes within
    the step), the following accepted steps stay below LIMIT_AFTER_FAILURE h, a cap that
    grows by LIMIT_RELAX per accepted step (the error estimate alone would double h back to
    the size that failed)."""
    import logging
    import re

    from drivedyn.solver.step_control import LIMIT_AFTER_FAILURE, LIMIT_RELAX

    b, w0 = 1e-4, -20.0
    spec, _ = two_gears(stiffness=1e9, backlash=b, damping=30.0)
    spec.add(dd.JointDriver("holdB", "hB", 0.0, quantity="angle"))
    body = spec.bodies["A"]
    spec.bodies["A"] = type(body)(**{**body.__dict__, "angular_velocity": np.array([0, 0, w0])})
    m = dd.compile_model(spec)
    # loose error tolerances: Newton, not the error estimate, limits the step here
    step = dd.AdaptiveStep(h0=1e-3, h_min=1e-9, h_max=1e-3, rtol=10.0, atol=1.0)
    with caplog.at_level(logging.DEBUG, logger="drivedyn"):
        res = dd.simulate(m, 2e-2, step=step, output_dt=1e-2)
    assert res.success
    cap, failures, checked = np.inf, 0, 0
    for rec in caplog.records:
        msg = rec.getMessage()
        h = float(re.search(r"h = (\S+) s", msg).group(1))
        if "rejected" in msg and "Newton" in msg:
            cap = LIMIT_AFTER_FAILURE * h
            failures += 1
        elif "Newton iterations" in msg:
            cap *= LIMIT_RELAX
            if np.isfinite(cap):
                assert h <= cap * (1 + 1e-9)
                checked += 1
    assert failures >= 1 and checked >= 5


def _perturbed_state(model, rng, turn: float):
    """The model's initial state with the nodes moved by ~1e-3 m, turned by ~``turn`` rad and
    given random velocities and accelerations (draws from ``rng``)."""
    from drivedyn.rotations import exp_so3

    st = model.initial_state()
    st.x[: model.nn] += 1e-3 * rng.standard_normal((model.nn, 3))
    for i in range(model.nn):
        st.R[i] = st.R[i] @ exp_so3(turn * rng.standard_normal(3))
    st.v[:] = rng.standard_normal(model.nd)
    st.vd[:] = rng.standard_normal(model.nd)
    return st


@pytest.mark.parametrize("internal", [None, "a", "b"])
def test_parallel_only_kernel_equals_the_general_kernel(internal):
    """A group without bevel or crossed pairs runs ``parallel_gear_kernel`` (two copies of the
    loop instead of three: a shorter first compilation); it must give what ``gear_kernel``
    gives, bit for bit, in every evaluation mode and at a state with the flanks loaded."""
    import dataclasses

    from drivedyn.elements.framework.contract import MODE_ACC, MODE_DYN, MODE_VEL
    from drivedyn.elements.gears.kernel import gear_kernel, parallel_gear_kernel
    from drivedyn.model.compile import compile_model
    from drivedyn.solver.system import System
    from element_cases.gears import parallel_case

    model = compile_model(parallel_case(internal))
    sys = System(model)
    (g,) = [g for g in model.groups if g.family == "gear_pair"]
    assert g.kernel is parallel_gear_kernel
    general = dataclasses.replace(g, kernel=gear_kernel, eout=g.eout.copy(), aux=g.aux.copy())
    st = _perturbed_state(model, np.random.default_rng(7), 0.02)
    st.t = 0.37
    sys.time_functions(st.t)
    for mode, want in ((MODE_DYN, True), (MODE_DYN, False), (MODE_ACC, True),
                       (MODE_VEL, False)):
        out = []
        for grp in (g, general):
            r, rabs, data = np.zeros_like(sys.r), np.zeros_like(sys.rabs), np.zeros_like(sys.data)
            grp.evaluate(st, sys.tfv, st.t, sys.Tn, 1.3, 0.7, 1.0, mode, want, r, rabs, data)
            out.append((r, rabs, data, grp.eout.copy(), grp.aux.copy()))
        assert np.abs(out[0][0]).max() > 0.0
        for a, b in zip(out[0], out[1], strict=True):
            np.testing.assert_array_equal(a, b)


def _centred_pair() -> dd.Spec:
    """Two spur wheels whose markers sit at their nodes' origins (no lever arms: the gear
    chain's layout), on hinges, with backlash and tooth friction."""
    spec = dd.Spec(gravity=(0.0, 0.0, 0.0))
    for i in range(2):
        pos = (0.1 * i, 0.0, 0.0)
        spec.add_rigid_body(f"w{i}", 1.0, (1e-3, 1e-3, 1e-3), position=pos)
        spec.add_marker(f"g{i}", dd.GROUND, position=pos, axis=(0.0, 0.0, 1.0))
        spec.add_marker(f"m{i}", f"w{i}", axis=(0.0, 0.0, 1.0))
        spec.add(dd.Hinge(f"h{i}", f"g{i}", f"m{i}"))
    spec.add(dd.GearPair("mesh", "m0", "m1", 50, 50, 2e-3, 0.02, stiffness=1e8,
                         damping=1e3, backlash=1e-4, friction=0.1, friction_velocity=1e-3))
    return spec


@pytest.mark.parametrize("case", ["external", "internal_a", "internal_b", "ground_a",
                                  "centred"])
def test_residual_only_parallel_pairs_equal_the_matrix_pass(case):
    """A residual-only evaluation of a parallel pair takes its primitives, rates and chain
    from ``gears.parallel_rows`` (scalar arithmetic, only the non-zero entries of the mesh
    Jacobian); a matrix evaluation from ``kinematics.projections`` and the general loops.
    Both must give the same residual, scales and outputs to the last bit, or a run's figures
    would depend on which evaluations assembled the matrix. Lever arms on both sides
    (``parallel_case``) and none (``_centred_pair``), a ground wheel, internal rings,
    friction, backlash and transmission error, at random states with a flank loaded and
    sliding. Fails with a sign or an index changed in ``parallel_rows`` (seen: ``g[4] = m2 *
    w0 - m0 * w2`` as ``m2 * w0 - m1 * w2``; ``Sj[3, 1]`` for ``Sj[3, 0]`` in ``sd[3]``;
    ``pB[1]`` for ``pB[2]`` in ``_axis_a``'s ``g[9]``; ``_axis_b``'s lever term with its
    sign turned) or with the chain's terms summed in another order (seen)."""
    from drivedyn.elements.framework.contract import MODE_DYN
    from drivedyn.model.compile import compile_model
    from drivedyn.solver.system import System
    from element_cases.gears import parallel_case

    spec = {"external": lambda: parallel_case(),
            "internal_a": lambda: parallel_case("a"),
            "internal_b": lambda: parallel_case("b"),
            "ground_a": lambda: parallel_case(ground_a=True),
            "centred": _centred_pair}[case]()
    model = compile_model(spec)
    (g,) = [g for g in model.groups if g.family == "gear_pair"]
    sys_ = System(model)
    rng = np.random.default_rng(5)
    loaded = 0
    for _ in range(6):
        st = _perturbed_state(model, rng, 0.05)
        out = []
        for want in (True, False):
            sys_.evaluate(st, 1.3e6, 0.7e3, 1.0, MODE_DYN, want)
            out.append((sys_.r.copy(), sys_.rabs.copy(), g.aux.copy(), g.eout.copy()))
        for a, b in zip(out[0], out[1], strict=True):
            np.testing.assert_array_equal(a, b)
        loaded += int(g.aux[0, 0] != 0.0 and g.aux[0, 11] > 0.0)
    assert loaded >= 3


@pytest.mark.parametrize("d", [0.0, 2e-8, 1e-6])
def test_flank_onset_law_is_a_c1_potential(d):
    """``_onset(u, d)``: f = W' and s = f' (central differences), continuous at u = d, the
    sharp law k u past the onset shifted by d/2, and exactly the sharp law for d = 0."""
    from drivedyn.elements.gears.kernel import _onset

    scale = d if d > 0 else 1e-6
    for u in np.array([0.1, 0.5, 0.9, 1.5, 7.0]) * scale:
        h = 1e-6 * scale
        Wp, fp, _ = _onset(u + h, d)
        Wm, fm, _ = _onset(u - h, d)
        _W, f, s = _onset(u, d)
        assert f == pytest.approx((Wp - Wm) / (2 * h), rel=1e-7)
        assert s == pytest.approx((fp - fm) / (2 * h), rel=1e-7)
        if u > d:
            assert f == pytest.approx(u - d / 2, rel=1e-14) and s == 1.0
    if d > 0:
        below, above = _onset(d * (1 - 1e-12), d), _onset(d * (1 + 1e-12), d)
        np.testing.assert_allclose(below, above, rtol=1e-9)
        assert _onset(0.5 * d, d)[2] == 0.5  # the stiffness rises linearly over the onset
    else:
        assert _onset(3e-6, 0.0) == (0.5 * 3e-6 * 3e-6, 3e-6, 1.0)


def test_flank_onset_is_refused_negative():
    with pytest.raises(ModelError, match="flank_onset"):
        dd.compile_model(two_gears(flank_onset=-1e-9)[0])
