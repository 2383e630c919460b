"""Tabulated springs, dampers and bump stops (``elements/nonlinear_springs.py``): forces
against their tables (read independently with SciPy's PCHIP), static equilibrium, imposed
motion, the one-sided stop, the energy balance and bad input.

The motion is along the z axis: a body ``mass`` on a prismatic (or driven screw) joint, the
element between a ground marker and the body's origin.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.integrate import quad
from scipy.interpolate import PchipInterpolator
from scipy.optimize import brentq
from test_tangents import _perturbed_state

import drivedyn as dd
from drivedyn.cli import main
from drivedyn.elements.framework.curves import pack_curves
from drivedyn.elements.nonlinear_springs import BumpStop, NonlinearSpringDamper, stop_potential
from drivedyn.errors import ModelError
from drivedyn.model.compile import compile_model
from drivedyn.solver.system import System
from element_cases import nonlinear_springs as cases
from fdcheck import residual

SPRING = cases.SPRING
REBOUND = cases.REBOUND
COMPRESSION = cases.COMPRESSION
STOP = cases.STOP
G = 9.81


def _pchip(table):
    """The table read by SciPy (the reference interpolation, extrapolating straight
    beyond the ends as the element does)."""
    x, y = np.array(table).T
    p = PchipInterpolator(x, y, extrapolate=False)
    d0, d1 = float(p(x[0], 1)), float(p(x[-1], 1))

    def f(q: float) -> float:
        if q < x[0]:
            return float(y[0] + d0 * (q - x[0]))
        if q > x[-1]:
            return float(y[-1] + d1 * (q - x[-1]))
        return float(p(q))

    return f


def _column(h: float, joint: str = "prismatic", gravity: float = 0.0, mass: float = 2.0,
            anchor_z: float = 0.0, **body) -> dd.Spec:
    """A body at height ``h`` on a joint along z (``"prismatic"``, or ``"screw"`` with a
    pitch of 0.1 m/rev); a ground marker ``anchor`` at height ``anchor_z``; the body's
    marker ``slider`` at its origin."""
    spec = dd.Spec(gravity=(0.0, 0.0, -gravity))
    spec.add_rigid_body("mass", mass, [0.01, 0.01, 0.01], position=(0.0, 0.0, h), **body)
    spec.add_marker("rail", "ground", position=(0.0, 0.0, h), axis=(0, 0, 1))
    spec.add_marker("slider", "mass", axis=(0, 0, 1))
    spec.add_marker("anchor", "ground", position=(0.0, 0.0, anchor_z))
    if joint == "prismatic":
        spec.add(dd.Prismatic("slide", "rail", "slider"))
    else:
        spec.add(dd.Screw("screw", "rail", "slider", pitch=0.1))
    return spec


PITCH = 0.1  # [m/rev] of the screw in _column


def _screw_speed(v: float) -> float:
    """Screw speed [rad/s] that moves the body along z at ``v`` [m/s]."""
    return 2.0 * np.pi * v / PITCH


def _at_height(model, z: float):
    st = model.initial_state()
    st.x[model.node_index["mass"], 2] = z
    return st


def test_spring_force_is_the_table_and_straight_beyond() -> None:
    """At rest, the tension is the spring table at the deflection ``L - L0`` (plus the
    preload): the table's values at its points, SciPy's PCHIP between them, the end tangent
    lines beyond both ends; the potential is the curve's integral from 0 plus ``F0 L``.

    Deliberate mutations that fail it: the deflection taken as ``L0 - L`` (a compression
    convention); cubic extrapolation of the end segments; the preload left out of the
    tension or its potential."""
    L0, F0 = 0.9, 40.0
    spec = _column(1.0)
    spec.add(NonlinearSpringDamper("coil", "anchor", "slider", spring_curve=SPRING,
                                   free_length=L0, preload=F0))
    model = compile_model(spec)
    ref = _pchip(SPRING)
    xs = [p[0] for p in SPRING]
    probes = [*xs, -0.25, -0.15, -0.03, 0.06, -0.45, -0.31, 0.12, 0.3]
    for x in probes:
        st = _at_height(model, L0 + x)
        out = dd.element_outputs(model, st)["coil"]
        assert out["length"] == pytest.approx(L0 + x, abs=1e-15)
        assert out["deflection"] == pytest.approx(x, abs=1e-15)
        assert out["spring_force"] - F0 == pytest.approx(ref(x), rel=1e-12, abs=1e-9)
        assert out["force"] == pytest.approx(out["spring_force"], abs=0.0)
        assert out["damper_force"] == 0.0
        if x in xs:
            assert out["spring_force"] - F0 == pytest.approx(dict(SPRING)[x], rel=1e-13)
        g, e = model.group("coil")
        V = quad(ref, 0.0, x, points=[p for p in xs if min(0, x) < p < max(0, x)])[0]
        assert g.eout[e, 1] == pytest.approx(V + F0 * (L0 + x), rel=1e-9)


def test_hanging_mass_and_resting_mass_equilibria_are_the_table_inverse() -> None:
    """A mass hanging below a coil spring stretches it until the tension is its weight:
    the deflection solves ``f_s(x) + F0 = m g`` (SciPy's PCHIP, inverted by brentq) within
    1e-6 m. A mass resting on top of the spring compresses it beyond the table: the
    deflection is on the straight extension, ``f_s(x) = -m g``.

    Deliberate mutations that fail it: the tension's sign flipped (the hanging mass falls
    through); the extrapolation continued with the end cubic; the preload ignored."""
    newton = dd.Newton(tol=1e-12, phi_tol=1e-14)
    ref = _pchip(SPRING)

    # hanging: anchor above, at z = 1.5; the spring is stretched
    m, F0 = 150.0, 300.0
    spec = _column(0.5, gravity=G, mass=m, anchor_z=1.5)
    spec.add(NonlinearSpringDamper("coil", "anchor", "slider", spring_curve=SPRING,
                                   free_length=1.0, preload=F0))
    model = compile_model(spec)
    st = dd.solve_static(model, newton=newton)
    x = dd.element_outputs(model, st)["coil"]["deflection"]
    expected = brentq(lambda q: ref(q) + F0 - m * G, -0.3, 0.1, xtol=1e-14)
    assert 0.0 < expected < 0.1
    assert x == pytest.approx(expected, abs=1e-6)

    # resting on top: anchor below, at z = 0; 1200 kg compress it beyond -0.3 m
    m = 1200.0
    spec = _column(0.8, gravity=G, mass=m)
    spec.add(NonlinearSpringDamper("coil", "anchor", "slider", spring_curve=SPRING,
                                   free_length=1.0))
    model = compile_model(spec)
    st = dd.solve_static(model, newton=newton)
    x = dd.element_outputs(model, st)["coil"]["deflection"]
    x0, y0 = SPRING[0]
    slope = float(PchipInterpolator(*np.array(SPRING).T)(x0, 1))
    expected = x0 + (-m * G - y0) / slope
    assert expected < x0
    assert x == pytest.approx(expected, abs=1e-6)


def _driven(v: float, spec: dd.Spec, t_end: float = 0.05) -> dd.Results:
    """``spec`` (a screw column) with the body moved along z at ``v`` [m/s] from the
    start, simulated for ``t_end``."""
    w = _screw_speed(v)
    spec.add(dd.JointDriver("drive", "screw", w, quantity="speed"))
    model = compile_model(spec)
    return dd.simulate(model, t_end, step=dd.FixedStep(1e-3), output_dt=5e-3,
                       newton=dd.Newton(tol=1e-10))


@pytest.mark.parametrize("v", [2.0, 0.7, -4.0, -0.2])
def test_damper_force_at_constant_imposed_speed_is_its_table(v: float) -> None:
    """The body is driven along z at a constant speed (a screw joint at constant speed):
    in rebound (the markers separate) the damper pulls with the rebound table's force at
    that speed, in compression it pushes with the compression table's force (beyond the
    last point: the straight extension); no spring, so that is the whole tension; the
    dissipated power is the force times the speed, positive.

    Deliberate mutations that fail it: the two tables swapped; the compression force not
    negated (a damper pulling while compressed); the speed passed with its sign to the
    compression table."""
    spec = _column(1.0, joint="screw", velocity=(0.0, 0.0, v),
                   angular_velocity=(0.0, 0.0, _screw_speed(v)))
    spec.add(NonlinearSpringDamper("damper", "anchor", "slider",
                                   damper_curve_rebound=REBOUND,
                                   damper_curve_compression=COMPRESSION))
    res = _driven(v, spec)
    assert res.success
    rate = res["damper.length_rate"].values
    force = res["damper.force"].values
    np.testing.assert_allclose(rate, v, rtol=1e-9)
    table = REBOUND if v > 0 else COMPRESSION
    expected = np.sign(v) * _pchip(table)(abs(v))
    np.testing.assert_allclose(force, expected, rtol=1e-9)
    np.testing.assert_allclose(res["damper.damper_force"].values, expected, rtol=1e-9)
    np.testing.assert_allclose(res["damper.dissipated_power"].values, expected * v,
                               rtol=1e-9)
    assert np.all(res["damper.dissipated_power"].values > 0.0)
    assert res["damper.dissipated_energy"].values[-1] == pytest.approx(
        expected * v * res.time[-1], rel=1e-9)


def _ramp(d: np.ndarray, eps: float) -> np.ndarray:
    t = np.clip(d / eps, 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def test_bump_stop_is_zero_in_the_gap_its_curve_beyond_and_never_pulls() -> None:
    """The body is driven into a compression stop and back out at 0.5 m/s: inside the gap
    the force, spring and damper forces are exactly zero; in contact the spring force is
    the ramp times the table at the deflection, the force the spring force plus the
    ramped damping times the deflection rate, except where that would pull (on the way
    out), where it is exactly zero; never negative.

    Deliberate mutations that fail it: no clamp at zero (the damper pulls on the way out);
    the damping not ramped (a force jump at contact); the deflection measured from the
    initial length instead of the contact length (force inside the gap)."""
    v, gap, c, eps = 0.5, 0.02, 4000.0, 0.01
    spec = _column(1.0, joint="screw", velocity=(0.0, 0.0, -v),
                   angular_velocity=(0.0, 0.0, _screw_speed(-v)))
    spec.add(BumpStop("stop", "anchor", "slider", STOP, gap=gap, damping=c, transition=eps))
    w = _screw_speed(v)
    speed = dd.Table([0.0, 0.1, 0.101, 1.0], [-w, -w, w, w])
    spec.add(dd.JointDriver("drive", "screw", speed, quantity="speed"))
    res = dd.simulate(compile_model(spec), 0.2, step=dd.FixedStep(5e-4), output_dt=1e-3,
                      newton=dd.Newton(tol=1e-10))
    assert res.success
    d = res["stop.deflection"].values
    rate = res["stop.length_rate"].values
    F = res["stop.force"].values
    Fk = res["stop.spring_force"].values
    Fd = res["stop.damper_force"].values
    np.testing.assert_allclose(d, (1.0 - gap) - res["stop.length"].values, atol=1e-14)
    out = d <= 0.0
    assert out.sum() > 20 and (~out).sum() > 20 and d.max() > 0.025
    assert np.all(F[out] == 0.0) and np.all(Fk[out] == 0.0) and np.all(Fd[out] == 0.0)
    assert np.all(F >= 0.0)
    S = _ramp(d, eps)
    curve = np.array([_pchip(STOP)(q) for q in np.maximum(d, 0.0)])
    np.testing.assert_allclose(Fk[~out], (S * curve)[~out], rtol=1e-9, atol=1e-9)
    push = np.maximum(S * (curve - c * rate), 0.0)  # deflection rate = -length rate
    np.testing.assert_allclose(F[~out], push[~out], rtol=1e-9, atol=1e-6)
    np.testing.assert_allclose(Fd, F - Fk, atol=1e-9)
    held = ~out & (curve - c * rate < 0.0)
    assert held.sum() > 5  # on the way out the damping would pull: held at zero
    assert np.all(F[held] == 0.0)
    assert np.all(res["stop.dissipated_power"].values >= 0.0)


def test_extension_stop_pulls_the_markers_together() -> None:
    """A rebound stop (``side = "extension"``): no force until the markers are ``gap``
    further apart than at the start, then the table's force, pulling them together (the
    body held below it rests on it).

    Deliberate mutation that fails it: the side ignored (the stop acting in compression)."""
    m = 20.0
    spec = _column(0.5, gravity=G, mass=m, anchor_z=1.5)
    spec.add(BumpStop("strap", "anchor", "slider", STOP, gap=0.03, side="extension"))
    model = compile_model(spec)
    # from a state in contact: out of it nothing holds the body (a singular matrix)
    st = dd.solve_static(model, _at_height(model, 1.5 - 1.03 - 0.04),
                         newton=dd.Newton(tol=1e-12, phi_tol=1e-14))
    out = dd.element_outputs(model, st)["strap"]
    d = brentq(lambda q: _pchip(STOP)(q) - m * G, 0.0, 0.08, xtol=1e-14)
    assert out["deflection"] == pytest.approx(d, abs=1e-6)
    assert out["length"] == pytest.approx(1.0 + 0.03 + d, abs=1e-6)
    assert out["force"] == pytest.approx(m * G, rel=1e-9)


def test_energy_balance_of_a_free_oscillation_through_the_bump_stop() -> None:
    """A mass on a coil spring with both damper branches falls (gravity and an initial
    speed) through the bump stop's gap, hits it and oscillates: the element potentials
    are the integrals of their curves (checked against SciPy's quadrature of the
    reference tables along the run), and kinetic + potential + dissipated energy stays the
    work in (the balance error small against the energy dissipated); both the stop and
    the damper dissipate.

    Deliberate mutations that fail it: the stop's potential without its onset ramp (the
    integral of the bare curve), the spring's potential taken as ``f_s(x) x / 2`` (exact for
    a linear spring only), the damper's dissipated power with the wrong sign."""
    m, L0, gap, eps = 100.0, 1.0, 0.05, 0.02
    spec = _column(1.0, gravity=G, mass=m, velocity=(0.0, 0.0, -2.5))
    spec.add(NonlinearSpringDamper("coil", "anchor", "slider", spring_curve=SPRING,
                                   free_length=L0, damper_curve_rebound=REBOUND,
                                   damper_curve_compression=COMPRESSION))
    spec.add(BumpStop("stop", "anchor", "slider", STOP, gap=gap, damping=800.0,
                      transition=eps))
    model = compile_model(spec)
    res = dd.simulate(model, 1.0, step=dd.FixedStep(2e-4), output_dt=2e-3,
                      integrator=dd.GeneralizedAlpha(1.0), newton=dd.Newton(tol=1e-10))
    assert res.success
    d_stop = res["stop.deflection"].values
    assert d_stop.max() > 2 * eps  # through the ramp into the curve

    # potentials from the reference tables (SciPy) along the run
    spring = _pchip(SPRING)
    stop = _pchip(STOP)
    Vs = np.array([quad(spring, 0.0, x, limit=200)[0] for x in res["coil.deflection"].values])
    Vb = np.array([quad(lambda q: _ramp(np.array(q), eps) * stop(q), 0.0, max(x, 0.0),
                        points=[eps], limit=200)[0] for x in d_stop])
    z = res["mass.position"].values[:, 2]
    V = Vs + Vb + m * G * z
    E_pot = res["energy.potential"].values
    np.testing.assert_allclose(E_pot - E_pot[0], V - V[0], atol=1e-7 * abs(V).max())

    diss_coil = res["coil.dissipated_energy"].values[-1]
    diss_stop = res["stop.dissipated_energy"].values[-1]
    assert diss_coil > 100.0 and diss_stop > 50.0
    balance = res["energy.balance_error"].values
    assert np.abs(res["energy.work_in"].values).max() == 0.0
    assert np.abs(balance).max() < 2e-5 * (diss_coil + diss_stop)
    T = res["energy.kinetic"].values
    D = res["energy.dissipated"].values
    np.testing.assert_allclose(T + E_pot + D - T[0] - E_pot[0], balance, atol=1e-9)


