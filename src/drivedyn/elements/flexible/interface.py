"""A node tied to an interface of a reduced flexible body (family ``flexible_interface``).

Interface ``k >= 1`` of a part moves, relative to the floating frame, by a translation ``t``
and a small rotation ``theta`` (part frame) linear in the elastic coordinates,
``(t, theta) = A_k q`` (``ReducedPart.maps``): for a rigid spider ``A_k`` selects its six
constraint-mode coordinates, for an averaging connection it is the averaged basis. The tie
makes an ordinary 6-dof node follow it, so markers on that node carry joints, contacts and
gears to the part::

    x_N - x_h - R_h (P + Rm t) = 0                      (3 rows, global)
    (R_c e_z).(R_N e_y) - theta_x = 0, (R_c e_x).(R_N e_z) - theta_y = 0,
    (R_c e_y).(R_N e_x) - theta_z = 0                   (R_c = R_h Rm: the part frame)

(``P`` the interface point in the host frame, ``Rm`` the part axes in the host frame; the
node's frame is the part frame at the interface). The rotation rows are the small-rotation
form of the spider rotation, consistent with the linear Craig-Bampton kinematics. Rows are
imposed by the augmented Lagrangian like every joint; the gradient is analytic, its
derivatives (the convective term ``v^T H v`` and the geometric stiffness ``sigma H``) come
from complex steps of the gradient.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.flexible.family import flexible_body_named
from drivedyn.elements.framework.building import make_group, what_of
from drivedyn.elements.framework.checks import check_param_optional
from drivedyn.elements.framework.contract import MODE_ACC, MODE_DYN, local_arrays
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.registry import ElementSpec, Family, register
from drivedyn.errors import ModelError, did_you_mean

#: (column of Rm, axis of the node frame, theta component) of the three rotation rows
_ROT = ((2, 1, 0), (0, 2, 1), (1, 0, 2))


@njit(cache=True, inline="always")
def _slot(k):
    return 12 + 6 * (k // 3) + (k % 3)


@njit(cache=True)
def tie_rows(xN, RN, xh, Rh, q, Ph, Rm, A, nq, val, g, zero):
    """Row values ``val`` (6,) and gradients ``g`` (6, nd) over the local dofs
    ``[N (6), host (6), coordinate slots]`` with ``(t, theta) = A q`` (``A`` (6, nq));
    real or complex arithmetic."""
    for r in range(6):
        for j in range(g.shape[1]):
            g[r, j] = zero
    tq0 = zero
    tq1 = zero
    tq2 = zero
    for k in range(nq):
        tq0 += A[0, k] * q[k]
        tq1 += A[1, k] * q[k]
        tq2 += A[2, k] * q[k]
    # w = Ph + Rm t (host frame), translation rows
    w0 = Ph[0] + Rm[0, 0] * tq0 + Rm[0, 1] * tq1 + Rm[0, 2] * tq2
    w1 = Ph[1] + Rm[1, 0] * tq0 + Rm[1, 1] * tq1 + Rm[1, 2] * tq2
    w2 = Ph[2] + Rm[2, 0] * tq0 + Rm[2, 1] * tq1 + Rm[2, 2] * tq2
    for a in range(3):
        val[a] = xN[a] - xh[a] - (Rh[a, 0] * w0 + Rh[a, 1] * w1 + Rh[a, 2] * w2)
        g[a, a] = 1.0 + zero
        g[a, 6 + a] = -1.0 + zero
        # d/dtheta_h of -R_h w = R_h w~
        g[a, 9] = Rh[a, 1] * w2 - Rh[a, 2] * w1
        g[a, 10] = Rh[a, 2] * w0 - Rh[a, 0] * w2
        g[a, 11] = Rh[a, 0] * w1 - Rh[a, 1] * w0
        # d/dq of -R_h Rm A_t q
        c0 = Rh[a, 0] * Rm[0, 0] + Rh[a, 1] * Rm[1, 0] + Rh[a, 2] * Rm[2, 0]
        c1 = Rh[a, 0] * Rm[0, 1] + Rh[a, 1] * Rm[1, 1] + Rh[a, 2] * Rm[2, 1]
        c2 = Rh[a, 0] * Rm[0, 2] + Rh[a, 1] * Rm[1, 2] + Rh[a, 2] * Rm[2, 2]
        for k in range(nq):
            g[a, _slot(k)] = -(c0 * A[0, k] + c1 * A[1, k] + c2 * A[2, k])
    # rotation rows: u = R_h c (c = Rm e_i), v = R_N e_j
    for r in range(3):
        ci, dj, comp = _ROT[r]
        c = (Rm[0, ci], Rm[1, ci], Rm[2, ci])
        u = (Rh[0, 0] * c[0] + Rh[0, 1] * c[1] + Rh[0, 2] * c[2],
             Rh[1, 0] * c[0] + Rh[1, 1] * c[1] + Rh[1, 2] * c[2],
             Rh[2, 0] * c[0] + Rh[2, 1] * c[1] + Rh[2, 2] * c[2])
        v = (RN[0, dj], RN[1, dj], RN[2, dj])
        th = zero
        for k in range(nq):
            th += A[3 + comp, k] * q[k]
        val[3 + r] = u[0] * v[0] + u[1] * v[1] + u[2] * v[2] - th
        # d/dtheta_h = c x (R_h^T v); d/dtheta_N = d x (R_N^T u), d = e_j
        hv = (Rh[0, 0] * v[0] + Rh[1, 0] * v[1] + Rh[2, 0] * v[2],
              Rh[0, 1] * v[0] + Rh[1, 1] * v[1] + Rh[2, 1] * v[2],
              Rh[0, 2] * v[0] + Rh[1, 2] * v[1] + Rh[2, 2] * v[2])
        g[3 + r, 9] = c[1] * hv[2] - c[2] * hv[1]
        g[3 + r, 10] = c[2] * hv[0] - c[0] * hv[2]
        g[3 + r, 11] = c[0] * hv[1] - c[1] * hv[0]
        nu = (RN[0, 0] * u[0] + RN[1, 0] * u[1] + RN[2, 0] * u[2],
              RN[0, 1] * u[0] + RN[1, 1] * u[1] + RN[2, 1] * u[2],
              RN[0, 2] * u[0] + RN[1, 2] * u[1] + RN[2, 2] * u[2])
        # e_j x nu
        j1 = (dj + 1) % 3
        j2 = (dj + 2) % 3
        g[3 + r, 3 + dj] = zero
        g[3 + r, 3 + j1] = -nu[j2]
        g[3 + r, 3 + j2] = nu[j1]
        for k in range(nq):
            g[3 + r, _slot(k)] = -A[3 + comp, k] + zero


@njit(cache=True)
def tie_kernel(
    Ph, Rm, Amap, nqs, kk, pp,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    nd = 6 * lnodes.shape[1]
    nqm = 3 * (lnodes.shape[1] - 2)
    cz = np.complex128
    z = np.zeros
    W = (local_arrays(nd, 6), z(nd), z(nd), z(nqm), z(6), z((6, nd)), z((3, 3), cz),
         z((3, 3), cz), z(nqm, cz), z(6, cz), z((6, nd), cz), z((6, nd), cz), z(6))
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    L, vl, al, qv, val, g, cR1, cR2, cq, cval, cg, dg, sig = W
    full = sc.full_pass(want, mode)
    rq, rl, M, Cd, K, G = L
    nnode = C[sc.LNODES].shape[1]
    nd = 6 * nnode
    h = 1e-30
    for e in range(sc.count(C)):
        nN = sc.node(C, e, 0)
        nh = sc.node(C, e, 1)
        nq = nqs[e]
        sc.velocities(C, e, nd, vl)
        if mode == MODE_ACC:
            sc.accelerations(C, e, nd, al)
        sc.clear(L, full)
        for k in range(nq):
            qv[k] = x[sc.node(C, e, 2 + k // 3), k % 3]
        tie_rows(x[nN], R[nN], x[nh], R[nh], qv, Ph[e], Rm[e], Amap[e], nq, val, g, 0.0)
        for i in range(6):
            sig[i] = kk[e, i] * sc.multiplier(C, e, nd, i) + pp[e, i] * val[i]
            for a in range(nd):
                rq[a] += sig[i] * g[i, a]
        need_h = full or mode == MODE_ACC
        if need_h:
            # positions moved along the velocities by i h: d/ds of g along v
            for a in range(3):
                for b in range(3):
                    cR1[a, b] = R[nN, a, b] + 1j * h * (
                        R[nN, a, (b + 1) % 3] * vl[3 + (b + 2) % 3]
                        - R[nN, a, (b + 2) % 3] * vl[3 + (b + 1) % 3])
                    cR2[a, b] = R[nh, a, b] + 1j * h * (
                        R[nh, a, (b + 1) % 3] * vl[9 + (b + 2) % 3]
                        - R[nh, a, (b + 2) % 3] * vl[9 + (b + 1) % 3])
            for k in range(nq):
                cq[k] = qv[k] + 1j * h * vl[_slot(k)]
            tie_rows(x[nN], cR1, x[nh], cR2, cq, Ph[e], Rm[e], Amap[e], nq, cval, cg, 0j)
        if mode == MODE_DYN:
            for i in range(6):
                rl[i] = kk[e, i] * val[i]
        else:
            vec = al if mode == MODE_ACC else vl
            for i in range(6):
                s = 0.0
                for a in range(nd):
                    s += g[i, a] * vec[a]
                if mode == MODE_ACC:
                    for a in range(nd):
                        s += cg[i, a].imag / h * vl[a]
                rl[i] = kk[e, i] * s
        if full:
            for i in range(6):
                for a in range(nd):
                    G[i, a] = kk[e, i] * g[i, a]
                    ga = pp[e, i] * g[i, a]
                    for b in range(nd):
                        K[a, b] += ga * g[i, b]
            # geometric stiffness sum_i sig_i d g_i / d pos_b: complex steps per column
            for b in range(12 + 6 * ((nq + 2) // 3)):
                if b < 12:
                    blk, t = b // 6, b % 6
                    if t < 3:
                        continue  # rows do not depend on the positions x
                    tt = t - 3
                    src = R[nN] if blk == 0 else R[nh]
                    for a in range(3):
                        for bb in range(3):
                            cR1[a, bb] = R[nN, a, bb]
                            cR2[a, bb] = R[nh, a, bb]
                    cR = cR1 if blk == 0 else cR2
                    b1 = (tt + 1) % 3
                    b2 = (tt + 2) % 3
                    for a in range(3):
                        cR[a, b1] = src[a, b1] + 1j * h * src[a, b2]
                        cR[a, b2] = src[a, b2] - 1j * h * src[a, b1]
                    for k in range(nq):
                        cq[k] = qv[k]
                else:
                    k = 3 * ((b - 12) // 6) + (b - 12) % 6
                    if (b - 12) % 6 >= 3 or k >= nq:
                        continue
                    for a in range(3):
                        for bb in range(3):
                            cR1[a, bb] = R[nN, a, bb]
                            cR2[a, bb] = R[nh, a, bb]
                    for kk2 in range(nq):
                        cq[kk2] = qv[kk2]
                    cq[k] = qv[k] + 1j * h
                tie_rows(x[nN], cR1, x[nh], cR2, cq, Ph[e], Rm[e], Amap[e], nq, cval, dg, 0j)
                for a in range(nd):
                    s = 0.0
                    for i in range(6):
                        s += sig[i] * dg[i, a].imag / h
                    K[a, b] += s
        sc.scatter(C, L, e, nnode, full)
        # force and moment the part applies to the node (global frame)
        sc.report(C, e, (-rq[0], -rq[1], -rq[2], -rq[3], -rq[4], -rq[5]))


@dataclass(frozen=True)
class FlexibleInterface(ElementSpec):
    """Node ``node`` tied to interface ``interface`` (index >= 1 or name) of the
    :class:`FlexibleBody` ``body``.

    Attributes:
        name: unique element name.
        body: the flexible body element's name.
        interface: index (>= 1) or name of the part's interface.
        node: a plain node placed at the interface (its frame: the part axes).
        k, p: scaling and penalty of the augmented Lagrangian [N/m on the three position
            rows, N m/rad on the three rotation rows] (None: automatic).
    """

    name: str
    body: str
    interface: int | str
    node: str
    k: float | None = None
    p: float | None = None
    family: ClassVar[str] = "flexible_interface"
    units: ClassVar[dict[str, str]] = {"k": "N/m or N m/rad", "p": "N/m or N m/rad"}

    def validate(self) -> None:
        check_param_optional(self, "k", 0.0, strict=True)
        check_param_optional(self, "p", 0.0, strict=True)


def interface_index(part, interface: int | str, what: str) -> int:
    """Index (>= 1) of a part's interface given by index or name."""
    names = [i.name for i in part.interfaces]
    if isinstance(interface, str):
        if interface not in names:
            raise ModelError(f"{what}.interface: unknown interface {interface!r}"
                             f"{did_you_mean(interface, names)} (interfaces: {names})")
        k = names.index(interface)
    else:
        k = int(interface)
    if not 1 <= k < len(names):
        raise ModelError(f"{what}.interface: must be one of the interfaces after the first "
                         f"(the mounting face), i.e. 1..{len(names) - 1}, got {interface!r}")
    return k


