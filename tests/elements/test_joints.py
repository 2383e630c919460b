"""Joints whose motion has a closed form not covered by the validation cases."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import ellipk

import drivedyn as dd
from drivedyn.rotations import frame_from_axis
from drivedyn.solver.simulation import Simulation
from small_models import rot_y

G = 9.81


def test_fixed_joint_makes_one_rigid_body():
    """A rod with a second body welded on by a Fixed joint swings as one compound pendulum:
    period 4 sqrt(I_o/(m g d)) K(k^2) with the combined mass properties."""
    th0 = 1.5
    Rb = rot_y(np.pi / 2 - th0)  # body x axis from the pivot, theta0 from hanging
    spec = dd.Spec(gravity=(0.0, 0.0, -G))
    J1 = np.diag([1e-3, 0.08, 0.08])
    J2 = np.diag([0.01, 0.02, 0.03])
    spec.add_rigid_body("rod", 1.0, J1, com=(0.5, 0.0, 0.0), rotation=Rb)
    spec.add_rigid_body("bob", 3.0, J2, com=(0.0, 0.0, 0.0), rotation=Rb,
                        position=Rb @ np.array([0.9, 0.0, 0.0]))
    spec.add_marker("pivot", "ground", axis=(0, 1, 0))
    spec.add_marker("rod_pivot", "rod", rotation=Rb.T @ frame_from_axis([0, 1, 0]))
    spec.add_marker("weld_rod", "rod", position=(0.9, 0.0, 0.0))
    spec.add_marker("weld_bob", "bob")
    spec.add(dd.Hinge("h", "pivot", "rod_pivot"))
    spec.add(dd.Fixed("weld", "weld_rod", "weld_bob"))
    res = dd.simulate(dd.compile_model(spec), 4.0, step=dd.FixedStep(5e-4),
                      integrator=dd.GeneralizedAlpha(0.9), output_dt=5e-4)
    assert res.success, res.message
    m = 4.0
    d = (1.0 * 0.5 + 3.0 * 0.9) / m
    I_o = J1[1, 1] + 1.0 * 0.5**2 + J2[1, 1] + 3.0 * 0.9**2
    T = 4.0 * np.sqrt(I_o / (m * G * d)) * ellipk(np.sin(th0 / 2) ** 2)
    x = res["rod.position"].values[:, 0]
    t = res.time
    i = np.where((x[:-1] > 0) & (x[1:] <= 0))[0]
    tc = t[i] + (t[i + 1] - t[i]) * x[i] / (x[i] - x[i + 1])
    # (omega0 h)^2 ~ 1e-5 phase accuracy per period at this step
    assert np.diff(tc)[0] == pytest.approx(T, rel=5e-5)
    # the weld holds: relative rotation of the bob stays zero
    Rr = res["rod.rotation"].values
    Rbob = res["bob.rotation"].values
    rel = np.einsum("tji,tjk->tik", Rr, Rbob)
    np.testing.assert_allclose(rel, np.broadcast_to(np.eye(3), rel.shape), atol=1e-9)


def test_cylindrical_joint_free_fall_while_spinning():
    """A spinning sleeve on a vertical cylindrical joint falls freely, z = -g t^2/2, and keeps
    its spin (no torque about the axis)."""
    spec = dd.Spec(gravity=(0.0, 0.0, -G))
    spec.add_rigid_body("sleeve", 2.0, [0.02, 0.02, 0.03], angular_velocity=(0.0, 0.0, 7.0))
    spec.add_marker("post", "ground", axis=(0, 0, 1))
    spec.add_marker("bore", "sleeve", axis=(0, 0, 1))
    spec.add(dd.Cylindrical("c", "post", "bore"))
    res = dd.simulate(dd.compile_model(spec), 1.0, step=dd.FixedStep(1e-3), output_dt=0.1)
    z = res["sleeve.position"].values[:, 2]
    # constant acceleration: generalized-alpha is exact for it (up to Newton tolerance)
    np.testing.assert_allclose(z, -0.5 * G * res.time**2, atol=1e-9)
    np.testing.assert_allclose(res["sleeve.angular_velocity"].values[:, 2], 7.0, rtol=1e-9)
    np.testing.assert_allclose(res["c.angle"].values, 7.0 * res.time, atol=1e-8)


def test_prismatic_joint_blocks_rotation_and_reacts_torque():
    """A slider on a horizontal prismatic joint loaded by a torque about the rail: it does
    not turn, and the joint reacts the torque exactly."""
    spec = dd.Spec()
    spec.add_rigid_body("slider", 1.0, [0.01, 0.01, 0.01])
    spec.add_marker("rail", "ground", axis=(1, 0, 0))
    spec.add_marker("shoe", "slider", axis=(1, 0, 0))
    spec.add(dd.Prismatic("p", "rail", "shoe"))
    spec.add(dd.Torque("T", "shoe", vector=(3.0, 0.0, 0.0)))
    spec.add(dd.Force("F", "shoe", vector=(2.0, 0.0, 0.0)))
    res = dd.simulate(dd.compile_model(spec), 0.5, step=dd.FixedStep(1e-3), output_dt=0.1)
    np.testing.assert_allclose(res["slider.position"].values[:, 0], 0.5 * 2.0 * res.time**2,
                               atol=1e-9)
    np.testing.assert_allclose(res["slider.angular_velocity"].values, 0.0, atol=1e-9)
    np.testing.assert_allclose(res["p.torque_x"].values[1:], -3.0, rtol=1e-8)


def _nut_on_screw(mu: float, t_end: float):
    """A nut (mass 2 kg, 0.004 kg m^2 about the axis) released at rest on a vertical screw
    (lead 2 pi c, c = 25 mm/rad, flank radius r = 50 mm) with flank friction mu, under
    gravity."""
    c, r, m, J = 0.025, 0.05, 2.0, 0.004
    spec = dd.Spec(gravity=(0.0, 0.0, -G))
    spec.add_rigid_body("nut", m, [0.003, 0.003, J])
    spec.add_marker("thread", "ground", axis=(0, 0, 1))
    spec.add_marker("bore", "nut", axis=(0, 0, 1))
    spec.add(dd.Screw("s", "thread", "bore", pitch=2 * np.pi * c, friction=mu, radius=r,
                      stick_stiffness=1e6))
    res = dd.simulate(dd.compile_model(spec), t_end, step=dd.FixedStep(1e-3),
                      integrator=dd.GeneralizedAlpha(0.8), output_dt=1e-3)
    assert res.success, res.message
    return res, c, r, m, J


def test_screw_friction_slip_follows_coulomb():
    """A nut whose flanks slip (mu 0.2 below c/r = 0.5) runs down the screw at the constant
    acceleration of Coulomb's law with the flanks' normal force N = sigma L / r:
    ``theta'' = m g (kappa/beta - c) / (J + m c^2 - kappa m c / beta)``, ``kappa = mu L^2/r``,
    ``beta = 1 + mu c/r``, and the friction force ``mu N`` along the helix. Fails if the
    normal force is taken as the axial force sigma (without L / r: the slide 3 % off) or
    the friction along the axis instead of the helix."""
    mu = 0.2
    res, c, r, m, J = _nut_on_screw(mu, 0.3)
    L = np.hypot(r, c)
    kappa, beta = mu * L * L / r, 1 + mu * c / r
    acc = m * G * (kappa / beta - c) / (J + m * c * c - kappa * m * c / beta)
    sigma = m * (c * acc + G) / beta
    t = res.time
    vz = res["nut.velocity"].values[:, 2]
    i, j = np.searchsorted(t, (0.1, 0.3))
    assert (vz[j] - vz[i]) / (t[j] - t[i]) == pytest.approx(c * acc, rel=1e-6)
    f = res["s.friction_force"].values
    assert f[-1] == pytest.approx(-mu * sigma * L / r, rel=1e-6)
    # the power dissipated is the friction force times the slide rate L theta'
    p = res["s.friction_power"].values[-1]
    assert p == pytest.approx(abs(f[-1] * L * vz[-1] / c), rel=1e-6)


def test_screw_friction_self_locking_holds():
    """With mu 0.6 above c/r = 0.5 the screw is self-locking: released at rest, the nut
    slips a few micrometres while the flanks' stick spring takes the sudden load (its
    dynamic overshoot exceeds mu N), then holds: the friction carries the helix component
    of its weight, ``F = -m g c / L`` on average (below the limit mu m g r / L), and the
    nut stops for good. A regularised (velocity-driven) friction lets it creep down; a
    stick force that is not kept across steps lets it slide."""
    res, c, r, m, _ = _nut_on_screw(0.6, 1.0)
    L = np.hypot(r, c)
    t = res.time
    late = t > 0.5
    f = res["s.friction_force"].values[late]
    assert f.mean() == pytest.approx(-m * G * c / L, rel=1e-3)
    assert np.abs(f).max() < 0.6 * m * G * r / L
    z = res["nut.position"].values[:, 2]
    assert np.abs(z).max() < 2e-5  # the slip of the first milliseconds
    # no creep: the mean position of the last quarter equals that of the one before, to
    # 2 % of the stick spring's oscillation (0.8 um, period 8 ms, windows not whole periods)
    a, b = z[(t > 0.5) & (t <= 0.75)], z[t > 0.75]
    assert abs(a.mean() - b.mean()) < 2e-8


@pytest.mark.parametrize("n_c", [0.0, 1.0])
def test_screw_stick_range_with_a_vanishing_load(n_c):
    """The return mapping's stick range along the helix: the largest slide ``|s - z|`` the
    flanks hold is ``mu N / k`` with the stick stiffness ``k = k_t N / (N + n_c)``, i.e.
    ``mu (N + n_c) / k_t``: with the onset it keeps about ``mu n_c / k_t`` (1e-10 m here) as
    the normal force vanishes, without it shrinks with N (1e-13 m). Just inside the range
    the flanks stick with ``F = k (s - z)``; just outside they slip with ``F = mu N`` and the
    slip leaves the spring at the limit (``k (s - z_new) = F``). Fails with the stiffness
    taken constant when ``n_c > 0``, or the slip's new ``z`` computed with ``k_t``."""
    from drivedyn.elements.screw_friction import coulomb_return

    mu, r, c, k_t, sigma = 0.1, 0.05, 0.025, 1e9, 1e-3
    n = sigma * np.hypot(r, c) / r
    k = k_t * n / (n + n_c) if n_c > 0 else k_t
    width = mu * (n + n_c) / k_t
    f, dfs, _, z, kk = coulomb_return(mu, r, c, k_t, n_c, 0.99 * width, 0.0, sigma)
    assert kk == pytest.approx(k, rel=1e-12)
    assert (f, dfs, z) == (pytest.approx(0.99 * k * width, rel=1e-12), kk, 0.0)
    f, dfs, _, z, _ = coulomb_return(mu, r, c, k_t, n_c, 1.01 * width, 0.0, sigma)
    assert (f, dfs) == (pytest.approx(mu * n, rel=1e-12), 0.0)
    assert k * (1.01 * width - z) == pytest.approx(f, rel=1e-9)
    assert width == pytest.approx(1.0e-10 if n_c else 1.118e-13, rel=2e-3)