def test_stop_potential_is_the_integral_of_the_ramped_curve() -> None:
    """The compiled potential of a stop is the integral of the ramp times the curve, for a
    ramp spanning several points of the table and beyond its last point.

    Deliberate mutation that fails it: two Gauss points instead of four on the ramped
    pieces (degree 6 not integrated exactly)."""
    X, Y, D, start = pack_curves([np.array(STOP).T])
    stop = _pchip(STOP)
    for eps in (0.0, 0.01, 0.06, 0.1):
        for d in (-0.01, 0.0, 0.005, 0.02, 0.035, 0.06, 0.09, 0.15):
            ref = quad(lambda q, e=eps: (_ramp(np.array(q), e) if e > 0 else 1.0) * stop(q),
                       0.0, max(d, 0.0), points=[0.02, 0.05, 0.08, eps], limit=200,
                       epsabs=1e-13)[0]
            assert stop_potential(X, Y, D, start, 0, d, eps) == pytest.approx(
                ref, rel=1e-11, abs=1e-13)


def _branch_outputs(case) -> dict[str, dict[str, float]]:
    """Outputs of the elements of a tangent case at the tangent test's perturbed state."""
    model = compile_model(case())
    st = _perturbed_state(model, np.random.default_rng(7))
    residual(System(model), st)
    out = {}
    for g in model.groups:
        if g.family in ("nonlinear_spring_damper", "bump_stop"):
            for e, name in enumerate(g.names):
                out[name] = dict(zip(g.aux_names, g.aux[e], strict=True))
    return out


