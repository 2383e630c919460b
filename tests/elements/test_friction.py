"""Friction laws and a block on an incline (regularised Coulomb, tanh, Stribeck and the
augmented-Lagrangian stick/slip contact).

The block is a rigid body whose centre of mass is the contact point (no tipping moment) on a
plane through the origin tilted by ``theta`` about the global y axis; gravity -z. Along the
slope (marker x axis, downhill) the exact motion while sliding has the constant acceleration
``g (sin theta - mu cos theta)`` (negative: deceleration).

What "sticking" means with a regularised law: ``mu_R(v)`` is continuous through 0, so no
static force exists at v = 0; the block creeps at the speed where ``mu_R(v) = tan theta``,
``v_c = eps_v (1 - sqrt(1 - tan(theta)/mu_s))`` for the seeds' law and
``eps_v atanh(tan(theta)/mu_s)`` for tanh. The tests check the creep speed against these
values (so the displacement is ``v_c t``: about 0.4 mm/s for eps_v = 1 mm/s) and that it stays
below eps_v. The augmented-Lagrangian contact really sticks: the block does not move (1e-9 m).
"""

from __future__ import annotations

import numpy as np
import pytest

import drivedyn as dd
from drivedyn.elements.contact.friction import FrictionLaw, friction_phi, friction_scalar
from drivedyn.model.spec import ModelError
from small_models import rot_y

G = 9.81
MASS = 2.0
K_N = 1e6  # normal penalty stiffness [N/m]


def incline(theta: float, v0: float = 0.0, friction: FrictionLaw | None = None,
            mu_al: float | None = None) -> dd.Model:
    """Block on the slope, released with speed ``v0`` downhill; a PlaneContact with a damped
    penalty law (starting at its static penetration) or, with ``mu_al``, a
    UnilateralContact touching the plane."""
    R = rot_y(theta)
    n, t = R[:, 2], R[:, 0]
    spec = dd.Spec(gravity=(0.0, 0.0, -G))
    spec.add_marker("slope", dd.GROUND, rotation=R)
    pen = 0.0 if mu_al is not None else MASS * G * np.cos(theta) / K_N
    spec.add_rigid_body("block", MASS, (0.01, 0.01, 0.01), position=-pen * n, velocity=v0 * t)
    spec.add_marker("foot", "block")
    if mu_al is not None:
        spec.add(dd.UnilateralContact("contact", "slope", "foot", mu=mu_al))
    else:
        law = dd.NormalLaw(K_N, 1.0, law="penalty", damping=2.0 * np.sqrt(K_N * MASS))
        spec.add(dd.PlaneContact("contact", "slope", "foot", law=law, friction=friction))
    return dd.compile_model(spec)


def _slope_motion(res, theta):
    t_axis = rot_y(theta)[:, 0]
    s = res["block.position"].values @ t_axis
    v = res["block.velocity"].values @ t_axis
    return res.time, s, v


def _run(model, t_end, h=1e-3):
    res = dd.simulate(model, t_end, integrator=dd.GeneralizedAlpha(0.9), step=dd.FixedStep(h),
                      output_dt=h)
    assert res.success, res.message
    return res


# --- the laws ---------------------------------------------------------------------------------


@pytest.mark.parametrize("law", ["coulomb", "tanh"])
@pytest.mark.parametrize("mu_s", [None, 0.6])
def test_coefficient_shape_and_derivatives(law: str, mu_s: float | None) -> None:
    f = FrictionLaw(0.4, eps_v=0.01, law=law, mu_static=mu_s, stribeck_speed=0.05)
    kind, mu, mus, vst, eps = f.params()
    v = np.concatenate([np.linspace(-0.3, 0.3, 601), [1e-9, -1e-9, 0.01, 0.0100001]])
    mu_r = f.coefficient(v)
    assert np.all(np.sign(mu_r) == np.sign(v))  # odd, opposes sliding
    assert np.all(np.abs(mu_r) <= max(0.4, mu_s or 0.0) * (1 + 1e-12))
    assert abs(f.coefficient(1.0)[()] - 0.4) < 1e-6  # kinetic far above eps and v_str
    for s in (-0.2, -0.004, 1e-7, 0.003, 0.02, 0.15):
        val, der = friction_scalar(s, int(kind), mu, mus, vst, eps)
        h = 1e-8
        fd = (friction_scalar(s + h, int(kind), mu, mus, vst, eps)[0]
              - friction_scalar(s - h, int(kind), mu, mus, vst, eps)[0]) / (2 * h)
        assert der == pytest.approx(fd, rel=1e-5, abs=1e-6)
        ph, _dph = friction_phi(abs(s), int(kind), mu, mus, vst, eps)
        assert ph * abs(s) == pytest.approx(abs(val), rel=1e-12)


