"""A double-wishbone corner built from rigid links, joints and bushings.

Bodies: upper arm, lower arm, upright (knuckle) and tie rod, each placed at its centre of
mass with its principal axes (an arm: x along its pivot axis, z normal to the plane of its
pickups and ball joint; the upright: the vehicle's axes; the tie rod: z along it). The
spindle (the hub's rotating part) is not built: the vehicle's wheel, hinged to the ``hub``
marker, carries it.

Connections:

* each arm to the chassis by two :class:`~drivedyn.elements.Bushing` s, one at each pickup
  (bushing frame on the chassis, z along the pivot axis); with ``rigid_bushings`` (or an arm
  without bushing rates) by one :class:`~drivedyn.elements.Hinge` on the pivot axis;
* the arms to the upright by :class:`~drivedyn.elements.Spherical` ball joints;
* the tie rod (the rear's toe link) to the upright by a ball joint and to the rack (the
  chassis at the rear) by a :class:`~drivedyn.elements.Universal` joint whose two axes are
  across the rod: it holds the rod's spin about its own axis, the one motion two ball joints
  would leave free (a dof of no consequence but without stiffness, hence singular);
* the coil spring and the damper (:class:`~drivedyn.elements.NonlinearSpringDamper`) from
  the chassis to the arm of ``coil_over_arm``, with bump and rebound
  :class:`~drivedyn.elements.BumpStop` s on the spring's line.

With rigid pivots the corner is one mechanism of one degree of freedom (the wheel travel)
for a held rack: 4 bodies, 24 coordinates, 23 independent constraint rows (2 hinges, 3 ball
joints, 1 universal joint); no redundant row. The wheel's own spin is the vehicle's hinge.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from drivedyn.elements import (
    BumpStop,
    Bushing,
    Hinge,
    NonlinearSpringDamper,
    Spherical,
    Universal,
)
from drivedyn.elements.framework.visuals import cylinder, link, sphere
from drivedyn.errors import ModelError
from drivedyn.library.vehicles.suspensions.geometry import (
    MIN_LINK,
    MIRROR,
    Mount,
    arm_frame,
    chassis_marker,
    frame,
    marker_at,
    marker_pose,
    on_side,
    rod_frame,
    side_sign,
    spin_axis,
    unit,
)
from drivedyn.library.vehicles.suspensions.schema import DoubleWishboneFile, Link, Stops
from drivedyn.model.spec import Spec

#: hardpoints of a corner, in the order of :class:`DoubleWishboneHardpoints`
HARDPOINTS = ("upper_arm_front", "upper_arm_rear", "upper_ball_joint", "lower_arm_front",
              "lower_arm_rear", "lower_ball_joint", "tie_rod_inner", "tie_rod_outer",
              "wheel_center", "spring_chassis", "spring_arm", "damper_chassis", "damper_arm")
#: largest distance [m] between the steering's tie-rod joint and the suspension's hardpoint
ASSEMBLY_TOLERANCE = 1e-6


@dataclass
class Corner:
    """Names and positions of a built corner.

    Attributes:
        prefix: the corner's name prefix (every body, marker and element name starts with it).
        side: ``"left"`` or ``"right"``.
        upright: the upright body.
        hub: marker on the upright at the wheel centre, z along the spin axis pointing to the
            vehicle's left on both sides (the wheel's hinge goes there).
        wheel_center: (3,) wheel centre [m], global, design position.
        upper_arm, lower_arm, tie_rod: the link bodies.
        spring, damper: the coil spring's and the damper's elements.
        bump_stop, rebound_stop: the stops' elements (None without stops).
        joints: role -> joint element (``upper_pivot``, ``lower_pivot`` with rigid pivots,
            ``upper_ball_joint``, ``lower_ball_joint``, ``tie_rod_outer``, ``tie_rod_inner``).
        bushings: the pickup bushings' elements (empty with rigid pivots).
        points: hardpoint name -> (3,) global position [m] of this corner.
        spring_markers: (chassis, arm) markers of the spring's line.
    """

    prefix: str
    side: str
    upright: str
    hub: str
    wheel_center: np.ndarray
    upper_arm: str
    lower_arm: str
    tie_rod: str
    spring: str
    damper: str
    bump_stop: str | None
    rebound_stop: str | None
    joints: dict[str, str] = field(default_factory=dict)
    bushings: tuple[str, ...] = ()
    points: dict[str, np.ndarray] = field(default_factory=dict)
    spring_markers: tuple[str, str] = ("", "")


def mirrored_inertia(J: Any, R_left: np.ndarray, R_side: np.ndarray, side: str) -> np.ndarray:
    """The inertia tensor (3, 3) of a link of ``side`` in its frame ``R_side``, from the
    left link's ``J`` (principal moments or a tensor in its frame ``R_left``): the mirror
    image of the left link's mass distribution."""
    J = np.asarray(J, dtype=float)
    J = np.diag(J) if J.shape == (3,) else J
    if side == "left":
        return J
    T = R_side.T @ MIRROR @ R_left
    return T @ J @ T.T