def test_tangent_cases_meet_every_branch() -> None:
    """The tangent cases (``element_cases/nonlinear_springs.py``) check the matrices on every
    branch at the registry test's perturbed state: springs inside their table and beyond
    both ends, dampers in rebound and compression (inside and beyond their tables, and
    without a curve for the branch met), stops open, inside the onset ramp, beyond it,
    beyond the table, held at zero, in compression and extension.

    Deliberate mutation that fails it: a change of the cases (or of the perturbation)
    that leaves a branch unchecked, such as the stops' gaps made positive."""
    sp = {**_branch_outputs(cases.spring_tables_case),
          **_branch_outputs(cases.spring_extrapolation_case)}
    x0, x1 = SPRING[0][0], SPRING[-1][0]
    inside = [o for o in sp.values() if x0 < o["deflection"] < x1]
    assert len(inside) >= 5
    assert sp["below"]["deflection"] < x0 and sp["above"]["deflection"] > x1
    rates = [o["length_rate"] for k, o in sp.items() if k.startswith("s")]
    assert min(rates) < 0.0 < max(rates)
    assert sp["below"]["length_rate"] > 0.4 and sp["above"]["length_rate"] < -0.4  # beyond
    assert sp["linear"]["length_rate"] < 0 and sp["linear"]["damper_force"] == 0.0
    assert sp["compression_only"]["length_rate"] > 0
    assert sp["compression_only"]["damper_force"] == 0.0

    st = {**_branch_outputs(cases.bump_stop_closed_case),
          **_branch_outputs(cases.bump_stop_open_case)}
    assert 0.0 < st["ramp"]["deflection"] < 0.05
    assert 0.03 < st["beyond_ramp"]["deflection"] < STOP[-1][0]
    assert st["beyond_table"]["deflection"] > STOP[-1][0]
    assert st["rebound_stop"]["deflection"] > 0.0 and st["rebound_stop"]["force"] > 0.0
    for name in ("ramp", "beyond_ramp", "beyond_table", "no_ramp"):
        assert st[name]["force"] > 0.0
        assert (st[name]["damper_force"] != 0.0) == (name != "no_ramp")
    assert st["open"]["deflection"] < 0 and st["open_rebound"]["deflection"] < 0
    for name in ("held", "held_rebound"):
        assert st[name]["deflection"] > 0.0 and st[name]["force"] == 0.0
        assert st[name]["spring_force"] > 0.0


