"""Mesh kinematics of the gear pair (numba): the mesh coordinates ``s`` of two wheel
configurations, with their first and second derivatives, and the chain rule that turns the
mesh law's derivatives in ``s`` into the element matrices in the node coordinates.

Two levels (see :mod:`drivedyn.elements.gears`): kinematic primitives ``p(q)`` (projections
of the centre offset ``d = x_mB - x_mA`` on the marker axes, and for bevel and crossed pairs
the dot products of the axes), with gradients ``gp`` and right-trivialised Hessians ``Hp``
from :mod:`drivedyn.elements.framework.primitives`; and the mesh coordinates ``s(p)`` (wheel angles
relative to the mesh frame, centre offset in the mesh frame), with the Jacobian ``Sj`` and
the second derivatives ``Spp``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from drivedyn.elements.framework.primitives import _hess_axial, mtv, mv, prim_dot, unwrap

KIND_PARALLEL = 0
KIND_SKEW = 1  # bevel and crossed axes: references from the other wheel's axis
NS = 5  # mesh coordinates: phi_A, phi_B, delta_a, delta_r, delta_t
NP = 7  # kinematic primitives at most


@njit(cache=True)
def _cross_into(a, b, g, i0):
    """g[i0:i0+3] = a x b."""
    g[i0] = a[1] * b[2] - a[2] * b[1]
    g[i0 + 1] = a[2] * b[0] - a[0] * b[2]
    g[i0 + 2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True)
def _hess_proj_b(RA, RB, pA, bbar, RBwn, RAv, H, Ht, ws):
    """Hessian of ``d . (R_B bbar)`` from prim_axial's with the roles of A and B swapped."""
    _hess_axial(RB, RA, pA, bbar, RBwn, RAv, Ht, ws)
    for i in range(12):
        ii = (i + 6) % 12
        for j in range(12):
            H[i, j] = -Ht[ii, (j + 6) % 12]


@njit(cache=True, inline="always")
def projections(xA, RA, xB, RB, pA, pB, RmA, RmB, nb, p, gp, Hp, Ht, full, wk, ws):
    """``p_i = d . a_i`` (i = 0, 1, 2: marker A's axes) and, if ``nb``, ``p_3+j = d . b_j``
    (j = 0, 1: marker B's x, y axes), ``d = x_mB - x_mA``, with gradients ``gp`` and (if
    ``full``) Hessians ``Hp``. Leaves the global axes of A in ``wk[2:5]``. The lever-arm
    terms of a marker at its node's origin (the usual wheel centre) are skipped: they are
    zero."""
    levA = pA[0] != 0.0 or pA[1] != 0.0 or pA[2] != 0.0
    levB = pB[0] != 0.0 or pB[1] != 0.0 or pB[2] != 0.0
    RApA = wk[0]
    RBpB = wk[1]
    if levA:
        mv(RA, pA, RApA)
    else:
        RApA[:] = 0.0
    if levB:
        mv(RB, pB, RBpB)
    else:
        RBpB[:] = 0.0
    w = wk[5]  # x_B + R_B pB - x_A = d + R_A pA
    d = wk[6]
    wB = wk[7]  # x_B - x_A - R_A pA = d - R_B pB
    for i in range(3):
        w[i] = xB[i] + RBpB[i] - xA[i]
        d[i] = w[i] - RApA[i]
        wB[i] = d[i] - RBpB[i]
    RAw = wk[8]
    RBwB = wk[9]
    mtv(RA, w, RAw)
    t = wk[10]
    for i in range(3):
        u = wk[2 + i]
        mv(RA, RmA[:, i], u)
        p[i] = d[0] * u[0] + d[1] * u[1] + d[2] * u[2]
        g = gp[i]
        for c in range(3):
            g[c] = -u[c]
            g[6 + c] = u[c]
        _cross_into(RmA[:, i], RAw, g, 3)
        if full or levB:
            mtv(RB, u, t)
            _cross_into(pB, t, g, 9)
        else:
            g[9] = 0.0
            g[10] = 0.0
            g[11] = 0.0
        if full:
            _hess_axial(RA, RB, pB, RmA[:, i], RAw, t, Hp[i], ws)
    if nb:
        mtv(RB, wB, RBwB)
        if full:
            for k in range(3):
                wB[k] = -wB[k]  # R_B^T (x_A + R_A pA - x_B) for the swapped Hessian
            mtv(RB, wB, wk[13])
        for j in range(2):
            v = wk[11]
            mv(RB, RmB[:, j], v)
            p[3 + j] = d[0] * v[0] + d[1] * v[1] + d[2] * v[2]
            g = gp[3 + j]
            for c in range(3):
                g[c] = -v[c]
                g[6 + c] = v[c]
            _cross_into(RmB[:, j], RBwB, g, 9)
            if full or levA:
                mtv(RA, v, t)
                _cross_into(t, pA, g, 3)  # -pA x (R_A^T v)
            else:
                g[3] = 0.0
                g[4] = 0.0
                g[5] = 0.0
            if full:
                _hess_proj_b(RA, RB, pA, RmB[:, j], wk[13], t, Hp[3 + j], Ht, ws)


