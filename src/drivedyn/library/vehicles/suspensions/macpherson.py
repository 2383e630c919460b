"""A MacPherson strut corner built from rigid links, joints and bushings.

Bodies: the lower control arm, the upright (knuckle) with the damper tube, the strut rod
(the damper's piston rod, sliding in the tube) and the tie rod, each placed at its centre of
mass with its principal axes (the arm: x along its pivot axis, z normal to the plane of its
pickups and ball joint; the upright: the vehicle's axes; the strut and the tie rod: z along
them). The spindle is not built: the vehicle's wheel, hinged to the ``hub`` marker, carries
it. The strut axis is the line from ``strut_lower`` (the lower spring seat on the tube) to
``strut_top`` (the top mount); the steering (kingpin) axis is the line from the lower ball
joint to the top mount.

Connections (the template of Chrono's ``ChMacPhersonStrut``):

* the lower arm to the chassis by two :class:`~drivedyn.elements.Bushing` s, one at each
  pickup (frame on the chassis, z along the pivot axis); with ``rigid_bushings`` (or an arm
  without bushing rates) by one :class:`~drivedyn.elements.Hinge` on the pivot axis;
* the lower arm to the upright by a :class:`~drivedyn.elements.Spherical` ball joint;
* the strut rod in the upright's damper tube by a :class:`~drivedyn.elements.Cylindrical`
  joint on the strut axis at ``strut_lower``: the rod slides and the upright turns about it
  (the steering), while the strut takes the wheel's side and fore-aft loads in bending;
* the strut's top on the chassis at ``strut_top`` by a :class:`~drivedyn.elements.Universal`
  joint (both tilts free, the rod's spin about its axis held), or by the ``top_mount``
  :class:`~drivedyn.elements.Bushing` (frame z along the strut axis; its rate about z holds
  the rod's spin);
* the tie rod (the rear's toe link) as in the double wishbone: a ball joint at the upright,
  a universal joint whose two axes are across the rod at the rack (the chassis at the rear);
* the coil spring and the damper (:class:`~drivedyn.elements.NonlinearSpringDamper`) from
  the chassis at ``strut_top`` to the upright at ``strut_lower``, along the strut axis (the
  load goes into the body beside the top mount, as in Chrono), with bump and rebound
  :class:`~drivedyn.elements.BumpStop` s on that line.

With rigid pivots the corner is one mechanism of one degree of freedom (the wheel travel)
for a held rack: 4 bodies, 24 coordinates, 23 independent constraint rows (a hinge 5, two
ball joints 3 + 3, the cylindrical joint 4, two universal joints 4 + 4); no redundant row.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from drivedyn.elements import (
    BumpStop,
    Bushing,
    Cylindrical,
    Hinge,
    NonlinearSpringDamper,
    Spherical,
    Universal,
)
from drivedyn.elements.framework.visuals import coil, cylinder, link, sphere
from drivedyn.errors import ModelError
from drivedyn.library.vehicles.suspensions.double_wishbone import (
    add_link_body,
    add_tie_rod_and_hub,
    stop_gaps,
)
from drivedyn.library.vehicles.suspensions.geometry import (
    MIN_LINK,
    Mount,
    arm_frame,
    chassis_marker,
    frame,
    marker_at,
    on_side,
    rod_frame,
    side_sign,
    unit,
)
from drivedyn.library.vehicles.suspensions.schema import Link, MacPhersonFile
from drivedyn.model.spec import Spec

#: hardpoints of a corner, in the order of :class:`MacPhersonHardpoints`
HARDPOINTS = ("lower_arm_front", "lower_arm_rear", "lower_ball_joint", "strut_top",
              "strut_lower", "tie_rod_inner", "tie_rod_outer", "wheel_center")


@dataclass
class MacPhersonCorner:
    """Names and positions of a built MacPherson corner.

    Attributes:
        prefix: the corner's name prefix (every body, marker and element name starts with it).
        side: ``"left"`` or ``"right"``.
        upright: the upright body (with the damper tube).
        hub: marker on the upright at the wheel centre, z along the spin axis pointing to the
            vehicle's left on both sides (the wheel's hinge goes there).
        wheel_center: (3,) wheel centre [m], global, design position.
        lower_arm, strut, tie_rod: the link bodies (``strut``: the strut rod).
        spring, damper: the coil spring's and the damper's elements.
        bump_stop, rebound_stop: the stops' elements (None without stops).
        joints: role -> joint element (``lower_pivot`` with a rigid pivot, ``strut_top`` with
            a rigid top mount, ``lower_ball_joint``, ``strut_slide`` (the cylindrical joint),
            ``tie_rod_outer``, ``tie_rod_inner``).
        bushings: the pickup bushings' and the top mount's elements (empty when rigid).
        points: hardpoint name -> (3,) global position [m] of this corner.
        spring_markers: (chassis, upright) markers of the spring's line.
        upper_arm: None (a MacPherson corner has no upper arm; the attribute lets code that
            reads either kind of corner ask).
    """

    prefix: str
    side: str
    upright: str
    hub: str
    wheel_center: np.ndarray
    lower_arm: str
    strut: str
    tie_rod: str
    spring: str
    damper: str
    bump_stop: str | None
    rebound_stop: str | None
    joints: dict[str, str] = field(default_factory=dict)
    bushings: tuple[str, ...] = ()
    points: dict[str, np.ndarray] = field(default_factory=dict)
    spring_markers: tuple[str, str] = ("", "")
    upper_arm: None = None


def check_geometry(p: MacPhersonFile) -> None:
    """Refuse hardpoints that cannot form the linkage: links of zero length (the arm's pivot
    axis, the strut, the tie rod), an arm without lever, a strut top that is not above the
    ball joint and the lower spring seat, a tie-rod joint on the steering axis (the upright
    would turn freely about it), a wheel centre that is not outboard of the steering axis.
    Messages name the keys and their values."""
    h = {n: p.point(n) for n in HARDPOINTS}

    def given(key: str) -> list[float]:
        return [float(f"{v:.6g}") for v in getattr(p.hardpoints, key)]

    def length(a: str, b: str, what: str) -> None:
        d = float(np.linalg.norm(h[a] - h[b]))
        if d < MIN_LINK:
            raise ModelError(f"hardpoints.{a} = {given(a)} m and hardpoints.{b} = "
                             f"{given(b)} m: {what} of length {d:.6g} m (below "
                             f"{MIN_LINK:g} m)")

    length("lower_arm_front", "lower_arm_rear", "lower arm pivot axis")
    length("lower_arm_front", "lower_ball_joint", "lower arm (front pickup to ball joint)")
    length("lower_arm_rear", "lower_ball_joint", "lower arm (rear pickup to ball joint)")
    length("strut_lower", "strut_top", "strut")
    length("tie_rod_inner", "tie_rod_outer", "tie rod")
    arm_frame(h["lower_arm_front"], h["lower_arm_rear"], h["lower_ball_joint"],
              f"hardpoints.lower_ball_joint = {given('lower_ball_joint')} m")
    for below, what in (("lower_ball_joint", "the ball joint"),
                        ("strut_lower", "the strut's lower seat")):
        rise = float(h["strut_top"][2] - h[below][2])
        if rise < MIN_LINK:
            raise ModelError(f"hardpoints.strut_top = {given('strut_top')} m is not above "
                             f"hardpoints.{below} = {given(below)} m ({what}; height "
                             f"difference {rise:.6g} m, at least {MIN_LINK:g} m): the strut "
                             "stands on the upright with its top mount above")
    kp = unit(h["strut_top"] - h["lower_ball_joint"], "steering axis")
    r = h["tie_rod_outer"] - h["lower_ball_joint"]
    lever = float(np.linalg.norm(r - (r @ kp) * kp))
    if lever < MIN_LINK:
        raise ModelError(f"hardpoints.tie_rod_outer = {given('tie_rod_outer')} m: on the "
                         f"steering axis (lower_ball_joint to strut_top; steering lever "
                         f"{lever:.3g} m): the upright would turn freely about it")
    c = h["wheel_center"] - h["lower_ball_joint"]
    outboard = float((c - (c @ kp) * kp)[1])  # the left corner: outboard is +y
    if outboard < MIN_LINK:
        where = "inboard of" if outboard < 0.0 else "outboard of"
        raise ModelError(f"hardpoints.wheel_center = {given('wheel_center')} m: "
                         f"{abs(outboard):.3g} m {where} the steering axis (lower_ball_joint "
                         "to strut_top): the wheel is not on a hub (the hub is on the "
                         f"upright's outer side, at least {MIN_LINK:g} m outboard of the axis)")


def add_macpherson(sp: Spec, prefix: str, side: Literal["left", "right"], p: MacPhersonFile,
                   mount: Mount, steer: str | None = None,
                   rigid_bushings: bool = False) -> MacPhersonCorner:
    """Build one corner of the MacPherson strut suspension ``p`` into ``sp``.

    Args:
        sp: the model being built; the chassis is already in it.
        prefix: names of the corner's bodies, markers and elements start with it (one per
            corner, e.g. ``"fl"``).
        side: ``"left"`` (the file's points) or ``"right"`` (mirrored, ``y -> -y``).
        p: the suspension.
        mount: ``mount(name, point)`` creates a marker on the chassis at the global
            ``point`` [m] (3,) and returns its name.
        steer: marker on the rack for the tie rod's inner joint, at this corner's
            ``tie_rod_inner``; None: the tie rod (a toe link) mounts on the chassis.
        rigid_bushings: hinge the lower arm to the chassis on its pivot axis and hold the
            strut top by a universal joint instead of the bushings (exact kinematics).

    Returns:
        the :class:`MacPhersonCorner`.

    Raises:
        ModelError: a degenerate geometry, a rack joint away from the tie rod's hardpoint, a
            spring's design length outside its stops (the message names the key and value).
    """
    side_sign(side, f"MacPherson strut {prefix!r}")
    check_geometry(p)
    pts = {n: on_side(p.point(n), side) for n in HARDPOINTS}
    left = {n: p.point(n) for n in HARDPOINTS}

    def com_of(link_: Link, *ends: str) -> np.ndarray:
        if link_.com is not None:
            return on_side(np.asarray(p.location) + np.asarray(link_.com), side)
        return np.mean([pts[e] for e in ends], axis=0)

    def name(part: str) -> str:
        return f"{prefix}_{part}"

    # -- bodies ------------------------------------------------------------------------------
    keys = ("lower_arm_front", "lower_arm_rear", "lower_ball_joint")
    R_arm = arm_frame(*(pts[k] for k in keys), f"{prefix} lower arm")
    R_arm_left = arm_frame(*(left[k] for k in keys), f"{prefix} lower arm")
    arm = add_link_body(sp, name("lower_arm"), p.lower_arm, com_of(p.lower_arm, *keys),
                        R_arm, R_arm_left, side)
    upright = add_link_body(sp, name("upright"), p.upright,
                            com_of(p.upright, "lower_ball_joint", "strut_lower"), np.eye(3),
                            np.eye(3), side)
    R_s = rod_frame(pts["strut_lower"], pts["strut_top"], f"{prefix} strut")
    R_s_left = rod_frame(left["strut_lower"], left["strut_top"], f"{prefix} strut")
    strut = add_link_body(sp, name("strut"), p.strut,
                          com_of(p.strut, "strut_lower", "strut_top"), R_s, R_s_left, side)
    R_tr = rod_frame(pts["tie_rod_inner"], pts["tie_rod_outer"], f"{prefix} tie rod")
    R_tr_left = rod_frame(left["tie_rod_inner"], left["tie_rod_outer"], f"{prefix} tie rod")
    tie_rod = add_link_body(sp, name("tie_rod"), p.tie_rod,
                            com_of(p.tie_rod, "tie_rod_inner", "tie_rod_outer"), R_tr,
                            R_tr_left, side)

    def on(body: str, part: str, point: str, R: np.ndarray | None = None) -> str:
        return marker_at(sp, name(part), body, pts[point], R)

    joints: dict[str, str] = {}
    bushings: list[str] = []
    # -- lower arm to chassis ------------------------------------------------------------------
    front, rear = pts["lower_arm_front"], pts["lower_arm_rear"]
    R_piv = frame(np.array([0.0, 0.0, 1.0]), unit(front - rear, f"{prefix} lower pivot"))
    if rigid_bushings or p.lower_arm.bushing is None:
        c = chassis_marker(sp, mount, name("lower_arm_front"), front, R_piv)
        a = on(arm, "lower_arm_pivot", "lower_arm_front", R_piv)
        joints["lower_pivot"] = sp.add(Hinge(name("lower_pivot"), c, a)).name
    else:
        b = p.lower_arm.bushing
        for end in ("front", "rear"):
            key = f"lower_arm_{end}"
            c = chassis_marker(sp, mount, name(key), pts[key], R_piv)
            a = on(arm, f"{key}_pickup", key)
            bushings.append(sp.add(Bushing(
                name(f"{key}_bushing"), c, a, stiffness=b.stiffness, damping=b.damping,
                rotational_stiffness=b.rotational_stiffness,
                rotational_damping=b.rotational_damping)).name)
    # -- ball joint ----------------------------------------------------------------------------
    a = on(arm, "lower_arm_ball", "lower_ball_joint")
    u = on(upright, "upright_lower_ball", "lower_ball_joint")
    joints["lower_ball_joint"] = sp.add(Spherical(name("lower_ball_joint"), a, u)).name
    # -- strut: the rod in the upright's tube, its top on the chassis ----------------------------
    tube = on(upright, "upright_strut", "strut_lower", R_s)
    rod = on(strut, "strut_slide", "strut_lower", R_s)
    joints["strut_slide"] = sp.add(Cylindrical(name("strut_slide"), tube, rod)).name
    top = chassis_marker(sp, mount, name("strut_top"), pts["strut_top"], R_s)
    rod_top = on(strut, "strut_top_mount", "strut_top", R_s)
    tm = p.top_mount
    if rigid_bushings or tm is None:
        joints["strut_top"] = sp.add(Universal(name("strut_top"), top, rod_top)).name
    else:
        bushings.append(sp.add(Bushing(
            name("top_mount"), top, rod_top, stiffness=tm.stiffness, damping=tm.damping,
            rotational_stiffness=tm.rotational_stiffness,
            rotational_damping=tm.rotational_damping)).name)
    # -- tie rod and hub -------------------------------------------------------------------------
    hub = add_tie_rod_and_hub(sp, prefix, "MacPherson strut", side, p, pts, upright, tie_rod,
                              R_tr, mount, steer, joints)
    # -- spring, damper and stops on the strut axis ----------------------------------------------
    spring_kw: dict[str, Any] = ({"spring_curve": p.spring.curve} if p.spring.curve is not None
                                 else {"stiffness": p.spring.rate})
    spring = sp.add(NonlinearSpringDamper(name("spring"), top, tube,
                                          free_length=p.spring.free_length, **spring_kw)).name
    damper = sp.add(NonlinearSpringDamper(
        name("damper"), top, tube, damper_curve_rebound=p.damper.table("rebound"),
        damper_curve_compression=p.damper.table("compression"))).name
    bump = rebound = None
    if p.stops is not None:
        g_bump, g_reb = stop_gaps(p.stops, float(np.linalg.norm(pts["strut_top"]
                                                                - pts["strut_lower"])))
        bump = sp.add(BumpStop(name("bump_stop"), top, tube, p.stops.bump_curve, g_bump,
                               transition=p.stops.transition)).name
        rebound = sp.add(BumpStop(name("rebound_stop"), top, tube, p.stops.rebound_curve,
                                  g_reb, transition=p.stops.transition,
                                  side="extension")).name
    # -- shapes for the viewer -------------------------------------------------------------------
    for end in ("front", "rear"):
        m = on(arm, f"lower_arm_{end}_end", f"lower_arm_{end}")
        sp.add_visual(link(m, name("lower_arm_ball"), 0.015, role="part",
                           label=name("lower_arm")))
    sp.add_visual(link(name("upright_lower_ball"), tube, 0.025, role="part", label=upright))
    sp.add_visual(link(name("upright_tie_rod"), name("upright_lower_ball"), 0.015,
                       role="part", label=upright))
    sp.add_visual(link(name("hub"), name("upright_lower_ball"), 0.02, role="part",
                       label=upright))
    sp.add_visual(cylinder(hub, 0.06, 0.04, role="part", label=name("hub")))
    sp.add_visual(link(rod, rod_top, 0.012, role="part", label=strut))
    sp.add_visual(link(tube, rod_top, 0.025, role="part", label=upright, fraction=0.5))
    sp.add_visual(coil(top, tube, 0.07, label=spring))
    sp.add_visual(link(name("tie_rod_in"), name("tie_rod_out"), 0.012, role="part",
                       label=tie_rod))
    sp.add_visual(sphere(name("upright_lower_ball"), 0.02, role="joint",
                         label=name("lower_ball_joint")))
    return MacPhersonCorner(
        prefix=prefix, side=side, upright=upright, hub=hub, wheel_center=pts["wheel_center"],
        lower_arm=arm, strut=strut, tie_rod=tie_rod, spring=spring, damper=damper,
        bump_stop=bump, rebound_stop=rebound, joints=joints, bushings=tuple(bushings),
        points=pts, spring_markers=(top, tube))
