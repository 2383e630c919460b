"""Compiled kernel of the geometrically exact beam (family ``beam``), one call per group.

Formulation (Sonneville, Cardona & Bruls 2014, CMAME 268, two-node element): the section
frames at the ends, ``H_A = (x_A, R_A C_A)`` and ``H_B`` (node frames times a constant
section rotation ``C``; x along the axis, y and z the principal axes of the section), are
interpolated by the SE(3) helix ``H(s) = H_A exp(s d / L)`` with ``d = log(H_A^-1 H_B)``.
The strain is constant along the element and exact for any constant-curvature deformation,
so the element does not lock and needs one integration point::

    eps = d / L - eps0              (axial, shear y, shear z, twist, curvature y, curvature z)
    sigma = K_s (eps + beta epsdot)  (N, V_y, V_z, T, M_y, M_z) [N, N m], section frame
    V = L/2 eps^T K_s eps,   K_s = diag(EA, GA_y, GA_z, GJ, EI_y, EI_z)

``eps0`` is the strain of the initial configuration (stress-free reference), ``beta`` [s] the
stiffness-proportional (material) damping. With ``delta d = Ti(d) dh_B - Ti(-d) dh_A``
(``Ti = T_SE3^-1``, ``dh`` the right SE(3) variations of the section frames) the internal
forces on the section frames are ``f_A = -Ti(-d)^T sigma`` and ``f_B = Ti(d)^T sigma``.
On the node dofs (translation global, rotation right increment) ``dh = (R_s^T dx,
C^T dtheta)``.

The stiffness ``d f / d d`` is in closed form (:func:`section_tangent`, with the derivatives
of ``T_SE3^-1`` of :func:`~drivedyn.elements.beams.se3.tangent_inv_se3_rate`); the tests
compare it with complex steps of :func:`section_forces` (``f`` is an analytic function of
``d``), exact to round-off. The complex steps, six complex evaluations of the section per
element, made the beam's matrix evaluation 8 times its residual (100 elements: 0.9 ms).

Mass: translational inertia either lumped, ``m/2`` at each node (default), or consistent
with the linear interpolation of the centre line, ``m/6 [[2, 1], [1, 2]]`` (global frame,
constant either way). Measured on a clamped-free rod with 20 elements (validation case
``beam_eigenfrequencies``): lumped 0.07 / 0.10 / 0.06 % error on the first three bending
frequencies, consistent 0.02 / 0.6 / 1.7 %: the one-point element is slightly stiff in
bending and the consistent mass errs on the same side, the lumped one compensates. The
rotary inertia of the sections (``rho I`` per length) is lumped at the nodes, half an element
each, in the node frame with its gyroscopic term (a consistent rotary matrix would couple two
node frames that rotate relative to each other).
"""

from __future__ import annotations

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.beams.se3 import (
    log_se3,
    tangent_inv_coeff_rate,
    tangent_inv_coeffs,
    tangent_inv_se3_pair,
    tangent_inv_se3_rate,
)
from drivedyn.elements.framework.contract import LOCAL_SIZE_12, local_arrays_at
from drivedyn.elements.framework.primitives import mm, mtv, set_skew
from drivedyn.elements.framework.work_arrays import carve

ROUNDOFF_SCALE = 1e-6  # see _term_scale