# --- bad input -----------------------------------------------------------------------------------


def _spring(**kw) -> NonlinearSpringDamper:
    return NonlinearSpringDamper("s", "a", "b", **kw)


def _stop(**kw) -> BumpStop:
    args = {"stiffness_curve": STOP, "gap": 0.01, **kw}
    return BumpStop("b", "a", "b", **args)


@pytest.mark.parametrize(("make", "words"), [
    (lambda: _spring(spring_curve=((0.0, 0.0), (0.1, 500.0), (0.2, 400.0))),
     ["NonlinearSpringDamper 's'.spring_curve", "must not decrease", "500.0", "400.0"]),
    (lambda: _spring(spring_curve=((0.0, 0.0), (0.0, 100.0))),
     ["'s'.spring_curve", "increase strictly"]),
    (lambda: _spring(spring_curve=((0.0, 0.0),)), ["'s'.spring_curve", "at least 2 points"]),
    (lambda: _spring(spring_curve=(0.0, 1.0, 2.0)),
     ["'s'.spring_curve", "expected a table of [deflection m, tension N] pairs",
      "(0.0, 1.0, 2.0)"]),
    (lambda: _spring(spring_curve=((0.0, "1 kg"), (0.1, 2.0))),
     ["'s'.spring_curve", "'1 kg' is in kg, expected N"]),
    (lambda: _spring(free_length=-0.2), ["'s'.free_length", "> 0 m", "-0.2"]),
    (lambda: _spring(free_length=0.0), ["'s'.free_length", "> 0 m"]),
    (lambda: _spring(stiffness=-3.0), ["'s'.stiffness", ">= 0 N/m", "-3.0"]),
    (lambda: _spring(stiffness=100.0, spring_curve=SPRING), ["'s'", "not both"]),
    (lambda: _spring(damper_curve_rebound=((-0.5, -100.0), (0.0, 0.0), (1.0, 200.0))),
     ["'s'.damper_curve_rebound", ">= 0 m/s", "-0.5"]),
    (lambda: _spring(damper_curve_compression=((-1.0, 50.0), (0.0, 0.0))),
     ["'s'.damper_curve_compression", ">= 0 m/s", "-1.0"]),
    (lambda: _spring(damper_curve_compression=((0.0, 20.0), (1.0, 200.0))),
     ["'s'.damper_curve_compression", "start at (0, 0)", "20.0"]),
    (lambda: _spring(damper_curve_rebound=((0.0, 0.0), (1.0, 200.0), (2.0, 100.0))),
     ["'s'.damper_curve_rebound", "must not decrease", "100.0"]),
    (lambda: _stop(stiffness_curve=((0.01, 0.0), (0.02, 100.0))),
     ["BumpStop 'b'.stiffness_curve", "start at (0, 0)", "0.01"]),
    (lambda: _stop(stiffness_curve=((0.0, 0.0), (0.02, 100.0), (0.03, 90.0))),
     ["'b'.stiffness_curve", "must not decrease", "90.0"]),
    (lambda: _stop(damping=100.0), ["'b'.transition", "> 0 m with damping"]),
    (lambda: _stop(transition=-0.01), ["'b'.transition", ">= 0 m", "-0.01"]),
    (lambda: _stop(side="sideways"), ["'b'.side", "'sideways'"]),
])
def test_bad_parameters_are_refused_naming_key_and_value(make, words) -> None:
    """Each malformed parameter is refused by ``validate`` with a ModelError naming the
    element, the key and the value.

    Deliberate mutations that fail it: ``check_table`` called with ``monotone=False`` for
    the spring; the damper tables' abscissae not checked for sign (a negative speed read
    as a magnitude); the table start not checked (a damper force jump at zero speed);
    numpy scalars printed with their repr (``np.float64(500.0)``)."""
    with pytest.raises(ModelError) as exc:
        make().validate()
    msg = str(exc.value)
    for w in words:
        assert w in msg, msg
    assert "np.float64" not in msg, msg  # values as written, not numpy reprs


