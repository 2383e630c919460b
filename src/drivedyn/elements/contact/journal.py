"""Pin in a bore: the force-type contact of family ``journal_contact``.

:class:`JournalContact`: a pin (marker B, radius ``pin_radius``) in a bore (marker A, axis
``z_A``, radius ``bore_radius``), or gear tips in a housing pocket. With ``e`` the offset of
the pin centre from the bore axis (its component normal to ``z_A``),
``delta = |e| - (bore_radius - pin_radius)``; the normal force acts along ``e``. Friction
acts at the contact point on the sliding velocity along the circumference,
``s = r_p (omega_B - omega_A) . z_A + (whirl of the pin centre)``, as a force
``f = mu_R(s) F`` there: on the pin it is a friction torque ``f r_p`` about its axis plus a
tangential force, reported as ``friction_force`` and ``friction_torque``. The contact lies
in the plane of marker B's origin (model a long journal with several elements).

Formulation, state and laws: :mod:`drivedyn.elements.contact`.
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
    check_laws,
    coerce_laws,
    contact_group,
    contact_normal,
    friction_coefficient,
    has_friction,
    omega_projection,
    transpose_times,
    work_offsets,
    work_size,
)
from drivedyn.elements.contact.friction import FrictionLaw
from drivedyn.elements.contact.impact_laws import NormalLaw, impact_state, initial_state
from drivedyn.elements.framework.building import two_markers, what_of
from drivedyn.elements.framework.checks import check_param, unit_of
from drivedyn.elements.framework.contract import local_arrays_at
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.primitives import prim_axial
from drivedyn.elements.framework.registry import Family, TwoMarkerSpec, register
from drivedyn.elements.framework.work_arrays import carve
from drivedyn.errors import ModelError


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
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    (L, (g1, H1), (g2, H2), (gd, Hd), (Js, dJs), (Gz, Dz), vl, Hv, Jv, (dFq, dFv), (ws, wv), M3) = W
    full = sc.full_pass(want, mode)
    rq, _, _, Cd, K, _ = L
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
        rb = check_param(self, "bore_radius", 0.0, strict=True)
        rp = check_param(self, "pin_radius", 0.0, strict=True)
        if rp >= rb:
            m = unit_of(self, "bore_radius")
            raise ModelError(f"{what}: pin_radius = {self.pin_radius!r} {m} must be < "
                             f"bore_radius = {self.bore_radius!r} {m} (a clearance is needed)")
        check_laws(self, what)

    def visuals(self) -> tuple:
        """The contact force on the pin, at the bore wall where the pin presses (on the
        line from the bore axis through the pin centre)."""
        from drivedyn.elements.framework.visuals import point_force

        return (point_force(self.marker_a, self.marker_b, f"{self.name}.normal_force",
                            self.bore_radius, radial=True, label=self.name),)



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
                             work_size.py_func(5, 5))




register(JournalContactFamily())
