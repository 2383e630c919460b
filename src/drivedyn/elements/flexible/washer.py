"""Rigid annular face on the contact points of a flexible washer (family
``flexible_washer_contact``).

The washer is a :class:`~drivedyn.elements.flexible.family.FlexibleBody`; its contact face is
sampled at points ``i`` with areas ``A_i`` (sum ``S``): either its surface nodes with their
tributary areas (the consistent load of a unit pressure), or the points and weights of a
quadrature rule of the face, where the displacement basis ``Phi_i`` is the mesh's shape
functions' interpolation. A rule integrates the face's smooth pressure with far fewer points
than the nodes: on the Type C's washers, 24 points (2 Gauss radii in each of the 2 cells
across, 6 angles; :func:`drivedyn.fe.annulus_quadrature`) against the 240 nodes of the face
(24 cells around); its four TDRs lie within 0.012 % of the node sums extrapolated to a fine
mesh, where the node sums on that mesh lie 0.14-0.25 % below (the mesh's mid-side nodes sit
inside the circle; the rule integrates over the annulus). Below, "node" is a contact point.

The counter face is the plane through the origin of ``marker_b`` with normal ``n = z_B``
pointing from the plane towards the washer. Per node, with ``r_i = x + R (X_i + Phi_i q)``::

    delta_i = -(r_i - x_B) . n                     penetration [m]
    s_i = rdot_i - v_B(r_i)                        velocity relative to the face [m/s]
    F_i = (A_i / S) F_law(delta_i, -s_i . n)        normal force [N]
    f_i = -mu F_i s_t / sqrt(|s_t|^2 + eps_v^2)     friction (s_t: s_i in the plane) [N]

``F_law`` is the face's :class:`~drivedyn.elements.contact.impact_laws.NormalLaw` for the whole face
(stiffness ``K`` [N/m^n]) with the approach speed fixed at ``min_impact_speed`` (no impact
state per node), so a uniform penetration gives the force of the rigid
:class:`~drivedyn.elements.contact.ThrustWasherContact` with the same law; the pressure at
node ``i`` is ``p_i = F_i / A_i`` [Pa]. The friction is Coulomb's with the smooth
regularisation above (kinetic ``mu`` of the :class:`FrictionLaw`; a Stribeck peak is not
used here). The friction torque and the axial force are sums over the nodes, so they follow
the pressure distribution: a uniform pressure gives ``M = mu F r_m`` with the friction radius
``r_m = 2 (r_e^3 - r_i^3) / (3 (r_e^2 - r_i^2))``.

The forces act on the washer's generalised coordinates through the virtual work of the node
displacements (host node, elastic coordinates) and on the face's node at the same points.
The tangent matrices are assembled from the nodes in contact: the derivatives of the nodal
force with respect to the node's position and velocity and to the face's rotation in closed
form (:func:`node_force_jacobian`; those with respect to the face's position and velocities
follow from them), chained with the node's kinematic Jacobian (``Dp``, ``Dv``: 3 x ncol per
node), plus the geometric terms of the Jacobians themselves (the force held). The nodes'
rows of the virtual work ``W`` (3 x ncol) and their ``Dp``, ``Dv`` are stacked, and the
element's matrices are the two products ``W^T Dp`` and ``W^T Dv`` over all nodes in contact
(BLAS): node by node they were most of the kernel's work (the Type C bench with five
flexible washers, four modes: 7.5-8.0 s against 8.2-8.35 s for the command, the same TDRs
within 3e-5).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.contact.common import check_laws, coerce_laws
from drivedyn.elements.contact.friction import FrictionLaw
from drivedyn.elements.contact.impact_laws import NormalLaw, law_table
from drivedyn.elements.flexible.family import flexible_body_named, invariants
from drivedyn.elements.flexible.washer_point import node_force, node_force_jacobian
from drivedyn.elements.framework.building import make_group, what_of
from drivedyn.elements.framework.contract import local_arrays_at, local_size
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.registry import Family, TwoMarkerSpec, register
from drivedyn.elements.framework.work_arrays import carve
from drivedyn.errors import ModelError
from drivedyn.rotations import skew_into

OUTPUTS = (
    ("normal_force", "N", "axial contact force, sum over the contact points"),
    ("max_pressure", "Pa", "largest contact pressure over the contact points"),
    ("pressure", "Pa", "mean contact pressure: normal force / face area"),
    ("penetration", "m", "largest nodal penetration (< 0: open gap)"),
    ("friction_torque", "N m", "friction moment on the washer about the face normal"),
    ("pressure_radius", "m", "pressure-weighted mean radius of the contact"),
    ("dissipated_power", "W", "power dissipated by friction and contact damping"),
)
NOUT = len(OUTPUTS)


@njit(cache=True, inline="always")
def work_size(nd: int, nqm: int, nfm: int) -> int:
    """Entries of the work buffer of a face-contact group: ``nd`` dofs per element, ``nqm``
    elastic coordinates and ``nfm`` face nodes at most. ``local_size(nd, 0)`` is written
    out (``nd + 3 nd^2``) so that the build takes ``work_size.py_func``: a compiled call
    from Python compiles on a first run's critical path."""
    ncol = 12 + nqm
    return (nd + 3 * nd * nd + nd + 2 * nqm + 24 + 6 * ncol + 81 + 9 * nfm * ncol
            + 2 * ncol * ncol + 33 + 6 * ncol)


