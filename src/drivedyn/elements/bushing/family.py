"""The bushing family: the group of all bushings of a model (registry ``bushing``)."""

from __future__ import annotations

import numpy as np

from drivedyn.elements.bushing.kernel import (
    COL_DEFL,
    NLAW,
    NPUB,
    OUTPUTS,
    WORK_SIZE,
    bushing_kernel,
)
from drivedyn.elements.bushing.spec import Bushing
from drivedyn.elements.framework.building import make_group, node_dofs, two_markers
from drivedyn.elements.framework.curves import pack_curves
from drivedyn.elements.framework.group import COMMIT_TIME, Group
from drivedyn.elements.framework.registry import Family, register


class BushingFamily(Family):
    """Registry entry of :class:`Bushing`."""

    name = "bushing"
    spec_types = (Bushing,)

    def build(self, specs, ctx) -> Group:
        pA, pB, RmA, RmB, lnodes = two_markers(specs, ctx, "a bushing")
        nel = len(specs)
        laws = [s.laws() for s in specs]
        nbm = max(len(lw[4]) for lw in laws)
        d0 = np.zeros((nel, 3))
        kx = np.zeros((nel, NLAW))
        cx = np.zeros((nel, NLAW))
        pre = np.zeros((nel, NLAW))
        cid = np.full((nel, NLAW), -1, np.int64)
        baxis = np.zeros((nel, max(nbm, 1)), np.int64)
        bk = np.ones((nel, max(nbm, 1)))
        bc = np.ones((nel, max(nbm, 1)))
        nbr = np.zeros(nel, np.int64)
        eoff = np.zeros(nel, np.int64)
        tables = []
        for e, (k, c, p, curves, branches) in enumerate(laws):
            nA, nB = lnodes[e]
            RA0 = ctx.R0[nA] @ RmA[e]
            RB0 = ctx.R0[nB] @ RmB[e]
            # B's frame corrected to A's at the start: rotations count from there
            RmB[e] = RmB[e] @ (RB0.T @ RA0)
            PA0 = ctx.x0[nA] + ctx.R0[nA] @ pA[e]
            PB0 = ctx.x0[nB] + ctx.R0[nB] @ pB[e]
            d0[e] = RA0.T @ (PB0 - PA0)
            kx[e], cx[e], pre[e] = k, c, p
            for j, xa, ya in curves:
                cid[e, j] = len(tables)
                tables.append((xa, ya))
            nbr[e] = len(branches)
            for b, (j, kb, cb) in enumerate(branches):
                baxis[e, b], bk[e, b], bc[e, b] = j, kb, cb
            if nbm:
                # committed state: time, the six deflections, the branch deflections
                eoff[e] = ctx.alloc_state([0.0] * (1 + NLAW + nbm))  # models start at t = 0
        CX, CY, CD, cstart = pack_curves(tables)
        params = (pA, pB, RmA, RmB, d0, kx, cx, pre, cid, CX, CY, CD, cstart, baxis, bk, bc,
                  nbr, np.zeros(WORK_SIZE))
        commit = (COMMIT_TIME, *range(COL_DEFL, COL_DEFL + NLAW),
                  *range(NPUB, NPUB + nbm)) if nbm else ()
        return make_group(
            self.name, specs, bushing_kernel, params, lnodes, node_dofs(ctx, lnodes), OUTPUTS,
            eoff=eoff, nstate=len(commit), commit_cols=commit, naux=NPUB + nbm,
            dissipative=True,
        )


register(BushingFamily())
