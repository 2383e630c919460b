"""The gear pair family: the group of all gear pairs of a model (registry ``gear_pair``)."""

from __future__ import annotations

import numpy as np

from drivedyn.elements.framework.building import make_group, node_dofs, two_markers, what_of
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.registry import Family, register
from drivedyn.elements.gears.kernel import (
    COL_PHI_A,
    COL_PHI_B,
    GEAR_AUX,
    NAUX_PUBLIC,
    WORK_SIZE,
    gear_kernel,
    parallel_gear_kernel,
)
from drivedyn.elements.gears.kinematics import KIND_PARALLEL, NS
from drivedyn.elements.gears.mesh import BUILDERS
from drivedyn.elements.gears.spec import GearPair
from drivedyn.elements.gears.stiffness import mesh_cycle_levels
from drivedyn.errors import ModelError

_CLASH = "{what}: both markers {a!r} and {b!r} are on the same body; a gear pair needs two wheels"


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


class GearPairFamily(Family):
    """Registry entry of :class:`GearPair`."""

    name = "gear_pair"
    spec_types = (GearPair,)

    def build(self, specs, ctx) -> Group:
        nel = len(specs)
        kind = np.zeros(nel, np.int64)
        pA, pB, RmA, RmB, lnodes = two_markers(specs, ctx, clash=_CLASH)
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
        onset = np.zeros(nel)
        eoff = np.zeros(nel, np.int64)
        info = []
        for e, s in enumerate(specs):
            what = what_of(s)
            nA, nB = lnodes[e]
            xA = ctx.x0[nA] + ctx.R0[nA] @ pA[e]
            xB = ctx.x0[nB] + ctx.R0[nB] @ pB[e]
            RA = ctx.R0[nA] @ RmA[e]
            RB = ctx.R0[nB] @ RmB[e]
            md = BUILDERS[s.kind](s, what, xA, RA, xB, RB)
            kind[e] = md.kind
            cof[e], crf[e], inv[e], s0[e], Wf[e], Mf[e] = md.cof, md.crf, md.inv, md.s0, md.W, md.Mf
            eoff[e] = ctx.alloc_state([md.s0[0], md.s0[1]])
            # stiffness (mean) and its variation over the mesh cycle
            km = s.stiffness if s.stiffness is not None else md.k_iso
            if km is None:  # pragma: no cover - validate() requires it
                raise ModelError(f"{what}.stiffness: required for kind {s.kind!r}")
            if not (np.isfinite(km) and km > 0.0):  # ISO 6336 outside its range
                raise ModelError(f"{what}: the mesh stiffness {float(km)!r} N/m is not a "
                                 "positive number (check the teeth, module and face width)")
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
            onset[e] = s.flank_onset
            info.append({"stiffness": float(km), "damping": float(cdamp[e]),
                         "contact_ratio": float(eps), "sliding_arm": float(md.s_eff),
                         "radius_a": float(md.radius_a), "radius_b": float(md.radius_b),
                         "base_radius_a": float(md.base_radius_a), "coef_a": float(md.cof[0]),
                         "coef_b": float(md.cof[1]), "normal_backlash": float(bn[e])})
        idx_skew = np.flatnonzero(kind != KIND_PARALLEL).astype(np.int64)
        params = (kind, pA, pB, RmA, RmB, cof, crf, inv, s0, x0, bn, kst, cdamp, terr, fric, Wf,
                  Mf, onset, np.flatnonzero(kind == KIND_PARALLEL).astype(np.int64), idx_skew,
                  np.zeros(WORK_SIZE))  # work buffer of the kernel (kernel._work)
        # without bevel or crossed pairs, the kernel without their code (compiles faster)
        kernel = gear_kernel if idx_skew.size else parallel_gear_kernel
        return make_group(
            self.name, specs, kernel, params, lnodes, node_dofs(ctx, lnodes), GEAR_AUX,
            eoff=eoff, nstate=2, commit_cols=(COL_PHI_A, COL_PHI_B),  # accumulated wheel angles
            extra={"mesh": info},
            naux=NAUX_PUBLIC + 2, dissipative=True,
        )


def mesh_info(model, name: str) -> dict:
    """Build-time data of gear pair ``name`` in a compiled model: mean stiffness [N/m],
    damping [N s/m], contact ratio, friction arm [m], operating pitch radii [m], base radius
    of A in its transverse plane [m], the coefficients c_A, c_B [m/rad] of the wheel
    rotations in the normal approach, and the normal backlash [m]."""
    gi, ei = model.group_of[name]
    return dict(model.groups[gi].extra["mesh"][ei])


register(GearPairFamily())
