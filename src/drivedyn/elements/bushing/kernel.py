"""The bushing kernel: deflections of the two marker frames and their derivative ``B``, the
laws of the six axes and the Maxwell branch update, the residual ``B^T f`` and its tangent
(see :mod:`drivedyn.elements.bushing` for the formulation)."""

from __future__ import annotations

import math

from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.beams.se3 import tangent_inv_coeffs
from drivedyn.elements.framework.contract import LOCAL_SIZE_12, local_arrays_at
from drivedyn.elements.framework.curves import curve_integral, curve_value
from drivedyn.elements.framework.primitives import cross, mm, mtm, mtv, mv, set_skew
from drivedyn.elements.framework.work_arrays import carve
from drivedyn.rotations import log_so3

OUTPUTS = (
    ("force_x", "N", "bushing force along the bushing frame's x axis (the law's value: the "
     "force on body B is -force_x along x, on body A +force_x)"),
    ("force_y", "N", "bushing force along y (as force_x)"),
    ("force_z", "N", "bushing force along z (as force_x)"),
    ("moment_x", "N m", "bushing moment about the bushing frame's x axis (the law's value, "
     "resisting the rotation rotation_x)"),
    ("moment_y", "N m", "bushing moment about y (as moment_x)"),
    ("moment_z", "N m", "bushing moment about z (as moment_x)"),
    ("deflection_x", "m", "displacement of marker B relative to marker A along the bushing "
     "frame's x axis, from the initial configuration"),
    ("deflection_y", "m", "displacement of B relative to A along y"),
    ("deflection_z", "m", "displacement of B relative to A along z"),
    ("rotation_x", "rad", "rotation vector of B relative to A (log of the relative rotation), "
     "x component in the bushing frame"),
    ("rotation_y", "rad", "rotation of B relative to A, y component"),
    ("rotation_z", "rad", "rotation of B relative to A, z component"),
    ("dissipated_power", "W", "power dissipated by the dampers and the Maxwell branches"),
)
NPUB = len(OUTPUTS)  # hidden columns after these: the branch deflections s_b (committed)
COL_DEFL = 6  # first deflection column (committed as x_n)
NLAW = 6  # axes

# work arrays (views of the group's buffer, see _work)
NMAT = 14
NVEC = 12
WORK_SIZE = LOCAL_SIZE_12 + 2 * 72 + 9 * NMAT + 3 * NVEC + 5 * 6 + 12


@njit(cache=True)
def _log_into(Rr, out):
    """``out`` (3,) <- the rotation vector of ``Rr`` (3, 3) without allocating (as
    :func:`drivedyn.rotations.log_so3`, whose near-pi branch it calls beyond 134 deg)."""
    tr = Rr[0, 0] + Rr[1, 1] + Rr[2, 2]
    c = min(1.0, max(-1.0, 0.5 * (tr - 1.0)))
    w0 = 0.5 * (Rr[2, 1] - Rr[1, 2])
    w1 = 0.5 * (Rr[0, 2] - Rr[2, 0])
    w2 = 0.5 * (Rr[1, 0] - Rr[0, 1])
    if c > -0.7:
        s = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        t = math.atan2(s, c)
        if t < 1e-4:
            t2 = t * t
            f = 1.0 / (1.0 - t2 / 6.0 + t2 * t2 / 120.0)
        else:
            f = t / s
        out[0] = f * w0
        out[1] = f * w1
        out[2] = f * w2
    else:
        th = log_so3(Rr)
        out[0] = th[0]
        out[1] = th[1]
        out[2] = th[2]


@njit(cache=True, inline="always")
def _mmt(A, B, out):
    """out = A B^T (3x3)."""
    for i in range(3):
        for j in range(3):
            out[i, j] = A[i, 0] * B[j, 0] + A[i, 1] * B[j, 1] + A[i, 2] * B[j, 2]


@njit(cache=True, inline="always")
def _put(K, r0, c0, M, s):
    """K[r0:r0+3, c0:c0+3] += s M."""
    for i in range(3):
        for j in range(3):
            K[r0 + i, c0 + j] += s * M[i, j]


