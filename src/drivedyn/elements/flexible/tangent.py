"""The stiffness and gyroscopic matrices of the floating-frame body in closed form: the
derivatives of :func:`~drivedyn.elements.flexible.kernel.ffrf_forces` with respect to the
frame's rotation and the elastic coordinates (positions) and to the body angular velocity
and the elastic velocities (velocities).

Each column is the linearisation of the forces along one direction, written from the
intermediate quantities of the residual (``alpha, S, Pd, B, W = 2 Omega~, G, Hd, Qq``; the
module docstring of :mod:`~drivedyn.elements.flexible.kernel` gives the forces)::

    d rx  = R (m d alpha + dB S + B dS + dW Pd + W dPd)  (+ R (e_j x f) for a rotation)
    d rth = dS x alpha + S x d alpha + skew parts of (dB G^T + B dG^T + dW Hd^T + W dHd^T)
            + dHdd - dHdd^T
    d rq  = Phib^T d alpha + sum_de dB_de P_de + B_de dP_de + (dW, W) Qa (qd, d qd)
            + Kr dq + Dr dqd

with, per direction, a right rotation ``theta_j`` (``d alpha = alpha x e_j``), an elastic
coordinate ``q_j`` (``dS = Phib_j``, ``dG``, ``dHd``, ``dHdd``, ``dP`` from ``A`` and ``Q``),
the angular velocity ``Omega_j`` (``dB = e_j Omega^T + Omega e_j^T - 2 Omega_j I``,
``dW = 2 e_j~``) and an elastic velocity ``qd_j`` (``dPd = Phib_j``, ``dHd``). The same
matrices as complex steps of the residual to round-off (``tests/elements/test_ffrf_tangent.py``)
in a seventh of their time: 2.8 us against 19.2 us for nq = 7 (20 complex evaluations; 5.8
us while the Levi-Civita triples were a loop over a global tuple of tuples, which numba
compiles to a slow generic iteration); the Type C bench's five flexible washers' matrix
pass went from 74 to 42 us, then 26 us (``benchmarks/compiled_step_costs.py``).
"""

from __future__ import annotations

from numba import njit


@njit(cache=True, inline="always")
def _column(mass, Phib, A, Qq, Qa, nq, R, al, S, Pd, f, B, W, G, Hd, qd, dal, dS, dPd, dB,
            dW, dG, dHd, dHdd, rot, T, col, spin):
    """Column ``col`` of ``T`` (6 + nq rows: rx, rth, rq) along a direction given by the
    changes of the intermediate quantities; ``rot`` the axis of a right rotation of the
    frame (-1: none); ``spin``: the direction changes ``B`` and ``W`` (an angular velocity:
    the only columns whose rq rows have the ``dB (A + Qq)`` and ``dW Qa qd`` terms). The rq
    terms of a direction's own coordinates (``B dP``, ``Kr``, ``Dr``, ``W Qa dqd``) are the
    caller's."""
    df0 = mass * dal[0]
    df1 = mass * dal[1]
    df2 = mass * dal[2]
    for d in range(3):
        df0 += dB[0, d] * S[d] + B[0, d] * dS[d] + dW[0, d] * Pd[d] + W[0, d] * dPd[d]
        df1 += dB[1, d] * S[d] + B[1, d] * dS[d] + dW[1, d] * Pd[d] + W[1, d] * dPd[d]
        df2 += dB[2, d] * S[d] + B[2, d] * dS[d] + dW[2, d] * Pd[d] + W[2, d] * dPd[d]
    if rot >= 0:  # d(R exp(theta~) f) = R (e_j x f)
        if rot == 0:
            df1 -= f[2]
            df2 += f[1]
        elif rot == 1:
            df0 += f[2]
            df2 -= f[0]
        else:
            df0 -= f[1]
            df1 += f[0]
    for i in range(3):
        T[i, col] = R[i, 0] * df0 + R[i, 1] * df1 + R[i, 2] * df2
    for a in range(3):  # (a, b, c) cyclic (a loop over a global tuple cost 2.8 of 5.8 us)
        b = (a + 1) % 3
        c = (a + 2) % 3
        t = (dS[b] * al[c] - dS[c] * al[b] + S[b] * dal[c] - S[c] * dal[b]
             + dHdd[b, c] - dHdd[c, b])
        for d in range(3):
            t += (dB[c, d] * G[b, d] + B[c, d] * dG[b, d] + dW[c, d] * Hd[b, d]
                  + W[c, d] * dHd[b, d] - dB[b, d] * G[c, d] - B[b, d] * dG[c, d]
                  - dW[b, d] * Hd[c, d] - W[b, d] * dHd[c, d])
        T[3 + a, col] = t
    for k in range(nq):
        t = Phib[0, k] * dal[0] + Phib[1, k] * dal[1] + Phib[2, k] * dal[2]
        if spin:
            for d in range(3):
                for e in range(3):
                    t += dB[d, e] * (A[e, d, k] + Qq[d, e, k])
            for m in range(nq):
                t += (dW[0, 1] * Qa[0, k, m] + dW[0, 2] * Qa[1, k, m]
                      + dW[1, 2] * Qa[2, k, m]) * qd[m]
        T[6 + k, col] = t


