"""Verification: the validation cases (quick variants) and their exact references.

* Every engine validation case of :mod:`drivedyn.validation` is run with ``quick=True``
  and every :class:`CaseResult` must pass. The tolerances live in the cases (each one is
  explained there, next to the check); they are derived from the step size used, never
  widened to make a run pass.
* The exact references (closed forms and quadratures) are checked independently of the
  simulator, mostly against high-accuracy ODE integration with scipy.
* Engine situations that the cases exercise are pinned by direct tests at the end of this
  file (free body, equations without terms of their own, dead-centre start).
"""

from __future__ import annotations

import functools
import math
import os

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import drivedyn as dd
import drivedyn.validation
from drivedyn.validation import base
from drivedyn.validation import common as VC  # noqa: N812
from drivedyn.validation import engine as VE  # noqa: N812
from drivedyn.validation import exact as X  # noqa: N812
from drivedyn.validation import integrator as VI  # noqa: N812
from drivedyn.validation import rigid_models as RM  # noqa: N812

CASE_NAMES = ("torque_free_body", "heavy_top", "pendulum", "slider_crank", "screw",
              "convergence", "energy_balance")


@functools.cache
def _run(name: str) -> tuple[base.CaseResult, ...]:
    """Run a case once per session (quick variant)."""
    return tuple(base.CASES[name](quick=True, figure_dir=None))


def _describe(results) -> str:
    return "\n".join(
        f"{'PASS' if r.passed else 'FAIL'} {r.case}: {r.quantity}: ref {r.reference:.10g}, "
        f"sim {r.simulated:.10g}, error {r.error:.3g} (tol {r.tolerance:.3g}) {r.source}"
        for r in results)


def test_all_cases_registered() -> None:
    assert set(CASE_NAMES) <= set(base.CASES)


@pytest.mark.parametrize("name", [n for n in CASE_NAMES if n != "torque_free_body"])
def test_case_passes(name: str) -> None:
    results = _run(name)
    assert results, f"case {name} returned no results"
    for r in results:
        assert r.case == name
        assert r.source, "every check must state its reference"
        assert math.isfinite(r.tolerance) and r.tolerance > 0
    assert all(r.passed for r in results), _describe(results)


def test_torque_free_body_pinned_passes() -> None:
    """Torque-free rotation of a body held at its centre of mass (weight and reaction act at
    the centre of mass, so the rotation is torque-free): |H|, T and the Euler-Poinsot
    solution. Tolerances (|w| h)^2 and (|w| h)^2 |w| t_end, see the case."""
    results = [r for r in _run("torque_free_body") if "pinned" in r.quantity]
    assert len(results) == 3
    assert all(r.passed for r in results), _describe(results)


def test_torque_free_body_free_passes() -> None:
    results = [r for r in _run("torque_free_body") if "free body" in r.quantity]
    assert len(results) == 3
    assert all(r.passed for r in results), _describe(results)


def test_convergence_errors_asymptotic() -> None:
    """Besides the fitted slope (checked by the case), each halving of h must divide the
    error by 4 within 10 % (asymptotic range, no round-off floor)."""
    hs = 4e-3 / 2.0 ** np.arange(3)
    errs, runs = VI.convergence_errors(hs, 0.25)
    assert all(r.success for r in runs)
    ratios = errs[:-1] / errs[1:]
    # second order: ratio 4; 10 % allows for the next term of the error expansion
    assert np.all(np.abs(ratios / 4.0 - 1.0) < 0.1), ratios


def test_rotation_convergence_is_second_order() -> None:
    """Lie-group generalized-alpha on a constrained 3-D rotation (torque-free body pinned at
    its centre of mass): each halving of h divides the rotation error by 4 within 1 %
    (measured within 2e-5), and the reference is orthogonal to round-off."""
    R_ref = VI.free_rotation_reference(1.0)
    assert np.linalg.norm(R_ref.T @ R_ref - np.eye(3)) < 1e-12
    hs = 8e-3 / 2.0 ** np.arange(3)
    errs, runs = VI.rotation_convergence_errors(hs, 1.0)
    assert all(r.success for r in runs)
    ratios = errs[:-1] / errs[1:]
    assert np.all(np.abs(ratios / 4.0 - 1.0) < 0.01), ratios


def test_case_writes_figure(tmp_path) -> None:
    results = VE.screw(quick=True, figure_dir=str(tmp_path))
    figs = {f for r in results for f in r.figures}
    assert figs, "a figure directory was given, the case must write a figure"
    for f in figs:
        assert os.path.isfile(f) and f.endswith(".png") and os.path.getsize(f) > 1000


