"""The force of a rigid face on one contact point of a flexible washer and its derivatives
(:mod:`~drivedyn.elements.flexible.washer`, whose docstring gives the law): one function per
point for the residual pass, one for the tangent in closed form."""

from __future__ import annotations

import numpy as np
from numba import njit

from drivedyn.elements.contact.impact_laws import power


@njit(cache=True, inline="always")
def node_force(r, rd, xB, RB, vB, wB, pB, nB, af, law, fric, zero, p):
    """Force ``p`` (3, global) of the face on one washer node at ``r`` moving with ``rd``
    (face node B at ``xB``, rotation ``RB``, velocity ``vB``, body angular velocity ``wB``).
    Returns (F normal, delta, V, P_dis, in contact)."""
    K, n, chi, c, vs = law[0], law[1], law[2], law[3], law[4]
    mu, epsv = fric[0], fric[1]
    p[0] = zero
    p[1] = zero
    p[2] = zero
    ng0 = RB[0, 0] * nB[0] + RB[0, 1] * nB[1] + RB[0, 2] * nB[2]
    ng1 = RB[1, 0] * nB[0] + RB[1, 1] * nB[1] + RB[1, 2] * nB[2]
    ng2 = RB[2, 0] * nB[0] + RB[2, 1] * nB[1] + RB[2, 2] * nB[2]
    e0 = r[0] - xB[0]
    e1 = r[1] - xB[1]
    e2 = r[2] - xB[2]
    d0 = e0 - (RB[0, 0] * pB[0] + RB[0, 1] * pB[1] + RB[0, 2] * pB[2])
    d1 = e1 - (RB[1, 0] * pB[0] + RB[1, 1] * pB[1] + RB[1, 2] * pB[2])
    d2 = e2 - (RB[2, 0] * pB[0] + RB[2, 1] * pB[1] + RB[2, 2] * pB[2])
    delta = -(d0 * ng0 + d1 * ng1 + d2 * ng2)
    if delta.real <= 0.0:
        return zero, delta, zero, zero, False
    wg0 = RB[0, 0] * wB[0] + RB[0, 1] * wB[1] + RB[0, 2] * wB[2]
    wg1 = RB[1, 0] * wB[0] + RB[1, 1] * wB[1] + RB[1, 2] * wB[2]
    wg2 = RB[2, 0] * wB[0] + RB[2, 1] * wB[1] + RB[2, 2] * wB[2]
    s0 = rd[0] - vB[0] - (wg1 * e2 - wg2 * e1)
    s1 = rd[1] - vB[1] - (wg2 * e0 - wg0 * e2)
    s2 = rd[2] - vB[2] - (wg0 * e1 - wg1 * e0)
    sn = s0 * ng0 + s1 * ng1 + s2 * ng2
    rate = -sn
    kdn = af * K * power(delta, n)
    V = kdn * delta / (n + 1.0)
    F = kdn * (1.0 + chi * rate / vs) + af * c * rate
    if F.real <= 0.0:
        return zero, delta, V, zero, False
    st0 = s0 - sn * ng0
    st1 = s1 - sn * ng1
    st2 = s2 - sn * ng2
    st2n = st0 * st0 + st1 * st1 + st2 * st2
    g = mu * F / np.sqrt(st2n + epsv * epsv)
    p[0] = F * ng0 - g * st0
    p[1] = F * ng1 - g * st1
    p[2] = F * ng2 - g * st2
    return F, delta, V, (F - kdn) * rate + g * st2n, True


