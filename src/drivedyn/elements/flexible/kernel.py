"""Kernel of the reduced flexible body in a floating frame of reference (family
``flexible_body``).

The body frame is the host node's frame (position ``x`` [m], rotation ``R``, body angular
velocity ``Omega``); a material node ``i`` of the part is at ``r_i = x + R u_i`` with
``u_i = X_i + Phi_i q`` (``X_i`` node position and ``Phi_i`` (3, nq) basis in the host frame,
``q`` the elastic coordinates). With the scalar consistent mass ``Ms`` (n, n) of the part the
body-frame nodal accelerations are::

    a_j = alpha + B u_j + 2 Omega~ Phi_j qd + Phi_j qdd,
    alpha = R^T (xdd - g),  B = Omegad~ + Omega~ Omega~

and virtual work with ``d r_i = dx + R (dtheta x u_i + Phi_i dq)`` gives the exact
generalised inertia forces (no term of the floating frame formulation is dropped)::

    r_x = R (m alpha + B S + 2 Omega~ Phib qd + Phib qdd)                    (global)
    r_th[a] = (S x alpha)_a + e_abc (B_cd G_bd + 2 Omega~_cd H(qd)_bd + H(qdd)_bc)  (body)
    r_q = Phib^T alpha + sum_de B_de P_de + 2 sum_de Omega~_de Q_de qd + Mqq qdd + Kr q + Dr qd

with the inertia invariants (computed once from the mesh, all in the host frame)::

    S = sum_j m_j u_j = S0 + Phib q            (m_j = row sums of Ms)
    G = U^T Ms U = G0 + A q + (A q)^T + q Q q  (3, 3)
    H(w)_bd = U_b^T Ms Phi_d w = A_bd . w + (Q_db q) . w
    P_de = Phi_d^T Ms U_e = A_ed + Q_de q     (nq,)

where ``A_bd = X_b^T Ms Phi_d`` (nq,) and ``Q_bd = Phi_b^T Ms Phi_d`` (nq, nq). The mass
matrix is assembled in closed form, and so are the position and velocity derivatives of the
rest (the stiffness and gyroscopic matrices, :mod:`~drivedyn.elements.flexible.tangent`;
complex steps of the residual, its test oracle, cost three times more). The residual
costs about ``12 nq^2`` multiply-adds.

Elastic coordinates live in *coordinate nodes*: engine nodes whose three translation slots
hold three coordinates ``q`` (their rotation slots and the unused translation slots of the
last one are held at zero by a decoupled spring-mass of very high frequency, so they neither
move nor add low modes). This keeps the solver's six-dof node layout.
"""

from __future__ import annotations

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.flexible.tangent import ffrf_tangent
from drivedyn.elements.framework.contract import local_arrays_at, local_size
from drivedyn.elements.framework.work_arrays import carve


