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

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.framework.building import make_group, node_dofs
from drivedyn.elements.framework.contract import local_arrays_at, local_size
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.registry import Family, register
from drivedyn.elements.framework.work_arrays import carve

_L6 = local_size.py_func(6, 0)  # the plain function: nothing compiled at import
#: entries of the rigid bodies' work buffer (their last parameter, ``work``)
WORK_SIZE = _L6 + 6


@njit(cache=True)
def rigid_body_kernel(
    mass, inertia, gravity, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    buf = sc.work_buffer(work, WORK_SIZE)  # the work arrays are views of the group's buffer
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    L, JOm, JOd = (local_arrays_at(buf, 0, 6, 0), carve(buf, _L6, 3), carve(buf, _L6 + 3, 3))
    full = sc.full_pass(want, mode)
    rq, _, M, Cd, _, _ = L
    rabs = C[sc.RABS]
    for e in range(sc.count(C)):
        d0 = sc.first_dof(C, e)
        n = sc.node(C, e, 0)
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
            Cd[:, :] = 0.0
            for i in range(3):
                M[i, i] = m
                for j in range(3):
                    M[3 + i, 3 + j] = J[i, j]
            # d(Omega x J Omega)/dOmega = Omega~ J - (J Omega)~
            for j in range(3):
                Cd[3, 3 + j] = o1 * J[2, j] - o2 * J[1, j]
                Cd[4, 3 + j] = o2 * J[0, j] - o0 * J[2, j]
                Cd[5, 3 + j] = o0 * J[1, j] - o1 * J[0, j]
            Cd[3, 4] += JOm[2]
            Cd[3, 5] -= JOm[1]
            Cd[4, 3] -= JOm[2]
            Cd[4, 5] += JOm[0]
            Cd[5, 3] += JOm[1]
            Cd[5, 4] -= JOm[0]
        sc.scatter(C, L, e, 1, full)
        # rabs holds the sum of |terms| of each equation (the convergence scale): replace
        # the |sum| that scatter added by |inertia| + |gyroscopic| + |weight|
        for i in range(3):
            rabs[d0 + i] += abs(m * vd[d0 + i]) + abs(m * gravity[i]) - abs(rq[i])
        rabs[d0 + 3] += abs(JOd[0]) + abs(o1 * JOm[2]) + abs(o2 * JOm[1]) - abs(rq[3])
        rabs[d0 + 4] += abs(JOd[1]) + abs(o2 * JOm[0]) + abs(o0 * JOm[2]) - abs(rq[4])
        rabs[d0 + 5] += abs(JOd[2]) + abs(o0 * JOm[1]) + abs(o1 * JOm[0]) - abs(rq[5])
        kinetic = 0.5 * m * (v[d0] ** 2 + v[d0 + 1] ** 2 + v[d0 + 2] ** 2) + 0.5 * (
            o0 * JOm[0] + o1 * JOm[1] + o2 * JOm[2]
        )
        weight = -m * (gravity[0] * x[n, 0] + gravity[1] * x[n, 1] + gravity[2] * x[n, 2])
        sc.energy(C, e, kinetic, weight, 0.0, 0.0)
        # angular momentum about the centre of mass, global frame
        Rn = R[n]
        sc.report(C, e, (Rn[0, 0] * JOm[0] + Rn[0, 1] * JOm[1] + Rn[0, 2] * JOm[2],
                         Rn[1, 0] * JOm[0] + Rn[1, 1] * JOm[1] + Rn[1, 2] * JOm[2],
                         Rn[2, 0] * JOm[0] + Rn[2, 1] * JOm[1] + Rn[2, 2] * JOm[2]))


class RigidBodyFamily(Family):
    """Inertia and weight of every rigid body (built from the model's nodes, not from specs)."""

    name = "rigid_body"

    def build(self, infos, ctx) -> Group:
        bodies = [inf for inf in infos if inf.mass > 0]
        lnodes = np.array([i for i, inf in enumerate(infos) if inf.mass > 0],
                          np.int64).reshape(-1, 1)
        return make_group(
            self.name, bodies, rigid_body_kernel,
            (np.array([b.mass for b in bodies]),
             np.array([b.inertia for b in bodies]).reshape(-1, 3, 3),
             np.asarray(ctx.gravity, float), np.zeros(WORK_SIZE)),
            lnodes, node_dofs(ctx, lnodes),
            tuple((f"angular_momentum_{c}", "kg m^2/s",
                   "angular momentum about the centre of mass, global frame") for c in "xyz"),
        )


register(RigidBodyFamily())
