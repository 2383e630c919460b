"""SE(3) operators of the geometrically exact beam (Sonneville, Cardona & Bruls 2014).

A frame ``H = (x, R)`` (origin [m], rotation body-to-global) is an element of SE(3). A
Lie-algebra vector ``d = (u, theta)`` (6,) holds a translational part ``u`` [m] in the body
frame and a rotation vector ``theta`` [rad]; ``exp(d) = (T(-theta) u, exp(theta))`` with the
SO(3) tangent ``T`` of :mod:`drivedyn.rotations` (``T(-theta)`` is the left Jacobian).

The right tangent operator of SE(3), ``exp(d + delta) = exp(d) exp(T_SE3(d) delta)``, is the
series ``sum (-ad_d)^k / (k+1)!`` of the block upper-triangular
``ad_d = [[theta~, u~], [0, theta~]]``. Any power series ``f`` of such a matrix has the
diagonal blocks ``f(theta~)`` and the off-diagonal block ``D f(theta~)[u~]`` (the directional
derivative), so the inverse is::

    T_SE3^-1(d) = [[Ti(theta), D Ti(theta)[u]], [0, Ti(theta)]]
    Ti(theta)        = I + theta~/2 + c(t) theta~^2,   c(t) = (1 - (t/2) cot(t/2)) / t^2
    D Ti(theta)[u]   = u~/2 + c(t) (u~ theta~ + theta~ u~) + (c'(t)/t) (theta . u) theta~^2

with ``t = |theta|``. Both ``c`` and ``c'/t`` are analytic functions of ``t^2``; they are
evaluated from their Bernoulli series for ``t^2 < 1`` and in closed form above, so the
functions below also accept complex arguments (``t^2 = theta . theta`` without conjugation):
the beam kernel differentiates its internal forces by complex steps, exact to round-off.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from drivedyn.elements.framework.primitives import mtm, set_skew
from drivedyn.rotations import SMALL_ANGLE, angle_coeffs, exp_so3, log_so3, tangent

# c(t) = sum_k |B_2k| t^(2k-2) / (2k)!  (Bernoulli numbers), k = 1..10: converges for t < 2 pi
_C = np.array([
    1.0 / 12.0, 1.0 / 720.0, 1.0 / 30240.0, 1.0 / 1209600.0, 1.0 / 47900160.0,
    (691.0 / 2730.0) / 479001600.0, (7.0 / 6.0) / 87178291200.0,
    (3617.0 / 510.0) / 20922789888000.0, (43867.0 / 798.0) / 6402373705728000.0,
    (174611.0 / 330.0) / 2432902008176640000.0,
])


@njit(cache=True)
def tangent_inv_coeffs(t2):
    """``c(t)`` and ``c'(t)/t`` of :func:`tangent_inv_se3` for ``t2 = theta . theta`` (real
    or complex). The series keeps 16 digits for ``t2 < 1`` (terms shrink by (t/2 pi)^2)."""
    if t2.real < 1.0:
        c = _C[9] * t2 + _C[8]
        e = 18.0 * _C[9] * t2 + 16.0 * _C[8]
        for k in range(7, 0, -1):
            c = c * t2 + _C[k]
            e = e * t2 + 2.0 * k * _C[k]
        c = c * t2 + _C[0]
        return c, e
    t = np.sqrt(t2)
    h = 0.5 * t
    s = np.sin(h)
    cot = np.cos(h) / s
    c = (1.0 - h * cot) / t2
    e = -2.0 / (t2 * t2) + cot / (2.0 * t2 * t) + 1.0 / (4.0 * t2 * s * s)
    return c, e


@njit(cache=True)
def tangent_inv_se3(d, sign, out, S, U):
    """``out`` (6, 6) <- ``T_SE3^-1(sign d)`` for ``d`` (6,) ``(u, theta)``, ``sign = +-1``.

    ``S, U`` (3, 3) are work arrays of ``out``'s dtype (real or complex)."""
    th = d[3:6]
    u = d[0:3]
    set_skew(th, S)
    set_skew(u, U)
    t2 = th[0] * th[0] + th[1] * th[1] + th[2] * th[2]
    c, e = tangent_inv_coeffs(t2)
    tu = sign * sign * (th[0] * u[0] + th[1] * u[1] + th[2] * u[2])
    for i in range(3):
        for j in range(3):
            s2 = S[i, 0] * S[0, j] + S[i, 1] * S[1, j] + S[i, 2] * S[2, j]
            us = (U[i, 0] * S[0, j] + U[i, 1] * S[1, j] + U[i, 2] * S[2, j]
                  + S[i, 0] * U[0, j] + S[i, 1] * U[1, j] + S[i, 2] * U[2, j])
            diag = 1.0 + 0.5 * sign * S[i, j] + c * s2 if i == j else \
                0.5 * sign * S[i, j] + c * s2
            out[i, j] = diag
            out[3 + i, 3 + j] = diag
            out[i, 3 + j] = 0.5 * sign * U[i, j] + c * us + e * tu * s2
            out[3 + i, j] = 0.0