@njit(cache=True)
def section_forces(d, etaA, etaB, L, eps0, Ks, beta, TiP, TiM, S, U, eps, epsd, sig, fA, fB):
    """Strain, strain rate and section forces of one element and its end forces.

    ``d`` (6,) relative configuration ``log(H_A^-1 H_B)``; ``etaA, etaB`` (6,) SE(3)
    velocities of the section frames (body frame); ``L`` [m]; ``eps0, Ks`` (6,); ``beta``
    [s]. Writes ``TiP = Ti(d)``, ``TiM = Ti(-d)`` (6, 6), ``eps, epsd, sig`` (6,) and the
    forces ``fA, fB`` (6,) on the section frames (internal, the residual's sign). Real or
    complex (for the complex-step derivative): all arrays of one dtype."""
    tangent_inv_se3_pair(d, TiP, TiM, S, U)
    # the lower left blocks of TiP and TiM are zero: left out of the sums (the same values
    # to the last bit)
    for i in range(6):
        r = 0.0 * d[0]
        for j in range(0 if i < 3 else 3, 6):
            r += TiP[i, j] * etaB[j] - TiM[i, j] * etaA[j]
        epsd[i] = r / L
        eps[i] = d[i] / L - eps0[i]
        sig[i] = Ks[i] * (eps[i] + beta * epsd[i])
    for i in range(6):
        a = 0.0 * d[0]
        b = 0.0 * d[0]
        for j in range(3 if i < 3 else 6):
            a += TiM[j, i] * sig[j]
            b += TiP[j, i] * sig[j]
        fA[i] = -a
        fB[i] = b


@njit(cache=True)
def section_tangent(d, etaA, etaB, L, Ks, beta, TiP, TiM, sig, dP, dM, ds, Dd):
    """``Dd`` (12, 6) <- the derivative of the end forces ``(fA, fB)`` of
    :func:`section_forces` with respect to ``d`` (6,), in closed form: with ``Ti_+- =
    T_SE3^-1(+-d)`` and their derivatives ``dTi_+-/dd_j``
    (:func:`~drivedyn.elements.beams.se3.tangent_inv_se3_rate`)::

        dsig/dd_j = K_s (e_j + beta (dTi_+/dd_j eta_B - dTi_-/dd_j eta_A)) / L
        dfA/dd_j  = -(dTi_-/dd_j)^T sig - Ti_-^T dsig/dd_j
        dfB/dd_j  =  (dTi_+/dd_j)^T sig + Ti_+^T dsig/dd_j

    ``TiP, TiM, sig`` as :func:`section_forces` left them; ``dP, dM`` (6, 6) and ``ds`` (6,)
    work arrays. The tests compare it with complex steps of :func:`section_forces`."""
    t2 = d[3] * d[3] + d[4] * d[4] + d[5] * d[5]
    c, e = tangent_inv_coeffs(t2)
    ep = tangent_inv_coeff_rate(t2)
    for j in range(6):
        tangent_inv_se3_rate(d, j, c, e, ep, dP, dM)
        # the blocks that are zero (the lower left of every matrix; for a translational
        # component j also both diagonal blocks of dP, dM) are left out of the sums: adding
        # their zero products changes no sum (the same values to the last bit)
        rot = j >= 3
        for i in range(6):
            acc = 0.0
            if i < 3:
                for m in range(0 if rot else 3, 6):
                    acc += dP[i, m] * etaB[m] - dM[i, m] * etaA[m]
            elif rot:
                for m in range(3, 6):
                    acc += dP[i, m] * etaB[m] - dM[i, m] * etaA[m]
            ds[i] = Ks[i] * ((1.0 if i == j else 0.0) + beta * acc) / L
        for i in range(6):
            a = 0.0
            b = 0.0
            # column i of Ti: rows 0-2 (i < 3) or all; of dTi: also the upper right block
            # (i >= 3, rows 0-2) for a translational j
            for m in range(3 if i < 3 else 6):
                if rot or (i >= 3 and m < 3):
                    a += dM[m, i] * sig[m] + TiM[m, i] * ds[m]
                    b += dP[m, i] * sig[m] + TiP[m, i] * ds[m]
                else:
                    a += TiM[m, i] * ds[m]
                    b += TiP[m, i] * ds[m]
            Dd[i, j] = -a
            Dd[6 + i, j] = b


