"""Gear pair: a compliant 3-D tooth mesh between two wheels (family ``gear_pair``).

The element joins two markers at the wheel centres (each marker's z axis is the wheel axis)
and acts as a nonlinear spring-damper along the tooth normal at the pitch point, after
Cardona's gear element (seed 003, "Gear pair element"; ``physics.md`` section 2), in the
equivalent compliant form the design allows: the mesh deflection is a function of the
configuration of the two wheels, measured from wheel rotations relative to the mesh frame
(accumulated over any number of revolutions) and the relative displacement of the wheels.

Mesh coordinates ``s`` (functions of the two node configurations, with exact gradients and
right-trivialised Hessians from :mod:`drivedyn.elements.primitives`):

* ``phi_A, phi_B``: rotation of each wheel about its own axis relative to the mesh frame
  (accumulated in ``State.es``). Parallel axes: relative to the centre line, i.e. the
  projection of ``d = x_mB - x_mA`` onto the wheel's plane. Bevel and crossed axes: relative
  to the other wheel's axis projected onto the wheel's plane. Both references turn with a
  carrier, so a planetary set obeys the Willis equation without anything special.
* ``delta = (d.a, d.f_r, d.f_t)``: the centre offset in the mesh frame ``(a, f_r, f_t)``
  (``f_r`` towards the other wheel). Parallel axes use ``(d.a, a_c, 0)`` with the transverse
  centre distance ``a_c = |d - (d.a) a|``.

Flank approach (penetration along the tooth normal ``n``, in m; ``u > 0`` = contact)::

    x   = c_A (phi_A - phi_A0) + c_B (phi_B - phi_B0) + cx . (delta - delta0)
          + X (1 - cos(z_A (phi_A - phi_A0))) - g0                (odd under flank mirror)
    rho = cr . (delta - delta0)                                     bevel, crossed axes
    rho = -/+ cos(beta_b) R [inv alpha_wt(a_c) - inv alpha_wt(a_c0)]  parallel, ext./int.
    u_drive = x + rho,     u_coast = -x + rho - b_n

``c_A = r_bA cos(beta_b)`` etc. come from the tooth normal at the pitch point; the exact
involute term (``cos alpha_wt = R / a_c``, ``R = r_bA +/- r_bB``) makes the radial force
follow the operating pressure angle when the centre distance changes; the axial offset enters
with ``sin(beta_b)`` exactly (involute helicoids). ``b_n`` is the normal backlash and ``g0``
the initial drive-flank gap. Each flank is a unilateral spring-damper::

    F = k_m(phi_A) u + c_m du/dt   while u > 0 (contact), else 0

with the potential ``V = k_m u^2 / 2`` per flank (the seeds' ``k_m [[u + x_err]]^2 / 2``
with the hoop backlash operator ``[[.]]`` when the centre distance is nominal). The
generalised force is ``F du/dq`` plus, for a stiffness that varies over the mesh cycle,
``V'(phi_A)`` (a conservative formulation: the energy balance closes exactly). The damper
acts on the rate of the whole flank deflection (transmission error included) and only in
contact; it is not clipped, so at separation it may briefly pull (Kelvin-Voigt contact).
The varying stiffness is ``k' (0.75 n + 0.25)`` with ``n`` tooth pairs in contact (n and
n + 1 over the fractions set by ``eps_alpha``; its cycle mean is ISO's
``c' (0.75 eps_alpha + 0.25)``), with quintic-smoothed steps; the mesh phase is
``z_A (phi_A - phi_A0) / 2 pi``.

Tooth friction (regularised Coulomb law of the seeds, ``physics.md`` section 3) acts on the
sliding velocity vector ``v_s = W s_dot`` (2 components, m/s): sliding at the pitch point
along the tooth trace (crossed axes, worms, and any relative axial motion of helical
gears), and the profile sliding of parallel and bevel gears at the effective contact
distance ``s_eff`` from the pitch point (mean loss of the ISO/TR 14179-2 gear loss factor,
see :func:`~drivedyn.elements.gear_geometry.effective_sliding_arm`)::

    Q_fric = mu_R(|v_s|) / |v_s| F_N  W^T v_s,    F_N = |F_drive| + |F_coast|

Its power ``mu_R(|v_s|) F_N |v_s|`` is reported as dissipated power, like the damping power.
The profile-sliding part is a couple on the two wheels (it changes the torque ratio, i.e.
the efficiency, not the mesh force); the trace part acts at the pitch point.

Sign conventions: the *drive flank* is the one that wheel A loads when it turns positively
about its axis (marker A's z); forces are reported on wheel B, in the global frame and in the
gear frame of wheel A at the pitch point: tangential ``t = a x e`` (direction of A's surface
motion), radial ``e`` (from A's axis towards the pitch point; positive radial force
separates the wheels) and axial ``a``; with these, a parallel pair gives
``F_a = -F_t tan(beta_A)``, ``F_r = |F_t| tan(alpha_n) / cos(beta)``. Helix (spiral) angles
are positive for a right hand (the tooth trace ``cos(beta) a + sin(beta) t`` turns
positively about the axis as it advances along it); external parallel pairs need opposite
hands, internal pairs the same. ``torque_a``/``torque_b`` are the mesh torques on the wheels
about their own axes (friction included).

Numerics: contact status changes the iteration matrix, so a flank within ``TANGENT_BAND``
(10 nm) of contact while neither flank is loaded lends its stiffness to the matrix (not to
the residual): a zero-backlash mesh that is unloaded when the matrix is factorised (at
t = 0, say) would otherwise enter it with no stiffness. The code that only bevel and
crossed pairs need and the assembly of the matrices are compiled out of line (first
compilation ~70 s instead of ~2 min), and the residual-only loop over parallel pairs is a
separate copy with the kind a compile-time constant (fixed loop lengths: 1.5x faster).

What is simplified (documented limits): one mean contact point (no line-contact
distribution over the face width, so misalignment changes the load but not its distribution);
bevel gears use the mean point of the pitch cones with linearised displacements and ISO 6336
stiffness of their virtual cylindrical gears; crossed-axis helical and worm pairs are point
contacts at the pitch point with sliding along the common tooth trace only, and need an
explicit stiffness (ISO 6336 does not cover them).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from drivedyn.elements.base import (
    MODE_ACC,
    ElementSpec,
    Family,
    Group,
    local_arrays,
    register,
    scatter_element,
)
from drivedyn.elements.gear_geometry import (
    CylindricalPair,
    effective_sliding_arm,
    iso6336_mesh_stiffness,
    mesh_cycle_levels,
)
from drivedyn.elements.primitives import _hess_axial, cross, gather_v, mtv, mv, prim_dot, unwrap
from drivedyn.errors import ModelError

KIND_PARALLEL = 0
KIND_SKEW = 1  # bevel and crossed axes: references from the other wheel's axis
NS = 5  # mesh coordinates: phi_A, phi_B, delta_a, delta_r, delta_t
NP = 7  # kinematic primitives at most
TANGENT_BAND = 1e-8  # [m] flank gap within which contact is anticipated in the matrix

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


# ---------------------------------------------------------------------------------------------
# numba helpers
# ---------------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _cross_into(a, b, g, i0):
    """g[i0:i0+3] = a x b."""
    g[i0] = a[1] * b[2] - a[2] * b[1]
    g[i0 + 1] = a[2] * b[0] - a[0] * b[2]
    g[i0 + 2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True)
def _hess_proj_b(RA, RB, pA, bbar, RBwn, RAv, H, Ht, ws):
    """Hessian of ``d . (R_B bbar)`` from prim_axial's with the roles of A and B swapped."""
    _hess_axial(RB, RA, pA, bbar, RBwn, RAv, Ht, ws)
    for i in range(12):
        ii = (i + 6) % 12
        for j in range(12):
            H[i, j] = -Ht[ii, (j + 6) % 12]