def test_seeds_regularisation_formula() -> None:
    """mu_R(v) = mu (2 - |v|/eps) v/eps below eps (seeds), mu sign(v) above."""
    f = FrictionLaw(0.3, eps_v=0.02)
    v = np.array([-0.05, -0.01, -0.001, 0.0, 0.005, 0.0199, 0.02, 0.3])
    ref = np.where(np.abs(v) < 0.02, 0.3 * (2 - np.abs(v) / 0.02) * v / 0.02, 0.3 * np.sign(v))
    np.testing.assert_allclose(f.coefficient(v), ref, rtol=1e-14, atol=1e-15)


def test_stribeck_peak_exceeds_kinetic() -> None:
    f = FrictionLaw(0.2, eps_v=1e-3, mu_static=0.5, stribeck_speed=0.05)
    v = np.linspace(0.0, 1.0, 20001)
    mu_r = f.coefficient(v)
    assert mu_r.max() == pytest.approx(0.5, rel=2e-3)  # peak ~ mu_s at v ~ eps_v
    assert v[np.argmax(mu_r)] == pytest.approx(1e-3, rel=0.05)
    assert mu_r[-1] == pytest.approx(0.2, rel=1e-9)


@pytest.mark.parametrize(("kw", "msg"), [
    ({"mu": -0.1}, "mu"), ({"mu": 0.3, "eps_v": 0.0}, "eps_v"),
    ({"mu": 0.3, "law": "viscous"}, "law"), ({"mu": 0.3, "mu_static": 0.2}, "mu_static"),
    ({"mu": 0.3, "stribeck_speed": 0.0}, "stribeck_speed"), ({"mu": float("nan")}, "mu"),
])
def test_invalid_friction_names_element(kw: dict, msg: str) -> None:
    spec = dd.Spec()
    spec.add_rigid_body("b", 1.0, (1, 1, 1))
    spec.add_marker("p", dd.GROUND)
    spec.add_marker("q", "b")
    spec.add(dd.PlaneContact("slider", "p", "q", friction=FrictionLaw(**kw)))
    with pytest.raises(ModelError, match=f"slider.*{msg}"):
        dd.compile_model(spec)


# --- block on an incline: regularised laws ------------------------------------------------------


@pytest.mark.parametrize("law", ["coulomb", "tanh"])
def test_block_creeps_below_tan_theta(law: str) -> None:
    mu, eps = 0.5, 1e-3
    theta = np.arctan(0.3)
    res = _run(incline(theta, friction=FrictionLaw(mu, eps_v=eps, law=law)), 1.0)
    t, s, v = _slope_motion(res, theta)
    ratio = np.tan(theta) / mu
    v_c = eps * (1 - np.sqrt(1 - ratio)) if law == "coulomb" else eps * np.arctanh(ratio)
    late = t > 0.5
    assert np.all(v[late] > 0) and np.all(v[late] < eps)
    np.testing.assert_allclose(v[late], v_c, rtol=1e-6)
    # displacement is the creep, nothing more (the start transient lasts milliseconds)
    assert s[-1] - s[0] == pytest.approx(v_c * t[-1], rel=0.02)
    f = res["contact.friction_force"].values[late]
    np.testing.assert_allclose(f, MASS * G * np.sin(theta), rtol=1e-6)


def test_block_slides_above_tan_theta_with_coulomb_acceleration() -> None:
    mu = 0.5
    theta = np.arctan(0.7)
    res = _run(incline(theta, friction=FrictionLaw(mu, eps_v=1e-3)), 0.6)
    t, _s, v = _slope_motion(res, theta)
    sel = t > 0.1
    a = np.polyfit(t[sel], v[sel], 1)[0]
    a_ref = G * (np.sin(theta) - mu * np.cos(theta))
    assert a == pytest.approx(a_ref, rel=1e-6)


