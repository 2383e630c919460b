"""Squeeze film between annular faces against closed forms.

* The annulus bracket ``C`` against a direct quadrature of the pressure from Reynolds'
  equation (finite differences of ``(1/r) d/dr (r dp/dr) = 12 mu hdot / h^3``).
* Approach under a constant load ``F`` (no metal contact): ``F = 3 pi mu (-hdot) C / (2 h^3)``
  integrates to ``1/h^2 = 1/h0^2 + 4 F t / (3 pi mu C)`` (the plate's inertia is negligible:
  its time constant m / c is ~1e-8 s).
* Viscous drag torque ``M = 2 pi (mu omega / h)(r_ext^4 - r_int^4)/4``.
* Conditioning as h and hdot go to zero: under a large load the faces meet the roughness and
  settle on the metal contact at ``h = Ra - F/K`` (inside the h_eff blend) without a failed
  step, with a bounded film force that vanishes with hdot; the energy account closes.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import drivedyn as dd
from drivedyn.elements.contact.squeeze_film import annulus_factor, effective_thickness
from drivedyn.model.spec import ModelError

R_I, R_O = 0.015, 0.03
MU = 0.01  # [Pa s]


def plate(F: float, h0: float, roughness: float = 1e-7, hdot0: float = 0.0,
          omega: float = 0.0, K: float = 1e11, mass: float = 0.01,
          r_int: float = R_I, mu: float = MU) -> dd.Model:
    """A plate (mass ``mass``) at film thickness h0 above the ground face, pushed down by F."""
    spec = dd.Spec()
    spec.add_marker("housing_face", dd.GROUND)
    spec.add_rigid_body("plate", mass, (1e-6, 1e-6, 2e-6), position=(0, 0, h0),
                        velocity=(0, 0, hdot0), angular_velocity=(0, 0, omega))
    spec.add_marker("plate_face", "plate")
    spec.add(dd.SqueezeFilm("film", "housing_face", "plate_face", viscosity=mu, r_int=r_int,
                            r_ext=R_O, roughness=roughness,
                            contact=dd.NormalLaw(K, 1.0, law="penalty")))
    if F:
        spec.add(dd.Force("load", "plate_face", vector=(0, 0, -F)))
    return dd.compile_model(spec)


def reynolds_force_per_rate(r_int: float, r_ext: float, n: int = 4001) -> float:
    """-F / (mu hdot / h^3) from a finite-difference solution of Reynolds' equation with
    p = 0 at both radii (in units where mu hdot / h^3 = 1)."""
    r = np.linspace(r_int, r_ext, n)
    dr = r[1] - r[0]
    # (1/r) d/dr (r dp/dr) = 12  ->  r_{i+1/2} (p_{i+1} - p_i) - r_{i-1/2} (p_i - p_{i-1})
    #                                 = 12 r_i dr^2
    m = n - 2
    A = np.zeros((m, m))
    b = 12.0 * r[1:-1] * dr**2
    rp = r[1:-1] + dr / 2
    rm = r[1:-1] - dr / 2
    A[np.arange(m), np.arange(m)] = -(rp + rm)
    A[np.arange(m - 1), np.arange(1, m)] = rp[:-1]
    A[np.arange(1, m), np.arange(m - 1)] = rm[1:]
    p = np.concatenate([[0.0], np.linalg.solve(A, b), [0.0]])
    return -float(np.trapezoid(p * 2 * np.pi * r, r))


@pytest.mark.parametrize(("ri", "ro"), [(0.015, 0.03), (0.01, 0.05), (0.029, 0.03)])
def test_annulus_factor_against_reynolds(ri: float, ro: float) -> None:
    ref = reynolds_force_per_rate(ri, ro)
    assert 1.5 * math.pi * annulus_factor(ri, ro) == pytest.approx(ref, rel=1e-5)


def test_full_disk_factor() -> None:
    assert annulus_factor(0.0, 0.03) == 0.03**4
    assert annulus_factor(1e-9, 0.03) == pytest.approx(0.03**4, rel=0.1)


def test_effective_thickness_is_c1_and_bounded() -> None:
    hmin = 1e-7
    h = np.linspace(-3e-7, 5e-7, 8001)
    he = np.array([effective_thickness(x, hmin)[0] for x in h])
    dhe = np.array([effective_thickness(x, hmin)[1] for x in h])
    assert he.min() == pytest.approx(hmin)
    np.testing.assert_allclose(he[h >= 2 * hmin], h[h >= 2 * hmin])
    np.testing.assert_allclose(np.gradient(he, h)[1:-1], dhe[1:-1], atol=2e-3)
    assert np.all(np.abs(np.diff(dhe)) < 2e-3)  # continuous derivative


@pytest.mark.parametrize("r_int", [R_I, 0.0])
def test_approach_under_constant_load_matches_closed_form(r_int: float) -> None:
    F, h0 = 100.0, 20e-6
    C = annulus_factor(r_int, R_O)
    c0 = 3 * math.pi * MU * C / 2
    hdot0 = -F * h0**3 / c0  # start on the quasi-static solution
    res = dd.simulate(plate(F, h0, hdot0=hdot0, r_int=r_int), 0.5,
                      integrator=dd.GeneralizedAlpha(0.8), step=dd.FixedStep(1e-3),
                      output_dt=1e-2)
    assert res.success, res.message
    t = res.time
    h_ref = 1.0 / np.sqrt(1 / h0**2 + 4 * F * t / (3 * math.pi * MU * C))
    h = res["film.film_thickness"].values
    assert h[-1] < 0.75 * h0  # a real approach
    np.testing.assert_allclose(h, h_ref, rtol=2e-5)
    np.testing.assert_allclose(res["film.film_force"].values[1:], F, rtol=1e-4)
    assert np.all(res["film.contact_force"].values == 0.0)
    # the film dissipates the work of the load
    W = res["energy.work_in"].values[-1]
    D = res["film.dissipated_energy"].values[-1]
    assert D == pytest.approx(W, rel=1e-4)


def test_viscous_drag_torque() -> None:
    h, w = 5e-6, 30.0
    model = plate(0.0, h, omega=w)
    out = dd.element_outputs(model, model.initial_state())["film"]
    ref = 2 * math.pi * MU * w / h * (R_O**4 - R_I**4) / 4
    assert out["drag_torque"] == pytest.approx(ref, rel=1e-12)
    assert out["relative_spin"] == pytest.approx(w, rel=1e-12)
    assert out["dissipated_power"] == pytest.approx(ref * w, rel=1e-12)


def test_settles_on_metal_contact_well_conditioned() -> None:
    """Thin oil, large load: the film thins from 0.3 um to the roughness (0.1 um) in about
    0.2 s, and the plate comes to rest on the metal contact at h = Ra - F/K, inside the h_eff
    blend (h < 2 h_min = Ra)."""
    F, Ra, K, mu, h0 = 1e4, 1e-7, 1e12, 1e-4, 3e-7
    C = annulus_factor(R_I, R_O)
    t_ra = (1 / Ra**2 - 1 / h0**2) * 3 * math.pi * mu * C / (4 * F)
    assert 0.1 < t_ra < 0.3
    hdot0 = -F * h0**3 / (1.5 * math.pi * mu * C)
    # on the metal contact the film still damps: relaxation time c(h)/K ~ 0.07 s
    res = dd.simulate(plate(F, h0, roughness=Ra, K=K, mu=mu, hdot0=hdot0), 1.5,
                      integrator=dd.GeneralizedAlpha(0.8),
                      step=dd.AdaptiveStep(h0=1e-5, h_min=1e-12, h_max=1e-2, rtol=1e-4,
                                           atol=1e-12), output_dt=1e-2)
    assert res.success, res.message
    t = res.time
    h = res["film.film_thickness"].values
    early = t < 0.9 * t_ra
    h_ref = 1.0 / np.sqrt(1 / h0**2 + 4 * F * t[early] / (3 * math.pi * mu * C))
    np.testing.assert_allclose(h[early], h_ref, rtol=1e-4)
    assert h[-1] == pytest.approx(Ra - F / K, rel=1e-6)
    assert res["film.contact_force"].values[-1] == pytest.approx(F, rel=1e-6)
    assert abs(res["film.film_force"].values[-1]) < 1e-6 * F
    E = res["energy.work_in"].values[-1]
    err = np.max(np.abs(res["energy.balance_error"].values))
    assert err < 1e-3 * E


@pytest.mark.parametrize(("kw", "msg"), [
    ({"viscosity": 0.0, "r_ext": 0.03, "roughness": 1e-7}, "viscosity"),
    ({"viscosity": 0.01, "r_int": 0.03, "r_ext": 0.02, "roughness": 1e-7}, "r_int"),
    ({"viscosity": 0.01, "r_ext": 0.03, "roughness": -1e-7}, "roughness"),
    ({"viscosity": 0.01, "r_ext": 0.03, "roughness": 0.0}, "min_film"),
    ({"viscosity": 0.01, "r_ext": 0.03, "roughness": 1e-7, "min_film": 0.0}, "min_film"),
])
def test_invalid_film_names_element(kw: dict, msg: str) -> None:
    spec = dd.Spec()
    spec.add_rigid_body("b", 1.0, (1, 1, 1))
    spec.add_marker("p", dd.GROUND)
    spec.add_marker("q", "b")
    spec.add(dd.SqueezeFilm("oil", "p", "q", **kw))
    with pytest.raises(ModelError, match=f"oil.*{msg}"):
        dd.compile_model(spec)