@njit(cache=True, inline="always")
def _projections(xA, RA, xB, RB, pA, pB, RmA, RmB, nb, p, gp, Hp, Ht, full, wk, ws):
    """``p_i = d . a_i`` (i = 0, 1, 2: marker A's axes) and, if ``nb``, ``p_3+j = d . b_j``
    (j = 0, 1: marker B's x, y axes), ``d = x_mB - x_mA``, with gradients ``gp`` and (if
    ``full``) Hessians ``Hp``. Leaves the global axes of A in ``wk[2:5]``. The lever-arm
    terms of a marker at its node's origin (the usual wheel centre) are skipped: they are
    zero."""
    levA = pA[0] != 0.0 or pA[1] != 0.0 or pA[2] != 0.0
    levB = pB[0] != 0.0 or pB[1] != 0.0 or pB[2] != 0.0
    RApA = wk[0]
    RBpB = wk[1]
    if levA:
        mv(RA, pA, RApA)
    else:
        RApA[:] = 0.0
    if levB:
        mv(RB, pB, RBpB)
    else:
        RBpB[:] = 0.0
    w = wk[5]  # x_B + R_B pB - x_A = d + R_A pA
    d = wk[6]
    wB = wk[7]  # x_B - x_A - R_A pA = d - R_B pB
    for i in range(3):
        w[i] = xB[i] + RBpB[i] - xA[i]
        d[i] = w[i] - RApA[i]
        wB[i] = d[i] - RBpB[i]
    RAw = wk[8]
    RBwB = wk[9]
    mtv(RA, w, RAw)
    t = wk[10]
    for i in range(3):
        u = wk[2 + i]
        mv(RA, RmA[:, i], u)
        p[i] = d[0] * u[0] + d[1] * u[1] + d[2] * u[2]
        g = gp[i]
        for c in range(3):
            g[c] = -u[c]
            g[6 + c] = u[c]
        _cross_into(RmA[:, i], RAw, g, 3)
        if full or levB:
            mtv(RB, u, t)
            _cross_into(pB, t, g, 9)
        else:
            g[9] = 0.0
            g[10] = 0.0
            g[11] = 0.0
        if full:
            _hess_axial(RA, RB, pB, RmA[:, i], RAw, t, Hp[i], ws)
    if nb:
        mtv(RB, wB, RBwB)
        if full:
            for k in range(3):
                wB[k] = -wB[k]  # R_B^T (x_A + R_A pA - x_B) for the swapped Hessian
            mtv(RB, wB, wk[13])
        for j in range(2):
            v = wk[11]
            mv(RB, RmB[:, j], v)
            p[3 + j] = d[0] * v[0] + d[1] * v[1] + d[2] * v[2]
            g = gp[3 + j]
            for c in range(3):
                g[c] = -v[c]
                g[6 + c] = v[c]
            _cross_into(RmB[:, j], RBwB, g, 9)
            if full or levA:
                mtv(RA, v, t)
                _cross_into(t, pA, g, 3)  # -pA x (R_A^T v)
            else:
                g[3] = 0.0
                g[4] = 0.0
                g[5] = 0.0
            if full:
                _hess_proj_b(RA, RB, pA, RmB[:, j], wk[13], t, Hp[3 + j], Ht, ws)


@njit(cache=True, inline="always")
def _atan_row(S, Spp, row, ix, iy, x, y, full):
    """Row of ``s = -atan2(y, x)``: first and second derivatives w.r.t. p[ix], p[iy]."""
    r2 = x * x + y * y
    S[row, ix] = y / r2
    S[row, iy] = -x / r2
    if full:
        r4 = r2 * r2
        Spp[row, ix, ix] = -2.0 * x * y / r4
        Spp[row, iy, iy] = 2.0 * x * y / r4
        Spp[row, ix, iy] = (x * x - y * y) / r4
        Spp[row, iy, ix] = Spp[row, ix, iy]
    return -np.arctan2(y, x)


@njit(cache=True, inline="always")
def _smoothstep(y, w):
    """Quintic ramp from 0 (y <= -w/2) to 1 (y >= w/2): value, d/dy, d2/dy2."""
    t = y / w + 0.5
    if t <= 0.0:
        return 0.0, 0.0, 0.0
    if t >= 1.0:
        return 1.0, 0.0, 0.0
    return (t * t * t * (10.0 + t * (-15.0 + 6.0 * t)), 30.0 * t * t * (1.0 - t) ** 2 / w,
            60.0 * t * (1.0 - t) * (1.0 - 2.0 * t) / (w * w))


@njit(cache=True, inline="always")
def _mesh_stiffness(dphi, kst):
    """k_m over the mesh cycle (smoothed two-level law): value, d/dphi_A, d2/dphi_A2."""
    k_lo = kst[0]
    k_hi = kst[1]
    if k_hi == k_lo:
        return k_lo, 0.0, 0.0
    f = kst[2]
    w = kst[3]
    dp = kst[4] / (2.0 * np.pi)
    ph = dp * dphi + kst[5]
    ph -= np.floor(ph)
    h0, h1, h2 = _smoothstep(ph, w)
    a0, a1, a2 = _smoothstep(ph - f, w)
    b0, b1, b2 = _smoothstep(ph - 1.0, w)
    dk = k_hi - k_lo
    return (k_lo + dk * (h0 - a0 + b0), dk * (h1 - a1 + b1) * dp,
            dk * (h2 - a2 + b2) * dp * dp)