@pytest.mark.parametrize("element", ["NonlinearSpringDamper", "BumpStop"])
def test_markers_at_one_point_are_refused(element: str) -> None:
    """A point-to-point element has no line of action between coinciding markers: the
    model is refused when compiled, naming the element and its markers.

    Deliberate mutation that fails it: the initial-length check removed (the model
    compiles; the force direction is undefined)."""
    spec = _column(1.0, anchor_z=1.0)
    el = (NonlinearSpringDamper("e", "anchor", "slider", stiffness=10.0)
          if element == "NonlinearSpringDamper" else
          BumpStop("e", "anchor", "slider", STOP, gap=0.01))
    spec.add(el)
    with pytest.raises(ModelError, match=rf"{element} 'e': markers 'anchor' and 'slider' "
                                         r"are at the same point"):
        compile_model(spec)


def test_gap_longer_than_the_initial_length_is_refused() -> None:
    """A compression stop whose contact length would be <= 0 is refused naming the gap.

    Deliberate mutation that fails it: the contact-length check removed."""
    spec = _column(1.0)
    spec.add(BumpStop("e", "anchor", "slider", STOP, gap=1.2))
    with pytest.raises(ModelError, match=r"BumpStop 'e'.gap: the contact length .* must be "
                                         r"> 0 m, got gap 1.2"):
        compile_model(spec)


