"""Point/sphere-on-plane contact: geometry, outputs, statics, two-body impacts, and the
tangents in the branches the registry test (tests/elements/test_tangents.py) does not reach:
the first step of a contact, a clipped (would-pull) force, no contact, zero sliding speed,
contacts without friction.

``fdcheck.check_tangents`` repeats the registry test's finite differences (through the
Lie-group update for rotations) on a given state, so that the internal state ``es`` can be set.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import drivedyn as dd
from drivedyn.elements.contact.impact_laws import NSTATE, ST_ACC, ST_FLAG, ST_PEN, ST_RATE
from drivedyn.library import bouncing_ball as bb
from drivedyn.model.spec import ModelError
from drivedyn.solver.system import System
from element_cases import contact as cc
from fdcheck import check_tangents, random_state


def _group(model, name):
    return model.group(name)


# --- tangents in the other branches -------------------------------------------------------


@pytest.mark.parametrize("case", [cc.plane_case, cc.sphere_case, cc.washer_case,
                                  cc.journal_case, cc.squeeze_metal_case])
def test_first_step_of_a_contact(case) -> None:
    """State says 'not in contact' (previous penetration < 0): v_s comes from the previous
    state and is a constant of the step."""
    model = dd.compile_model(case())
    st = random_state(model)
    g = model.groups[-1]
    o = g.eoff[0]
    st.es[o + ST_FLAG] = 0.0
    st.es[o + ST_PEN] = -1e-3
    st.es[o + ST_RATE] = 7.0
    st.es[o + ST_ACC] = 100.0
    check_tangents(model, st)
    sys = System(model)
    sys.evaluate(st)
    vs = g.aux[0, g.naux - NSTATE + 1]
    assert vs == pytest.approx(math.sqrt(49.0 + 2 * 100.0 * 1e-3))


def test_clipped_force_and_no_contact_branches() -> None:
    model = dd.compile_model(cc.plane_case())
    st = random_state(model)
    g = model.groups[-1]
    # a fast separation makes 1 + chi v/v_s < 0: the force is clipped to zero
    st.v *= -1.0  # separating (the random state approaches at 1.85 m/s)
    st.es[g.eoff[0] + 1] = 0.05
    check_tangents(model, st)
    System(model).evaluate(st)
    assert g.aux[0, 0] == 0.0 and g.aux[0, 1] < 0  # penetrating, no force
    # no contact at all
    st = random_state(model)
    st.x[model.node_index["B"]] += 0.3 * cc._RM[:, 2]  # marker A's normal, global
    A = _group(model, "c")[0]
    check_tangents(model, st)
    System(model).evaluate(st)
    assert A.aux[0, 0] == 0.0 and A.eout[0, 3] == 0.0


def test_zero_sliding_speed_and_frictionless() -> None:
    spec = dd.Spec()
    a, b = cc.two_bodies(spec, np.array([0.0, 0.0, -0.02]), ground_a=True)
    # at s = 0 the friction force F phi(|s|) s has the C1-only term phi'(0) |s| s: central
    # differences lose an order there (error ~ F mu/eps_v^2 EPS), hence a wide eps_v
    spec.add(dd.PlaneContact("c", a, b, law=dd.NormalLaw(1e4, 1.5, min_impact_speed=5.0),
                             friction=dd.FrictionLaw(0.3, eps_v=10.0)))
    model = dd.compile_model(spec)
    st = model.initial_state()  # at rest: sliding speed exactly 0
    st.vd[:] = 1.0
    check_tangents(model, st)
    spec.elements[0] = dd.PlaneContact("c", a, b, law=dd.NormalLaw(1e4, 1.5))
    model = dd.compile_model(spec)
    check_tangents(model, random_state(model))


# --- geometry and physics -------------------------------------------------------------------


def _ball(radius: float, v, w, gap: float = -1e-4):
    spec = dd.Spec(gravity=(0, 0, -9.81))
    spec.add_marker("floor", dd.GROUND)
    spec.add_rigid_body("ball", 1.0, (4e-4, 4e-4, 4e-4), position=(0, 0, radius + gap),
                        velocity=v, angular_velocity=w)
    spec.add_marker("centre", "ball")
    spec.add(dd.PlaneContact("c", "floor", "centre", law=dd.NormalLaw(1e7, 1.5),
                             friction=dd.FrictionLaw(0.4, eps_v=1e-3), radius=radius))
    return dd.compile_model(spec)


def test_rolling_sphere_does_not_slide() -> None:
    rho = 0.05
    model = _ball(rho, (1.0, 0.5, 0.0), (-0.5 / rho, 1.0 / rho, 3.0))  # rolls along (1, .5)
    out = dd.element_outputs(model, model.initial_state())["c"]
    assert out["sliding_speed"] == pytest.approx(0.0, abs=1e-14)
    assert out["friction_force"] == pytest.approx(0.0, abs=1e-12)
    # spinning about the normal does not slide at a point contact either; sliding does
    model = _ball(rho, (1.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    out = dd.element_outputs(model, model.initial_state())["c"]
    assert out["sliding_speed"] == pytest.approx(1.0)
    assert out["friction_force"] == pytest.approx(0.4 * out["normal_force"])
    assert out["gap"] == pytest.approx(-1e-4)


def test_sliding_sphere_rolls_up_to_5_7_of_its_speed() -> None:
    """A sphere launched sliding without spin on a floor: friction brings it to rolling at
    5/7 of the initial speed (solid sphere, J = 2/5 m r^2), whatever mu."""
    rho, m, v0 = 0.05, 1.0, 2.0
    J = 0.4 * m * rho**2
    spec = dd.Spec(gravity=(0, 0, -9.81))
    spec.add_marker("floor", dd.GROUND)
    pen = (m * 9.81 / 1e7) ** (1 / 1.5)
    spec.add_rigid_body("ball", m, (J, J, J), position=(0, 0, rho - pen), velocity=(v0, 0, 0))
    spec.add_marker("centre", "ball")
    spec.add(dd.PlaneContact("c", "floor", "centre",
                             law=dd.NormalLaw(1e7, 1.5, restitution=0.3),
                             friction=dd.FrictionLaw(0.3, eps_v=1e-4), radius=rho))
    res = dd.simulate(dd.compile_model(spec), 0.8, integrator=dd.GeneralizedAlpha(0.8),
                      step=dd.FixedStep(1e-4), output_dt=1e-2)
    assert res.success, res.message
    v = res["ball.velocity"].values[-1, 0]
    w = res["ball.angular_velocity"].values[-1, 1]
    assert v == pytest.approx(5 / 7 * v0, rel=1e-4)
    assert w * rho == pytest.approx(v, rel=1e-4)
    assert res["c.sliding_speed"].values[-1] < 1e-4
    lost = 0.5 * m * v0**2 - (0.5 * m * v**2 + 0.5 * J * w**2)
    assert res["c.dissipated_energy"].values[-1] == pytest.approx(lost, rel=2e-3)


def test_static_penetration() -> None:
    m, g, K, n = 2.0, 9.81, 1e8, 1.5
    # (slightly penetrated: the Hertz stiffness n K delta^(n-1) vanishes at delta = 0)
    spec = bb.bouncing_ball_spec(h0=-1e-6, mass=m, gravity=g, k=K, n=n)
    # statics needs the free motions held: a vertical prismatic guide
    spec.add_marker("guide_a", dd.GROUND)
    spec.add_marker("guide_b", "ball")
    spec.add(dd.Prismatic("guide", "guide_a", "guide_b"))
    model = dd.compile_model(spec)
    out = dd.element_outputs(model, dd.solve_static(model))["floor_contact"]
    assert -out["gap"] == pytest.approx((m * g / K) ** (1 / n), rel=1e-9)
    assert out["normal_force"] == pytest.approx(m * g, rel=1e-9)


def test_two_free_bodies_collide() -> None:
    """A ball hits a free slab carrying the plane (no gravity): momentum is conserved and the
    relative restitution is the law's (the relation holds with the reduced mass)."""
    m1, m2, v0 = 0.3, 1.7, 3.0
    spec = dd.Spec()
    spec.add_rigid_body("slab", m2, (0.1, 0.1, 0.2), position=(0, 0, 0),
                        velocity=(0, 0, 0.0))
    spec.add_marker("top", "slab", position=(0, 0, 0.01))
    spec.add_rigid_body("ball", m1, (1e-4, 1e-4, 1e-4), position=(0.02, 0, 0.01 + 1e-5),
                        velocity=(0, 0, -v0))
    spec.add_marker("bottom", "ball")
    law = dd.NormalLaw(1e9, 1.5, law="exact", restitution=0.6)
    spec.add(dd.PlaneContact("hit", "top", "bottom", law=law))
    res = dd.simulate(dd.compile_model(spec), 1e-3, integrator=dd.GeneralizedAlpha(1.0),
                      step=bb.default_step(), output_times=[0.0, 1e-3])
    assert res.success
    vb = res["ball.velocity"].values[-1]
    vs = res["slab.velocity"].values[-1]
    p = m1 * vb + m2 * vs
    np.testing.assert_allclose(p, [0, 0, -m1 * v0], atol=1e-12)
    # relative normal velocity at the contact point (the off-centre hit turns the slab)
    w = res["slab.angular_velocity"].values[-1]
    r = res["ball.position"].values[-1] - res["slab.position"].values[-1]
    v_point = vs + np.cross(w, r)
    assert abs(w[1]) > 0.1
    assert (vb[2] - v_point[2]) / v0 == pytest.approx(0.6, abs=1e-5)
    # the offset contact point turns the slab: angular momentum about the origin conserved
    Ls = res["slab.angular_momentum"].values[-1]
    x_b = res["ball.position"].values[-1]
    L = Ls + np.cross(x_b, m1 * vb) + np.cross(res["slab.position"].values[-1], m2 * vs)
    np.testing.assert_allclose(L, np.cross([0.02, 0, 0.01 + 1e-5], [0, 0, -m1 * v0]),
                               atol=1e-12)


