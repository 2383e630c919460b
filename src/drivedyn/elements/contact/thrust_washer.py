"""Annular face on a thrust washer: the force-type contact of family ``thrust_washer_contact``.

:class:`ThrustWasherContact`: the annular face of a gear (marker B) on a thrust washer
(marker A, normal ``z_A``), radii ``r_int < r_ext``: axial penetration
``delta = -(x_B - x_A) . n``, uniform pressure ``F/S``, ``S = pi (r_ext^2 - r_int^2)``, and
the friction torque on the relative spin ``omega = (omega_B - omega_A) . n``::

    M = 2 pi mu_R (F/S) (r_ext^3 - r_int^3)/3 = mu_R F r_m,
    r_m = 2 (r_ext^3 - r_int^3) / (3 (r_ext^2 - r_int^2))

with the coefficient taken at the sliding speed ``r_m omega`` [m/s] at the friction radius.
Radial sliding of the faces is not resisted (the gears are centred by their joints).

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
    axis_distance,
    check_laws,
    coerce_laws,
    contact_group,
    contact_normal,
    friction_coefficient,
    has_friction,
    omega_projection,
    transpose_times,
    washer_friction_radius,
    washer_work,
    work_size,
)
from drivedyn.elements.contact.friction import FrictionLaw
from drivedyn.elements.contact.impact_laws import NormalLaw, impact_state, initial_state
from drivedyn.elements.framework.building import two_markers, what_of
from drivedyn.elements.framework.checks import check_param, unit_of
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.registry import Family, TwoMarkerSpec, register
from drivedyn.errors import ModelError


@njit(cache=True)
def washer_contact_kernel(
    pA, pB, RmA, rm, area, law, fric, na, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    W = washer_work(work)
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    L, (gn, Hn), (Gs, Ds), vl, Hv, Dv, (dFq, dFv), (ws, wv), M3 = W
    full = sc.full_pass(want, mode)
    rq, _, _, Cd, K, _ = L
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
        ri = check_param(self, "r_int", 0.0)
        re = check_param(self, "r_ext", 0.0, strict=True)
        if ri >= re:
            m = unit_of(self, "r_ext")
            raise ModelError(f"{what}: r_int = {self.r_int!r} {m} must be < r_ext = "
                             f"{self.r_ext!r} {m}")
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
                             (pA, pB, RmA, rm, area), states, outputs, lnodes,
                             work_size.py_func(2, 5))



register(ThrustWasherContactFamily())
