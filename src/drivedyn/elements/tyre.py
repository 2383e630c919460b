"""A tyre on a flat road (family ``tyre``): Magic Formula forces on a wheel body.

:class:`TyreContact` attaches a :class:`drivedyn.tyres.Tyre` to a marker on the wheel: origin
at the wheel centre, z axis along the spin axis pointing to the tyre's left (the ISO-W +y
axis: forward rolling is a positive spin about it). The road is the plane ``z = road_height``
of the global frame (z up) with a friction factor per x-interval (:class:`RoadPatch`, e.g.
split-mu or a mu-jump).

Per evaluation, in the road axes of the tyre (``e_x = a x n`` heading, ``e_y = n x e_x``,
``n`` the road normal, ``a`` the spin axis):

* deflection ``rho = R0 - h / cos(gamma)`` (``h`` height of the centre, camber
  ``gamma = asin(-a . n)``: positive when the wheel top leans to the tyre's +y side);
  vertical load ``Fz = max(0, Cz rho + Kz rho_dot)`` (the file's VERTICAL_STIFFNESS and
  VERTICAL_DAMPING);
* slip velocities of the contact point (``R_e`` the effective rolling radius)
  ``V_sx = e_x . (v_c + omega x (-R_e n))``, ``V_sy = e_y . (...)``; forward speed
  ``V_x = e_x . v_c``;
* transient slips (Pacejka 2012 sec. 7.2, the first-order model written with the slip
  velocities so that standstill is regular):
  ``sigma_k dkappa'/dt + |V_x| kappa' = -V_sx``, ``sigma_a dalpha'/dt + |V_x| alpha' = V_sy``
  (``alpha'`` is tan of the transient slip angle), integrated over the step from the values
  and rates committed at the last accepted step by the theta method, ``theta = 1/2``
  (trapezoidal, second order like the rest of the step) while ``z = dt |V_x| / sigma <= 1``
  and ``theta = 1 - 1/(2 z)`` beyond (towards backward Euler where the step is long against
  the relaxation time, so no ringing). Backward Euler throughout made the slips' error of
  first order in the step, which the step control does not see: a vehicle's window figures
  then followed ``h_max`` whatever the tolerance (4WD launch: 2.4e-4 off at every
  tolerance; with this update 7.4e-6 to 2.7e-6 from three times to a thirtieth of the
  file's tolerances, ``benchmarks/work_precision.py``); with ``relaxation=False`` the
  steady slips
  ``kappa = -V_sx/|V_x|``, ``tan alpha = V_sy/|V_x|`` with ``|V_x| >= VXLOW/10``;
* below VXLOW a damping ``kappa' - d w V_sx/VXLOW``, ``alpha' + d w V_sy/VXLOW`` with
  ``w = (1 + cos(pi |V_x|/VXLOW))/2`` stops the carcass spring ringing at standstill
  (MF-Tyre's low-speed damping; ``d = low_speed_damping``), and the formula's horizontal and
  vertical shifts, the aligning moment's trail and its residual moment are scaled by
  ``1 - w``: a tyre at rest carries no force at zero slip, and the aligning moment, whose
  trail and residual moment change sign with ``V_x``, stays continuous through standstill
  (without the scaling a loaded wheel creeping at 1e-7 m/s flipped 2 N m of residual moment
  with each sign of ``V_x``, and Newton failed on it: the 4WD launch at fixed 100 us steps);
* forces ``Fx, Fy, Mz`` from the formula at the contact point below the centre, rolling
  resistance ``My`` opposing the spin (smoothed over 0.01 m/s of rolling speed).

The tangent matrices are forward finite differences of the element's own residual over its
12 local coordinates (6 positions with right rotation perturbations, 6 velocities), from
the residual already evaluated: the combined-slip formula's derivatives in closed form would
be long and fragile, and a tyre group has a handful of elements. The registry tangent test
checks them like any other (its 1e-6 relative; steps FD_POS, FD_VEL). Central differences
took twice the evaluations: 160 against 81 us for the 4WD vehicle's four tyres with their
matrix, the same steps and wheel torques (benchmarks/README.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.framework.building import make_group, node_dofs, what_of
from drivedyn.elements.framework.checks import check_param, check_param_optional, unit_of
from drivedyn.elements.framework.contract import local_arrays_at, local_size
from drivedyn.elements.framework.group import COMMIT_TIME, Group
from drivedyn.elements.framework.primitives import mm
from drivedyn.elements.framework.registry import ElementSpec, Family, register
from drivedyn.elements.framework.work_arrays import carve
from drivedyn.errors import ModelError
from drivedyn.rotations import exp_so3_into
from drivedyn.tyres import Tyre, resolve_tyre
from drivedyn.tyres.magic_formula import (
    NOUT,
    NPAR,
    effective_radius,
    evaluate,
    relaxation_lengths,
)

MAX_PATCHES = 8
NSTATE = 5  # kappa', alpha' (tan), time of the committed values, their rates
NAUX = 22
FD_POS = 1e-7  # [m] and [rad]: steps of the in-kernel finite differences
FD_VEL = 1e-7  # [m/s] and [rad/s] (1e-6 left the damping tangent 2.5e-6 off, forward)
V_ROLL = 0.01  # [m/s] rolling speed over which the rolling resistance changes sign
_L6 = local_size.py_func(6, 0)  # the plain function: nothing compiled at import
#: entries of the tyres' work buffer (their last parameter, ``work``)
WORK_SIZE = _L6 + NOUT + 2 * NAUX + 42


@dataclass(frozen=True)
class RoadPatch:
    """Road friction factor ``mu`` on ``x_start <= x < x_end`` [m] (global x of the contact
    point), blended linearly over ``TyreContact.transition`` at the edges."""

    x_start: float
    x_end: float
    mu: float
    units: ClassVar[dict[str, str]] = {"x_start": "m", "x_end": "m", "mu": "1"}


@dataclass(frozen=True)
class TyreContact(ElementSpec):
    """A tyre on the flat road under the wheel of ``marker`` (see the module docstring).

    Attributes:
        name: unique element name.
        marker: marker on the wheel: origin at the centre, z = spin axis (tyre's +y).
        tyre: the :class:`~drivedyn.tyres.Tyre` (``read_tir``, ``simple_tyre``), or a
            string: a shipped tyre name, ``simple-<dry|wet|snow|ice>`` or a ``.tir`` path
            (model files).
        mu: road friction factor (on LMUX, LMUY; on D for simple tyres) outside the patches.
        patches: :class:`RoadPatch` (or ``{x_start, x_end, mu}`` tables, at most 8)
            overriding ``mu`` on x-intervals.
        transition: blend length [m] > 0 of the friction at patch edges.
        road_height: z of the road [m].
        pressure: inflation pressure [Pa]; 0 = the file's INFLPRES (MF 6.x only).
        relaxation: first-order transient slips (True) or steady slips.
        low_speed_damping: ``d`` [-] >= 0 of the low-speed damping.
        vertical_damping: Kz [N s/m]; None = the file's VERTICAL_DAMPING.
        side: ``"left"`` or ``"right"``: the side of the vehicle the wheel is on; a tyre
            given by name or path whose file was measured on the other side
            (``[MODEL] TYRESIDE``) is mirrored (:func:`drivedyn.tyres.read_tir`). None: the
            file as it is. A :class:`~drivedyn.tyres.Tyre` object is used as it is.
    """

    name: str
    marker: str
    tyre: Tyre | str
    mu: float = 1.0
    patches: tuple[RoadPatch, ...] = ()
    transition: float = 0.05
    road_height: float = 0.0
    pressure: float = 0.0
    relaxation: bool = True
    low_speed_damping: float = 0.2
    vertical_damping: float | None = None
    side: str | None = None
    family: ClassVar[str] = "tyre"
    units: ClassVar[dict[str, str]] = {"mu": "1", "transition": "m", "road_height": "m",
                                       "pressure": "Pa", "low_speed_damping": "1",
                                       "vertical_damping": "N s/m"}

    def markers(self) -> tuple[str, ...]:
        return (self.marker,)

    def resolved(self) -> tuple[Tyre, tuple[RoadPatch, ...]]:
        """The tyre and the patches as objects (strings and tables of model files read)."""
        what = what_of(self)
        try:
            if self.side is not None and self.side not in ("left", "right"):
                raise ModelError(f"side: expected 'left' or 'right', got {self.side!r}")
            tyre = resolve_tyre(self.tyre, self.side)
        except ModelError as exc:
            raise ModelError(f"{what}.{exc}") from None
        patches = []
        for i, p in enumerate(self.patches):
            if isinstance(p, dict):
                try:
                    p = RoadPatch(**p)
                except TypeError:
                    raise ModelError(f"{what}.patches[{i}]: expected the keys x_start, x_end, "
                                     f"mu, got {sorted(p)}") from None
            elif not isinstance(p, RoadPatch):
                raise ModelError(f"{what}.patches[{i}]: expected a RoadPatch or a table, got "
                                 f"{p!r}")
            patches.append(p)
        return tyre, tuple(patches)

    def visuals(self) -> tuple:
        """The wheel as a tyre (a tube of the unloaded radius, section width 0.35 R0, a rim
        of 0.65 R0) on the wheel marker, z = spin axis."""
        from drivedyn.elements.framework.visuals import cylinder

        try:
            r0 = self.resolved()[0].unloaded_radius
        except Exception:  # an unreadable tyre is reported by validate(), not here
            return ()
        return (cylinder(self.marker, r0, 0.35 * r0, inner_radius=0.65 * r0, role="wheel",
                         label=self.name),)

    def road(self) -> dict | None:
        """What the 3-D viewer draws of this tyre's road (JSON-ready): ``height`` [m] of the
        plane, ``mu`` outside the patches, ``patches`` ``[[x_start, x_end, mu], ...]`` [m],
        ``transition`` [m], and the tyre's unloaded ``radius`` and section ``width`` [m]
        (the footprint); None when the tyre cannot be read (``validate`` says why)."""
        try:
            tyre, patches = self.resolved()
            r0 = tyre.unloaded_radius
            width = tyre.value("WIDTH")
        except Exception:  # an unreadable tyre is reported by validate(), not here
            return None
        return {"height": float(self.road_height), "mu": float(self.mu),
                "patches": [[float(q.x_start), float(q.x_end), float(q.mu)] for q in patches],
                "transition": float(self.transition), "radius": float(r0),
                "width": float(width) if width > 0 else 0.35 * float(r0)}

    def validate(self) -> None:
        what = what_of(self)
        _, patches = self.resolved()
        check_param(self, "mu", 0.0)
        check_param(self, "transition", 0.0, strict=True)
        check_param(self, "pressure", 0.0)
        check_param(self, "low_speed_damping", 0.0)
        check_param_optional(self, "vertical_damping", 0.0)
        check_param(self, "road_height")
        if len(self.patches) > MAX_PATCHES:
            raise ModelError(f"{what}.patches: at most {MAX_PATCHES}, got {len(self.patches)}")
        for i, p in enumerate(patches):
            where = f"{what}.patches[{i}]"
            check_param(p, "mu", 0.0, what=where)
            x0 = check_param(p, "x_start", what=where)
            x1 = check_param(p, "x_end", what=where)
            if not x1 > x0:
                raise ModelError(f"{where}: expected x_start < x_end [{unit_of(p, 'x_end')}], "
                                 f"got {p.x_start!r}, {p.x_end!r}")


@njit(cache=True, inline="always")
def _road_mu(x, mu0, patches, npatch, blend):
    """Friction factor at global x: ``mu0`` outside the patches, each patch's mu inside,
    linear over ``blend`` centred on the edges (later patches win where they overlap)."""
    mu = mu0
    for k in range(npatch):
        x0 = patches[k, 0]
        x1 = patches[k, 1]
        w0 = min(max((x - x0) / blend + 0.5, 0.0), 1.0)
        w1 = min(max((x1 - x) / blend + 0.5, 0.0), 1.0)
        w = min(w0, w1)
        mu = (1.0 - w) * mu + w * patches[k, 2]
    return mu


@njit(cache=True, inline="always")
def _rot(R, x, y, z, k):
    """Component ``k`` of ``R @ (x, y, z)``."""
    return R[k, 0] * x + R[k, 1] * y + R[k, 2] * z


@njit(cache=True)
def _tyre_state(P, opt, patches, npatch, pm, Rm, xn, Rn, vn, Om, es0, t, out, aux, rq):
    """The residual ``rq`` (6,) of one tyre at node position ``xn`` (3,), rotation ``Rn``
    (3, 3), velocity ``vn`` (3,) and body angular velocity ``Om`` (3,); ``aux`` (NAUX,) the
    outputs, returns (potential energy, dissipated power). Scalar arithmetic only: it runs
    13 times per tangent evaluation (the forward differences)."""
    mu0, blend, zroad, pres, relax, dlow, kz, _ = opt
    for i in range(6):
        rq[i] = 0.0
    for i in range(NAUX):
        aux[i] = 0.0
    # arm of the wheel centre, spin axis a, road axes e_x = a x n / |.|, e_y = n x e_x
    arx = _rot(Rn, pm[0], pm[1], pm[2], 0)
    ary = _rot(Rn, pm[0], pm[1], pm[2], 1)
    arz = _rot(Rn, pm[0], pm[1], pm[2], 2)
    ax = _rot(Rn, Rm[0, 2], Rm[1, 2], Rm[2, 2], 0)
    ay = _rot(Rn, Rm[0, 2], Rm[1, 2], Rm[2, 2], 1)
    az = _rot(Rn, Rm[0, 2], Rm[1, 2], Rm[2, 2], 2)
    cg = math.sqrt(ax * ax + ay * ay)  # cos(camber)
    exx, exy = ay / cg, -ax / cg
    eyx, eyy = -exy, exx
    gamma = math.asin(min(max(-az, -1.0), 1.0))
    cx = xn[0] + arx
    h = xn[2] + arz - zroad
    r0 = P[4]
    rho = r0 - h / cg
    wx = _rot(Rn, Om[0], Om[1], Om[2], 0)  # angular velocity, global
    wy = _rot(Rn, Om[0], Om[1], Om[2], 1)
    wz = _rot(Rn, Om[0], Om[1], Om[2], 2)
    vcx = vn[0] + wy * arz - wz * ary
    vcy = vn[1] + wz * arx - wx * arz
    vcz = vn[2] + wx * ary - wy * arx
    vx = exx * vcx + exy * vcy
    # state
    kap_n = es0[0]
    alp_n = es0[1]
    tn = es0[2]
    kd_n = es0[3]
    ad_n = es0[4]
    dt = t - tn if math.isfinite(tn) else 0.0
    if dt < 0.0:
        dt = 0.0
    re = effective_radius(P, max(rho, 0.0))
    # contact-point slip velocities: v_c + w x (-R_e n), w x n = (wy, -wx, 0)
    vpx = vcx - re * wy
    vpy = vcy + re * wx
    vsx = exx * vpx + exy * vpy
    vsy = eyx * vpx + eyy * vpy
    spin = ax * wx + ay * wy + az * wz
    mu = _road_mu(cx, mu0, patches, npatch, blend)
    aux[6] = kap_n
    aux[7] = alp_n
    # rates of a wheel off the road or with steady slips: none (the work buffer holds the
    # previous element's)
    aux[20] = 0.0
    aux[21] = 0.0
    aux[10] = rho
    aux[13] = mu
    aux[14] = h
    aux[15] = spin
    aux[16] = vx
    if rho <= 0.0:
        return 0.0, 0.0
    rhod = -vcz / cg
    fz = P[6] * rho + kz * rhod
    if fz <= 0.0:  # leaving the road faster than the tyre springs back: no load, no force
        return 0.5 * P[6] * rho * rho, -P[6] * rho * rhod
    sig_k, sig_a = relaxation_lengths(P, fz, gamma, pres)
    avx = abs(vx)
    vxlow = P[2]
    if relax:
        zk = dt * avx / sig_k
        za = dt * avx / sig_a
        th = 0.5 if zk <= 1.0 else 1.0 - 0.5 / zk
        if math.isnan(kd_n):  # no rate committed yet (a run's first step)
            th = 1.0
            kd_n = 0.0
        kap = ((kap_n + (1.0 - th) * dt * kd_n) * sig_k - th * dt * vsx) / (sig_k + th * dt * avx)
        th = 0.5 if za <= 1.0 else 1.0 - 0.5 / za
        if math.isnan(ad_n):
            th = 1.0
            ad_n = 0.0
        alp = ((alp_n + (1.0 - th) * dt * ad_n) * sig_a + th * dt * vsy) / (sig_a + th * dt * avx)
        aux[20] = -(vsx + avx * kap) / sig_k
        aux[21] = (vsy - avx * alp) / sig_a
    else:
        vref = max(avx, 0.1 * vxlow)
        kap = -vsx / vref
        alp = vsy / vref
    kap_f = kap
    alp_f = alp
    wl = 0.0
    if avx < vxlow:
        wl = 0.5 * (1.0 + math.cos(math.pi * avx / vxlow))
        kap_f = kap - dlow * wl * vsx / vxlow
        alp_f = alp + dlow * wl * vsy / vxlow
    evaluate(P, fz, kap_f, math.atan(alp_f), gamma, vx, pres, mu, 1.0 - wl, out)
    fx = out[0]
    fy = out[1]
    mz = out[2]
    rr = abs(out[3])
    vroll = spin * re
    my = -rr * vroll / math.sqrt(vroll * vroll + V_ROLL * V_ROLL)
    Fx = fx * exx + fy * eyx
    Fy = fx * exy + fy * eyy
    Fz = fz
    # moment about the node origin: arm to the contact point below the centre, plus Mz about
    # the road normal and My about the tyre's y axis
    rcz = arz - h
    Mx = ary * Fz - rcz * Fy + my * eyx
    My = rcz * Fx - arx * Fz + my * eyy
    Mz = arx * Fy - ary * Fx + mz
    rq[0] = -Fx
    rq[1] = -Fy
    rq[2] = -Fz
    for k in range(3):  # body components
        rq[3 + k] = -(Rn[0, k] * Mx + Rn[1, k] * My + Rn[2, k] * Mz)
    # power on the wheel at the contact point v_c + w x (-h n) = v_c + (-h wy, h wx, 0)
    pw = (Fx * (vcx - h * wy) + Fy * (vcy + h * wx) + Fz * vcz + mz * wz
          + my * (eyx * wx + eyy * wy))
    pot = 0.5 * P[6] * rho * rho
    dis = -pw - P[6] * rho * rhod
    aux[0] = fx
    aux[1] = fy
    aux[2] = fz
    aux[3] = mz
    aux[4] = my
    aux[5] = kap_f
    aux[6] = kap
    aux[7] = alp
    aux[8] = math.atan(alp_f)
    aux[9] = gamma
    aux[11] = sig_k
    aux[12] = sig_a
    aux[17] = vsx
    aux[18] = dis
    aux[19] = out[8] * fz
    return pot, dis


@njit(cache=True)
def tyre_kernel(params, opts, patches, npatch, pm, Rm, work,
                lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
                cM, cC, cK, mode, want, r, rabs, data, eout, aux):
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    buf = sc.work_buffer(work, WORK_SIZE)  # the work arrays are views of the group's buffer
    L = local_arrays_at(buf, 0, 6, 0)
    o = _L6
    out, ax, axd = carve(buf, o, NOUT), carve(buf, o + NOUT, NAUX), \
        carve(buf, o + NOUT + NAUX, NAUX)
    o += NOUT + 2 * NAUX
    rp, rm, Rp, vp, Op, xp, ph, Eph = carve(buf, o, 6), carve(buf, o + 6, 6), \
        carve(buf, o + 12, (3, 3)), carve(buf, o + 21, 3), carve(buf, o + 24, 3), \
        carve(buf, o + 27, 3), carve(buf, o + 30, 3), carve(buf, o + 33, (3, 3))
    full = sc.full_pass(want, mode)
    rq, _, _, Cd, K, _ = L
    for e in range(sc.count(C)):
        n = sc.node(C, e, 0)
        d0 = sc.first_dof(C, e)
        s0 = sc.state_offset(C, e)
        es0 = es[s0:s0 + NSTATE]
        vn = v[d0:d0 + 3]
        Om = v[d0 + 3:d0 + 6]
        pot, dis = _tyre_state(params[e], opts[e], patches[e], npatch[e], pm[e], Rm[e], x[n],
                               R[n], vn, Om, es0, t, out, ax, rq)
        if full:
            for j in range(6):  # forward differences (module docstring): every column set
                for i in range(3):
                    for k in range(3):  # element-wise: a slice copy allocates
                        Rp[i, k] = R[n, i, k]
                    vp[i] = vn[i]
                    Op[i] = Om[i]
                for i in range(3):
                    xp[i] = x[n, i]
                # positions: translation j < 3, right rotation j >= 3
                if j < 3:
                    xp[j] += FD_POS
                else:
                    for i in range(3):
                        ph[i] = 0.0
                    ph[j - 3] = FD_POS
                    exp_so3_into(ph, Eph)
                    mm(R[n], Eph, Rp)
                _tyre_state(params[e], opts[e], patches[e], npatch[e], pm[e], Rm[e], xp,
                            Rp, vn, Om, es0, t, out, axd, rp)
                for i in range(6):
                    K[i, j] = (rp[i] - rq[i]) / FD_POS
                # velocities
                if j < 3:
                    vp[j] += FD_VEL
                else:
                    Op[j - 3] += FD_VEL
                _tyre_state(params[e], opts[e], patches[e], npatch[e], pm[e], Rm[e], x[n],
                            R[n], vp, Op, es0, t, out, axd, rm)
                for i in range(6):
                    Cd[i, j] = (rm[i] - rq[i]) / FD_VEL
        sc.scatter(C, L, e, 1, full)
        sc.energy(C, e, 0.0, pot, 0.0, dis)
        for k in range(NAUX):
            aux[e, k] = ax[k]


OUTPUTS = (
    ("fx", "N", "longitudinal force on the wheel (tyre axes, ISO-W)"),
    ("fy", "N", "lateral force on the wheel (tyre axes, ISO-W)"),
    ("fz", "N", "vertical load"),
    ("mz", "N m", "aligning moment"),
    ("my", "N m", "rolling-resistance moment about the tyre's y axis"),
    ("kappa", "1", "longitudinal slip the formula used (transient, with low-speed damping)"),
    ("kappa_transient", "1", "transient longitudinal slip kappa'"),
    ("tan_alpha_transient", "1", "transient slip (tan of the slip angle) alpha'"),
    ("alpha", "rad", "slip angle the formula used"),
    ("camber", "rad", "camber angle"),
    ("deflection", "m", "radial deflection rho"),
    ("sigma_kappa", "m", "longitudinal relaxation length"),
    ("sigma_alpha", "m", "lateral relaxation length"),
    ("road_mu", "1", "road friction factor under the tyre"),
    ("height", "m", "height of the wheel centre above the road"),
    ("spin", "rad/s", "wheel spin rate about its axis"),
    ("vx", "m/s", "forward speed of the wheel centre"),
    ("slip_speed", "m/s", "longitudinal slip velocity V_sx of the contact point"),
    ("dissipated_power", "W", "power dissipated by the tyre (slip and vertical damping)"),
    ("friction_limit", "N", "longitudinal friction limit mu_x Fz (road friction included)"),
    ("kappa_rate", "1/s", "rate of the transient longitudinal slip dkappa'/dt"),
    ("tan_alpha_rate", "1/s", "rate of the transient slip dalpha'/dt"),
)
assert len(OUTPUTS) == NAUX


class TyreFamily(Family):
    name = "tyre"
    spec_types = (TyreContact,)

    def build(self, specs, ctx) -> Group:
        nel = len(specs)
        params = np.zeros((nel, NPAR))
        opts = np.zeros((nel, 8))
        patches = np.zeros((nel, MAX_PATCHES, 3))
        npatch = np.zeros(nel, np.int64)
        pm = np.zeros((nel, 3))
        Rm = np.zeros((nel, 3, 3))
        lnodes = np.zeros((nel, 1), np.int64)
        eoff = np.zeros(nel, np.int64)
        for e, s in enumerate(specs):
            what = what_of(s)
            lnodes[e, 0], pm[e], Rm[e] = ctx.marker(s.marker, what)
            if lnodes[e, 0] == ctx.nn:
                raise ModelError(f"{what}: marker {s.marker!r} is on the ground; a tyre must "
                                 "be on a wheel body")
            tyre, pts = s.resolved()
            params[e] = tyre.params
            kz = tyre.vertical_damping if s.vertical_damping is None else s.vertical_damping
            opts[e] = (s.mu, s.transition, s.road_height, s.pressure, float(s.relaxation),
                       s.low_speed_damping, kz, 0.0)
            npatch[e] = len(pts)
            for k, p in enumerate(pts):
                patches[e, k] = (p.x_start, p.x_end, p.mu)
            # models start at t = 0; the rates are unknown until the first step commits
            # them (NaN: that step takes backward Euler, one step of local error O(h^2); a
            # rate of 0 where the slip velocity is not was an O(h) error carried on)
            eoff[e] = ctx.alloc_state([0.0, 0.0, 0.0, math.nan, math.nan])
        return make_group(
            self.name, specs, tyre_kernel, (params, opts, patches, npatch, pm, Rm,
                                            np.zeros(WORK_SIZE)), lnodes,
            node_dofs(ctx, lnodes), OUTPUTS, eoff=eoff, nstate=NSTATE,
            commit_cols=(6, 7, COMMIT_TIME, 20, 21),  # transient slips, their time and rates
            dissipative=True,
        )


register(TyreFamily())