@njit(cache=True, inline="always")
def _to_nodes(X, ncol, RsA, CA, RsB, CB, out):
    """out[:, :ncol] = blockdiag(RsA, CA, RsB, CB) X[:, :ncol]: section-frame (SE(3)) rows
    to node-dof rows (translation global, rotation in the node frame)."""
    for blk in range(4):
        A = RsA if blk == 0 else (CA if blk == 1 else (RsB if blk == 2 else CB))
        o = 3 * blk
        for j in range(ncol):
            x0 = X[o, j]
            x1 = X[o + 1, j]
            x2 = X[o + 2, j]
            for i in range(3):
                out[o + i, j] = A[i, 0] * x0 + A[i, 1] * x1 + A[i, 2] * x2


@njit(cache=True, inline="always")
def _rotary(J, om, omd, rq, o, M, Cd, full):
    """Lumped rotary inertia ``J`` (3, 3) of one node (node frame): ``J omd + om x J om`` into
    ``rq[o:o+3]``, ``J`` into ``M`` and the gyroscopic block into ``Cd``; returns the kinetic
    energy ``om . J om / 2``."""
    j0 = J[0, 0] * om[0] + J[0, 1] * om[1] + J[0, 2] * om[2]
    j1 = J[1, 0] * om[0] + J[1, 1] * om[1] + J[1, 2] * om[2]
    j2 = J[2, 0] * om[0] + J[2, 1] * om[1] + J[2, 2] * om[2]
    for i in range(3):
        rq[o + i] += J[i, 0] * omd[0] + J[i, 1] * omd[1] + J[i, 2] * omd[2]
    rq[o] += om[1] * j2 - om[2] * j1
    rq[o + 1] += om[2] * j0 - om[0] * j2
    rq[o + 2] += om[0] * j1 - om[1] * j0
    if full:
        for i in range(3):
            for j in range(3):
                M[o + i, o + j] += J[i, j]
        # d(om x J om)/d om = om~ J - (J om)~
        for j in range(3):
            Cd[o, o + j] += om[1] * J[2, j] - om[2] * J[1, j]
            Cd[o + 1, o + j] += om[2] * J[0, j] - om[0] * J[2, j]
            Cd[o + 2, o + j] += om[0] * J[1, j] - om[1] * J[0, j]
        Cd[o, o + 1] += j2
        Cd[o, o + 2] -= j1
        Cd[o + 1, o] -= j2
        Cd[o + 1, o + 2] += j0
        Cd[o + 2, o] += j1
        Cd[o + 2, o + 1] -= j0
    return 0.5 * (om[0] * j0 + om[1] * j1 + om[2] * j2)


@njit(cache=True, inline="always")
def _term_scale(rabs, dofs, d, L, eps0, Ks, TiP, TiM, RsA, CA, RsB, CB, a, w):
    """Add to ``rabs`` the round-off scale of the elastic forces. ``K_s d/L`` and ``K_s eps0``
    cancel (in a straight beam both axial terms are ``EA`` and their difference is the
    axial force), so the force carries a round-off of ``1e-16 EA`` that no iteration
    removes. They are counted at ``ROUNDOFF_SCALE`` of their size (mapped to the node
    equations by ``|B^T Ti^T|``): the relative test (1e-8) then stops at 1e-14 of them,
    100 times the round-off, instead of asking for digits that do not exist, and stays as
    strict as without them wherever the forces do not cancel."""
    for j in range(6):
        a[j] = ROUNDOFF_SCALE * Ks[j] * (abs(d[j]) / L + abs(eps0[j]))
    for side in range(2):
        Ti = TiM if side == 0 else TiP
        Rs = RsA if side == 0 else RsB
        Cs = CA if side == 0 else CB
        o = 6 * side
        for blk in range(2):
            for k in range(3):
                acc = 0.0
                for j in range(3 if blk == 0 else 6):  # Ti's lower left block is zero
                    acc += abs(Ti[j, 3 * blk + k]) * a[j]
                w[k] = acc
            A = Rs if blk == 0 else Cs
            for i in range(3):
                gi = dofs[o + 3 * blk + i]
                if gi >= 0:
                    rabs[gi] += abs(A[i, 0]) * w[0] + abs(A[i, 1]) * w[1] + abs(A[i, 2]) * w[2]