MODEL = """
[model]
name = "quarter"
gravity = [0, 0, -9.81]

[[bodies]]
name = "wheel"
mass = "40 kg"
inertia = [0.5, 0.8, 0.5]
position = [0, 0, "300 mm"]

[[markers]]
name = "rail"
body = "ground"
position = [0, 0, "300 mm"]
axis = [0, 0, 1]

[[markers]]
name = "hub"
body = "wheel"
axis = [0, 0, 1]

[[markers]]
name = "tower"
body = "ground"
position = [0, 0, "700 mm"]

[[elements]]
type = "Prismatic"
name = "guide"
marker_a = "rail"
marker_b = "hub"

[[elements]]
type = "NonlinearSpringDamper"
name = "coil"
marker_a = "tower"
marker_b = "hub"
free_length = "450 mm"
spring_curve = [["-100 mm", "-4 kN"], [-0.05, -1500.0], [0.0, 0.0], [0.05, 1500.0]]
damper_curve_rebound = [[0.0, 0.0], ["0.5 m/s", 900.0], [2.0, 2000.0]]
damper_curve_compression = [[0.0, 0.0], [0.5, 400.0], [2.0, 900.0]]

[[elements]]
type = "BumpStop"
name = "bumper"
marker_a = "tower"
marker_b = "hub"
gap = "30 mm"
stiffness_curve = [[0.0, 0.0], ["10 mm", 300.0], [0.02, "1.5 kN"]]
damping = "500 N s/m"
transition = "5 mm"

[solver]
t_end = "0.05 s"
step = { mode = "fixed", h = "1 ms" }

[output]
dt = "10 ms"
"""


