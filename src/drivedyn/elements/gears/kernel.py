"""The gear pair's kernel (numba): flank approach, mesh law, tooth friction and outputs of all
gear pairs of a model (formulation: :mod:`drivedyn.elements.gears`).

Per element: the mesh coordinates ``s`` (:mod:`~drivedyn.elements.gears.kinematics`), the
drive and coast flank approaches, the unilateral spring-damper of each flank with the
stiffness of :func:`~drivedyn.elements.gears.stiffness.mesh_stiffness`, the regularised
Coulomb friction on the sliding velocity, and the generalised force and matrices by the
chain rule. Contact status changes the iteration matrix, so a flank within
:data:`TANGENT_BAND` of contact while neither flank is loaded lends its stiffness to the
matrix (not to the residual).

With ``flank_onset = d > 0`` (:class:`~drivedyn.elements.gears.GearPair`) a flank's elastic
force rises smoothly (C1) over the first ``d`` of approach ``u``: ``k u^2 / (2 d)`` for
``u < d``, then ``k (u - d/2)``, from the potential ``k W(u)`` (:func:`_onset`; ``d = 0``:
the sharp law ``k u``). With the stiffness jumping from 0 to ``k`` at first touch, a flank
closing within a step made Newton diverge: in a zero-torque hold of the Type C vehicle
configuration 134 failures in 0.3 s, every one at the sun, and steps of 67 us (median)
against the 0.2 ms of a loaded hold. With a 20 nm onset the same hold runs at 0.2 ms without
a failure (the TORSEN model files set it; 20 nm is a five-hundredth of a loaded flank's
deflection, about 10 um under the benches' torques).

Speed: the loop over parallel pairs is a separate copy with the kind a compile-time
constant (fixed loop lengths: 1.5x faster), in the residual and the matrix pass alike; only
bevel and crossed pairs run the copy with their code, and the assembly of the matrices is
compiled out of line. A residual-only pass over parallel pairs takes their primitives, rates
and generalised force from :mod:`~drivedyn.elements.gears.parallel_rows` (scalar arithmetic,
the same bits; 199 spur pairs 35 -> 28 us).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.framework.contract import LOCAL_SIZE_12, local_arrays_at
from drivedyn.elements.framework.primitives import cross
from drivedyn.elements.framework.work_arrays import carve
from drivedyn.elements.gears.kinematics import (
    KIND_PARALLEL,
    NP,
    NS,
    chain_matrices,
    parallel_coords,
    projections,
    skew_coords,
)
from drivedyn.elements.gears.parallel_rows import (
    parallel_chain,
    parallel_projections,
    parallel_rates,
)
from drivedyn.elements.gears.stiffness import mesh_stiffness

TANGENT_BAND = 1e-12  # [m] flank gap within which contact is anticipated in the matrix

GEAR_AUX = (
    ("normal_force", "N", "normal tooth force (positive: drive flank, negative: coast flank)"),
    ("tangential_force", "N", "mesh force on wheel B along the tangent t of wheel A at the "
     "pitch point (gear frame)"),
    ("radial_force", "N", "mesh force on wheel B along e, from wheel A's axis to the pitch "
     "point (gear frame; positive separates the wheels)"),
    ("axial_force", "N", "mesh force on wheel B along wheel A's axis (gear frame)"),
    ("force_x", "N", "mesh force on wheel B, global x"),
    ("force_y", "N", "mesh force on wheel B, global y"),
    ("force_z", "N", "mesh force on wheel B, global z"),
    ("torque_a", "N m", "torque of the mesh on wheel A about its axis (marker A z)"),
    ("torque_b", "N m", "torque of the mesh on wheel B about its axis (marker B z)"),
    ("deflection", "m", "mesh deflection along the tooth normal (positive: drive flank, "
     "negative: coast flank, 0 in the backlash)"),
    ("approach", "m", "drive-flank approach along the tooth normal (negative: gap)"),
    ("sliding_velocity", "m/s", "tooth sliding speed |v_s|"),
    ("friction_power", "W", "power dissipated by tooth friction"),
    ("dissipated_power", "W", "power dissipated by mesh damping and tooth friction"),
    ("angle_a", "rad", "rotation of wheel A relative to the mesh frame since the start "
     "(accumulated)"),
    ("angle_b", "rad", "rotation of wheel B relative to the mesh frame since the start "
     "(accumulated)"),
    ("stiffness", "N/m", "current mesh stiffness k_m"),
)
NAUX_PUBLIC = len(GEAR_AUX)
COL_PHI_A = NAUX_PUBLIC  # hidden columns: absolute accumulated angles (for commit)
COL_PHI_B = NAUX_PUBLIC + 1


@njit(cache=True)
def _onset(u, d):
    """A flank's elastic law at approach ``u > 0`` [m] with a C1 onset over ``d`` [m]:
    ``(W, f, s)``, the potential ``W(u)`` [m^2], the force ``f = W'`` [m] and the stiffness
    ``s = f'`` [1], each to be multiplied by the mesh stiffness k. ``d = 0``: the sharp law
    (``W = u^2/2``, ``f = u``, ``s = 1``); past the onset the sharp law shifted by ``d/2``."""
    if u < d:
        return u * u * u / (6.0 * d), 0.5 * u * u / d, u / d
    return 0.5 * u * u - 0.5 * d * u + d * d / 6.0, u - 0.5 * d, 1.0


def _gear_kernel(skew: bool, name: str) -> Any:
    """A gear kernel named ``name`` over the pairs of any kind (``skew``) or over the
    parallel pairs only; the arguments are :func:`gear_kernel`'s.

    The copy with ``skew`` set runs the bevel and crossed pairs (``idx_skew``), the copy
    without the parallel pairs (``idx_par``), each in both passes; the parallel copy has the
    kind a compile-time constant (fixed loop lengths, ~1.5x faster) and no bevel/crossed
    code (numba prunes it before typing, so it is never compiled). numba caches the two
    copies apart (the closure's constants are part of its cache key).

    The loop is the kernel's own body rather than a function the kernel calls: numba
    compiles a called function on its own and then optimises and code-generates it again
    inside its caller (docs/numba-notes.md, note 5); one function per copy is compiled
    once.
    """

    def kernel(
        kind, pA, pB, RmA, RmB, cof, crf, inv, s0, x0, bn, kst, cdamp, terr, fric, Wf, Mf,
        onset, idx_par, idx_skew, work, lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t,
        Tn, cM, cC, cK, mode, want, r, rabs, data, eout, aux,
    ):
        C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
             r, rabs, data, eout, aux)
        (L, p, gp, Hp, Ht, Sj, Spp, s, sd, pd, vl, Qs, dQs, dQd, Qp, Ap, Bp, Tm, AG, gx, gr, gu,
         dF, dFN, dFNd, WTv, wk, (ws, wv)) = _work(work)
        rq, _, _, Cd, K, _ = L
        full = sc.full_pass(want, mode)
        idx = idx_skew if skew else idx_par
        for ie in range(idx.shape[0]):
            e = idx[ie]
            if skew:
                par = kind[e] == KIND_PARALLEL
            else:
                par = True  # constant in this copy: fixed loop trip counts (nprim = 5)
            nA, nB = sc.pair(C, e)
            nprim = 5 if par else 7
            fast = par and not full  # parallel_rows: reads only Sj's non-zero entries
            if not fast:
                Sj[:, :] = 0.0
            if full:
                Spp[:, :, :] = 0.0
            # -- kinematic primitives p (gradients gp, Hessians Hp) ------------------------------
            if fast:
                parallel_projections(x[nA], R[nA], x[nB], R[nB], pA[e], pB[e], RmA[e], RmB[e],
                                     p, gp, wk)
            else:
                projections(x[nA], R[nA], x[nB], R[nB], pA[e], pB[e], RmA[e], RmB[e], par, p,
                            gp, Hp, Ht, full, wk, ws)
            # -- mesh coordinates s(p) with Jacobian Sj and second derivatives Spp ---------------
            off = sc.state_offset(C, e)
            ac = 1.0
            fr_c0 = 1.0
            fr_c1 = 0.0
            if par:
                ac, fr_c0, fr_c1 = parallel_coords(p, Sj, Spp, s, es[off], es[off + 1], full)
            elif skew:
                fr_c0, fr_c1 = skew_coords(R[nA], R[nB], RmA[e], RmB[e], p, gp, Hp, Sj, Spp, s,
                                           es[off], es[off + 1], full, ws, wv)
            # -- rates --------------------------------------------------------------------------
            sc.velocities(C, e, 12, vl)
            if fast:
                parallel_rates(Sj, gp, vl, pd, sd)
            else:
                for i in range(nprim):
                    acc = 0.0
                    for a in range(12):
                        acc += gp[i, a] * vl[a]
                    pd[i] = acc
                for j in range(NS):
                    acc = 0.0
                    for i in range(nprim):
                        acc += Sj[j, i] * pd[i]
                    sd[j] = acc
            # -- mesh law in s ----------------------------------------------------------------
            dphi = s[0] - s0[e, 0]
            k, k1, k2 = mesh_stiffness(dphi, kst[e])
            c = cdamp[e]
            X = terr[e]
            xx = x0[e]
            for j in range(NS):
                xx += cof[e, j] * (s[j] - s0[e, j])
                gx[j] = cof[e, j]
                gr[j] = 0.0
            hx00 = 0.0
            if X != 0.0:
                zz = kst[e, 4]
                ce = np.cos(zz * dphi)
                xx += X * (1.0 - ce)
                gx[0] += X * zz * np.sin(zz * dphi)
                hx00 = X * zz * zz * ce
            hr33 = 0.0
            if par:
                # rho = ic [w(a_c) - w(a_c0)], w = R inv(alpha_wt) = tq - R atan(tq / R),
                # tq = sqrt(a_c^2 - R^2); the difference is formed without cancellation:
                # atan(tq/R) - atan(tq0/R) = atan(R dtq / (R^2 + tq tq0))
                ic = inv[e, 0]
                Rb = inv[e, 1]
                tq0 = inv[e, 2]
                ac0 = s0[e, 3]
                tq = np.sqrt(ac * ac - Rb * Rb)
                dtq = (ac - ac0) * (ac + ac0) / (tq + tq0)
                zt = Rb * dtq / (Rb * Rb + tq * tq0)
                if abs(zt) < 1e-2:
                    z2 = zt * zt
                    at = zt * (1.0 - z2 * (1.0 / 3.0 - z2 * (0.2 - z2 * (1.0 / 7.0 - z2 / 9.0))))
                else:
                    at = np.arctan(zt)
                rho = ic * (dtq - Rb * at)
                gr[3] = ic * tq / ac
                hr33 = ic * Rb * Rb / (ac * ac * tq)
            else:
                rho = 0.0
                for i in range(3):
                    rho += crf[e, i] * (s[2 + i] - s0[e, 2 + i])
                    gr[2 + i] = crf[e, i]
            xd = 0.0
            rd = 0.0
            for j in range(NS):
                xd += gx[j] * sd[j]
                rd += gr[j] * sd[j]
            for j in range(NS):
                Qs[j] = 0.0
            if full:
                dQs[:, :] = 0.0
                dQd[:, :] = 0.0
                dFN[:] = 0.0
                dFNd[:] = 0.0
            u_p = xx + rho
            u_m = -xx + rho - bn[e]
            Fp = 0.0
            Fm = 0.0
            V = 0.0
            Pd = 0.0
            # contact anticipated in the matrix only: with neither flank loaded, the flank within
            # TANGENT_BAND of contact lends its stiffness to K and C (an unloaded zero-backlash
            # mesh would otherwise enter a factorisation with no stiffness at all)
            ant = 0
            if full and u_p <= 0.0 and u_m <= 0.0:
                if u_p >= u_m and u_p > -TANGENT_BAND:
                    ant = 1
                elif u_m > u_p and u_m > -TANGENT_BAND:
                    ant = 2
            if ant > 0:
                sg = 1.0 if ant == 1 else -1.0
                for i in range(NS):
                    gu[i] = sg * gx[i] + gr[i]
                for i in range(NS):
                    for j in range(NS):
                        dQs[i, j] += k * gu[i] * gu[j]
                        dQd[i, j] += c * gu[i] * gu[j]
            for fl in range(2):
                sg = 1.0 if fl == 0 else -1.0
                u = u_p if fl == 0 else u_m
                if u <= 0.0:
                    continue
                ud = sg * xd + rd
                Wu, fu, su = _onset(u, onset[e])
                F = k * fu + c * ud
                if fl == 0:
                    Fp = F
                else:
                    Fm = F
                for j in range(NS):
                    gu[j] = sg * gx[j] + gr[j]
                    Qs[j] += F * gu[j]
                Qs[0] += k1 * Wu
                V += k * Wu
                Pd += c * ud * ud
                if full:
                    sgnF = 1.0 if F >= 0.0 else -1.0
                    for j in range(NS):
                        dF[j] = k * su * gu[j]
                    dF[0] += k1 * fu + c * sg * hx00 * sd[0]
                    dF[3] += c * hr33 * sd[3]
                    for i in range(NS):
                        for j in range(NS):
                            dQs[i, j] += gu[i] * dF[j]
                            dQd[i, j] += c * gu[i] * gu[j]
                        dQs[0, i] += k1 * fu * gu[i]
                        dFN[i] += sgnF * dF[i]
                        dFNd[i] += sgnF * c * gu[i]
                    dQs[0, 0] += F * sg * hx00 + k2 * Wu
                    dQs[3, 3] += F * hr33
            # -- tooth friction (regularised Coulomb on the sliding vector W s_dot) --------------
            v1 = 0.0
            v2 = 0.0
            for j in range(NS):
                v1 += Wf[e, 0, j] * sd[j]
                v2 += Wf[e, 1, j] * sd[j]
            vn = np.sqrt(v1 * v1 + v2 * v2)
            FN = abs(Fp) + abs(Fm)
            mu = fric[e, 0]
            Pf = 0.0
            if mu > 0.0 and FN > 0.0:
                eps = fric[e, 1]
                if vn < eps:
                    ph = mu * (2.0 - vn / eps) / eps
                    dph = -mu / (eps * eps)
                else:
                    ph = mu / vn
                    dph = -mu / (vn * vn)
                for j in range(NS):
                    WTv[j] = Wf[e, 0, j] * v1 + Wf[e, 1, j] * v2
                    Qs[j] += ph * FN * WTv[j]
                Pf = ph * FN * vn * vn
                if full:
                    dv = dph * FN / vn if vn > 1e-300 else 0.0
                    for i in range(NS):
                        for j in range(NS):
                            dQd[i, j] += (ph * FN * (Wf[e, 0, i] * Wf[e, 0, j]
                                                     + Wf[e, 1, i] * Wf[e, 1, j])
                                          + dv * WTv[i] * WTv[j] + ph * WTv[i] * dFNd[j])
                            dQs[i, j] += ph * WTv[i] * dFN[j]
            # -- chain to the primitives and to the node coordinates ---------------------------
            if fast:
                parallel_chain(Sj, Qs, gp, Qp, rq)
            else:
                for i in range(nprim):
                    acc = 0.0
                    for j in range(NS):
                        acc += Sj[j, i] * Qs[j]
                    Qp[i] = acc
                for a in range(12):
                    acc = 0.0
                    for i in range(nprim):
                        acc += gp[i, a] * Qp[i]
                    rq[a] = acc
            if full:
                chain_matrices(nprim, Sj, Spp, Qs, dQs, dQd, pd, gp, Hp, vl, Qp, Tm, Ap, Bp, AG, K,
                               Cd)
            sc.scatter(C, L, e, 2, full)
            # -- outputs ------------------------------------------------------------------------
            fa = wk[4]  # global axis of A
            fr = wk[11]
            ft = wk[12]
            for i in range(3):
                fr[i] = fr_c0 * wk[2, i] + fr_c1 * wk[3, i]
            cross(fa, fr, ft)
            for row in range(3):  # the mesh force on B in A's gear frame (t, e, a)
                acc = 0.0
                for i in range(3):
                    gvec = Mf[e, row, 0] * fa[i] + Mf[e, row, 1] * fr[i] + Mf[e, row, 2] * ft[i]
                    acc += gvec * (-rq[6 + i])
                aux[e, 1 + row] = acc
            sc.energy(C, e, 0.0, V, 0.0, Pd + Pf)
            aux[e, 0] = Fp - Fm
            aux[e, 4] = -rq[6]
            aux[e, 5] = -rq[7]
            aux[e, 6] = -rq[8]
            aux[e, 7] = -(rq[3] * RmA[e, 0, 2] + rq[4] * RmA[e, 1, 2] + rq[5] * RmA[e, 2, 2])
            aux[e, 8] = -(rq[9] * RmB[e, 0, 2] + rq[10] * RmB[e, 1, 2] + rq[11] * RmB[e, 2, 2])
            if u_p > 0.0 and (u_m <= 0.0 or Fp >= Fm):
                aux[e, 9] = u_p
            elif u_m > 0.0:
                aux[e, 9] = -u_m
            else:
                aux[e, 9] = 0.0
            aux[e, 10] = u_p
            aux[e, 11] = vn
            aux[e, 12] = Pf
            aux[e, 13] = Pd + Pf
            aux[e, 14] = dphi
            aux[e, 15] = s[1] - s0[e, 1]
            aux[e, 16] = k
            aux[e, 17] = s[0]
            aux[e, 18] = s[1]

    kernel.__name__ = kernel.__qualname__ = name
    return njit(cache=True)(kernel)


# the gear loop's work arrays after local_arrays(12, 0): shapes, offsets in one buffer
_WSHAPES = (NP, (NP, 12), (NP, 12, 12), (12, 12), (NS, NP), (NS, NP, NP), NS, NS, NP, 12, NS,
            (NS, NS), (NS, NS), NP, (NP, NP), (NP, NP), (NS, NP), (NP, 12), NS, NS, NS, NS,
            NS, NS, NS, (16, 3))
_WO = tuple(int(v) for v in np.cumsum([0] + [int(np.prod(s)) for s in _WSHAPES]))
#: entries of a gear group's work buffer (its last parameter, ``work``)
WORK_SIZE = LOCAL_SIZE_12 + _WO[-1] + sc.WORKSPACE_SIZE


@njit(cache=True, inline="always")
def _work(work):
    """The gear loop's work arrays, views of the group's work buffer (``work``, a parameter
    of :data:`WORK_SIZE` entries: :func:`~drivedyn.elements.framework.scaffold.work_buffer`)."""
    buf = sc.work_buffer(work, WORK_SIZE)
    return (local_arrays_at(buf, 0, 12, 0), carve(buf, LOCAL_SIZE_12 + _WO[0], NP),
            carve(buf, LOCAL_SIZE_12 + _WO[1], (NP, 12)),
            carve(buf, LOCAL_SIZE_12 + _WO[2], (NP, 12, 12)),
            carve(buf, LOCAL_SIZE_12 + _WO[3], (12, 12)),
            carve(buf, LOCAL_SIZE_12 + _WO[4], (NS, NP)),
            carve(buf, LOCAL_SIZE_12 + _WO[5], (NS, NP, NP)),
            carve(buf, LOCAL_SIZE_12 + _WO[6], NS),
            carve(buf, LOCAL_SIZE_12 + _WO[7], NS),
            carve(buf, LOCAL_SIZE_12 + _WO[8], NP),
            carve(buf, LOCAL_SIZE_12 + _WO[9], 12),
            carve(buf, LOCAL_SIZE_12 + _WO[10], NS),
            carve(buf, LOCAL_SIZE_12 + _WO[11], (NS, NS)),
            carve(buf, LOCAL_SIZE_12 + _WO[12], (NS, NS)),
            carve(buf, LOCAL_SIZE_12 + _WO[13], NP),
            carve(buf, LOCAL_SIZE_12 + _WO[14], (NP, NP)),
            carve(buf, LOCAL_SIZE_12 + _WO[15], (NP, NP)),
            carve(buf, LOCAL_SIZE_12 + _WO[16], (NS, NP)),
            carve(buf, LOCAL_SIZE_12 + _WO[17], (NP, 12)),
            carve(buf, LOCAL_SIZE_12 + _WO[18], NS),
            carve(buf, LOCAL_SIZE_12 + _WO[19], NS),
            carve(buf, LOCAL_SIZE_12 + _WO[20], NS),
            carve(buf, LOCAL_SIZE_12 + _WO[21], NS),
            carve(buf, LOCAL_SIZE_12 + _WO[22], NS),
            carve(buf, LOCAL_SIZE_12 + _WO[23], NS),
            carve(buf, LOCAL_SIZE_12 + _WO[24], NS),
            carve(buf, LOCAL_SIZE_12 + _WO[25], (16, 3)),
            sc.workspace_at(buf, LOCAL_SIZE_12 + _WO[-1]))


@njit(cache=True)
def gear_kernel(
    kind, pA, pB, RmA, RmB, cof, crf, inv, s0, x0, bn, kst, cdamp, terr, fric, Wf, Mf, onset,
    idx_par, idx_skew, work, lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    """All gear pairs of a model (``nel`` elements; trailing arguments: see
    :mod:`drivedyn.elements.framework.contract`).

    Parameters (per element ``e``; lengths in m, angles in rad):
        kind (nel,): KIND_PARALLEL or KIND_SKEW (bevel, crossed axes).
        pA, pB (nel, 3): marker origins in their node frames; RmA, RmB (nel, 3, 3) marker
            rotations in their node frames (z = wheel axis).
        cof (nel, 5): coefficients of the odd approach x in the mesh coordinates
            (c_A, c_B [m/rad], cx [1] for delta_a, delta_r, delta_t).
        crf (nel, 3): coefficients of the even approach rho in delta (skew pairs).
        inv (nel, 3): involute term of parallel pairs: (-/+ cos beta_b, R = r_bA +/- r_bB,
            sqrt(a_c0^2 - R^2)).
        s0 (nel, 5): mesh coordinates in the initial configuration.
        x0 (nel,): -initial drive-flank gap (normal); bn (nel,): normal backlash.
        kst (nel, 6): stiffness law (k_low, k_high [N/m], fraction of the cycle at k_high,
            smoothing width [cycles], z_A, phase at t = 0 [cycles]).
        cdamp (nel,): damping [N s/m]; terr (nel,): transmission error amplitude X.
        fric (nel, 2): (mu, eps_v [m/s]); Wf (nel, 2, 5): sliding velocity rows W [m/rad, 1].
        Mf (nel, 3, 3): gear frame (t, e, a) in the mesh frame (f_a, f_r, f_t).
        onset (nel,): approach over which a flank's stiffness rises to k (0: sharp law).
        idx_par, idx_skew: indices of the parallel and of the bevel/crossed elements.
        work (WORK_SIZE,): the kernel's work buffer (overwritten at every call).
    State: ``es[eoff[e]], es[eoff[e] + 1]`` hold the accumulated wheel angles phi_A, phi_B
    of the last accepted step (see :data:`GEAR_AUX` for the outputs).
    """
    parallel_gear_kernel(
        kind, pA, pB, RmA, RmB, cof, crf, inv, s0, x0, bn, kst, cdamp, terr, fric, Wf, Mf,
        onset, idx_par, idx_skew, work, lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv,
        t, Tn, cM, cC, cK, mode, want, r, rabs, data, eout, aux)
    _any_gear_kernel(
        kind, pA, pB, RmA, RmB, cof, crf, inv, s0, x0, bn, kst, cdamp, terr, fric, Wf, Mf, onset,
        idx_par, idx_skew, work, lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
        cM, cC, cK, mode, want, r, rabs, data, eout, aux)


#: :func:`gear_kernel` for a group of parallel-axis pairs only (``idx_skew`` empty): the
#: parallel-only copy of the loop, in both passes. A model without bevel or crossed pairs
#: (both TORSEN models) so compiles one copy of the loop, without the bevel/crossed code.
parallel_gear_kernel = _gear_kernel(False, "parallel_gear_kernel")
#: the bevel and crossed pairs (the copy that handles pairs of any kind)
_any_gear_kernel = _gear_kernel(True, "_any_gear_kernel")