@njit(cache=True)
def tangent_inv_se3_pair(d, TiP, TiM, S, U):
    """``TiP`` and ``TiM`` (6, 6) <- ``T_SE3^-1(d)`` and ``T_SE3^-1(-d)``: the two calls of
    :func:`tangent_inv_se3` in one pass, sharing the coefficients and the products that do
    not depend on the sign (the same values to the last bit; the beam's section forces
    need both at every evaluation)."""
    th = d[3:6]
    u = d[0:3]
    set_skew(th, S)
    set_skew(u, U)
    t2 = th[0] * th[0] + th[1] * th[1] + th[2] * th[2]
    c, e = tangent_inv_coeffs(t2)
    tu = 1.0 * (th[0] * u[0] + th[1] * u[1] + th[2] * u[2])
    for i in range(3):
        for j in range(3):
            s2 = S[i, 0] * S[0, j] + S[i, 1] * S[1, j] + S[i, 2] * S[2, j]
            us = (U[i, 0] * S[0, j] + U[i, 1] * S[1, j] + U[i, 2] * S[2, j]
                  + S[i, 0] * U[0, j] + S[i, 1] * U[1, j] + S[i, 2] * U[2, j])
            cs2 = c * s2
            if i == j:
                dP = 1.0 + 0.5 * S[i, j] + cs2
                dM = 1.0 + -0.5 * S[i, j] + cs2
            else:
                dP = 0.5 * S[i, j] + cs2
                dM = -0.5 * S[i, j] + cs2
            TiP[i, j] = dP
            TiP[3 + i, 3 + j] = dP
            TiM[i, j] = dM
            TiM[3 + i, 3 + j] = dM
            rest = c * us
            ets = e * tu * s2
            TiP[i, 3 + j] = 0.5 * U[i, j] + rest + ets
            TiM[i, 3 + j] = -0.5 * U[i, j] + rest + ets
            TiP[3 + i, j] = 0.0
            TiM[3 + i, j] = 0.0


@njit(cache=True)
def tangent_inv_coeff_rate(t2):
    """``e' = de/dt2`` of ``e = c'(t)/t`` (:func:`tangent_inv_coeffs`; ``e = 2 dc/dt2``, so
    ``e'`` is twice the second derivative of ``c`` in ``t2``) for real ``t2 = theta .
    theta``: the Bernoulli series for ``t2 < 1``, the closed form above (``h = t/2``)::

        de/dt = 8/t^5 - 3 csc^2(h)/(4 t^3) - 3 cot(h)/(2 t^4) - csc^2(h) cot(h)/(4 t^2)
        e'    = (de/dt) / (2 t)
    """
    if t2 < 1.0:
        r = 2.0 * 9.0 * 8.0 * _C[9]
        for k in range(8, 1, -1):
            r = r * t2 + 2.0 * k * (k - 1) * _C[k]
        return r
    t = np.sqrt(t2)
    h = 0.5 * t
    s = np.sin(h)
    cot = np.cos(h) / s
    csc2 = 1.0 / (s * s)
    dedt = (8.0 / (t2 * t2 * t) - 0.75 * csc2 / (t2 * t) - 1.5 * cot / (t2 * t2)
            - 0.25 * csc2 * cot / t2)
    return dedt / (2.0 * t)