@njit(cache=True)
def ffrf_forces(mass, S0, Phib, G0, A, Q, Qa, Mqq, Kr, Dr, nq, g, R, xdd, Om, Omd, q, qd, qdd,
                zero, Qq, G, Hd, Hdd, B, rx, rth, rq):
    """Generalised inertia, gravity, elastic and damping forces of one body (see the module
    docstring) into ``rx`` (3, global), ``rth`` (3, body) and ``rq`` (nq,). Works in real or
    complex arithmetic (the tangent's test takes complex steps of it; ``zero`` is 0 in that
    arithmetic). Work arrays:
    ``Qq`` (3, 3, nq), ``G, Hd, Hdd, B`` (3, 3), of the arithmetic of ``q``."""
    # alpha = R^T (xdd - g)
    a0 = xdd[0] - g[0]
    a1 = xdd[1] - g[1]
    a2 = xdd[2] - g[2]
    al0 = R[0, 0] * a0 + R[1, 0] * a1 + R[2, 0] * a2
    al1 = R[0, 1] * a0 + R[1, 1] * a1 + R[2, 1] * a2
    al2 = R[0, 2] * a0 + R[1, 2] * a1 + R[2, 2] * a2
    # Qq[b, d, k] = sum_l Q[b, d, k, l] q_l
    for b in range(3):
        for d in range(3):
            for k in range(nq):
                s = zero
                for l in range(nq):
                    s += Q[b, d, k, l] * q[l]
                Qq[b, d, k] = s
    # G, H(qd), H(qdd)
    for b in range(3):
        for d in range(3):
            gs = G0[b, d] + zero
            h1 = zero
            h2 = zero
            for k in range(nq):
                gs += (A[b, d, k] + A[d, b, k] + Qq[b, d, k]) * q[k]
                h1 += (A[b, d, k] + Qq[d, b, k]) * qd[k]
                h2 += (A[b, d, k] + Qq[d, b, k]) * qdd[k]
            G[b, d] = gs
            Hd[b, d] = h1
            Hdd[b, d] = h2
    # S = S0 + Phib q; F_body = m alpha + B S + 2 Om~ Phib qd + Phib qdd
    s0 = S0[0] + zero
    s1 = S0[1] + zero
    s2 = S0[2] + zero
    pd0 = zero
    pd1 = pd0
    pd2 = pd0
    pa0 = pd0
    pa1 = pd0
    pa2 = pd0
    for k in range(nq):
        s0 += Phib[0, k] * q[k]
        s1 += Phib[1, k] * q[k]
        s2 += Phib[2, k] * q[k]
        pd0 += Phib[0, k] * qd[k]
        pd1 += Phib[1, k] * qd[k]
        pd2 += Phib[2, k] * qd[k]
        pa0 += Phib[0, k] * qdd[k]
        pa1 += Phib[1, k] * qdd[k]
        pa2 += Phib[2, k] * qdd[k]
    o0, o1, o2 = Om[0], Om[1], Om[2]
    w0, w1, w2 = Omd[0], Omd[1], Omd[2]
    # B = Omd~ + Om~ Om~ ;  Om~ Om~ = Om Om^T - |Om|^2 I
    oo = o0 * o0 + o1 * o1 + o2 * o2
    B[0, 0] = o0 * o0 - oo
    B[1, 1] = o1 * o1 - oo
    B[2, 2] = o2 * o2 - oo
    B[0, 1] = o0 * o1 - w2
    B[1, 0] = o1 * o0 + w2
    B[0, 2] = o0 * o2 + w1
    B[2, 0] = o2 * o0 - w1
    B[1, 2] = o1 * o2 - w0
    B[2, 1] = o2 * o1 + w0
    # body-frame resultant
    f0 = mass * al0 + B[0, 0] * s0 + B[0, 1] * s1 + B[0, 2] * s2 + 2.0 * (o1 * pd2 - o2 * pd1) + pa0
    f1 = mass * al1 + B[1, 0] * s0 + B[1, 1] * s1 + B[1, 2] * s2 + 2.0 * (o2 * pd0 - o0 * pd2) + pa1
    f2 = mass * al2 + B[2, 0] * s0 + B[2, 1] * s1 + B[2, 2] * s2 + 2.0 * (o0 * pd1 - o1 * pd0) + pa2
    for i in range(3):
        rx[i] = R[i, 0] * f0 + R[i, 1] * f1 + R[i, 2] * f2
    # 2 Om~ = W (rows c, columns d): sum_d W_cd Hd_bd = 2 (Om x Hd[b, :])_c. Written with
    # array indices: a tuple indexed by a loop variable, and a loop over a tuple of index
    # triples, cost the tangent half of its time (tangent.py)
    sa0 = s1 * al2 - s2 * al1
    sa1 = s2 * al0 - s0 * al2
    sa2 = s0 * al1 - s1 * al0
    for a in range(3):  # (a, b, c) cyclic: e_abc = +1
        b = (a + 1) % 3
        c = (a + 2) % 3
        # e_abc X_bc - e_acb X_cb with X_bc = sum_d B_cd G_bd + W_cd Hd_bd, plus Hdd
        t = (sa0 if a == 0 else (sa1 if a == 1 else sa2)) + Hdd[b, c] - Hdd[c, b]
        t += 2.0 * (Om[a] * Hd[b, b] - Om[b] * Hd[b, a] - Om[c] * Hd[c, a] + Om[a] * Hd[c, c])
        for d in range(3):
            t += B[c, d] * G[b, d] - B[b, d] * G[c, d]
        rth[a] = t
    w01 = -2.0 * o2
    w02 = 2.0 * o1
    w12 = -2.0 * o0
    # generalised elastic forces
    for k in range(nq):
        t = Phib[0, k] * al0 + Phib[1, k] * al1 + Phib[2, k] * al2
        for d in range(3):
            for e in range(3):
                t += B[d, e] * (A[e, d, k] + Qq[d, e, k])
        # 2 sum_de Om~_de Q_de qd = sum over pairs d<e of W_de (Q_de - Q_ed) qd
        for l in range(nq):
            t += (w01 * Qa[0, k, l] + w02 * Qa[1, k, l] + w12 * Qa[2, k, l]) * qd[l]
            t += Mqq[k, l] * qdd[l] + Kr[k, l] * q[l] + Dr[k, l] * qd[l]
        rq[k] = t


