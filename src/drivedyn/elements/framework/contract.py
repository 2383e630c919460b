"""The kernel contract: how every element family's kernel is called and what it adds.

An element *family* (``Hinge``, ``SpringDamper``, ``RigidBody``...) is a frozen parameter
record (the spec the user writes) plus a :class:`~drivedyn.elements.framework.registry.Family`
that turns every spec of that family in a model into one
:class:`~drivedyn.elements.framework.group.Group`: parameters stored as arrays, local-to-global
index maps, and a numba kernel evaluated over all elements at once.

Kernel contract (every family's kernel has these trailing arguments, see :data:`COMMON_ARGS`)::

    kernel(<family params...>,
           lnodes,   # (nel, nnode)   node index of each local node (nn = ground)
           dofs,     # (nel, nloc)    global equation index of each local dof (-1: none)
           kmap,     # (nel, nloc*nloc) index into the CSC data array (-1: not stored)
           eoff,     # (nel,)         offset of the element's internal state in ``es``
           x, R,     # (nn+1, 3), (nn+1, 3, 3) node positions [m] / rotations (row nn = ground)
           v, vd,    # (ndof,) velocities / accelerations: per node [xdot (global), Omega (body)]
           lam,      # (nmult,) multipliers; constraint force sigma = k lam + p Phi
           es,       # (nstate,) element internal state (committed at step acceptance)
           tfv,      # (nfun, 4) time functions: value, d/dt, d2/dt2, integral from 0
           t,        # time [s]
           Tn,       # (nn+1, 3, 3) tangent operator of each node's rotation increment
           cM, cC, cK, mode, want,
           r, rabs,  # (neq,) residual and sum of |contributions| (for scaled convergence)
           data,     # (nnz,) CSC values of the iteration matrix
           eout,     # (nel, 4) kinetic energy, potential energy, power input, power dissipated
           aux)      # (nel, naux) named per-element outputs (forces, gaps, angles...)

Local dofs of an element are ``6 * nnode`` node dofs (per node: 3 translations [m] in the
global frame, 3 rotations [rad] as right (body-frame) increments) followed by its ``nmult``
multipliers. A kernel computes, per element, the local residual ``rq`` (generalised forces,
positive = internal/inertial, so ``r = M vd + f_int - f_ext``), the constraint residual ``rl``,
and the local matrices ``M = d rq / d vd``, ``C = d rq / d v``, ``K = d rq / d q`` (right
perturbations) and ``G = d rl / d q``, then calls :func:`scatter_local`.

Families write their kernels on :mod:`drivedyn.elements.framework.scaffold` (dispatch, common
arguments, scatter and outputs) and build their groups with
:mod:`drivedyn.elements.framework.building`.

Modes: ``MODE_DYN`` (time step / statics: ``rl = k Phi``; matrix
``[cM M + cC C + cK K T, G^T; G T, 0]``), ``MODE_ACC`` (consistent accelerations:
``rl = k (dPhi/dq . vd + v^T H v + Phi_tt)``, matrix ``[M, G^T; G, 0]``) and ``MODE_VEL``
(velocity projection: ``rl = k (dPhi/dq . v + Phi_t)``, same matrix).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from drivedyn.elements.framework.work_arrays import carve

MODE_DYN = 0
MODE_ACC = 1
MODE_VEL = 2


@njit(cache=True, inline="always")
def scatter_local(
    rq, rl, M, C, K, G, nnode, lnodes, dofs, kmap, Tn, cM, cC, cK, mode, want, r, rabs, data
):
    """Add one element's local residual and matrices into the global arrays.

    ``rq`` (nd,), ``rl`` (nm,), ``M, C, K`` (nd, nd), ``G`` (nm, nd) with ``nd = 6 nnode``.
    In ``MODE_DYN`` the K and G columns of each node's rotation dofs are post-multiplied by
    the node's tangent operator ``Tn`` (Newton corrections are increments of the Lie-algebra
    step ``h dq``, not right perturbations of the new rotation).
    """
    nd = 6 * nnode
    nm = rl.shape[0]
    for i in range(nd):
        gi = dofs[i]
        if gi >= 0:
            r[gi] += rq[i]
            rabs[gi] += abs(rq[i])
    for i in range(nm):
        gi = dofs[nd + i]
        if gi >= 0:
            r[gi] += rl[i]
            rabs[gi] += abs(rl[i])
    if want:
        _scatter_matrix(M, C, K, G, nnode, nm, lnodes, kmap, Tn, cM, cC, cK, mode, data)


@njit(cache=True)
def local_arrays(nd, nm):
    """Work arrays of one element for :func:`scatter_local`: ``rq`` (nd,), ``rl`` (nm,),
    ``M, C, K`` (nd, nd) and ``G`` (nm, nd), zeroed; allocated once per kernel call, as views
    of one buffer (:mod:`drivedyn.elements.framework.work_arrays`)."""
    return local_arrays_at(np.zeros(local_size(nd, nm)), 0, nd, nm)


@njit(cache=True, inline="always")
def local_size(nd: int, nm: int) -> int:
    """Entries of :func:`local_arrays` ``(nd, nm)`` in one buffer."""
    return nd + nm + 3 * nd * nd + nm * nd


#: entries of ``local_arrays(12, 0)`` (a two-node element without multipliers), from the
#: plain function: a module computing its work size from it compiles nothing at import
LOCAL_SIZE_12 = local_size.py_func(12, 0)


@njit(cache=True, inline="always")
def local_arrays_at(buf, o, nd, nm):
    """:func:`local_arrays` as views of ``buf`` from entry ``o`` (:func:`local_size` entries;
    zeroed by the caller)."""
    a = o + nd + nm
    return (carve(buf, o, nd), carve(buf, o + nd, nm), carve(buf, a, (nd, nd)),
            carve(buf, a + nd * nd, (nd, nd)), carve(buf, a + 2 * nd * nd, (nd, nd)),
            carve(buf, a + 3 * nd * nd, (nm, nd)))


@njit(cache=True, inline="always")
def scatter_element(
    rq, rl, M, C, K, G, nnode, lnodes, dofs, kmap, Tn, cM, cC, cK, mode, want, full, r, rabs,
    data,
):
    """:func:`scatter_local` from an element loop: with ``full`` false (a residual-only
    evaluation) no matrix is scattered."""
    scatter_local(rq, rl, M, C, K, G, nnode, lnodes, dofs, kmap, Tn, cM, cC, cK, mode,
                  want and full, r, rabs, data)


@njit(cache=True, inline="always")
def tangent_columns(A, nrows, c0, Tn, node):
    """``A[:nrows, c0:c0+3] <- A[:nrows, c0:c0+3] Tn[node]``: the columns of a node's rotation
    dofs times its tangent operator (``MODE_DYN``)."""
    for i in range(nrows):
        a0 = A[i, c0]
        a1 = A[i, c0 + 1]
        a2 = A[i, c0 + 2]
        for j in range(3):
            A[i, c0 + j] = a0 * Tn[node, 0, j] + a1 * Tn[node, 1, j] + a2 * Tn[node, 2, j]


@njit(cache=True)
def _scatter_matrix(M, C, K, G, nnode, nm, lnodes, kmap, Tn, cM, cC, cK, mode, data):
    """Matrix part of :func:`scatter_local` (out of line so that residual-only evaluations
    do not carry its code in their loops)."""
    nd = 6 * nnode
    nloc = nd + nm
    # multiplier columns: d rq / d lam = G^T (no tangent operator: lam is not on the group)
    for i in range(nm):
        for j in range(nd):
            p = kmap[j * nloc + nd + i]
            if p >= 0:
                data[p] += G[i, j]
    if mode == MODE_DYN:
        # K T and G T on rotation columns
        for a in range(nnode):
            tangent_columns(K, nd, 6 * a + 3, Tn, lnodes[a])
            tangent_columns(G, nm, 6 * a + 3, Tn, lnodes[a])
        for i in range(nd):
            for j in range(nd):
                p = kmap[i * nloc + j]
                if p >= 0:
                    data[p] += cM * M[i, j] + cC * C[i, j] + cK * K[i, j]
    else:
        for i in range(nd):
            for j in range(nd):
                p = kmap[i * nloc + j]
                if p >= 0:
                    data[p] += M[i, j]
    for i in range(nm):
        for j in range(nd):
            p = kmap[(nd + i) * nloc + j]
            if p >= 0:
                data[p] += G[i, j]