@njit(cache=True)
def tangent_inv_se3_rate(d, j, c, e, ep, dP, dM):
    """``dP`` and ``dM`` (6, 6) <- the derivatives of ``T_SE3^-1(d)`` and of
    ``T_SE3^-1(-d)`` with respect to the component ``j`` of ``d`` (6,) ``(u, theta)``, for
    real ``d``; ``c, e`` of :func:`tangent_inv_coeffs` and ``ep`` of
    :func:`tangent_inv_coeff_rate` at ``t2 = theta . theta``.

    With ``S = theta~``, ``U = u~``, ``tu = theta . u`` and the identity
    ``a~ b~ + b~ a~ = a b^T + b a^T - 2 (a . b) I``, the blocks of :func:`tangent_inv_se3`
    (``sign = +-1``) ``D = I + sign S/2 + c S^2`` and ``O = sign U/2 + c (U S + S U) + e tu
    S^2`` have, for ``E = e_k~`` (``k`` the component within its half)::

        d/du_k:     dD = 0,                    dO = sign E/2 + c (E S + S E) + e theta_k S^2
        d/dtheta_k: dD = sign E/2 + c (E S + S E) + e theta_k S^2,
                    dO = c (U E + E U) + e theta_k (U S + S U) + 2 e' theta_k tu S^2
                         + e u_k S^2 + e tu (E S + S E)

    (``dc/dt2 = e/2``, ``dtu/dtheta_k = u_k``)."""
    k = j % 3
    rot = j >= 3
    t0, t1, t2_ = d[3], d[4], d[5]
    u0, u1, u2 = d[0], d[1], d[2]
    th2 = t0 * t0 + t1 * t1 + t2_ * t2_
    tu = t0 * u0 + t1 * u1 + t2_ * u2
    thk = d[3 + k]
    uk = d[k]
    for a in range(3):
        ta = d[3 + a]
        ua = d[a]
        for b in range(3):
            tb = d[3 + b]
            ub = d[b]
            dab = 1.0 if a == b else 0.0
            eak = 1.0 if a == k else 0.0
            ebk = 1.0 if b == k else 0.0
            # E = e_k~: E[a, b] = -eps_{a b k} (-1 for (a, b, k) cyclic)
            Eab = 0.0
            if a != b and a != k and b != k:
                Eab = -1.0 if (b - a + 3) % 3 == 1 else 1.0
            s2 = ta * tb - th2 * dab                               # S^2
            es = ta * ebk + eak * tb - 2.0 * thk * dab               # E S + S E
            if rot:
                us = ua * tb + ta * ub - 2.0 * tu * dab              # U S + S U
                eu = ua * ebk + eak * ub - 2.0 * uk * dab            # U E + E U
                sym = c * es + e * thk * s2
                off = (c * eu + e * thk * us + 2.0 * ep * thk * tu * s2 + e * uk * s2
                       + e * tu * es)
                dP[a, b] = 0.5 * Eab + sym
                dM[a, b] = -0.5 * Eab + sym
                dP[3 + a, 3 + b] = dP[a, b]
                dM[3 + a, 3 + b] = dM[a, b]
                dP[a, 3 + b] = off
                dM[a, 3 + b] = off
            else:
                sym = c * es + e * thk * s2
                dP[a, b] = 0.0
                dM[a, b] = 0.0
                dP[3 + a, 3 + b] = 0.0
                dM[3 + a, 3 + b] = 0.0
                dP[a, 3 + b] = 0.5 * Eab + sym
                dM[a, 3 + b] = -0.5 * Eab + sym
            dP[3 + a, b] = 0.0
            dM[3 + a, b] = 0.0


