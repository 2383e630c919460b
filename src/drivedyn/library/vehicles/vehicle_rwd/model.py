"""The rear-wheel-drive vehicle: a flexible ladder frame on four double-wishbone corners,
rack steering, Magic Formula tyres and a rear differential of any type, built from the
library's parts.

Global frame at t = 0: x forward, y left, z up, origin on the road at mid-wheelbase. The
suspensions' data (Project Chrono's HMMWV, ``load_suspensions``) are given in Chrono's
vehicle frame, whose origin lies on the centre line at mid-wheelbase in the plane of the
chassis reference; the builder lifts them so that the wheel centres sit at the loaded tyre
radius. The ladder frame's rails lie in that reference plane.

Parts and connections:

* **frame**: :func:`~drivedyn.library.vehicles.chassis.add_ladder_frame` (geometrically
  exact beams), carrying the sprung body (``[body]``: Chrono's chassis mass, centre of
  gravity and inertia) on its body mounts; the carried mass is ``body.mass`` less the
  frame's beams and the driveline parts on the frame, and its centre of gravity is set so
  that the sprung mass and its centre of gravity are ``body.mass`` and ``body.cg``;
* **corners**: :func:`~drivedyn.library.vehicles.suspensions.add_corner`, the type of each
  axle's section (a double wishbone, the HMMWV's; or a MacPherson strut,
  :func:`~drivedyn.library.vehicles.suspensions.add_macpherson`), each arm on two bushings
  mounted on the nearest frame node; spring free lengths from
  :func:`~drivedyn.library.vehicles.suspensions.free_length_for_load` for the static load
  of each corner, so that the vehicle starts at its ride height;
* **steering**: :func:`~drivedyn.library.vehicles.suspensions.add_rack_steering`, the
  pinion angle held at ``steering.pinion_angle`` or given as a time function
  (:func:`build_spec`'s ``steer``: the cornering scenario);
* **wheels**: a rigid body per corner hinged on the corner's hub; a
  :class:`~drivedyn.elements.TyreContact` per wheel, the property file mirrored for the
  side it was not measured on (:func:`~.inputs.measured_side`);
* **driveline**: the engine and gearbox as one shaft hinged on the frame, driven by an
  :class:`~drivedyn.elements.EngineTorque` reacted on the frame (the engine's maps at
  ``gear_ratio`` times the shaft's speed relative to the frame, times ``gear_ratio``)
  -> universal joint -> rigid propeller shaft -> slip yoke (a cylindrical joint along the
  shaft with a torsional spring-damper, the shaft's compliance) -> universal joint -> pinion
  shaft hinged in the rear carrier -> bevel :class:`~drivedyn.elements.GearPair` (the final
  drive)
  -> the rear differential (``open``, ``locked``, ``clutch``: the straight bevel
  differential of :mod:`..bevel_differential`; ``torsen-b``: the full TORSEN Type B
  model), included with its ground replaced by the rear carrier, a rigid body fixed to the
  frame's rear cross member -> rigid half-shafts: a universal joint at the side gear, a
  plunging universal joint (a prismatic slide along the shaft and a universal joint) at
  the wheel, so that the wheels travel and the shafts' length follows -> rear wheels.
  The front wheels turn freely.

Simplifications (stated in the model file too):

* engine: Chrono's HMMWV torque maps (zero throttle + throttle x (full load - zero
  throttle)) read as PCHIP curves (Chrono interpolates linearly), the speed clamped to the
  maps' 0-2700 rpm as Chrono does; a throttle ramp; first gear, torque converter locked, no
  shifts;
* the propeller shaft is straight at the static ride height (the gearbox output and the
  pinion at the wheel centres' height): its universal joints and slip yoke take only the
  carrier's motion with the frame's bending; its torsional compliance is one spring-damper
  at the slip yoke;
* the carried body's inertia is Chrono's chassis inertia as given (the frame's beams add
  their own on top, about 7 % in pitch);
* gravity acts on everything except the gears inside the differential (their weight in the
  pocket clearances makes them rattle at low speed for no effect on the torques; the 4WD
  vehicle does the same);
* no aerodynamic drag, no brakes; the front wheels carry no drive.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from drivedyn.elements import (
    Bushing,
    Cylindrical,
    EngineTorque,
    Fixed,
    Force,
    GearPair,
    Hinge,
    Prismatic,
    RoadPatch,
    TorsionalSpringDamper,
    TyreContact,
    Universal,
)
from drivedyn.elements.framework.visuals import box, cylinder, link
from drivedyn.errors import ModelError
from drivedyn.library.differentials import get as get_differential
from drivedyn.library.differentials import with_mesh_variation
from drivedyn.library.vehicles.bevel_differential import build_bevel
from drivedyn.library.vehicles.chassis import add_ladder_frame
from drivedyn.library.vehicles.chassis.schema import CarriedBody, LadderFrameFile
from drivedyn.library.vehicles.suspensions import (
    SuspensionSet,
    add_corner,
    add_rack_steering,
    free_length_for_load,
)
from drivedyn.library.vehicles.suspensions.geometry import marker_at, marker_pose
from drivedyn.library.vehicles.vehicle_4wd.model import (
    R_AXLE,
    R_CENTRAL,
    _final_drive_geometry,
)
from drivedyn.library.vehicles.vehicle_rwd.inputs import (
    SIDES,
    axle_error,
    check_parameters,
    load_tyre,
    tyre_notes,
    vehicle_suspensions,
)
from drivedyn.library.vehicles.vehicle_rwd.schema import WHEELS, VehicleRWDFile
from drivedyn.model.spec import Spec
from drivedyn.model.subassembly import include
from drivedyn.rotations import frame_from_axis
from drivedyn.timefunctions import SmoothStep
from drivedyn.tyres import Tyre

X = np.array([1.0, 0.0, 0.0])
Y = np.array([0.0, 1.0, 0.0])
Z = np.array([0.0, 0.0, 1.0])
G = 9.81
#: bodies of the differential that carry their weight (the gears inside do not)
CARRIED = ("housing", "case")


@dataclass
class Layout:
    """Names and numbers of a built vehicle that the analysis reads.

    Attributes:
        wheels: wheel -> wheel body name.
        tyres: wheel -> tyre element name.
        uprights: wheel -> the body its hub bearing is on (the upright).
        drives: rear wheel -> the joint whose reaction torque on the wheel about its spin
            axis is the wheel's drive torque (the outboard universal joint).
        engine: engine torque element name; propshaft: its spring's name.
        bevel: the final drive's gear pair; housing: the differential's housing body.
        rear_type: the rear differential's type.
        ratio: final-drive ratio.
        total_mass: [kg]; cg: (3,) centre of gravity [m] at t = 0.
        wheel_x: wheel -> x of the wheel centre [m] at t = 0.
        static_load: wheel -> static vertical load from the centre of gravity [N].
        rolling_radius: effective rolling radius at the static load [m].
        tdr: (lowest, highest) analytic bench TDR of a TORSEN (None for the other types).
        frame_nodes: number of frame nodes; frame_mass: the beams' mass [kg].
        free_lengths: corner -> the spring's free length [m].
        notes: what the user should know about the build (:func:`tyre_notes`).
    """

    wheels: dict[str, str] = field(default_factory=dict)
    tyres: dict[str, str] = field(default_factory=dict)
    uprights: dict[str, str] = field(default_factory=dict)
    drives: dict[str, str] = field(default_factory=dict)
    engine: str = "engine"
    propshaft: str = "prop_spring"
    bevel: str = "rear_bevel"
    housing: str = "rear_housing"
    rear_type: str = ""
    ratio: float = 1.0
    total_mass: float = 0.0
    cg: np.ndarray = field(default_factory=lambda: np.zeros(3))
    wheel_x: dict[str, float] = field(default_factory=dict)
    static_load: dict[str, float] = field(default_factory=dict)
    rolling_radius: float = 0.0
    tdr: tuple[float, float] | None = None
    frame_nodes: int = 0
    frame_mass: float = 0.0
    free_lengths: dict[str, float] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def _lifted(s: SuspensionSet, dz: float) -> SuspensionSet:
    """The suspension set moved up by ``dz`` [m]."""
    off = np.array([0.0, 0.0, dz])
    st = s.steering
    steering = st.model_copy(update={"location": tuple(np.asarray(st.location) + off)})
    return s.model_copy(update={"front": s.front.translated(off), "rear": s.rear.translated(off),
                                "steering": steering})


def _differential(p: VehicleRWDFile, torsen: dict, omega: float = 0.0
                  ) -> tuple[Spec, str, str, str, tuple[float, float] | None]:
    """The rear differential in its own frame, every body turning at ``omega`` [rad/s]:
    (spec, housing, output at lower z, output at higher z, analytic TDR range or None)."""
    kind = p.differentials.rear
    if kind in ("open", "locked", "clutch"):
        return build_bevel(p.differentials.bevel, kind, omega), "housing", "a", "b", None
    diff = get_differential(kind)
    params = with_mesh_variation(torsen[kind], p.differentials.mesh_stiffness_variation)
    spec, _ = diff.build(params, (omega, omega, omega), 1.0)
    first, second = (o.body for o in diff.outputs)
    lo, hi = ((first, second) if spec.bodies[first].position[2] <= spec.bodies[second].position[2]
              else (second, first))
    from drivedyn.library.differentials.torsen_b import analytic

    try:
        tdrs = analytic.all_modes(params)
    except RuntimeError as exc:
        raise ModelError(f"differentials.torsen_b = {p.differentials.torsen_b!r}: the analytic "
                         f"model finds no TDR ({exc})") from None
    return spec, "housing", lo, hi, (min(tdrs), max(tdrs))


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _frame_z(z: np.ndarray, x_hint: np.ndarray) -> np.ndarray:
    """Rotation whose z is ``z`` and whose x is ``x_hint`` made normal to it."""
    z = _unit(z)
    x = _unit(x_hint - (x_hint @ z) * z)
    return np.column_stack([x, np.cross(z, x), z])


def mass_properties(sp: Spec) -> tuple[float, np.ndarray]:
    """Total mass [kg] and centre of gravity (3,) [m] of the rigid bodies and beams of
    ``sp`` at t = 0 (each beam element's mass at its middle)."""
    m, mx = 0.0, np.zeros(3)
    for bd in sp.bodies.values():
        m += bd.mass
        mx += bd.mass * (bd.position + bd.rotation @ np.asarray(bd.com))
    for el in _elements(sp):
        if type(el).__name__ != "GeometricallyExactBeam":
            continue
        a, b = sp.nodes[el.node_a].position, sp.nodes[el.node_b].position
        me = el.section.properties(el.material).mass_per_length * float(np.linalg.norm(b - a))
        m += me
        mx += me * 0.5 * (a + b)
    return m, mx / m


def build_spec(p: VehicleRWDFile, torsen: dict, base_dir: str | Path = ".",
               tyre: Tyre | None = None, parked: bool = False,
               steer: Any = None, throttle: Any = None) -> tuple[Spec, Layout]:
    """The vehicle at its static ride height.

    ``parked`` adds what a static solution needs and a rolling vehicle does not have: a
    brake on each wheel (a torsional spring on its bearing) and a ground bushing on the
    frame that holds only the plane motions (x, y and yaw; free in heave, roll and pitch).
    At rest the tyres' horizontal forces vanish, so without them the vehicle's plane motion
    and the wheels' spins would have no stiffness; with them the vertical loads are the
    vehicle's own (the bushing carries no vertical force or moment about x and y).

    Args:
        p: validated parameters.
        torsen: ``"torsen-b"`` -> its validated parameters (when the rear uses it).
        base_dir: directory a relative tyre path is read from.
        tyre: the tyre of every wheel (default: :func:`load_tyre` per side).
        steer: the pinion angle [rad] as a time function (number, TimeFunction or dict);
            default ``steering.pinion_angle``, held.
        throttle: the engine's throttle (0 to 1) as a time function (number, TimeFunction
            or dict; an FMU's held input); default ``[engine]``'s ramp from
            ``idle_throttle`` to ``throttle``.
    Returns:
        (spec, layout).
    """
    check_parameters(p, base_dir)
    tyres = ({"l": tyre, "r": tyre} if tyre is not None else
             {k: load_tyre(p, base_dir, side) for k, side in SIDES.items()})
    susp = vehicle_suspensions(p, base_dir)
    r0 = tyres["l"].unloaded_radius
    # first pass: the masses (independent of heights and free lengths)
    sp0, lay0 = _assemble(p, torsen, susp, tyres, r0, None, p.body.mass, p.body.cg)
    # the sprung parts other than the carried body: frame beams and driveline on the frame
    sprung_names = [n for n in sp0.bodies if not n.startswith(("fl_", "fr_", "rl_", "rr_",
                                                               "wheel_", "halfshaft_",
                                                               "plunger_", "frame.body"))]
    bm, bcg = _beams(sp0)
    m_s, mx_s = bm, bm * bcg
    for n in sprung_names:
        bd = sp0.bodies[n]
        m_s += bd.mass
        mx_s += bd.mass * (bd.position + bd.rotation @ np.asarray(bd.com))
    z_lift = sp0.bodies[lay0.wheels["rl"]].position[2] - susp.rear.point("wheel_center")[2]
    cg_s = np.asarray(p.body.cg) + np.array([0.0, 0.0, z_lift])
    body_m = p.body.mass - m_s
    if not body_m > 0.0:
        raise ModelError(f"body.mass = {p.body.mass} kg: less than the frame and driveline on "
                         f"it ({m_s:.1f} kg)")
    body_cg = (p.body.mass * cg_s - mx_s) / body_m
    # static loads from the whole vehicle's centre of gravity
    _, lay1 = _assemble(p, torsen, susp, tyres, r0, None, body_m, body_cg - [0, 0, z_lift])
    m, cg = lay1.total_mass, lay1.cg
    xf = 0.5 * (lay1.wheel_x["fl"] + lay1.wheel_x["fr"])
    xr = 0.5 * (lay1.wheel_x["rl"] + lay1.wheel_x["rr"])
    w_front = m * G * (cg[0] - xr) / (xf - xr)
    w_rear = m * G - w_front
    loads = {"fl": w_front / 2, "fr": w_front / 2, "rl": w_rear / 2, "rr": w_rear / 2}
    rho = float(np.mean([f / tyres["l"].vertical_stiffness for f in loads.values()]))
    re = tyres["l"].effective_radius(rho)
    sp, lay = _assemble(p, torsen, susp, tyres, r0 - rho, loads, body_m,
                        body_cg - [0, 0, z_lift], lift=not parked, rolling_radius=re,
                        steer=steer, throttle=throttle)
    if parked:
        _park(sp, lay)
    lay.static_load = loads
    lay.rolling_radius = re
    lay.notes = tyre_notes(p, base_dir) if tyre is None else []
    return sp, lay


#: stiffness of the parking restraints (brakes [N m/rad], ground bushing [N/m, N m/rad])
PARK_TORSION = 1.0e5
PARK_PLANE = 1.0e6


def _park(sp: Spec, lay: Layout) -> None:
    """Brakes on the wheels and a ground bushing holding the frame's plane motions (see
    :func:`build_spec`)."""
    for w, name in lay.wheels.items():
        sp.add(TorsionalSpringDamper(f"brake_{w}", f"{name}_bearing_hub", f"{name}_hub",
                                     stiffness=PARK_TORSION))
    sp.add(TorsionalSpringDamper("brake_engine", "engine_bearing_frame_axis"
                                 if "engine_bearing_frame_axis" in sp.markers
                                 else "engine_bearing_frame", "engine_out",
                                 stiffness=PARK_TORSION))
    node = "frame.cross3.n2" if "frame.cross3.n2" in sp.nodes else next(iter(sp.nodes))
    pos = sp.nodes[node].position
    sp.add_marker("park_ground", "ground", position=pos)
    sp.add_marker("park_frame", node)
    sp.add(Bushing("park", "park_ground", "park_frame", stiffness=(PARK_PLANE, PARK_PLANE, 0.0),
                   rotational_stiffness=(0.0, 0.0, PARK_PLANE)))


def _beams(sp: Spec) -> tuple[float, np.ndarray]:
    m, mx = 0.0, np.zeros(3)
    for el in _elements(sp):
        if type(el).__name__ != "GeometricallyExactBeam":
            continue
        a, b = sp.nodes[el.node_a].position, sp.nodes[el.node_b].position
        me = el.section.properties(el.material).mass_per_length * float(np.linalg.norm(b - a))
        m += me
        mx += me * 0.5 * (a + b)
    return m, mx / max(m, 1e-300)


def _elements(sp: Spec) -> list[Any]:
    els = sp.elements
    return list(els.values()) if isinstance(els, dict) else list(els)


def _unsprung(corner_p: Any, wheel_mass: float, shaft_mass: float) -> float:
    """Mass [kg] below a corner's spring: the wheel, the upright, half of each link (the
    arms, the tie rod, a MacPherson's strut rod) and of the half-shaft (the links' other
    halves hang on the frame)."""
    links = sum(getattr(corner_p, k).mass for k in ("upper_arm", "lower_arm", "tie_rod",
                                                    "strut") if hasattr(corner_p, k))
    return wheel_mass + corner_p.upright.mass + 0.5 * (links + shaft_mass)


def _assemble(p: VehicleRWDFile, torsen: dict, susp: SuspensionSet, tyres: dict[str, Tyre],
              h_wc: float, loads: dict[str, float] | None, body_mass: float,
              body_cg: Any, lift: bool = True, rolling_radius: float = 1.0,
              steer: Any = None, throttle: Any = None) -> tuple[Spec, Layout]:
    """The vehicle with its wheel centres at height ``h_wc`` [m], the springs' free lengths
    for the corner ``loads`` [N] (None: the file's), the carried body's mass and centre of
    gravity (``body_cg`` in Chrono's vehicle frame); ``lift`` cancels the weight of the
    gears inside the differential (a rolling vehicle; a static solution keeps it, so that
    the tyres carry the whole weight). The vehicle moves forward at ``body.speed``, the
    wheels rolling on ``rolling_radius`` [m]; ``steer``: the pinion angle's time function
    (None: ``steering.pinion_angle``); ``throttle``: the throttle's (None: ``[engine]``'s
    ramp)."""
    lay = Layout(ratio=p.final_drive.teeth_ring / p.final_drive.teeth_pinion,
                 rear_type=p.differentials.rear)
    dz = h_wc - susp.rear.point("wheel_center")[2]
    s = _lifted(susp, dz)
    sh, fd = p.shafts, p.final_drive
    sp = Spec(gravity=(0.0, 0.0, -G))
    # frame with the carried body
    origin = np.asarray(p.frame_origin) + np.array([0.0, 0.0, dz])
    cg_frame = np.asarray(body_cg) + np.array([0.0, 0.0, dz]) - origin
    chassis = p.chassis.model_copy(update={"body": CarriedBody(
        mass=body_mass, cg=tuple(cg_frame), inertia=p.body.inertia,
        mounts=list(p.body.mounts))})
    chassis = LadderFrameFile.model_validate(chassis.model_dump())
    frame = add_ladder_frame(sp, "frame", chassis, origin=origin)
    lay.frame_nodes = len(frame.nodes)
    lay.frame_mass = frame.beam_mass

    def mount(name: str, point: np.ndarray) -> str:
        return frame.mount(name, point)

    # steering: held, or the given pinion angle's time function
    rack = add_rack_steering(sp, "steer", s.steering, mount,
                             p.steering.pinion_angle if steer is None else steer)
    # corners with the free lengths of their static loads
    corners = {}
    for w in WHEELS:
        cp = s.front if w[0] == "f" else s.rear
        if loads is not None:
            shaft = sh.halfshaft_mass + sh.plunger_mass if w[0] == "r" else 0.0
            sprung_load = loads[w] - G * _unsprung(cp, p.wheels.mass, shaft)
            fl = free_length_for_load(cp, sprung_load)
            cp = cp.model_copy(update={"spring": cp.spring.model_copy(
                update={"free_length": fl})})
            lay.free_lengths[w] = fl
        side = SIDES[w[1]]
        try:
            corners[w] = add_corner(sp, w, side, cp, mount,
                                    steer=rack.marker(side) if w[0] == "f" else None)
        except ModelError as exc:
            raise axle_error(p, "front" if w[0] == "f" else "rear", exc) from None
    # wheels and tyres
    patches = {w: tuple(RoadPatch(pa.x_start, pa.x_end, pa.mu) for pa in p.road.patches
                        if w in pa.wheels) for w in WHEELS}
    J = p.wheels.inertia
    Jw = np.diag([J[0], J[2], J[1]]) if np.ndim(J) == 1 else None
    for w in WHEELS:
        c = corners[w]
        pos, R = marker_pose(sp, c.hub)
        name = f"wheel_{w}"
        sp.add_rigid_body(name, p.wheels.mass, Jw if Jw is not None else J, position=pos,
                          rotation=R)
        sp.add_marker(f"{name}_hub", name)
        sp.add(Hinge(f"{name}_bearing", c.hub, f"{name}_hub"))
        marker_at(sp, f"{name}_bearing_hub", sp.markers[c.hub].body, pos, R)
        sp.add(TyreContact(f"tyre_{w}", f"{name}_hub", tyres[w[1]], mu=getattr(p.road.mu, w),
                           patches=patches[w], transition=p.road.transition,
                           relaxation=p.wheels.relaxation,
                           low_speed_damping=p.wheels.low_speed_damping,
                           vertical_damping=p.wheels.vertical_damping))
        lay.wheels[w] = name
        lay.tyres[w] = f"tyre_{w}"
        lay.uprights[w] = sp.markers[c.hub].body
        lay.wheel_x[w] = float(pos[0])
    # rear carrier on the frame, the differential on it
    x_rear = 0.5 * (corners["rl"].wheel_center[0] + corners["rr"].wheel_center[0])
    x_front = 0.5 * (corners["fl"].wheel_center[0] + corners["fr"].wheel_center[0])
    centre = np.array([x_rear, 0.0, h_wc])
    ca = p.carrier
    sp.add_rigid_body("carrier", ca.mass, ca.inertia, position=centre)
    sp.add_marker("carrier_seat", "carrier")
    sp.add_visual(box("carrier_seat", 0.35, 0.45, 0.4, role="case", label="carrier"))
    sp.add(Fixed("carrier_fix", mount("carrier_mount", centre), "carrier_seat"))
    v0 = p.body.speed
    w_wheel = v0 / rolling_radius
    sub, housing, lo, hi, rng = _differential(p, torsen, w_wheel)
    for body, mk in ((lo, "vehicle_lo"), (hi, "vehicle_hi"), (housing, "vehicle_housing")):
        sub.add_marker(mk, body, rotation=sub.bodies[body].rotation.T @ frame_from_axis(Z))
    names = include(sp, sub, "rear_", position=centre, rotation=R_AXLE, ground="carrier",
                    velocity=v0 * X)
    lay.housing = f"rear_{housing}"
    lay.tdr = rng
    diff_bodies = [names[b] for b in sub.bodies]
    # engine and gearbox on the frame, ahead of the propeller shaft
    e = p.engine
    x_eng = x_front - 0.5
    eng_pos = np.array([x_eng, 0.0, h_wc])
    J_eng = e.inertia * e.gear_ratio ** 2 + e.output_inertia
    # a disc's transverse moments (half the axial one): the reflected inertia is a number
    # about the axis, the body needs a mass distribution that has it
    sp.add_rigid_body("engine_shaft", e.shaft_mass, (0.5 * J_eng, 0.5 * J_eng, J_eng),
                      position=eng_pos,
                      rotation=R_CENTRAL)
    sp.add_marker("engine_out", "engine_shaft")
    eng_mount = marker_at(sp, "engine_bearing_frame", frame.nearest_node(eng_pos), eng_pos,
                          frame_from_axis(X))
    sp.add(Hinge("engine_bearing", eng_mount, "engine_out"))
    sp.add(EngineTorque("engine", eng_mount, "engine_out", full_load=e.full_load,
                        zero_throttle=e.zero_throttle,
                        throttle_function=SmoothStep(e.start, e.start + e.ramp,
                                                     e.idle_throttle, e.throttle)
                        if throttle is None else throttle,
                        ratio=e.gear_ratio))
    # propeller shaft: a universal joint at the gearbox output, a slip yoke (sliding and
    # turning on the shaft against its torsional compliance) and a universal joint at the
    # pinion's flange; the pinion hinged on the carrier
    fd_geo = _final_drive_geometry(fd)
    pin_pos = centre + fd_geo["d_pinion"] * X
    brg = pin_pos + p.carrier.pinion_offset * X
    Rx = frame_from_axis(X)
    sp.add_rigid_body("propshaft", sh.propshaft_mass, sh.propshaft_inertia,
                      position=0.5 * (eng_pos + brg), rotation=R_CENTRAL)
    sp.add_rigid_body("propshaft_slip", sh.slip_mass, sh.slip_inertia, position=brg,
                      rotation=R_CENTRAL)
    sp.add_rigid_body("pinion_shaft", ca.pinion_mass, ca.pinion_inertia,
                      position=0.5 * (pin_pos + brg), rotation=R_CENTRAL)
    sp.add(Universal("prop_front_uj",
                     marker_at(sp, "gearbox_flange", "engine_shaft", eng_pos, Rx),
                     marker_at(sp, "prop_front_yoke", "propshaft", eng_pos, Rx)))
    prop_rear = marker_at(sp, "prop_rear", "propshaft", brg, Rx)
    slip = marker_at(sp, "prop_slip_in", "propshaft_slip", brg, Rx)
    sp.add(Cylindrical("prop_slip", prop_rear, slip))
    sp.add(TorsionalSpringDamper("prop_spring", prop_rear, slip,
                                 stiffness=sh.propshaft_stiffness, damping=sh.propshaft_damping))
    sp.add(Universal("prop_rear_uj", marker_at(sp, "prop_slip_out", "propshaft_slip", brg, Rx),
                     marker_at(sp, "pinion_flange", "pinion_shaft", brg, Rx)))
    sp.add(Hinge("pinion_bearing", marker_at(sp, "carrier_pinion", "carrier", brg, Rx),
                 marker_at(sp, "pinion_bearing_shaft", "pinion_shaft", brg, Rx)))
    marker_at(sp, "rear_pinion", "pinion_shaft", pin_pos, Rx)
    sp.add_visual(link("prop_front_yoke", "prop_rear", 0.035, label="propshaft"))  # 70 mm tube
    sp.add_visual(cylinder("engine_out", 0.05, 0.3, label="engine_shaft"))
    sp.add_visual(cylinder("prop_slip_in", 0.045, 0.15, label="propshaft_slip"))  # slip yoke
    sp.add_visual(box(eng_mount, 0.55, 0.6, 1.1, role="case", label="engine and gearbox"))
    ring = centre - fd_geo["d_ring"] * Y  # the ring on the -y side drives forward
    marker_at(sp, "rear_ring", lay.housing, ring, frame_from_axis(Y))
    sp.add(GearPair("rear_bevel", "rear_pinion", "rear_ring", fd.teeth_pinion, fd.teeth_ring,
                    module=fd.module, face_width=fd.face_width,
                    pressure_angle=fd.pressure_angle, kind="bevel",
                    cone_angle_a=fd_geo["cone_pinion"], cone_angle_b=fd_geo["cone_ring"],
                    damping_ratio=fd.damping_ratio,
                    stiffness_variation=fd.stiffness_variation))
    # rigid half-shafts: universal joint at the side gear, plunging universal at the wheel
    for w, out in (("rl", "rear_vehicle_hi"), ("rr", "rear_vehicle_lo")):
        p_in, _ = marker_pose(sp, out)
        gear = sp.markers[out].body
        c_w = sp.bodies[lay.wheels[w]].position
        axis = _unit(c_w - p_in)
        ys = _unit(np.cross(axis, X))  # the shaft's y: across it, normal to x
        Rs = np.column_stack([np.cross(ys, axis), ys, axis])
        hs = f"halfshaft_{w}"
        sp.add_rigid_body(hs, sh.halfshaft_mass, sh.halfshaft_inertia,
                          position=0.5 * (p_in + c_w), rotation=Rs)
        # the side gear's cross axis is x (normal to the shaft's y)
        ra = _frame_z(axis - (axis @ X) * X, X)
        sp.add(Universal(f"{hs}_inner", marker_at(sp, f"{hs}_gear", gear, p_in, ra),
                         marker_at(sp, f"{hs}_in", hs, p_in, Rs)))
        pl = f"plunger_{w}"
        sp.add_rigid_body(pl, sh.plunger_mass, sh.plunger_inertia, position=c_w, rotation=Rs)
        sp.add(Prismatic(f"{hs}_plunge", marker_at(sp, f"{hs}_out", hs, c_w, Rs),
                         marker_at(sp, f"{pl}_in", pl, c_w, Rs)))
        xp = _unit(X - (X @ axis) * axis)
        Rp = np.column_stack([xp, np.cross(axis, xp), axis])
        k = sp.bodies[lay.wheels[w]].rotation[:, 2]
        yb = _unit(np.cross(k, xp))
        Rw = np.column_stack([np.cross(yb, k), yb, k])
        sp.add(Universal(f"{hs}_outer", marker_at(sp, f"{pl}_out", pl, c_w, Rp),
                         marker_at(sp, f"{hs}_wheel", lay.wheels[w], c_w, Rw)))
        lay.drives[w] = f"{hs}_outer"
        sp.add_visual(link(f"{hs}_in", f"{hs}_out", 0.015, label=hs))  # 30 mm shaft
        sp.add_visual(cylinder(f"{pl}_in", 0.04, 0.08, label=pl))  # the plunging joint's can
    # the gears inside the differential carry no weight: a lift cancels it
    for b in diff_bodies if lift else ():
        if b.split("_", 1)[1] in CARRIED:
            continue
        bd = sp.bodies[b]
        sp.add_marker(f"{b}_cg", b, position=bd.com)
        sp.add(Force(f"{b}_lift", f"{b}_cg", vector=(0.0, 0.0, G * bd.mass)))
    if v0 != 0.0:
        _moving(sp, lay, diff_bodies, v0, w_wheel)
    lay.total_mass, lay.cg = mass_properties(sp)
    return sp, lay


def _moving(sp: Spec, lay: Layout, diff_bodies: list[str], v0: float, w_wheel: float) -> None:
    """Initial velocities of a vehicle moving forward at ``v0`` [m/s]: every body and node
    translates with it; the wheels, half-shafts and plungers turn at ``w_wheel`` about their
    axes, the propeller and engine shafts at the final-drive ratio times it about x (the
    differential's bodies were built turning)."""
    spin = {lay.wheels[w]: w_wheel * sp.bodies[lay.wheels[w]].rotation[:, 2] for w in WHEELS}
    for w in lay.drives:
        for b in (f"halfshaft_{w}", f"plunger_{w}"):
            spin[b] = w_wheel * sp.bodies[b].rotation[:, 2]
    for b in ("engine_shaft", "propshaft", "propshaft_slip", "pinion_shaft"):
        spin[b] = lay.ratio * w_wheel * X
    for name, bd in list(sp.bodies.items()):
        if name in diff_bodies:
            continue
        sp.bodies[name] = replace(bd, velocity=v0 * X,
                                  angular_velocity=spin.get(name, np.zeros(3)))
    for name, nd in list(sp.nodes.items()):
        sp.nodes[name] = replace(nd, velocity=v0 * X)

