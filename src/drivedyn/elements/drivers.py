"""Drivers: prescribed motion of joints as rheonomic constraints.

* :class:`JointDriver` prescribes the relative angle of a hinge, cylindrical or screw joint,
  ``theta - theta0 = f(t)`` (``quantity="angle"``), or its speed, ``theta - theta0 =
  integral_0^t f`` (``quantity="speed"``, integrated exactly so there is no drift).
* :class:`TravelDriver` prescribes the slide of a prismatic, cylindrical or screw joint along
  its axis, ``s - s0 = f(t)`` (``quantity="travel"``) or ``s - s0 = integral_0^t f``
  (``quantity="speed"``), with ``s = d . a3`` the position of marker B's origin along the
  z axis of marker A: a steering rack, a wheel-pad actuator of a suspension rig.
* :class:`SpeedDifferenceDriver` prescribes the difference of the speeds of two joints,
  ``(theta_1 - theta_1,0) - (theta_2 - theta_2,0) = integral_0^t f``: the test bench's speed
  control of one output relative to another.

The multiplier is the driving torque: the driver reports ``torque``, the torque it applies on
body B of the (first) joint about the joint axis [N m], and ``power`` = torque x prescribed
speed [W], which the energy balance counts as work supplied (a travel driver: ``force`` [N]
along the axis and ``power``). Drivers start at t = 0 from the angles (slides) the joints have
in the initial configuration.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.framework.building import make_group, what_of
from drivedyn.elements.framework.checks import check_param_optional
from drivedyn.elements.framework.contract import MODE_ACC, MODE_DYN, local_arrays_at, local_size
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.primitives import prim_angle, quad_form, unwrap
from drivedyn.elements.framework.registry import ElementSpec, Family, register
from drivedyn.elements.framework.work_arrays import carve
from drivedyn.elements.joints import (
    COL_ANGLE,
    COL_DRIVE,
    COL_POWER,
    ROW_DRIVE,
    ROW_TRAVEL,
    build_constraint_group,
    relative_angle,
)
from drivedyn.errors import ModelError

_ANGLE_JOINTS = ("hinge", "cylindrical", "screw")
_SLIDE_JOINTS = ("prismatic", "cylindrical", "screw")


def _driven_joint(ctx, joint: str, what: str, kinds: tuple[str, ...] = _ANGLE_JOINTS):
    try:
        j = ctx.spec.element(joint)
    except KeyError:
        raise ModelError(f"{what}: unknown joint {joint!r}") from None
    kind = getattr(j, "kind", "")
    if kind not in kinds:
        need = "a rotation axis" if kinds == _ANGLE_JOINTS else "a sliding axis"
        hint = ("; a prismatic joint's slide is driven by a TravelDriver"
                if kind == "prismatic" else "")
        raise ModelError(f"{what}: joint {joint!r} is a {type(j).__name__}; a driver needs a "
                         f"joint with {need} ({', '.join(kinds)}){hint}")
    return j


@dataclass(frozen=True)
class JointDriver(ElementSpec):
    """Prescribed angle [rad] or speed [rad/s] of a joint as a function of time.

    Attributes:
        name: unique element name.
        joint: name of a hinge, cylindrical or screw joint.
        function: time function (number, :class:`~drivedyn.timefunctions.TimeFunction` or
            dict) giving the angle increment [rad] or the speed [rad/s].
        quantity: ``"angle"`` or ``"speed"``.
        k, p: scaling [N m/rad] > 0 and penalty [N m/rad] >= 0 of the constraint row (a
            rotation row; None = automatic).
    """

    name: str
    joint: str
    function: Any = 0.0
    quantity: str = "speed"
    k: float | None = None
    p: float | None = None
    family: ClassVar[str] = "joint_driver"
    units: ClassVar[dict[str, str]] = {"k": "N m/rad", "p": "N m/rad"}

    def validate(self) -> None:
        if self.quantity not in ("angle", "speed"):
            raise ModelError(f"JointDriver {self.name!r}.quantity: expected 'angle' or 'speed', "
                             f"got {self.quantity!r}")
        check_param_optional(self, "k", 0.0, strict=True)
        check_param_optional(self, "p", 0.0)


@dataclass(frozen=True)
class _DriverView:
    """The markers of the driven joint seen as a one-row constraint element."""

    name: str
    marker_a: str
    marker_b: str
    k: float | None
    p: float | None

    def markers(self) -> tuple[str, str]:
        return (self.marker_a, self.marker_b)


class JointDriverFamily(Family):
    name = "joint_driver"

    def build(self, specs, ctx) -> Group:
        views, drive = [], []
        for s in specs:
            j = _driven_joint(ctx, s.joint, f"JointDriver {s.name!r}")
            views.append(_DriverView(s.name, j.marker_a, j.marker_b, s.k, s.p))
            drive.append((ctx.time_function(s.function), 0 if s.quantity == "angle" else 1))
        g = build_constraint_group(self.name, views, ctx, [((ROW_DRIVE, 0, 0),)] * len(views),
                                   [True] * len(views), drive)
        g.extra["joint"] = [s.joint for s in specs]
        # outputs: driving torque (-sigma of the drive row), angle, power
        g.aux_cols = (COL_DRIVE, COL_ANGLE, COL_POWER)
        g.aux_names = ("torque", "angle", "power")
        g.aux_units = ("N m", "rad", "W")
        g.aux_desc = ("torque applied by the driver on body B about the joint axis",
                      "accumulated joint angle", "power supplied by the driver")
        return g


@dataclass(frozen=True)
class TravelDriver(ElementSpec):
    """Prescribed slide [m] or sliding speed [m/s] of a joint along its axis (the z axis of
    its marker A) as a function of time.

    The slide is ``s = (x_mB - x_mA) . a3``, measured from its value in the initial
    configuration: ``s - s0 = f(t)`` (``quantity="travel"``) or ``s - s0 = integral_0^t f``
    (``quantity="speed"``, exact, no drift).

    Attributes:
        name: unique element name.
        joint: name of a prismatic, cylindrical or screw joint.
        function: time function (number, :class:`~drivedyn.timefunctions.TimeFunction` or
            dict) giving the travel [m] or the speed [m/s].
        quantity: ``"travel"`` or ``"speed"``.
        k, p: scaling [N/m] > 0 and penalty [N/m] >= 0 of the constraint row (a position
            row; None = automatic).
    """

    name: str
    joint: str
    function: Any = 0.0
    quantity: str = "travel"
    k: float | None = None
    p: float | None = None
    family: ClassVar[str] = "travel_driver"
    units: ClassVar[dict[str, str]] = {"k": "N/m", "p": "N/m"}

    def validate(self) -> None:
        if self.quantity not in ("travel", "speed"):
            raise ModelError(f"TravelDriver {self.name!r}.quantity: expected 'travel' or "
                             f"'speed', got {self.quantity!r}")
        check_param_optional(self, "k", 0.0, strict=True)
        check_param_optional(self, "p", 0.0)


class TravelDriverFamily(Family):
    name = "travel_driver"

    def build(self, specs, ctx) -> Group:
        views, drive = [], []
        for s in specs:
            j = _driven_joint(ctx, s.joint, f"TravelDriver {s.name!r}", _SLIDE_JOINTS)
            views.append(_DriverView(s.name, j.marker_a, j.marker_b, s.k, s.p))
            drive.append((ctx.time_function(s.function), 0 if s.quantity == "travel" else 1))
        g = build_constraint_group(self.name, views, ctx, [((ROW_TRAVEL, 2, 0),)] * len(views),
                                   [False] * len(views), drive)
        g.extra["joint"] = [s.joint for s in specs]
        # outputs: driving force (-sigma of the travel row) and power
        g.aux_cols = (COL_DRIVE, COL_POWER)
        g.aux_names = ("force", "power")
        g.aux_units = ("N", "W")
        g.aux_desc = ("force applied by the driver on body B along the joint axis",
                      "power supplied by the driver")
        return g


_L24 = local_size.py_func(24, 1)  # the plain functions: nothing compiled at import
_GH24 = sc.grad_hess_size.py_func(24)
#: entries of a speed-difference driver group's work buffer (its last parameter, ``work``)
WORK_SIZE = _L24 + 2 * sc.GRAD_HESS_SIZE_12 + sc.ANGLE_WORK_SIZE + _GH24 + 48 + sc.WORKSPACE_SIZE


@njit(cache=True)
def speed_difference_kernel(
    RmA1, RmB1, RmA2, RmB2, kk, pp, c0, tfid, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    # work arrays: views of the group's work buffer (WORK_SIZE; scaffold.work_buffer)
    buf = sc.work_buffer(work, WORK_SIZE)
    g = _L24 + 2 * sc.GRAD_HESS_SIZE_12
    a = g + sc.ANGLE_WORK_SIZE
    o = a + _GH24
    W = (local_arrays_at(buf, 0, 24, 1), sc.grad_hess_at(buf, _L24, 12),
         sc.grad_hess_at(buf, _L24 + sc.GRAD_HESS_SIZE_12, 12), sc.angle_work_at(buf, g),
         sc.grad_hess_at(buf, a, 24), carve(buf, o, 24), carve(buf, o + 24, 24),
         sc.workspace_at(buf, o + 48))
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    L, (g1, H1), (g2, H2), (w1, w2, w3, w4), (g, H), vl, al, (ws, wv) = W
    full = sc.full_pass(want, mode)
    rq, rl, _, _, K, G = L
    nd = 24
    for e in range(sc.count(C)):
        raw1 = prim_angle(R[sc.node(C, e, 0)], R[sc.node(C, e, 1)], RmA1[e, :, 0],
                          RmA1[e, :, 1], RmB1[e, :, 0], g1, H1, full, w1, w2, w3, w4, ws, wv)
        raw2 = prim_angle(R[sc.node(C, e, 2)], R[sc.node(C, e, 3)], RmA2[e, :, 0],
                          RmA2[e, :, 1], RmB2[e, :, 0], g2, H2, full, w1, w2, w3, w4, ws, wv)
        o = sc.state_offset(C, e)
        th1 = unwrap(raw1, es[o])
        th2 = unwrap(raw2, es[o + 1])
        for a in range(12):  # loops: a slice copy of -g2 would allocate per element
            g[a] = g1[a]
            g[12 + a] = -g2[a]
        if full:  # H1, H2 exist only then (MODE_ACC is a full pass)
            H[:, :] = 0.0
            for a in range(12):
                for b in range(12):
                    H[a, b] = H1[a, b]
                    H[12 + a, 12 + b] = -H2[a, b]
        f = tfid[e]
        val = th1 - th2 - c0[e] - tfv[f, 3]
        phit = -tfv[f, 0]
        phitt = -tfv[f, 1]
        k = kk[e]
        p = pp[e]
        sig = k * sc.multiplier(C, e, nd, 0) + p * val
        for a in range(nd):
            rq[a] = sig * g[a]
            G[0, a] = k * g[a]
        sc.velocities(C, e, nd, vl)
        if mode == MODE_DYN:
            rl[0] = k * val
        elif mode == MODE_ACC:
            sc.accelerations(C, e, nd, al)
            s = 0.0
            for a in range(nd):
                s += g[a] * al[a]
            rl[0] = k * (s + quad_form(H, vl) + phitt)
        else:
            s = 0.0
            for a in range(nd):
                s += g[a] * vl[a]
            rl[0] = k * (s + phit)
        if full:
            for a in range(nd):
                for b in range(nd):
                    K[a, b] = sig * H[a, b] + p * g[a] * g[b]
        sc.scatter(C, L, e, 4, full)
        sc.energy(C, e, 0.0, 0.0, sig * phit, 0.0)
        sc.report(C, e, (-sig, th1, th2, sig * phit))


@dataclass(frozen=True)
class SpeedDifferenceDriver(ElementSpec):
    """Prescribed speed difference ``omega_1 - omega_2 = f(t)`` [rad/s] of two joints.

    Attributes:
        name: unique element name.
        joint_1, joint_2: hinge, cylindrical or screw joints.
        function: time function of the speed difference [rad/s].
        k, p: scaling [N m/rad] > 0 and penalty [N m/rad] >= 0 of the constraint row (a
            rotation row; None = automatic).
    """

    name: str
    joint_1: str
    joint_2: str
    function: Any = 0.0
    k: float | None = None
    p: float | None = None
    family: ClassVar[str] = "speed_difference_driver"
    units: ClassVar[dict[str, str]] = {"k": "N m/rad", "p": "N m/rad"}

    def validate(self) -> None:
        check_param_optional(self, "k", 0.0, strict=True)
        check_param_optional(self, "p", 0.0)


class SpeedDifferenceDriverFamily(Family):
    name = "speed_difference_driver"

    def build(self, specs, ctx) -> Group:
        nel = len(specs)
        Rm = np.zeros((4, nel, 3, 3))
        kk = np.zeros(nel)
        pp = np.zeros(nel)
        c0 = np.zeros(nel)
        tfid = np.zeros(nel, np.int64)
        lnodes = np.zeros((nel, 4), np.int64)
        dofs = np.zeros((nel, 25), np.int64)
        eoff = np.zeros(nel, np.int64)
        for e, s in enumerate(specs):
            what = what_of(s)
            ths = []
            for jj, jn in enumerate((s.joint_1, s.joint_2)):
                j = _driven_joint(ctx, jn, what)
                nA, _, Rm[2 * jj, e] = ctx.marker(j.marker_a, what)
                nB, _, Rm[2 * jj + 1, e] = ctx.marker(j.marker_b, what)
                lnodes[e, 2 * jj] = nA
                lnodes[e, 2 * jj + 1] = nB
                ths.append(relative_angle(ctx.R0[nA], ctx.R0[nB], Rm[2 * jj, e],
                                          Rm[2 * jj + 1, e]))
            kk[e], pp[e] = ctx.scaling(s.k, s.p, True)
            c0[e] = ths[0] - ths[1]
            eoff[e] = ctx.alloc_state(ths)
            tfid[e] = ctx.time_function(s.function)
            m0 = ctx.alloc_mult(1, f"speed_difference_driver {s.name}", [kk[e]])
            dofs[e] = ctx.local_dofs(list(lnodes[e]), m0, 1)
        return make_group(
            self.name, specs, speed_difference_kernel,
            (Rm[0], Rm[1], Rm[2], Rm[3], kk, pp, c0, tfid, np.zeros(WORK_SIZE)), lnodes, dofs,
            (("torque", "N m", "torque applied on body B of joint 1 about its axis (minus that "
              "on joint 2)"),
             ("angle_1", "rad", "accumulated angle of joint 1"),
             ("angle_2", "rad", "accumulated angle of joint 2"),
             ("power", "W", "power supplied by the driver")),
            nmult=1, eoff=eoff, nstate=2,
            commit_cols=(1, 2),  # the two joints' accumulated angles
        )


register(JointDriverFamily())
register(TravelDriverFamily())
register(SpeedDifferenceDriverFamily())