class FlexibleInterfaceFamily(Family):
    """Registry entry of :class:`FlexibleInterface`."""

    name = "flexible_interface"

    def build(self, specs, ctx) -> Group:
        nel = len(specs)
        rows = []
        for s in specs:
            what = what_of(s)
            fb = flexible_body_named(ctx.spec, s.body, what)
            k = interface_index(fb.part, s.interface, what)
            if s.node not in ctx.spec.nodes:
                raise ModelError(f"{what}.node: {s.node!r} is not a plain node"
                                 f"{did_you_mean(s.node, ctx.spec.nodes)}")
            nh, p, Rm = ctx.marker(fb.marker, what)
            rows.append((ctx.node_index[s.node], nh, [ctx.node_index[c] for c in fb.coordinates],
                         p + Rm @ fb.part.interfaces[k].point, Rm, fb.part.maps[k - 1],
                         fb.part.nq))
        ncm = max(len(r[2]) for r in rows)
        lnodes = np.full((nel, 2 + ncm), ctx.nn, np.int64)
        Ph = np.zeros((nel, 3))
        Rms = np.zeros((nel, 3, 3))
        Amap = np.zeros((nel, 6, 3 * ncm))
        nqs = np.zeros(nel, np.int64)
        kk = np.zeros((nel, 6))
        pp = np.zeros((nel, 6))
        dofs = []
        for e, (nN, nh, cn, P, Rm, A, nq) in enumerate(rows):
            lnodes[e, 0], lnodes[e, 1] = nN, nh
            lnodes[e, 2:2 + len(cn)] = cn
            Ph[e], Rms[e], nqs[e] = P, Rm, nq
            Amap[e, :, :nq] = A
            kp = [ctx.scaling(specs[e].k, specs[e].p, i >= 3) for i in range(6)]
            kk[e] = [a for a, _ in kp]
            pp[e] = [b for _, b in kp]
            m0 = ctx.alloc_mult(6, specs[e].name, kk[e])
            dofs.append(ctx.local_dofs(list(lnodes[e]), m0, 6))
        return make_group(self.name, specs, tie_kernel, (Ph, Rms, Amap, nqs, kk, pp), lnodes,
                          np.array(dofs, np.int64), (
                              ("force_x", "N", "force of the part on the node, global"),
                              ("force_y", "N", "force of the part on the node, global"),
                              ("force_z", "N", "force of the part on the node, global"),
                              ("moment_x", "N m", "moment on the node, node frame"),
                              ("moment_y", "N m", "moment on the node, node frame"),
                              ("moment_z", "N m", "moment on the node, node frame")),
                          nmult=6)


register(FlexibleInterfaceFamily())