@njit(cache=True)
def _skew_coords(RA, RB, RmA, RmB, p, gp, Hp, Sj, Spp, s, ref_a, ref_b, full, ws, wv):
    """Bevel and crossed pairs: the primitives ``b . a1, b . a2, a . b1, a . b2`` (p[3:7])
    and the mesh coordinates phi_A, phi_B (from the other wheel's axis), delta (in the frame
    of A's axis and b projected on A's plane) with their first and (if ``full``) second
    derivatives in p. Returns the components of f_r on A's x and y axes. Out of line, so that
    the parallel-axes loop stays small and fast."""
    p[3] = prim_dot(RA, RB, RmA[:, 0], RmB[:, 2], gp[3], Hp[3], full, ws, wv)
    p[4] = prim_dot(RA, RB, RmA[:, 1], RmB[:, 2], gp[4], Hp[4], full, ws, wv)
    p[5] = prim_dot(RA, RB, RmA[:, 2], RmB[:, 0], gp[5], Hp[5], full, ws, wv)
    p[6] = prim_dot(RA, RB, RmA[:, 2], RmB[:, 1], gp[6], Hp[6], full, ws, wv)
    s[0] = unwrap(_atan_row(Sj, Spp, 0, 3, 4, p[3], p[4], full), ref_a)
    s[1] = unwrap(_atan_row(Sj, Spp, 1, 5, 6, p[5], p[6], full), ref_b)
    s[2] = p[2]
    Sj[2, 2] = 1.0
    rho2 = p[3] * p[3] + p[4] * p[4]
    rh = np.sqrt(rho2)
    cp = p[3] / rh
    sp = p[4] / rh
    dr = p[0] * cp + p[1] * sp
    dt = p[1] * cp - p[0] * sp
    s[3] = dr
    s[4] = dt
    ps3 = -sp / rh  # d psi / d p3, psi = atan2(p4, p3)
    ps4 = cp / rh
    Sj[3, 0] = cp
    Sj[3, 1] = sp
    Sj[3, 3] = dt * ps3
    Sj[3, 4] = dt * ps4
    Sj[4, 0] = -sp
    Sj[4, 1] = cp
    Sj[4, 3] = -dr * ps3
    Sj[4, 4] = -dr * ps4
    if full:
        r4 = rho2 * rho2
        p33 = 2.0 * p[3] * p[4] / r4
        p44 = -p33
        p34 = (p[4] * p[4] - p[3] * p[3]) / r4
        # delta_r: f_p0psi = -sp, f_p1psi = cp, f_psipsi = -dr, f_psi = dt
        # delta_t: f_p0psi = -cp, f_p1psi = -sp, f_psipsi = -dt, f_psi = -dr
        for row in range(3, 5):
            if row == 3:
                f0, f1, fpp, fp = -sp, cp, -dr, dt
            else:
                f0, f1, fpp, fp = -cp, -sp, -dt, -dr
            Spp[row, 0, 3] = f0 * ps3
            Spp[row, 0, 4] = f0 * ps4
            Spp[row, 1, 3] = f1 * ps3
            Spp[row, 1, 4] = f1 * ps4
            Spp[row, 3, 0] = Spp[row, 0, 3]
            Spp[row, 4, 0] = Spp[row, 0, 4]
            Spp[row, 3, 1] = Spp[row, 1, 3]
            Spp[row, 4, 1] = Spp[row, 1, 4]
            Spp[row, 3, 3] = fpp * ps3 * ps3 + fp * p33
            Spp[row, 4, 4] = fpp * ps4 * ps4 + fp * p44
            Spp[row, 3, 4] = fpp * ps3 * ps4 + fp * p34
            Spp[row, 4, 3] = Spp[row, 3, 4]
    return cp, sp  # f_r = (p3 a1 + p4 a2) / rho


@njit(cache=True)
def _matrices(nprim, Sj, Spp, Qs, dQs, dQd, pd, gp, Hp, vl, Qp, Tm, Ap, Bp, AG, K, C):
    """K and C of one element from the mesh law's derivatives in s (``dQs``, ``dQd``), the
    map s(p) (``Sj``, ``Spp``) and the primitives p(q) (``gp``, ``Hp``): with
    ``Q_p = S^T Q_s`` and ``p_dot = G v``, ``K = sum_i Q_p,i H_i + G^T (A G + B H^T v)`` and
    ``C = G^T B G``, ``A = dQ_p/dp``, ``B = dQ_p/dp_dot``. Out of line: only the matrix path
    calls it, and inlined it added ~25 s to the kernel's first compilation."""
    # Tm[l, k] = sum_m Spp[l, m, k] pd[m]  (d s_dot / d p at fixed p_dot)
    for l_ in range(NS):
        for kk in range(nprim):
            acc = 0.0
            for m in range(nprim):
                acc += Spp[l_, m, kk] * pd[m]
            Tm[l_, kk] = acc
    # Ap = sum_j Qs_j Spp_j + S^T dQs S + S^T dQd Tm ;  Bp = S^T dQd S
    for i in range(nprim):
        for kk in range(nprim):
            acc = 0.0
            accb = 0.0
            for j in range(NS):
                acc += Qs[j] * Spp[j, i, kk]
                sji = Sj[j, i]
                if sji != 0.0:
                    for l_ in range(NS):
                        acc += sji * (dQs[j, l_] * Sj[l_, kk] + dQd[j, l_] * Tm[l_, kk])
                        accb += sji * dQd[j, l_] * Sj[l_, kk]
            Ap[i, kk] = acc
            Bp[i, kk] = accb
    # AG = Ap G + Bp (H^T v) ; K = sum_i Qp_i H_i + G^T AG ; C = G^T Bp G
    for i in range(nprim):
        for b in range(12):
            acc = 0.0
            for kk in range(nprim):
                hv = 0.0
                for a in range(12):
                    hv += Hp[kk, a, b] * vl[a]
                acc += Ap[i, kk] * gp[kk, b] + Bp[i, kk] * hv
            AG[i, b] = acc
    for a in range(12):
        for b in range(12):
            acc = 0.0
            for i in range(nprim):
                acc += Qp[i] * Hp[i, a, b] + gp[i, a] * AG[i, b]
            K[a, b] = acc
    for i in range(nprim):
        for b in range(12):
            acc = 0.0
            for kk in range(nprim):
                acc += Bp[i, kk] * gp[kk, b]
            AG[i, b] = acc
    for a in range(12):
        for b in range(12):
            acc = 0.0
            for i in range(nprim):
                acc += gp[i, a] * AG[i, b]
            C[a, b] = acc


