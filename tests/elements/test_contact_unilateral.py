"""Augmented-Lagrangian unilateral contact: tangents in every branch, and behaviour.

The registry test checks the active-and-sticking branch (where the contact is a bilateral
constraint). Here: no contact, slip (Alart-Curnier return mapping, non-symmetric blocks with
multiplier-multiplier coupling), frictionless, and the acceleration/velocity-level rows of a
slipping and of an initially sliding contact; then a ball resting on the plane, lift-off, a
ball launched from the floor (its velocity is not projected away) and the incline cases in
tests/elements/test_friction.py.
"""

from __future__ import annotations

import numpy as np
import pytest

import drivedyn as dd
from drivedyn.model.spec import ModelError
from drivedyn.solver.system import System
from element_cases import contact as cc
from fdcheck import check_tangents, random_state


def _model(offset_z: float, mu: float, ground_a: bool = False):
    spec = dd.Spec(gravity=(0, 0, -9.81))
    a, b = cc.two_bodies(spec, np.array([0.02, 0.01, offset_z]), ground_a=ground_a)
    spec.add(dd.UnilateralContact("u", a, b, mu=mu, k=300.0, p=1e3))
    return dd.compile_model(spec)


def _branch(model, st):
    System(model).evaluate(st)
    g = model.group("u")[0]
    return {"active": g.aux[0, 6], "stick": g.aux[0, 5]}


@pytest.mark.parametrize(("offset", "mu", "active", "stick"), [
    (0.05, 1.0, 0.0, 0.0),  # separated: rows -k lambda
    (-0.05, 0.1, 1.0, 0.0),  # slipping
    (-0.05, 0.0, 1.0, 0.0),  # frictionless
    (-0.05, 3.0, 1.0, 1.0),  # sticking (as in the registry case)
])
@pytest.mark.parametrize("ground_a", [False, True])
def test_tangents_in_every_branch(offset, mu, active, stick, ground_a) -> None:
    model = _model(offset, mu, ground_a)
    st = random_state(model)
    assert _branch(model, st) == {"active": active, "stick": stick}
    check_tangents(model, st, acc_vel=True)


def test_initially_sliding_contact_rows() -> None:
    """State flag 'sliding' (initial tangential velocity): Coulomb force against the sliding
    velocity at acceleration level, no velocity projection of the tangential rows."""
    model = _model(-0.05, 0.4)
    st = random_state(model)
    g = model.group("u")[0]
    st.es[g.eoff[0] + 1] = 1.0
    check_tangents(model, st, acc_vel=True)


def ball_on_floor(h: float, v: float = 0.0, mu: float = 0.3, lift=None) -> dd.Model:
    spec = dd.Spec(gravity=(0, 0, -9.81))
    spec.add_marker("floor", dd.GROUND)
    spec.add_rigid_body("ball", 0.5, (1e-4, 1e-4, 1e-4), position=(0, 0, h),
                        velocity=(0.0, 0.0, v))
    spec.add_marker("bottom", "ball")
    spec.add(dd.UnilateralContact("u", "floor", "bottom", mu=mu))
    if lift is not None:
        spec.add(dd.Force("lift", "bottom", vector=(0, 0, 1.0), function=lift))
    return dd.compile_model(spec)


def test_ball_set_down_rests_without_penetration() -> None:
    """A ball placed on the floor at rest: the normal force carries the weight exactly and
    the gap stays zero (the constraint is exact). Impacts at a non-zero speed are not this
    element's job (see the module docstring of drivedyn.elements.contact.unilateral)."""
    res = dd.simulate(ball_on_floor(0.0), 0.3, integrator=dd.GeneralizedAlpha(0.8),
                      step=dd.FixedStep(1e-3), output_dt=1e-2)
    assert res.success, res.message
    np.testing.assert_allclose(res["u.gap"].values, 0.0, atol=1e-10)
    np.testing.assert_allclose(res["u.normal_force"].values, 0.5 * 9.81, rtol=1e-8)
    assert np.all(res["u.active"].values == 1.0)


def test_lift_off_releases_the_contact() -> None:
    """Resting ball, a force ramping from 0 to twice the weight over 0.2 s: contact until the
    force exceeds the weight (t = 0.1 s), then free flight with a = (F - mg)/m."""
    m, g = 0.5, 9.81
    model = ball_on_floor(0.0, lift=dd.Ramp(0.0, 0.2, 0.0, 2 * m * g))
    res = dd.simulate(model, 0.2, integrator=dd.GeneralizedAlpha(0.8), step=dd.FixedStep(1e-4),
                      output_dt=1e-3)
    assert res.success, res.message
    t = res.time
    N = res["u.normal_force"].values
    on = t < 0.099
    np.testing.assert_allclose(N[on], m * g - 2 * m * g * t[on] / 0.2, rtol=1e-6, atol=1e-6)
    off = t > 0.101
    assert np.all(N[off] == 0.0) and np.all(res["u.active"].values[off] == 0.0)
    # a = F/m - g = g (t - 0.1)/0.1, so z(t) = g (t - 0.1)^3 / 0.6 for t > 0.1
    z = res["ball.position"].values[:, 2]
    # lift-off is detected at step ends (1e-4 s): a few nm of position error
    np.testing.assert_allclose(z[off], g * (t[off] - 0.1) ** 3 / 0.6, rtol=1e-3, atol=1e-8)


def test_ball_launched_from_the_floor_is_not_projected() -> None:
    res = dd.simulate(ball_on_floor(0.0, v=2.0), 0.2, integrator=dd.GeneralizedAlpha(0.8),
                      step=dd.FixedStep(1e-4), output_dt=1e-3)
    assert res.success, res.message
    t = res.time
    z = res["ball.position"].values[:, 2]
    np.testing.assert_allclose(z, 2.0 * t - 0.5 * 9.81 * t**2, atol=1e-9)


def test_invalid_parameters_name_element() -> None:
    spec = dd.Spec()
    spec.add_rigid_body("b", 1.0, (1, 1, 1))
    spec.add_marker("p", dd.GROUND)
    spec.add_marker("q", "b")
    for kw, msg in (({"mu": -0.2}, "mu"), ({"k": 0.0}, "k"), ({"p": -1.0}, "p")):
        spec.elements = [dd.UnilateralContact("stop", "p", "q", **kw)]
        with pytest.raises(ModelError, match=f"stop.*{msg}"):
            dd.compile_model(spec)
