"""Closed-loop loads (family ``speed_controller``): a PI controller holding a speed.

A :class:`SpeedController` measures the speed ``u`` of its ``sensor`` marker's origin along
the marker's x axis (the forward speed of a vehicle: the marker on the chassis, x forward)
and applies a torque ``T`` on the body of ``marker_b`` about that marker's z axis, and
``-T`` on the body of ``marker_a`` about its own z axis (the reaction; both follow their
markers, like the engine torque and its reaction on the frame: put the two markers on the
axis of a hinge between the bodies). The control law, with the error
``e = g(t) (u_ref(t) - u)``::

    s = clip(s_n + k_i dt e, T_min, T_max)      integral term [N m]
    T = clip(k_p e + s, T_min, T_max)

``s_n`` is the integral term committed at the last accepted step (time ``t_n``,
``dt = t - t_n``: backward Euler, implicit in the step, first order in the step);
it starts at ``initial_torque``. The integral term is clipped to the torque limits (anti-
windup: it never holds more than the output can give). ``g(t)`` (``gate_function``) in
[0, 1] switches the loop: at ``g = 0`` the error is zero and the torque is held at the
integral term's last value (a driver who keeps the pedal where it is).

Derivatives (the tangents, checked by the registry tangent test): with ``d = R_S m_x`` the
sensor direction (global) and ``p`` the marker's offset on its node,
``u = d . v_S + m_x . (Omega_S x p)``, so ``du/dv_S = d``, ``du/dOmega_S = p x m_x``,
``du/dtheta_S = m_x x (R_S^T v_S)`` (right rotation perturbation);
``dT/du = -g (k_p + k_i dt)`` inside the limits (the clipped terms contribute nothing).

Outputs: ``torque`` [N m], ``speed`` [m/s] (``u``), ``reference`` [m/s], ``error`` [m/s]
(``e``), ``integral`` [N m] (``s``) and ``power`` [W], the power the torque supplies
(counted as work supplied in the energy balance).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.framework.building import make_group, what_of
from drivedyn.elements.framework.checks import check_param, check_param_optional, unit_of
from drivedyn.elements.framework.contract import local_arrays_at, local_size
from drivedyn.elements.framework.group import COMMIT_TIME, Group
from drivedyn.elements.framework.registry import ElementSpec, Family, register
from drivedyn.elements.framework.work_arrays import carve
from drivedyn.errors import ModelError

#: aux column of the integral term (committed with the time)
COL_INTEGRAL = 4


_L18 = local_size.py_func(18, 0)  # the plain function: nothing compiled at import
#: entries of a controller group's work buffer (its last parameter, ``work``)
WORK_SIZE = _L18 + 18 + 15


@njit(cache=True)
def controller_kernel(
    gains, limits, pS, RmS, RmA, RmB, tfid, gid, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    buf = sc.work_buffer(work, WORK_SIZE)  # the work arrays are views of the group's buffer
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    L, vl, wv = (local_arrays_at(buf, 0, 18, 0), carve(buf, _L18, 18),
                 carve(buf, _L18 + 18, (5, 3)))
    full = sc.full_pass(want, mode)
    rq, _, _, Cd, K, _ = L
    for e in range(sc.count(C)):
        sc.clear(L, full)
        nS = sc.node(C, e, 0)
        sc.velocities(C, e, 18, vl)
        Rs = R[nS]
        for a in range(3):
            mx = RmS[e, a, 0]
            wv[0, a] = Rs[a, 0] * RmS[e, 0, 0] + Rs[a, 1] * RmS[e, 1, 0] + Rs[a, 2] * RmS[e, 2, 0]
            wv[1, a] = mx  # sensor direction in the node frame
        d = wv[0]
        m = wv[1]
        p = pS[e]
        # p x m_x, and R_S^T v_S
        wv[2, 0] = p[1] * m[2] - p[2] * m[1]
        wv[2, 1] = p[2] * m[0] - p[0] * m[2]
        wv[2, 2] = p[0] * m[1] - p[1] * m[0]
        u = (d[0] * vl[0] + d[1] * vl[1] + d[2] * vl[2]
             + wv[2, 0] * vl[3] + wv[2, 1] * vl[4] + wv[2, 2] * vl[5])
        o = sc.state_offset(C, e)
        s_n = es[o]
        dt = t - es[o + 1]
        if not dt > 0.0:
            dt = 0.0
        g = tfv[gid[e], 0]
        ref = tfv[tfid[e], 0]
        err = g * (ref - u)
        kp = gains[e, 0]
        ki = gains[e, 1]
        lo = limits[e, 0]
        hi = limits[e, 1]
        s = s_n + ki * dt * err
        ds = ki * dt
        if s > hi:
            s = hi
            ds = 0.0
        elif s < lo:
            s = lo
            ds = 0.0
        T = kp * err + s
        dT = kp + ds
        if T > hi:
            T = hi
            dT = 0.0
        elif T < lo:
            T = lo
            dT = 0.0
        # applied torques (node frames): T zB on B, -T zA on A; rq = -applied
        for a in range(3):
            rq[9 + a] = T * RmA[e, a, 2]
            rq[15 + a] = -T * RmB[e, a, 2]
        if full:
            dTdu = -g * dT
            # R_S^T v_S, then m_x x (R_S^T v_S)
            for a in range(3):
                wv[3, a] = Rs[0, a] * vl[0] + Rs[1, a] * vl[1] + Rs[2, a] * vl[2]
            wv[4, 0] = m[1] * wv[3, 2] - m[2] * wv[3, 1]
            wv[4, 1] = m[2] * wv[3, 0] - m[0] * wv[3, 2]
            wv[4, 2] = m[0] * wv[3, 1] - m[1] * wv[3, 0]
            for k in range(3):
                for row, c in ((9 + k, RmA[e, k, 2] * dTdu), (15 + k, -RmB[e, k, 2] * dTdu)):
                    for j in range(3):
                        Cd[row, j] += c * d[j]
                        Cd[row, 3 + j] += c * wv[2, j]
                        K[row, 3 + j] += c * wv[4, j]
        power = T * (RmB[e, 0, 2] * vl[15] + RmB[e, 1, 2] * vl[16] + RmB[e, 2, 2] * vl[17]
                     - RmA[e, 0, 2] * vl[9] - RmA[e, 1, 2] * vl[10] - RmA[e, 2, 2] * vl[11])
        sc.scatter(C, L, e, 3, full)
        sc.energy(C, e, 0.0, 0.0, power, 0.0)
        sc.report(C, e, (T, u, ref, err, s, power))


@dataclass(frozen=True)
class SpeedController(ElementSpec):
    """PI control of the forward speed of ``sensor`` by a torque between the bodies of
    ``marker_a`` and ``marker_b`` (see the module docstring).

    Attributes:
        name: unique element name.
        sensor: marker whose origin's speed along its x axis is controlled (not on the
            ground).
        marker_a: the reaction's marker (``-T`` about its z axis; may be on the ground).
        marker_b: the driven marker (``T`` about its z axis; not on the ground).
        function: reference speed [m/s] (number, time function or dict).
        gain: proportional gain ``k_p`` [N m per m/s = N s] >= 0.
        integral_gain: integral gain ``k_i`` [N m per m = N] >= 0.
        torque_min, torque_max: limits of the torque and of the integral term [N m]
            (None: unbounded); ``torque_min <= torque_max``.
        initial_torque: the integral term at t = 0 [N m] (within the limits).
        gate_function: ``g(t)`` in [0, 1] multiplying the error (1: controlling; 0: the
            torque held at the integral term).
    """

    name: str
    sensor: str
    marker_a: str
    marker_b: str
    function: Any = 0.0
    gain: float = 0.0
    integral_gain: float = 0.0
    torque_min: float | None = None
    torque_max: float | None = None
    initial_torque: float = 0.0
    gate_function: Any = 1.0
    family: ClassVar[str] = "speed_controller"
    units: ClassVar[dict[str, str]] = {"gain": "N s", "integral_gain": "N",
                                       "torque_min": "N m", "torque_max": "N m",
                                       "initial_torque": "N m"}

    def markers(self) -> tuple[str, ...]:
        return (self.sensor, self.marker_a, self.marker_b)

    def limits(self) -> tuple[float, float]:
        """(lowest, highest) torque [N m], infinite where unbounded."""
        return (-math.inf if self.torque_min is None else float(self.torque_min),
                math.inf if self.torque_max is None else float(self.torque_max))

    def validate(self) -> None:
        what = what_of(self)
        check_param(self, "gain", 0.0)
        check_param(self, "integral_gain", 0.0)
        check_param_optional(self, "torque_min")
        check_param_optional(self, "torque_max")
        t0 = check_param(self, "initial_torque")
        lo, hi = self.limits()
        unit = unit_of(self, "torque_max")
        if not lo <= hi:
            raise ModelError(f"{what}.torque_max: must be >= torque_min = {lo:g} {unit}, got "
                             f"{hi!r}")
        if not lo <= t0 <= hi:
            raise ModelError(f"{what}.initial_torque: must be within [{lo:g}, {hi:g}] {unit} "
                             f"(torque_min, torque_max), got {t0!r}")


class SpeedControllerFamily(Family):
    name = "speed_controller"
    spec_types = (SpeedController,)

    def build(self, specs, ctx) -> Group:
        nel = len(specs)
        gains = np.zeros((nel, 2))
        limits = np.zeros((nel, 2))
        pS = np.zeros((nel, 3))
        Rm = np.zeros((3, nel, 3, 3))
        lnodes = np.zeros((nel, 3), np.int64)
        eoff = np.zeros(nel, np.int64)
        for e, s in enumerate(specs):
            what = what_of(s)
            for i, mk in enumerate((s.sensor, s.marker_a, s.marker_b)):
                lnodes[e, i], off, Rm[i, e] = ctx.marker(mk, what)
                if i == 0:
                    pS[e] = off
            for i, role in ((0, "sensor"), (2, "marker_b")):
                if lnodes[e, i] == ctx.nn:
                    raise ModelError(f"{what}.{role}: marker {getattr(s, role)!r} is on the "
                                     "ground; it must be on a body or node")
            gains[e] = (s.gain, s.integral_gain)
            limits[e] = s.limits()
            eoff[e] = ctx.alloc_state([s.initial_torque, 0.0])  # models start at t = 0
        tfid = np.array([ctx.time_function(s.function) for s in specs], np.int64)
        gid = np.array([ctx.time_function(s.gate_function) for s in specs], np.int64)
        dofs = np.array([ctx.local_dofs(list(ln), 0, 0) for ln in lnodes],
                        np.int64).reshape(nel, 18)
        return make_group(
            self.name, specs, controller_kernel,
            (gains, limits, pS, Rm[0], Rm[1], Rm[2], tfid, gid, np.zeros(WORK_SIZE)), lnodes,
            dofs,
            (("torque", "N m", "torque applied on the body of marker_b about its z axis"),
             ("speed", "m/s", "measured speed of the sensor along its x axis"),
             ("reference", "m/s", "reference speed"),
             ("error", "m/s", "gated speed error g (reference - speed)"),
             ("integral", "N m", "integral term of the control law"),
             ("power", "W", "power supplied by the torque")),
            eoff=eoff, nstate=2, commit_cols=(COL_INTEGRAL, COMMIT_TIME),
        )


register(SpeedControllerFamily())