@njit(cache=True)
def log_se3(xA, RA, xB, RB, out):
    """``out`` (6,) <- ``log(H_A^-1 H_B)`` of two frames (positions (3,) [m], rotations
    (3, 3)): the relative rotation vector ``theta`` and ``u = T(-theta)^-1 R_A^T (x_B - x_A)``
    (the left Jacobian's inverse is ``Ti(-theta)``). Written with scalars and no
    temporaries: it runs for every element at every evaluation (3x3 products through BLAS
    and small allocations cost more than the arithmetic). The rotation vector is
    :func:`~drivedyn.rotations.log_so3`'s, operation for operation; for frames turned by
    more than 134 deg relative to each other (``cos theta <= -0.7``) it is log_so3 itself."""
    r00 = RA[0, 0] * RB[0, 0] + RA[1, 0] * RB[1, 0] + RA[2, 0] * RB[2, 0]
    r11 = RA[0, 1] * RB[0, 1] + RA[1, 1] * RB[1, 1] + RA[2, 1] * RB[2, 1]
    r22 = RA[0, 2] * RB[0, 2] + RA[1, 2] * RB[1, 2] + RA[2, 2] * RB[2, 2]
    r01 = RA[0, 0] * RB[0, 1] + RA[1, 0] * RB[1, 1] + RA[2, 0] * RB[2, 1]
    r10 = RA[0, 1] * RB[0, 0] + RA[1, 1] * RB[1, 0] + RA[2, 1] * RB[2, 0]
    r02 = RA[0, 0] * RB[0, 2] + RA[1, 0] * RB[1, 2] + RA[2, 0] * RB[2, 2]
    r20 = RA[0, 2] * RB[0, 0] + RA[1, 2] * RB[1, 0] + RA[2, 2] * RB[2, 0]
    r12 = RA[0, 1] * RB[0, 2] + RA[1, 1] * RB[1, 2] + RA[2, 1] * RB[2, 2]
    r21 = RA[0, 2] * RB[0, 1] + RA[1, 2] * RB[1, 1] + RA[2, 2] * RB[2, 1]
    c = min(1.0, max(-1.0, 0.5 * (r00 + r11 + r22 - 1.0)))
    w0 = 0.5 * (r21 - r12)
    w1 = 0.5 * (r02 - r20)
    w2 = 0.5 * (r10 - r01)
    s = np.sqrt(w0**2 + w1**2 + w2**2)
    t = np.arctan2(s, c)
    if t < SMALL_ANGLE:
        a, _, _ = angle_coeffs(t)
        t0, t1, t2 = w0 / a, w1 / a, w2 / a
    elif c > -0.7:
        f = t / s
        t0, t1, t2 = w0 * f, w1 * f, w2 * f
    else:  # near a half turn: log_so3's symmetric-part branch
        Rr = np.empty((3, 3))
        mtm(RA, RB, Rr)
        th = log_so3(Rr)
        t0, t1, t2 = th[0], th[1], th[2]
    d0 = xB[0] - xA[0]
    d1 = xB[1] - xA[1]
    d2 = xB[2] - xA[2]
    p0 = RA[0, 0] * d0 + RA[1, 0] * d1 + RA[2, 0] * d2
    p1 = RA[0, 1] * d0 + RA[1, 1] * d1 + RA[2, 1] * d2
    p2 = RA[0, 2] * d0 + RA[1, 2] * d1 + RA[2, 2] * d2
    c, _ = tangent_inv_coeffs(t0 * t0 + t1 * t1 + t2 * t2)
    # Ti(-theta) p = p - theta x p / 2 + c theta x (theta x p)
    c0 = t1 * p2 - t2 * p1
    c1 = t2 * p0 - t0 * p2
    c2 = t0 * p1 - t1 * p0
    out[0] = p0 - 0.5 * c0 + c * (t1 * c2 - t2 * c1)
    out[1] = p1 - 0.5 * c1 + c * (t2 * c0 - t0 * c2)
    out[2] = p2 - 0.5 * c2 + c * (t0 * c1 - t1 * c0)
    out[3] = t0
    out[4] = t1
    out[5] = t2


def exp_se3(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(x, R)`` of ``exp(d)`` for ``d`` (6,) (Python; used by builders and tests)."""
    th = np.asarray(d[3:6], float)
    return tangent(-th) @ np.asarray(d[0:3], float), exp_so3(th)