@njit(cache=True, inline="always")
def atan_row(S, Spp, row, ix, iy, x, y, full):
    """Row of ``s = -atan2(y, x)``: first and second derivatives w.r.t. p[ix], p[iy]."""
    r2 = x * x + y * y
    S[row, ix] = y / r2
    S[row, iy] = -x / r2
    if full:
        r4 = r2 * r2
        Spp[row, ix, ix] = -2.0 * x * y / r4
        Spp[row, iy, iy] = 2.0 * x * y / r4
        Spp[row, ix, iy] = (x * x - y * y) / r4
        Spp[row, iy, ix] = Spp[row, ix, iy]
    return -np.arctan2(y, x)



@njit(cache=True, inline="always")
def parallel_coords(p, Sj, Spp, s, ref_a, ref_b, full):
    """Parallel pairs: the mesh coordinates from the projections ``p[0:5]`` (wheel angles
    from the centre line, accumulated from ``ref_a``, ``ref_b``; axial offset; transverse
    centre distance ``a_c``; 0), with ``Sj`` and (if ``full``) ``Spp``. Returns ``a_c`` and
    the components of f_r on A's x and y axes."""
    s[0] = unwrap(atan_row(Sj, Spp, 0, 0, 1, p[0], p[1], full), ref_a)
    s[1] = unwrap(atan_row(Sj, Spp, 1, 3, 4, p[3], p[4], full), ref_b)
    s[2] = p[2]
    Sj[2, 2] = 1.0
    ac = np.sqrt(p[0] * p[0] + p[1] * p[1])
    s[3] = ac
    s[4] = 0.0
    Sj[3, 0] = p[0] / ac
    Sj[3, 1] = p[1] / ac
    if full:
        a3 = ac * ac * ac
        Spp[3, 0, 0] = p[1] * p[1] / a3
        Spp[3, 1, 1] = p[0] * p[0] / a3
        Spp[3, 0, 1] = -p[0] * p[1] / a3
        Spp[3, 1, 0] = Spp[3, 0, 1]
    return ac, p[0] / ac, p[1] / ac  # f_r = (p0 a1 + p1 a2) / a_c


@njit(cache=True)
def skew_coords(RA, RB, RmA, RmB, p, gp, Hp, Sj, Spp, s, ref_a, ref_b, full, ws, wv):
    """Bevel and crossed pairs: the primitives ``b . a1, b . a2, a . b1, a . b2`` (p[3:7])
    and the mesh coordinates phi_A, phi_B (from the other wheel's axis), delta (in the frame
    of A's axis and b projected on A's plane) with their first and (if ``full``) second
    derivatives in p. Returns the components of f_r on A's x and y axes. Out of line, so that
    the parallel-axes loop stays small and fast."""
    p[3] = prim_dot(RA, RB, RmA[:, 0], RmB[:, 2], gp[3], Hp[3], full, ws, wv)
    p[4] = prim_dot(RA, RB, RmA[:, 1], RmB[:, 2], gp[4], Hp[4], full, ws, wv)
    p[5] = prim_dot(RA, RB, RmA[:, 2], RmB[:, 0], gp[5], Hp[5], full, ws, wv)
    p[6] = prim_dot(RA, RB, RmA[:, 2], RmB[:, 1], gp[6], Hp[6], full, ws, wv)
    s[0] = unwrap(atan_row(Sj, Spp, 0, 3, 4, p[3], p[4], full), ref_a)
    s[1] = unwrap(atan_row(Sj, Spp, 1, 5, 6, p[5], p[6], full), ref_b)
    s[2] = p[2]
    Sj[2, 2] = 1.0
    rho2 = p[3] * p[3] + p[4] * p[4]
    rh = np.sqrt(rho2)
    cp = p[3] / rh
    sp = p[4] / rh
    dr = p[0] * cp + p[1] * sp
    dt = p[1] * cp - p[0] * sp
    s[3] = dr
    s[4] = dt
    ps3 = -sp / rh  # d psi / d p3, psi = atan2(p4, p3)
    ps4 = cp / rh
    Sj[3, 0] = cp
    Sj[3, 1] = sp
    Sj[3, 3] = dt * ps3
    Sj[3, 4] = dt * ps4
    Sj[4, 0] = -sp
    Sj[4, 1] = cp
    Sj[4, 3] = -dr * ps3
    Sj[4, 4] = -dr * ps4
    if full:
        r4 = rho2 * rho2
        p33 = 2.0 * p[3] * p[4] / r4
        p44 = -p33
        p34 = (p[4] * p[4] - p[3] * p[3]) / r4
        # delta_r: f_p0psi = -sp, f_p1psi = cp, f_psipsi = -dr, f_psi = dt
        # delta_t: f_p0psi = -cp, f_p1psi = -sp, f_psipsi = -dt, f_psi = -dr
        for row in range(3, 5):
            if row == 3:
                f0, f1, fpp, fp = -sp, cp, -dr, dt
            else:
                f0, f1, fpp, fp = -cp, -sp, -dt, -dr
            Spp[row, 0, 3] = f0 * ps3
            Spp[row, 0, 4] = f0 * ps4
            Spp[row, 1, 3] = f1 * ps3
            Spp[row, 1, 4] = f1 * ps4
            Spp[row, 3, 0] = Spp[row, 0, 3]
            Spp[row, 4, 0] = Spp[row, 0, 4]
            Spp[row, 3, 1] = Spp[row, 1, 3]
            Spp[row, 4, 1] = Spp[row, 1, 4]
            Spp[row, 3, 3] = fpp * ps3 * ps3 + fp * p33
            Spp[row, 4, 4] = fpp * ps4 * ps4 + fp * p44
            Spp[row, 3, 4] = fpp * ps3 * ps4 + fp * p34
            Spp[row, 4, 3] = Spp[row, 3, 4]
    return cp, sp  # f_r = (p3 a1 + p4 a2) / rho



