"""Kinematic primitives shared by joints, drivers and force elements (numba).

Each primitive is a scalar function of the configurations of two nodes A and B, with its
gradient ``g`` (12,) and the derivative of that gradient ``H`` (12, 12) with respect to the
node coordinates ``[x_A, theta_A, x_B, theta_B]`` (translations global, rotations right
perturbations ``R <- R exp(theta~)``). ``H`` is the right-trivialised second derivative and
is not symmetric in general; it is exactly ``d g / d q`` as the Newton matrix needs. ``H`` is
only computed when ``want`` is true (residual-only evaluations skip it).

Vectors carried by a node are given in that node's frame: ``abar`` (axis on A),
``bbar`` (axis on B), ``pA``/``pB`` (marker origins relative to the node origin).

Derivation (right perturbation): ``R exp(d) u = R u + R (d x u)`` so
``d(R u) = -R u~ d``; and ``d(R^T w) = (R^T w)~ d`` for a fixed global ``w``.

Performance: everything is written with explicit 3x3 loops on preallocated work arrays
(``ws`` (8, 3, 3) and ``wv`` (8, 3)), because numba's ``@`` calls BLAS, whose overhead
dwarfs a 3x3 product, and small allocations in the element loop cost more than the maths.
Kernels run their element loop with a flag ``full`` (matrices wanted) that skips the
Hessian branches in a residual-only evaluation.
The few-statement helpers (``mv``, ``mtv``, ``cross``, ``unwrap``) are plain ``njit``
functions that LLVM inlines, not inlined at numba's IR level: same stepping cost, shorter
first compilation. ``mm``, ``mtm``, ``set_skew`` and ``gather_v``
stay IR-inlined: left to LLVM, the joints' matrix pass takes 28 % longer (measured).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
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
def mv(R, u, out):
    """out = R u."""
    for i in range(3):
        out[i] = R[i, 0] * u[0] + R[i, 1] * u[1] + R[i, 2] * u[2]


@njit(cache=True)
def mtv(R, w, out):
    """out = R^T w."""
    for i in range(3):
        out[i] = R[0, i] * w[0] + R[1, i] * w[1] + R[2, i] * w[2]


# The scalar forms below serve the residual-only paths (elements/joint_rows.py,
# elements/gears/parallel_rows.py), which hold their vectors in scalar variables. They are
# plain njit functions, which LLVM inlines (the same cost per evaluation); inlined at numba's
# IR level instead, they made the first compilation of a Type C bench command 1.4 s longer
# (17.2 -> 18.6 s, benchmarks/cold_start.py).
@njit(cache=True)
def mv_scalar(R, v0, v1, v2):
    """R v for a (3, 3) array ``R`` and a vector given by its components, returned as three
    components (the arithmetic of ``mv``)."""
    return (R[0, 0] * v0 + R[0, 1] * v1 + R[0, 2] * v2,
            R[1, 0] * v0 + R[1, 1] * v1 + R[1, 2] * v2,
            R[2, 0] * v0 + R[2, 1] * v1 + R[2, 2] * v2)


@njit(cache=True)
def mtv_scalar(R, v0, v1, v2):
    """R^T v on and to components (the arithmetic of ``mtv``)."""
    return (R[0, 0] * v0 + R[1, 0] * v1 + R[2, 0] * v2,
            R[0, 1] * v0 + R[1, 1] * v1 + R[2, 1] * v2,
            R[0, 2] * v0 + R[1, 2] * v1 + R[2, 2] * v2)


@njit(cache=True, inline="always")
def mm(A, B, out):
    """out = A B (3x3)."""
    for i in range(3):
        for j in range(3):
            out[i, j] = A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j]


@njit(cache=True, inline="always")
def mtm(A, B, out):
    """out = A^T B (3x3)."""
    for i in range(3):
        for j in range(3):
            out[i, j] = A[0, i] * B[0, j] + A[1, i] * B[1, j] + A[2, i] * B[2, j]


@njit(cache=True, inline="always")
def skew_skew(a, b, out, sign, H, r0, c0):
    """H[r0:r0+3, c0:c0+3] = sign * a~ b~ = sign * (b a^T - (a.b) I)."""
    ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    for i in range(3):
        for j in range(3):
            v = b[i] * a[j]
            if i == j:
                v -= ab
            H[r0 + i, c0 + j] = sign * v


@njit(cache=True, inline="always")
def skew_mat_skew(a, M, b, sign, H, r0, c0):
    """H[r0:r0+3, c0:c0+3] = sign * a~ M b~."""
    # N = a~ M : N[:, j] = a x M[:, j]
    for j in range(3):
        n0 = a[1] * M[2, j] - a[2] * M[1, j]
        n1 = a[2] * M[0, j] - a[0] * M[2, j]
        n2 = a[0] * M[1, j] - a[1] * M[0, j]
        # row-wise later; store temporarily in H block columns
        H[r0 + 0, c0 + j] = n0
        H[r0 + 1, c0 + j] = n1
        H[r0 + 2, c0 + j] = n2
    # (N b~)[i, :] = N[i, :] b~ = -(b~ N[i,:]^T)^T... row i: r = N[i, :]; r b~ = (r x b)?
    # (r^T b~)_j = sum_k r_k (b~)_kj = (b x r)_j ... check: (b~)_kj = -eps_kjl b_l, so
    # sum_k r_k (b~)_kj = -eps_kjl r_k b_l = (r x b)_j with eps_jlk -> (r x b)_j = eps_jkl r_k b_l
    for i in range(3):
        r0_ = H[r0 + i, c0 + 0]
        r1_ = H[r0 + i, c0 + 1]
        r2_ = H[r0 + i, c0 + 2]
        H[r0 + i, c0 + 0] = sign * (r1_ * b[2] - r2_ * b[1])
        H[r0 + i, c0 + 1] = sign * (r2_ * b[0] - r0_ * b[2])
        H[r0 + i, c0 + 2] = sign * (r0_ * b[1] - r1_ * b[0])


@njit(cache=True, inline="always")
def skew_mat(a, M, sign, H, r0, c0):
    """H[r0:r0+3, c0:c0+3] = sign * a~ M."""
    for j in range(3):
        H[r0 + 0, c0 + j] = sign * (a[1] * M[2, j] - a[2] * M[1, j])
        H[r0 + 1, c0 + j] = sign * (a[2] * M[0, j] - a[0] * M[2, j])
        H[r0 + 2, c0 + j] = sign * (a[0] * M[1, j] - a[1] * M[0, j])


@njit(cache=True, inline="always")
def mat_skew(M, b, sign, H, r0, c0):
    """H[r0:r0+3, c0:c0+3] = sign * M b~  (row i: M[i,:] x b)."""
    for i in range(3):
        m0 = M[i, 0]
        m1 = M[i, 1]
        m2 = M[i, 2]
        H[r0 + i, c0 + 0] = sign * (m1 * b[2] - m2 * b[1])
        H[r0 + i, c0 + 1] = sign * (m2 * b[0] - m0 * b[2])
        H[r0 + i, c0 + 2] = sign * (m0 * b[1] - m1 * b[0])


def workspace() -> tuple[np.ndarray, np.ndarray]:
    """Work arrays for the primitives (allocate once per kernel call)."""
    return np.empty((8, 3, 3)), np.empty((8, 3))


@njit(cache=True)
def _hess_dot(RA, RB, abar, bbar, RAb, RBa, H, ws):
    """Hessian of prim_dot (kept out of line: inlining it slows the gradient-only path)."""
    H[:, :] = 0.0
    RtR = ws[0]
    mtm(RA, RB, RtR)
    skew_skew(abar, RAb, ws[1], 1.0, H, 3, 3)
    skew_mat_skew(abar, RtR, bbar, -1.0, H, 3, 9)
    RtRT = ws[2]
    for i in range(3):
        for j in range(3):
            RtRT[i, j] = RtR[j, i]
    skew_mat_skew(bbar, RtRT, abar, -1.0, H, 9, 3)
    skew_skew(bbar, RBa, ws[1], 1.0, H, 9, 9)


@njit(cache=True, inline="always")
def _dot_value(RA, RB, abar, bbar, a, b):
    """``(R_A abar) . (R_B bbar)``, leaving ``R_A abar`` in ``a`` and ``R_B bbar`` in ``b``."""
    mv(RA, abar, a)
    mv(RB, bbar, b)
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, inline="always")
def prim_dot(RA, RB, abar, bbar, g, H, want, ws, wv):
    """Phi = (R_A abar) . (R_B bbar); fills g (12,), H (12, 12) if ``want``; returns Phi."""
    a = wv[0]
    b = wv[1]
    RAb = wv[2]
    RBa = wv[3]
    val = _dot_value(RA, RB, abar, bbar, a, b)
    mtv(RA, b, RAb)
    mtv(RB, a, RBa)
    for i in range(12):
        g[i] = 0.0
    g[3] = abar[1] * RAb[2] - abar[2] * RAb[1]
    g[4] = abar[2] * RAb[0] - abar[0] * RAb[2]
    g[5] = abar[0] * RAb[1] - abar[1] * RAb[0]
    g[9] = bbar[1] * RBa[2] - bbar[2] * RBa[1]
    g[10] = bbar[2] * RBa[0] - bbar[0] * RBa[2]
    g[11] = bbar[0] * RBa[1] - bbar[1] * RBa[0]
    if want:
        _hess_dot(RA, RB, abar, bbar, RAb, RBa, H, ws)
    return val


@njit(cache=True)
def _hess_axial(RA, RB, pB, abar, RAw, RBa, H, ws):
    """Hessian of prim_axial (out of line, see _hess_dot)."""
    H[:, :] = 0.0
    # d g_xA / d thA = R_A abar~ ; d g_xB / d thA = -R_A abar~
    RAs = ws[0]
    mat_skew(RA, abar, 1.0, RAs, 0, 0)
    for i in range(3):
        for j in range(3):
            H[i, 3 + j] = RAs[i, j]
            H[6 + i, 3 + j] = -RAs[i, j]
    # g_thA = abar x (R_A^T w)
    skew_skew(abar, RAw, ws[1], 1.0, H, 3, 3)
    RAT = ws[2]
    for i in range(3):
        for j in range(3):
            RAT[i, j] = RA[j, i]
    skew_mat(abar, RAT, -1.0, H, 3, 0)
    skew_mat(abar, RAT, 1.0, H, 3, 6)
    RtR = ws[3]
    mtm(RA, RB, RtR)
    skew_mat_skew(abar, RtR, pB, -1.0, H, 3, 9)
    # g_thB = pB x (R_B^T a)
    skew_skew(pB, RBa, ws[1], 1.0, H, 9, 9)
    RtRT = ws[4]
    for i in range(3):
        for j in range(3):
            RtRT[i, j] = RtR[j, i]
    skew_mat_skew(pB, RtRT, abar, -1.0, H, 9, 3)


@njit(cache=True, inline="always")
def prim_axial(xA, RA, xB, RB, pA, pB, abar, g, H, want, ws, wv):
    """Phi = d . (R_A abar) with d = x_B + R_B pB - x_A - R_A pA (distance along an A axis)."""
    a = wv[0]
    w = wv[1]
    RAw = wv[2]
    RBa = wv[3]
    t = wv[4]
    mv(RA, abar, a)
    mv(RB, pB, w)
    for i in range(3):
        w[i] += xB[i] - xA[i]  # w = d + R_A pA
    mv(RA, pA, t)
    val = 0.0
    for i in range(3):
        val += (w[i] - t[i]) * a[i]
    mtv(RA, w, RAw)
    mtv(RB, a, RBa)
    for i in range(3):
        g[i] = -a[i]
        g[6 + i] = a[i]
    g[3] = abar[1] * RAw[2] - abar[2] * RAw[1]
    g[4] = abar[2] * RAw[0] - abar[0] * RAw[2]
    g[5] = abar[0] * RAw[1] - abar[1] * RAw[0]
    g[9] = pB[1] * RBa[2] - pB[2] * RBa[1]
    g[10] = pB[2] * RBa[0] - pB[0] * RBa[2]
    g[11] = pB[0] * RBa[1] - pB[1] * RBa[0]
    if want:
        _hess_axial(RA, RB, pB, abar, RAw, RBa, H, ws)
    return val


@njit(cache=True, inline="always")
def prim_global(xA, RA, xB, RB, pA, pB, i, g, H, want, ws, wv):
    """Phi = d . e_i, the global component ``i`` of d = x_B + R_B pB - x_A - R_A pA. Its
    gradient on the translations is constant; on the rotations (right perturbations)
    ``(R_A^T e_i) x pA`` and ``pB x (R_B^T e_i)``, and its Hessian has their two diagonal
    blocks only."""
    uA = wv[0]
    uB = wv[1]
    w = wv[2]
    t = wv[3]
    mv(RB, pB, w)
    mv(RA, pA, t)
    val = (xB[i] + w[i]) - (xA[i] + t[i])
    for k in range(3):
        uA[k] = RA[i, k]  # R_A^T e_i
        uB[k] = RB[i, k]
        g[k] = 0.0
        g[6 + k] = 0.0
    g[i] = -1.0
    g[6 + i] = 1.0
    g[3] = uA[1] * pA[2] - uA[2] * pA[1]
    g[4] = uA[2] * pA[0] - uA[0] * pA[2]
    g[5] = uA[0] * pA[1] - uA[1] * pA[0]
    g[9] = pB[1] * uB[2] - pB[2] * uB[1]
    g[10] = pB[2] * uB[0] - pB[0] * uB[2]
    g[11] = pB[0] * uB[1] - pB[1] * uB[0]
    if want:
        H[:, :] = 0.0
        skew_skew(pA, uA, ws[1], -1.0, H, 3, 3)
        skew_skew(pB, uB, ws[1], 1.0, H, 9, 9)
    return val


@njit(cache=True)
def _hess_distance(RA, RB, pA, pB, n, RAn, RBn, L, H, ws):
    """Hessian of prim_distance (out of line, see _hess_dot). Its two (3, 12) work arrays
    are the workspace ``ws`` (8, 3, 3), whose matrices the curvature terms take afterwards."""
    # Jd = [-I, R_A pA~, I, -R_B pB~]; H = Jd^T (I - n n^T)/L Jd + curvature terms
    Jd = ws[0:4].reshape((3, 12))
    for i in range(3):
        for j in range(12):
            Jd[i, j] = 0.0
        Jd[i, i] = -1.0
        Jd[i, 6 + i] = 1.0
    mat_skew(RA, pA, 1.0, Jd, 0, 3)
    mat_skew(RB, pB, -1.0, Jd, 0, 9)
    PJ = ws[4:8].reshape((3, 12))
    for j in range(12):
        s = n[0] * Jd[0, j] + n[1] * Jd[1, j] + n[2] * Jd[2, j]
        for i in range(3):
            PJ[i, j] = (Jd[i, j] - n[i] * s) / L
    for a in range(12):
        for b in range(12):
            H[a, b] = Jd[0, a] * PJ[0, b] + Jd[1, a] * PJ[1, b] + Jd[2, a] * PJ[2, b]
    S = ws[0]
    skew_skew(pA, RAn, ws[1], -1.0, S, 0, 0)
    skew_skew(pB, RBn, ws[1], 1.0, ws[2], 0, 0)
    for i in range(3):
        for j in range(3):
            H[3 + i, 3 + j] += S[i, j]
            H[9 + i, 9 + j] += ws[2][i, j]


@njit(cache=True, inline="always")
def prim_distance(xA, RA, xB, RB, pA, pB, g, H, want, ws, wv):
    """Phi = |d|, d = x_B + R_B pB - x_A - R_A pA; returns L (fills n = wv[5])."""
    d = wv[0]
    t = wv[1]
    n = wv[5]
    mv(RB, pB, d)
    mv(RA, pA, t)
    for i in range(3):
        d[i] += xB[i] - xA[i] - t[i]
    L = np.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2)
    for i in range(12):
        g[i] = 0.0
    if L < 1e-300:
        if want:
            H[:, :] = 0.0
        n[:] = 0.0
        return L
    for i in range(3):
        n[i] = d[i] / L
    RAn = wv[2]
    RBn = wv[3]
    mtv(RA, n, RAn)
    mtv(RB, n, RBn)
    for i in range(3):
        g[i] = -n[i]
        g[6 + i] = n[i]
    # g_thA = -pA x (R_A^T n), g_thB = pB x (R_B^T n)
    g[3] = -(pA[1] * RAn[2] - pA[2] * RAn[1])
    g[4] = -(pA[2] * RAn[0] - pA[0] * RAn[2])
    g[5] = -(pA[0] * RAn[1] - pA[1] * RAn[0])
    g[9] = pB[1] * RBn[2] - pB[2] * RBn[1]
    g[10] = pB[2] * RBn[0] - pB[0] * RBn[2]
    g[11] = pB[0] * RBn[1] - pB[1] * RBn[0]
    if want:
        _hess_distance(RA, RB, pA, pB, n, RAn, RBn, L, H, ws)
    return L


@njit(cache=True, inline="always")
def prim_angle(RA, RB, a1, a2, b1, g, H, want, gs, Hs, gc, Hc, ws, wv):
    """Relative rotation angle of B about the third axis of A, in (-pi, pi].

    ``theta = atan2(b . a2, b . a1)`` with ``a1, a2`` the first two axes of marker A and
    ``b`` the first axis of marker B (node-frame vectors ``a1, a2, b1``). Work arrays
    ``gs, Hs, gc, Hc`` have the sizes of ``g, H``.
    """
    s = prim_dot(RA, RB, a2, b1, gs, Hs, want, ws, wv)
    c = prim_dot(RA, RB, a1, b1, gc, Hc, want, ws, wv)
    r2 = s * s + c * c
    th = np.arctan2(s, c)
    for i in range(12):
        g[i] = (c * gs[i] - s * gc[i]) / r2
    if want:
        _hess_angle(s, c, r2, g, gs, gc, Hs, Hc, H)
    return th


@njit(cache=True)
def _hess_angle(s, c, r2, g, gs, gc, Hs, Hc, H):
    """Hessian of prim_angle from those of its two dot products."""
    for i in range(12):
        for j in range(12):
            H[i, j] = (
                (c * Hs[i, j] - s * Hc[i, j] + gs[i] * gc[j] - gc[i] * gs[j]) / r2
                - g[i] * 2.0 * (c * gc[j] + s * gs[j]) / r2
            )


@njit(cache=True)
def unwrap(raw, ref):
    """Angle equal to ``raw`` modulo 2 pi and closest to ``ref`` (accumulates revolutions)."""
    return raw + 2.0 * np.pi * np.round((ref - raw) / (2.0 * np.pi))


@njit(cache=True)
def quad_form(H, v):
    """v^T H v."""
    s = 0.0
    n = v.shape[0]
    for i in range(n):
        for j in range(n):
            s += v[i] * H[i, j] * v[j]
    return s


@njit(cache=True, inline="always")
def add_scaled(c, gs, Hs, g, H, full):
    """``g += c gs`` and, if ``full``, ``H += c Hs`` (gradients (12,), derivatives (12, 12))."""
    for a in range(12):
        g[a] += c * gs[a]
    if full:
        for a in range(12):
            for b in range(12):
                H[a, b] += c * Hs[a, b]


@njit(cache=True, inline="always")
def gather_v(v, dofs, nd, out):
    """Local velocity/acceleration vector (nd,) from the global one (0 for ground dofs)."""
    for i in range(nd):
        gi = dofs[i]
        out[i] = v[gi] if gi >= 0 else 0.0



@njit(cache=True, inline="always")
def scalar_force(s, ks, cs, g, H, vl, Hv, rq, K, Cd, full):
    """The generalised force of a force ``s`` along a scalar coordinate ``q`` of two nodes
    (a distance, a relative angle) with gradient ``g`` (12,) and derivative ``H`` (12, 12):
    residual ``rq = s g`` and, if ``full``, stiffness ``K = s H + g (ks g + cs H^T v)^T``
    and damping ``Cd = cs g g^T``, with ``ks = ds/dq``, ``cs = ds/dqdot`` and ``vl`` (12,)
    the local velocities (``Hv`` (12,) work)."""
    for a in range(12):
        rq[a] = s * g[a]
    if full:
        for b in range(12):
            hv = 0.0
            for a in range(12):
                hv += H[a, b] * vl[a]
            Hv[b] = hv
        for a in range(12):
            for b in range(12):
                K[a, b] = s * H[a, b] + g[a] * (ks * g[b] + cs * Hv[b])
                Cd[a, b] = cs * g[a] * g[b]