def test_potential_energy_and_outputs() -> None:
    model = bb.bouncing_ball_model(h0=-2e-4, k=1e10, n=1.5)
    g = model.group("floor_contact")[0]
    System(model).evaluate(model.initial_state())
    assert g.eout[0, 1] == pytest.approx(1e10 * 2e-4**2.5 / 2.5)
    names = [o[1] for o in g.outputs()]
    for n in ("normal_force", "gap", "gap_rate", "sliding_speed", "friction_force",
              "dissipated_power", "impact_speed", "rebound_speed", "impacts", "in_contact"):
        assert n in names
    assert g.dissipative


def test_contact_needs_two_bodies_and_a_law() -> None:
    spec = dd.Spec()
    spec.add_rigid_body("b", 1.0, (1, 1, 1))
    spec.add_marker("p", "b")
    spec.add_marker("q", "b", position=(0, 0, 1))
    spec.add(dd.PlaneContact("c", "p", "q"))
    with pytest.raises(ModelError, match=r"'c'.*two different bodies"):
        dd.compile_model(spec)
    spec = dd.Spec()
    spec.add_rigid_body("b", 1.0, (1, 1, 1))
    spec.add_marker("p", dd.GROUND)
    spec.add_marker("q", "b")
    spec.add(dd.PlaneContact("c", "p", "q", law=1e6))
    with pytest.raises(ModelError, match=r"'c'.*NormalLaw"):
        dd.compile_model(spec)
    spec.elements[0] = dd.PlaneContact("c", "p", "q", radius=-1.0)
    with pytest.raises(ModelError, match=r"'c'.*radius"):
        dd.compile_model(spec)
