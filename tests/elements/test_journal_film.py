"""Oil film of a pin in a bore (:class:`JournalFilm`) against closed forms and quadratures.

* The film forces at a prescribed eccentricity and velocity against the short-bearing
  squeeze-film coefficients computed here by quadrature of the circumferential integrals
  ``C_rr = C0/pi int cos^2 / (1 - eps cos)^3``, ``C_tt = C0/pi int sin^2 / (1 - eps cos)^3``
  (independent of the element's closed forms), for a plain journal and a land film.
* The land film's closed form against the discrete sum over ``n`` flat lands, averaged over
  the land phase.
* Objectivity: a bore turning with its carrier and a pin carried along make no force.
* Approach under a constant load: ``F = c C_rr(eps) deps/dt`` integrated by scipy against the
  simulated eccentricity (a light pin: its inertia time constant is microseconds).
* Past the wall (metal contact): no radial film force, the tangential force of the film's pin
  held at ``c - h_min``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

import drivedyn as dd
from drivedyn.model.spec import ModelError

R_PIN, R_BORE, LENGTH, MU = 0.010, 0.011, 0.02, 0.1
C = R_BORE - R_PIN
HMIN = 5e-5


def film(lands: int = 0, width: float = 0.0) -> dd.JournalFilm:
    return dd.JournalFilm("film", "bore", "pin_centre", viscosity=MU, length=LENGTH,
                          bore_radius=R_BORE, pin_radius=R_PIN, lands=lands,
                          land_width=width, min_film=HMIN)


def pin_model(offset, velocity, f: dd.JournalFilm, omega: float = 0.0,
              load: float = 0.0, mass: float = 0.2) -> dd.Model:
    """A pin (centre at ``offset`` [m] in the bore's plane, ``velocity`` [m/s]) in a bore on
    a carrier turning at ``omega`` [rad/s] about the bore axis through the origin (the pin
    is then given the carrier's velocity on top); an optional force ``load`` along +x."""
    spec = dd.Spec()
    spec.add_rigid_body("carrier", 1.0, (1.0, 1.0, 1.0), angular_velocity=(0, 0, omega))
    spec.add_marker("g", dd.GROUND)
    spec.add_marker("c", "carrier")
    spec.add(dd.Hinge("bearing", "g", "c"))
    spec.add_marker("bore", "carrier")
    p = np.array([offset[0], offset[1], 0.0])
    v = np.array([velocity[0], velocity[1], 0.0]) + np.cross((0, 0, omega), p)
    spec.add_rigid_body("pin", mass, (1e-6, 1e-6, 1e-6), position=p, velocity=v)
    spec.add_marker("pin_centre", "pin")
    spec.add(f)
    if load:
        spec.add(dd.Force("load", "pin_centre", vector=(load, 0, 0)))
    return dd.compile_model(spec)


def outputs(model: dd.Model) -> dict[str, float]:
    return dd.element_outputs(model, model.initial_state())["film"]


def quadrature_coefficients(eps: float) -> tuple[float, float]:
    """(C_rr / C0, C_tt / C0) of the short-length 2-pi film by quadrature."""
    crr = quad(lambda t: math.cos(t) ** 2 / (1 - eps * math.cos(t)) ** 3, 0, 2 * math.pi,
               epsabs=0, epsrel=1e-12)[0] / math.pi
    ctt = quad(lambda t: math.sin(t) ** 2 / (1 - eps * math.cos(t)) ** 3, 0, 2 * math.pi,
               epsabs=0, epsrel=1e-12)[0] / math.pi
    return crr, ctt


@pytest.mark.parametrize("lands", [0, 12])
@pytest.mark.parametrize("eps", [1e-3, 0.3, 0.7, 0.9])
def test_forces_against_quadrature(lands: int, eps: float) -> None:
    """Radial and tangential forces at eccentricity ``eps`` (clear of the near-wall blend:
    ``h >= 2 h_min``) for a radial and a whirl velocity. Fails if an eccentricity function
    (e.g. the numerator 1 + 2 eps^2 of C_rr as 1 + 1.9 eps^2) or the centred coefficient is
    wrong, or if the reported forces are not those the film applies (power identity)."""
    f = film(lands, 1e-3)
    c0 = f.centred_damping
    crr, ctt = quadrature_coefficients(eps)
    phi = 0.4  # direction of the offset in the bore frame
    n = np.array([math.cos(phi), math.sin(phi)])
    t = np.array([-n[1], n[0]])
    for vel, k_r, k_t in ((0.02 * n, -crr, 0.0), (0.03 * t, 0.0, -ctt)):
        out = outputs(pin_model(eps * C * n, vel, f))
        assert out["radial_force"] == pytest.approx(k_r * c0 * (vel @ n), rel=1e-9, abs=1e-12)
        assert out["tangential_force"] == pytest.approx(k_t * c0 * (vel @ t), rel=1e-9,
                                                        abs=1e-12)
        # power dissipated = -(force . velocity) of the film
        assert out["dissipated_power"] == pytest.approx(
            -(out["radial_force"] * (vel @ n) + out["tangential_force"] * (vel @ t)), rel=1e-9)


def test_centred_coefficients() -> None:
    """C0 = pi mu R L^3 / c^3 (plain, short bearing) and n mu L b^3 / (2 c^3) (lands)."""
    assert film().centred_damping == pytest.approx(math.pi * MU * R_PIN * LENGTH**3 / C**3,
                                                   rel=1e-14)
    assert film(12, 1e-3).centred_damping == pytest.approx(
        12 * MU * LENGTH * 1e-9 / (2 * C**3), rel=1e-14)


@pytest.mark.parametrize("eps", [0.2, 0.6])
def test_land_film_is_the_phase_average_of_flat_lands(eps: float) -> None:
    """The land film's C_rr and C_tt against the sum over n flat lands of width b
    (``mu L b^3 / h_j^3`` each, acting along the land's normal), averaged over the land
    phase. Fails if the factor 1/2 of C0 or the land exponent b^3 is wrong."""
    n, b = 12, 1e-3
    f = film(n, b)
    crr, ctt = quadrature_coefficients(eps)
    phases = np.linspace(0.0, 2 * math.pi / n, 400, endpoint=False)
    srr = stt = 0.0
    for ph in phases:
        th = ph + 2 * math.pi * np.arange(n) / n
        h = C * (1 - eps * np.cos(th))
        k = MU * LENGTH * b**3 / h**3
        srr += float(np.sum(k * np.cos(th) ** 2))
        stt += float(np.sum(k * np.sin(th) ** 2))
    assert srr / len(phases) == pytest.approx(crr * f.centred_damping, rel=1e-9)
    assert stt / len(phases) == pytest.approx(ctt * f.centred_damping, rel=1e-9)


def test_no_force_when_the_pin_turns_with_the_bore() -> None:
    """Bore on a carrier turning at 300 rad/s, the pin carried along at eccentricity 0.6:
    the relative velocity is zero, so is the force (fails if the film used the absolute
    velocity of the pin, or missed the bore frame's rotation)."""
    out = outputs(pin_model((0.05 + 0.6 * C, 0.0), (0.0, 0.0), film(12, 1e-3), omega=300.0))
    # the pocket is 5 cm off the carrier axis; here the bore is on the carrier axis, so
    # the offset is the pin's position and the carrier speed its whole velocity
    assert abs(out["radial_force"]) < 1e-9
    assert abs(out["tangential_force"]) < 1e-9


def test_approach_under_constant_load() -> None:
    """A pin (1 g) starting centred at rest, pushed along +x by 2 N through the plain film:
    ``m xddot = F - C_rr(x / c) xdot`` integrated by scipy (Radau, 1e-11) against the
    simulated eccentricity up to eps = 0.9, to 2e-6 (the step's error control at rtol 1e-6).
    Fails if the radial film force is wrong (the factor 3 of ``C_rr - C_tt = 3 C0 eps^2 /
    (1 - eps^2)^(5/2)`` as 2.9); the tangents are checked in test_tangents.py."""
    f = film()
    c0 = f.centred_damping
    F, m = 2.0, 1e-3
    model = pin_model((0.0, 0.0), (0.0, 0.0), f, load=F, mass=m)

    def rhs(_t, y):
        e = y[0] / C
        return [y[1], (F - c0 * (1 + 2 * e * e) / (1 - e * e) ** 2.5 * y[1]) / m]

    hit = lambda _t, y: y[0] / C - 0.9  # noqa: E731
    hit.terminal = True
    ref = solve_ivp(rhs, (0, 10.0), [0.0, 0.0], method="Radau", rtol=1e-11, atol=1e-15,
                    events=hit, dense_output=True)
    t_end = float(ref.t_events[0][0])
    res = dd.simulate(model, t_end, step=dd.AdaptiveStep(h0=1e-7, rtol=1e-6, atol=1e-10),
                      output_dt=t_end / 40)
    assert res.success, res.message
    eps = res["film.eccentricity"].values
    np.testing.assert_allclose(eps, ref.sol(res.time)[0] / C, rtol=0, atol=2e-6)


def test_metal_contact_keeps_only_the_tangential_film() -> None:
    """Pin past the wall (|e| = 1.3 c): the film's pin stays at c - h_min, so a radial
    velocity (elastic approach) squeezes nothing and a whirl velocity ``v`` meets
    ``-C_tt(eps_f) s v`` with ``s = (c - h_min) / |e|``. Fails if the film acted on the
    elastic penetration (radial force != 0) or on the unclipped whirl."""
    f = film(12, 1e-3)
    eps_f = 1 - HMIN / C
    _, ctt = quadrature_coefficients(eps_f)
    e = 1.3 * C
    out = outputs(pin_model((e, 0.0), (0.01, 0.0), f))
    assert out["radial_force"] == 0.0
    out = outputs(pin_model((e, 0.0), (0.0, 0.01), f))
    s = (C - HMIN) / e
    assert out["tangential_force"] == pytest.approx(-ctt * f.centred_damping * s * 0.01,
                                                    rel=1e-9)


@pytest.mark.parametrize(("kw", "key"), [
    ({"lands": -1}, "lands"),
    ({"lands": 2.5}, "lands"),
    ({"lands": 12, "land_width": 0.0}, "land_width"),
    ({"lands": 12, "land_width": 0.01}, "land_width"),
    ({"min_film": 6e-4}, "min_film"),
    ({"min_film": 0.0}, "min_film"),
    ({"pin_radius": 0.011}, "pin_radius"),
    ({"viscosity": 0.0}, "viscosity"),
])
def test_bad_parameters_name_the_key(kw: dict, key: str) -> None:
    """Impossible parameters are refused at build time, the message naming the key."""
    args = dict(viscosity=MU, length=LENGTH, bore_radius=R_BORE, pin_radius=R_PIN,
                min_film=HMIN)
    args.update(kw)
    spec = dd.Spec()
    spec.add_rigid_body("pin", 0.1, (1e-6, 1e-6, 1e-6))
    spec.add_marker("bore", dd.GROUND)
    spec.add_marker("pin_centre", "pin")
    spec.add(dd.JournalFilm("film", "bore", "pin_centre", **args))
    with pytest.raises(ModelError, match=f"film.*{key}"):
        dd.compile_model(spec)
