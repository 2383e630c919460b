"""Exact (closed-form or quadrature) references of the engine validation cases, plain functions
so that the tests check them independently of the simulator."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from scipy.integrate import quad
from scipy.special import ellipj, ellipk, ellipkinc


def euler_free_body_exact(J: Sequence[float], w0: Sequence[float], t: Any) -> np.ndarray:
    """Body-frame angular velocity (..., 3) of a torque-free rigid body (Euler-Poinsot).

    ``J`` principal moments with ``J1 < J2 < J3``; ``w0`` initial body angular velocity, in
    the regime ``|H|^2 > 2 T J2`` (rotation around the axis of the largest moment).
    Landau & Lifshitz, Mechanics, section 37: ``Omega = (A1 cn, A2 sn, A3 dn)(tau)`` with
    ``tau = rate t + tau0``, parameter ``m = (J2 - J1)(2 T J3 - H^2) / ((J3 - J2)(H^2 - 2 T J1))``.
    """
    J1, J2, J3 = (float(v) for v in J)
    w = np.asarray(w0, float)
    Jv = np.array([J1, J2, J3])
    H2 = float(np.sum((Jv * w) ** 2))
    E2 = float(np.sum(Jv * w * w))
    if not (J1 < J2 < J3) or not H2 > E2 * J2:
        raise ValueError("euler_free_body_exact needs J1 < J2 < J3 and |H|^2 > 2 T J2")
    A1 = np.sqrt((E2 * J3 - H2) / (J1 * (J3 - J1)))
    A2 = np.sqrt((E2 * J3 - H2) / (J2 * (J3 - J2)))
    s = 1.0 if w[2] >= 0.0 else -1.0
    A3 = s * np.sqrt((H2 - E2 * J1) / (J3 * (J3 - J1)))
    rate = np.sqrt((J3 - J2) * (H2 - E2 * J1) / (J1 * J2 * J3))
    m = (J2 - J1) * (E2 * J3 - H2) / ((J3 - J2) * (H2 - E2 * J1))
    tau0 = ellipkinc(np.arctan2(w[1] / A2, w[0] / A1), m)
    sn, cn, dn, _ = ellipj(s * rate * np.asarray(t, float) + tau0, m)
    return np.stack([A1 * cn, A2 * sn, A3 * dn], axis=-1)


def top_steady_precession_rate(I1: float, I3: float, m: float, g: float, l: float,
                               theta: float, w3: float, branch: str = "slow") -> float:
    """Precession rate [rad/s] of a heavy symmetric top in steady precession.

    ``I1`` transverse moment about the fixed point, ``I3`` axial moment, ``l`` fixed point to
    centre of mass, ``theta`` nutation angle from the upward vertical, ``w3`` spin component
    along the symmetry axis (``psidot + phidot cos theta``). Root of
    ``m g l = Omega (I3 w3 - I1 Omega cos theta)`` (the theta equation of the Lagrangian
    ``L = I1/2 (thetadot^2 + phidot^2 sin^2) + I3/2 w3^2 - m g l cos theta`` with
    ``thetadot = thetaddot = 0``).
    """
    c = np.cos(theta)
    p = I3 * w3
    disc = p * p - 4.0 * I1 * c * m * g * l
    if disc < 0.0:
        raise ValueError("no steady precession at this spin (spin too slow)")
    # numerically stable roots of I1 c W^2 - p W + m g l = 0
    q = 0.5 * (p + np.copysign(np.sqrt(disc), p))
    slow = m * g * l / q
    fast = q / (I1 * c)
    return float(slow if branch == "slow" else fast)


def top_nutation_reference(I1: float, I3: float, m: float, g: float, l: float,
                           theta0: float, w3: float, phidot0: float = 0.0) -> dict[str, float]:
    """Nutation of a heavy symmetric top released with ``thetadot = 0`` (Goldstein, Classical
    Mechanics, section 5.7): with ``u = cos theta``,
    ``udot^2 = f(u) = (1 - u^2)(alpha - beta u) - (b - a u)^2``,
    ``phidot = (b - a u) / (1 - u^2)``, ``a = I3 w3 / I1``, ``b = (I1 phidot0 sin^2 theta0 +
    I3 w3 u0) / I1``, ``beta = 2 m g l / I1``, ``alpha = phidot0^2 sin^2 theta0 + beta u0``.

    The motion is between the two roots ``u1 < u2`` of the cubic in [-1, 1]. Quadratures over
    one nutation period (substitution ``u = u1 + (u2 - u1) sin^2 s`` removes the endpoint
    square-root singularities)::

        T_nut = 2 int du / sqrt(f),   dphi = 2 int (b - a u)/(1 - u^2) du / sqrt(f)

    Returns ``T_nut`` [s], ``dphi`` [rad], ``theta_min``, ``theta_max`` [rad], the roots
    ``u1, u2, u3`` and the closed form ``T_nut_elliptic = 4 K(k^2) / sqrt(beta (u3 - u1))``.
    """
    u0 = np.cos(theta0)
    s0 = np.sin(theta0)
    a = I3 * w3 / I1
    b = (I1 * phidot0 * s0 * s0 + I3 * w3 * u0) / I1
    beta = 2.0 * m * g * l / I1
    alpha = phidot0 ** 2 * s0 * s0 + beta * u0
    coeffs = [beta, -alpha - a * a, -beta + 2.0 * a * b, alpha - b * b]
    roots = np.sort(np.real(np.roots(coeffs)))
    # polish the roots (Newton on the cubic)
    for _ in range(3):
        f = np.polyval(coeffs, roots)
        df = np.polyval(np.polyder(coeffs), roots)
        roots = roots - np.where(df != 0.0, f / np.where(df != 0.0, df, 1.0), 0.0)
    u1, u2, u3 = (float(r) for r in roots)
    du = u2 - u1

    def u_of(s: float) -> float:
        return u1 + du * np.sin(s) ** 2

    # f = beta (u - u1)(u2 - u)(u3 - u): du / sqrt(f) = 2 ds / sqrt(beta (u3 - u))
    def w_t(s: float) -> float:
        return 2.0 / np.sqrt(beta * (u3 - u_of(s)))

    def w_phi(s: float) -> float:
        u = u_of(s)
        return (b - a * u) / (1.0 - u * u) * w_t(s)

    opts = {"epsabs": 0.0, "epsrel": 1e-13, "limit": 200}
    T = 2.0 * quad(w_t, 0.0, 0.5 * np.pi, **opts)[0]
    dphi = 2.0 * quad(w_phi, 0.0, 0.5 * np.pi, **opts)[0]
    kk = du / (u3 - u1)
    T_ell = 4.0 * ellipk(kk) / np.sqrt(beta * (u3 - u1))
    return {"T_nut": T, "dphi": dphi, "theta_min": float(np.arccos(min(u2, 1.0))),
            "theta_max": float(np.arccos(max(u1, -1.0))), "u1": u1, "u2": u2, "u3": u3,
            "T_nut_elliptic": float(T_ell), "a": a, "b": b, "alpha": alpha, "beta": beta}


def pendulum_period_exact(I_o: float, m: float, g: float, d: float, theta0: float) -> float:
    """Period [s] of a physical pendulum released from rest at ``theta0`` [rad]:
    ``4 sqrt(I_o / (m g d)) K(k^2)``, ``k = sin(theta0 / 2)`` (scipy's ``ellipk`` takes
    ``m = k^2``)."""
    return float(4.0 * np.sqrt(I_o / (m * g * d)) * ellipk(np.sin(0.5 * theta0) ** 2))


def pendulum_angle_exact(I_o: float, m: float, g: float, d: float, theta0: float,
                         t: Any) -> np.ndarray:
    """Angle [rad] of a physical pendulum released from rest at ``theta0`` at t = 0:
    ``sin(theta/2) = k sn(K - omega0 t, k)``, ``k = sin(theta0/2)``,
    ``omega0 = sqrt(m g d / I_o)``."""
    k = np.sin(0.5 * theta0)
    K = ellipk(k * k)
    w0 = np.sqrt(m * g * d / I_o)
    sn = ellipj(K - w0 * np.asarray(t, float), k * k)[0]
    return 2.0 * np.arcsin(k * sn)


def slider_crank_position(r: float, l: float, theta: Any) -> np.ndarray:
    """Piston position [m] along the line of stroke through the crank centre:
    ``x = r cos theta + sqrt(l^2 - r^2 sin^2 theta)``."""
    th = np.asarray(theta, float)
    return r * np.cos(th) + np.sqrt(l * l - (r * np.sin(th)) ** 2)


def slider_crank_statics(r: float, l: float, P: float, theta: float) -> tuple[float, float]:
    """Crank torque and guide normal force of a slider-crank in static equilibrium with a
    force ``P`` pushing the piston towards the crank (no gravity, no friction):
    ``T = P r sin(theta + phi) / cos(phi)`` (the torque the gas force exerts on the crank,
    positive in the direction of increasing theta), ``N = P tan(phi)``,
    ``sin(phi) = r sin(theta) / l``."""
    phi = np.arcsin(r * np.sin(theta) / l)
    return float(P * r * np.sin(theta + phi) / np.cos(phi)), float(P * np.tan(phi))


# ---------------------------------------------------------------------------------------------
# model builders
# ---------------------------------------------------------------------------------------------

# physical pendulum: a rod whose centre of mass is d = 1 m from the pivot