def test_scalar_angles_are_prim_angles_to_the_last_bit():
    """A residual-only evaluation takes a hinge's angle from ``joint_rows.angle_only``, and
    a driver's, a screw's or a torsional spring's angle with its gradient from
    ``joint_rows.angle_gradient``; a matrix evaluation from ``prim_angle``. They must agree
    bit for bit, or a reported and accumulated angle would depend on whether the
    evaluation assembled the matrix. Random frames, angles in all four quadrants. Fails
    with ``a1`` and ``a2`` swapped, a dot product summed in another order, or a sign
    changed in a gradient entry (seen)."""
    from drivedyn.elements.framework.primitives import prim_angle
    from drivedyn.elements.joint_rows import angle_gradient, angle_only

    rng = np.random.default_rng(5)
    g, H, g2 = np.zeros(12), np.zeros((12, 12)), np.zeros(12)
    w = [np.zeros(12), np.zeros((12, 12)), np.zeros(12), np.zeros((12, 12))]
    ws, wv = np.zeros((8, 3, 3)), np.zeros((6, 3))
    seen = set()
    for _ in range(200):
        RA, RB, Rm = (frame_from_axis(rng.standard_normal(3)) @ rot_y(rng.uniform(-3, 3))
                      for _ in range(3))
        ref = prim_angle(RA, RB, Rm[:, 0], Rm[:, 1], Rm[:, 2], g, H, False, *w, ws, wv)
        assert angle_only(RA, RB, Rm[:, 0], Rm[:, 1], Rm[:, 2]) == ref
        assert angle_gradient(RA, RB, Rm[:, 0], Rm[:, 1], Rm[:, 2], g2) == ref
        assert np.all(g2 == g)
        assert np.all(np.signbit(g2) == np.signbit(g))
        seen.add(int(np.floor(ref / (np.pi / 2))))
    assert seen == {-2, -1, 0, 1}