def test_model_file_tables_with_units(tmp_path: Path) -> None:
    """Tables in a model file: pairs of plain SI numbers or quantities with units,
    converted to SI per column; the model runs.

    Deliberate mutation that fails it: the table entries' units ignored (-100 mm read as
    -100 m)."""
    from drivedyn.config import load_model

    path = tmp_path / "m.toml"
    path.write_text(MODEL)
    model = load_model(path)
    coil = next(e for e in model.spec.elements if e.name == "coil")
    stop = next(e for e in model.spec.elements if e.name == "bumper")
    assert coil.spring_curve[0] == (-0.1, -4000.0)
    assert coil.damper_curve_rebound[1] == (0.5, 900.0)
    assert stop.stiffness_curve == ((0.0, 0.0), (0.01, 300.0), (0.02, 1500.0))
    assert stop.gap == pytest.approx(0.03) and stop.damping == 500.0
    res = dd.simulate(model)
    assert res.success


def test_python_tables_as_arrays_and_the_plot_category() -> None:
    """From Python a table may be an (n, 2) array (stored as a tuple of float pairs, so the
    spec stays hashable); bump stops are drawn with the springs by ``drivedyn plot``.

    Deliberate mutations that fail it: arrays refused as "not a table"; the plot category of
    ``bump_stop`` left to its own figure."""
    from drivedyn.plots.quantities import category

    arr = np.array(SPRING)
    s = NonlinearSpringDamper("s", "a", "b", spring_curve=arr,
                              damper_curve_rebound=[np.array(p) for p in REBOUND])
    s.validate()
    assert s.spring_curve == SPRING and s.damper_curve_rebound == REBOUND
    assert all(type(v) is float for p in s.spring_curve for v in p)
    hash(s)
    assert category("bump_stop", {"force", "deflection"}) == "springs"
    assert category("nonlinear_spring_damper", {"force", "deflection"}) == "springs"