@njit(cache=True, inline="always")
def _work(buf, nd, nqm, nfm, ncol):
    """The kernel's work arrays as views of ``buf`` (:func:`work_size` entries), the node
    stacks and the element's matrices for ``ncol`` columns (at most ``12 + nqm``): the
    virtual work's rows but the translations' (``ncol - 6``) and the sums of the nodes'
    rows ``Sp``, ``Sv`` (3, ncol), the translations' products."""
    o = local_size(nd, 0)
    vl = carve(buf, o, nd)
    qv = carve(buf, o + nd, nqm)
    qdv = carve(buf, o + nd + nqm, nqm)
    o += nd + 2 * nqm
    v3 = (carve(buf, o, 3), carve(buf, o + 3, 3), carve(buf, o + 6, 3), carve(buf, o + 9, 3),
          carve(buf, o + 12, 3), carve(buf, o + 15, 3), carve(buf, o + 18, 3),
          carve(buf, o + 21, 3))
    o += 24
    Jr = carve(buf, o, (3, ncol))
    Jd = carve(buf, o + 3 * ncol, (3, ncol))
    o += 6 * (12 + nqm)
    dP = carve(buf, o, (3, 18))
    S1 = carve(buf, o + 54, (3, 3))
    S2 = carve(buf, o + 63, (3, 3))
    S3 = carve(buf, o + 72, (3, 3))
    o += 81
    n = 3 * nfm * (12 + nqm)
    Ws = carve(buf, o, (3 * nfm, ncol - 6))
    Dps = carve(buf, o + n, (3 * nfm, ncol))
    Dvs = carve(buf, o + 2 * n, (3 * nfm, ncol))
    o += 3 * n
    Kc = carve(buf, o, (ncol - 6, ncol))
    Cc = carve(buf, o + (12 + nqm) ** 2, (ncol - 6, ncol))
    o += 2 * (12 + nqm) ** 2
    Dq = carve(buf, o, (3, 3))
    Tr = carve(buf, o + 9, (3, 3))
    Tb = carve(buf, o + 18, (3, 3))
    ng = carve(buf, o + 27, 3)
    xo = carve(buf, o + 30, 3)
    Sp = carve(buf, o + 33, (3, ncol))
    Sv = carve(buf, o + 33 + 3 * (12 + nqm), (3, ncol))
    return (local_arrays_at(buf, 0, nd, 0), vl, qv, qdv, *v3, Jr, Jd, dP, S1, S2, S3, Ws, Dps,
            Dvs, Kc, Cc, Dq, Tr, Tb, ng, xo, Sp, Sv)