def test_run_cases_sets_wall_time() -> None:
    results = drivedyn.validation.run_cases(["screw"], quick=True)
    assert results and all(r.wall_s > 0 for r in results)


# ---------------------------------------------------------------------------------------------
# exact references, checked without the simulator
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("w0", [(0.2, 1.0, 0.3), (-0.5, 0.7, -0.6), (0.9, -0.3, 0.8)])
def test_euler_poinsot_reference(w0) -> None:
    J = np.array([1.0, 2.0, 3.0])

    def euler(t, w):
        return [(J[1] - J[2]) / J[0] * w[1] * w[2], (J[2] - J[0]) / J[1] * w[2] * w[0],
                (J[0] - J[1]) / J[2] * w[0] * w[1]]

    t = np.linspace(0.0, 20.0, 201)
    sol = solve_ivp(euler, (0.0, 20.0), w0, t_eval=t, method="DOP853", rtol=1e-12,
                    atol=1e-14)
    # both are accurate to ~1e-12; 1e-9 leaves room for the ODE solver's global error
    assert np.max(np.abs(X.euler_free_body_exact(J, w0, t) - sol.y.T)) < 1e-9


def _top_rhs(a: float, b: float, beta: float):
    """Heavy top in Euler angles with the cyclic momenta eliminated: state (theta, thetadot,
    phi); I1 thetaddot = I1 phidot^2 sin cos - I3 w3 phidot sin + m g l sin (divided by I1)."""

    def rhs(t, y):
        th, thd, _ = y
        s, c = np.sin(th), np.cos(th)
        phid = (b - a * c) / (s * s)
        return [thd, phid * phid * s * c - a * phid * s + 0.5 * beta * s, phid]

    return rhs


def test_top_steady_precession_rate() -> None:
    th, w3 = np.radians(30.0), 40.0
    args = (RM.TOP_I1, RM.TOP_I3, RM.TOP_M, VC.G, RM.TOP_L, th, w3)
    for branch in ("slow", "fast"):
        Om = X.top_steady_precession_rate(*args, branch=branch)
        lhs = RM.TOP_M * VC.G * RM.TOP_L
        rhs = Om * (RM.TOP_I3 * w3 - RM.TOP_I1 * Om * np.cos(th))
        assert abs(lhs - rhs) < 1e-12 * lhs
        # integrating the Lagrangian from thetadot = 0, phidot = Om keeps theta constant
        a = RM.TOP_I3 * w3 / RM.TOP_I1
        b = (RM.TOP_I1 * Om * np.sin(th) ** 2 + RM.TOP_I3 * w3 * np.cos(th)) / RM.TOP_I1
        beta = 2 * RM.TOP_M * VC.G * RM.TOP_L / RM.TOP_I1
        sol = solve_ivp(_top_rhs(a, b, beta), (0.0, 1.0), [th, 0.0, 0.0], method="DOP853",
                        rtol=1e-12, atol=1e-13, dense_output=True)
        tt = np.linspace(0.0, 1.0, 101)
        assert np.max(np.abs(sol.sol(tt)[0] - th)) < 1e-8
        assert abs(sol.y[2, -1] - Om * 1.0) < 1e-8 * abs(Om)


@pytest.mark.parametrize("theta0_deg,w3,phidot0", [(30.0, 40.0, 0.0), (60.0, 25.0, 0.0),
                                                   (45.0, 30.0, 3.0)])
def test_top_nutation_reference(theta0_deg, w3, phidot0) -> None:
    th0 = np.radians(theta0_deg)
    ref = X.top_nutation_reference(RM.TOP_I1, RM.TOP_I3, RM.TOP_M, VC.G, RM.TOP_L, th0, w3,
                                   phidot0)
    # quadrature and closed-form complete elliptic integral agree
    assert abs(ref["T_nut"] / ref["T_nut_elliptic"] - 1.0) < 1e-12
    # the release angle is a turning point
    assert min(abs(ref["theta_min"] - th0), abs(ref["theta_max"] - th0)) < 1e-12
    # direct integration of the Lagrangian over two nutation periods
    rhs = _top_rhs(ref["a"], ref["b"], ref["beta"])
    lower = abs(ref["theta_min"] - th0) < 1e-12  # released at the top of the nutation

    def turn(t, y):
        return y[1]

    turn.direction = 1.0 if lower else -1.0  # back at the release turning point
    sol = solve_ivp(rhs, (0.0, 2.2 * ref["T_nut"]), [th0, 0.0, 0.0], method="DOP853",
                    rtol=1e-12, atol=1e-13, events=turn, dense_output=True)
    te = sol.t_events[0]
    te = te[te > 0.5 * ref["T_nut"]]
    assert len(te) == 2
    assert abs(te[0] / ref["T_nut"] - 1.0) < 1e-8
    assert abs((te[1] - te[0]) / ref["T_nut"] - 1.0) < 1e-8
    assert abs(sol.sol(te[0])[2] / ref["dphi"] - 1.0) < 1e-8
    tt = np.linspace(0.0, te[0], 4001)
    th = sol.sol(tt)[0]
    assert abs(th.max() - ref["theta_max"]) < 1e-6  # sampled extreme (4000 samples)
    assert abs(th.min() - ref["theta_min"]) < 1e-6


