"""Integrator validation cases (registered with
:func:`drivedyn.validation.base.register_case`): order of convergence of the global error and
the energy account.

* ``convergence``: the slope of log(error) against log(h) on the 120 deg pendulum (exact
  elliptic-function solution) and on a constrained 3-D rotation (torque-free body pinned at its
  centre of mass, reference by DOP853 to 1e-13) must be 2, the order of generalized alpha.
* ``energy_balance``: ``(T + V) - (T0 + V0) - W_in + D = 0`` with dissipation, the work of a
  torque and the work of a driver, relative to the energy exchanged.

The mechanisms are those of :mod:`drivedyn.validation.rigid_models`, run with the integrator
settings of :mod:`drivedyn.validation.engine` (``rho_inf = 0.9`` for long constrained runs).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from drivedyn.elements import Hinge, Torque
from drivedyn.model import Model, Spec, compile_model
from drivedyn.solver import FixedStep, GeneralizedAlpha, Newton, simulate
from drivedyn.timefunctions import Ramp, SmoothStep
from drivedyn.validation.base import CaseResult, compare, register_case
from drivedyn.validation.common import G, failed_check, finish_case, save_figure
from drivedyn.validation.exact import pendulum_angle_exact
from drivedyn.validation.rigid_models import (
    PEND_D,
    PEND_IO,
    PEND_M,
    TF_J,
    TF_W0,
    pendulum_model,
    slider_crank_model,
    top_model,
    torque_free_model,
)


def convergence_errors(hs: Sequence[float], t_final: float, theta0: float = np.radians(120.0),
                       rho_inf: float = 0.9) -> tuple[np.ndarray, list[Any]]:
    """Global position error [m] of the pendulum's centre of mass at ``t_final`` for each
    step size (exact solution from Jacobi elliptic functions)."""
    model = pendulum_model(theta0)
    th = float(pendulum_angle_exact(PEND_IO, PEND_M, G, PEND_D, theta0, t_final))
    x_ex = PEND_D * np.array([np.sin(th), 0.0, -np.cos(th)])
    errs, runs = [], []
    for h in hs:
        # Newton: the default residual test (1e-8 relative) changes the positions by about
        # tol * |r| * beta h^2 / m < 1e-15 m per step, far below the smallest error measured
        # (~1e-7 m); constraints to 1e-12. (tol = 1e-12 is below the round-off of the
        # penalty terms and cannot be met.)
        res = simulate(model, t_final, step=FixedStep(h),
                          integrator=GeneralizedAlpha(rho_inf),
                          newton=Newton(tol=1e-8, phi_tol=1e-12),
                          output_times=[0.0, t_final])
        runs.append(res)
        if not res.success:
            errs.append(np.nan)
            continue
        errs.append(float(np.linalg.norm(res["rod.position"].values[-1] - x_ex)))
    return np.asarray(errs), runs


def free_rotation_reference(t_final: float) -> np.ndarray:
    """Rotation matrix (3, 3) at ``t_final`` [s] of the torque-free body of
    :func:`torque_free_model` (J = 1, 2, 3 kg m^2, Omega(0) = TF_W0), from Euler's equations
    and ``dR/dt = R [Omega]x`` integrated by DOP853 to 1e-13 (its own error is below 1e-12,
    under the smallest error measured, about 5e-9)."""
    from scipy.integrate import solve_ivp

    def rhs(_t, y):
        R = y[:9].reshape(3, 3)
        w = y[9:]
        S = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
        return np.r_[(R @ S).ravel(), -np.cross(w, TF_J * w) / TF_J]

    sol = solve_ivp(rhs, (0.0, t_final), np.r_[np.eye(3).ravel(), TF_W0], method="DOP853",
                    rtol=1e-13, atol=1e-14)
    return sol.y[:9, -1].reshape(3, 3)


def rotation_convergence_errors(hs: Sequence[float], t_final: float, rho_inf: float = 0.9
                                ) -> tuple[np.ndarray, list[Any]]:
    """Global rotation error ``|R - R_ref|`` (Frobenius) at ``t_final`` of the torque-free
    body pinned at its centre of mass (spherical joint, gravity: a constrained 3-D rotation)
    for each step size."""
    model = torque_free_model(True)
    R_ref = free_rotation_reference(t_final)
    errs, runs = [], []
    for h in hs:
        res = simulate(model, t_final, step=FixedStep(h), integrator=GeneralizedAlpha(rho_inf),
                       newton=Newton(tol=1e-10, phi_tol=1e-12), output_times=[0.0, t_final])
        runs.append(res)
        errs.append(float(np.linalg.norm(res["body.rotation"].values[-1] - R_ref))
                    if res.success else np.nan)
    return np.asarray(errs), runs


@register_case("convergence")
def convergence(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Order of the global error on the 120 deg pendulum (exact elliptic-function solution)
    and on a 3-D rotation (torque-free body pinned at its centre of mass, Lie-group update
    of the rotation).

    Catches a scheme that is only first order (inconsistent generalized-alpha coefficients,
    a first-order rotation update). Fails on (quick, seen): gamma = 0.55 + alpha_f - alpha_m
    instead of 0.5 + alpha_f - alpha_m: slope 1.14 on the pendulum (tolerance [1.8, 2.2])
    and 0.99 on the rotation (tolerance [1.9, 2.1]); the finest position error, 2.0e-5 m,
    still passes its 1e-4 m bound."""
    t0 = time.perf_counter()
    case = "convergence"
    h0 = 4e-3
    n = 4 if quick else 5
    hs = h0 / 2.0 ** np.arange(n)
    t_final = 0.5 if quick else 1.0
    rho = 0.9
    errs, runs = convergence_errors(hs, t_final, rho_inf=rho)
    src = "generalized alpha is second order (Chung & Hulbert 1993; Bruls et al. 2012)"
    q = (f"slope of log(error) vs log(h), pendulum 120 deg, rho_inf = {rho}, "
         f"h = {hs[0]:g}..{hs[-1]:g} s")
    # slope in [1.8, 2.2]
    if not np.all(np.isfinite(errs)):
        bad = next(r for r in runs if not r.success)
        return finish_case([failed_check(case, q, "1", 0.1, src, bad)], t0, [])
    slope = float(np.polyfit(np.log(hs), np.log(errs), 1)[0])
    r = compare(case, q, 2.0, slope, "1", 0.1, src)  # relative 0.1 <=> slope in [1.8, 2.2]
    out = [r]
    # the finest error must stay well above round-off / Newton noise (asymptotic range)
    out.append(compare(case, f"position error at t = {t_final:g} s, h = {hs[-1]:g} s",
                       0.0, float(errs[-1]), "m", 1e-4,
                       "exact: sin(theta/2) = k sn(K - w0 t, k)"))
    # 3-D: the rotation of the pinned torque-free body (measured slope 2.000004)
    hr = 8e-3 / 2.0 ** np.arange(n)
    rerrs, rruns = rotation_convergence_errors(hr, 1.0, rho_inf=rho)
    q3 = (f"slope of log|R - R_ref| vs log(h), torque-free body on a spherical joint, "
          f"rho_inf = {rho}, h = {hr[0]:g}..{hr[-1]:g} s")
    if not np.all(np.isfinite(rerrs)):
        out.append(failed_check(case, q3, "1", 0.05, src, next(r for r in rruns
                                                              if not r.success)))
    else:
        rslope = float(np.polyfit(np.log(hr), np.log(rerrs), 1)[0])
        out.append(compare(case, q3, 2.0, rslope, "1", 0.05, src))  # slope in [1.9, 2.1]

    def draw(fig):
        ax = fig.subplots()
        ax.loglog(hs, errs, "o-", label=f"simulated (slope {slope:.3f})")
        ax.loglog(hs, errs[0] * (hs / hs[0]) ** 2, "k--", lw=0.8, label="slope 2")
        ax.set_xlabel("step size h [s]")
        ax.set_ylabel(f"position error at t = {t_final:g} s [m]")
        ax.legend()
        fig.suptitle("global error of the pendulum (120 deg)")
    return finish_case(out, t0, save_figure(figure_dir, "convergence", draw))