@njit(cache=True, inline="always")
def _d_tinv(th, t2, cc, ee, y, sgn, out):
    """``out`` (3, 3) <- d(T_s(theta) y)/d theta for ``T_s = I + sgn theta~/2 + cc theta~^2``
    (``sgn = 1``: the inverse tangent ``T^-1``; ``-1``: its transpose), ``cc = c(t)``,
    ``ee = c'(t)/t`` (:func:`~drivedyn.elements.beams.se3.tangent_inv_coeffs`)."""
    ty = th[0] * y[0] + th[1] * y[1] + th[2] * y[2]
    for i in range(3):
        gi = th[i] * ty - t2 * y[i]  # (theta x (theta x y))_i
        for j in range(3):
            v = cc * (th[i] * y[j] - 2.0 * y[i] * th[j]) + ee * gi * th[j]
            if i == j:
                v += cc * ty
            out[i, j] = v
    # -sgn y~ / 2
    h = -0.5 * sgn
    out[0, 1] -= h * y[2]
    out[0, 2] += h * y[1]
    out[1, 0] += h * y[2]
    out[1, 2] -= h * y[0]
    out[2, 0] -= h * y[1]
    out[2, 1] += h * y[0]


@njit(cache=True, inline="always")
def _tinv_apply(th, t2, cc, y, sgn, out):
    """``out`` (3,) <- ``(I + sgn theta~/2 + cc theta~^2) y``."""
    ty = th[0] * y[0] + th[1] * y[1] + th[2] * y[2]
    c0 = th[1] * y[2] - th[2] * y[1]
    c1 = th[2] * y[0] - th[0] * y[2]
    c2 = th[0] * y[1] - th[1] * y[0]
    out[0] = y[0] + 0.5 * sgn * c0 + cc * (th[0] * ty - t2 * y[0])
    out[1] = y[1] + 0.5 * sgn * c1 + cc * (th[1] * ty - t2 * y[1])
    out[2] = y[2] + 0.5 * sgn * c2 + cc * (th[2] * ty - t2 * y[2])


@njit(cache=True, inline="always")
def _axis_laws(e, xv, xd, kx, cx, pre, cid, CX, CY, CD, cstart, f, kt, cv):
    """Static law and damper of each axis of element ``e``: forces ``f``, tangents ``kt``
    (d f / d x) and ``cv`` (d f / d xdot) (6,); returns (potential energy, dissipated
    power)."""
    pot = 0.0
    dis = 0.0
    for j in range(NLAW):
        q = xv[j]
        k = cid[e, j]
        if k >= 0:
            fs, ks = curve_value(CX, CY, CD, cstart, k, q)
            pot += curve_integral(CX, CY, CD, cstart, k, 0.0, q)
        else:
            ks = kx[e, j]
            fs = ks * q
            pot += 0.5 * ks * q * q
        fd = cx[e, j] * xd[j]
        f[j] = fs + pre[e, j] + fd
        kt[j] = ks
        cv[j] = cx[e, j]
        pot += pre[e, j] * q
        dis += fd * xd[j]
    return pot, dis


@njit(cache=True, inline="always")
def _branches(e, xv, es, s0, t, baxis, bk, bc, nbr, f, kt, aux):
    """Maxwell branches of element ``e`` from the committed state ``es[s0:]`` (time, six
    deflections, branch deflections): forces added to ``f``, tangents to ``kt``, the new
    branch deflections into ``aux[e, NPUB + b]``; returns (potential energy, dissipated
    power)."""
    pot = 0.0
    dis = 0.0
    nb = nbr[e]
    if nb == 0:
        return pot, dis
    tn = es[s0]
    h = t - tn if math.isfinite(tn) else 0.0
    if h < 0.0:
        h = 0.0
    for b in range(nb):
        j = baxis[e, b]
        kb = bk[e, b]
        cb = bc[e, b]
        r = h * kb / cb
        E = math.exp(-r)
        phi = -math.expm1(-r) / r if r > 1e-12 else 1.0 - 0.5 * r
        s = phi * (xv[j] - es[s0 + 1 + j]) + E * es[s0 + 1 + NLAW + b]
        fb = kb * s
        f[j] += fb
        kt[j] += kb * phi
        aux[e, NPUB + b] = s
        pot += 0.5 * fb * s
        dis += fb * fb / cb
    return pot, dis