@pytest.mark.parametrize("deg", [2.0, 120.0, 170.0])
def test_pendulum_references(deg) -> None:
    th0 = np.radians(deg)
    Io, m, g, d = RM.PEND_IO, RM.PEND_M, VC.G, RM.PEND_D
    T = X.pendulum_period_exact(Io, m, g, d, th0)
    t = np.linspace(0.0, 1.5 * T, 301)
    sol = solve_ivp(lambda t, y: [y[1], -m * g * d / Io * np.sin(y[0])], (0.0, t[-1]),
                    [th0, 0.0], t_eval=t, method="DOP853", rtol=1e-12, atol=1e-13)
    assert np.max(np.abs(X.pendulum_angle_exact(Io, m, g, d, th0, t) - sol.y[0])) < 1e-8
    assert abs(X.pendulum_angle_exact(Io, m, g, d, th0, T) - th0) < 1e-10
    assert abs(X.pendulum_angle_exact(Io, m, g, d, th0, 0.5 * T) + th0) < 1e-10


@pytest.mark.parametrize("deg", [20.0, 100.0, 200.0, 330.0])
def test_slider_crank_references(deg) -> None:
    r, l, P = RM.SC_R, RM.SC_L, 100.0
    th = np.radians(deg)
    T, N = X.slider_crank_statics(r, l, P, th)
    # virtual work: T dtheta + (-P) dx = 0
    e = 1e-6
    dx = (X.slider_crank_position(r, l, th + e) - X.slider_crank_position(r, l, th - e)) / (2 * e)
    assert abs(T - P * (-dx)) < 1e-7 * P * r
    # the rod is a two-force member: its force on the piston has components (P, -N)
    A = r * np.array([np.cos(th), np.sin(th)])
    B = np.array([float(X.slider_crank_position(r, l, th)), 0.0])
    u = (B - A) / l
    assert abs(-P * u[1] / u[0] - N) < 1e-9 * P


def test_crossings_and_peak() -> None:
    t = np.linspace(0.0, 10.0, 2001)
    y = np.sin(2.0 * np.pi * 0.7 * t + 0.3)
    up = VC.crossings(t, y, direction=1)
    assert np.allclose(np.diff(up), 1.0 / 0.7, rtol=1e-6)
    assert len(VC.crossings(t, y)) == len(up) + len(VC.crossings(t, y, direction=-1))
    assert abs(VC.peak(t, y) - 1.0) < 1e-7


# ---------------------------------------------------------------------------------------------
# engine situations the cases rely on: the Newton test scales each equation by the sum of
# |terms| with a model-wide floor and accepts corrections at round-off
# ---------------------------------------------------------------------------------------------


def test_slider_crank_statics_symmetric_rod() -> None:
    th = np.radians(60.0)
    model = RM.slider_crank_model(th, ("angle", 0.0), piston_force=100.0, rod_com_offset=0.0)
    dd.solve_static(model)
    g, e = model.group("crank_drive")
    col = {n: c for c, n, _, _ in g.outputs()}
    T_ref, _ = X.slider_crank_statics(RM.SC_R, RM.SC_L, 100.0, th)
    assert abs(g.aux[e, col["torque"]] + T_ref) < 1e-7 * abs(T_ref)


def test_slider_crank_start_from_rest_at_dead_centre() -> None:
    model = RM.slider_crank_model(0.0, ("speed", dd.SmoothStep(0.0, 0.5, 0.0, 4.0 * np.pi)))
    res = dd.simulate(model, 0.1, step=dd.FixedStep(2e-3),
                      integrator=dd.GeneralizedAlpha(0.9))
    assert res.success, res.message
