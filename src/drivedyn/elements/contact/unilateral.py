"""Unilateral frictional contact by the augmented Lagrangian (family ``unilateral_contact``).

The seeds' contact condition (seeds 000-002, physics.md 3) between a point (origin of marker
B) and the plane of marker A (normal ``n = z_A``): the gap ``d_n = (x_B - x_A) . n`` and the
tangential displacement ``u_t`` (components along ``x_A, y_A``) of the point since the stick
anchor, with the multipliers ``lambda_n, lambda_t`` (3 per contact) and::

    sigma_n = k lambda_n + p d_n,        sigma_t = k lambda_t + p u_t

* ``sigma_n >= 0``: no contact; the rows read ``-k lambda = 0`` (multipliers vanish, no force).
* ``sigma_n < 0``: contact, ``k d_n = 0``; the normal force on B is ``N = -sigma_n`` along n.

  - stick, ``|sigma_t| <= mu N``: ``k u_t = 0``, the friction force is ``-sigma_t``: the point
    does not move relative to its anchor (true sticking, up to the Newton tolerance);
  - slip: the friction force on B is ``-mu N sigma_t/|sigma_t|`` and the rows read
    ``k lambda_t - mu N sigma_t/|sigma_t| = 0`` (Alart-Curnier return mapping).

The anchor is the point's position in A's frame at the last accepted step (kept in the State
while sticking), so ``u_t`` is the slip over the step and the slip force opposes it: Coulomb's
law integrated by backward Euler. Frictionless contact: ``mu = 0``.

``k`` (scaling) and ``p`` (penalty) default to the automatic translational scaling of the
joints.

**Not for impacts.** The constraint is exact (no penetration), so an impact at a non-zero
approach speed is a velocity jump within one step, which the index-3 generalized-alpha scheme
does not resolve physically: the multipliers oscillate and the contact may release with any
leftover velocity (measured: a ball dropped from 5 cm rebounds to between 2 and 30 cm
depending on rho_inf and the step, i.e. energy is even created). This is the seeds'
"convergence problems due to impact phenomena" of the Lagrange multiplier contact. Use a
:class:`~drivedyn.elements.contact.PlaneContact` with a continuous-impact law where bodies
hit; use this element for persistent contact where true sticking matters (bodies set down at
rest, loaded faces, stick-slip).

Consistent initial accelerations and velocities (``MODE_ACC``, ``MODE_VEL``): the contact is
active if the State says so (set from the initial gap and velocity, then at every accepted
step), and its normal row is then a bilateral constraint. A contact sliding initially (State
flag, from the initial velocities) gets the Coulomb force ``mu N`` against its sliding
velocity, and its velocity is not projected away. Otherwise stick or slip is chosen as in the
dynamics from the current multipliers, with ``sigma_t = k lambda_t + p h^2 a_t``
(``sigma_t = k lambda_t + p h^2 v_t`` for velocities; ``a_t`` the tangential acceleration,
``h`` = 1 ms: stick means ``a_t = 0``, slip opposes ``a_t``); the group sets
``extra["active_set"]`` so that
:func:`~drivedyn.solver.simulate.consistent_initial_state` re-solves until that choice
settles (a body released at rest on a slope steeper than ``atan(mu)`` starts slipping). The
slip rows depend on the normal multiplier, so the group also asks for multiplier-multiplier
entries in the matrix pattern (``extra["coupled_multipliers"]``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.contact.common import axial_motion, commit_range
from drivedyn.elements.framework.building import make_group, two_markers
from drivedyn.elements.framework.checks import check_param, check_param_optional
from drivedyn.elements.framework.contract import (
    MODE_ACC,
    MODE_DYN,
    MODE_VEL,
    local_arrays_at,
    local_size,
    tangent_columns,
)
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.primitives import prim_axial, quad_form
from drivedyn.elements.framework.registry import Family, TwoMarkerSpec, register
from drivedyn.elements.framework.work_arrays import carve

H_ACC = 1e-3  # [s]: sigma_t = k lambda_t + p H_ACC^2 a_t (or v_t) at acceleration level
NSTATE_AL = 4  # active flag, sliding flag, anchor along x_A, anchor along y_A
NAUX_AL = 8

_L123 = local_size.py_func(12, 3)  # the plain functions: nothing compiled at import
#: entries of the contacts' work buffer (their last parameter, ``work``)
WORK_SIZE = _L123 + 105 + 3 * sc.GRAD_HESS_SIZE_12 + sc.WORKSPACE_SIZE


@njit(cache=True, inline="always")
def _scatter_multipliers(B, Gq, D, nm, C, e):
    """Non-symmetric multiplier blocks of element ``e``: ``B = d rq/d lam`` (12, nm),
    ``Gq = d rl/d q`` (nm, 12; times the tangent operator on rotation columns in MODE_DYN) and
    ``D = d rl/d lam`` (nm, nm)."""
    lnodes_e = C[sc.LNODES][e]
    kmap_e = C[sc.KMAP][e]
    Tn = C[sc.TN]
    data = C[sc.DATA]
    nloc = 12 + nm
    for i in range(nm):
        for j in range(12):
            p = kmap_e[j * nloc + 12 + i]
            if p >= 0:
                data[p] += B[j, i]
    if sc.mode_of(C) == MODE_DYN:
        for a in range(2):
            tangent_columns(Gq, nm, 6 * a + 3, Tn, lnodes_e[a])
    for i in range(nm):
        for j in range(12):
            p = kmap_e[(12 + i) * nloc + j]
            if p >= 0:
                data[p] += Gq[i, j]
        for j in range(nm):
            p = kmap_e[(12 + i) * nloc + 12 + j]
            if p >= 0:
                data[p] += D[i, j]


@njit(cache=True)
def unilateral_kernel(
    pA, pB, RmA, mu, kk, pp, cacc, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    buf = sc.work_buffer(work, WORK_SIZE)  # the work arrays are views of the group's buffer
    o = _L123
    gh = sc.GRAD_HESS_SIZE_12
    W = (local_arrays_at(buf, 0, 12, 3), carve(buf, o, (12, 3)), carve(buf, o + 36, (3, 12)),
         carve(buf, o + 72, (3, 3)), sc.grad_hess_at(buf, o + 81, 12),
         sc.grad_hess_at(buf, o + 81 + gh, 12), sc.grad_hess_at(buf, o + 81 + 2 * gh, 12),
         carve(buf, o + 81 + 3 * gh, 12), carve(buf, o + 93 + 3 * gh, 12),
         sc.workspace_at(buf, o + 105 + 3 * gh))
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    L, B, Gq, D, (gn, Hn), (g1, H1), (g2, H2), vl, al, (ws, wv) = W
    full = sc.full_pass(want, mode)
    rq, rl, M, _, K, _ = L
    for e in range(sc.count(C)):
        nA, nB = sc.pair(C, e)
        o = sc.state_offset(C, e)
        RA = R[nA]
        RB = R[nB]
        k = kk[e]
        p = pp[e]
        m = mu[e]
        sc.velocities(C, e, 12, vl)
        if mode == MODE_ACC:
            sc.accelerations(C, e, 12, al)
        dn = prim_axial(x[nA], RA, x[nB], RB, pA[e], pB[e], RmA[e, :, 2], gn, Hn, full, ws, wv)
        t1 = prim_axial(x[nA], RA, x[nB], RB, pA[e], pB[e], RmA[e, :, 0], g1, H1, full, ws, wv)
        t2 = prim_axial(x[nA], RA, x[nB], RB, pA[e], pB[e], RmA[e, :, 1], g2, H2, full, ws, wv)
        ln_ = sc.multiplier(C, e, 12, 0)
        l1 = sc.multiplier(C, e, 12, 1)
        l2 = sc.multiplier(C, e, 12, 2)
        vn = 0.0
        v1 = 0.0
        v2 = 0.0
        for a in range(12):
            vn += gn[a] * vl[a]
            v1 += g1[a] * vl[a]
            v2 += g2[a] * vl[a]
        vt = np.sqrt(v1 * v1 + v2 * v2)
        # the tangential kinematic quantity of the mode and its weight in sigma_t: slip since
        # the anchor (MODE_DYN), tangential acceleration (MODE_ACC) or velocity (MODE_VEL);
        # its derivative with respect to the mode's unknown (q, vd or v) is g_t in all three
        if mode == MODE_DYN:
            z1 = t1 - es[o + 2]
            z2 = t2 - es[o + 3]
            cz = p
        elif mode == MODE_ACC:
            z1 = quad_form(H1, vl)
            z2 = quad_form(H2, vl)
            for a in range(12):
                z1 += g1[a] * al[a]
                z2 += g2[a] * al[a]
            cz = cacc[e]
        else:
            z1 = v1
            z2 = v2
            cz = cacc[e]
        sn = k * ln_ + p * dn
        s1 = k * l1 + cz * z1
        s2 = k * l2 + cz * z2
        for a in range(12):
            rq[a] = 0.0
        for i in range(3):
            rl[i] = 0.0
        if full:
            K[:, :] = 0.0
            M[:, :] = 0.0
            B[:, :] = 0.0
            Gq[:, :] = 0.0
            D[:, :] = 0.0
        if mode == MODE_DYN:
            active = sn < 0.0
        else:
            active = es[o] > 0.5
        N = -sn if active else 0.0
        stick = False
        slide = False
        f1 = 0.0
        f2 = 0.0
        if not active:
            rl[0] = -k * ln_
            rl[1] = -k * l1
            rl[2] = -k * l2
            if full:
                for i in range(3):
                    D[i, i] = -k
        else:
            for a in range(12):
                rq[a] += sn * gn[a]
            if full:
                for a in range(12):
                    B[a, 0] = k * gn[a]
                    Gq[0, a] = k * gn[a]
                    if mode == MODE_DYN:
                        for b in range(12):
                            K[a, b] += sn * Hn[a, b] + p * gn[a] * gn[b]
            if mode == MODE_DYN:
                rl[0] = k * dn
            elif mode == MODE_ACC:
                s = quad_form(Hn, vl)
                for a in range(12):
                    s += gn[a] * al[a]
                rl[0] = k * s
            else:
                rl[0] = k * vn
            st = np.sqrt(s1 * s1 + s2 * s2)
            if m <= 0.0:
                rl[1] = -k * l1
                rl[2] = -k * l2
                if full:
                    D[1, 1] = -k
                    D[2, 2] = -k
            elif mode != MODE_DYN and es[o + 1] > 0.5 and vt > 0.0:
                # initialisation of a sliding contact: Coulomb force mu N against the sliding
                # velocity (linear in lambda_n); the velocity is not projected
                slide = True
                h1 = v1 / vt
                h2 = v2 / vt
                f1 = m * N * h1
                f2 = m * N * h2
                for a in range(12):
                    rq[a] += f1 * g1[a] + f2 * g2[a]
                if full:
                    for a in range(12):
                        B[a, 0] += -k * m * (h1 * g1[a] + h2 * g2[a])
                if mode == MODE_ACC:
                    rl[1] = k * l1 - f1
                    rl[2] = k * l2 - f2
                    if full:
                        D[1, 0] = k * m * h1
                        D[2, 0] = k * m * h2
                        D[1, 1] = k
                        D[2, 2] = k
                else:
                    rl[1] = -k * l1
                    rl[2] = -k * l2
                    if full:
                        D[1, 1] = -k
                        D[2, 2] = -k
            elif st <= m * N:
                stick = True
                f1 = s1
                f2 = s2
                rl[1] = k * z1
                rl[2] = k * z2
                for a in range(12):
                    rq[a] += s1 * g1[a] + s2 * g2[a]
                if full:
                    for a in range(12):
                        B[a, 1] = k * g1[a]
                        B[a, 2] = k * g2[a]
                        Gq[1, a] = k * g1[a]
                        Gq[2, a] = k * g2[a]
                        for b in range(12):
                            gg = g1[a] * g1[b] + g2[a] * g2[b]
                            if mode == MODE_DYN:
                                K[a, b] += s1 * H1[a, b] + s2 * H2[a, b] + p * gg
                            elif mode == MODE_ACC:
                                M[a, b] += cz * gg
            else:
                slide = True
                h1 = s1 / st
                h2 = s2 / st
                f1 = m * N * h1
                f2 = m * N * h2
                rl[1] = k * l1 - f1
                rl[2] = k * l2 - f2
                for a in range(12):
                    rq[a] += f1 * g1[a] + f2 * g2[a]
                if full:
                    c = m * N / st
                    q11 = c * (1.0 - h1 * h1)
                    q12 = -c * h1 * h2
                    q22 = c * (1.0 - h2 * h2)
                    for a in range(12):
                        # derivative of f_i with respect to the mode's unknown: cz (Q g_t)_i,
                        # and in MODE_DYN through N = -(k lambda_n + p d_n): -mu h_i p g_n
                        d1 = cz * (q11 * g1[a] + q12 * g2[a])
                        d2 = cz * (q12 * g1[a] + q22 * g2[a])
                        if mode == MODE_DYN:
                            d1 -= p * m * h1 * gn[a]
                            d2 -= p * m * h2 * gn[a]
                        Gq[1, a] = -d1
                        Gq[2, a] = -d2
                        if mode != MODE_VEL:
                            for b in range(12):
                                gd = g1[b] * d1 + g2[b] * d2
                                if mode == MODE_DYN:
                                    K[b, a] += gd
                                else:
                                    M[b, a] += gd
                        B[a, 0] += -k * m * (h1 * g1[a] + h2 * g2[a])
                        B[a, 1] = k * (q11 * g1[a] + q12 * g2[a])
                        B[a, 2] = k * (q12 * g1[a] + q22 * g2[a])
                    if mode == MODE_DYN:
                        for a in range(12):
                            for b in range(12):
                                K[a, b] += f1 * H1[a, b] + f2 * H2[a, b]
                    D[1, 0] = k * m * h1
                    D[2, 0] = k * m * h2
                    D[1, 1] = k * (1.0 - q11)
                    D[1, 2] = -k * q12
                    D[2, 1] = -k * q12
                    D[2, 2] = k * (1.0 - q22)
        sc.scatter(C, L, e, 2, full)
        if full and sc.wants_matrix(C):
            _scatter_multipliers(B, Gq, D, 3, C, e)
        pdis = f1 * v1 + f2 * v2 if slide else 0.0
        sc.energy(C, e, 0.0, 0.0, 0.0, pdis)
        # state after an accepted step: flags; anchor kept while sticking
        sc.report(C, e, (N, dn, vn, vt, np.sqrt(f1 * f1 + f2 * f2), 1.0 if stick else 0.0,
                         1.0 if active else 0.0, pdis, 1.0 if active else 0.0,
                         1.0 if slide else 0.0, es[o + 2] if stick else t1,
                         es[o + 3] if stick else t2))


@dataclass(frozen=True)
class UnilateralContact(TwoMarkerSpec):
    """Point (origin of ``marker_b``) on the plane of ``marker_a`` (normal = its z axis) as an
    augmented-Lagrangian unilateral constraint with Coulomb stick/slip friction.

    Attributes:
        name: unique element name.
        marker_a: the plane (origin on it, z axis = normal towards the free side).
        marker_b: the contact point.
        mu: Coulomb friction coefficient [-] >= 0 (0: frictionless).
        k: scaling factor [N/m] > 0 of the multipliers; None = automatic (as joints).
        p: penalty (regularisation) parameter [N/m] >= 0; None = k.
    """

    mu: float = 0.0
    k: float | None = None
    p: float | None = None
    family: ClassVar[str] = "unilateral_contact"
    units: ClassVar[dict[str, str]] = {"mu": "1", "k": "N/m", "p": "N/m"}

    def validate(self) -> None:
        check_param(self, "mu", 0.0)
        check_param_optional(self, "k", 0.0, strict=True)
        check_param_optional(self, "p", 0.0)


class UnilateralContactFamily(Family):
    """Registry entry of :class:`UnilateralContact`."""

    name = "unilateral_contact"

    def build(self, specs, ctx) -> Group:
        pA, pB, RmA, _, lnodes = two_markers(specs, ctx, "a contact")
        nel = len(specs)
        kk = np.zeros(nel)
        pp = np.zeros(nel)
        dofs = np.zeros((nel, 15), np.int64)
        eoff = np.zeros(nel, np.int64)
        tol = ctx.spec.settings.assembly_tolerance
        for e, s in enumerate(specs):
            nA, nB = lnodes[e]
            kk[e], pp[e] = ctx.scaling(s.k, s.p, False)
            gap, gap_rate = axial_motion(ctx, nA, pA[e], RmA[e][:, 2], nB, pB[e])
            a1, r1 = axial_motion(ctx, nA, pA[e], RmA[e][:, 0], nB, pB[e])
            a2, r2 = axial_motion(ctx, nA, pA[e], RmA[e][:, 1], nB, pB[e])
            active = gap <= tol and gap_rate <= 0.0
            sliding = active and math.hypot(r1, r2) > 1e-12
            eoff[e] = ctx.alloc_state([float(active), float(sliding), a1, a2])
            m0 = ctx.alloc_mult(3, f"unilateral_contact {s.name}", [kk[e]] * 3,
                                bilateral=False)
            dofs[e] = ctx.local_dofs([nA, nB], m0, 3)
        g = make_group(
            self.name, specs, unilateral_kernel,
            (pA, pB, RmA, np.array([float(s.mu) for s in specs]), kk, pp, pp * H_ACC**2,
             np.zeros(WORK_SIZE)),
            lnodes, dofs,
            (("normal_force", "N", "normal contact force N = -sigma_n (>= 0)"),
             ("gap", "m", "gap of the point above the plane"),
             ("gap_rate", "m/s", "rate of the gap"),
             ("sliding_speed", "m/s", "tangential speed of the point relative to the plane"),
             ("friction_force", "N", "friction force magnitude"),
             ("stick", "1", "1 while sticking"),
             ("active", "1", "1 while in contact"),
             ("dissipated_power", "W", "friction power (slip)")),
            nmult=3, eoff=eoff, nstate=NSTATE_AL, commit_cols=commit_range(NAUX_AL, NSTATE_AL),
            naux=NAUX_AL + NSTATE_AL, dissipative=True,
        )
        g.extra["coupled_multipliers"] = True
        g.extra["active_set"] = True
        return g


register(UnilateralContactFamily())
