"""Kinematic primitives shared by joints, drivers and force elements (numba).

Each primitive is a scalar function of the configurations of two nodes A and B, with its
gradient ``g`` (12,) and the derivative of that gradient ``H`` (12, 12) with respect to the
node coordinates ``[x_A, theta_A, x_B, theta_B]`` (translations global, rotations right
perturbations ``R <- R exp(theta~)``). ``H`` is the right-trivialised second derivative and
is not symmetric in general; it is exactly ``d g / d q`` as the Newton matrix needs.

Vectors carried by a node are given in that node's frame: ``abar`` (axis on A),
``bbar`` (axis on B), ``pA``/``pB`` (marker origins relative to the node origin).

Derivation (right perturbation): ``R exp(d) u = R u + R (d x u)`` so
``d(R u) = -R u~ d``; and ``d(R^T w) = (R^T w)~ d`` for a fixed global ``w``.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def cross(a, b, out):
    """out = a x b for 3-vectors."""
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True, inline="always")
def set_skew(v, S):
    """S = v~ (skew matrix of v)."""
    S[0, 0] = 0.0
    S[0, 1] = -v[2]
    S[0, 2] = v[1]
    S[1, 0] = v[2]
    S[1, 1] = 0.0
    S[1, 2] = -v[0]
    S[2, 0] = -v[1]
    S[2, 1] = v[0]
    S[2, 2] = 0.0


@njit(cache=True)
def matTvec(R, w):
    """R^T w (3,)."""
    out = np.empty(3)
    for i in range(3):
        out[i] = R[0, i] * w[0] + R[1, i] * w[1] + R[2, i] * w[2]
    return out


@njit(cache=True)
def matvec(R, u):
    """R u (3,)."""
    out = np.empty(3)
    for i in range(3):
        out[i] = R[i, 0] * u[0] + R[i, 1] * u[1] + R[i, 2] * u[2]
    return out


@njit(cache=True)
def skew3(v):
    S = np.empty((3, 3))
    set_skew(v, S)
    return S


@njit(cache=True)
def marker_position(x, R, node, p):
    """Global position (3,) of a marker with node-frame offset ``p``."""
    return x[node] + matvec(R[node], p)


@njit(cache=True)
def prim_dot(RA, RB, abar, bbar, g, H):
    """Phi = (R_A abar) . (R_B bbar); fills g (12,), H (12, 12); returns Phi."""
    a = matvec(RA, abar)
    b = matvec(RB, bbar)
    val = a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    g[:] = 0.0
    H[:, :] = 0.0
    RAb = matTvec(RA, b)
    RBa = matTvec(RB, a)
    tmp = np.empty(3)
    cross(abar, RAb, tmp)
    g[3:6] = tmp
    cross(bbar, RBa, tmp)
    g[9:12] = tmp
    As = skew3(abar)
    Bs = skew3(bbar)
    H[3:6, 3:6] = As @ skew3(RAb)
    RAtRB = RA.T @ RB
    H[3:6, 9:12] = -(As @ RAtRB @ Bs)
    H[9:12, 3:6] = -(Bs @ RAtRB.T @ As)
    H[9:12, 9:12] = Bs @ skew3(RBa)
    return val


@njit(cache=True)
def prim_axial(xA, RA, xB, RB, pA, pB, abar, g, H):
    """Phi = d . (R_A abar) with d = x_B + R_B pB - x_A - R_A pA (distance along an A axis)."""
    a = matvec(RA, abar)
    w = xB + matvec(RB, pB) - xA  # = d + R_A pA
    d = w - matvec(RA, pA)
    val = d[0] * a[0] + d[1] * a[1] + d[2] * a[2]
    g[:] = 0.0
    H[:, :] = 0.0
    RAw = matTvec(RA, w)
    RBa = matTvec(RB, a)
    tmp = np.empty(3)
    g[0:3] = -a
    cross(abar, RAw, tmp)
    g[3:6] = tmp
    g[6:9] = a
    cross(pB, RBa, tmp)
    g[9:12] = tmp
    As = skew3(abar)
    Ps = skew3(pB)
    RAs = RA @ As
    # d g_xA / d thA, d g_xB / d thA
    H[0:3, 3:6] = RAs
    H[6:9, 3:6] = -RAs
    # g_thA = abar x (R_A^T w)
    H[3:6, 3:6] = As @ skew3(RAw)
    H[3:6, 0:3] = -(As @ RA.T)
    H[3:6, 6:9] = As @ RA.T
    H[3:6, 9:12] = -(As @ RA.T @ RB @ Ps)
    # g_thB = pB x (R_B^T a)
    H[9:12, 9:12] = Ps @ skew3(RBa)
    H[9:12, 3:6] = -(Ps @ RB.T @ RAs)
    return val


@njit(cache=True)
def prim_distance(xA, RA, xB, RB, pA, pB, g, H):
    """Phi = |d|, d = x_B + R_B pB - x_A - R_A pA; returns (L, unit vector n)."""
    d = xB + matvec(RB, pB) - xA - matvec(RA, pA)
    L = np.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)
    g[:] = 0.0
    H[:, :] = 0.0
    n = np.zeros(3)
    if L < 1e-300:
        return L, n
    n = d / L
    RAn = matTvec(RA, n)
    RBn = matTvec(RB, n)
    # Jd = [-I, R_A pA~, I, -R_B pB~]
    Jd = np.zeros((3, 12))
    Jd[0, 0] = -1.0
    Jd[1, 1] = -1.0
    Jd[2, 2] = -1.0
    Jd[0, 6] = 1.0
    Jd[1, 7] = 1.0
    Jd[2, 8] = 1.0
    Jd[:, 3:6] = RA @ skew3(pA)
    Jd[:, 9:12] = -(RB @ skew3(pB))
    for j in range(12):
        g[j] = Jd[0, j] * n[0] + Jd[1, j] * n[1] + Jd[2, j] * n[2]
    P = (np.eye(3) - np.outer(n, n)) / L
    H[:, :] = Jd.T @ P @ Jd
    H[3:6, 3:6] += -(skew3(pA) @ skew3(RAn))
    H[9:12, 9:12] += skew3(pB) @ skew3(RBn)
    return L, n


@njit(cache=True)
def prim_angle(RA, RB, a1, a2, b1, g, H, gs, Hs, gc, Hc):
    """Relative rotation angle of B about the third axis of A, in (-pi, pi].

    ``theta = atan2(b . a2, b . a1)`` with ``a1, a2`` the first two axes of marker A and
    ``b`` the first axis of marker B (node-frame vectors ``a1, a2, b1``). Work arrays
    ``gs, Hs, gc, Hc`` have the sizes of ``g, H``.
    """
    s = prim_dot(RA, RB, a2, b1, gs, Hs)
    c = prim_dot(RA, RB, a1, b1, gc, Hc)
    r2 = s * s + c * c
    th = np.arctan2(s, c)
    for i in range(12):
        g[i] = (c * gs[i] - s * gc[i]) / r2
    for i in range(12):
        for j in range(12):
            H[i, j] = (
                (c * Hs[i, j] - s * Hc[i, j] + gs[i] * gc[j] - gc[i] * gs[j]) / r2
                - g[i] * 2.0 * (c * gc[j] + s * gs[j]) / r2
            )
    return th


@njit(cache=True, inline="always")
def unwrap(raw, ref):
    """Angle equal to ``raw`` modulo 2 pi and closest to ``ref`` (accumulates revolutions)."""
    return raw + 2.0 * np.pi * np.round((ref - raw) / (2.0 * np.pi))


@njit(cache=True)
def dot12(g, v):
    s = 0.0
    for i in range(g.shape[0]):
        s += g[i] * v[i]
    return s


@njit(cache=True)
def quad_form(H, v):
    """v^T H v."""
    s = 0.0
    n = v.shape[0]
    for i in range(n):
        for j in range(n):
            s += v[i] * H[i, j] * v[j]
    return s


@njit(cache=True)
def gather_v(v, dofs, nd, out):
    """Local velocity/acceleration vector (nd,) from the global one (0 for ground dofs)."""
    for i in range(nd):
        gi = dofs[i]
        out[i] = v[gi] if gi >= 0 else 0.0


@njit(cache=True)
def marker_velocity(x, R, v, node, p, dof0):
    """Global velocity (3,) of a marker at node-frame offset p; ``dof0 < 0`` for ground."""
    out = np.zeros(3)
    if dof0 < 0:
        return out
    Om = v[dof0 + 3 : dof0 + 6]
    w = np.empty(3)
    cross(Om, p, w)
    out[:] = v[dof0 : dof0 + 3] + matvec(R[node], w)
    return out
