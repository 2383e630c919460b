"""Engine torque from torque-speed maps (family ``engine_torque``).

An :class:`EngineTorque` drives the shaft carrying marker B about the z axis of marker A,
the mount on the body the engine is fixed to (a frame), which takes the reaction. The engine
turns at ``omega_e = ratio * omega`` [rad/s], ``omega`` the speed of B relative to A about
A's z axis and ``ratio`` the fixed gear between the engine and the shaft (1: the engine's
own crankshaft). Its torque is the map of a simple engine model (Project Chrono's
``ChEngineSimpleMap``)::

    T_e = T_0(omega_e) + u(t) (T_F(omega_e) - T_0(omega_e))        [N m]

with ``T_F`` the full-load curve, ``T_0`` the zero-throttle curve (motoring friction,
negative; 0 when not given) and ``u(t)`` the throttle (a time function, 0 to 1). The shaft
gets ``T = ratio * T_e`` about A's z axis (and the mount ``-T``). The curves are tables of
``(engine speed [rad/s], torque [N m])`` read as monotone cubic curves
(:mod:`drivedyn.elements.framework.curves`, PCHIP: no overshoot between points, the table
values at the points); outside the table the torque keeps its end value (the speed is
clamped to the table's range, as Chrono clamps it to ``[0, maximum engine speed]``).

Residual ``s g`` with ``s = -T`` and ``g`` the gradient of the relative angle (as
:class:`~drivedyn.elements.springs.TorsionalSpringDamper`'s, whose kinematics it shares);
stiffness ``s H + c g (H^T v)^T`` and damping ``c g g^T`` with
``c = ds/domega = -ratio^2 dT_e/domega_e``. The power ``T omega`` [W] counts as work
supplied in the energy balance.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
import drivedyn.units as U  # noqa: N812
from drivedyn.elements.framework.building import make_group, node_dofs, two_markers, what_of
from drivedyn.elements.framework.checks import check_param
from drivedyn.elements.framework.contract import LOCAL_SIZE_12, local_arrays_at
from drivedyn.elements.framework.curves import curve_value, pack_curves
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.primitives import prim_angle, scalar_force
from drivedyn.elements.framework.registry import Family, TwoMarkerSpec, register
from drivedyn.elements.framework.work_arrays import carve
from drivedyn.elements.nonlinear_springs import CurveTable, coerce_tables, table_arrays
from drivedyn.errors import ModelError

_DIMS = (U.ANGULAR_VELOCITY, U.TORQUE)
_COLUMNS = "[engine speed rad/s, torque N m]"


@njit(cache=True, inline="always")
def clamped_curve(X, Y, D, start, k, q):
    """Value and derivative of packed curve ``k`` at ``q`` clamped to the table's range:
    the end value and slope 0 outside it; (0, 0) for ``k < 0`` (no curve)."""
    if k < 0:
        return 0.0, 0.0
    i0 = start[k]
    i1 = start[k + 1] - 1
    if q <= X[i0]:
        return Y[i0], 0.0
    if q >= X[i1]:
        return Y[i1], 0.0
    return curve_value(X, Y, D, start, k, q)


#: entries of an engine group's work buffer (its ``work`` parameter)
WORK_SIZE = LOCAL_SIZE_12 + sc.GRAD_HESS_SIZE_12 + sc.ANGLE_WORK_SIZE + 24 + sc.WORKSPACE_SIZE


@njit(cache=True)
def engine_kernel(
    ratio, RmA, RmB, cid, tfid, X, Y, D, start, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    buf = sc.work_buffer(work, WORK_SIZE)
    o = LOCAL_SIZE_12
    g, H = sc.grad_hess_at(buf, o, 12)
    o += sc.GRAD_HESS_SIZE_12
    aw = sc.angle_work_at(buf, o)
    o += sc.ANGLE_WORK_SIZE
    W = (local_arrays_at(buf, 0, 12, 0), g, H, aw, carve(buf, o, 12), carve(buf, o + 12, 12),
         sc.workspace_at(buf, o + 24))
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    L, g, H, (w1, w2, w3, w4), vl, Hv, (ws, wv) = W
    full = sc.full_pass(want, mode)
    rq, _, _, Cd, K, _ = L
    for e in range(sc.count(C)):
        nA, nB = sc.pair(C, e)
        prim_angle(R[nA], R[nB], RmA[e, :, 0], RmA[e, :, 1], RmB[e, :, 0], g, H, full,
                   w1, w2, w3, w4, ws, wv)
        sc.velocities(C, e, 12, vl)
        om = 0.0
        for a in range(12):
            om += g[a] * vl[a]
        n = ratio[e]
        we = n * om
        u = tfv[tfid[e], 0]
        tf, dtf = clamped_curve(X, Y, D, start, cid[e, 0], we)
        t0, dt0 = clamped_curve(X, Y, D, start, cid[e, 1], we)
        te = t0 + u * (tf - t0)
        T = n * te
        s = -T
        c = -n * n * (dt0 + u * (dtf - dt0))
        scalar_force(s, 0.0, c, g, H, vl, Hv, rq, K, Cd, full)
        sc.scatter(C, L, e, 2, full)
        sc.energy(C, e, 0.0, 0.0, T * om, 0.0)
        sc.report(C, e, (T, we, te, u, T * om))


@dataclass(frozen=True)
class EngineTorque(TwoMarkerSpec):
    """Engine torque from a full-load and a zero-throttle curve, scaled by a throttle.

    Attributes:
        name: unique element name.
        marker_a: the engine's mount on the body it is fixed to (a frame, or the ground):
            its z axis is the shaft's axis; the reaction torque acts on its body.
        marker_b: on the driven shaft, its z axis (nearly) along A's (a hinge keeps it so).
        full_load: table ``((engine speed [rad/s], torque [N m]), ...)`` at full throttle:
            speeds >= 0 and strictly increasing, at least two points.
        zero_throttle: the same at zero throttle (the engine's friction, usually negative);
            None: no torque at zero throttle.
        throttle_function: the throttle ``u(t)`` (number, TimeFunction or dict), 0 to 1.
        ratio: gear ratio [1] > 0, engine speed over the shaft's speed relative to A; the
            shaft's torque is ``ratio`` times the engine's.
    """

    full_load: CurveTable = ()
    zero_throttle: CurveTable | None = None
    throttle_function: Any = 1.0
    ratio: float = 1.0
    family: ClassVar[str] = "engine_torque"
    units: ClassVar[dict[str, str]] = {"ratio": "1"}

    def __post_init__(self) -> None:
        coerce_tables(self, {"full_load": _DIMS, "zero_throttle": _DIMS})

    def tables(self) -> tuple[tuple[np.ndarray, np.ndarray],
                              tuple[np.ndarray, np.ndarray] | None]:
        """The checked (speeds, torques) of the full-load and zero-throttle curves (None
        where not given)."""
        out = []
        for key in ("full_load", "zero_throttle"):
            if getattr(self, key) is None:
                out.append(None)
                continue
            xa, ya = table_arrays(self, key, _DIMS, _COLUMNS, monotone=False,
                                  xname="engine speeds")
            if xa[0] < 0.0:
                raise ModelError(f"{what_of(self)}.{key}: engine speeds must be >= 0 rad/s, "
                                 f"got {float(xa[0])!r}")
            out.append((xa, ya))
        return out[0], out[1]

    def validate(self) -> None:
        check_param(self, "ratio", 0.0, strict=True)
        self.tables()

    def torque(self, engine_speed: float, throttle: float) -> float:
        """The engine's torque [N m] at ``engine_speed`` [rad/s] and ``throttle`` (what the
        kernel computes, for checks and reports)."""
        full, zero = self.tables()
        X, Y, D, start = pack_curves([t for t in (full, zero) if t is not None])
        tf, _ = clamped_curve.py_func(X, Y, D, start, 0, float(engine_speed))
        t0, _ = clamped_curve.py_func(X, Y, D, start, 1 if zero else -1, float(engine_speed))
        return t0 + throttle * (tf - t0)


class EngineFamily(Family):
    name = "engine_torque"

    def build(self, specs, ctx) -> Group:
        _, _, RmA, RmB, lnodes = two_markers(specs, ctx, "an engine torque")
        tables, cid = [], np.full((len(specs), 2), -1, np.int64)
        for e, s in enumerate(specs):
            for j, tab in enumerate(s.tables()):
                if tab is not None:
                    cid[e, j] = len(tables)
                    tables.append(tab)
        X, Y, D, start = pack_curves(tables)
        tfid = np.array([ctx.time_function(s.throttle_function) for s in specs], np.int64)
        ratio = np.array([s.ratio for s in specs], float)
        return make_group(
            self.name, specs, engine_kernel,
            (ratio, RmA, RmB, cid, tfid, X, Y, D, start, np.zeros(WORK_SIZE)), lnodes,
            node_dofs(ctx, lnodes),
            (("torque", "N m", "torque on the shaft (marker B) about marker A's z axis"),
             ("engine_speed", "rad/s", "engine speed: ratio x the shaft's relative speed"),
             ("engine_torque", "N m", "engine torque from the maps (before the ratio)"),
             ("throttle", "1", "throttle"),
             ("power", "W", "power supplied to the shaft")),
        )


register(EngineFamily())