@njit(cache=True)
def ffrf_mass(mass, S0, Phib, A, Qq, Mqq, nq, R, q, G, Mx):
    """The mass matrix ``d r / d (xdd, Omegad, qdd)`` (6 + nq, 6 + nq) into ``Mx``; needs
    ``Qq`` and ``G`` of the last :func:`ffrf_forces` call (same q)."""
    Mx[:, :] = 0.0
    s0 = S0[0]
    s1 = S0[1]
    s2 = S0[2]
    for k in range(nq):
        s0 += Phib[0, k] * q[k]
        s1 += Phib[1, k] * q[k]
        s2 += Phib[2, k] * q[k]
    tr = G[0, 0] + G[1, 1] + G[2, 2]
    for i in range(3):
        Mx[i, i] = mass
        # -(R S~)[i, :] with S~ = [[0, -s2, s1], [s2, 0, -s0], [-s1, s0, 0]]
        rs0 = R[i, 1] * s2 - R[i, 2] * s1
        rs1 = R[i, 2] * s0 - R[i, 0] * s2
        rs2 = R[i, 0] * s1 - R[i, 1] * s0
        Mx[i, 3] = -rs0
        Mx[i, 4] = -rs1
        Mx[i, 5] = -rs2
        Mx[3, i] = -rs0
        Mx[4, i] = -rs1
        Mx[5, i] = -rs2
        for j in range(3):
            Mx[3 + i, 3 + j] = -G[i, j] + (tr if i == j else 0.0)
    for k in range(nq):
        for i in range(3):
            t = 0.0
            for j in range(3):
                t += R[i, j] * Phib[j, k]
            Mx[i, 6 + k] = t
            Mx[6 + k, i] = t
        for a in range(3):
            b = (a + 1) % 3
            c = (a + 2) % 3
            h = A[b, c, k] + Qq[c, b, k] - A[c, b, k] - Qq[b, c, k]
            Mx[3 + a, 6 + k] = h
            Mx[6 + k, 3 + a] = h
        for l in range(nq):
            Mx[6 + k, 6 + l] = Mqq[k, l]


