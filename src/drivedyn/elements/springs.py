"""Spring-dampers between two markers (families ``spring_damper``, ``torsional_spring_damper``).

* :class:`SpringDamper`: linear, point to point. Tension
  ``s = k (L - L0) + c Ldot + F0`` [N] along the line of the markers (positive pulls them
  together), potential ``k (L - L0)^2 / 2 + F0 L``, dissipation ``c Ldot^2``.
* :class:`TorsionalSpringDamper`: about the z axis of marker A, on the relative rotation
  angle ``theta`` of marker B (accumulated over revolutions). Torque
  ``s = k (theta - theta0) + c thetadot + T0`` [N m] resists the relative rotation.

Both have the residual ``s g`` with ``g`` the gradient of ``L`` or ``theta``, the stiffness
``s H + g (k g + c H^T v)^T`` and the damping ``c g g^T``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.framework.building import make_group, node_dofs, two_markers
from drivedyn.elements.framework.checks import check_param, check_param_optional
from drivedyn.elements.framework.contract import LOCAL_SIZE_12, local_arrays_at
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.primitives import (
    prim_angle,
    prim_distance,
    scalar_force,
    unwrap,
)
from drivedyn.elements.framework.registry import Family, TwoMarkerSpec, register
from drivedyn.elements.framework.work_arrays import carve
from drivedyn.elements.joint_rows import angle_gradient
from drivedyn.elements.joints import relative_angle

#: entries of the springs' work buffer (their last parameter, ``work``)
WORK_SIZE = LOCAL_SIZE_12 + sc.GRAD_HESS_SIZE_12 + sc.ANGLE_WORK_SIZE + 24 + sc.WORKSPACE_SIZE


@njit(cache=True)
def scalar_spring_kernel(
    angular, pA, pB, RmA, RmB, stiff, damp, ref, pre, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    buf = sc.work_buffer(work, WORK_SIZE)  # the work arrays are views of the group's buffer
    o = LOCAL_SIZE_12 + sc.GRAD_HESS_SIZE_12
    W = (local_arrays_at(buf, 0, 12, 0), sc.grad_hess_at(buf, LOCAL_SIZE_12, 12),
         sc.angle_work_at(buf, o),
         carve(buf, o + sc.ANGLE_WORK_SIZE, 12), carve(buf, o + sc.ANGLE_WORK_SIZE + 12, 12),
         sc.workspace_at(buf, o + sc.ANGLE_WORK_SIZE + 24))
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    L, (g, H), (w1, w2, w3, w4), vl, Hv, (ws, wv) = W
    full = sc.full_pass(want, mode)
    rq, _, _, Cd, K, _ = L
    for e in range(sc.count(C)):
        nA, nB = sc.pair(C, e)
        if angular and not full:
            # the same angle and gradient in scalar arithmetic (200 springs: 17 -> 11 us)
            raw = angle_gradient(R[nA], R[nB], RmA[e, :, 0], RmA[e, :, 1], RmB[e, :, 0], g)
            q = unwrap(raw, es[sc.state_offset(C, e)])
        elif angular:
            raw = prim_angle(R[nA], R[nB], RmA[e, :, 0], RmA[e, :, 1], RmB[e, :, 0],
                             g, H, full, w1, w2, w3, w4, ws, wv)
            q = unwrap(raw, es[sc.state_offset(C, e)])
        else:
            q = prim_distance(x[nA], R[nA], x[nB], R[nB], pA[e], pB[e], g, H, full, ws, wv)
        sc.velocities(C, e, 12, vl)
        qd = 0.0
        for a in range(12):
            qd += g[a] * vl[a]
        k = stiff[e]
        c = damp[e]
        dq = q - ref[e]
        s = k * dq + c * qd + pre[e]
        scalar_force(s, k, c, g, H, vl, Hv, rq, K, Cd, full)
        sc.scatter(C, L, e, 2, full)
        sc.energy(C, e, 0.0, 0.5 * k * dq * dq + pre[e] * q, 0.0, c * qd * qd)
        sc.report(C, e, (s, q, qd, c * qd * qd))


@dataclass(frozen=True)
class SpringDamper(TwoMarkerSpec):
    """Linear spring-damper between the origins of two markers.

    Attributes:
        name: unique element name.
        marker_a, marker_b: attachment markers.
        stiffness: k [N/m] >= 0.
        damping: c [N s/m] >= 0.
        free_length: L0 [m]; None = the initial distance.
        preload: F0 [N], tension at L = L0 (negative: compression).
    """

    stiffness: float = 0.0
    damping: float = 0.0
    free_length: float | None = None
    preload: float = 0.0
    family: ClassVar[str] = "spring_damper"
    units: ClassVar[dict[str, str]] = {
        "stiffness": "N/m",
        "damping": "N s/m",
        "free_length": "m",
        "preload": "N",
    }

    def validate(self) -> None:
        check_param(self, "stiffness", 0.0)
        check_param(self, "damping", 0.0)
        check_param_optional(self, "free_length", 0.0)
        check_param(self, "preload")


@dataclass(frozen=True)
class TorsionalSpringDamper(TwoMarkerSpec):
    """Torsional spring-damper on the relative rotation about the z axis of marker A.

    Attributes:
        name: unique element name.
        marker_a, marker_b: markers whose z axes are (nearly) aligned; use with a joint that
            keeps them aligned (hinge, cylindrical) or where tilts stay small.
        stiffness: k [N m/rad] >= 0.
        damping: c [N m s/rad] >= 0.
        free_angle: theta0 [rad] relative to the initial configuration.
        preload: T0 [N m], torque at theta = theta0.
    """

    stiffness: float = 0.0
    damping: float = 0.0
    free_angle: float = 0.0
    preload: float = 0.0
    family: ClassVar[str] = "torsional_spring_damper"
    units: ClassVar[dict[str, str]] = {
        "stiffness": "N m/rad",
        "damping": "N m s/rad",
        "free_angle": "rad",
        "preload": "N m",
    }

    def validate(self) -> None:
        check_param(self, "stiffness", 0.0)
        check_param(self, "damping", 0.0)
        check_param(self, "free_angle")
        check_param(self, "preload")


class SpringFamily(Family):
    """Registry entry of :class:`SpringDamper` (``angular=False``) or
    :class:`TorsionalSpringDamper`."""

    def __init__(self, name: str, angular: bool) -> None:
        self.name = name
        self.angular = angular

    def build(self, specs, ctx) -> Group:
        pA, pB, RmA, RmB, lnodes = two_markers(specs, ctx, "a spring-damper")
        nel = len(specs)
        eoff = np.zeros(nel, np.int64)
        ref = np.zeros(nel)
        for e, s in enumerate(specs):
            nA, nB = lnodes[e]
            if self.angular:
                th0 = relative_angle(ctx.R0[nA], ctx.R0[nB], RmA[e], RmB[e])
                eoff[e] = ctx.alloc_state([th0])
                ref[e] = th0 + s.free_angle
            else:
                d = (ctx.x0[nB] + ctx.R0[nB] @ pB[e]) - (ctx.x0[nA] + ctx.R0[nA] @ pA[e])
                ref[e] = float(np.linalg.norm(d)) if s.free_length is None else s.free_length
        params = (
            self.angular, pA, pB, RmA, RmB,
            np.array([s.stiffness for s in specs], float),
            np.array([s.damping for s in specs], float),
            ref,
            np.array([s.preload for s in specs], float),
            np.zeros(WORK_SIZE),
        )
        if self.angular:
            outputs = (("torque", "N m", "spring-damper torque resisting the relative rotation"),
                       ("angle", "rad", "relative rotation angle (accumulated)"),
                       ("angular_speed", "rad/s", "relative angular speed"))
        else:
            outputs = (("force", "N", "tension (positive pulls the markers together)"),
                       ("length", "m", "distance of the markers"),
                       ("length_rate", "m/s", "rate of the distance"))
        return make_group(
            self.name, specs, scalar_spring_kernel, params, lnodes, node_dofs(ctx, lnodes),
            (*outputs, ("dissipated_power", "W", "power dissipated by the damper")),
            eoff=eoff, nstate=1 if self.angular else 0,
            commit_cols=(1,) if self.angular else (),  # accumulated angle
            dissipative=True,
        )


register(SpringFamily("spring_damper", False))
register(SpringFamily("torsional_spring_damper", True))
