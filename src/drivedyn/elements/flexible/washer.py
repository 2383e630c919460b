"""Rigid annular face on the surface nodes of a flexible washer (family
``flexible_washer_contact``).

The washer is a :class:`~drivedyn.elements.flexible.family.FlexibleBody`; its contact face is
a set of surface nodes ``i`` with tributary areas ``A_i`` (the consistent load of a unit
pressure, sum ``S``). The counter face is the plane through the origin of ``marker_b`` with
normal ``n = z_B`` pointing from the plane towards the washer. Per node, with
``r_i = x + R (X_i + Phi_i q)``::

    delta_i = -(r_i - x_B) . n                     penetration [m]
    s_i = rdot_i - v_B(r_i)                        velocity relative to the face [m/s]
    F_i = (A_i / S) F_law(delta_i, -s_i . n)        normal force [N]
    f_i = -mu F_i s_t / sqrt(|s_t|^2 + eps_v^2)     friction (s_t: s_i in the plane) [N]

``F_law`` is the face's :class:`~drivedyn.elements.impact_laws.NormalLaw` for the whole face
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
The tangent matrices come from complex steps of the residual (exact to round-off).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.scaffold as sc
from drivedyn.elements._contact_common import check_laws, coerce_laws
from drivedyn.elements.base import Family, Group, TwoMarkerSpec, local_arrays, register
from drivedyn.elements.building import make_group, what_of
from drivedyn.elements.flexible.family import FlexibleBody, invariants
from drivedyn.elements.friction import FrictionLaw
from drivedyn.elements.impact_laws import NormalLaw, law_table
from drivedyn.errors import ModelError, did_you_mean

OUTPUTS = (
    ("normal_force", "N", "axial contact force, sum over the face nodes"),
    ("max_pressure", "Pa", "largest nodal contact pressure"),
    ("mean_pressure", "Pa", "normal force / face area"),
    ("penetration", "m", "largest nodal penetration (< 0: open gap)"),
    ("friction_torque", "N m", "friction moment on the washer about the face normal"),
    ("pressure_radius", "m", "pressure-weighted mean radius of the contact"),
    ("contact_power", "W", "power dissipated by friction and contact damping"),
)
NOUT = len(OUTPUTS)


@njit(cache=True)
def washer_forces(X, Phi, af, nf, nq, law, fric, xB, RB, pB, nB, vB, wB, xh, Rh, vh, Wh, q, qd,
                  zero, res, nodal, want_nodal):
    """Residual (local: B node 0..5, host 6..11, q slots) into ``res`` and, if
    ``want_nodal``, per-node normal forces into ``nodal`` (real arithmetic only). Returns
    (F, M_fric, V, P_dis, pen_max, F r sum)."""
    K, n, chi, c, vs = law[0], law[1], law[2], law[3], law[4]
    mu, epsv = fric[0], fric[1]
    for i in range(res.shape[0]):
        res[i] = zero
    # global normal and marker origin of face B
    ng = (RB[0, 0] * nB[0] + RB[0, 1] * nB[1] + RB[0, 2] * nB[2],
          RB[1, 0] * nB[0] + RB[1, 1] * nB[1] + RB[1, 2] * nB[2],
          RB[2, 0] * nB[0] + RB[2, 1] * nB[1] + RB[2, 2] * nB[2])
    xo = (xB[0] + RB[0, 0] * pB[0] + RB[0, 1] * pB[1] + RB[0, 2] * pB[2],
          xB[1] + RB[1, 0] * pB[0] + RB[1, 1] * pB[1] + RB[1, 2] * pB[2],
          xB[2] + RB[2, 0] * pB[0] + RB[2, 1] * pB[1] + RB[2, 2] * pB[2])
    wg = (RB[0, 0] * wB[0] + RB[0, 1] * wB[1] + RB[0, 2] * wB[2],
          RB[1, 0] * wB[0] + RB[1, 1] * wB[1] + RB[1, 2] * wB[2],
          RB[2, 0] * wB[0] + RB[2, 1] * wB[1] + RB[2, 2] * wB[2])
    Ftot = zero
    Mf = zero
    V = zero
    Pd = zero
    pen = -1e300
    Fr = zero
    u = np.empty(3, dtype=res.dtype)
    ud = np.empty(3, dtype=res.dtype)
    r = np.empty(3, dtype=res.dtype)
    s = np.empty(3, dtype=res.dtype)
    pl = np.empty(3, dtype=res.dtype)
    for i in range(nf):
        for a in range(3):
            ua = X[i, a] + zero
            ua2 = zero
            for k in range(nq):
                ua += Phi[i, a, k] * q[k]
                ua2 += Phi[i, a, k] * qd[k]
            u[a] = ua
            ud[a] = ua2
        # ud = Wh x u + Phi qd (body frame)
        ud0 = Wh[1] * u[2] - Wh[2] * u[1] + ud[0]
        ud1 = Wh[2] * u[0] - Wh[0] * u[2] + ud[1]
        ud2 = Wh[0] * u[1] - Wh[1] * u[0] + ud[2]
        for a in range(3):
            r[a] = xh[a] + Rh[a, 0] * u[0] + Rh[a, 1] * u[1] + Rh[a, 2] * u[2]
        d0 = r[0] - xo[0]
        d1 = r[1] - xo[1]
        d2 = r[2] - xo[2]
        delta = -(d0 * ng[0] + d1 * ng[1] + d2 * ng[2])
        if delta.real > pen:
            pen = delta.real
        if want_nodal:
            nodal[i] = 0.0
        if delta.real <= 0.0:
            continue
        e0 = r[0] - xB[0]
        e1 = r[1] - xB[1]
        e2 = r[2] - xB[2]
        for a in range(3):
            s[a] = vh[a] + Rh[a, 0] * ud0 + Rh[a, 1] * ud1 + Rh[a, 2] * ud2 - vB[a]
        s[0] -= wg[1] * e2 - wg[2] * e1
        s[1] -= wg[2] * e0 - wg[0] * e2
        s[2] -= wg[0] * e1 - wg[1] * e0
        sn = s[0] * ng[0] + s[1] * ng[1] + s[2] * ng[2]
        rate = -sn
        kdn = K * delta**n
        Fi = af[i] * (kdn * (1.0 + chi * rate / vs) + c * rate)
        if Fi.real <= 0.0:
            V += af[i] * kdn * delta / (n + 1.0)
            continue
        V += af[i] * kdn * delta / (n + 1.0)
        Pd += (Fi - af[i] * kdn) * rate
        # friction
        st0 = s[0] - sn * ng[0]
        st1 = s[1] - sn * ng[1]
        st2 = s[2] - sn * ng[2]
        den = np.sqrt(st0 * st0 + st1 * st1 + st2 * st2 + epsv * epsv)
        g = mu * Fi / den
        p0 = Fi * ng[0] - g * st0
        p1 = Fi * ng[1] - g * st1
        p2 = Fi * ng[2] - g * st2
        Pd += g * (st0 * st0 + st1 * st1 + st2 * st2)
        Ftot += Fi
        Fr += Fi * np.sqrt(d0 * d0 + d1 * d1 + d2 * d2 - (d0 * ng[0] + d1 * ng[1]
                                                          + d2 * ng[2]) ** 2)
        # friction moment on the washer about the normal through the face origin
        Mf += ng[0] * (d1 * (-g * st2) - d2 * (-g * st1)) + ng[1] * (d2 * (-g * st0)
                                                                      - d0 * (-g * st2)) \
            + ng[2] * (d0 * (-g * st1) - d1 * (-g * st0))
        if want_nodal:
            nodal[i] = Fi.real
        # on the washer: r_x -= p, r_th -= u x (Rh^T p), r_q -= Phi^T Rh^T p
        for a in range(3):
            pl[a] = Rh[0, a] * p0 + Rh[1, a] * p1 + Rh[2, a] * p2
        res[6] -= p0
        res[7] -= p1
        res[8] -= p2
        res[9] -= u[1] * pl[2] - u[2] * pl[1]
        res[10] -= u[2] * pl[0] - u[0] * pl[2]
        res[11] -= u[0] * pl[1] - u[1] * pl[0]
        for k in range(nq):
            res[12 + 6 * (k // 3) + (k % 3)] -= (Phi[i, 0, k] * pl[0] + Phi[i, 1, k] * pl[1]
                                                 + Phi[i, 2, k] * pl[2])
        # on face B: r_x += p, r_th += rho x (RB^T p), rho = RB^T (r - x_B)
        res[0] += p0
        res[1] += p1
        res[2] += p2
        rho0 = RB[0, 0] * e0 + RB[1, 0] * e1 + RB[2, 0] * e2
        rho1 = RB[0, 1] * e0 + RB[1, 1] * e1 + RB[2, 1] * e2
        rho2 = RB[0, 2] * e0 + RB[1, 2] * e1 + RB[2, 2] * e2
        q0 = RB[0, 0] * p0 + RB[1, 0] * p1 + RB[2, 0] * p2
        q1 = RB[0, 1] * p0 + RB[1, 1] * p1 + RB[2, 1] * p2
        q2 = RB[0, 2] * p0 + RB[1, 2] * p1 + RB[2, 2] * p2
        res[3] += rho1 * q2 - rho2 * q1
        res[4] += rho2 * q0 - rho0 * q2
        res[5] += rho0 * q1 - rho1 * q0
    return Ftot, Mf, V, Pd, pen, Fr


@njit(cache=True, inline="always")
def _washers(P, C, W, full):
    X, Phi, af, nfs, nqs, area, law, fric, pB, nB = P
    L, vl, res, nodal, cres, (cxB, cRB, cvB, cwB, cxh, cRh, cvh, cWh, cq, cqd), qv, qdv = W
    rq, _, M, Cd, K, _ = L
    x, R, _, _, _, _, _, _ = sc.state(C)
    aux = C[sc.AUX]
    nnode = C[sc.LNODES].shape[1]
    nd = 6 * nnode
    h = 1e-30
    for e in range(sc.count(C)):
        nb = sc.node(C, e, 0)
        nh = sc.node(C, e, 1)
        nq = nqs[e]
        nf = nfs[e]
        sc.velocities(C, e, nd, vl)
        sc.clear(L, full)
        for k in range(nq):
            qv[k] = x[sc.node(C, e, 2 + k // 3), k % 3]
            qdv[k] = vl[12 + 6 * (k // 3) + (k % 3)]
        F, Mf, V, Pd, pen, Fr = washer_forces(
            X[e], Phi[e], af[e], nf, nq, law[e], fric[e], x[nb], R[nb], pB[e], nB[e],
            vl[0:3], vl[3:6], x[nh], R[nh], vl[6:9], vl[9:12], qv, qdv, 0.0, res, nodal, True)
        for i in range(nd):
            rq[i] = res[i]
        if full:
            # complex steps on positions (K) and velocities (C) of B, host and q
            for i in range(3):
                cxB[i] = x[nb, i]
                cvB[i] = vl[i]
                cwB[i] = vl[3 + i]
                cxh[i] = x[nh, i]
                cvh[i] = vl[6 + i]
                cWh[i] = vl[9 + i]
                for j in range(3):
                    cRB[i, j] = R[nb, i, j]
                    cRh[i, j] = R[nh, i, j]
            for k in range(nq):
                cq[k] = qv[k]
                cqd[k] = qdv[k]
            ncol = 12 + nq
            for cc in range(2 * ncol):
                pos = cc < ncol
                j = cc if pos else cc - ncol
                if j < 12:
                    blk = j // 6   # 0: B, 1: host
                    t = j % 6
                    if pos:
                        if t < 3:
                            if blk == 0:
                                cxB[t] = x[nb, t] + 1j * h
                            else:
                                cxh[t] = x[nh, t] + 1j * h
                        else:
                            tt = t - 3
                            b1 = (tt + 1) % 3
                            b2 = (tt + 2) % 3
                            Rs = R[nb] if blk == 0 else R[nh]
                            cR = cRB if blk == 0 else cRh
                            for a in range(3):
                                cR[a, b1] = Rs[a, b1] + 1j * h * Rs[a, b2]
                                cR[a, b2] = Rs[a, b2] - 1j * h * Rs[a, b1]
                    else:
                        if blk == 0:
                            if t < 3:
                                cvB[t] = vl[t] + 1j * h
                            else:
                                cwB[t - 3] = vl[t] + 1j * h
                        else:
                            if t < 3:
                                cvh[t] = vl[6 + t] + 1j * h
                            else:
                                cWh[t - 3] = vl[6 + t] + 1j * h
                    col = j
                else:
                    k = j - 12
                    if pos:
                        cq[k] = qv[k] + 1j * h
                    else:
                        cqd[k] = qdv[k] + 1j * h
                    col = 12 + 6 * (k // 3) + (k % 3)
                washer_forces(X[e], Phi[e], af[e], nf, nq, law[e], fric[e], cxB, cRB, pB[e],
                              nB[e], cvB, cwB, cxh, cRh, cvh, cWh, cq, cqd, 0j, cres, nodal,
                              False)
                T = K if pos else Cd
                for i in range(nd):
                    T[i, col] = cres[i].imag / h
                # restore
                for i in range(3):
                    cxB[i] = x[nb, i]
                    cvB[i] = vl[i]
                    cwB[i] = vl[3 + i]
                    cxh[i] = x[nh, i]
                    cvh[i] = vl[6 + i]
                    cWh[i] = vl[9 + i]
                    for jj in range(3):
                        cRB[i, jj] = R[nb, i, jj]
                        cRh[i, jj] = R[nh, i, jj]
                if j >= 12:
                    cq[j - 12] = qv[j - 12]
                    cqd[j - 12] = qdv[j - 12]
        sc.scatter(C, L, e, nnode, full)
        sc.energy(C, e, 0.0, V, 0.0, Pd)
        pmax = 0.0
        for i in range(nf):
            pi = nodal[i] / (af[e, i] * area[e])
            if pi > pmax:
                pmax = pi
            aux[e, NOUT + i] = pi
        sc.report(C, e, (F, pmax, F / area[e], pen, Mf, Fr / F if F > 0.0 else 0.0, Pd))


@njit(cache=True)
def flexible_washer_kernel(
    X, Phi, af, nfs, nqs, area, law, fric, pB, nB,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    nd = 6 * lnodes.shape[1]
    nqm = Phi.shape[3]
    nfm = X.shape[1]
    z = np.zeros
    cz = np.complex128
    W = (local_arrays(nd, 0), z(nd), z(nd), z(nfm), z(nd, cz),
         (z(3, cz), z((3, 3), cz), z(3, cz), z(3, cz), z(3, cz), z((3, 3), cz), z(3, cz),
          z(3, cz), z(nqm, cz), z(nqm, cz)), z(nqm), z(nqm))
    sc.run(_washers, (X, Phi, af, nfs, nqs, area, law, fric, pB, nB),
           (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
            r, rabs, data, eout, aux), W)


@dataclass(frozen=True)
class FlexibleWasherContact(TwoMarkerSpec):
    """A rigid face (``marker_b``) on the surface nodes of a flexible washer.

    Attributes:
        name: unique element name.
        marker_a: the washer's mounting marker (the :class:`FlexibleBody`'s ``marker``).
        marker_b: the counter face: origin on the face plane, z axis = normal pointing
            towards the washer.
        body: name of the :class:`FlexibleBody` element of the washer.
        face: indices of the washer's contact-face nodes (``SolidModel.select``).
        law: normal law of the whole face (``K`` in N/m^n for the face).
        friction: :class:`FrictionLaw` (kinetic ``mu`` and ``eps_v``) or None.
    """

    body: str = ""
    face: Any = ()
    law: NormalLaw = field(default_factory=lambda: NormalLaw(1e9, 1.0, law="penalty"))
    friction: FrictionLaw | None = None
    family: ClassVar[str] = "flexible_washer_contact"

    def __post_init__(self) -> None:
        coerce_laws(self, what_of(self))

    def validate(self) -> None:
        what = what_of(self)
        if len(np.asarray(self.face).ravel()) == 0:
            raise ModelError(f"{what}.face: no face nodes given")
        check_laws(self, what)


class FlexibleWasherContactFamily(Family):
    """Registry entry of :class:`FlexibleWasherContact`."""

    name = "flexible_washer_contact"

    def build(self, specs, ctx) -> Group:
        bodies = {e.name: e for e in ctx.spec.elements if isinstance(e, FlexibleBody)}
        rows = []
        for s in specs:
            what = what_of(s)
            fb = bodies.get(s.body)
            if fb is None:
                raise ModelError(f"{what}.body: no flexible body {s.body!r}"
                                 f"{did_you_mean(s.body, bodies)}")
            if s.marker_a != fb.marker:
                raise ModelError(f"{what}.marker_a: must be the washer's mounting marker "
                                 f"{fb.marker!r}, got {s.marker_a!r}")
            part = fb.part
            face = np.asarray(s.face, np.int64).ravel()
            if face.min() < 0 or face.max() >= part.n:
                raise ModelError(f"{what}.face: node indices must be in [0, {part.n})")
            if part.solid is None:
                raise ModelError(f"{what}: the part of {s.body!r} has no solid model "
                                 "(needed for the face areas)")
            areas = part.solid.face_areas(face)
            nh, p, Rm = ctx.marker(fb.marker, what)
            nb, pB, RmB = ctx.marker(s.marker_b, what)
            inv = invariants(part, p, Rm)
            rows.append((nb, nh, [ctx.node_index[c] for c in fb.coordinates], inv["X"][face],
                         inv["Phi"][face], areas, pB, RmB[:, 2], part.nq))
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
        for e, (nb, nh, cn, Xf, Pf, A, pB, nz, nq) in enumerate(rows):
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
                        pBa, nBa), lnodes, dofs, OUTPUTS, dissipative=True)
        g.naux = NOUT + nfm
        g.extra["fields"] = [{"name": "pressure", "column": NOUT, "count": int(nfs[e]),
                              "units": "Pa", "description": "contact pressure at the face "
                              "nodes", "points": X[e, :nfs[e]]} for e in range(nel)]
        return g


register(FlexibleWasherContactFamily())