# the work arrays' shapes, in the order of the kernel's unpacking (after the local arrays)
_SHAPES = ((6,), (6,), (6,), (6, 6), (6, 6), (3, 3), (3, 3), (6,), (6,), (6,), (6,), (6,),
           (12,), (12,), (6, 6), (6, 6), (6,), (12, 6), (6, 12), (12, 6), (6, 12), (24, 12),
           (3, 3), (3, 3), (3, 3), (3,), (6,))
#: entries of the beams' work buffer (their last parameter, ``work``)
WORK_SIZE = LOCAL_SIZE_12 + sum(int(np.prod(s)) for s in _SHAPES)


@njit(cache=True, inline="always")
def _work(buf):
    """The kernel's work arrays as views of ``buf`` (:data:`_SHAPES`, after the local
    arrays)."""
    o = LOCAL_SIZE_12
    d = carve(buf, o, 6)
    etaA = carve(buf, o + 6, 6)
    etaB = carve(buf, o + 12, 6)
    TiP = carve(buf, o + 18, (6, 6))
    TiM = carve(buf, o + 54, (6, 6))
    S = carve(buf, o + 90, (3, 3))
    U = carve(buf, o + 99, (3, 3))
    o += 108
    v5 = (carve(buf, o, 6), carve(buf, o + 6, 6), carve(buf, o + 12, 6), carve(buf, o + 18, 6),
          carve(buf, o + 24, 6))
    o += 30
    vl = carve(buf, o, 12)
    al = carve(buf, o + 12, 12)
    dTP = carve(buf, o + 24, (6, 6))
    dTM = carve(buf, o + 60, (6, 6))
    dsig = carve(buf, o + 96, 6)
    o += 102
    Dd = carve(buf, o, (12, 6))
    Q = carve(buf, o + 72, (6, 12))
    Fe = carve(buf, o + 144, (12, 6))
    Wv = carve(buf, o + 216, (6, 12))
    X = carve(buf, o + 288, (24, 12))
    o += 576
    RsA = carve(buf, o, (3, 3))
    RsB = carve(buf, o + 9, (3, 3))
    Sk = carve(buf, o + 18, (3, 3))
    w = carve(buf, o + 27, 3)
    tw = carve(buf, o + 30, 6)
    return (d, etaA, etaB, TiP, TiM, S, U, *v5, vl, al, dTP, dTM, dsig, Dd, Q, Fe, Wv, X, RsA, RsB,
            Sk, w, tw)