@pytest.mark.parametrize(("old", "new", "words"), [
    ("[-0.05, -1500.0], [0.0, 0.0]", "[-0.05, -1500.0], [0.0, -2000.0]",
     ["elements[1] (coil).spring_curve", "must not decrease", "-1500.0", "-2000.0"]),
    ('free_length = "450 mm"', "free_length = -0.45",
     ["elements[1] (coil).free_length", "> 0 m", "-0.45"]),
    ("damper_curve_rebound = [[0.0, 0.0],", "damper_curve_rebound = [[-0.2, -50.0], [0.0, 0.0],",
     ["elements[1] (coil).damper_curve_rebound", ">= 0 m/s", "-0.2"]),
    ('["10 mm", 300.0]', '["10 s", 300.0]',
     ["elements[2] (bumper).stiffness_curve", "'10 s' is in s, expected m"]),
    ('stiffness_curve = [[0.0, 0.0],', 'stiffness_curve = [0.0, 0.0,',
     ["elements[2] (bumper).stiffness_curve", "expected a table of"]),
    ('position = [0, 0, "700 mm"]', 'position = [0, 0, "300 mm"]',
     ["NonlinearSpringDamper 'coil'", "markers 'tower' and 'hub' are at the same point"]),
])
def test_bad_model_files_exit_2_with_the_message(tmp_path: Path, old: str, new: str,
                                                 words: list[str]) -> None:
    """``drivedyn run`` on a model file with a bad table, free length or coinciding markers
    exits with 2 and one message naming the entry, the key and the value, no traceback.

    Deliberate mutations that fail it: the initial-length check removed (the coinciding
    markers run, exit 0); the units of table entries not converted ("10 s" read as 10 m)."""
    assert old in MODEL
    path = tmp_path / "m.toml"
    path.write_text(MODEL.replace(old, new))
    res = CliRunner().invoke(main, ["run", str(path), "--out", str(tmp_path / "r.nc")])
    out = res.output + (res.stderr if res.stderr_bytes is not None else "")
    assert res.exit_code == 2, f"exit {res.exit_code}: {out}\n{res.exception!r}"
    assert "Traceback" not in out, out
    for w in words:
        assert w in out, out
    assert not (tmp_path / "r.nc").exists()