def test_block_launched_downhill_decelerates_then_creeps() -> None:
    mu, v0 = 0.5, 2.0
    theta = np.arctan(0.2)
    res = _run(incline(theta, v0=v0, friction=FrictionLaw(mu, eps_v=1e-3)), 1.0)
    t, s, v = _slope_motion(res, theta)
    a_ref = G * (np.sin(theta) - mu * np.cos(theta))  # < 0
    t_stop = v0 / -a_ref
    sel = (t > 0.05) & (t < t_stop - 0.05)
    a = np.polyfit(t[sel], v[sel], 1)[0]
    assert a == pytest.approx(a_ref, rel=1e-6)
    s_stop = v0 * t_stop / 2
    assert s[np.searchsorted(t, t_stop + 0.1)] == pytest.approx(s_stop, rel=1e-3)
    v_c = 1e-3 * (1 - np.sqrt(1 - np.tan(theta) / mu))
    np.testing.assert_allclose(v[t > t_stop + 0.2], v_c, rtol=1e-5)


def test_stribeck_static_holds_kinetic_slides() -> None:
    """mu_k < tan(theta) < mu_s: from rest the block creeps (static friction holds it); once
    sliding above the Stribeck speed it keeps accelerating with the kinetic coefficient."""
    theta = np.arctan(0.3)
    f = FrictionLaw(0.2, eps_v=1e-3, mu_static=0.5, stribeck_speed=0.02)
    t, _, v = _slope_motion(_run(incline(theta, friction=f), 0.5), theta)
    assert np.all(v[t > 0.2] < 1e-3)
    t, _s, v = _slope_motion(_run(incline(theta, v0=0.5, friction=f), 0.5), theta)
    sel = t > 0.1
    a = np.polyfit(t[sel], v[sel], 1)[0]
    assert a == pytest.approx(G * (np.sin(theta) - 0.2 * np.cos(theta)), rel=1e-6)


# --- block on an incline: augmented-Lagrangian stick/slip ---------------------------------------


def test_unilateral_contact_really_sticks() -> None:
    theta = np.arctan(0.3)
    res = _run(incline(theta, mu_al=0.5), 1.0)
    _t, s, _v = _slope_motion(res, theta)
    assert np.max(np.abs(s - s[0])) < 1e-9
    assert np.all(res["contact.stick"].values[1:] == 1.0)
    np.testing.assert_allclose(res["contact.friction_force"].values[1:],
                               MASS * G * np.sin(theta), rtol=1e-6)
    np.testing.assert_allclose(res["contact.normal_force"].values[1:],
                               MASS * G * np.cos(theta), rtol=1e-6)
    gap = res["contact.gap"].values
    assert np.max(np.abs(gap)) < 1e-9


def test_unilateral_contact_slides_above_tan_theta() -> None:
    mu = 0.5
    theta = np.arctan(0.7)
    res = _run(incline(theta, mu_al=mu), 0.6)
    t, s, v = _slope_motion(res, theta)
    sel = t > 0.05
    assert np.polyfit(t[sel], v[sel], 1)[0] == pytest.approx(
        G * (np.sin(theta) - mu * np.cos(theta)), rel=1e-6)
    assert np.all(res["contact.stick"].values[sel] == 0.0)
    # friction power = mu N v, integrated
    D = res["contact.dissipated_energy"].values[-1]
    assert D == pytest.approx(mu * MASS * G * np.cos(theta) * (s[-1] - s[0]), rel=1e-3)


def test_unilateral_contact_decelerates_and_stops_dead() -> None:
    mu, v0 = 0.5, 2.0
    theta = np.arctan(0.2)
    res = _run(incline(theta, v0=v0, mu_al=mu), 1.0)
    t, s, v = _slope_motion(res, theta)
    assert v[0] == pytest.approx(v0)  # no velocity projection of a sliding contact
    a_ref = G * (np.sin(theta) - mu * np.cos(theta))
    t_stop = v0 / -a_ref
    sel = (t > 0.05) & (t < t_stop - 0.05)
    assert np.polyfit(t[sel], v[sel], 1)[0] == pytest.approx(a_ref, rel=1e-6)
    after = t > t_stop + 0.05
    assert np.all(res["contact.stick"].values[after] == 1.0)
    assert np.ptp(s[after]) < 1e-9
    assert s[-1] == pytest.approx(v0 * t_stop / 2, rel=2e-3)