@njit(cache=True)
def chain_matrices(nprim, Sj, Spp, Qs, dQs, dQd, pd, gp, Hp, vl, Qp, Tm, Ap, Bp, AG, K, C):
    """K and C of one element from the mesh law's derivatives in s (``dQs``, ``dQd``), the
    map s(p) (``Sj``, ``Spp``) and the primitives p(q) (``gp``, ``Hp``): with
    ``Q_p = S^T Q_s`` and ``p_dot = G v``, ``K = sum_i Q_p,i H_i + G^T (A G + B H^T v)`` and
    ``C = G^T B G``, ``A = dQ_p/dp``, ``B = dQ_p/dp_dot``. Out of line: only the matrix path
    calls it, and inlined it added ~25 s to the kernel's first compilation."""
    # Tm[l, k] = sum_m Spp[l, m, k] pd[m]  (d s_dot / d p at fixed p_dot)
    for l_ in range(NS):
        for kk in range(nprim):
            acc = 0.0
            for m in range(nprim):
                acc += Spp[l_, m, kk] * pd[m]
            Tm[l_, kk] = acc
    # Ap = sum_j Qs_j Spp_j + S^T dQs S + S^T dQd Tm ;  Bp = S^T dQd S
    for i in range(nprim):
        for kk in range(nprim):
            acc = 0.0
            accb = 0.0
            for j in range(NS):
                acc += Qs[j] * Spp[j, i, kk]
                sji = Sj[j, i]
                if sji != 0.0:
                    for l_ in range(NS):
                        acc += sji * (dQs[j, l_] * Sj[l_, kk] + dQd[j, l_] * Tm[l_, kk])
                        accb += sji * dQd[j, l_] * Sj[l_, kk]
            Ap[i, kk] = acc
            Bp[i, kk] = accb
    # AG = Ap G + Bp (H^T v) ; K = sum_i Qp_i H_i + G^T AG ; C = G^T Bp G. H^T v first, in
    # C's first rows (C is written last): once per primitive instead of once for each of
    # the nprim rows of AG (4200 -> 1320 multiply-adds for a parallel pair; the same
    # values, summed in the same order)
    for kk in range(nprim):
        for b in range(12):
            hv = 0.0
            for a in range(12):
                hv += Hp[kk, a, b] * vl[a]
            C[kk, b] = hv
    for i in range(nprim):
        for b in range(12):
            acc = 0.0
            for kk in range(nprim):
                acc += Ap[i, kk] * gp[kk, b] + Bp[i, kk] * C[kk, b]
            AG[i, b] = acc
    for a in range(12):
        for b in range(12):
            acc = 0.0
            for i in range(nprim):
                acc += Qp[i] * Hp[i, a, b] + gp[i, a] * AG[i, b]
            K[a, b] = acc
    for i in range(nprim):
        for b in range(12):
            acc = 0.0
            for kk in range(nprim):
                acc += Bp[i, kk] * gp[kk, b]
            AG[i, b] = acc
    for a in range(12):
        for b in range(12):
            acc = 0.0
            for i in range(nprim):
                acc += gp[i, a] * AG[i, b]
            C[a, b] = acc