@njit(cache=True)
def _matrices(B, Jv, K, Cd, f, kt, cv, vl, Ra, A, Bm, Mab, U, Rrel, Ti, th, t2, cc, ee, ra, pb,
              T1, T2, T3, T4, Q, Z, N, Sk, D3, sv, ua, fa, Fb, mu, om, v1, v2):
    """Stiffness ``K`` and damping ``Cd`` (12, 12) of one bushing:
    ``K = G(f) + B^T diag(kt) B + B^T diag(cv) dxdot/dq``, ``Cd = B^T diag(cv) B``, with
    ``G(f) = d(B^T f)/dq`` at fixed ``f`` (the geometric part); node rotations perturbed on
    the right. Matrices in node frames: ``Mab = Ra^T Rb``, ``U = Mab Bm``, ``Rrel = A^T U``;
    ``ra`` is marker B's origin from node A (node A frame)."""
    wA = vl[3:6]
    wB = vl[9:12]
    # --- dxdot/dq, translation rows: xdot_d = A^T (Ra^T u + ra x Omega_A),
    # u = xdot_B - xdot_A - Rb (pb x Omega_B)
    cross(pb, wB, sv)
    mv(Mab, sv, v1)
    for i in range(3):
        v2[i] = vl[6 + i] - vl[i]
    mtv(Ra, v2, ua)
    for i in range(3):
        ua[i] -= v1[i]
    Jv[:, :] = 0.0
    set_skew(wA, Sk)
    _mmt(Sk, Ra, T1)  # Omega_A~ Ra^T
    mtm(A, T1, T2)
    for i in range(3):
        for j in range(3):
            Jv[i, j] = T2[i, j]
            Jv[i, 6 + j] = -T2[i, j]
    set_skew(ra, T3)
    mm(Sk, T3, T1)  # Omega_A~ ra~
    set_skew(ua, T3)
    for i in range(3):
        for j in range(3):
            T1[i, j] = T3[i, j] - T1[i, j]
    mtm(A, T1, T2)
    for i in range(3):
        for j in range(3):
            Jv[i, 3 + j] = T2[i, j]
    set_skew(sv, T3)
    mm(Mab, T3, T1)  # Mab s~
    set_skew(pb, T3)
    mm(Mab, T3, T2)  # Mab pb~
    mm(Sk, T2, T3)
    for i in range(3):
        for j in range(3):
            T1[i, j] += T3[i, j]
    mtm(A, T1, T2)
    for i in range(3):
        for j in range(3):
            Jv[i, 9 + j] = T2[i, j]
    # rotation rows: thetadot = Ti omega, omega = Bm^T Omega_B - Rrel^T A^T Omega_A;
    # d thetadot = (DTi[omega] Ti - Ti (Rrel^T A^T Omega_A)~) dxi,
    # dxi = -U^T dphi_A + Bm^T dphi_B
    mtv(A, wA, v1)
    mtv(Rrel, v1, v2)
    mtv(Bm, wB, om)
    for i in range(3):
        om[i] -= v2[i]
    _d_tinv(th, t2, cc, ee, om, 1.0, D3)
    mm(D3, Ti, N)
    set_skew(v2, Sk)
    mm(Ti, Sk, T1)
    for i in range(3):
        for j in range(3):
            N[i, j] -= T1[i, j]
    _mmt(N, U, T1)
    _mmt(N, Bm, T2)
    for i in range(3):
        for j in range(3):
            Jv[3 + i, 3 + j] = -T1[i, j]
            Jv[3 + i, 9 + j] = T2[i, j]
    # --- material part: B^T diag(kt) B + B^T diag(cv) Jv; damping B^T diag(cv) B
    for a in range(12):
        for b in range(12):
            sk = 0.0
            sc_ = 0.0
            sj = 0.0
            for i in range(6):
                sk += B[i, a] * kt[i] * B[i, b]
                sc_ += B[i, a] * cv[i] * B[i, b]
                sj += B[i, a] * cv[i] * Jv[i, b]
            K[a, b] = sk + sj
            Cd[a, b] = sc_
    # --- geometric part, translation: rq = (-Ra fa, fa~ ra, Ra fa, pb~ Mab^T fa), fa = A f_d
    mv(A, f[0:3], fa)
    mtv(Mab, fa, Fb)
    set_skew(fa, Sk)
    mm(Ra, Sk, T1)  # Ra fa~
    _put(K, 0, 3, T1, 1.0)
    _put(K, 6, 3, T1, -1.0)
    _mmt(Sk, Ra, T1)  # fa~ Ra^T
    _put(K, 3, 0, T1, -1.0)
    _put(K, 3, 6, T1, 1.0)
    set_skew(ra, T3)
    mm(Sk, T3, T1)  # fa~ ra~
    _put(K, 3, 3, T1, 1.0)
    set_skew(pb, T3)
    mm(Mab, T3, T2)
    mm(Sk, T2, T1)  # fa~ Mab pb~
    _put(K, 3, 9, T1, -1.0)
    mtm(Mab, Sk, T2)  # Mab^T fa~
    mm(T3, T2, T1)  # pb~ Mab^T fa~
    _put(K, 9, 3, T1, -1.0)
    set_skew(Fb, T2)
    mm(T3, T2, T1)  # pb~ Fb~
    _put(K, 9, 9, T1, 1.0)
    # rotation: rq = (-U mu, Bm mu), mu = Ti^T m; with Q = Dmu Ti, Z = mu~ - Q:
    # d rq_A = U Z dxi, d rq_B = Bm Q dxi
    _tinv_apply(th, t2, cc, f[3:6], -1.0, mu)
    _d_tinv(th, t2, cc, ee, f[3:6], -1.0, D3)
    mm(D3, Ti, Q)
    set_skew(mu, Z)
    for i in range(3):
        for j in range(3):
            Z[i, j] -= Q[i, j]
    mm(U, Z, T1)  # U Z
    _mmt(T1, U, T2)
    _put(K, 3, 3, T2, -1.0)
    _mmt(T1, Bm, T2)
    _put(K, 3, 9, T2, 1.0)
    mm(Bm, Q, T1)  # Bm Q
    _mmt(T1, U, T2)
    _put(K, 9, 3, T2, -1.0)
    _mmt(T1, Bm, T2)
    _put(K, 9, 9, T2, 1.0)


