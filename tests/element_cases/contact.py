"""Small models exercising the contact families, for the registry tangent test
(``tests/elements/test_tangents.py``) and the contact tests.

Every case puts the contact well inside its active branch (penetration of a few cm against
the 1e-2 m position perturbations of the test, impact speed floor large against the random
velocities so that the force stays positive) and uses friction laws in the regularised, the
Stribeck and the saturated ranges, so that every term of the tangents is active. Bodies are
rotated arbitrarily and carry centre-of-mass offsets.
"""

from __future__ import annotations

import numpy as np

from drivedyn.elements.contact.friction import FrictionLaw
from drivedyn.elements.contact.impact_laws import NormalLaw
from drivedyn.model.spec import Spec
from drivedyn.rotations import exp_so3

_RA = exp_so3(np.array([0.3, -0.5, 0.8]))
_RB = exp_so3(np.array([-0.7, 0.2, 0.4]))
_RM = exp_so3(np.array([0.2, 0.9, -0.3]))  # global frame of marker A
_TARGET = np.array([0.3, -0.2, 0.5])
_J = np.array([[2.0, 0.1, 0.0], [0.1, 3.0, 0.2], [0.0, 0.2, 2.5]])


def two_bodies(spec: Spec, offset_b: np.ndarray, rot_b: np.ndarray | None = None,
               ground_a: bool = False) -> tuple[str, str]:
    """Bodies 'A' (or the ground) and 'B'; marker 'mA' at the global point _TARGET with
    orientation _RM, marker 'mB' at ``_TARGET + _RM @ offset_b`` (offset in marker A's frame)
    with global orientation ``rot_b`` (default _RM)."""
    rot_b = _RM if rot_b is None else rot_b
    if ground_a:
        spec.add_marker("mA", "ground", position=_TARGET, rotation=_RM)
    else:
        xa = np.array([0.1, 0.2, -0.1])
        spec.add_rigid_body("A", 1.5, _J, com=(0.05, 0.0, 0.02), position=xa, rotation=_RA)
        spec.add_marker("mA", "A", position=_RA.T @ (_TARGET - xa), rotation=_RA.T @ _RM)
    xb = np.array([-0.2, 0.4, 0.3])
    spec.add_rigid_body("B", 2.0, 0.8 * _J, com=(-0.03, 0.04, 0.0), position=xb, rotation=_RB)
    pb = _TARGET + _RM @ np.asarray(offset_b, float)
    spec.add_marker("mB", "B", position=_RB.T @ (pb - xb), rotation=_RB.T @ rot_b)
    return "mA", "mB"


def _law(kind: str = "lankarani-nikravesh", n: float = 1.5, c: float = 0.0) -> NormalLaw:
    # v_s floor 6 m/s: the hysteresis factor 1 + chi v/v_s stays positive for random v
    return NormalLaw(stiffness=2e4, exponent=n, law=kind, restitution=0.6, damping=c,
                     min_impact_speed=6.0)


def plane_case() -> Spec:
    from drivedyn.elements.contact import PlaneContact

    spec = Spec(gravity=(0.0, 0.0, -9.81))
    a, b = two_bodies(spec, np.array([0.02, -0.01, -0.05]))
    spec.add(PlaneContact("c", a, b, law=_law(),
                          friction=FrictionLaw(0.3, eps_v=20.0, mu_static=0.5,
                                               stribeck_speed=2.0)))
    return spec


def sphere_case() -> Spec:
    from drivedyn.elements.contact import PlaneContact

    spec = Spec()
    a, b = two_bodies(spec, np.array([0.0, 0.0, 0.08]))
    spec.add(PlaneContact("c", a, b, law=_law("hu-guo"), radius=0.13,
                          friction=FrictionLaw(0.4, eps_v=30.0, law="tanh")))
    return spec


def plane_ground_case() -> Spec:
    from drivedyn.elements.contact import PlaneContact

    spec = Spec(gravity=(0.0, 0.0, -9.81))
    a, b = two_bodies(spec, np.array([0.0, 0.0, 0.05]), ground_a=True)
    spec.add(PlaneContact("c", a, b, law=_law("penalty", 1.0, c=40.0), radius=0.1,
                          friction=FrictionLaw(0.3, eps_v=1e-2)))
    return spec


def washer_case() -> Spec:
    from drivedyn.elements.contact import ThrustWasherContact

    spec = Spec()
    a, b = two_bodies(spec, np.array([0.01, 0.02, -0.05]))
    spec.add(ThrustWasherContact("w", a, b, law=_law("gonthier", 1.0), r_int=0.02,
                                 r_ext=0.05, friction=FrictionLaw(0.2, eps_v=1.0,
                                                                  mu_static=0.3,
                                                                  stribeck_speed=0.3)))
    return spec


def washer_ground_case() -> Spec:
    from drivedyn.elements.contact import ThrustWasherContact

    spec = Spec()
    a, b = two_bodies(spec, np.array([0.0, 0.0, -0.04]), ground_a=True)
    spec.add(ThrustWasherContact("w", a, b, law=_law("exact", 1.5), r_int=0.0,
                                 r_ext=0.04, friction=FrictionLaw(0.15, eps_v=1e-3)))
    return spec