def add_link_body(sp: Spec, name: str, link_: Link, com: np.ndarray, R: np.ndarray,
                  R_left: np.ndarray, side: str) -> str:
    """A rigid link ``name`` of mass and inertia ``link_`` (given for the left side, in the
    frame ``R_left``) at ``com`` [m] in the frame ``R`` of its ``side``."""
    return sp.add_rigid_body(name, link_.mass, mirrored_inertia(link_.inertia, R_left, R, side),
                             position=com, rotation=R)


def stop_gaps(st: Stops, length: float) -> tuple[float, float]:
    """Bump and rebound gaps [m] of the stops ``st`` from the spring's design ``length``; a
    design length outside the stops is refused naming the key and the value."""
    if not st.bump_length < length:
        raise ModelError(f"stops.bump_length: {st.bump_length:g} m is not below the spring's "
                         f"design length {length:.6g} m (the stop would be compressed in the "
                         "design position)")
    if not length < st.rebound_length:
        raise ModelError(f"stops.rebound_length: {st.rebound_length:g} m is not above the "
                         f"spring's design length {length:.6g} m")
    return length - st.bump_length, st.rebound_length - length


def check_geometry(p: DoubleWishboneFile) -> None:
    """Refuse hardpoints that cannot form the linkage: links of zero length, arms without
    lever, a knuckle whose ball joints and tie-rod joint are in line (it would turn freely
    about its kingpin axis), a wheel centre that is not outboard of the kingpin axis (the
    hub is on the upright's outer side). Messages name the keys and their values."""
    h = {n: p.point(n) for n in HARDPOINTS}

    def given(key: str) -> list[float]:
        return [float(f"{v:.6g}") for v in getattr(p.hardpoints, key)]

    def length(a: str, b: str, what: str) -> None:
        d = float(np.linalg.norm(h[a] - h[b]))
        if d < MIN_LINK:
            raise ModelError(f"hardpoints.{a} = {given(a)} m and hardpoints.{b} = "
                             f"{given(b)} m: {what} of length {d:.6g} m (below "
                             f"{MIN_LINK:g} m)")

    length("upper_arm_front", "upper_arm_rear", "upper arm pivot axis")
    length("lower_arm_front", "lower_arm_rear", "lower arm pivot axis")
    length("upper_ball_joint", "lower_ball_joint", "knuckle (ball joint to ball joint)")
    length("tie_rod_inner", "tie_rod_outer", "tie rod")
    length("spring_chassis", "spring_arm", "spring")
    length("damper_chassis", "damper_arm", "damper")
    for arm in ("upper", "lower"):
        arm_frame(h[f"{arm}_arm_front"], h[f"{arm}_arm_rear"], h[f"{arm}_ball_joint"],
                  f"hardpoints.{arm}_ball_joint = {given(f'{arm}_ball_joint')} m")
    kp = unit(h["upper_ball_joint"] - h["lower_ball_joint"], "knuckle")
    r = h["tie_rod_outer"] - h["lower_ball_joint"]
    lever = float(np.linalg.norm(r - (r @ kp) * kp))
    if lever < MIN_LINK:
        raise ModelError(f"hardpoints.tie_rod_outer = {given('tie_rod_outer')} m: on the "
                         f"kingpin axis (steering lever {lever:.3g} m): the upright would turn "
                         "freely about it")
    c = h["wheel_center"] - h["lower_ball_joint"]
    outboard = float((c - (c @ kp) * kp)[1])  # the left corner: outboard is +y
    if outboard < MIN_LINK:
        where = "inboard of" if outboard < 0.0 else "outboard of"
        raise ModelError(f"hardpoints.wheel_center = {given('wheel_center')} m: "
                         f"{abs(outboard):.3g} m {where} the kingpin axis (lower_ball_joint "
                         "to upper_ball_joint): the wheel is not on a hub (the hub is on the "
                         f"upright's outer side, at least {MIN_LINK:g} m outboard of the axis)")


