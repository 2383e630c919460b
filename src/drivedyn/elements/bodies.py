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

from drivedyn.elements.base import Family, Group, register, scatter_local


@njit(cache=True)
def rigid_body_kernel(
    mass, inertia, gravity,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    nel = mass.shape[0]
    rq = np.zeros(6)
    rl = np.zeros(0)
    M = np.zeros((6, 6))
    C = np.zeros((6, 6))
    K = np.zeros((6, 6))
    G = np.zeros((0, 6))
    for e in range(nel):
        d0 = dofs[e, 0]
        n = lnodes[e, 0]
        m = mass[e]
        J = inertia[e]
        Om = v[d0 + 3 : d0 + 6]
        JOm = J @ Om
        gyro = np.cross(Om, JOm)
        JOd = J @ vd[d0 + 3 : d0 + 6]
        for i in range(3):
            rq[i] = m * vd[d0 + i] - m * gravity[i]
            rq[3 + i] = JOd[i] + gyro[i]
        if want:
            M[:, :] = 0.0
            C[:, :] = 0.0
            for i in range(3):
                M[i, i] = m
                for j in range(3):
                    M[3 + i, 3 + j] = J[i, j]
            # Omega~ J - (J Omega)~
            S = np.zeros((3, 3))
            S[0, 1] = -Om[2]
            S[0, 2] = Om[1]
            S[1, 0] = Om[2]
            S[1, 2] = -Om[0]
            S[2, 0] = -Om[1]
            S[2, 1] = Om[0]
            W = np.zeros((3, 3))
            W[0, 1] = -JOm[2]
            W[0, 2] = JOm[1]
            W[1, 0] = JOm[2]
            W[1, 2] = -JOm[0]
            W[2, 0] = -JOm[1]
            W[2, 1] = JOm[0]
            C[3:6, 3:6] = S @ J - W
        scatter_local(rq, rl, M, C, K, G, 1, lnodes[e], dofs[e], kmap[e], Tn,
                      cM, cC, cK, mode, want, r, rabs, data)
        xv = v[d0 : d0 + 3]
        eout[e, 0] = 0.5 * m * (xv[0] ** 2 + xv[1] ** 2 + xv[2] ** 2) + 0.5 * (
            Om[0] * JOm[0] + Om[1] * JOm[1] + Om[2] * JOm[2]
        )
        eout[e, 1] = -m * (gravity[0] * x[n, 0] + gravity[1] * x[n, 1] + gravity[2] * x[n, 2])
        eout[e, 2] = 0.0
        eout[e, 3] = 0.0
        # aux: angular momentum about the centre of mass, global frame
        Hg = R[n] @ JOm
        aux[e, 0] = Hg[0]
        aux[e, 1] = Hg[1]
        aux[e, 2] = Hg[2]


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

    def tangent_cases(self):
        from drivedyn.elements import _tangent_cases as tc

        return [tc.spinning_body]


register(RigidBodyFamily())
