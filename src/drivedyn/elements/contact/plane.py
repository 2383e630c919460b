"""Force-type contact elements between two markers (families ``plane_contact``,
``thrust_washer_contact``, ``journal_contact``).

Every contact computes a penetration ``delta`` [m] from the marker frames, a normal force from
a :class:`~drivedyn.elements.contact.impact_laws.NormalLaw` (penalty or continuous impact, with the
approach speed at first contact kept in the State) and a friction force or torque from a
:class:`~drivedyn.elements.contact.friction.FrictionLaw`. It reports its normal force, gap, sliding
velocity, friction force or torque and dissipated power, puts the contact spring's potential
energy into the energy account and counts the impact damping and friction power as
dissipated (physics.md 3, seeds 000-002). Markers on the ground are allowed on either side.

* :class:`PlaneContact`: a point (or sphere of radius ``radius``) at the origin of marker B
  against the plane through the origin of marker A with normal ``n = z_A`` (B on the +z side).
  ``delta = radius - (x_B - x_A) . n``. Friction on the sliding velocity of the contact point
  ``x_B - radius n``: ``s = (v_B(x_c) - v_A(x_c))`` projected on the plane, force
  ``mu_R(|s|) F s/|s|`` opposing it (a sphere that rolls without slipping feels none).
* :class:`ThrustWasherContact`: the annular face of a gear (marker B) on a thrust washer
  (marker A, normal ``z_A``), radii ``r_int < r_ext``: axial penetration
  ``delta = -(x_B - x_A) . n``, uniform pressure ``F/S``, ``S = pi (r_ext^2 - r_int^2)``, and
  the friction torque on the relative spin ``omega = (omega_B - omega_A) . n``::

      M = 2 pi mu_R (F/S) (r_ext^3 - r_int^3)/3 = mu_R F r_m,
      r_m = 2 (r_ext^3 - r_int^3) / (3 (r_ext^2 - r_int^2))

  with the coefficient taken at the sliding speed ``r_m omega`` [m/s] at the friction radius.
  Radial sliding of the faces is not resisted (the gears are centred by their joints).
* :class:`JournalContact`: a pin (marker B, radius ``pin_radius``) in a bore (marker A, axis
  ``z_A``, radius ``bore_radius``), or gear tips in a housing pocket. With ``e`` the offset of
  the pin centre from the bore axis (its component normal to ``z_A``),
  ``delta = |e| - (bore_radius - pin_radius)``; the normal force acts along ``e``. Friction
  acts at the contact point on the sliding velocity along the circumference,
  ``s = r_p (omega_B - omega_A) . z_A + (whirl of the pin centre)``, as a force
  ``f = mu_R(s) F`` there: on the pin it is a friction torque ``f r_p`` about its axis plus a
  tangential force, reported as ``friction_force`` and ``friction_torque``. The contact lies
  in the plane of marker B's origin (model a long journal with several elements).

Formulation: the residual is a sum of scalar forces times gradients of kinematic functions
(:mod:`drivedyn.elements.framework.primitives`): ``delta`` (distance along a marker axis, or the norm
of two of them for the journal) and velocity-level sliding rates ``s = J(q) . v``, for which
``J`` and ``dJ/dq`` are known (relative spin projected on a marker axis,
:func:`~drivedyn.elements.contact.common.omega_projection`). The stiffness is
``F d2delta/dq2 + grad(delta) (dF/dq)^T`` plus the friction terms ``f dJ/dq + J (df/dq)^T``,
the damping ``grad(delta) (dF/dv)^T + J (df/dv)^T``; both are non-symmetric, as the Newton
matrix allows.

Per-contact state (:data:`~drivedyn.elements.contact.impact_laws.NSTATE` floats in ``State.es``):
contact flag, approach speed at first contact, last penetration, rate, time and acceleration,
last separation speed, number of contacts; the kernel writes the values of an accepted step
into hidden ``aux`` columns and the group's ``commit`` copies them (never during Newton
iterations).

Laws may be given as mappings (model files: TOML tables), e.g.
``law = {stiffness = 1e10, exponent = 1.5, law = "lankarani-nikravesh", restitution = 0.8}``.

This module also re-exports the rest of the contact family's public API (:class:`NormalLaw`,
:class:`FrictionLaw`, :class:`~drivedyn.elements.contact.squeeze_film.SqueezeFilm`,
:class:`~drivedyn.elements.contact.unilateral.UnilateralContact`); importing it registers all of them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.contact.common import (
    CONTACT_POWER,
    GAP_RATE,
    MU_R,
    add_normal,
    add_velocity_force,
    axial_motion,
    axis_distance,
    check_laws,
    coerce_laws,
    contact_group,
    contact_normal,
    friction_coefficient,
    friction_ratio,
    has_friction,
    omega_projection,
    transpose_times,
    washer_friction_radius,
    washer_work,
    work_offsets,
    work_size,
)
from drivedyn.elements.contact.friction import FrictionLaw
from drivedyn.elements.contact.impact_laws import NormalLaw, impact_state, initial_state
from drivedyn.elements.framework.building import two_markers, what_of
from drivedyn.elements.framework.checks import check_number
from drivedyn.elements.framework.contract import local_arrays_at
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.primitives import add_scaled, prim_axial
from drivedyn.elements.framework.registry import Family, TwoMarkerSpec, register
from drivedyn.elements.framework.work_arrays import carve
from drivedyn.errors import ModelError

# --- point / sphere on plane ----------------------------------------------------------------


@njit(cache=True)
def _plane_contacts(P, C, W, full):
    (pA, pB, RmA, radius), law, fric, na = P
    (L, (gn, Hn), (J1, dJ1), (J2, dJ2), (Go, Do), vl, Hv, S1, S2, (dFq, dFv), (df1q, df2q),
     (ws, wv), M3) = W
    rq, _, _, Cd, K, _ = L
    x, R, _, _, _, es, _, t = sc.state(C)
    aux = C[sc.AUX]
    for e in range(sc.count(C)):
        nA, nB = sc.pair(C, e)
        o = sc.state_offset(C, e)
        RA = R[nA]
        RB = R[nB]
        rho = radius[e]
        sc.velocities(C, e, 12, vl)
        sc.clear(L, full)
        phin, phid = axis_distance(x[nA], RA, x[nB], RB, pA[e], pB[e], RmA[e, :, 2], gn, Hn,
                                   vl, Hv, full, ws, wv)
        delta = rho - phin
        rate = -phid
        F, Fd, Fr, V, Pn, vs = contact_normal(law, e, delta, rate, es, o)
        add_normal(F, Fd, Fr, -1.0, gn, Hn, Hv, rq, K, Cd, dFq, dFv, full)
        sp = 0.0
        ftot = 0.0
        mu_now = 0.0
        Pf = 0.0
        if F > 0.0 and has_friction(fric, e):
            prim_axial(x[nA], RA, x[nB], RB, pA[e], pB[e], RmA[e, :, 0], J1, dJ1, full, ws, wv)
            prim_axial(x[nA], RA, x[nB], RB, pA[e], pB[e], RmA[e, :, 1], J2, dJ2, full, ws, wv)
            if rho != 0.0:
                # contact point below the centre: slip = centre slip -/+ rho (w_B - w_A).t2/t1
                omega_projection(RA, RB, RmA[e, :, 1], Go, Do, full, M3)
                add_scaled(-rho, Go, Do, J1, dJ1, full)
                omega_projection(RA, RB, RmA[e, :, 0], Go, Do, full, M3)
                add_scaled(rho, Go, Do, J2, dJ2, full)
            s1 = 0.0
            s2 = 0.0
            for a in range(12):
                s1 += J1[a] * vl[a]
                s2 += J2[a] * vl[a]
            sp = np.sqrt(s1 * s1 + s2 * s2)
            ph, dph = friction_ratio(fric, e, sp)
            f1 = F * ph * s1
            f2 = F * ph * s2
            mu_now = ph * sp
            ftot = F * mu_now
            Pf = F * ph * sp * sp
            for a in range(12):
                rq[a] += f1 * J1[a] + f2 * J2[a]
            if full:
                a11 = ph
                a22 = ph
                a12 = 0.0
                if sp > 0.0:
                    q = dph / sp
                    a11 += q * s1 * s1
                    a22 += q * s2 * s2
                    a12 = q * s1 * s2
                transpose_times(dJ1, vl, S1)
                transpose_times(dJ2, vl, S2)
                for b in range(12):
                    df1q[b] = F * (a11 * S1[b] + a12 * S2[b]) + ph * s1 * dFq[b]
                    df2q[b] = F * (a12 * S1[b] + a22 * S2[b]) + ph * s2 * dFq[b]
                for a in range(12):
                    j1 = J1[a]
                    j2 = J2[a]
                    for b in range(12):
                        K[a, b] += f1 * dJ1[a, b] + f2 * dJ2[a, b] + j1 * df1q[b] + j2 * df2q[b]
                        Cd[a, b] += (j1 * (F * (a11 * J1[b] + a12 * J2[b]) + ph * s1 * dFv[b])
                                     + j2 * (F * (a12 * J1[b] + a22 * J2[b]) + ph * s2 * dFv[b]))
        sc.report(C, e, (F, -delta, -rate, sp, ftot, mu_now, Pn + Pf))
        sc.energy(C, e, 0.0, V, 0.0, Pn + Pf)
        impact_state(delta, rate, vs, t, es, o, aux, e, na)
        sc.scatter(C, L, e, 2, full)


@njit(cache=True)
def plane_contact_kernel(
    pA, pB, RmA, radius, law, fric, na, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    buf = sc.work_buffer(work, work_size(4, 8))
    G, V, w = work_offsets(4, 8)
    W = (local_arrays_at(buf, 0, 12, 0), sc.grad_hess_at(buf, G, 12),
         sc.grad_hess_at(buf, G + 156, 12), sc.grad_hess_at(buf, G + 312, 12),
         sc.grad_hess_at(buf, G + 468, 12), carve(buf, V, 12), carve(buf, V + 12, 12),
         carve(buf, V + 24, 12), carve(buf, V + 36, 12),
         (carve(buf, V + 48, 12), carve(buf, V + 60, 12)),
         (carve(buf, V + 72, 12), carve(buf, V + 84, 12)), sc.workspace_at(buf, w),
         carve(buf, w + sc.WORKSPACE_SIZE, (3, 3)))
    sc.run(_plane_contacts, ((pA, pB, RmA, radius), law, fric, na),
           (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
            r, rabs, data, eout, aux), W)


# --- annular face on thrust washer ----------------------------------------------------------


@njit(cache=True)
def _washer_contacts(P, C, W, full):
    (pA, pB, RmA, rm, area), law, fric, na = P
    L, (gn, Hn), (Gs, Ds), vl, Hv, Dv, (dFq, dFv), (ws, wv), M3 = W
    rq, _, _, Cd, K, _ = L
    x, R, _, _, _, es, _, t = sc.state(C)
    aux = C[sc.AUX]
    for e in range(sc.count(C)):
        nA, nB = sc.pair(C, e)
        o = sc.state_offset(C, e)
        RA = R[nA]
        RB = R[nB]
        sc.velocities(C, e, 12, vl)
        sc.clear(L, full)
        phin, phid = axis_distance(x[nA], RA, x[nB], RB, pA[e], pB[e], RmA[e, :, 2], gn, Hn,
                                   vl, Hv, full, ws, wv)
        delta = -phin
        rate = -phid
        F, Fd, Fr, V, Pn, vs = contact_normal(law, e, delta, rate, es, o)
        add_normal(F, Fd, Fr, -1.0, gn, Hn, Hv, rq, K, Cd, dFq, dFv, full)
        omega_projection(RA, RB, RmA[e, :, 2], Gs, Ds, full, M3)
        w = 0.0
        for a in range(12):
            w += Gs[a] * vl[a]
        Mf = 0.0
        mu_now = 0.0
        Pf = 0.0
        if F > 0.0 and has_friction(fric, e):
            mu_now, dmu = friction_coefficient(fric, e, rm[e] * w)
            Mf = mu_now * F * rm[e]
            Pf = Mf * w
            if full:
                transpose_times(Ds, vl, Dv)
            add_velocity_force(Mf, dmu * F * rm[e] * rm[e], mu_now * rm[e], Gs, Ds, Dv, dFq,
                               dFv, rq, K, Cd, full)
        sc.report(C, e, (F, -delta, -rate, F / area[e], w, rm[e] * w, mu_now, Mf, Pn + Pf))
        sc.energy(C, e, 0.0, V, 0.0, Pn + Pf)
        impact_state(delta, rate, vs, t, es, o, aux, e, na)
        sc.scatter(C, L, e, 2, full)


@njit(cache=True)
def washer_contact_kernel(
    pA, pB, RmA, rm, area, law, fric, na, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    W = washer_work(work)
    sc.run(_washer_contacts, ((pA, pB, RmA, rm, area), law, fric, na),
           (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
            r, rabs, data, eout, aux), W)


# --- journal: pin in bore -------------------------------------------------------------------


@njit(cache=True)
def _journal_contacts(P, C, W, full):
    (pA, pB, RmA, clear, rpin), law, fric, na = P
    (L, (g1, H1), (g2, H2), (gd, Hd), (Js, dJs), (Gz, Dz), vl, Hv, Jv, (dFq, dFv), (ws, wv),
     M3) = W
    rq, _, _, Cd, K, _ = L
    x, R, _, _, _, es, _, t = sc.state(C)
    aux = C[sc.AUX]
    for e in range(sc.count(C)):
        nA, nB = sc.pair(C, e)
        o = sc.state_offset(C, e)
        RA = R[nA]
        RB = R[nB]
        sc.velocities(C, e, 12, vl)
        sc.clear(L, full)
        p1 = prim_axial(x[nA], RA, x[nB], RB, pA[e], pB[e], RmA[e, :, 0], g1, H1, full, ws, wv)
        p2 = prim_axial(x[nA], RA, x[nB], RB, pA[e], pB[e], RmA[e, :, 1], g2, H2, full, ws, wv)
        roff = np.sqrt(p1 * p1 + p2 * p2)
        delta = roff - clear[e]
        rate = 0.0
        if roff > 0.0:
            for a in range(12):
                gd[a] = (p1 * g1[a] + p2 * g2[a]) / roff
                rate += gd[a] * vl[a]
        F = 0.0
        V = 0.0
        Pn = 0.0
        vs = 0.0
        sv = 0.0
        mu_now = 0.0
        f = 0.0
        Pf = 0.0
        if delta > 0.0:
            F, Fd, Fr, V, Pn, vs = contact_normal(law, e, delta, rate, es, o)
            if full:
                for a in range(12):
                    for b in range(12):
                        Hd[a, b] = (g1[a] * g1[b] + p1 * H1[a, b] + g2[a] * g2[b]
                                    + p2 * H2[a, b] - gd[a] * gd[b]) / roff
                transpose_times(Hd, vl, Hv)
            add_normal(F, Fd, Fr, 1.0, gd, Hd, Hv, rq, K, Cd, dFq, dFv, full)
            if F > 0.0 and has_friction(fric, e):
                omega_projection(RA, RB, RmA[e, :, 2], Gz, Dz, full, M3)
                rp = rpin[e]
                for a in range(12):
                    Js[a] = (p1 * g2[a] - p2 * g1[a]) / roff + rp * Gz[a]
                    sv += Js[a] * vl[a]
                if full:
                    for a in range(12):
                        ta = (p1 * g2[a] - p2 * g1[a]) / roff
                        for b in range(12):
                            dJs[a, b] = ((g2[a] * g1[b] - g1[a] * g2[b] + p1 * H2[a, b]
                                          - p2 * H1[a, b]) / roff - ta * gd[b] / roff
                                         + rp * Dz[a, b])
                    transpose_times(dJs, vl, Jv)
                mu_now, dmu = friction_coefficient(fric, e, sv)
                f = mu_now * F
                Pf = f * sv
                add_velocity_force(f, dmu * F, mu_now, Js, dJs, Jv, dFq, dFv, rq, K, Cd, full)
        sc.report(C, e, (F, -delta, -rate, sv, mu_now, f, f * rpin[e], Pn + Pf))
        sc.energy(C, e, 0.0, V, 0.0, Pn + Pf)
        impact_state(delta, rate, vs, t, es, o, aux, e, na)
        sc.scatter(C, L, e, 2, full)


@njit(cache=True)
def journal_contact_kernel(
    pA, pB, RmA, clear, rpin, law, fric, na, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    buf = sc.work_buffer(work, work_size(5, 5))
    G, V, w = work_offsets(5, 5)
    W = (local_arrays_at(buf, 0, 12, 0), sc.grad_hess_at(buf, G, 12),
         sc.grad_hess_at(buf, G + 156, 12), sc.grad_hess_at(buf, G + 312, 12),
         sc.grad_hess_at(buf, G + 468, 12), sc.grad_hess_at(buf, G + 624, 12),
         carve(buf, V, 12), carve(buf, V + 12, 12), carve(buf, V + 24, 12),
         (carve(buf, V + 36, 12), carve(buf, V + 48, 12)), sc.workspace_at(buf, w),
         carve(buf, w + sc.WORKSPACE_SIZE, (3, 3)))
    sc.run(_journal_contacts, ((pA, pB, RmA, clear, rpin), law, fric, na),
           (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
            r, rabs, data, eout, aux), W)


# --- specs ------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PlaneContact(TwoMarkerSpec):
    """Point or sphere (origin of ``marker_b``) against the plane of ``marker_a``.

    Attributes:
        name: unique element name.
        marker_a: the plane: through the marker origin, normal = its z axis, pointing to the
            side where marker B is free.
        marker_b: the point, or the centre of the sphere.
        law: normal force law (:class:`NormalLaw`).
        friction: :class:`FrictionLaw` or None (frictionless).
        radius: sphere radius [m] >= 0 (0: a point).
    """

    law: NormalLaw = field(default_factory=lambda: NormalLaw(1e8))
    friction: FrictionLaw | None = None
    radius: float = 0.0
    family: ClassVar[str] = "plane_contact"
    units: ClassVar[dict[str, str]] = {"radius": "m"}

    def __post_init__(self) -> None:
        coerce_laws(self, what_of(self))

    def validate(self) -> None:
        what = what_of(self)
        check_number(what, "radius", self.radius, 0.0)
        check_laws(self, what)


@dataclass(frozen=True)
class ThrustWasherContact(TwoMarkerSpec):
    """Annular face (``marker_b``, e.g. a gear face) on a thrust washer (``marker_a``).

    Attributes:
        name: unique element name.
        marker_a: washer face: origin on the face, z axis = washer normal towards B.
        marker_b: the other face (origin on it, on the axis).
        law: normal force law of the axial contact.
        r_int, r_ext: inner and outer radii of the annulus [m], 0 <= r_int < r_ext.
        friction: :class:`FrictionLaw` of this face (each face its own), or None.
    """

    law: NormalLaw = field(default_factory=lambda: NormalLaw(1e9, 1.0))
    r_int: float = 0.0
    r_ext: float = 0.0
    friction: FrictionLaw | None = None
    family: ClassVar[str] = "thrust_washer_contact"
    units: ClassVar[dict[str, str]] = {"r_int": "m", "r_ext": "m"}

    def __post_init__(self) -> None:
        coerce_laws(self, what_of(self))

    def validate(self) -> None:
        what = what_of(self)
        ri = check_number(what, "r_int", self.r_int, 0.0)
        re = check_number(what, "r_ext", self.r_ext, 0.0, strict=True)
        if ri >= re:
            raise ModelError(f"{what}: r_int = {self.r_int!r} must be < r_ext = {self.r_ext!r}")
        check_laws(self, what)

    def visuals(self) -> tuple:
        """The washer as an annulus behind face A (thickness a tenth of its radial width)
        and its normal force as an arrow along the washer normal."""
        from drivedyn.elements.framework.visuals import arrow, cylinder

        t = 0.1 * (self.r_ext - self.r_int)
        return (cylinder(self.marker_a, self.r_ext, t, inner_radius=self.r_int, z0=-t,
                         role="washer", label=self.name),
                arrow(self.marker_a, f"{self.name}.normal_force", label=self.name))

    @property
    def area(self) -> float:
        """Face area S = pi (r_ext^2 - r_int^2) [m^2]."""
        return math.pi * (self.r_ext**2 - self.r_int**2)

    @property
    def friction_radius(self) -> float:
        """r_m = 2 (r_ext^3 - r_int^3) / (3 (r_ext^2 - r_int^2)) [m]: M = mu F r_m."""
        return washer_friction_radius(self.r_int, self.r_ext)


@dataclass(frozen=True)
class JournalContact(TwoMarkerSpec):
    """Pin (``marker_b``, its origin the pin centre) in a bore (``marker_a``, z = bore axis).

    Attributes:
        name: unique element name.
        marker_a: bore: origin on the bore axis, z axis along it.
        marker_b: pin centre (in the contact plane).
        law: normal force law of the radial contact.
        bore_radius: [m] > pin_radius.
        pin_radius: [m] > 0 (for gear tips in a pocket: the tip radius).
        friction: :class:`FrictionLaw` or None.
    """

    law: NormalLaw = field(default_factory=lambda: NormalLaw(1e9, 1.0))
    bore_radius: float = 0.0
    pin_radius: float = 0.0
    friction: FrictionLaw | None = None
    family: ClassVar[str] = "journal_contact"
    units: ClassVar[dict[str, str]] = {"bore_radius": "m", "pin_radius": "m"}

    def __post_init__(self) -> None:
        coerce_laws(self, what_of(self))

    def validate(self) -> None:
        what = what_of(self)
        rb = check_number(what, "bore_radius", self.bore_radius, 0.0, strict=True)
        rp = check_number(what, "pin_radius", self.pin_radius, 0.0, strict=True)
        if rp >= rb:
            raise ModelError(f"{what}: pin_radius = {self.pin_radius!r} must be < bore_radius "
                             f"= {self.bore_radius!r} (a clearance is needed)")
        check_laws(self, what)

    def visuals(self) -> tuple:
        """The contact force on the pin, at the bore wall where the pin presses (on the
        line from the bore axis through the pin centre)."""
        from drivedyn.elements.framework.visuals import point_force

        return (point_force(self.marker_a, self.marker_b, f"{self.name}.normal_force",
                            self.bore_radius, radial=True, label=self.name),)


# --- building ---------------------------------------------------------------------------------


class PlaneContactFamily(Family):
    """Registry entry of :class:`PlaneContact`."""

    name = "plane_contact"

    def build(self, specs, ctx) -> Group:
        pA, pB, RmA, _, lnodes = two_markers(specs, ctx, "a contact")
        states = []
        for e, s in enumerate(specs):
            phi, rate = axial_motion(ctx, lnodes[e, 0], pA[e], RmA[e][:, 2], lnodes[e, 1], pB[e])
            states.append(initial_state(s.radius - phi, -rate, s.law.min_impact_speed))
        radius = np.array([s.radius for s in specs], float)
        outputs = (
            ("normal_force", "N", "normal contact force (>= 0)"),
            ("gap", "m", "distance of the point (sphere surface) from the plane; < 0: "
             "penetration"),
            ("gap_rate", "m/s", "rate of the gap (< 0: approaching)"),
            ("sliding_speed", "m/s", "sliding speed of the contact point in the plane"),
            ("friction_force", "N", "friction force magnitude"),
            MU_R,
            CONTACT_POWER,
        )
        return contact_group(self.name, specs, ctx, plane_contact_kernel,
                             (pA, pB, RmA, radius), states, outputs, lnodes, work_size(4, 8))


class ThrustWasherContactFamily(Family):
    """Registry entry of :class:`ThrustWasherContact`."""

    name = "thrust_washer_contact"

    def build(self, specs, ctx) -> Group:
        pA, pB, RmA, _, lnodes = two_markers(specs, ctx, "a contact")
        states = []
        for e, s in enumerate(specs):
            phi, rate = axial_motion(ctx, lnodes[e, 0], pA[e], RmA[e][:, 2], lnodes[e, 1], pB[e])
            states.append(initial_state(-phi, -rate, s.law.min_impact_speed))
        rm = np.array([s.friction_radius for s in specs], float)
        area = np.array([s.area for s in specs], float)
        outputs = (
            ("normal_force", "N", "axial contact force (>= 0)"),
            ("gap", "m", "axial gap between the faces along the washer normal; < 0: "
             "penetration"),
            GAP_RATE,
            ("pressure", "Pa", "mean contact pressure F/S"),
            ("relative_spin", "rad/s", "spin of B relative to A about the washer normal"),
            ("sliding_speed", "m/s", "sliding speed at the friction radius r_m"),
            MU_R,
            ("friction_torque", "N m", "friction torque resisting the relative spin"),
            CONTACT_POWER,
        )
        return contact_group(self.name, specs, ctx, washer_contact_kernel,
                             (pA, pB, RmA, rm, area), states, outputs, lnodes, work_size(2, 5))


class JournalContactFamily(Family):
    """Registry entry of :class:`JournalContact`."""

    name = "journal_contact"

    def build(self, specs, ctx) -> Group:
        pA, pB, RmA, _, lnodes = two_markers(specs, ctx, "a contact")
        states = []
        for e, s in enumerate(specs):
            nA, nB = lnodes[e]
            p1, r1 = axial_motion(ctx, nA, pA[e], RmA[e][:, 0], nB, pB[e])
            p2, r2 = axial_motion(ctx, nA, pA[e], RmA[e][:, 1], nB, pB[e])
            roff = math.hypot(p1, p2)
            rate = (p1 * r1 + p2 * r2) / roff if roff > 0 else 0.0
            states.append(initial_state(roff - (s.bore_radius - s.pin_radius), rate,
                                        s.law.min_impact_speed))
        clear = np.array([s.bore_radius - s.pin_radius for s in specs], float)
        rpin = np.array([s.pin_radius for s in specs], float)
        outputs = (
            ("normal_force", "N", "radial contact force (>= 0)"),
            ("gap", "m", "radial clearance left (bore - pin radius - offset); < 0: "
             "penetration"),
            GAP_RATE,
            ("sliding_speed", "m/s", "circumferential sliding speed at the contact point"),
            MU_R,
            ("friction_force", "N", "circumferential friction force at the contact point"),
            ("friction_torque", "N m", "friction torque on the pin about its axis (f r_pin)"),
            CONTACT_POWER,
        )
        return contact_group(self.name, specs, ctx, journal_contact_kernel,
                             (pA, pB, RmA, clear, rpin), states, outputs, lnodes,
                             work_size(5, 5))


register(PlaneContactFamily())
register(ThrustWasherContactFamily())
register(JournalContactFamily())