@njit(cache=True, inline="always")
def _work(buf):
    """The work arrays of :func:`bushing_kernel` as views of ``buf`` (:data:`WORK_SIZE`)."""
    o = LOCAL_SIZE_12
    B = carve(buf, o, (6, 12))
    Jv = carve(buf, o + 72, (6, 12))
    o += 144
    S = carve(buf, o, (NMAT, 3, 3))
    o += 9 * NMAT
    V = carve(buf, o, (NVEC, 3))
    o += 3 * NVEC
    rows = carve(buf, o, (5, 6))
    return (local_arrays_at(buf, 0, 12, 0), B, Jv, S, V, rows, carve(buf, o + 30, 12))


@njit(cache=True)
def bushing_kernel(
    pA, pB, RmA, RmB, d0, kx, cx, pre, cid, CX, CY, CD, cstart, baxis, bk, bc, nbr, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    buf = sc.work_buffer(work, WORK_SIZE)
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    L, B, Jv, S, V, rows, vl = _work(buf)
    full = sc.full_pass(want, mode)
    rq, _, _, Cd, K, _ = L
    f, kt, cv, xv, xd = rows[0], rows[1], rows[2], rows[3], rows[4]
    RAg, Mab, U, Rrel, Ti, T1, T2, Q, Z, N, Sk, D3, T3, T4 = (
        S[0], S[1], S[2], S[3], S[4], S[5], S[6], S[7], S[8], S[9], S[10], S[11], S[12], S[13])
    th, PA, PB, ra, sv, ua, fa, Fb, mu, om, v1, v2 = (
        V[0], V[1], V[2], V[3], V[4], V[5], V[6], V[7], V[8], V[9], V[10], V[11])
    for e in range(sc.count(C)):
        nA, nB = sc.pair(C, e)
        Ra = R[nA]
        Rb = R[nB]
        A = RmA[e]
        Bm = RmB[e]
        pb = pB[e]
        # frames: marker A (global), node B in node A's frame, U = A Rrel, Rrel = R_A^T R_B'
        mm(Ra, A, RAg)
        mtm(Ra, Rb, Mab)
        mm(Mab, Bm, U)
        mtm(A, U, Rrel)
        _log_into(Rrel, th)
        t2 = th[0] * th[0] + th[1] * th[1] + th[2] * th[2]
        cc, ee = tangent_inv_coeffs(t2)
        set_skew(th, Sk)
        for i in range(3):
            for j in range(3):
                s2 = Sk[i, 0] * Sk[0, j] + Sk[i, 1] * Sk[1, j] + Sk[i, 2] * Sk[2, j]
                Ti[i, j] = (1.0 if i == j else 0.0) + 0.5 * Sk[i, j] + cc * s2
        # marker origins, the arm of marker B from node A (node A frame), deflections
        mv(Ra, pA[e], v1)
        mv(Rb, pb, v2)
        for i in range(3):
            PA[i] = x[nA, i] + v1[i]
            PB[i] = x[nB, i] + v2[i]
            v1[i] = PB[i] - x[nA, i]
            v2[i] = PB[i] - PA[i]
        mtv(Ra, v1, ra)
        mtv(RAg, v2, fa)  # (fa as scratch: R_A^T (p_B - p_A))
        for i in range(3):
            xv[i] = fa[i] - d0[e, i]
            xv[3 + i] = th[i]
        # B = d x / d q (6, 12): rows d (translation), theta (rotation)
        B[:, :] = 0.0
        set_skew(ra, Sk)
        mtm(A, Sk, T1)  # A^T ra~
        set_skew(pb, Sk)
        mm(Mab, Sk, T2)  # Mab pb~
        mtm(A, T2, T3)  # A^T Mab pb~
        for i in range(3):
            for j in range(3):
                B[i, j] = -RAg[j, i]
                B[i, 3 + j] = T1[i, j]
                B[i, 6 + j] = RAg[j, i]
                B[i, 9 + j] = -T3[i, j]
        _mmt(Ti, U, T1)  # Ti U^T
        _mmt(Ti, Bm, T2)  # Ti Bm^T
        for i in range(3):
            for j in range(3):
                B[3 + i, 3 + j] = -T1[i, j]
                B[3 + i, 9 + j] = T2[i, j]
        sc.velocities(C, e, 12, vl)
        for i in range(6):
            sv_ = 0.0
            for a in range(12):
                sv_ += B[i, a] * vl[a]
            xd[i] = sv_
        # laws
        pot, dis = _axis_laws(e, xv, xd, kx, cx, pre, cid, CX, CY, CD, cstart, f, kt, cv)
        p2, d2 = _branches(e, xv, es, sc.state_offset(C, e), t, baxis, bk, bc, nbr, f, kt, aux)
        pot += p2
        dis += d2
        for a in range(12):
            r_ = 0.0
            for i in range(6):
                r_ += B[i, a] * f[i]
            rq[a] = r_
        if full:
            _matrices(B, Jv, K, Cd, f, kt, cv, vl, Ra, A, Bm, Mab, U, Rrel, Ti, th, t2, cc, ee,
                      ra, pb, T1, T2, T3, T4, Q, Z, N, Sk, D3, sv, ua, fa, Fb, mu, om, v1, v2)
        sc.scatter(C, L, e, 2, full)
        sc.energy(C, e, 0.0, pot, 0.0, dis)
        for j in range(6):
            aux[e, j] = f[j]
            aux[e, COL_DEFL + j] = xv[j]
        aux[e, 12] = dis