def add_tie_rod_and_hub(sp: Spec, prefix: str, kind: str, side: str, p: Any,
                        pts: dict[str, np.ndarray], upright: str, tie_rod: str,
                        R_tr: np.ndarray, mount: Any, steer: str | None,
                        joints: dict[str, str]) -> str:
    """The tie rod of a corner (``kind``: its type, for messages) and the wheel's hub marker on
    the upright, the same for every corner type: a ball joint at the upright, a universal
    joint at the chassis pickup or at the rack's marker ``steer`` (which must sit at the
    inner hardpoint, within :data:`ASSEMBLY_TOLERANCE`); the hub's z axis the spin axis from
    ``p.camber`` and ``p.toe``, to the vehicle's left on both sides. ``pts``: the corner's
    hardpoints on its ``side`` [m]; ``R_tr``: the tie rod's frame; the joints' names are
    added to ``joints``. Returns the hub marker's name."""

    def name(part: str) -> str:
        return f"{prefix}_{part}"

    def on(body: str, part: str, point: str, R: np.ndarray | None = None) -> str:
        return marker_at(sp, name(part), body, pts[point], R)

    u = on(upright, "upright_tie_rod", "tie_rod_outer")
    t_out = on(tie_rod, "tie_rod_out", "tie_rod_outer")
    joints["tie_rod_outer"] = sp.add(Spherical(name("tie_rod_outer"), u, t_out)).name
    if steer is None:
        inner = chassis_marker(sp, mount, name("tie_rod_inner"), pts["tie_rod_inner"], R_tr)
    else:
        if steer not in sp.markers:
            raise ModelError(f"{kind} {prefix!r}: steer marker {steer!r} does not "
                             "exist")
        pos, _ = marker_pose(sp, steer)
        gap = float(np.linalg.norm(pos - pts["tie_rod_inner"]))
        if gap > ASSEMBLY_TOLERANCE:
            raise ModelError(f"hardpoints.tie_rod_inner = {list(p.hardpoints.tie_rod_inner)} "
                             f"m (the {side} one at {pts['tie_rod_inner'].tolist()} m in the "
                             f"vehicle frame): the rack's joint {steer!r} is at "
                             f"{pos.tolist()} m, {gap:.6g} m away: the tie rod does not "
                             "assemble")
        inner = marker_at(sp, f"{steer}_{prefix}_axis", sp.markers[steer].body,
                          pts["tie_rod_inner"], R_tr)
    t_in = on(tie_rod, "tie_rod_in", "tie_rod_inner", R_tr)
    joints["tie_rod_inner"] = sp.add(Universal(name("tie_rod_inner"), inner, t_in)).name
    # -- hub -------------------------------------------------------------------------------------
    out = spin_axis(p.camber, p.toe, side)
    axis = out if side == "left" else -out  # to the vehicle's left on both sides
    hub = on(upright, "hub", "wheel_center", frame(np.array([1.0, 0.0, 0.0]), axis))
    return hub


