"""Point or sphere on a plane: the force-type contact of family ``plane_contact``.

:class:`PlaneContact`: a point (or sphere of radius ``radius``) at the origin of marker B
against the plane through the origin of marker A with normal ``n = z_A`` (B on the +z side).
``delta = radius - (x_B - x_A) . n``. Friction on the sliding velocity of the contact point
``x_B - radius n``: ``s = (v_B(x_c) - v_A(x_c))`` projected on the plane, force
``mu_R(|s|) F s/|s|`` opposing it (a sphere that rolls without slipping feels none).

Formulation, state and laws: :mod:`drivedyn.elements.contact`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.contact.common import (
    CONTACT_POWER,
    MU_R,
    add_normal,
    axial_motion,
    axis_distance,
    check_laws,
    coerce_laws,
    contact_group,
    contact_normal,
    friction_ratio,
    has_friction,
    omega_projection,
    transpose_times,
    work_offsets,
    work_size,
)
from drivedyn.elements.contact.friction import FrictionLaw
from drivedyn.elements.contact.impact_laws import NormalLaw, impact_state, initial_state
from drivedyn.elements.framework.building import two_markers, what_of
from drivedyn.elements.framework.checks import check_param
from drivedyn.elements.framework.contract import local_arrays_at
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.primitives import add_scaled, prim_axial
from drivedyn.elements.framework.registry import Family, TwoMarkerSpec, register
from drivedyn.elements.framework.work_arrays import carve


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
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    (L, (gn, Hn), (J1, dJ1), (J2, dJ2), (Go, Do), vl, Hv, S1, S2, (dFq, dFv), (df1q, df2q),
     (ws, wv), M3) = W
    full = sc.full_pass(want, mode)
    rq, _, _, Cd, K, _ = L
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
        check_param(self, "radius", 0.0)
        check_laws(self, what)



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
                             (pA, pB, RmA, radius), states, outputs, lnodes,
                             work_size.py_func(4, 8))



register(PlaneContactFamily())