@njit(cache=True)
def flexible_washer_kernel(
    X, Phi, af, nfs, nqs, area, law, fric, pB, nB, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    nd = 6 * lnodes.shape[1]
    nqm = Phi.shape[3]
    nfm = X.shape[1]
    buf = sc.work_buffer(work, work_size(nd, nqm, nfm))  # the work arrays: views of it
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    full = sc.full_pass(want, mode)
    nnode = C[sc.LNODES].shape[1]
    nd = 6 * nnode
    for e in range(sc.count(C)):
        nb = sc.node(C, e, 0)
        nh = sc.node(C, e, 1)
        nq = nqs[e]
        nf = nfs[e]
        ncol = 12 + nq
        (L, vl, qv, qdv, u, ud, r, rd, p, a, b, rho, Jr, Jd, dP, S1, S2, S3, Ws, Dps, Dvs, Kc,
         Cc, Dq, Tr, Tb, ng, xo, Sp, Sv) = _work(buf, nd, nqm, nfm, ncol)
        if full:
            for d in range(3):
                for cc in range(ncol):
                    Sp[d, cc] = 0.0
                    Sv[d, cc] = 0.0
        rq, _, _, Cd, K, _ = L
        ns = 0  # nodes in contact stacked in Ws, Dps, Dvs (the matrix pass)
        sc.velocities(C, e, nd, vl)
        sc.clear(L, full)
        for k in range(nq):
            qv[k] = x[sc.node(C, e, 2 + k // 3), k % 3]
            qdv[k] = vl[12 + 6 * (k // 3) + (k % 3)]
        xB = x[nb]
        RB = R[nb]
        xh = x[nh]
        Rh = R[nh]
        Ftot = 0.0
        Mf = 0.0
        Vt = 0.0
        Pd = 0.0
        pen = -1e300
        Fr = 0.0
        pmax = 0.0
        # face normal and origin (global)
        for d in range(3):
            ng[d] = RB[d, 0] * nB[e, 0] + RB[d, 1] * nB[e, 1] + RB[d, 2] * nB[e, 2]
            xo[d] = xB[d] + RB[d, 0] * pB[e, 0] + RB[d, 1] * pB[e, 1] + RB[d, 2] * pB[e, 2]
        for i in range(nf):
            # node position: u (body), r (global); the velocity only for nodes in contact
            for d in range(3):
                ua = X[e, i, d]
                for k in range(nq):
                    ua += Phi[e, i, d, k] * qv[k]
                u[d] = ua
            for d in range(3):
                r[d] = xh[d] + Rh[d, 0] * u[0] + Rh[d, 1] * u[1] + Rh[d, 2] * u[2]
            gap = (ng[0] * (r[0] - xo[0]) + ng[1] * (r[1] - xo[1]) + ng[2] * (r[2] - xo[2]))
            aux[e, NOUT + i] = 0.0
            if gap >= 0.0:
                if -gap > pen:
                    pen = -gap
                continue
            for d in range(3):
                va = 0.0
                for k in range(nq):
                    va += Phi[e, i, d, k] * qdv[k]
                ud[d] = va
            w0, w1, w2 = vl[9], vl[10], vl[11]
            t0 = w1 * u[2] - w2 * u[1] + ud[0]
            t1 = w2 * u[0] - w0 * u[2] + ud[1]
            t2 = w0 * u[1] - w1 * u[0] + ud[2]
            for d in range(3):
                rd[d] = vl[6 + d] + Rh[d, 0] * t0 + Rh[d, 1] * t1 + Rh[d, 2] * t2
            F, delta, V, Pdi, on = node_force(r, rd, xB, RB, vl[0:3], vl[3:6], pB[e], nB[e],
                                              af[e, i], law[e], fric[e], 0.0, p)
            if delta > pen:
                pen = delta
            Vt += V
            if not on:
                continue
            Pd += Pdi
            Ftot += F
            pi = F / (af[e, i] * area[e])
            aux[e, NOUT + i] = pi
            if pi > pmax:
                pmax = pi
            # radius about the face normal and friction moment on the washer
            ng0, ng1, ng2 = ng[0], ng[1], ng[2]
            d0 = r[0] - xo[0]
            d1 = r[1] - xo[1]
            d2 = r[2] - xo[2]
            dn = d0 * ng0 + d1 * ng1 + d2 * ng2
            Fr += F * np.sqrt(max(d0 * d0 + d1 * d1 + d2 * d2 - dn * dn, 0.0))
            Mf += ng0 * (d1 * p[2] - d2 * p[1]) + ng1 * (d2 * p[0] - d0 * p[2]) \
                + ng2 * (d0 * p[1] - d1 * p[0])
            # residual: washer -J_r^T p, face J_B^T p
            for d in range(3):
                a[d] = Rh[0, d] * p[0] + Rh[1, d] * p[1] + Rh[2, d] * p[2]   # Rh^T p
                b[d] = RB[0, d] * p[0] + RB[1, d] * p[1] + RB[2, d] * p[2]   # RB^T p
                rho[d] = (RB[0, d] * (r[0] - xB[0]) + RB[1, d] * (r[1] - xB[1])
                          + RB[2, d] * (r[2] - xB[2]))
            rq[6] -= p[0]
            rq[7] -= p[1]
            rq[8] -= p[2]
            rq[9] -= u[1] * a[2] - u[2] * a[1]
            rq[10] -= u[2] * a[0] - u[0] * a[2]
            rq[11] -= u[0] * a[1] - u[1] * a[0]
            for k in range(nq):
                rq[12 + 6 * (k // 3) + (k % 3)] -= (Phi[e, i, 0, k] * a[0] + Phi[e, i, 1, k]
                                                    * a[1] + Phi[e, i, 2, k] * a[2])
            rq[0] += p[0]
            rq[1] += p[1]
            rq[2] += p[2]
            rq[3] += rho[1] * b[2] - rho[2] * b[1]
            rq[4] += rho[2] * b[0] - rho[0] * b[2]
            rq[5] += rho[0] * b[1] - rho[1] * b[0]
            if not full:
                continue
            # --- tangent: dp/d(r, rd, thB) in closed form; p depends on xB, vB, wB through
            # e = r - xB and s = rd - vB + e~ RB wB, so dp/dxB = -dp/dr (at fixed s: the
            # e~ term is in dp/dr), dp/dvB = -dp/drd and dp/dwB = dp/drd e~ RB
            node_force_jacobian(r, rd, xB, RB, vl[0:3], vl[3:6], pB[e], nB[e], af[e, i],
                                law[e], fric[e], dP)
            for d in range(3):
                e0, e1, e2 = r[0] - xB[0], r[1] - xB[1], r[2] - xB[2]
                for j in range(3):
                    dP[d, 6 + j] = -dP[d, j]
                    dP[d, 12 + j] = -dP[d, 3 + j]
                # (dp/drd e~ RB)[d, j]
                g0 = dP[d, 3]
                g1 = dP[d, 4]
                g2 = dP[d, 5]
                # row (g^T e~) = (e x g)^T... g^T e~ = -(e~ g)^T = (g x e)^T
                h0 = g1 * e2 - g2 * e1
                h1 = g2 * e0 - g0 * e2
                h2 = g0 * e1 - g1 * e0
                for j in range(3):
                    dP[d, 15 + j] = h0 * RB[0, j] + h1 * RB[1, j] + h2 * RB[2, j]
            # J_r (3, ncol) over [xB thB xh thh q]: dr/dxh = I, dr/dthh = -Rh u~, dr/dq = Rh Phi
            # Jd: d rd / d positions: thh: -Rh (W~u + Phi qd)~, q: Rh W~ Phi
            for d in range(3):
                for cc in range(ncol):
                    Jr[d, cc] = 0.0
                    Jd[d, cc] = 0.0
                Jr[d, 6 + d] = 1.0
            ud[0], ud[1], ud[2] = t0, t1, t2
            skew_into(u, S1)
            skew_into(ud, S2)
            for d in range(3):
                for f in range(3):
                    Jr[d, 9 + f] = -(Rh[d, 0] * S1[0, f] + Rh[d, 1] * S1[1, f]
                                     + Rh[d, 2] * S1[2, f])
                    Jd[d, 9 + f] = -(Rh[d, 0] * S2[0, f] + Rh[d, 1] * S2[1, f]
                                     + Rh[d, 2] * S2[2, f])
                for k in range(nq):
                    sp_ = 0.0
                    for m in range(3):
                        sp_ += Rh[d, m] * Phi[e, i, m, k]
                    # W~ Phi_k
                    wp0 = w1 * Phi[e, i, 2, k] - w2 * Phi[e, i, 1, k]
                    wp1 = w2 * Phi[e, i, 0, k] - w0 * Phi[e, i, 2, k]
                    wp2 = w0 * Phi[e, i, 1, k] - w1 * Phi[e, i, 0, k]
                    sw = Rh[d, 0] * wp0 + Rh[d, 1] * wp1 + Rh[d, 2] * wp2
                    Jr[d, 12 + k] = sp_
                    Jd[d, 12 + k] = sw
            # dp/dpos (3, ncol) and dp/dvel (3, ncol), stacked for the element's product
            # (the face's columns 0-5 have J_r = J_d = 0, the host's translation 6-8 J_r = I
            # and J_d = 0: written directly)
            j = 3 * ns
            for d in range(3):
                for cc in range(6):
                    Dps[j + d, cc] = dP[d, 6 + cc]
                    Dvs[j + d, cc] = dP[d, 12 + cc]
                for cc in range(3):
                    Dps[j + d, 6 + cc] = dP[d, cc]
                    Dvs[j + d, 6 + cc] = dP[d, 3 + cc]
                for cc in range(9, ncol):
                    sp_ = 0.0
                    sv = 0.0
                    for m in range(3):
                        sp_ += dP[d, m] * Jr[m, cc] + dP[d, 3 + m] * Jd[m, cc]
                        sv += dP[d, 3 + m] * Jr[m, cc]
                    Dps[j + d, cc] = sp_
                    Dvs[j + d, cc] = sv
                for cc in range(ncol):
                    Sp[d, cc] += Dps[j + d, cc]
                    Sv[d, cc] += Dvs[j + d, cc]
            # rows: washer -J_r^T (.), face J_B^T (.) with J_B = [I, -RB rho~] on B cols
            skew_into(a, S1)     # a~
            skew_into(b, S2)     # b~
            skew_into(rho, S3)   # rho~
            # rho~ RB^T (rows of J_B^T on theta_B) and b~ RB^T (geometric term), once
            for f in range(3):
                for d in range(3):
                    Tr[f, d] = S3[f, 0] * RB[d, 0] + S3[f, 1] * RB[d, 1] + S3[f, 2] * RB[d, 2]
                    Tb[f, d] = S2[f, 0] * RB[d, 0] + S2[f, 1] * RB[d, 1] + S2[f, 2] * RB[d, 2]
            # the node's rows of the virtual work, W^T (3, ncol): xB I, theta_B rho~ RB^T,
            # the washer's -J_r (its xh columns are I); the element's matrices are
            # sum W^T Dp and sum W^T Dv over the nodes, one product after the loop. The
            # translations' rows (I and -I) are the sums Sp, Sv: Ws holds the others,
            # theta_B and the washer's rotation and elastic coordinates (ncol - 6)
            for d in range(3):
                for f in range(3):
                    Ws[j + d, f] = Tr[f, d]
                for cc in range(9, ncol):
                    Ws[j + d, cc - 6] = -Jr[d, cc]
            ns += 1
            # geometric terms (p held): washer: d[u x a] = -a~ Phi dq + u~ a~ dth_h;
            # d[Phi^T a] = Phi^T a~ dth_h; face: d[rho x b] = -b~ RB^T (dr - dxB)
            #   + (rho~ b~ - b~ rho~) dth_B
            skew_into(u, Dq)     # u~
            for f in range(3):
                for g_ in range(3):
                    ua = 0.0
                    rb = 0.0
                    for m in range(3):
                        ua += Dq[f, m] * S1[m, g_]
                        rb += S3[f, m] * S2[m, g_] - S2[f, m] * S3[m, g_]
                    K[9 + f, 9 + g_] -= ua
                    K[3 + f, 3 + g_] += rb
                for k in range(nq):
                    col = 12 + 6 * (k // 3) + (k % 3)
                    s_ = 0.0
                    for m in range(3):
                        s_ += S1[f, m] * Phi[e, i, m, k]
                    K[9 + f, col] += s_
                    K[col, 9 + f] -= (Phi[e, i, 0, k] * S1[0, f] + Phi[e, i, 1, k] * S1[1, f]
                                      + Phi[e, i, 2, k] * S1[2, f])
                # face rows: -b~ RB^T (J_r dpos - dxB) (J_r: 0 on the face's columns, I on
                # the host's translation)
                for g_ in range(3):
                    K[3 + f, g_] += Tb[f, g_]
                    K[3 + f, 6 + g_] -= Tb[f, g_]
                for cc in range(9, ncol):
                    col = cc if cc < 12 else 12 + 6 * ((cc - 12) // 3) + ((cc - 12) % 3)
                    K[3 + f, col] -= Tb[f, 0] * Jr[0, cc] + Tb[f, 1] * Jr[1, cc] \
                        + Tb[f, 2] * Jr[2, cc]
        if full and ns > 0:
            # sum over the nodes in contact of W^T Dp and W^T Dv, as one product each
            np.dot(Ws[:3 * ns].T, Dps[:3 * ns], Kc)
            np.dot(Ws[:3 * ns].T, Dvs[:3 * ns], Cc)
            for cc in range(ncol):
                col = cc if cc < 12 else 12 + 6 * ((cc - 12) // 3) + ((cc - 12) % 3)
                for d in range(3):
                    K[d, col] += Sp[d, cc]
                    Cd[d, col] += Sv[d, cc]
                    K[6 + d, col] -= Sp[d, cc]
                    Cd[6 + d, col] -= Sv[d, cc]
            for rr in range(ncol - 6):
                # Ws's columns: theta_B (rows 3-5), then rows 9...
                rf = 3 + rr if rr < 3 else 6 + rr
                row = rf if rf < 12 else 12 + 6 * ((rf - 12) // 3) + ((rf - 12) % 3)
                for cc in range(ncol):
                    col = cc if cc < 12 else 12 + 6 * ((cc - 12) // 3) + ((cc - 12) % 3)
                    K[row, col] += Kc[rr, cc]
                    Cd[row, col] += Cc[rr, cc]
        sc.scatter(C, L, e, nnode, full)
        sc.energy(C, e, 0.0, Vt, 0.0, Pd)
        sc.report(C, e, (Ftot, pmax, Ftot / area[e], pen, Mf, Fr / Ftot if Ftot > 0.0 else 0.0,
                         Pd))


@dataclass(frozen=True)
class FlexibleWasherContact(TwoMarkerSpec):
    """A rigid face (``marker_b``) on the surface nodes of a flexible washer.

    Attributes:
        name: unique element name.
        marker_a: the washer's mounting marker (the :class:`FlexibleBody`'s ``marker``).
        marker_b: the counter face: origin on the face plane, z axis = normal pointing
            towards the washer.
        body: name of the :class:`FlexibleBody` element of the washer.
        face: indices of the washer's contact-face nodes (``SolidModel.select``): the contact
            is evaluated at these nodes with their tributary areas.
        points: instead of ``face``, contact points (k, 3) [m] on the face, in the part's
            frame (its mesh coordinates), where the contact is evaluated; the displacement
            basis there is the mesh's (quadratic shape functions,
            :meth:`~drivedyn.fe.solid.SolidModel.interpolation`). A quadrature rule of the
            face: far fewer points than nodes for the same face integrals (see the module
            docstring).
        weights: with ``points``, the area of each point (k,) [m^2], the quadrature weights
            (their sum is the face area).
        law: normal law of the whole face (``K`` in N/m^n for the face).
        friction: :class:`FrictionLaw` (kinetic ``mu`` and ``eps_v``) or None.
    """

    body: str = ""
    face: Any = ()
    points: Any = ()
    weights: Any = ()
    law: NormalLaw = field(default_factory=lambda: NormalLaw(1e9, 1.0, law="penalty"))
    friction: FrictionLaw | None = None
    family: ClassVar[str] = "flexible_washer_contact"

    def __post_init__(self) -> None:
        coerce_laws(self, what_of(self))

    def validate(self) -> None:
        what = what_of(self)
        nf = len(np.asarray(self.face).ravel())
        pts = np.asarray(self.points, float)
        if (nf == 0) == (pts.size == 0):
            raise ModelError(f"{what}: give either the face nodes (face) or the contact points "
                             f"(points, weights), got {nf} face nodes and {pts.size // 3} "
                             "points")
        if pts.size:
            w = np.asarray(self.weights, float)
            if pts.ndim != 2 or pts.shape[1] != 3:
                raise ModelError(f"{what}.points: expected an array (k, 3) [m], got shape "
                                 f"{pts.shape}")
            if w.shape != (pts.shape[0],) or not np.all(np.isfinite(w)) or not np.all(w > 0):
                raise ModelError(f"{what}.weights: expected {pts.shape[0]} positive areas "
                                 f"[m^2], one per point, got {w.tolist()}")
        check_laws(self, what)


class FlexibleWasherContactFamily(Family):
    """Registry entry of :class:`FlexibleWasherContact`."""

    name = "flexible_washer_contact"

    def build(self, specs, ctx) -> Group:
        rows = []
        for s in specs:
            what = what_of(s)
            fb = flexible_body_named(ctx.spec, s.body, what)
            if s.marker_a != fb.marker:
                raise ModelError(f"{what}.marker_a: must be the washer's mounting marker "
                                 f"{fb.marker!r}, got {s.marker_a!r}")
            part = fb.part
            if part.solid is None:
                raise ModelError(f"{what}: the part of {s.body!r} has no solid model "
                                 "(needed for the face areas)")
            nh, p, Rm = ctx.marker(fb.marker, what)
            nb, pB, RmB = ctx.marker(s.marker_b, what)
            if len(np.asarray(s.points).ravel()):
                # contact points: the FE field's values there (shape functions)
                Xp = np.asarray(s.points, float).reshape(-1, 3)
                areas = np.asarray(s.weights, float).ravel()
                P = part.solid.interpolation(Xp)
                Pm = np.einsum("ij,njk->nik", Rm,
                               (P @ part.Phi.reshape(part.n, -1)).reshape(len(Xp), 3, part.nq))
                rows.append((nb, nh, [ctx.node_index[c] for c in fb.coordinates],
                             p + (P @ part.X) @ Rm.T, Pm, areas, pB, RmB[:, 2], part.nq, Xp))
                continue
            face = np.asarray(s.face, np.int64).ravel()
            if face.min() < 0 or face.max() >= part.n:
                raise ModelError(f"{what}.face: node indices must be in [0, {part.n})")
            areas = part.solid.face_areas(face)
            inv = invariants(part, p, Rm)
            rows.append((nb, nh, [ctx.node_index[c] for c in fb.coordinates], inv["X"][face],
                         inv["Phi"][face], areas, pB, RmB[:, 2], part.nq, part.X[face]))
        nel = len(specs)
        nqm = max(r[8] for r in rows)
        nfm = max(len(r[5]) for r in rows)
        ncm = max(1, math.ceil(nqm / 3))
        lnodes = np.full((nel, 2 + ncm), ctx.nn, np.int64)
        X = np.zeros((nel, nfm, 3))
        Phi = np.zeros((nel, nfm, 3, nqm))
        af = np.zeros((nel, nfm))
        nfs = np.zeros(nel, np.int64)
        nqs = np.zeros(nel, np.int64)
        area = np.zeros(nel)
        pBa = np.zeros((nel, 3))
        nBa = np.zeros((nel, 3))
        for e, (nb, nh, cn, Xf, Pf, A, pB, nz, nq, _) in enumerate(rows):
            lnodes[e, 0], lnodes[e, 1] = nb, nh
            lnodes[e, 2:2 + len(cn)] = cn
            nf = len(A)
            X[e, :nf] = Xf
            Phi[e, :nf, :, :nq] = Pf
            area[e] = A.sum()
            af[e, :nf] = A / area[e]
            nfs[e], nqs[e] = nf, nq
            pBa[e], nBa[e] = pB, nz
        fric = np.array([[s.friction.mu, s.friction.eps_v] if s.friction is not None else
                         [0.0, 1.0] for s in specs], float)
        dofs = np.array([ctx.local_dofs(list(ln), 0, 0) for ln in lnodes], np.int64)
        g = make_group(self.name, specs, flexible_washer_kernel,
                       (X, Phi, af, nfs, nqs, area, law_table([s.law for s in specs]), fric,
                        pBa, nBa, np.zeros(work_size.py_func(6 * lnodes.shape[1], nqm, nfm))),
                       lnodes, dofs, OUTPUTS, dissipative=True)
        g.naux = NOUT + nfm
        g.extra["fields"] = [{"name": "contact_pressure", "column": NOUT, "count": int(nfs[e]),
                              "units": "Pa", "description": "contact pressure at the contact "
                              "points (face nodes or quadrature points)", "points": rows[e][9],
                              "points_description": "contact points in the washer's part "
                              "frame (z: its axis)"} for e in range(nel)]
        return g


register(FlexibleWasherContactFamily())