@njit(cache=True, inline="always")
def _gear_kernel_element(P, I, S_, Cc, O, W, full, skew, idx):
    """Loop over the elements ``idx``. ``full`` and ``skew`` are literals; the copy with
    ``skew=False`` handles parallel pairs only, with the kind a compile-time constant (fixed
    loop lengths, ~1.5x faster) and without the call to the bevel/crossed code."""
    (kind, pA, pB, RmA, RmB, cof, crf, inv, s0, x0, bn, kst, cdamp, terr, fric, Wf, Mf,
     idx_par, idx_skew) = P
    lnodes, dofs, kmap, eoff = I
    x, R, v, vd, lam, es, tfv, t = S_
    Tn, cM, cC, cK, mode, want = Cc
    r, rabs, data, eout, aux = O
    (nel, rq, rl, M, C, K, G, p, gp, Hp, Ht, Sj, Spp, s, sd, pd, vl, Qs, dQs, dQd, Qp, Ap, Bp,
     Tm, AG, gx, gr, gu, dF, dFN, dFNd, WTv, wk, ws, wv) = W
    for ie in range(idx.shape[0]):
        e = idx[ie]
        if skew:
            par = kind[e] == KIND_PARALLEL
        else:
            par = True  # constant in this copy: fixed loop trip counts (nprim = 5)
        nA = lnodes[e, 0]
        nB = lnodes[e, 1]
        nprim = 5 if par else 7
        Sj[:, :] = 0.0
        if full:
            Spp[:, :, :] = 0.0
        # -- kinematic primitives p (gradients gp, Hessians Hp) ------------------------------
        _projections(x[nA], R[nA], x[nB], R[nB], pA[e], pB[e], RmA[e], RmB[e], par, p, gp, Hp,
                     Ht, full, wk, ws)
        # -- mesh coordinates s(p) with Jacobian Sj and second derivatives Spp ---------------
        off = eoff[e]
        ac = 1.0
        fr_c0 = 1.0
        fr_c1 = 0.0
        if par:
            s[0] = unwrap(_atan_row(Sj, Spp, 0, 0, 1, p[0], p[1], full), es[off])
            s[1] = unwrap(_atan_row(Sj, Spp, 1, 3, 4, p[3], p[4], full), es[off + 1])
            s[2] = p[2]
            Sj[2, 2] = 1.0
            ac = np.sqrt(p[0] * p[0] + p[1] * p[1])
            s[3] = ac
            s[4] = 0.0
            Sj[3, 0] = p[0] / ac
            Sj[3, 1] = p[1] / ac
            if full:
                a3 = ac * ac * ac
                Spp[3, 0, 0] = p[1] * p[1] / a3
                Spp[3, 1, 1] = p[0] * p[0] / a3
                Spp[3, 0, 1] = -p[0] * p[1] / a3
                Spp[3, 1, 0] = Spp[3, 0, 1]
            fr_c0 = p[0] / ac  # f_r = (p0 a1 + p1 a2) / a_c
            fr_c1 = p[1] / ac
        elif skew:
            fr_c0, fr_c1 = _skew_coords(R[nA], R[nB], RmA[e], RmB[e], p, gp, Hp, Sj, Spp, s,
                                        es[off], es[off + 1], full, ws, wv)
        # -- rates --------------------------------------------------------------------------
        gather_v(v, dofs[e], 12, vl)
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
        k, k1, k2 = _mesh_stiffness(dphi, kst[e])
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
            F = k * u + c * ud
            if fl == 0:
                Fp = F
            else:
                Fm = F
            for j in range(NS):
                gu[j] = sg * gx[j] + gr[j]
                Qs[j] += F * gu[j]
            Qs[0] += 0.5 * k1 * u * u
            V += 0.5 * k * u * u
            Pd += c * ud * ud
            if full:
                sgnF = 1.0 if F >= 0.0 else -1.0
                for j in range(NS):
                    dF[j] = k * gu[j]
                dF[0] += k1 * u + c * sg * hx00 * sd[0]
                dF[3] += c * hr33 * sd[3]
                for i in range(NS):
                    for j in range(NS):
                        dQs[i, j] += gu[i] * dF[j]
                        dQd[i, j] += c * gu[i] * gu[j]
                    dQs[0, i] += k1 * u * gu[i]
                    dFN[i] += sgnF * dF[i]
                    dFNd[i] += sgnF * c * gu[i]
                dQs[0, 0] += F * sg * hx00 + 0.5 * k2 * u * u
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
            _matrices(nprim, Sj, Spp, Qs, dQs, dQd, pd, gp, Hp, vl, Qp, Tm, Ap, Bp, AG, K, C)
        scatter_element(rq, rl, M, C, K, G, 2, lnodes[e], dofs[e], kmap[e], Tn, cM, cC, cK,
                        mode, want, full, r, rabs, data)
        # -- outputs ------------------------------------------------------------------------
        fa = wk[4]  # global axis of A
        fr = wk[11]
        ft = wk[12]
        for i in range(3):
            fr[i] = fr_c0 * wk[2, i] + fr_c1 * wk[3, i]
        cross(fa, fr, ft)
        Fx = -rq[6]
        Fy = -rq[7]
        Fz = -rq[8]
        for row in range(3):
            acc = 0.0
            for i in range(3):
                gvec = Mf[e, row, 0] * fa[i] + Mf[e, row, 1] * fr[i] + Mf[e, row, 2] * ft[i]
                acc += gvec * (-rq[6 + i])
            aux[e, 1 + row] = acc
        aux[e, 0] = Fp - Fm
        aux[e, 4] = Fx
        aux[e, 5] = Fy
        aux[e, 6] = Fz
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
        eout[e, 0] = 0.0
        eout[e, 1] = V
        eout[e, 2] = 0.0
        eout[e, 3] = Pd + Pf


