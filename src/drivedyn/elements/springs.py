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

import drivedyn.elements.scaffold as sc
from drivedyn.elements.base import ElementSpec, Family, Group, local_arrays, register
from drivedyn.elements.joints import relative_angle
from drivedyn.elements.primitives import prim_angle, prim_distance, unwrap
from drivedyn.errors import ModelError


@njit(cache=True, inline="always")
def _scalar_springs(P, C, W, full):
    angular, pA, pB, RmA, RmB, stiff, damp, ref, pre = P
    L, (g, H), (w1, w2, w3, w4), vl, Hv, (ws, wv) = W
    rq, _, _, Cd, K, _ = L
    x, R, _, _, _, es, _, _ = sc.state(C)
    for e in range(sc.count(C)):
        nA, nB = sc.pair(C, e)
        if angular:
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
        for a in range(12):
            rq[a] = s * g[a]
        if full:
            for b in range(12):
                sv = 0.0
                for a in range(12):
                    sv += H[a, b] * vl[a]
                Hv[b] = sv
            for a in range(12):
                for b in range(12):
                    K[a, b] = s * H[a, b] + g[a] * (k * g[b] + c * Hv[b])
                    Cd[a, b] = c * g[a] * g[b]
        sc.scatter(C, L, e, 2, full)
        sc.energy(C, e, 0.0, 0.5 * k * dq * dq + pre[e] * q, 0.0, c * qd * qd)
        sc.report(C, e, (s, q, qd, c * qd * qd))


@njit(cache=True)
def scalar_spring_kernel(
    angular, pA, pB, RmA, RmB, stiff, damp, ref, pre,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    W = (local_arrays(12, 0), sc.grad_hess(12), sc.angle_work(), np.zeros(12), np.zeros(12),
         sc.workspace())
    sc.run(_scalar_springs, (angular, pA, pB, RmA, RmB, stiff, damp, ref, pre),
           (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
            r, rabs, data, eout, aux), W)


def _commit_angle(group: Group, state) -> None:
    state.es[group.eoff] = group.aux[:, 1]


def _check(what: str, label: str, value: float, positive: bool = False) -> float:
    try:
        val = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"{what}.{label}: expected a number, got {value!r}") from None
    if not np.isfinite(val) or val < 0 or (positive and val == 0):
        raise ModelError(f"{what}.{label}: must be {'> 0' if positive else '>= 0'}, got {value!r}")
    return val


@dataclass(frozen=True)
class SpringDamper(ElementSpec):
    """Linear spring-damper between the origins of two markers.

    Attributes:
        name: unique element name.
        marker_a, marker_b: attachment markers.
        stiffness: k [N/m] >= 0.
        damping: c [N s/m] >= 0.
        free_length: L0 [m]; None = the initial distance.
        preload: F0 [N], tension at L = L0 (negative: compression).
    """

    name: str
    marker_a: str
    marker_b: str
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

    def markers(self) -> tuple[str, ...]:
        return (self.marker_a, self.marker_b)

    def validate(self) -> None:
        what = f"SpringDamper {self.name!r}"
        _check(what, "stiffness", self.stiffness)
        _check(what, "damping", self.damping)
        if self.free_length is not None:
            _check(what, "free_length", self.free_length)


@dataclass(frozen=True)
class TorsionalSpringDamper(ElementSpec):
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

    name: str
    marker_a: str
    marker_b: str
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

    def markers(self) -> tuple[str, ...]:
        return (self.marker_a, self.marker_b)

    def validate(self) -> None:
        what = f"TorsionalSpringDamper {self.name!r}"
        _check(what, "stiffness", self.stiffness)
        _check(what, "damping", self.damping)


class _SpringFamily(Family):
    angular = False

    def build(self, specs, ctx) -> Group:
        nel = len(specs)
        pA = np.zeros((nel, 3))
        pB = np.zeros((nel, 3))
        RmA = np.zeros((nel, 3, 3))
        RmB = np.zeros((nel, 3, 3))
        lnodes = np.zeros((nel, 2), np.int64)
        dofs = np.zeros((nel, 12), np.int64)
        eoff = np.zeros(nel, np.int64)
        ref = np.zeros(nel)
        for e, s in enumerate(specs):
            what = f"{type(s).__name__} {s.name!r}"
            nA, pA[e], RmA[e] = ctx.marker(s.marker_a, what)
            nB, pB[e], RmB[e] = ctx.marker(s.marker_b, what)
            if nA == nB:
                raise ModelError(f"{what}: both markers are on the same body")
            lnodes[e] = (nA, nB)
            dofs[e] = ctx.local_dofs([nA, nB], 0, 0)
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
        )
        if self.angular:
            names = ("torque", "angle", "angular_speed", "dissipated_power")
            units = ("N m", "rad", "rad/s", "W")
            desc = ("spring-damper torque resisting the relative rotation",
                    "relative rotation angle (accumulated)", "relative angular speed",
                    "power dissipated by the damper")
        else:
            names = ("force", "length", "length_rate", "dissipated_power")
            units = ("N", "m", "m/s", "W")
            desc = ("tension (positive pulls the markers together)", "distance of the markers",
                    "rate of the distance", "power dissipated by the damper")
        return Group(
            family=self.name, names=[s.name for s in specs], kernel=scalar_spring_kernel,
            params=params, lnodes=lnodes, nmult=0, dofs=dofs, eoff=eoff,
            nstate=1 if self.angular else 0, aux_names=names, aux_units=units, aux_desc=desc,
            commit=_commit_angle if self.angular else None, dissipative=True,
        )


class SpringDamperFamily(_SpringFamily):
    name = "spring_damper"


class TorsionalSpringDamperFamily(_SpringFamily):
    name = "torsional_spring_damper"
    angular = True


register(SpringDamperFamily())
register(TorsionalSpringDamperFamily())