def test_geometric_rows_equal_the_primitives_bit_for_bit():
    """A residual-only evaluation takes a joint's axial and dot rows from
    ``joint_rows.geometric_rows`` and the angles of drivers and torsional springs from
    ``joint_rows.angle_gradient`` (scalar arithmetic); a matrix evaluation from the
    primitives. Both must give the same residual and term sums to the last bit, or a run's
    figures would depend on which evaluations assembled the matrix. Every joint type of the
    tangent cases (one group of all types side by side included), the drivers and the
    torsional spring, at random states. Fails
    with a sign or an index changed in ``geometric_rows`` (seen: ``e1 * u2 - e2 * u1`` as
    ``e1 * u2 - e1 * u1``; ``pB`` for ``f`` in a dot row), or with the rows added in
    another order."""
    from drivedyn.elements.framework.contract import MODE_DYN
    from drivedyn.model.compile import compile_model
    from drivedyn.rotations import exp_so3
    from drivedyn.solver.system import System
    from element_cases import TANGENT_CASES

    rng = np.random.default_rng(11)
    families = ("joint", "joint_driver", "torsional_spring_damper")
    for case in (c for f in families for c in TANGENT_CASES[f]):
        model = compile_model(case())
        for _ in range(5):
            st = model.initial_state()
            st.x[:model.nn] += 1e-2 * rng.standard_normal((model.nn, 3))
            for i in range(model.nn):
                st.R[i] = st.R[i] @ exp_so3(rng.standard_normal(3))
            st.lam[:] = 5.0 * rng.standard_normal(model.nm) / model.meta["kscale"][model.nd:]
            sys_ = System(model)
            sys_.evaluate(st, 1e6, 1e3, 1.0, MODE_DYN, True)
            r_full, rabs_full = sys_.r.copy(), sys_.rabs.copy()
            sys_.evaluate(st, 1e6, 1e3, 1.0, MODE_DYN, False)
            assert np.all(sys_.r == r_full), case
            assert np.all(sys_.rabs == rabs_full), case
            assert np.count_nonzero(r_full[model.nd:]) == model.nm
            assert np.count_nonzero(r_full[:model.nd]) > 0


