"""Joints between two markers, by the augmented Lagrangian (one family for all joint types).

Every joint is a set of scalar constraint rows ``Phi_i(q) = 0`` built from three primitives
(:mod:`drivedyn.elements.framework.primitives`) on the frames of marker A (axes ``a1, a2, a3``) and
marker B (axes ``b1, b2, b3``), with ``d = x_mB - x_mA``:

============  ==================================================  ==================
joint         rows                                                free motion
============  ==================================================  ==================
Spherical     d.a1, d.a2, d.a3                                     3 rotations
Fixed         d.e1, d.e2, d.e3, a2.b3, a3.b1, a1.b2                none
Hinge         d.a1, d.a2, d.a3, a3.b1, a3.b2                       rotation about a3
Cylindrical   d.a1, d.a2, a3.b1, a3.b2                             rotation and slide along a3
Prismatic     d.a1, d.a2, a3.b1, a3.b2, a1.b2                      slide along a3
Screw         Cylindrical + d.a3 - pitch theta / (2 pi) - c0        coupled screw motion
Universal     d.a1, d.a2, d.a3, a1.b2                              about a1 and b2
Planar        d.a3, a3.b1, a3.b2                                   slide in the a1-a2 plane,
                                                                   rotation about a3
ParallelAxes  a3.b1, a3.b2                                         3 translations,
                                                                   rotation about a3
============  ==================================================  ==================

A fixed joint writes its three position rows as the global components ``d.e1, d.e2,
d.e3`` (``e_i`` the global axes; the same constraint as ``d.a_i``, its first three
multipliers the global components of the reaction): their gradients on the translations do
not turn with marker A, so the iteration matrix of a part welded on a spinning body stays
valid over many steps (the unbalance of ``benchmarks/flexible_shaft.py`` at 300 rad/s: its
rows ``d.a_i`` turned 0.03 rad a step). The other joints keep ``d.a_i``: their axes are
where their free motions are.

The joint axis is the z axis of marker A (the markers must be assembled: B's axes as the
row list requires, e.g. b3 along a3 for a hinge). ``theta`` is the rotation of B relative to A
about a3, accumulated over revolutions (kept in the State).

Augmented Lagrangian (seeds, eqs. 2-3): each row adds ``g (k lam + p Phi)`` to the
residual and the equation ``k Phi = 0``; ``k`` (scaling) and ``p`` (penalty) are per row,
settable per joint, with automatic defaults (see :func:`drivedyn.model.compile.compile_model`).
Reactions are reported as the force and torque the joint applies on body B at marker B,
in the global frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.framework.building import make_group, two_markers, what_of
from drivedyn.elements.framework.checks import check_param, check_param_optional
from drivedyn.elements.framework.contract import (
    LOCAL_SIZE_12,
    MODE_ACC,
    MODE_DYN,
    local_arrays_at,
    local_size,
)
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.primitives import (
    add_scaled,
    cross,
    mv,
    prim_angle,
    prim_axial,
    prim_dot,
    prim_global,
    quad_form,
    unwrap,
)
from drivedyn.elements.framework.registry import Family, TwoMarkerSpec, register
from drivedyn.elements.framework.work_arrays import carve
from drivedyn.elements.joint_rows import angle_gradient, angle_only, geometric_rows
from drivedyn.elements.screw_friction import coulomb_return, helix_slide
from drivedyn.errors import ModelError

ROW_AXIAL = 0  # d . a_i
ROW_DOT = 1  # a_i . b_j
ROW_SCREW = 2  # d . a3 - pitch/(2 pi) theta - c0
ROW_DRIVE = 3  # theta - theta0 - f(t)   (or the integral of f for a speed driver)
ROW_TRAVEL = 4  # d.a3 - s0 - f(t)       (or the integral of f): a prescribed slide
ROW_GLOBAL = 5  # d . e_i (global axis i)

JOINT_OUTPUTS = (
    ("force_x", "N", "reaction force on body B, global x"),
    ("force_y", "N", "reaction force on body B, global y"),
    ("force_z", "N", "reaction force on body B, global z"),
    ("torque_x", "N m", "reaction torque on body B about marker B, global x"),
    ("torque_y", "N m", "reaction torque on body B about marker B, global y"),
    ("torque_z", "N m", "reaction torque on body B about marker B, global z"),
    ("angle", "rad", "relative rotation of B about the joint axis (accumulated)"),
    ("power", "W", "power supplied by the constraint (rheonomic rows)"),
    ("friction_force", "N", "screw friction on body B along the helix (positive: resisting "
     "B's advance along it; 0 without friction)"),
    ("friction_power", "W", "power dissipated by the screw friction"),
)
# aux columns: the public outputs above (0-7, then 10, 11), the driving force of a driver
# row (8) and the screw's slip committed at step acceptance (9)
COL_ANGLE, COL_POWER, COL_DRIVE, COL_SLIP = 6, 7, 8, 9
JOINT_AUX_COLS = (0, 1, 2, 3, 4, 5, 6, 7, 10, 11)




@njit(cache=True, inline="always")
def work_size(nm: int) -> int:
    """Entries of the work buffer of a joint group with ``nm`` constraint rows per element
    (``local_size(12, nm)`` is ``local_size(12, 0) + 13 nm``, written out so that the build
    takes ``work_size.py_func``: a compiled call from Python compiles on a first run's
    critical path, 0.3 s)."""
    return (LOCAL_SIZE_12 + 13 * nm + 3 * sc.GRAD_HESS_SIZE_12 + sc.ANGLE_WORK_SIZE + 24
            + sc.WORKSPACE_SIZE)


@njit(cache=True)
def constraint_kernel(
    rtype, ai, bj, nrow, has_angle, pA, pB, RmA, RmB, kk, pp, pitch, c0, tfid, tfmode, fmu,
    frad, fstick, work, lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    # work arrays: views of the group's work buffer (work_size; scaffold.work_buffer)
    nm = rtype.shape[1]
    o = local_size(12, nm)
    g = sc.grad_hess_size(12)
    a = o + 2 * g + sc.ANGLE_WORK_SIZE
    buf = sc.work_buffer(work, work_size(nm))
    W = (local_arrays_at(buf, 0, 12, nm), sc.grad_hess_at(buf, o, 12),
         sc.grad_hess_at(buf, o + g, 12), sc.angle_work_at(buf, o + 2 * g), carve(buf, a, 12),
         carve(buf, a + 12, 12), sc.grad_hess_at(buf, a + 24, 12),
         sc.workspace_at(buf, a + 24 + g))
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    L, (g, H), (gth, Hth), (w1, w2, w3, w4), vl, al, (gs, Hs), (ws, wv) = W
    full = sc.full_pass(want, mode)
    rq, rl, _, _, K, G = L
    for e in range(sc.count(C)):
        nA, nB = sc.pair(C, e)
        xA = x[nA]
        xB = x[nB]
        RA = R[nA]
        RB = R[nB]
        rq[:] = 0.0
        # rows beyond this element's own (a group mixes joint types) stay zero
        rl[:] = 0.0
        if full:
            K[:, :] = 0.0
            G[:, :] = 0.0
        friction = fmu[e] > 0.0
        if mode != MODE_DYN or friction:
            sc.velocities(C, e, 12, vl)
        if mode == MODE_ACC:
            sc.accelerations(C, e, 12, al)
        th = 0.0
        if has_angle[e]:
            # the angle's gradient serves a driver's or a screw's row and the matrix; a
            # hinge's angle is otherwise an output
            grad = full
            for i in range(nrow[e]):
                if rtype[e, i] == ROW_DRIVE or rtype[e, i] == ROW_SCREW:
                    grad = True
            if full:
                raw = prim_angle(RA, RB, RmA[e, :, 0], RmA[e, :, 1], RmB[e, :, 0], gth, Hth,
                                 full, w1, w2, w3, w4, ws, wv)
            elif grad:  # the same angle and gradient in scalar arithmetic (joint_rows)
                raw = angle_gradient(RA, RB, RmA[e, :, 0], RmA[e, :, 1], RmB[e, :, 0], gth)
            else:
                raw = angle_only(RA, RB, RmA[e, :, 0], RmA[e, :, 1], RmB[e, :, 0])
            th = unwrap(raw, es[sc.state_offset(C, e)])
        power = 0.0
        sig = 0.0
        slide = 0.0
        z = es[sc.state_offset(C, e) + 1]  # the screw's committed slip
        ff = 0.0
        fpow = 0.0
        kstick = 0.0
        lam_col = -1
        dlam = 0.0
        geometric = not full and mode == MODE_DYN and not friction
        for i in range(nrow[e]):
            if rtype[e, i] != ROW_AXIAL and rtype[e, i] != ROW_DOT:
                geometric = False
        if geometric:
            # the same residual in scalar arithmetic (joint_rows: 46 -> 22 us for 200 hinges)
            sig = geometric_rows(nrow[e], rtype[e], ai[e], bj[e], kk[e], pp[e], lam, dofs[e],
                                 r.shape[0] - lam.shape[0], xA, RA, xB, RB, pA[e], pB[e],
                                 RmA[e], RmB[e], rq, rl)
        for i in range(0 if geometric else nrow[e]):
            typ = rtype[e, i]
            phit = 0.0
            phitt = 0.0
            # one inlined copy of prim_axial for the axial and the screw rows (each copy is
            # typed and lowered again at first compilation)
            if typ == ROW_AXIAL or typ == ROW_SCREW or typ == ROW_TRAVEL:
                col = ai[e, i] if typ == ROW_AXIAL else 2
                val = prim_axial(xA, RA, xB, RB, pA[e], pB[e], RmA[e, :, col], g, H,
                                 full, ws, wv)
                if typ == ROW_SCREW:
                    c = pitch[e] / (2.0 * np.pi)
                    if friction:
                        slide = helix_slide(frad[e], c, th, val, gth, Hth, g, H, full, gs, Hs)
                    val -= c * th + c0[e]
                    add_scaled(-c, gth, Hth, g, H, full)
                elif typ == ROW_TRAVEL:
                    f = tfid[e]
                    if tfmode[e] == 0:
                        val -= c0[e] + tfv[f, 0]
                        phit = -tfv[f, 1]
                        phitt = -tfv[f, 2]
                    else:
                        val -= c0[e] + tfv[f, 3]
                        phit = -tfv[f, 0]
                        phitt = -tfv[f, 1]
            elif typ == ROW_GLOBAL:
                val = prim_global(xA, RA, xB, RB, pA[e], pB[e], ai[e, i], g, H, full, ws, wv)
            elif typ == ROW_DOT:
                val = prim_dot(RA, RB, RmA[e, :, ai[e, i]], RmB[e, :, bj[e, i]], g, H, full,
                               ws, wv)
            else:  # ROW_DRIVE
                f = tfid[e]
                if tfmode[e] == 0:
                    val = th - c0[e] - tfv[f, 0]
                    phit = -tfv[f, 1]
                    phitt = -tfv[f, 2]
                else:
                    val = th - c0[e] - tfv[f, 3]
                    phit = -tfv[f, 0]
                    phitt = -tfv[f, 1]
                # element loops, not ``g[:] = gth``: an array-to-array slice assignment
                # compiles numba's shape-mismatch error message (2.5 s of first compilation)
                for a in range(12):
                    g[a] = gth[a]
                if full:
                    for a in range(12):
                        for b in range(12):
                            H[a, b] = Hth[a, b]
            k = kk[e, i]
            p = pp[e, i]
            sig = k * sc.multiplier(C, e, 12, i) + p * val
            for a in range(12):
                rq[a] += sig * g[a]
            if full:
                for a in range(12):
                    G[i, a] = k * g[a]
            if mode == MODE_DYN:
                rl[i] = k * val
            elif mode == MODE_ACC:
                s = 0.0
                for a in range(12):
                    s += g[a] * al[a]
                rl[i] = k * (s + quad_form(H, vl) + phitt)
            else:
                s = 0.0
                for a in range(12):
                    s += g[a] * vl[a]
                rl[i] = k * (s + phit)
            power += sig * phit
            if full:
                for a in range(12):
                    ga = p * g[a]
                    for b in range(12):
                        K[a, b] += sig * H[a, b] + ga * g[b]
            if typ == ROW_SCREW and friction:
                ff, dfs, dfsig, z, kstick = coulomb_return(
                    fmu[e], frad[e], pitch[e] / (2.0 * np.pi), fstick[e, 0], fstick[e, 1],
                    slide, z, sig)
                rate = 0.0
                for a in range(12):
                    rq[a] += ff * gs[a]
                    rate += gs[a] * vl[a]
                if dfs == 0.0:  # slipping: the slider takes the whole rate
                    fpow = abs(ff * rate)
                if full:
                    for a in range(12):
                        ca = dfs * gs[a]
                        da = dfsig * p * gs[a]
                        for b in range(12):
                            K[a, b] += ca * gs[b] + ff * Hs[a, b] + da * g[b]
                lam_col = i
                dlam = dfsig * k
        sc.scatter(C, L, e, 2, full)
        if lam_col >= 0 and dlam != 0.0 and full and sc.wants_matrix(C) and mode == MODE_DYN:
            # d(friction)/d(lambda) of the screw row (slip, or stick with the stiffness
            # rising with the load): its multiplier column
            km = kmap[e]
            for a in range(12):
                q = km[a * (12 + rtype.shape[1]) + 12 + lam_col]
                if q >= 0:
                    data[q] += dlam * gs[a]
        # reactions on B at marker B (global frame): applied = -(residual contribution)
        for a in range(3):
            wv[0, a] = -rq[6 + a]
            wv[1, a] = -rq[9 + a]
        mv(RB, wv[1], wv[2])  # torque about the node, global
        mv(RB, pB[e], wv[3])  # arm from node to marker
        cross(wv[3], wv[0], wv[4])
        vstick = 0.5 * ff * ff / kstick if friction and kstick > 0.0 else 0.0
        sc.energy(C, e, 0.0, vstick, power, fpow)
        # the last row's force -sig: the driving torque of a driver row
        sc.report(C, e, (wv[0, 0], wv[0, 1], wv[0, 2], wv[2, 0] - wv[4, 0], wv[2, 1] - wv[4, 1],
                         wv[2, 2] - wv[4, 2], th, power, -sig, z, ff, fpow))


def _row_value(typ: int, a: int, b: int, xA, RA, xB, RB, pA, pB, RmA, RmB) -> float:
    """Plain numpy value of a geometric row (for the assembly check at build time)."""
    d = xB + RB @ pB - xA - RA @ pA
    if typ == ROW_AXIAL:
        return float(d @ (RA @ RmA[:, a]))
    if typ == ROW_GLOBAL:
        return float(d[a])
    if typ == ROW_DOT:
        return float((RA @ RmA[:, a]) @ (RB @ RmB[:, b]))
    return 0.0


def relative_angle(RA, RB, RmA, RmB) -> float:
    """Rotation angle of marker B about the z axis of marker A, in (-pi, pi] [rad]."""
    a1 = RA @ RmA[:, 0]
    a2 = RA @ RmA[:, 1]
    b1 = RB @ RmB[:, 0]
    return float(np.arctan2(b1 @ a2, b1 @ a1))


@dataclass(frozen=True)
class Joint(TwoMarkerSpec):
    """Base of all joints: between ``marker_a`` and ``marker_b``.

    Attributes:
        name: unique element name.
        marker_a: marker on the first body (its z axis is the joint axis).
        marker_b: marker on the second body.
        k: scaling factor of the augmented Lagrangian [N/m on the rows that hold a position,
            N m/rad on those that hold a rotation]; None = automatic.
        p: penalty factor [N/m or N m/rad, as k]; None = equal to k.
    """

    k: float | None = None
    p: float | None = None

    family: ClassVar[str] = "joint"
    # one k (and p) for all rows of the joint: N/m on position rows, N m/rad on rotation rows
    units: ClassVar[dict[str, str]] = {"k": "N/m or N m/rad", "p": "N/m or N m/rad"}
    kind: ClassVar[str] = ""  # joint type, e.g. "hinge"
    rows: ClassVar[tuple[tuple[int, int, int], ...]] = ()
    has_angle: ClassVar[bool] = False

    def validate(self) -> None:
        check_param_optional(self, "k", 0.0, strict=True)
        check_param_optional(self, "p", 0.0, strict=True)

    def visuals(self) -> tuple:
        """The joint frame (z = joint axis) at ``marker_a``, drawn on request; length 0 lets
        the viewer size it to the scene."""
        from drivedyn.elements.framework.visuals import axes

        return (axes(self.marker_a, 0.0, label=self.name),)


_A, _D, _S, _G = ROW_AXIAL, ROW_DOT, ROW_SCREW, ROW_GLOBAL


@dataclass(frozen=True)
class Spherical(Joint):
    """Ball joint: marker origins coincide, all rotations free."""

    kind: ClassVar[str] = "spherical"
    units: ClassVar[dict[str, str]] = {"k": "N/m", "p": "N/m"}  # position rows only
    rows: ClassVar = ((_A, 0, 0), (_A, 1, 0), (_A, 2, 0))


@dataclass(frozen=True)
class Fixed(Joint):
    """Rigid connection: marker frames coincide."""

    kind: ClassVar[str] = "fixed"
    rows: ClassVar = ((_G, 0, 0), (_G, 1, 0), (_G, 2, 0), (_D, 1, 2), (_D, 2, 0), (_D, 0, 1))


@dataclass(frozen=True)
class Hinge(Joint):
    """Revolute joint about the z axis of marker A (marker B's z along it)."""

    kind: ClassVar[str] = "hinge"
    rows: ClassVar = ((_A, 0, 0), (_A, 1, 0), (_A, 2, 0), (_D, 2, 0), (_D, 2, 1))
    has_angle: ClassVar[bool] = True


@dataclass(frozen=True)
class Cylindrical(Joint):
    """Rotation about and translation along the z axis of marker A."""

    kind: ClassVar[str] = "cylindrical"
    rows: ClassVar = ((_A, 0, 0), (_A, 1, 0), (_D, 2, 0), (_D, 2, 1))
    has_angle: ClassVar[bool] = True


@dataclass(frozen=True)
class Prismatic(Joint):
    """Translation along the z axis of marker A; no relative rotation."""

    kind: ClassVar[str] = "prismatic"
    rows: ClassVar = ((_A, 0, 0), (_A, 1, 0), (_D, 2, 0), (_D, 2, 1), (_D, 0, 1))


@dataclass(frozen=True)
class Universal(Joint):
    """Cardan joint: origins coincide; rotation axes are x of marker A and y of marker B."""

    kind: ClassVar[str] = "universal"
    rows: ClassVar = ((_A, 0, 0), (_A, 1, 0), (_A, 2, 0), (_D, 0, 1))


@dataclass(frozen=True)
class Planar(Joint):
    """Plane-on-plane: B slides in the x-y plane of marker A and turns about its z axis.

    Holds a floating gear axially and against tilting while leaving its centre free to
    move radially, e.g. a TORSEN planet in its housing pocket, where a
    :class:`~drivedyn.elements.contact.JournalContact` takes the radial load.
    """

    kind: ClassVar[str] = "planar"
    rows: ClassVar = ((_A, 2, 0), (_D, 2, 0), (_D, 2, 1))


@dataclass(frozen=True)
class ParallelAxes(Joint):
    """Keeps marker B's z axis parallel to marker A's: the three translations and the
    rotation about the axis are free, the two tilts are held.

    Holds a floating gear against tilting while its centre moves freely, e.g. a TORSEN Type B
    element gear in its pocket, where a :class:`~drivedyn.elements.contact.JournalContact`
    takes the radial load and thrust-washer contacts on its end faces the axial load.
    """

    kind: ClassVar[str] = "parallel_axes"
    units: ClassVar[dict[str, str]] = {"k": "N m/rad", "p": "N m/rad"}  # rotation rows only
    rows: ClassVar = ((_D, 2, 0), (_D, 2, 1))


@dataclass(frozen=True)
class Screw(Joint):
    """Screw: cylindrical joint whose slide is ``pitch * theta / (2 pi)`` [m]; a helical
    spline or a thread, optionally with Coulomb friction and stick on its flanks
    (:mod:`drivedyn.elements.screw_friction`).

    Attributes:
        pitch: advance per revolution [m/rev] (negative for a left-hand thread).
        friction: Coulomb coefficient mu of the flanks [-] (0: none).
        radius: pitch radius of the flanks [m] (> 0 with friction): resolves the screw's
            axial force into the flanks' normal force and the motion into the slide along
            the helix.
        stick_stiffness: stiffness of the flanks along the helix while they stick [N/m]
            (> 0 with friction), reached under load.
        stick_onset: normal force of the flanks at which their stick stiffness is half
            ``stick_stiffness`` [N]: it rises as ``N / (N + stick_onset)`` from 0 in an
            unloaded spline (0: constant; :mod:`~drivedyn.elements.screw_friction`).
    """

    pitch: float = 0.0
    friction: float = 0.0
    radius: float = 0.0
    stick_stiffness: float = 0.0
    stick_onset: float = 0.0
    kind: ClassVar[str] = "screw"
    units: ClassVar[dict[str, str]] = {**Joint.units, "pitch": "m", "friction": "1",
                                       "radius": "m", "stick_stiffness": "N/m",
                                       "stick_onset": "N"}
    rows: ClassVar = ((_A, 0, 0), (_A, 1, 0), (_D, 2, 0), (_D, 2, 1), (_S, 2, 0))
    has_angle: ClassVar[bool] = True

    def validate(self) -> None:
        super().validate()
        check_param(self, "pitch")
        if check_param(self, "friction", 0.0) > 0.0:
            check_param(self, "radius", 0.0, strict=True)
            check_param(self, "stick_stiffness", 0.0, strict=True)
            check_param(self, "stick_onset", 0.0)


def build_constraint_group(family: str, specs, ctx, rows_of, angle_of,
                           drive: list[tuple[int, int]] | None = None) -> Group:
    """Arrays and index maps of a group of two-marker constraint elements.

    Per element: ``rows_of`` its ``(type, i, j)`` row triples (a group may mix joint
    types), ``angle_of`` whether it measures the relative angle, and ``drive`` (time-function
    id, mode) for ``ROW_DRIVE`` and ``ROW_TRAVEL`` rows. Elements with fewer rows than the
    longest have their remaining rows and multiplier dofs unused (zero and -1).
    """
    nel = len(specs)
    nr = max(len(r) for r in rows_of)
    pA, pB, RmA, RmB, lnodes = two_markers(specs, ctx, "a joint")
    kk = np.zeros((nel, nr))
    pp = np.zeros((nel, nr))
    rt = np.zeros((nel, nr), np.int64)
    ai = np.zeros((nel, nr), np.int64)
    bj = np.zeros((nel, nr), np.int64)
    nrow = np.zeros(nel, np.int64)
    angle = np.zeros(nel, np.int64)
    pitch = np.zeros(nel)
    c0 = np.zeros(nel)
    # per element: mu, flank radius [m], stick stiffness [N/m] and its onset [N]
    fmu, frad, fstick = np.zeros(nel), np.ones(nel), np.zeros((nel, 2))
    fstick[:, 0] = 1.0
    dofs = np.full((nel, 12 + nr), -1, np.int64)
    eoff = np.zeros(nel, np.int64)
    tfid = np.zeros(nel, np.int64)
    tfmode = np.zeros(nel, np.int64)
    tol = ctx.spec.settings.assembly_tolerance
    for e, s in enumerate(specs):
        what = what_of(s)
        ma, mb = s.markers()[:2]
        nA, nB = lnodes[e]
        xA, RA, xB, RB = ctx.x0[nA], ctx.R0[nA], ctx.x0[nB], ctx.R0[nB]
        er = rows_of[e]
        nrow[e] = len(er)
        angle[e] = bool(angle_of[e])
        for i, (typ, a, b) in enumerate(er):
            rt[e, i], ai[e, i], bj[e, i] = typ, a, b
            rot = typ == ROW_DOT or typ == ROW_DRIVE  # a travel row holds a position
            kk[e, i], pp[e, i] = ctx.scaling(getattr(s, "k", None), getattr(s, "p", None), rot)
            if typ in (ROW_AXIAL, ROW_GLOBAL, ROW_DOT):
                val = _row_value(typ, a, b, xA, RA, xB, RB, pA[e], pB[e], RmA[e], RmB[e])
                if abs(val) > tol:
                    kind = "orientation" if typ == ROW_DOT else "position"
                    raise ModelError(
                        f"{what}: markers {ma!r} and {mb!r} are not assembled ({kind} "
                        f"constraint {i} = {val:.3g} exceeds {tol:g}); check positions and axes")
        th0 = relative_angle(RA, RB, RmA[e], RmB[e]) if angle[e] else 0.0
        # every element keeps an angle and a slip slot (the group's state layout is uniform)
        eoff[e] = ctx.alloc_state([th0, 0.0])
        if any(r[0] == ROW_SCREW for r in er):
            pitch[e] = s.pitch
            if s.friction > 0.0:
                fmu[e], frad[e] = s.friction, s.radius
                fstick[e] = s.stick_stiffness, s.stick_onset
            d = xB + RB @ pB[e] - xA - RA @ pA[e]
            c0[e] = float(d @ (RA @ RmA[e][:, 2])) - s.pitch / (2 * np.pi) * th0
        if drive is not None:
            tfid[e], tfmode[e] = drive[e]
            if any(r[0] == ROW_TRAVEL for r in er):  # the initial slide along a3
                d = xB + RB @ pB[e] - xA - RA @ pA[e]
                c0[e] = float(d @ (RA @ RmA[e][:, 2]))
            else:
                c0[e] = th0
        m0 = ctx.alloc_mult(len(er), f"{getattr(s, 'kind', family)} {s.name}",
                            list(kk[e, :len(er)]))
        dofs[e, :12 + len(er)] = ctx.local_dofs([nA, nB], m0, len(er))
    return make_group(
        family, specs, constraint_kernel,
        (rt, ai, bj, nrow, angle, pA, pB, RmA, RmB, kk, pp, pitch, c0, tfid, tfmode, fmu, frad,
         fstick, np.zeros(work_size.py_func(rt.shape[1]))),  # the kernel's work buffer
        lnodes, dofs, JOINT_OUTPUTS, nmult=nr, eoff=eoff, nstate=2,
        # the accumulated angle and the screw's slip
        commit_cols=(COL_ANGLE, COL_SLIP) if angle.any() else (), naux=12,
        aux_cols=JOINT_AUX_COLS, dissipative=bool(fmu.any()),
        extra={"kinds": [getattr(s, "kind", family) for s in specs]},
    )


JOINT_TYPES = (Spherical, Fixed, Hinge, Cylindrical, Prismatic, Universal, Planar, ParallelAxes,
               Screw)


class JointFamily(Family):
    """Registry entry of all joint types: one group, so one kernel call per evaluation
    whatever the mix of types (each call costs a few microseconds of Python and dispatch)."""

    name = "joint"

    def build(self, specs, ctx) -> Group:
        return build_constraint_group(self.name, specs, ctx, [type(s).rows for s in specs],
                                      [type(s).has_angle for s in specs])


register(JointFamily())
