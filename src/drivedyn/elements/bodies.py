"""Rigid body inertia and gravity (family ``rigid_body``).

The node of a rigid body sits at its centre of mass with the body's orientation, so the mass
matrix is constant and block diagonal: ``diag(m I, J)`` with ``J`` the inertia about the
centre of mass in the body frame. Per node the residual is::

    r_x = m xdd - m g                 (global frame)  [N]
    r_O = J Omegadot + Omega x J Omega (body frame)   [N m]

with the gyroscopic damping block ``d(Omega x J Omega)/dOmega = Omega~ J - (J Omega)~``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from drivedyn.elements.base import MODE_ACC, Family, Group, local_arrays, register, scatter_element


@njit(cache=True, inline="always")
def _rigid_body_kernel_element(P, I, S, Cc, O, W, full):
    mass, inertia, gravity = P
    lnodes, dofs, kmap, eoff = I
    x, R, v, vd, lam, es, tfv, t = S
    Tn, cM, cC, cK, mode, want = Cc
    r, rabs, data, eout, aux = O
    nel, rq, rl, M, C, K, G, JOm, JOd = W
    for e in range(nel):
        d0 = dofs[e, 0]
        n = lnodes[e, 0]
        m = mass[e]
        J = inertia[e]
        o0 = v[d0 + 3]
        o1 = v[d0 + 4]
        o2 = v[d0 + 5]
        for i in range(3):
            JOm[i] = J[i, 0] * o0 + J[i, 1] * o1 + J[i, 2] * o2
            JOd[i] = J[i, 0] * vd[d0 + 3] + J[i, 1] * vd[d0 + 4] + J[i, 2] * vd[d0 + 5]
        for i in range(3):
            rq[i] = m * vd[d0 + i] - m * gravity[i]
        rq[3] = JOd[0] + o1 * JOm[2] - o2 * JOm[1]
        rq[4] = JOd[1] + o2 * JOm[0] - o0 * JOm[2]
        rq[5] = JOd[2] + o0 * JOm[1] - o1 * JOm[0]
        if full:
            M[:, :] = 0.0
            C[:, :] = 0.0
            for i in range(3):
                M[i, i] = m
                for j in range(3):
                    M[3 + i, 3 + j] = J[i, j]
            # d(Omega x J Omega)/dOmega = Omega~ J - (J Omega)~
            for j in range(3):
                C[3, 3 + j] = o1 * J[2, j] - o2 * J[1, j]
                C[4, 3 + j] = o2 * J[0, j] - o0 * J[2, j]
                C[5, 3 + j] = o0 * J[1, j] - o1 * J[0, j]
            C[3, 4] += JOm[2]
            C[3, 5] -= JOm[1]
            C[4, 3] -= JOm[2]
            C[4, 5] += JOm[0]
            C[5, 3] += JOm[1]
            C[5, 4] -= JOm[0]
        scatter_element(rq, rl, M, C, K, G, 1, lnodes[e], dofs[e], kmap[e], Tn, cM, cC,
                        cK, mode,want, full, r, rabs, data)
        # rabs holds the sum of |terms| of each equation (the convergence scale): replace
        # the |sum| that scatter_local added by |inertia| + |gyroscopic| + |weight|
        for i in range(3):
            rabs[d0 + i] += abs(m * vd[d0 + i]) + abs(m * gravity[i]) - abs(rq[i])
        rabs[d0 + 3] += abs(JOd[0]) + abs(o1 * JOm[2]) + abs(o2 * JOm[1]) - abs(rq[3])
        rabs[d0 + 4] += abs(JOd[1]) + abs(o2 * JOm[0]) + abs(o0 * JOm[2]) - abs(rq[4])
        rabs[d0 + 5] += abs(JOd[2]) + abs(o0 * JOm[1]) + abs(o1 * JOm[0]) - abs(rq[5])
        eout[e, 0] = 0.5 * m * (v[d0] ** 2 + v[d0 + 1] ** 2 + v[d0 + 2] ** 2) + 0.5 * (
            o0 * JOm[0] + o1 * JOm[1] + o2 * JOm[2]
        )
        eout[e, 1] = -m * (gravity[0] * x[n, 0] + gravity[1] * x[n, 1] + gravity[2] * x[n, 2])
        eout[e, 2] = 0.0
        eout[e, 3] = 0.0
        # aux: angular momentum about the centre of mass, global frame
        Rn = R[n]
        for i in range(3):
            aux[e, i] = Rn[i, 0] * JOm[0] + Rn[i, 1] * JOm[1] + Rn[i, 2] * JOm[2]


@njit(cache=True)
def rigid_body_kernel(
    mass, inertia, gravity,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    nel = mass.shape[0]
    rq, rl, M, C, K, G = local_arrays(6, 0)
    JOm = np.zeros(3)
    JOd = np.zeros(3)
    P = (mass, inertia, gravity)
    I = (lnodes, dofs, kmap, eoff)
    S = (x, R, v, vd, lam, es, tfv, t)
    Cc = (Tn, cM, cC, cK, mode, want)
    O = (r, rabs, data, eout, aux)
    W = (nel, rq, rl, M, C, K, G, JOm, JOd)
    if want or mode == MODE_ACC:
        _rigid_body_kernel_element(P, I, S, Cc, O, W, True)
    else:
        _rigid_body_kernel_element(P, I, S, Cc, O, W, False)


class RigidBodyFamily(Family):
    """Inertia and weight of every rigid body (built from the model's nodes, not from specs)."""

    name = "rigid_body"

    def build(self, infos, ctx) -> Group:
        idx = [i for i, inf in enumerate(infos) if inf.mass > 0]
        mass = np.array([infos[i].mass for i in idx])
        inertia = np.array([infos[i].inertia for i in idx]).reshape(-1, 3, 3)
        lnodes = np.array(idx, dtype=np.int64).reshape(-1, 1)
        dofs = np.array([ctx.local_dofs([i], 0, 0) for i in idx], dtype=np.int64).reshape(-1, 6)
        return Group(
            family=self.name,
            names=[infos[i].name for i in idx],
            kernel=rigid_body_kernel,
            params=(mass, inertia, np.asarray(ctx.gravity, float)),
            lnodes=lnodes,
            nmult=0,
            dofs=dofs,
            eoff=np.zeros(len(idx), np.int64),
            aux_names=("angular_momentum_x", "angular_momentum_y", "angular_momentum_z"),
            aux_units=("kg m^2/s",) * 3,
            aux_desc=("angular momentum about the centre of mass, global frame",) * 3,
        )


register(RigidBodyFamily())