def energy_scale(res: Any) -> float:
    """Energy exchanged in a run [J]: ``max|T - T0| + max|V - V0| + max|W_in| + D(t_end)``
    (kinetic, potential, supplied work, dissipated energy)."""
    T = res["energy.kinetic"].values
    V = res["energy.potential"].values
    W = res["energy.work_in"].values
    D = res["energy.dissipated"].values
    return float(np.max(np.abs(T - T[0])) + np.max(np.abs(V - V[0])) + np.max(np.abs(W))
                 + abs(D[-1]))


def flywheel_model(torque: Any) -> Model:
    """A flywheel (J = 0.05 kg m^2 about z) on a hinge, driven by a torque time function."""
    spec = Spec()
    spec.add_rigid_body("wheel", 5.0, [0.03, 0.03, 0.05])
    spec.add_marker("bearing", "ground", axis=(0.0, 0.0, 1.0))
    spec.add_marker("wheel_axis", "wheel", axis=(0.0, 0.0, 1.0))
    spec.add(Hinge("wheel_bearing", "bearing", "wheel_axis"))
    spec.add(Torque("motor", "wheel_axis", vector=(0.0, 0.0, 1.0), function=torque))
    return compile_model(spec)


@register_case("energy_balance")
def energy_balance(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Energy account ``(T + V) - (T0 + V0) - W_in + D = 0`` with dissipation, work of a
    torque and work of a driver; rho_inf = 1 (and 0.9, the setting of the constrained
    cases of :mod:`drivedyn.validation.engine`).

    Catches an energy term left out of the account (damper dissipation, the power of a load
    or driver). Fails on (quick, seen): the spring-dampers' dissipated power c qd^2 taken as
    0: pendulum 4.8e-2 and slider-crank 7.6e-2 of the energy exchanged, both rho_inf
    (tolerance 1e-3); the z term left out of a torque's power: flywheel 1.0. The heavy top,
    with no dissipation or load, passes both at 4.5e-4 (quick)."""
    t0 = time.perf_counter()
    case = "energy_balance"
    h = 2e-3 if quick else 1e-3
    t_end = 2.0
    th_top = np.radians(30.0)
    runs = [
        ("pendulum 120 deg with torsional spring-damper (dissipation)",
         lambda: pendulum_model(np.radians(120.0), damper=(2.0, 0.05)), (1.0, 0.9)),
        ("flywheel driven by a torque Ramp + SmoothStep (work in)",
         lambda: flywheel_model(Ramp(0.0, 0.5, 0.0, 2.0)
                                + SmoothStep(1.0, 1.5, 0.0, -3.0)), (1.0, 0.9)),
        ("slider-crank from rest at a dead centre up to 2 rev/s against a guide "
         "spring-damper (driver work)",
         lambda: slider_crank_model(0.0, ("speed", SmoothStep(0.0, 0.5, 0.0, 4.0 * np.pi)),
                                    guide_spring=(2000.0, 5.0)), (1.0, 0.9)),
        # rho_inf = 1 is unstable for the top (growing (-1)^n multiplier oscillation)
        ("heavy top nutating (3D, spherical joint)",
         lambda: top_model(th_top, 40.0, 0.0), (0.9,)),
    ]
    # The balance error of a second-order scheme is O(h^2) relative to the energy exchanged
    # (powers integrated by the trapezoidal rule over each step); 1e-3 is the required
    # accuracy of the energy account; what is measured is 1e-7 ... 2e-5.
    tol = 1e-3
    out: list[CaseResult] = []
    hist = []
    for label, build, rhos in runs:
        model = build()
        for rho in rhos:
            res = simulate(model, t_end, step=FixedStep(h),
                              integrator=GeneralizedAlpha(rho_inf=rho), output_dt=5 * h)
            q = f"max |balance error| / energy exchanged, rho_inf = {rho:g}: {label}"
            src = "energy conservation: (T + V) - (T0 + V0) = W_in - D"
            if not res.success:
                out.append(failed_check(case, q, "1", tol, src, res))
                continue
            scale = energy_scale(res)
            err = float(np.max(np.abs(res["energy.balance_error"].values)) / scale)
            out.append(compare(case, q, 0.0, err, "1", tol,
                               src + f"; energy exchanged {scale:.4g} J"))
            if rho == rhos[0]:
                hist.append((f"{label}, rho_inf = {rho:g}", res))

    def draw(fig):
        axs = fig.subplots(len(hist), 1, squeeze=False)[:, 0]
        for ax, (label, res) in zip(axs, hist, strict=True):
            t = res.time
            for name in ("kinetic", "potential", "work_in", "dissipated", "balance_error"):
                ax.plot(t, res[f"energy.{name}"].values, label=name)
            ax.set_title(label, fontsize=8)
            ax.set_ylabel("[J]")
        axs[0].legend(fontsize=7)
        axs[-1].set_xlabel("time [s]")
    figs = save_figure(figure_dir, "energy_balance", draw) if hist else []
    return finish_case(out, t0, figs)