@njit(cache=True)
def node_force_jacobian(r, rd, xB, RB, vB, wB, pB, nB, af, law, fric, dP):
    """Derivatives of :func:`node_force` (in contact, force not clipped) with respect to the
    node position ``r`` (columns 0-2), velocity ``rd`` (3-5) and the face rotation (right
    perturbation, 9-11) into ``dP`` (3, 18); the other columns follow from these (see the
    kernel)."""
    K, n, chi, c, vs = law[0], law[1], law[2], law[3], law[4]
    mu, epsv = fric[0], fric[1]
    ng = (RB[0, 0] * nB[0] + RB[0, 1] * nB[1] + RB[0, 2] * nB[2],
          RB[1, 0] * nB[0] + RB[1, 1] * nB[1] + RB[1, 2] * nB[2],
          RB[2, 0] * nB[0] + RB[2, 1] * nB[1] + RB[2, 2] * nB[2])
    wg = (RB[0, 0] * wB[0] + RB[0, 1] * wB[1] + RB[0, 2] * wB[2],
          RB[1, 0] * wB[0] + RB[1, 1] * wB[1] + RB[1, 2] * wB[2],
          RB[2, 0] * wB[0] + RB[2, 1] * wB[1] + RB[2, 2] * wB[2])
    xo = (xB[0] + RB[0, 0] * pB[0] + RB[0, 1] * pB[1] + RB[0, 2] * pB[2],
          xB[1] + RB[1, 0] * pB[0] + RB[1, 1] * pB[1] + RB[1, 2] * pB[2],
          xB[2] + RB[2, 0] * pB[0] + RB[2, 1] * pB[1] + RB[2, 2] * pB[2])
    e = (r[0] - xB[0], r[1] - xB[1], r[2] - xB[2])
    d = (r[0] - xo[0], r[1] - xo[1], r[2] - xo[2])
    delta = -(d[0] * ng[0] + d[1] * ng[1] + d[2] * ng[2])
    s = (rd[0] - vB[0] - (wg[1] * e[2] - wg[2] * e[1]),
         rd[1] - vB[1] - (wg[2] * e[0] - wg[0] * e[2]),
         rd[2] - vB[2] - (wg[0] * e[1] - wg[1] * e[0]))
    sn = s[0] * ng[0] + s[1] * ng[1] + s[2] * ng[2]
    rate = -sn
    dn1 = power(delta, n) / delta  # delta^(n - 1): delta > 0 in contact
    kdn = af * K * dn1 * delta
    F = kdn * (1.0 + chi * rate / vs) + af * c * rate
    Fd = af * K * n * dn1 * (1.0 + chi * rate / vs)
    Fr = kdn * chi / vs + af * c
    st = (s[0] - sn * ng[0], s[1] - sn * ng[1], s[2] - sn * ng[2])
    den = np.sqrt(st[0] ** 2 + st[1] ** 2 + st[2] ** 2 + epsv * epsv)
    g = mu * F / den
    for col in range(9):
        j = col % 3
        blk = col // 3
        if blk == 0:    # position of the node: d delta = -n_j, ds = e_j x wg, dn = 0
            dd = -(ng[0] if j == 0 else (ng[1] if j == 1 else ng[2]))
            ds0 = (0.0 if j == 0 else (wg[2] if j == 1 else -wg[1]))
            ds1 = (-wg[2] if j == 0 else (0.0 if j == 1 else wg[0]))
            ds2 = (wg[1] if j == 0 else (-wg[0] if j == 1 else 0.0))
            dn0 = dn1 = dn2 = 0.0
        elif blk == 1:  # velocity of the node
            dd = 0.0
            ds0 = 1.0 if j == 0 else 0.0
            ds1 = 1.0 if j == 1 else 0.0
            ds2 = 1.0 if j == 2 else 0.0
            dn0 = dn1 = dn2 = 0.0
        else:           # face rotation: RB <- RB exp(theta_j e_j~)
            b1 = (j + 1) % 3
            b2 = (j + 2) % 3
            # RB (e_j x v) for a body vector v: e_j x v = -v[b2] e_b1 + v[b1] e_b2
            dn0 = -RB[0, b1] * nB[b2] + RB[0, b2] * nB[b1]
            dn1 = -RB[1, b1] * nB[b2] + RB[1, b2] * nB[b1]
            dn2 = -RB[2, b1] * nB[b2] + RB[2, b2] * nB[b1]
            dxo0 = -RB[0, b1] * pB[b2] + RB[0, b2] * pB[b1]
            dxo1 = -RB[1, b1] * pB[b2] + RB[1, b2] * pB[b1]
            dxo2 = -RB[2, b1] * pB[b2] + RB[2, b2] * pB[b1]
            dw0 = -RB[0, b1] * wB[b2] + RB[0, b2] * wB[b1]
            dw1 = -RB[1, b1] * wB[b2] + RB[1, b2] * wB[b1]
            dw2 = -RB[2, b1] * wB[b2] + RB[2, b2] * wB[b1]
            dd = (dxo0 * ng[0] + dxo1 * ng[1] + dxo2 * ng[2]) - (d[0] * dn0 + d[1] * dn1
                                                                 + d[2] * dn2)
            # ds = -(dw x e)
            ds0 = -(dw1 * e[2] - dw2 * e[1])
            ds1 = -(dw2 * e[0] - dw0 * e[2])
            ds2 = -(dw0 * e[1] - dw1 * e[0])
        dsn = ds0 * ng[0] + ds1 * ng[1] + ds2 * ng[2] + s[0] * dn0 + s[1] * dn1 + s[2] * dn2
        dF = Fd * dd - Fr * dsn
        dst0 = ds0 - dsn * ng[0] - sn * dn0
        dst1 = ds1 - dsn * ng[1] - sn * dn1
        dst2 = ds2 - dsn * ng[2] - sn * dn2
        dden = (st[0] * dst0 + st[1] * dst1 + st[2] * dst2) / den
        dg = mu * dF / den - g * dden / den
        c0 = 3 * blk + j if blk < 2 else 9 + j
        dP[0, c0] = dF * ng[0] + F * dn0 - dg * st[0] - g * dst0
        dP[1, c0] = dF * ng[1] + F * dn1 - dg * st[1] - g * dst1
        dP[2, c0] = dF * ng[2] + F * dn2 - dg * st[2] - g * dst2