def add_double_wishbone(sp: Spec, prefix: str, side: Literal["left", "right"],
                        p: DoubleWishboneFile, mount: Mount, steer: str | None = None,
                        rigid_bushings: bool = False) -> Corner:
    """Build one corner of the double-wishbone suspension ``p`` into ``sp``.

    Args:
        sp: the model being built; the chassis is already in it.
        prefix: names of the corner's bodies, markers and elements start with it (one per
            corner, e.g. ``"fl"``).
        side: ``"left"`` (the file's points) or ``"right"`` (mirrored, ``y -> -y``).
        p: the suspension.
        mount: ``mount(name, point)`` creates a marker on the chassis at the global
            ``point`` [m] (3,) and returns its name (the vehicle decides whether that is a
            rigid body or a beam node); its orientation does not matter.
        steer: marker on the rack for the tie rod's inner joint, at this corner's
            ``tie_rod_inner`` (see :func:`~drivedyn.library.vehicles.suspensions.steering.
            add_rack_steering`); None: the tie rod (a toe link) mounts on the chassis.
        rigid_bushings: hinge the arms to the chassis on their pivot axes instead of the
            pickup bushings (exact kinematics).

    Returns:
        the :class:`Corner`.

    Raises:
        ModelError: a degenerate geometry, a rack joint away from the tie rod's hardpoint, a
            spring's design length outside its stops (the message names the key and value).
    """
    side_sign(side, f"double wishbone {prefix!r}")
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
    arms = {}
    for arm, link_ in (("upper", p.upper_arm), ("lower", p.lower_arm)):
        keys = (f"{arm}_arm_front", f"{arm}_arm_rear", f"{arm}_ball_joint")
        R = arm_frame(*(pts[k] for k in keys), f"{prefix} {arm} arm")
        R_left = arm_frame(*(left[k] for k in keys), f"{prefix} {arm} arm")
        arms[arm] = add_link_body(sp, name(f"{arm}_arm"), link_, com_of(link_, *keys), R,
                                  R_left, side)
    upright = add_link_body(sp, name("upright"), p.upright,
                            com_of(p.upright, "upper_ball_joint", "lower_ball_joint"),
                            np.eye(3), np.eye(3), side)
    R_tr = rod_frame(pts["tie_rod_inner"], pts["tie_rod_outer"], f"{prefix} tie rod")
    R_tr_left = rod_frame(left["tie_rod_inner"], left["tie_rod_outer"], f"{prefix} tie rod")
    tie_rod = add_link_body(sp, name("tie_rod"), p.tie_rod,
                            com_of(p.tie_rod, "tie_rod_inner", "tie_rod_outer"), R_tr,
                            R_tr_left, side)

    def on(body: str, part: str, point: str, R: np.ndarray | None = None) -> str:
        return marker_at(sp, name(part), body, pts[point], R)

    joints: dict[str, str] = {}
    bushings: list[str] = []
    # -- arms to chassis ---------------------------------------------------------------------
    for arm, link_ in (("upper", p.upper_arm), ("lower", p.lower_arm)):
        front, rear = pts[f"{arm}_arm_front"], pts[f"{arm}_arm_rear"]
        R_piv = frame(np.array([0.0, 0.0, 1.0]), unit(front - rear, f"{prefix} {arm} pivot"))
        if rigid_bushings or link_.bushing is None:
            c = chassis_marker(sp, mount, name(f"{arm}_arm_front"), front, R_piv)
            a = on(arms[arm], f"{arm}_arm_pivot", f"{arm}_arm_front", R_piv)
            joints[f"{arm}_pivot"] = sp.add(Hinge(name(f"{arm}_pivot"), c, a)).name
            continue
        b = link_.bushing
        for end in ("front", "rear"):
            key = f"{arm}_arm_{end}"
            c = chassis_marker(sp, mount, name(key), pts[key], R_piv)
            a = on(arms[arm], f"{key}_pickup", key)
            bushings.append(sp.add(Bushing(
                name(f"{key}_bushing"), c, a, stiffness=b.stiffness, damping=b.damping,
                rotational_stiffness=b.rotational_stiffness,
                rotational_damping=b.rotational_damping)).name)
    # -- ball joints ---------------------------------------------------------------------------
    for arm in ("upper", "lower"):
        key = f"{arm}_ball_joint"
        a = on(arms[arm], f"{arm}_arm_ball", key)
        u = on(upright, f"upright_{arm}_ball", key)
        joints[key] = sp.add(Spherical(name(key), a, u)).name
    # -- tie rod and hub -------------------------------------------------------------------------
    hub = add_tie_rod_and_hub(sp, prefix, "double wishbone", side, p, pts, upright, tie_rod,
                              R_tr, mount, steer, joints)
    # -- coil-over and stops ---------------------------------------------------------------------
    arm_body = arms[p.coil_over_arm]
    s_c = chassis_marker(sp, mount, name("spring_chassis"), pts["spring_chassis"])
    s_a = on(arm_body, "spring_arm", "spring_arm")
    if (np.allclose(pts["damper_chassis"], pts["spring_chassis"], atol=1e-12)
            and np.allclose(pts["damper_arm"], pts["spring_arm"], atol=1e-12)):
        d_c, d_a = s_c, s_a
    else:
        d_c = chassis_marker(sp, mount, name("damper_chassis"), pts["damper_chassis"])
        d_a = on(arm_body, "damper_arm", "damper_arm")
    spring_kw: dict[str, Any] = ({"spring_curve": p.spring.curve} if p.spring.curve is not None
                                 else {"stiffness": p.spring.rate})
    spring = sp.add(NonlinearSpringDamper(name("spring"), s_c, s_a,
                                          free_length=p.spring.free_length, **spring_kw)).name
    damper = sp.add(NonlinearSpringDamper(
        name("damper"), d_c, d_a, damper_curve_rebound=p.damper.table("rebound"),
        damper_curve_compression=p.damper.table("compression"))).name
    bump = rebound = None
    if p.stops is not None:
        g_bump, g_reb = stop_gaps(p.stops, float(np.linalg.norm(pts["spring_chassis"]
                                                                - pts["spring_arm"])))
        bump = sp.add(BumpStop(name("bump_stop"), s_c, s_a, p.stops.bump_curve, g_bump,
                               transition=p.stops.transition)).name
        rebound = sp.add(BumpStop(name("rebound_stop"), s_c, s_a, p.stops.rebound_curve,
                                  g_reb, transition=p.stops.transition,
                                  side="extension")).name
    # -- shapes for the viewer -------------------------------------------------------------------
    for arm in ("upper", "lower"):
        for end in ("front", "rear"):
            m = on(arms[arm], f"{arm}_arm_{end}_end", f"{arm}_arm_{end}")
            sp.add_visual(link(m, name(f"{arm}_arm_ball"), 0.015, role="part",
                               label=name(f"{arm}_arm")))
    sp.add_visual(link(name("upright_lower_ball"), name("upright_upper_ball"), 0.025,
                       role="part", label=upright))
    sp.add_visual(link(name("upright_tie_rod"), name("upright_lower_ball"), 0.015, role="part",
                       label=upright))
    sp.add_visual(link(name("hub"), name("upright_lower_ball"), 0.02, role="part",
                       label=upright))
    sp.add_visual(cylinder(hub, 0.06, 0.04, role="part", label=name("hub")))
    sp.add_visual(link(name("tie_rod_in"), name("tie_rod_out"), 0.012, role="part",
                       label=tie_rod))
    for key in ("upper_ball_joint", "lower_ball_joint"):
        sp.add_visual(sphere(name(f"upright_{key.split('_')[0]}_ball"), 0.02, role="joint",
                             label=name(key)))
    return Corner(
        prefix=prefix, side=side, upright=upright, hub=hub, wheel_center=pts["wheel_center"],
        upper_arm=arms["upper"], lower_arm=arms["lower"], tie_rod=tie_rod, spring=spring,
        damper=damper, bump_stop=bump, rebound_stop=rebound, joints=joints,
        bushings=tuple(bushings), points=pts, spring_markers=(s_c, s_a))