def _unbalanced_rotor(speed: float = 300.0) -> dd.Spec:
    """A rotor (2 kg) on a hinge about x turning at ``speed`` [rad/s], gravity -z, with a
    0.1 kg unbalance welded on (Fixed) 50 mm off the axis; marker A of the weld on the rotor,
    its axes turned off the rotor's."""
    spec = dd.Spec(gravity=(0.0, 0.0, -G))
    w = (speed, 0.0, 0.0)
    r = np.array([0.0, 0.0, 0.05])
    spec.add_rigid_body("rotor", 2.0, (4e-3, 2e-3, 2e-3), angular_velocity=w)
    spec.add_rigid_body("mass", 0.1, (1e-6, 1e-6, 1e-6), position=r,
                        velocity=np.cross(w, r), angular_velocity=w)
    spec.add_marker("bearing", dd.GROUND, axis=(1, 0, 0))
    spec.add_marker("journal", "rotor", axis=(1, 0, 0))
    spec.add_marker("seat", "rotor", position=r, rotation=rot_y(0.4))
    spec.add_marker("on_mass", "mass", rotation=rot_y(0.4))
    spec.add(dd.Hinge("bearing", "bearing", "journal"))
    spec.add(dd.Fixed("weld", "seat", "on_mass"))
    spec.add(dd.JointDriver("motor", "bearing", speed, quantity="speed"))
    return spec


def test_the_position_rows_of_a_weld_are_global_components(monkeypatch):
    """A Fixed joint writes its three position rows as global components (``ROW_GLOBAL``):
    here a weld whose marker A turns with a rotor at 300 rad/s. Its first three multipliers
    are then the reaction on B, global, ``force = -k lam`` (fails with the rows ``d . a_i``
    of marker A: the multipliers are the components in A's turning axes). The same run with
    the rows ``d . a_i`` (``Fixed.rows`` replaced) moves the same way within Newton's
    tolerance, and refreshes its iteration matrix far more often, as the rows turn 0.03 rad
    a step with the rotor (measured 56 -> 189 factorisations, 944 -> 2039 Newton
    iterations over 0.05 s; fails if the global rows turn with marker A)."""
    from drivedyn.elements import joints

    def run():
        model = dd.compile_model(_unbalanced_rotor())
        sim = Simulation(model, step=dd.FixedStep(1e-4))
        assert sim.advance(0.05, output_times=np.arange(1, 51) * 1e-3)
        return model, sim

    model, sim = run()
    res = sim.results()
    g, e = model.group("weld")
    k = g.params[9][e, :3]
    lam = sim.state.lam[g.dofs[e, 12:15] - model.nd]
    force = np.stack([res[f"weld.force_{c}"].values for c in "xyz"], axis=1)
    # centrifugal 0.1 kg x 0.05 m x 300^2 = 450 N turning with the rotor, and the weight
    assert np.abs(force).max() > 400.0
    np.testing.assert_allclose(force[-1], -k * lam, rtol=1e-6, atol=1e-9)
    a = joints.ROW_AXIAL
    monkeypatch.setattr(joints.Fixed, "rows", tuple((a, r[1], 0) if r[0] == joints.ROW_GLOBAL
                                                    else r for r in joints.Fixed.rows))
    _, sim_a = run()
    res_a = sim_a.results()
    assert res_a.stats.factorizations > 3 * res.stats.factorizations
    np.testing.assert_allclose(res_a["mass.position"].values, res["mass.position"].values,
                               atol=1e-9)
    np.testing.assert_allclose(np.stack([res_a[f"weld.force_{c}"].values for c in "xyz"], 1),
                               force, atol=1e-4 * 450.0)