@njit(cache=True, inline="always")
def _slot(k):
    """Local dof of elastic coordinate ``k`` (after the host node's 6 dofs)."""
    return 6 + 6 * (k // 3) + (k % 3)


@njit(cache=True, inline="always")
def _force_scales(rabs, dofs, Mx, acc, Kr, qv, mass, gvec, nq):
    """Add the sizes of the terms of the floating-frame equations to ``rabs``: per row the
    sum of ``|M_ij a_j|`` (inertia), ``|K_kl q_l|`` (elastic, modal rows) and the weight
    ``mass |g|`` (frame translation rows). The kernel adds each equation's net residual
    only, so without them a body's equations had no force scale beyond that net: their
    residual scaled to 0.99 at any size, a free spinning part's hub equations could not
    converge on the round-off of their cancelling inertia terms (2e-10 N of about 1e3 N),
    and a free flexible part did not take a step. ``acc`` (6 + nq): the frame's and the
    elastic coordinates' accelerations, in the order of ``Mx``."""
    g = np.sqrt(gvec[0] ** 2 + gvec[1] ** 2 + gvec[2] ** 2)
    for i in range(6 + nq):
        ii = i if i < 6 else _slot(i - 6)
        s = mass * g if i < 3 else 0.0
        for j in range(6 + nq):
            s += abs(Mx[i, j] * acc[j])
        if i >= 6:
            for m in range(nq):
                s += abs(Kr[i - 6, m] * qv[m])
        gi = dofs[ii]
        if gi >= 0:
            rabs[gi] += s


@njit(cache=True, inline="always")
def work_size(nd: int, nqm: int) -> int:
    """Entries of the work buffer of a flexible-body group: ``nd`` dofs per element, ``nqm``
    elastic coordinates at most. ``local_size(nd, 0)`` is written out (``nd + 3 nd^2``) so
    that the build takes ``work_size.py_func`` (a compiled call from Python compiles on a
    first run's critical path)."""
    nm = 6 + nqm
    return (nd + 3 * nd * nd) + 2 * nd + 3 * nm * nm + 6 + 4 * nqm + 9 * nqm + 36 + 24 + 63 \
        + 2 * nm


@njit(cache=True, inline="always")
def _work(buf, nd, nqm):
    """The kernel's work arrays as views of ``buf`` (:func:`work_size` entries)."""
    nm = 6 + nqm
    o = local_size(nd, 0)
    vl = carve(buf, o, nd)
    al = carve(buf, o + nd, nd)
    o += 2 * nd
    Mx = carve(buf, o, (nm, nm))
    Kx = carve(buf, o + nm * nm, (nm, nm))
    Cx = carve(buf, o + 2 * nm * nm, (nm, nm))
    o += 3 * nm * nm
    rx = carve(buf, o, 3)
    rth = carve(buf, o + 3, 3)
    o += 6
    rq = carve(buf, o, nqm)
    qv = carve(buf, o + nqm, nqm)
    qdv = carve(buf, o + 2 * nqm, nqm)
    qddv = carve(buf, o + 3 * nqm, nqm)
    o += 4 * nqm
    Qq = carve(buf, o, (3, 3, nqm))
    o += 9 * nqm
    G = carve(buf, o, (3, 3))
    Hd = carve(buf, o + 9, (3, 3))
    Hdd = carve(buf, o + 18, (3, 3))
    Bw = carve(buf, o + 27, (3, 3))
    o += 36
    v3 = carve(buf, o, (8, 3))
    m3 = carve(buf, o + 24, (7, 3, 3))
    o += 87
    vel_m = carve(buf, o, nm)
    acc_m = carve(buf, o + nm, nm)
    return (local_arrays_at(buf, 0, nd, 0), vl, al, Mx, rx, rth, rq, qv, qdv, qddv, Qq, G, Hd,
            Hdd, Bw, Kx, Cx, v3, m3, vel_m, acc_m)


@njit(cache=True)
def flexible_body_kernel(
    mass, S0, Phib, G0, A, Q, Qa, Mqq, Kr, Dr, nqs, hold, gvec, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    nnode = lnodes.shape[1]
    nd = 6 * nnode
    nqm = Kr.shape[1]
    # the work arrays: views of the group's buffer (no allocation per call)
    W = _work(sc.work_buffer(work, work_size(nd, nqm)), nd, nqm)
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    (L, vl, al, Mx, rx, rth, rq, qv, qdv, qddv, Qq, G, Hd, Hdd, Bw, Kx, Cx, v3, m3, vel_m,
     acc_m) = W
    full = sc.full_pass(want, mode)
    rqL, _, M, Cd, K, _ = L
    nnode = C[sc.LNODES].shape[1]
    gnd = x.shape[0] - 1
    nd = 6 * nnode
    for e in range(sc.count(C)):
        nq = nqs[e]
        n0 = sc.node(C, e, 0)
        sc.velocities(C, e, nd, vl)
        sc.accelerations(C, e, nd, al)
        sc.clear(L, full)
        for k in range(nq):
            nk = sc.node(C, e, 1 + k // 3)
            qv[k] = x[nk, k % 3]
            qdv[k] = vl[_slot(k)]
            qddv[k] = al[_slot(k)]
        Re = R[n0]
        ffrf_forces(mass[e], S0[e], Phib[e], G0[e], A[e], Q[e], Qa[e], Mqq[e], Kr[e], Dr[e],
                    nq, gvec, Re, al[0:3], vl[3:6], al[3:6], qv, qdv, qddv, 0.0, Qq, G, Hd, Hdd,
                    Bw, rx, rth, rq)
        for i in range(3):
            rqL[i] = rx[i]
            rqL[3 + i] = rth[i]
        for k in range(nq):
            rqL[_slot(k)] = rq[k]
        # held slots: coordinate nodes' rotations and unused translations
        hm, hk = hold[e, 0], hold[e, 1]
        for j in range(1, nnode):
            nj = sc.node(C, e, j)
            if nj == gnd:
                continue
            Rj = R[nj]
            # vee of the skew part of Rj: the rotation angle to first order
            th = (0.5 * (Rj[2, 1] - Rj[1, 2]), 0.5 * (Rj[0, 2] - Rj[2, 0]),
                  0.5 * (Rj[1, 0] - Rj[0, 1]))
            for t in range(3):
                d = 6 * j + 3 + t
                rqL[d] = hm * al[d] + hk * th[t]
                if 3 * (j - 1) + t >= nq:
                    d = 6 * j + t
                    rqL[d] = hm * al[d] + hk * x[nj, t]
        if full:
            ffrf_mass(mass[e], S0[e], Phib[e], A[e], Qq, Mqq[e], nq, Re, qv, G, Mx)
            for i in range(6 + nq):
                ii = i if i < 6 else _slot(i - 6)
                for j in range(6 + nq):
                    jj = j if j < 6 else _slot(j - 6)
                    M[ii, jj] = Mx[i, j]
            for j in range(1, nnode):
                if sc.node(C, e, j) == gnd:
                    continue
                Rj = R[sc.node(C, e, j)]
                for t in range(3):
                    d = 6 * j + 3 + t
                    M[d, d] = hm
                    # d vee(skew(R))/d theta_c for R <- R exp(theta_c e_c~): column c is
                    # 1/2 vee(R e_c~ - e_c~ R^T) = 1/2 ((tr R) e_c - R^T e_c)
                    trR = Rj[0, 0] + Rj[1, 1] + Rj[2, 2]
                    for c in range(3):
                        K[6 * j + 3 + c, d] = 0.5 * hk * ((trR if c == t else 0.0) - Rj[t, c])
                    if 3 * (j - 1) + t >= nq:
                        M[6 * j + t, 6 * j + t] = hm
                        K[6 * j + t, 6 * j + t] = hk
            # stiffness and gyroscopic matrices in closed form (the state of this
            # element's ffrf_forces call above)
            ffrf_tangent(mass[e], S0[e], Phib[e], A[e], Q[e], Qa[e], Kr[e], Dr[e], nq, gvec,
                         Re, al[0:3], vl[3:6], qv, qdv, qddv, Qq, G, Hd, Bw, Kx, Cx, v3, m3)
            for i in range(6 + nq):
                ii = i if i < 6 else _slot(i - 6)
                for j in range(3, 6 + nq):
                    jj = j if j < 6 else _slot(j - 6)
                    K[ii, jj] = Kx[i, j]
                    Cd[ii, jj] = Cx[i, j]
        sc.scatter(C, L, e, nnode, full)
        # energies: T = 1/2 v^T M v (needs M: build it if not done)
        if not full:
            ffrf_mass(mass[e], S0[e], Phib[e], A[e], Qq, Mqq[e], nq, Re, qv, G, Mx)
        # the velocities and accelerations in the order of Mx, once (not picked per entry)
        for i in range(6 + nq):
            vel_m[i] = vl[i] if i < 6 else qdv[i - 6]
            acc_m[i] = al[i] if i < 6 else qddv[i - 6]
        kin = 0.0
        for i in range(6 + nq):
            for j in range(6 + nq):
                kin += 0.5 * vel_m[i] * Mx[i, j] * vel_m[j]
        # Mx rows 0-2 use the global xdot, rows 3-5 the body Omega (as the residual)
        el = 0.0
        dis = 0.0
        for k in range(nq):
            for l in range(nq):
                el += 0.5 * qv[k] * Kr[e, k, l] * qv[l]
                dis += qdv[k] * Dr[e, k, l] * qdv[l]
        s0 = S0[e, 0]
        s1 = S0[e, 1]
        s2 = S0[e, 2]
        for k in range(nq):
            s0 += Phib[e, 0, k] * qv[k]
            s1 += Phib[e, 1, k] * qv[k]
            s2 += Phib[e, 2, k] * qv[k]
        grav = 0.0
        for i in range(3):
            rs = Re[i, 0] * s0 + Re[i, 1] * s1 + Re[i, 2] * s2
            grav -= gvec[i] * (mass[e] * x[n0, i] + rs)
        sc.energy(C, e, kin, el + grav, 0.0, dis)
        _force_scales(C[sc.RABS], C[sc.DOFS][e], Mx, acc_m, Kr[e], qv, mass[e], gvec, nq)
        aux[e, 0] = el
        for k in range(nq):
            aux[e, 1 + k] = qv[k]