@njit(cache=True)
def beam_kernel(
    length, eps0, Ks, beta, CA, CB, mass, cmix, Jn, gravity, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    CAs, CBs = CA, CB
    buf = sc.work_buffer(work, WORK_SIZE)  # the work arrays are views of the group's buffer
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    (L, d, etaA, etaB, TiP, TiM, S, U, eps, epsd, sig, fA, fB, vl, al, dTP, dTM, dsig, Dd, Q,
     Fe, Wv, X, RsA, RsB, Sk, w, tw) = (local_arrays_at(buf, 0, 12, 0), *_work(buf))
    full = sc.full_pass(want, mode)
    rq, _, M, Cd, K, _ = L
    for e in range(sc.count(C)):
        nA, nB = sc.pair(C, e)
        CA = CAs[e]
        CB = CBs[e]
        mm(R[nA], CA, RsA)
        mm(R[nB], CB, RsB)
        log_se3(x[nA], RsA, x[nB], RsB, d)
        sc.velocities(C, e, 12, vl)
        sc.accelerations(C, e, 12, al)
        mtv(RsA, vl[0:3], etaA[0:3])
        mtv(CA, vl[3:6], etaA[3:6])
        mtv(RsB, vl[6:9], etaB[0:3])
        mtv(CB, vl[9:12], etaB[3:6])
        Le = length[e]
        be = beta[e]
        section_forces(d, etaA, etaB, Le, eps0[e], Ks[e], be, TiP, TiM, S, U, eps, epsd, sig,
                       fA, fB)
        sc.clear(L, full)
        # internal forces on the node dofs: translation R_s f_u (global), rotation C f_theta
        for i in range(3):
            rq[i] = RsA[i, 0] * fA[0] + RsA[i, 1] * fA[1] + RsA[i, 2] * fA[2]
            rq[3 + i] = CA[i, 0] * fA[3] + CA[i, 1] * fA[4] + CA[i, 2] * fA[5]
            rq[6 + i] = RsB[i, 0] * fB[0] + RsB[i, 1] * fB[1] + RsB[i, 2] * fB[2]
            rq[9 + i] = CB[i, 0] * fB[3] + CB[i, 1] * fB[4] + CB[i, 2] * fB[5]
        # translational mass (lumped or consistent) and weight
        m = mass[e]
        # consistent (cmix = 1): m/6 [[2, 1], [1, 2]]; lumped (cmix = 0): m/2 [[1, 0], [0, 1]]
        MO = cmix[e] / 6.0
        MD = 0.5 - MO
        for i in range(3):
            rq[i] += m * (MD * al[i] + MO * al[6 + i]) - 0.5 * m * gravity[i]
            rq[6 + i] += m * (MO * al[i] + MD * al[6 + i]) - 0.5 * m * gravity[i]
        if full:
            for i in range(3):
                M[i, i] = m * MD
                M[6 + i, 6 + i] = m * MD
                M[i, 6 + i] = m * MO
                M[6 + i, i] = m * MO
        kin = _rotary(Jn[e, 0], vl[3:6], al[3:6], rq, 3, M, Cd, full)
        kin += _rotary(Jn[e, 1], vl[9:12], al[9:12], rq, 9, M, Cd, full)
        vv = 0.0
        for i in range(3):
            vv += MD * (vl[i] * vl[i] + vl[6 + i] * vl[6 + i]) + 2.0 * MO * vl[i] * vl[6 + i]
        kin += 0.5 * m * vv
        if full:
            # Q: d(d)/dq = [-Ti(-d) B_A, Ti(d) B_B] (6, 12), B = diag(R_s^T, C^T)
            for i in range(6):
                for j in range(3):
                    Q[i, j] = -(TiM[i, 0] * RsA[j, 0] + TiM[i, 1] * RsA[j, 1]
                                + TiM[i, 2] * RsA[j, 2])
                    Q[i, 3 + j] = -(TiM[i, 3] * CA[j, 0] + TiM[i, 4] * CA[j, 1]
                                    + TiM[i, 5] * CA[j, 2])
                    Q[i, 6 + j] = (TiP[i, 0] * RsB[j, 0] + TiP[i, 1] * RsB[j, 1]
                                   + TiP[i, 2] * RsB[j, 2])
                    Q[i, 9 + j] = (TiP[i, 3] * CB[j, 0] + TiP[i, 4] * CB[j, 1]
                                   + TiP[i, 5] * CB[j, 2])
            # Dd = d(fA, fB)/dd (12, 6)
            section_tangent(d, etaA, etaB, Le, Ks[e], be, TiP, TiM, sig, dTP, dTM, dsig, Dd)
            # Fe = d(fA, fB)/d(epsdot) . (1/L) = [-Ti(-d)^T; Ti(d)^T] beta K_s / L (12, 6)
            for i in range(6):
                for j in range(6):
                    s = be * Ks[e, j] / Le
                    Fe[i, j] = -TiM[j, i] * s
                    Fe[6 + i, j] = TiP[j, i] * s
            # velocity-dependent strain rate: eta_u = C^T R^T xdot depends on the node
            # rotation: d eta_u / d theta = C^T (R^T xdot)~
            Wv[:, :] = 0.0
            for side in range(2):
                n = nA if side == 0 else nB
                Cs = CA if side == 0 else CB
                Ti = TiM if side == 0 else TiP
                sgn = -1.0 if side == 0 else 1.0
                o = 6 * side
                Rn = R[n]
                for i in range(3):
                    w[i] = Rn[0, i] * vl[o] + Rn[1, i] * vl[o + 1] + Rn[2, i] * vl[o + 2]
                set_skew(w, Sk)
                for i in range(6):
                    for j in range(3):
                        acc = 0.0
                        for k in range(3):
                            acc += (Ti[i, 0] * Cs[k, 0] + Ti[i, 1] * Cs[k, 1]
                                    + Ti[i, 2] * Cs[k, 2]) * Sk[k, j]
                        Wv[i, o + 3 + j] = sgn * acc
            # K = B^T (Dd Q + Fe Wv), C = B^T Fe Q (on section rows, then to node rows)
            for i in range(12):
                for j in range(12):
                    a = 0.0
                    b = 0.0
                    # zero blocks left out (the same sums to the last bit): the rows 3-5 of
                    # Q's translation columns and of Wv (Ti's lower left block), and Wv's
                    # translation columns
                    if j % 6 >= 3:
                        for k in range(3):
                            a += Dd[i, k] * Q[k, j] + Fe[i, k] * Wv[k, j]
                            b += Fe[i, k] * Q[k, j]
                        for k in range(3, 6):
                            a += Dd[i, k] * Q[k, j]
                            b += Fe[i, k] * Q[k, j]
                    else:
                        for k in range(3):
                            a += Dd[i, k] * Q[k, j]
                            b += Fe[i, k] * Q[k, j]
                    X[i, j] = a
                    X[12 + i, j] = b
            _to_nodes(X[0:12], 12, RsA, CA, RsB, CB, K)
            _to_nodes(X[12:24], 12, RsA, CA, RsB, CB, X[0:12])
            for i in range(12):
                for j in range(12):
                    Cd[i, j] += X[i, j]
            # d(R C f_u)/d theta = -R (C f_u)~ (the force turns with the node)
            for side in range(2):
                n = nA if side == 0 else nB
                Cs = CA if side == 0 else CB
                f = fA if side == 0 else fB
                o = 6 * side
                for i in range(3):
                    w[i] = Cs[i, 0] * f[0] + Cs[i, 1] * f[1] + Cs[i, 2] * f[2]
                set_skew(w, Sk)
                Rn = R[n]
                for i in range(3):
                    for j in range(3):
                        K[o + i, o + 3 + j] -= (Rn[i, 0] * Sk[0, j] + Rn[i, 1] * Sk[1, j]
                                                + Rn[i, 2] * Sk[2, j])
        sc.scatter(C, L, e, 2, full)
        _term_scale(C[sc.RABS], C[sc.DOFS][e], d, Le, eps0[e], Ks[e], TiP, TiM, RsA, CA, RsB,
                    CB, tw, w)
        el = 0.0
        dis = 0.0
        for i in range(6):
            el += Ks[e, i] * eps[i] * eps[i]
            dis += Ks[e, i] * epsd[i] * epsd[i]
        weight = 0.0
        for i in range(3):
            weight -= 0.5 * m * gravity[i] * (x[nA, i] + x[nB, i])
        sc.energy(C, e, kin, 0.5 * Le * el + weight, 0.0, be * Le * dis)
        # columns 12-14, the outer-fibre stresses, are computed when read, from the section
        # forces (family.py: the group's derived outputs)
        aux = C[sc.AUX]
        for i in range(6):
            aux[e, i] = sig[i]
            aux[e, 6 + i] = eps[i]
        aux[e, 15] = 0.5 * Le * el