def journal_case() -> Spec:
    from drivedyn.elements.contact import JournalContact

    spec = Spec()
    # pin centre 0.06 m off the bore axis with 0.02 m clearance: 0.04 m penetration
    a, b = two_bodies(spec, np.array([0.05, 0.036, 0.01]))
    spec.add(JournalContact("j", a, b, law=_law("flores", 1.5), bore_radius=0.1,
                            pin_radius=0.08, friction=FrictionLaw(0.3, eps_v=5.0,
                                                                  mu_static=0.4,
                                                                  stribeck_speed=1.0)))
    return spec


def journal_ground_case() -> Spec:
    from drivedyn.elements.contact import JournalContact

    spec = Spec()
    a, b = two_bodies(spec, np.array([-0.04, 0.05, -0.02]), ground_a=True)
    spec.add(JournalContact("j", a, b, law=_law("hunt-crossley", 1.0), bore_radius=0.05,
                            pin_radius=0.02, friction=FrictionLaw(0.2, eps_v=0.01,
                                                                  law="tanh")))
    return spec


def journal_film_case() -> Spec:
    """Plain journal film at eccentricity 0.21, clear of the blend (h >= 2 h_min)."""
    from drivedyn.elements.contact import JournalFilm

    spec = Spec()
    a, b = two_bodies(spec, np.array([0.08, 0.06, 0.01]))
    spec.add(JournalFilm("f", a, b, viscosity=3.0, length=0.2, bore_radius=0.6,
                         pin_radius=0.12, min_film=0.05))
    return spec


def journal_film_blend_case() -> Spec:
    """Land film in the blend near the wall (0 < h = 0.07 m < 2 h_min)."""
    from drivedyn.elements.contact import JournalFilm

    spec = Spec()
    a, b = two_bodies(spec, np.array([0.06, 0.08, -0.02]))
    spec.add(JournalFilm("f", a, b, viscosity=3.0, length=0.2, bore_radius=0.27,
                         pin_radius=0.1, lands=8, land_width=0.03, min_film=0.06))
    return spec


def journal_film_contact_case() -> Spec:
    """Land film past the wall (h = -0.022 m < 0: the floor h_min) and a plain film at
    eccentricity 0.57 on the same markers, bore on the ground."""
    from drivedyn.elements.contact import JournalFilm

    spec = Spec()
    a, b = two_bodies(spec, np.array([-0.14, 0.1, 0.02]), ground_a=True)
    spec.add(JournalFilm("f", a, b, viscosity=2.0, length=0.15, bore_radius=0.25,
                         pin_radius=0.1, lands=6, land_width=0.02, min_film=0.03))
    spec.add(JournalFilm("g", a, b, viscosity=2.0, length=0.15, bore_radius=0.4,
                         pin_radius=0.1, min_film=0.03))
    return spec


def journal_film_centred_case() -> Spec:
    """Plain film 5 mm off the centre of a 0.3 m clearance, where it is isotropic."""
    from drivedyn.elements.contact import JournalFilm

    spec = Spec()
    a, b = two_bodies(spec, np.array([0.004, -0.003, 0.05]))
    spec.add(JournalFilm("f", a, b, viscosity=2.0, length=0.15, bore_radius=0.4,
                         pin_radius=0.1, min_film=0.03))
    return spec


def squeeze_case() -> Spec:
    """Film only, thickness 0.1 m >= 2 h_min: the exact film law and the drag torque."""
    from drivedyn.elements.contact.squeeze_film import SqueezeFilm

    spec = Spec()
    a, b = two_bodies(spec, np.array([0.01, -0.02, 0.1]))
    spec.add(SqueezeFilm("f", a, b, viscosity=50.0, r_int=0.1, r_ext=0.3, roughness=0.01,
                         contact=_law("penalty", 1.0)))
    return spec


def squeeze_metal_case() -> Spec:
    """Thickness 0.06 m inside the conditioning blend (h_min = 0.06) and below the roughness
    (0.12): film, metal contact with a hysteresis law, metal friction and drag."""
    from drivedyn.elements.contact.squeeze_film import SqueezeFilm

    spec = Spec()
    a, b = two_bodies(spec, np.array([0.0, 0.01, 0.06]), ground_a=True)
    spec.add(SqueezeFilm("f", a, b, viscosity=20.0, r_int=0.0, r_ext=0.2, roughness=0.12,
                         min_film=0.06, contact=_law("lankarani-nikravesh", 1.5),
                         friction=FrictionLaw(0.1, eps_v=2.0, mu_static=0.15,
                                              stribeck_speed=0.5)))
    return spec


def unilateral_case() -> Spec:
    """Active and sticking (penetration 0.05 m, p d_n ~ -50 N against multiplier forces of a
    few N, mu N > |sigma_t|): the branch where the contact is a bilateral constraint, so the
    acceleration- and velocity-level rows are checked as well. The other branches (no contact,
    slip) are checked in ``tests/elements/test_contact_unilateral.py``."""
    from drivedyn.elements.contact.unilateral import UnilateralContact

    spec = Spec(gravity=(0.0, 0.0, -9.81))
    a, b = two_bodies(spec, np.array([0.02, 0.01, -0.05]))
    spec.add(UnilateralContact("u", a, b, mu=3.0, k=300.0, p=1e3))
    return spec


def unilateral_ground_case() -> Spec:
    from drivedyn.elements.contact.unilateral import UnilateralContact

    spec = Spec()
    a, b = two_bodies(spec, np.array([0.0, 0.0, -0.05]), ground_a=True)
    spec.add(UnilateralContact("u", a, b, mu=4.0, k=200.0, p=1.5e3))
    return spec