@njit(cache=True)
def gear_kernel(
    kind, pA, pB, RmA, RmB, cof, crf, inv, s0, x0, bn, kst, cdamp, terr, fric, Wf, Mf,
    idx_par, idx_skew, lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    """All gear pairs of a model (``nel`` elements; trailing arguments: see
    :mod:`drivedyn.elements.base`).

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
        idx_par, idx_skew: indices of the parallel and of the bevel/crossed elements.
    State: ``es[eoff[e]], es[eoff[e] + 1]`` hold the accumulated wheel angles phi_A, phi_B
    of the last accepted step (see :data:`GEAR_AUX` for the outputs).
    """
    nel = kind.shape[0]
    rq, rl, M, C, K, G = local_arrays(12, 0)
    p = np.zeros(NP)
    gp = np.zeros((NP, 12))
    Hp = np.zeros((NP, 12, 12))
    Ht = np.zeros((12, 12))
    Sj = np.zeros((NS, NP))
    Spp = np.zeros((NS, NP, NP))
    s = np.zeros(NS)
    sd = np.zeros(NS)
    pd = np.zeros(NP)
    vl = np.zeros(12)
    Qs = np.zeros(NS)
    dQs = np.zeros((NS, NS))
    dQd = np.zeros((NS, NS))
    Qp = np.zeros(NP)
    Ap = np.zeros((NP, NP))
    Bp = np.zeros((NP, NP))
    Tm = np.zeros((NS, NP))
    AG = np.zeros((NP, 12))
    gx = np.zeros(NS)
    gr = np.zeros(NS)
    gu = np.zeros(NS)
    dF = np.zeros(NS)
    dFN = np.zeros(NS)
    dFNd = np.zeros(NS)
    WTv = np.zeros(NS)
    wk = np.zeros((16, 3))
    ws = np.empty((8, 3, 3))
    wv = np.empty((8, 3))
    P = (kind, pA, pB, RmA, RmB, cof, crf, inv, s0, x0, bn, kst, cdamp, terr, fric, Wf, Mf,
         idx_par, idx_skew)
    I = (lnodes, dofs, kmap, eoff)
    S_ = (x, R, v, vd, lam, es, tfv, t)
    Cc = (Tn, cM, cC, cK, mode, want)
    O = (r, rabs, data, eout, aux)
    W = (nel, rq, rl, M, C, K, G, p, gp, Hp, Ht, Sj, Spp, s, sd, pd, vl, Qs, dQs, dQd, Qp, Ap,
         Bp, Tm, AG, gx, gr, gu, dF, dFN, dFNd, WTv, wk, ws, wv)
    if want or mode == MODE_ACC:
        _gear_kernel_element(P, I, S_, Cc, O, W, True, True, np.arange(nel))
    else:
        _gear_kernel_element(P, I, S_, Cc, O, W, False, False, idx_par)
        if idx_skew.shape[0] > 0:
            _gear_kernel_element(P, I, S_, Cc, O, W, False, True, idx_skew)


# ---------------------------------------------------------------------------------------------
# specification
# ---------------------------------------------------------------------------------------------

KINDS = ("parallel", "bevel", "crossed")


@dataclass(frozen=True)
class GearPair(ElementSpec):
    """A gear mesh between wheel A (``marker_a``) and wheel B (``marker_b``).

    Each marker sits at its wheel's centre with its z axis along the wheel axis: for spur,
    helical and internal pairs (``kind="parallel"``) at the centre of the wheel in the
    mid-face plane; for bevel pairs at the centre of the mean pitch circle; for crossed-axis
    helical and worm pairs at the point of the wheel axis on the common perpendicular of the
    axes. The markers may sit on rigid bodies, nodes or the ground (one of the two wheels).
    The initial configuration must be assembled: the centre distance (or cone distances,
    shaft angle) must match the gear data within ``tolerance``, otherwise :class:`ModelError`.

    Attributes:
        name: unique element name.
        marker_a, marker_b: wheel markers (z axis = wheel axis).
        teeth_a, teeth_b: tooth numbers (> 0; a worm's number of starts for wheel A).
        module: normal module m_n [m] (bevel: at the mean cone distance).
        face_width: b [m] (used by the ISO 6336 stiffness).
        pressure_angle: normal pressure angle alpha_n [rad] (0 < alpha_n < 45 deg).
        helix_angle: helix angle beta of wheel A [rad] at the reference (pitch) cylinder,
            positive for a right hand (bevel: mean spiral angle; worm: 90 deg - lead angle).
        helix_angle_b: helix angle of wheel B [rad]; required for ``"crossed"``; for the other
            kinds it is checked (external and bevel pairs: ``-helix_angle``, internal pairs:
            ``helix_angle``) when given.
        kind: ``"parallel"`` (spur, helical, internal), ``"bevel"`` (intersecting axes,
            conical pitch surfaces) or ``"crossed"`` (skew axes: crossed helical, worm).
        internal: ``None`` (external pair), ``"a"`` or ``"b"``: which wheel is the ring
            (internal gear); parallel pairs only.
        cone_angle_a, cone_angle_b: pitch cone angles [rad] (bevel; 0 < gamma <= 90 deg, the
            shaft angle is their sum).
        profile_shift_a, profile_shift_b: profile shift coefficients x (ISO 21771 signs).
        addendum: addendum of the basic rack over the module, h_aP / m_n.
        dedendum: dedendum of the basic rack over the module, h_fP / m_n (ISO C_B factor).
        stiffness: mean mesh stiffness k_m [N/m] along the tooth normal; None = ISO 6336-1
            method B from the geometry (parallel and bevel pairs).
        stiffness_variation: vary k_m over the mesh cycle with the number of tooth pairs in
            contact (from the transverse contact ratio); the mean stays ``stiffness``.
        contact_ratio: transverse contact ratio eps_alpha; None = from the geometry.
        variation_smoothing: width of the smoothed stiffness steps, fraction of a mesh cycle.
        mesh_phase: mesh-cycle phase at t = 0, fraction of a cycle (0: a double-contact
            zone starts).
        damping: mesh damping c_m [N s/m] along the tooth normal.
        damping_ratio: zeta; c_m = 2 zeta sqrt(k_m m_e) with the equivalent mass of the
            wheels' rotary inertias about their axes (exclusive with ``damping``).
        backlash: hoop backlash b [m] measured along the line of action in the transverse
            plane of wheel A (base tangent): with B held, A turns freely by b / r_bA.
        initial_gap: gap on the drive flank at t = 0 [m], same measure, 0 <= gap <= backlash.
        transmission_error: amplitude X [m] of the loaded transmission error
            X (1 - cos(z_A psi_A)) along the tooth normal (psi_A: rotation of A in the mesh).
        friction: tooth friction coefficient mu (0: none).
        friction_velocity: regularisation speed eps_v [m/s] of the friction law.
        youngs_modulus: equivalent Young's modulus 2 E1 E2 / (E1 + E2) [Pa] for ISO 6336.
        rim_factor: ISO 6336 gear blank factor C_R (1: solid disc).
        max_misalignment: largest initial angle between the axes of a parallel pair [rad].
        tolerance: relative tolerance of the assembly checks (centre and cone distances);
            angles are checked to the same value in rad.
    """

    name: str
    marker_a: str
    marker_b: str
    teeth_a: int
    teeth_b: int
    module: float
    face_width: float
    pressure_angle: float = float(np.radians(20.0))
    helix_angle: float = 0.0
    helix_angle_b: float | None = None
    kind: str = "parallel"
    internal: str | None = None
    cone_angle_a: float | None = None
    cone_angle_b: float | None = None
    profile_shift_a: float = 0.0
    profile_shift_b: float = 0.0
    addendum: float = 1.0
    dedendum: float = 1.25
    stiffness: float | None = None
    stiffness_variation: bool = False
    contact_ratio: float | None = None
    variation_smoothing: float = 0.05
    mesh_phase: float = 0.0
    damping: float | None = None
    damping_ratio: float | None = None
    backlash: float = 0.0
    initial_gap: float = 0.0
    transmission_error: float = 0.0
    friction: float = 0.0
    friction_velocity: float = 1e-3
    youngs_modulus: float = 206e9
    rim_factor: float = 1.0
    max_misalignment: float = float(np.radians(1.0))
    tolerance: float = 1e-3
    family: ClassVar[str] = "gear_pair"

    def markers(self) -> tuple[str, ...]:
        return (self.marker_a, self.marker_b)

    def _fail(self, label: str, msg: str, value) -> None:
        raise ModelError(f"GearPair {self.name!r}.{label}: {msg}, got {value!r}")

    def validate(self) -> None:
        for label in ("teeth_a", "teeth_b"):
            val = getattr(self, label)
            if isinstance(val, bool) or int(val) != val or val <= 0:
                self._fail(label, "must be a positive whole number of teeth", val)
        fields = ("module", "face_width", "pressure_angle", "helix_angle", "profile_shift_a",
                  "profile_shift_b", "addendum", "dedendum", "variation_smoothing",
                  "mesh_phase", "backlash", "initial_gap", "transmission_error", "friction",
                  "friction_velocity", "youngs_modulus", "rim_factor", "max_misalignment",
                  "tolerance")
        for label in fields:
            val = getattr(self, label)
            try:
                ok = np.isfinite(float(val))
            except (TypeError, ValueError):
                ok = False
            if not ok:
                self._fail(label, "expected a finite number", val)
        for label in ("module", "face_width", "friction_velocity", "youngs_modulus",
                      "rim_factor", "tolerance", "addendum", "dedendum"):
            if getattr(self, label) <= 0:
                self._fail(label, "must be > 0", getattr(self, label))
        for label in ("backlash", "initial_gap", "transmission_error", "friction",
                      "max_misalignment"):
            if getattr(self, label) < 0:
                self._fail(label, "must be >= 0", getattr(self, label))
        if not 0.0 < self.pressure_angle < np.radians(45.0):
            self._fail("pressure_angle", "must be in (0, 45 deg) [rad]", self.pressure_angle)
        for label in ("helix_angle", "helix_angle_b"):
            val = getattr(self, label)
            if val is not None and not abs(val) < 0.5 * np.pi:
                self._fail(label, "|beta| must be < 90 deg [rad]", val)
        if self.kind not in KINDS:
            self._fail("kind", f"must be one of {KINDS}", self.kind)
        if self.internal not in (None, "a", "b"):
            self._fail("internal", "must be None, 'a' or 'b' (the ring gear)", self.internal)
        if self.internal is not None:
            if self.kind != "parallel":
                self._fail("internal", "internal gears are supported for parallel axes only",
                           self.internal)
            ring, pinion = ((self.teeth_a, self.teeth_b) if self.internal == "a"
                            else (self.teeth_b, self.teeth_a))
            if ring <= pinion:
                self._fail(f"teeth_{self.internal}", "the ring gear needs more teeth than the "
                           f"pinion ({pinion})", ring)
        if self.initial_gap > self.backlash:
            self._fail("initial_gap", f"must not exceed the backlash {self.backlash!r}",
                       self.initial_gap)
        if self.stiffness is not None and not (np.isfinite(self.stiffness)
                                               and self.stiffness > 0):
            self._fail("stiffness", "must be > 0 [N/m]", self.stiffness)
        if self.damping is not None and self.damping_ratio is not None:
            self._fail("damping_ratio", "give either damping or damping_ratio",
                       self.damping_ratio)
        for label in ("damping", "damping_ratio"):
            val = getattr(self, label)
            if val is not None and not (np.isfinite(val) and val >= 0):
                self._fail(label, "must be >= 0", val)
        if self.contact_ratio is not None and not (np.isfinite(self.contact_ratio)
                                                   and self.contact_ratio >= 1.0):
            self._fail("contact_ratio", "must be >= 1", self.contact_ratio)
        if not 0.0 < self.variation_smoothing <= 0.5:
            self._fail("variation_smoothing", "must be in (0, 0.5] (fraction of a mesh cycle)",
                       self.variation_smoothing)
        if self.kind == "bevel":
            for label in ("cone_angle_a", "cone_angle_b"):
                val = getattr(self, label)
                if val is None or not (0.0 < val <= 0.5 * np.pi + 1e-12):
                    self._fail(label, "bevel pairs need a pitch cone angle in (0, 90 deg] "
                               "[rad]", val)
        if self.kind == "crossed":
            if self.helix_angle_b is None:
                self._fail("helix_angle_b", "crossed-axis pairs need the helix angle of "
                           "wheel B", None)
            if self.stiffness is None:
                self._fail("stiffness", "crossed-axis (and worm) pairs need an explicit mesh "
                           "stiffness (ISO 6336 does not cover them)", None)


# ---------------------------------------------------------------------------------------------
# build: geometry of the mesh frame, coefficients of the mesh law
# ---------------------------------------------------------------------------------------------


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _axis_inertia(ctx, marker: str, what: str, needed: bool) -> float:
    """Rotary inertia [kg m^2] of the body carrying ``marker`` about the marker's z axis
    (inf for the ground; 0 for a massless node, refused when ``needed``)."""
    body = ctx.spec.markers[marker].body
    if body in ctx.spec.bodies:
        bd = ctx.spec.bodies[body]
        m = ctx.spec.markers[marker]
        ax = m.rotation[:, 2]
        rr = m.position - bd.com
        rp = rr - (rr @ ax) * ax
        return float(ax @ bd.inertia @ ax + bd.mass * (rp @ rp))
    if body in ctx.spec.nodes:
        if needed:
            raise ModelError(f"{what}: damping_ratio needs the inertia of wheel marker "
                             f"{marker!r}, which is on the massless node {body!r}; give the "
                             "damping coefficient instead")
        return 0.0
    return np.inf


class _MeshData:
    """Per-element constants of the kernel (see :func:`gear_kernel`)."""

    def __init__(self) -> None:
        self.kind = KIND_PARALLEL
        self.cof = np.zeros(NS)
        self.crf = np.zeros(3)
        self.inv = np.zeros(3)
        self.s0 = np.zeros(NS)
        self.W = np.zeros((2, NS))
        self.Mf = np.zeros((3, 3))
        self.n_perp = 1.0  # |n projected on A's transverse plane| (backlash conversion)
        self.k_iso: float | None = None
        self.k_single: float | None = None
        self.eps_alpha = 1.0
        self.s_eff = 0.0
        self.radius_a = 0.0  # pitch (operating) radii [m]
        self.radius_b = 0.0
        self.base_radius_a = 0.0


def _frame_coeffs(fa, fr, ft, vecs) -> np.ndarray:
    """Rows: components of each vector in the frame (fa, fr, ft)."""
    return np.array([[v @ fa, v @ fr, v @ ft] for v in vecs])


def _parallel(s: GearPair, what: str, xA, RA, xB, RB) -> _MeshData:
    md = _MeshData()
    a, b = RA[:, 2], RB[:, 2]
    sab = float(a @ b)
    ang = float(np.arccos(min(1.0, abs(sab))))
    if ang > s.max_misalignment:
        raise ModelError(f"{what}: the wheel axes are not parallel (angle {np.degrees(ang):.4g} "
                         f"deg > max_misalignment {np.degrees(s.max_misalignment):.4g} deg); "
                         "use kind='bevel' or 'crossed' for non-parallel axes")
    sig = 1.0 if sab > 0 else -1.0
    ext = s.internal is None
    beta = float(s.helix_angle)
    hb = s.helix_angle_b
    if hb is not None:
        want = -beta if ext else beta
        if abs(hb - want) > s.tolerance:
            hands = "opposite hands" if ext else "the same hand"
            raise ModelError(f"{what}.helix_angle_b: {'external' if ext else 'internal'} "
                             f"parallel helical gears need {hands} (helix_angle_b = "
                             f"{want!r}), got {hb!r}")
    if s.internal == "a":
        z1, z2, x1, x2 = s.teeth_b, -s.teeth_a, s.profile_shift_b, s.profile_shift_a
    elif s.internal == "b":
        z1, z2, x1, x2 = s.teeth_a, -s.teeth_b, s.profile_shift_a, s.profile_shift_b
    else:
        z1, z2, x1, x2 = s.teeth_a, s.teeth_b, s.profile_shift_a, s.profile_shift_b
    geo = CylindricalPair.build(z1, z2, s.module, s.pressure_angle, beta, x1, x2, s.addendum)
    rb1, rb2 = abs(geo.rb1), abs(geo.rb2)
    rbA, rbB = (rb2, rb1) if s.internal == "a" else (rb1, rb2)
    d = xB - xA
    da = float(d @ a)
    dperp = d - da * a
    ac0 = float(np.linalg.norm(dperp))
    aw = geo.centre_distance
    if abs(ac0 - aw) > s.tolerance * aw:
        raise ModelError(f"{what}: centre distance of the markers {ac0:.9g} m does not match "
                         f"the gear data ({'|r_B - r_A|' if not ext else 'r_A + r_B'} with "
                         f"profile shift: {aw:.9g} m) within tolerance {s.tolerance:g}")
    fr = dperp / ac0
    ft = np.cross(a, fr)
    se = -1.0 if s.internal == "b" else 1.0  # e_A = se f_r
    eA = se * fr
    tA = np.cross(a, eA)
    sm = -1.0 if s.internal == "a" else 1.0
    ca, sa = np.cos(s.pressure_angle), np.sin(s.pressure_angle)
    cbb = float(np.cos(geo.beta_b))
    md.kind = KIND_PARALLEL
    md.cof[0] = rbA * cbb
    md.cof[1] = sig * rbB * cbb * (1.0 if ext else -1.0)
    md.cof[2] = ca * np.sin(beta)
    Rinv = rbA + rbB if ext else abs(rbB - rbA)
    if not Rinv < ac0:
        raise ModelError(f"{what}: centre distance {ac0:.6g} m is below the base radii sum "
                         f"{Rinv:.6g} m")
    tq = np.sqrt(ac0**2 - Rinv**2)
    md.inv[:] = ((-1.0 if ext else 1.0) * cbb, Rinv, tq)
    cwt = Rinv / ac0
    rwA, rwB = rbA / cwt, rbB / cwt
    md.s0[:] = (-np.arctan2(d @ RA[:, 1], d @ RA[:, 0]), -np.arctan2(d @ RB[:, 1], d @ RB[:, 0]),
                da, ac0, 0.0)
    lam = np.cos(beta) * a + np.sin(beta) * tA
    tB = sig * (-1.0 if ext else 1.0) * tA
    md.W[0] = (rwA * (tA @ lam), -rwB * (tB @ lam), -(lam @ a), -(lam @ fr), 0.0)
    md.s_eff = effective_sliding_arm(geo.eps_1, geo.eps_2, geo.p_bt)
    md.W[1] = (md.s_eff, -sig * md.s_eff, 0.0, 0.0, 0.0)
    md.Mf = _frame_coeffs(a, fr, ft, (tA, eA, a))
    n = ca * (np.cos(beta) * tA - np.sin(beta) * a) + sm * sa * eA
    md.n_perp = float(np.linalg.norm(n - (n @ a) * a))
    md.eps_alpha = geo.eps_alpha
    md.radius_a, md.radius_b = rwA, rwB
    md.base_radius_a = rbA
    eps = s.contact_ratio if s.contact_ratio is not None else geo.eps_alpha
    iso = iso6336_mesh_stiffness(z1, z2, abs(beta), s.pressure_angle, eps, s.face_width, x1, x2,
                                 s.dedendum, s.rim_factor, s.youngs_modulus)
    md.k_iso, md.k_single = iso.k_mesh, iso.k_single
    return md


def _skew_common(md: _MeshData, s: GearPair, RA, RB, d, rA, rB, tA, tB, eA, lam, tau, m,
                 what: str) -> None:
    """Coefficients shared by bevel and crossed pairs (frame from the two axes)."""
    a, b = RA[:, 2], RB[:, 2]
    bp = b - (b @ a) * a
    if np.linalg.norm(bp) < 0.05:
        raise ModelError(f"{what}: the wheel axes are (nearly) parallel; use kind='parallel'")
    fr = _unit(bp)
    ft = np.cross(a, fr)
    ca, sa = np.cos(s.pressure_angle), np.sin(s.pressure_angle)
    n = ca * tau + sa * m
    md.kind = KIND_SKEW
    md.cof[0] = rA * (tA @ n)
    md.cof[1] = -rB * (tB @ n)
    md.cof[2:5] = [-ca * (tau @ f) for f in (a, fr, ft)]
    md.crf[:] = [-sa * (m @ f) for f in (a, fr, ft)]
    md.s0[:] = (-np.arctan2(b @ RA[:, 1], b @ RA[:, 0]), -np.arctan2(a @ RB[:, 1], a @ RB[:, 0]),
                d @ a, d @ fr, d @ ft)
    md.W[0] = (rA * (tA @ lam), -rB * (tB @ lam), -(lam @ a), -(lam @ fr), -(lam @ ft))
    md.Mf = _frame_coeffs(a, fr, ft, (tA, eA, a))
    md.n_perp = float(np.linalg.norm(n - (n @ a) * a))
    md.radius_a, md.radius_b = rA, rB
    md.base_radius_a = md.cof[0] / md.n_perp


def _bevel(s: GearPair, what: str, xA, RA, xB, RB) -> _MeshData:
    md = _MeshData()
    a, b = RA[:, 2], RB[:, 2]
    beta = float(s.helix_angle)
    if s.helix_angle_b is not None and abs(s.helix_angle_b + beta) > s.tolerance:
        raise ModelError(f"{what}.helix_angle_b: bevel gears need opposite spiral hands "
                         f"(helix_angle_b = {-beta!r}), got {s.helix_angle_b!r}")
    gA, gB = float(s.cone_angle_a), float(s.cone_angle_b)
    cb = np.cos(beta)
    rA = s.teeth_a * s.module / (2.0 * cb)
    rB = s.teeth_b * s.module / (2.0 * cb)
    Rm = rA / np.sin(gA)
    if abs(rB / np.sin(gB) - Rm) > s.tolerance * Rm:
        raise ModelError(f"{what}: cone angles do not fit the tooth numbers (z_A / sin gamma_A "
                         f"= {s.teeth_a / np.sin(gA):.6g}, z_B / sin gamma_B = "
                         f"{s.teeth_b / np.sin(gB):.6g})")
    # apex: closest points of the two axis lines
    w0 = xA - xB
    ab = a @ b
    den = 1.0 - ab * ab
    if den < 1e-6:
        raise ModelError(f"{what}: the wheel axes are (nearly) parallel; use kind='parallel'")
    ta = (ab * (b @ w0) - (a @ w0)) / den
    tb = ((b @ w0) - ab * (a @ w0)) / den
    PA, PB = xA + ta * a, xB + tb * b
    if np.linalg.norm(PA - PB) > s.tolerance * Rm:
        raise ModelError(f"{what}: bevel wheel axes do not intersect (distance "
                         f"{np.linalg.norm(PA - PB):.6g} m)")
    O = 0.5 * (PA + PB)
    LA, LB = float((xA - O) @ a), float((xB - O) @ b)
    for lab, L, g in (("a", LA, gA), ("b", LB, gB)):
        if abs(abs(L) - Rm * np.cos(g)) > s.tolerance * Rm:
            raise ModelError(f"{what}: marker {lab.upper()} is {abs(L):.9g} m from the cone "
                             f"apex, the gear data need R_m cos(gamma_{lab}) = "
                             f"{Rm * np.cos(g):.9g} m (centre of the mean pitch circle)")
    ao, bo = np.sign(LA) * a, np.sign(LB) * b
    Sig = float(np.arccos(np.clip(ao @ bo, -1.0, 1.0)))
    if abs(Sig - (gA + gB)) > s.tolerance:
        raise ModelError(f"{what}: shaft angle {np.degrees(Sig):.6g} deg does not match "
                         f"cone_angle_a + cone_angle_b = {np.degrees(gA + gB):.6g} deg")
    g = _unit(np.sin(gB) * ao + np.sin(gA) * bo)
    P = O + Rm * g
    eA = _unit((P - xA) - ((P - xA) @ a) * a)
    eB = _unit((P - xB) - ((P - xB) @ b) * b)
    tA, tB = np.cross(a, eA), np.cross(b, eB)
    toA = np.cross(ao, eA)
    lam = np.cos(beta) * g + np.sin(beta) * toA
    m = _unit(eA - (eA @ g) * g)
    tau = np.sign(LA) * (np.cos(beta) * toA - np.sin(beta) * g)
    _skew_common(md, s, RA, RB, xB - xA, rA, rB, tA, tB, eA, lam, tau, m, what)
    # virtual cylindrical gears (Tredgold) for the contact ratio, friction arm and stiffness
    zvA, zvB = s.teeth_a / np.cos(gA), s.teeth_b / np.cos(gB)
    geo = CylindricalPair.build(zvA, zvB, s.module, s.pressure_angle, beta, s.profile_shift_a,
                                s.profile_shift_b, s.addendum)
    md.eps_alpha = geo.eps_alpha
    md.s_eff = effective_sliding_arm(geo.eps_1, geo.eps_2, geo.p_bt)
    md.W[1] = (md.s_eff * (a @ g), -md.s_eff * (b @ g), 0.0, 0.0, 0.0)
    eps = s.contact_ratio if s.contact_ratio is not None else geo.eps_alpha
    iso = iso6336_mesh_stiffness(zvA, zvB, abs(beta), s.pressure_angle, eps, s.face_width,
                                 s.profile_shift_a, s.profile_shift_b, s.dedendum, s.rim_factor,
                                 s.youngs_modulus)
    md.k_iso, md.k_single = iso.k_mesh, iso.k_single
    return md


def _crossed(s: GearPair, what: str, xA, RA, xB, RB) -> _MeshData:
    md = _MeshData()
    a, b = RA[:, 2], RB[:, 2]
    bA, bB = float(s.helix_angle), float(s.helix_angle_b)
    rA = s.teeth_a * s.module / (2.0 * abs(np.cos(bA)))
    rB = s.teeth_b * s.module / (2.0 * abs(np.cos(bB)))
    d = xB - xA
    dist = float(np.linalg.norm(d))
    if abs(dist - (rA + rB)) > s.tolerance * (rA + rB):
        raise ModelError(f"{what}: centre distance of the markers {dist:.9g} m does not match "
                         f"r_A + r_B = {rA + rB:.9g} m within tolerance {s.tolerance:g}")
    for lab, ax in (("a", a), ("b", b)):
        if abs(d @ ax) > s.tolerance * dist:
            raise ModelError(f"{what}: the markers are not on the common perpendicular of the "
                             f"axes (offset along the axis of wheel {lab.upper()}: "
                             f"{d @ ax:.6g} m)")
    eA = d / dist
    eB = -eA
    tA, tB = np.cross(a, eA), np.cross(b, eB)
    lamA = np.cos(bA) * a + np.sin(bA) * tA
    lamB = np.cos(bB) * b + np.sin(bB) * tB
    mis = float(np.linalg.norm(np.cross(lamA, lamB)))
    if mis > s.tolerance:
        Sig = np.degrees(np.arccos(min(1.0, abs(a @ b))))
        raise ModelError(f"{what}: helix angles {np.degrees(bA):.6g} and {np.degrees(bB):.6g} "
                         f"deg do not mesh at the shaft angle {Sig:.6g} deg of the markers "
                         "(the tooth traces must coincide at the pitch point)")
    tau = np.cos(bA) * tA - np.sin(bA) * a
    _skew_common(md, s, RA, RB, d, rA, rB, tA, tB, eA, lamA, tau, eA, what)
    md.W[1] = 0.0
    return md


class GearPairFamily(Family):
    """Registry entry of :class:`GearPair`."""

    name = "gear_pair"
    spec_types = (GearPair,)

    def build(self, specs, ctx) -> Group:
        nel = len(specs)
        kind = np.zeros(nel, np.int64)
        pA = np.zeros((nel, 3))
        pB = np.zeros((nel, 3))
        RmA = np.zeros((nel, 3, 3))
        RmB = np.zeros((nel, 3, 3))
        cof = np.zeros((nel, NS))
        crf = np.zeros((nel, 3))
        inv = np.zeros((nel, 3))
        s0 = np.zeros((nel, NS))
        x0 = np.zeros(nel)
        bn = np.zeros(nel)
        kst = np.zeros((nel, 6))
        cdamp = np.zeros(nel)
        terr = np.zeros(nel)
        fric = np.zeros((nel, 2))
        Wf = np.zeros((nel, 2, NS))
        Mf = np.zeros((nel, 3, 3))
        lnodes = np.zeros((nel, 2), np.int64)
        dofs = np.zeros((nel, 12), np.int64)
        eoff = np.zeros(nel, np.int64)
        info = []
        for e, s in enumerate(specs):
            what = f"GearPair {s.name!r}"
            nA, pA[e], RmA[e] = ctx.marker(s.marker_a, what)
            nB, pB[e], RmB[e] = ctx.marker(s.marker_b, what)
            if nA == nB:
                raise ModelError(f"{what}: both markers {s.marker_a!r} and {s.marker_b!r} are on "
                                 "the same body; a gear pair needs two wheels")
            lnodes[e] = (nA, nB)
            dofs[e] = ctx.local_dofs([nA, nB], 0, 0)
            xA = ctx.x0[nA] + ctx.R0[nA] @ pA[e]
            xB = ctx.x0[nB] + ctx.R0[nB] @ pB[e]
            RA = ctx.R0[nA] @ RmA[e]
            RB = ctx.R0[nB] @ RmB[e]
            build = {"parallel": _parallel, "bevel": _bevel, "crossed": _crossed}[s.kind]
            md = build(s, what, xA, RA, xB, RB)
            kind[e] = md.kind
            cof[e], crf[e], inv[e], s0[e], Wf[e], Mf[e] = md.cof, md.crf, md.inv, md.s0, md.W, md.Mf
            eoff[e] = ctx.alloc_state([md.s0[0], md.s0[1]])
            # stiffness (mean) and its variation over the mesh cycle
            km = s.stiffness if s.stiffness is not None else md.k_iso
            if km is None:  # pragma: no cover - validate() requires it
                raise ModelError(f"{what}.stiffness: required for kind {s.kind!r}")
            eps = s.contact_ratio if s.contact_ratio is not None else md.eps_alpha
            k_lo = k_hi = float(km)
            f_hi, w_tr = 0.0, 1.0
            if s.stiffness_variation:
                lo, hi, f_hi = mesh_cycle_levels(1.0, eps)
                mean = 0.75 * eps + 0.25
                if f_hi > 1e-9:
                    k_lo, k_hi = km * lo / mean, km * hi / mean
                    w_tr = min(s.variation_smoothing, f_hi, 1.0 - f_hi)
            kst[e] = (k_lo, k_hi, f_hi, w_tr, float(s.teeth_a), float(s.mesh_phase))
            # damping
            if s.damping_ratio is not None:
                JA = _axis_inertia(ctx, s.marker_a, what, True)
                JB = _axis_inertia(ctx, s.marker_b, what, True)
                inv_me = md.cof[0] ** 2 / JA + md.cof[1] ** 2 / JB
                if inv_me <= 0:
                    raise ModelError(f"{what}.damping_ratio: both wheels are on the ground")
                cdamp[e] = 2.0 * s.damping_ratio * np.sqrt(km / inv_me)
            else:
                cdamp[e] = s.damping or 0.0
            bn[e] = s.backlash * md.n_perp
            x0[e] = -s.initial_gap * md.n_perp
            terr[e] = s.transmission_error
            fric[e] = (s.friction, s.friction_velocity)
            info.append({"stiffness": float(km), "damping": float(cdamp[e]),
                         "contact_ratio": float(eps), "sliding_arm": float(md.s_eff),
                         "radius_a": float(md.radius_a), "radius_b": float(md.radius_b),
                         "base_radius_a": float(md.base_radius_a), "coef_a": float(md.cof[0]),
                         "coef_b": float(md.cof[1]), "normal_backlash": float(bn[e])})
        params = (kind, pA, pB, RmA, RmB, cof, crf, inv, s0, x0, bn, kst, cdamp, terr, fric, Wf,
                  Mf, np.flatnonzero(kind == KIND_PARALLEL).astype(np.int64),
                  np.flatnonzero(kind != KIND_PARALLEL).astype(np.int64))
        return Group(
            family=self.name, names=[s.name for s in specs], kernel=gear_kernel, params=params,
            lnodes=lnodes, nmult=0, dofs=dofs, eoff=eoff, nstate=2,
            aux_names=tuple(n for n, _, _ in GEAR_AUX), aux_units=tuple(u for _, u, _ in GEAR_AUX),
            aux_desc=tuple(d for _, _, d in GEAR_AUX), commit=_commit_angles,
            extra={"mesh": info}, naux=NAUX_PUBLIC + 2, dissipative=True,
        )


def _commit_angles(group: Group, state) -> None:
    """Store the accumulated wheel angles (relative to the mesh frame) after a step."""
    state.es[group.eoff] = group.aux[:, COL_PHI_A]
    state.es[group.eoff + 1] = group.aux[:, COL_PHI_B]


def mesh_info(model, name: str) -> dict:
    """Build-time data of gear pair ``name`` in a compiled model: mean stiffness [N/m],
    damping [N s/m], contact ratio, friction arm [m], operating pitch radii [m], base radius
    of A in its transverse plane [m], the coefficients c_A, c_B [m/rad] of the wheel
    rotations in the normal approach, and the normal backlash [m]."""
    gi, ei = model.group_of[name]
    return dict(model.groups[gi].extra["mesh"][ei])


register(GearPairFamily())
