"""Thrust washer and journal contacts against closed forms.

* Washer: a gear pressed by an axial force F on a washer fixed to the ground and driven at
  constant speed by a driver; in steady state the driver torque equals the friction torque
  ``M = 2 pi mu_R (F/S)(r_ext^3 - r_int^3)/3`` (seeds), with ``mu_R`` at the sliding speed
  ``r_m omega``. A free washer between the gear and the housing, each face with its own
  coefficient, transmits the smaller of the two face torques and turns with the face that
  grips.
* Journal: a pin loaded radially by a force F and spun by a torque in a fixed bore climbs the
  bore wall to the friction angle ``phi = atan(mu)``: normal force ``F cos(phi)``, friction
  force ``F sin(phi)``, friction torque ``F r_pin sin(phi)`` (the friction circle); the spin
  then accelerates at ``(T - F r_pin sin(phi)) / J``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import drivedyn as dd
from drivedyn.elements.contact.common import washer_friction_radius
from drivedyn.model.spec import ModelError

R_INT, R_EXT = 0.02, 0.04
K_AX = 1e9  # axial contact stiffness [N/m]


def _washer_torque(mu_r: float, F: float) -> float:
    S = math.pi * (R_EXT**2 - R_INT**2)
    return 2 * math.pi * mu_r * (F / S) * (R_EXT**3 - R_INT**3) / 3


def _law(mass: float) -> dd.NormalLaw:
    return dd.NormalLaw(K_AX, 1.0, law="penalty", damping=2.0 * math.sqrt(K_AX * mass))


def gear_on_washer(F: float, omega: float, friction: dd.FrictionLaw,
                   free_washer: dd.FrictionLaw | None = None) -> dd.Model:
    """Gear (z axis, on a cylindrical joint to the ground, speed-driven) pressed with F onto a
    washer: fixed (the ground) or, with ``free_washer``, a free washer (2 mm, own cylindrical
    joint) whose other face runs on the housing with the friction ``free_washer``."""
    spec = dd.Spec()
    spec.add_marker("axis", dd.GROUND)
    spec.add_marker("housing", dd.GROUND)
    z_gear = 0.0
    if free_washer is not None:
        spec.add_rigid_body("washer", 0.05, (2e-5, 2e-5, 4e-5), position=(0, 0, -F / K_AX))
        spec.add_marker("washer_bottom", "washer")
        spec.add_marker("washer_top", "washer", position=(0, 0, 0.002))
        spec.add_marker("washer_axis", "washer")
        spec.add(dd.Cylindrical("washer_guide", "axis", "washer_axis"))
        spec.add(dd.ThrustWasherContact("housing_face", "housing", "washer_bottom",
                                        law=_law(0.05), r_int=R_INT, r_ext=R_EXT,
                                        friction=free_washer))
        z_gear = 0.002 - 2 * F / K_AX
        lower = "washer_top"
    else:
        z_gear = -F / K_AX
        lower = "housing"
    spec.add_rigid_body("gear", 0.5, (2e-4, 2e-4, 4e-4), position=(0, 0, z_gear),
                        angular_velocity=(0, 0, omega))
    spec.add_marker("gear_face", "gear")
    spec.add_marker("gear_axis", "gear")
    spec.add(dd.Cylindrical("gear_guide", "axis", "gear_axis"))
    spec.add(dd.JointDriver("motor", "gear_guide", omega, quantity="speed"))
    spec.add(dd.Force("thrust", "gear_face", vector=(0, 0, -F)))
    spec.add(dd.ThrustWasherContact("gear_face_contact", lower, "gear_face", law=_law(0.5),
                                    r_int=R_INT, r_ext=R_EXT, friction=friction))
    return dd.compile_model(spec)


def _run(model, t_end=0.2, h=1e-4):
    res = dd.simulate(model, t_end, integrator=dd.GeneralizedAlpha(0.8), step=dd.FixedStep(h),
                      output_dt=1e-3)
    assert res.success, res.message
    return res


def test_friction_radius() -> None:
    rm = washer_friction_radius(R_INT, R_EXT)
    assert rm == pytest.approx(2 / 3 * (R_EXT**3 - R_INT**3) / (R_EXT**2 - R_INT**2))
    assert washer_friction_radius(0.0, 0.03) == pytest.approx(0.02)  # full disk: 2 R / 3


@pytest.mark.parametrize(("omega", "law"), [(10.0, "coulomb"), (-25.0, "tanh")])
def test_washer_friction_torque_sliding(omega: float, law: str) -> None:
    F, mu = 200.0, 0.12
    res = _run(gear_on_washer(F, omega, dd.FrictionLaw(mu, eps_v=1e-3, law=law)))
    late = res.time > 0.1
    M_ref = _washer_torque(mu, F)
    np.testing.assert_allclose(res["gear_face_contact.normal_force"].values[late], F,
                               rtol=1e-8)
    np.testing.assert_allclose(res["gear_face_contact.friction_torque"].values[late],
                               math.copysign(M_ref, omega), rtol=1e-8)
    np.testing.assert_allclose(res["motor.torque"].values[late], math.copysign(M_ref, omega),
                               rtol=1e-6)
    S = math.pi * (R_EXT**2 - R_INT**2)
    np.testing.assert_allclose(res["gear_face_contact.pressure"].values[late], F / S,
                               rtol=1e-8)
    # friction power = driver power
    P = res["gear_face_contact.dissipated_power"].values[late]
    np.testing.assert_allclose(P, M_ref * abs(omega), rtol=1e-6)


def test_washer_friction_torque_regularised_range() -> None:
    """Below eps_v the coefficient is mu (2 - v/eps) v/eps at v = r_m omega."""
    F, mu, eps = 150.0, 0.1, 0.05
    rm = washer_friction_radius(R_INT, R_EXT)
    omega = 0.4 * eps / rm
    res = _run(gear_on_washer(F, omega, dd.FrictionLaw(mu, eps_v=eps)))
    x = rm * omega / eps
    mu_r = mu * (2 - x) * x
    late = res.time > 0.1
    np.testing.assert_allclose(res["motor.torque"].values[late], _washer_torque(mu_r, F),
                               rtol=1e-6)


@pytest.mark.parametrize(("mu_gear", "mu_housing"), [(0.2, 0.1), (0.1, 0.2)])
def test_free_washer_faces_with_own_coefficients(mu_gear: float, mu_housing: float) -> None:
    F, omega, eps = 100.0, 20.0, 1e-3
    model = gear_on_washer(F, omega, dd.FrictionLaw(mu_gear, eps_v=eps),
                           free_washer=dd.FrictionLaw(mu_housing, eps_v=eps))
    res = _run(model, t_end=0.3)
    late = res.time > 0.2
    mu_min = min(mu_gear, mu_housing)
    np.testing.assert_allclose(res["motor.torque"].values[late], _washer_torque(mu_min, F),
                               rtol=1e-5)
    w_washer = res["washer.angular_velocity"].values[late, 2]
    rm = washer_friction_radius(R_INT, R_EXT)
    # the washer sticks (creeps, regularised law) to the face with the larger coefficient
    ratio = mu_min / max(mu_gear, mu_housing)
    creep = eps * (1 - math.sqrt(1 - ratio)) / rm
    expected = omega - creep if mu_gear > mu_housing else creep
    np.testing.assert_allclose(w_washer, expected, rtol=1e-5)


# --- journal ---------------------------------------------------------------------------------

R_BORE, R_PIN = 0.0102, 0.01
K_RAD = 1e8


def pin_in_bore(F: float, T: float, mu: float, omega0: float = 0.0) -> tuple[dd.Model, float]:
    """Pin (z axis) in a fixed bore, pushed along -x by F and driven by the torque T about z.

    It starts spinning at ``omega0`` at its equilibrium: on the wall at the friction angle
    ``atan(mu)`` from the load line (on the +y side for a positive spin), penetrated by the
    static normal force. Motion along the wall has no damping once the friction saturates
    (Coulomb friction does not depend on the speed), so a start away from it would oscillate
    about the equilibrium for ever.
    """
    J = 2e-5
    m = 0.2
    spec = dd.Spec()
    spec.add_marker("bore", dd.GROUND)
    phi = math.atan(mu)
    roff = R_BORE - R_PIN + F * math.cos(phi) / K_RAD
    spec.add_rigid_body("pin", m, (J, J, J), position=(-roff * math.cos(phi),
                                                       roff * math.sin(phi), 0),
                        angular_velocity=(0, 0, omega0))
    spec.add_marker("pin_centre", "pin")
    law = dd.NormalLaw(K_RAD, 1.0, law="penalty", damping=2 * math.sqrt(K_RAD * m))
    spec.add(dd.JournalContact("journal", "bore", "pin_centre", law=law, bore_radius=R_BORE,
                               pin_radius=R_PIN, friction=dd.FrictionLaw(mu, eps_v=1e-3)))
    spec.add(dd.Force("load", "pin_centre", vector=(-F, 0, 0)))
    spec.add(dd.Torque("drive", "pin_centre", vector=(0, 0, T)))
    return dd.compile_model(spec), J


def test_journal_friction_circle() -> None:
    F, mu, T = 500.0, 0.15, 2.0
    model, J = pin_in_bore(F, T, mu, omega0=50.0)
    res = dd.simulate(model, 0.3, integrator=dd.GeneralizedAlpha(0.8), step=dd.FixedStep(1e-4),
                      output_dt=1e-3)
    assert res.success, res.message
    phi = math.atan(mu)
    late = res.time > 0.01
    np.testing.assert_allclose(res["journal.normal_force"].values[late], F * math.cos(phi),
                               rtol=1e-5)
    np.testing.assert_allclose(np.abs(res["journal.friction_force"].values[late]),
                               F * math.sin(phi), rtol=1e-5)
    M = F * R_PIN * math.sin(phi)
    np.testing.assert_allclose(np.abs(res["journal.friction_torque"].values[late]), M,
                               rtol=1e-5)
    w = res["pin.angular_velocity"].values[:, 2]
    alpha = np.polyfit(res.time[late], w[late], 1)[0]
    assert alpha == pytest.approx((T - M) / J, rel=1e-5)
    # the pin centre sits on the wall at the friction angle from the load line
    x, y = res["pin.position"].values[-1, :2]
    assert math.atan2(abs(y), -x) == pytest.approx(phi, rel=1e-3)


def test_journal_radial_contact_without_friction() -> None:
    F = 300.0
    model, _ = pin_in_bore(F, 0.0, 0.0)
    out = dd.element_outputs(model, dd.solve_static(model))["journal"]
    assert out["normal_force"] == pytest.approx(F, rel=1e-9)
    assert out["gap"] == pytest.approx(-F / K_RAD, rel=1e-6)


@pytest.mark.parametrize(("cls", "kw", "msg"), [
    (dd.ThrustWasherContact, {"r_int": 0.04, "r_ext": 0.02}, "r_int"),
    (dd.ThrustWasherContact, {"r_int": -0.01, "r_ext": 0.02}, "r_int"),
    (dd.ThrustWasherContact, {"r_int": 0.01, "r_ext": 0.0}, "r_ext"),
    (dd.JournalContact, {"bore_radius": 0.01, "pin_radius": 0.01}, "pin_radius"),
    (dd.JournalContact, {"bore_radius": 0.01, "pin_radius": 0.0}, "pin_radius"),
    (dd.ThrustWasherContact, {"r_int": 0.01, "r_ext": 0.02,
                              "law": dd.NormalLaw(-1.0)}, "stiffness"),
])
def test_invalid_geometry_names_element(cls, kw, msg) -> None:
    spec = dd.Spec()
    spec.add_rigid_body("b", 1.0, (1, 1, 1))
    spec.add_marker("p", dd.GROUND)
    spec.add_marker("q", "b")
    spec.add(cls("face", "p", "q", **kw))
    with pytest.raises(ModelError, match=f"face.*{msg}"):
        dd.compile_model(spec)