@njit(cache=True)
def ffrf_tangent(mass, S0, Phib, A, Q, Qa, Kr, Dr, nq, g, R, xdd, Om, q, qd, qdd, Qq, G, Hd,
                 B, Kx, Cx, v3, m3):
    """Derivatives of :func:`~drivedyn.elements.flexible.kernel.ffrf_forces` at the state
    of its last call (``Qq, G, Hd, B`` of that call, the same ``R, xdd, Om, q, qd, qdd``):
    ``Kx`` (6 + nq, 6 + nq) with respect to ``[x, theta, q]`` (right rotation of the frame)
    and ``Cx`` with respect to ``[v, Omega, qd]``; rows ``[rx, rth, rq]``. The columns of x
    and v are zero (the forces do not depend on them). Work arrays: ``v3`` (8, 3),
    ``m3`` (7, 3, 3)."""
    al, S, Pd, f, dal, dS, dPd, z3 = v3[0], v3[1], v3[2], v3[3], v3[4], v3[5], v3[6], v3[7]
    W, dB, dW, dG, dHd, dHdd, Z = m3[0], m3[1], m3[2], m3[3], m3[4], m3[5], m3[6]
    for i in range(6 + nq):
        for j in range(6 + nq):
            Kx[i, j] = 0.0
            Cx[i, j] = 0.0
    a0 = xdd[0] - g[0]
    a1 = xdd[1] - g[1]
    a2 = xdd[2] - g[2]
    for i in range(3):
        al[i] = R[0, i] * a0 + R[1, i] * a1 + R[2, i] * a2
        s = S0[i]
        p = 0.0
        pa = 0.0
        for k in range(nq):
            s += Phib[i, k] * q[k]
            p += Phib[i, k] * qd[k]
            pa += Phib[i, k] * qdd[k]
        S[i] = s
        Pd[i] = p
        z3[i] = pa  # Pa
    o0, o1, o2 = Om[0], Om[1], Om[2]
    W[0, 0] = 0.0
    W[1, 1] = 0.0
    W[2, 2] = 0.0
    W[0, 1] = -2.0 * o2
    W[0, 2] = 2.0 * o1
    W[1, 0] = 2.0 * o2
    W[1, 2] = -2.0 * o0
    W[2, 0] = -2.0 * o1
    W[2, 1] = 2.0 * o0
    for i in range(3):
        t = mass * al[i] + z3[i]
        for d in range(3):
            t += B[i, d] * S[d] + W[i, d] * Pd[d]
        f[i] = t
    for i in range(3):
        z3[i] = 0.0
        for j in range(3):
            Z[i, j] = 0.0
    # frame rotation theta_j: d alpha = alpha x e_j
    for j in range(3):
        dal[0] = 0.0 if j == 0 else (al[1] if j == 2 else -al[2])
        dal[1] = 0.0 if j == 1 else (al[2] if j == 0 else -al[0])
        dal[2] = 0.0 if j == 2 else (al[0] if j == 1 else -al[1])
        _column(mass, Phib, A, Qq, Qa, nq, R, al, S, Pd, f, B, W, G, Hd, qd, dal, z3, z3, Z,
                Z, Z, Z, Z, j, Kx, 3 + j, False)
    for i in range(3):
        dal[i] = 0.0
    # elastic coordinate q_j
    for j in range(nq):
        for b in range(3):
            dS[b] = Phib[b, j]
            for d in range(3):
                sg = A[b, d, j] + A[d, b, j] + Qq[b, d, j]
                sh = 0.0
                sa = 0.0
                for k in range(nq):
                    sg += Q[b, d, k, j] * q[k]
                    sh += Q[d, b, k, j] * qd[k]
                    sa += Q[d, b, k, j] * qdd[k]
                dG[b, d] = sg
                dHd[b, d] = sh
                dHdd[b, d] = sa
        _column(mass, Phib, A, Qq, Qa, nq, R, al, S, Pd, f, B, W, G, Hd, qd, dal, dS, z3, Z,
                Z, dG, dHd, dHdd, -1, Kx, 6 + j, False)
        for k in range(nq):
            t = Kr[k, j]
            for d in range(3):
                for e in range(3):
                    t += B[d, e] * Q[d, e, k, j]
            Kx[6 + k, 6 + j] += t
    # body angular velocity Omega_j: dB = e_j Om^T + Om e_j^T - 2 Om_j I, dW = 2 e_j~
    for j in range(3):
        for r in range(3):
            for c in range(3):
                dB[r, c] = ((Om[c] if r == j else 0.0) + (Om[r] if c == j else 0.0)
                            - (2.0 * Om[j] if r == c else 0.0))
                dW[r, c] = 0.0
        b1 = (j + 1) % 3
        b2 = (j + 2) % 3
        dW[b2, b1] = 2.0
        dW[b1, b2] = -2.0
        _column(mass, Phib, A, Qq, Qa, nq, R, al, S, Pd, f, B, W, G, Hd, qd, dal, z3, z3, dB,
                dW, Z, Z, Z, -1, Cx, 3 + j, True)
    # elastic velocity qd_j
    for j in range(nq):
        for b in range(3):
            dPd[b] = Phib[b, j]
            for d in range(3):
                dHd[b, d] = A[b, d, j] + Qq[d, b, j]
        _column(mass, Phib, A, Qq, Qa, nq, R, al, S, Pd, f, B, W, G, Hd, qd, dal, z3, dPd, Z,
                Z, Z, dHd, Z, -1, Cx, 6 + j, False)
        for k in range(nq):
            Cx[6 + k, 6 + j] += (W[0, 1] * Qa[0, k, j] + W[0, 2] * Qa[1, k, j]
                                 + W[1, 2] * Qa[2, k, j] + Dr[k, j])
