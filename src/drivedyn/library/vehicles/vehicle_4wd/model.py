"""The four-wheel-drive vehicle of seed 003 (Figures 14-15), built from its parts.

Global frame at t = 0: x forward, y left, z up, origin on the road at mid-wheelbase. The car
body (a lumped mass) moves in the x-z plane (a planar joint: longitudinal, heave, pitch). The
four wheels are hinged to it (axis +y, no suspension: the tyres' radial stiffness carries the
longitudinal load transfer through the pitch degree of freedom; the wheels' vertical damping
stands for the dampers). The central differential's axis is +x at the height of the wheel
centres; the axle differentials' axes are +y on the axle lines. Every differential is the
full dynamic model of its type (:mod:`drivedyn.library.differentials` or
:mod:`..bevel_differential`), built in its own frame and placed by
:func:`drivedyn.model.subassembly.include` with its ground replaced by the car body (the
differentials are hinged to the frame, seed 003).

Power path: engine torque on the central housing (reacted on the car body) -> central outputs
(Type C: sun to the front, coupling/ring to the rear) -> torsional spring-dampers (propeller
shaft compliance) -> propeller shafts (rigid, hinged to the body) -> straight bevel pinion /
ring :class:`GearPair` (ratio ``teeth_ring/teeth_pinion``, 1 in seed 003) -> axle
differential housing -> side gears -> torsional spring-dampers (half-shafts) -> wheels ->
:class:`~drivedyn.elements.TyreContact` on the road.

Simplifications (stated in the model file too): no suspension kinematics, no steering, no
roll or yaw (the body stays in its plane, so split-mu yaw moments are reacted by the planar
joint and reported, not simulated); no aerodynamic drag (below 10 m/s it is < 2 % of the
tractive force of the shipped case); shafts rigid with their torsional compliance lumped.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from drivedyn.elements import (
    Force,
    GearPair,
    Hinge,
    Planar,
    RoadPatch,
    Torque,
    TorsionalSpringDamper,
    TyreContact,
)
from drivedyn.elements.framework.visuals import box, link
from drivedyn.errors import ModelError
from drivedyn.library.differentials import get as get_differential
from drivedyn.library.differentials import with_mesh_variation
from drivedyn.library.vehicles.bevel_differential import (
    build_bevel,
    check_bevel,
    check_mesh,
    undercut_shift,
)
from drivedyn.library.vehicles.vehicle_4wd.schema import WHEELS, Vehicle4WDFile
from drivedyn.model.spec import Spec
from drivedyn.model.subassembly import include
from drivedyn.rotations import frame_from_axis
from drivedyn.timefunctions import SmoothStep
from drivedyn.tyres import Tyre, resolve_tyre, simple_tyre

X = np.array([1.0, 0.0, 0.0])
Y = np.array([0.0, 1.0, 0.0])
Z = np.array([0.0, 0.0, 1.0])
G = 9.81
#: rotation taking a differential's z axis to the vehicle's +x (central) / +y (axles)
R_CENTRAL = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
R_AXLE = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
POSITIONS = ("central", "front", "rear")
#: bodies of a differential that carry their weight (the others: see build_spec)
CARRIED = ("housing", "case")


@dataclass
class Layout:
    """Names and numbers of a built vehicle that the analysis reads.

    Attributes:
        wheels: wheel -> wheel body name.
        tyres: wheel -> tyre element name.
        halfshafts: wheel -> half-shaft spring name (its torque is the wheel's drive torque).
        propshafts: ``front``/``rear`` -> propeller-shaft spring name.
        bevels: ``front``/``rear`` -> final-drive gear pair (its ``torque_b`` drives the axle
            differential's housing).
        housings: position -> housing body name.
        types: position -> differential type.
        engine: engine torque element name.
        ratio: final-drive ratio.
        wheel_height: wheel-centre height at t = 0 [m].
        rolling_radius: effective rolling radius at the static load [m].
        static_load: wheel -> static vertical load [N].
        total_mass: [kg].
        tdr: position -> (lowest, highest) analytic bench TDR of a TORSEN's four modes
            (None for the other types).
        modes: position -> the analytic bench TDRs of a TORSEN's modes 1-4 (None for the
            other types).
        outputs: position -> (output body at the lower, at the higher z of the
            differential's own frame).
        driveline: body -> mass [kg] of every body between the engine and the wheels
            (shafts and differentials).
    """

    wheels: dict[str, str] = field(default_factory=dict)
    tyres: dict[str, str] = field(default_factory=dict)
    halfshafts: dict[str, str] = field(default_factory=dict)
    propshafts: dict[str, str] = field(default_factory=dict)
    bevels: dict[str, str] = field(default_factory=dict)
    housings: dict[str, str] = field(default_factory=dict)
    types: dict[str, str] = field(default_factory=dict)
    engine: str = "engine"
    ratio: float = 1.0
    wheel_height: float = 0.0
    rolling_radius: float = 0.0
    static_load: dict[str, float] = field(default_factory=dict)
    total_mass: float = 0.0
    tdr: dict[str, tuple[float, float] | None] = field(default_factory=dict)
    modes: dict[str, list[float] | None] = field(default_factory=dict)
    outputs: dict[str, tuple[str, str]] = field(default_factory=dict)
    driveline: dict[str, float] = field(default_factory=dict)


def load_tyre(p: Vehicle4WDFile, base_dir: str | Path = ".", side: str | None = None) -> Tyre:
    """The tyre of ``wheels.tyre`` (shipped name, ``simple-<surface>`` with
    ``wheels.simple_radius``, or a path relative to ``base_dir``) for a wheel on ``side``
    (``"left"``/``"right"``: a property file measured on the other side is mirrored)."""
    name = p.wheels.tyre
    path = Path(base_dir) / name
    try:
        if name.startswith("simple-"):
            return simple_tyre(name.removeprefix("simple-"),
                               unloaded_radius=p.wheels.simple_radius)
        return resolve_tyre(str(path) if path.exists() and not Path(name).is_absolute()
                            else name, side)
    except ModelError as exc:  # "tyre ...", "simple tyre: ..."
        text = str(exc)
        raise ModelError(f"wheels.{text}" if text.startswith("tyre") else
                         f"wheels.tyre = {name!r}: {text}") from None


def check_parameters(p: Vehicle4WDFile) -> None:
    """Refuse impossible vehicles, naming the key."""
    b = p.body
    if not b.cg_to_front < b.wheelbase:
        raise ModelError(f"body.cg_to_front: must lie between the axles (< wheelbase = "
                         f"{b.wheelbase} m), got {b.cg_to_front} m")
    for pos in POSITIONS:
        t = getattr(p.differentials, pos)
        if pos == "central" and t == "torsen-b":
            continue  # a symmetric central differential: allowed
        if pos != "central" and t == "torsen-c":
            raise ModelError(f"differentials.{pos}: torsen-c is the central (epicyclic, "
                             f"asymmetric) differential; use torsen-b, open, locked or clutch")
    if not p.load.start + p.load.ramp > p.load.start:
        raise ModelError(f"load.ramp = {p.load.ramp!r} s: ends where it starts at load.start = "
                         f"{p.load.start!r} s (floating point); a longer ramp")
    if {getattr(p.differentials, pos) for pos in POSITIONS} & {"open", "locked", "clutch"}:
        check_bevel(p.differentials.bevel)
    fd = p.final_drive
    geo = _final_drive_geometry(fd)
    for key, cone in (("teeth_pinion", geo["cone_pinion"]), ("teeth_ring", geo["cone_ring"])):
        if undercut_shift(getattr(fd, key), cone, fd.pressure_angle) > 1e-12:
            raise ModelError(f"final_drive.{key} = {getattr(fd, key)}: undercuts (no profile "
                             f"shift) with final_drive.teeth_pinion = {fd.teeth_pinion}, "
                             f"final_drive.teeth_ring = {fd.teeth_ring} and "
                             f"final_drive.pressure_angle = "
                             f"{math.degrees(fd.pressure_angle):.4g} deg (DIN 3960 practical "
                             "limit)")
    check_mesh(GearPair("check", "pinion", "ring", fd.teeth_pinion, fd.teeth_ring,
                        module=fd.module, face_width=fd.face_width,
                        pressure_angle=fd.pressure_angle, kind="bevel",
                        cone_angle_a=geo["cone_pinion"], cone_angle_b=geo["cone_ring"],
                        damping_ratio=fd.damping_ratio),
               "final_drive", FINAL_DRIVE_KEYS, fd)


#: the parameters of the final-drive mesh and the keys of [final_drive] they come from
FINAL_DRIVE_KEYS = {"teeth_a": "teeth_pinion", "teeth_b": "teeth_ring", "module": "module",
                    "face_width": "face_width", "pressure_angle": "pressure_angle",
                    "damping_ratio": "damping_ratio"}


def _differential(p: Vehicle4WDFile, pos: str, torsen: dict, omega: float
                  ) -> tuple[Spec, str, str, str, list[float] | None]:
    """The differential at ``pos`` in its own frame: (spec, housing, output at lower z,
    output at higher z, analytic bench TDRs of its four modes or None)."""
    kind = getattr(p.differentials, pos)
    if kind in ("open", "locked", "clutch"):
        return build_bevel(p.differentials.bevel, kind, omega), "housing", "a", "b", None
    diff = get_differential(kind)
    params = with_mesh_variation(torsen[kind], p.differentials.mesh_stiffness_variation)
    spec, _ = diff.build(params, (omega, omega, omega), 1.0)
    first, second = (o.body for o in diff.outputs)
    z1 = spec.bodies[first].position[2]
    z2 = spec.bodies[second].position[2]
    lo, hi = (first, second) if z1 <= z2 else (second, first)
    try:
        tdrs = diff_analytic(kind).all_modes(params)
    except RuntimeError as exc:  # no sliding equilibrium: the checks would have no bound
        key = kind.replace("-", "_")
        raise ModelError(f"differentials.{key} = {getattr(p.differentials, key)!r}: the "
                         f"analytic model of the {kind} finds no TDR ({exc})") from None
    return spec, "housing", lo, hi, list(tdrs)


def diff_analytic(kind: str):
    """The analytic quasi-static module of a TORSEN type (its ``all_modes`` gives the bench
    TDR of the four modes)."""
    if kind == "torsen-c":
        from drivedyn.library.differentials.torsen_c import analytic
    else:
        from drivedyn.library.differentials.torsen_b import analytic
    return analytic


def _output_marker(sp: Spec, body: str, name: str) -> None:
    """A marker on ``body`` at its origin with z along the differential's axis."""
    R = sp.bodies[body].rotation
    sp.add_marker(name, body, rotation=R.T @ frame_from_axis(Z))


def build_spec(p: Vehicle4WDFile, torsen: dict, base_dir: str | Path = ".",
               tyre: Tyre | None = None, engine: Any = None) -> tuple[Spec, Layout]:
    """The vehicle.

    Args:
        p: validated parameters.
        torsen: ``"torsen-c"``/``"torsen-b"`` -> validated parameters of that differential
            (those the positions use).
        base_dir: directory a relative tyre path is read from.
        tyre: the tyre of every wheel (default: :func:`load_tyre` for each side, a property
            file mirrored on the side it was not measured on).
        engine: the engine torque [N m] as a time function (default: ``[load]``'s ramp to
            ``load.torque``), e.g. a :class:`~drivedyn.timefunctions.Held` input.
    Returns:
        (spec, layout).
    """
    check_parameters(p)
    tyres = ({"l": tyre, "r": tyre} if tyre is not None else
             {w: load_tyre(p, base_dir, side) for w, side in (("l", "left"), ("r", "right"))})
    tyre = tyres["l"]  # the sides differ in lateral terms only: one radius and stiffness
    b, sh, fd = p.body, p.shafts, p.final_drive
    L, T = b.wheelbase, b.track
    x_front, x_rear = L / 2, -L / 2
    x_cg = x_front - b.cg_to_front
    v0 = b.speed
    lay = Layout(ratio=fd.teeth_ring / fd.teeth_pinion)
    # differentials first (their masses set the static load)
    r0 = tyre.unloaded_radius
    parts = {}
    for pos in POSITIONS:
        parts[pos] = _differential(p, pos, torsen, 0.0)
    m_parts = sum(sum(bd.mass for n, bd in s[0].bodies.items() if n in CARRIED)
                  for s in parts.values())
    m_total = b.mass + 4 * p.wheels.mass + 2 * sh.propshaft_mass + m_parts
    # static loads: body (and everything on it) split by the centre of gravity
    w_front = m_total * G * (L - b.cg_to_front) / L
    w_rear = m_total * G - w_front
    loads = {"fl": w_front / 2, "fr": w_front / 2, "rl": w_rear / 2, "rr": w_rear / 2}
    defl = {w: f / tyre.vertical_stiffness for w, f in loads.items()}
    rho = float(np.mean(list(defl.values())))  # level start; the body settles into pitch
    h = r0 - rho
    re = tyre.effective_radius(rho)
    lay.wheel_height, lay.rolling_radius, lay.total_mass = h, re, m_total
    lay.static_load = loads
    w_wheel = v0 / re
    w_prop = w_wheel * lay.ratio
    # rebuild the differentials turning with the vehicle's initial speed
    if v0 != 0.0:
        parts = {"central": _differential(p, "central", torsen, w_prop),
                 "front": _differential(p, "front", torsen, w_wheel),
                 "rear": _differential(p, "rear", torsen, w_wheel)}
    sp = Spec()  # weights as forces: see WEIGHED
    vel = (v0, 0.0, 0.0)
    # car body in its plane
    sp.add_rigid_body("body", b.mass, b.inertia, position=(x_cg, 0.0, b.cg_height),
                      velocity=vel)
    sp.add_marker("g_body", "ground", position=(x_cg, 0.0, b.cg_height), axis=Y)
    sp.add_marker("b_plane", "body", axis=Y)
    sp.add(Planar("body_plane", "g_body", "b_plane"))
    body_pos = np.array([x_cg, 0.0, b.cg_height])

    def on_body(name: str, pos, axis) -> str:
        return sp.add_marker(name, "body", position=np.asarray(pos) - body_pos, axis=axis)

    # the car body for the 3-D viewer: a semi-transparent box over the wheels (0.6 m
    # overhangs, as narrow as the track so that the wheels show; illustrative sizes)
    sp.add_marker("b_shell", "body", position=np.array([0.0, 0.0, r0 + 0.35]) - body_pos)
    sp.add_visual(box("b_shell", L + 1.2, T - 0.3, 0.7, role="chassis", label="body"))

    # differentials
    placement = {"central": (np.array([0.0, 0.0, h]), R_CENTRAL),
                 "front": (np.array([x_front, 0.0, h]), R_AXLE),
                 "rear": (np.array([x_rear, 0.0, h]), R_AXLE)}
    outs = {}
    for pos in POSITIONS:
        sub, housing, lo, hi, tdrs = parts[pos]
        _output_marker(sub, lo, "vehicle_lo")
        _output_marker(sub, hi, "vehicle_hi")
        _output_marker(sub, housing, "vehicle_housing")
        at, R = placement[pos]
        include(sp, sub, f"{pos}_", position=at, rotation=R, ground="body", velocity=vel)
        lay.housings[pos] = f"{pos}_{housing}"
        lay.types[pos] = getattr(p.differentials, pos)
        lay.tdr[pos] = None if tdrs is None else (min(tdrs), max(tdrs))
        lay.modes[pos] = tdrs
        lay.outputs[pos] = (f"{pos}_{lo}", f"{pos}_{hi}")
        outs[pos] = (f"{pos}_vehicle_lo", f"{pos}_vehicle_hi")
    # engine torque on the central housing, reacted on the body
    start, ramp = p.load.start, p.load.ramp
    f = SmoothStep(start, start + ramp, 0.0, 1.0) if engine is None else engine
    level = p.load.torque if engine is None else 1.0
    sp.add(Torque("engine", "central_vehicle_housing", vector=(0, 0, level),
                  function=f, frame="marker"))
    on_body("b_engine", (0.0, 0.0, h), X)
    sp.add(Torque("engine_reaction", "b_engine", vector=(0, 0, -level), function=f,
                  frame="marker"))
    # propeller shafts with their pinions
    fd_geo = _final_drive_geometry(fd)
    for axle, x_axle, central_out, sgn in (("front", x_front, outs["central"][0], -1.0),
                                           ("rear", x_rear, outs["central"][1], 1.0)):
        name = f"prop_{axle}"
        xp = x_axle / 2
        sp.add_rigid_body(name, sh.propshaft_mass, sh.propshaft_inertia,
                          position=(xp, 0.0, h), rotation=R_CENTRAL, velocity=vel,
                          angular_velocity=w_prop * X)
        on_body(f"b_{name}", (xp, 0.0, h), X)
        sp.add_marker(f"m_{name}", name, axis=Z)
        sp.add(Hinge(f"{name}_bearing", f"b_{name}", f"m_{name}"))
        sp.add(TorsionalSpringDamper(f"{name}_spring", central_out, f"m_{name}",
                                     stiffness=sh.propshaft_stiffness,
                                     damping=sh.propshaft_damping))
        lay.propshafts[axle] = f"{name}_spring"
        # pinion behind (front axle) / ahead of (rear axle) the apex on the axle line;
        # ring on the +y (front) / -y (rear) side so that both axles drive forward
        apex = np.array([x_axle, 0.0, h])
        pin_pos = apex + sgn * fd_geo["d_pinion"] * X
        sp.add_marker(f"{axle}_pinion", name, position=R_CENTRAL.T @ (pin_pos - [xp, 0, h]),
                      rotation=R_CENTRAL.T @ frame_from_axis(X))
        # the shaft for the 3-D viewer: from its pinion to the central output (a 70 mm
        # tube, illustrative); on the shaft's own marker, so no inertia box stands for it
        sp.add_visual(link(f"{axle}_pinion", central_out, 0.035, label=name))
        ring_side = 1.0 if axle == "front" else -1.0
        sp.add_marker(f"{axle}_ring", f"{axle}_housing",
                      position=(0.0, 0.0, ring_side * fd_geo["d_ring"]), axis=Z)
        sp.add(GearPair(f"{axle}_bevel", f"{axle}_pinion", f"{axle}_ring", fd.teeth_pinion,
                        fd.teeth_ring, module=fd.module, face_width=fd.face_width,
                        pressure_angle=fd.pressure_angle, kind="bevel",
                        cone_angle_a=fd_geo["cone_pinion"], cone_angle_b=fd_geo["cone_ring"],
                        damping_ratio=fd.damping_ratio,
                        stiffness_variation=fd.stiffness_variation))
        lay.bevels[axle] = f"{axle}_bevel"
    # wheels, half-shafts, tyres
    patches = {w: tuple(RoadPatch(pa.x_start, pa.x_end, pa.mu) for pa in p.road.patches
                        if w in pa.wheels) for w in WHEELS}
    for w in WHEELS:
        axle = "front" if w[0] == "f" else "rear"
        x_axle = x_front if axle == "front" else x_rear
        y = T / 2 if w[1] == "l" else -T / 2
        name = f"wheel_{w}"
        sp.add_rigid_body(name, p.wheels.mass, p.wheels.inertia, position=(x_axle, y, h),
                          velocity=vel, angular_velocity=w_wheel * Y)
        on_body(f"b_{name}", (x_axle, y, h), Y)
        sp.add_marker(f"hub_{w}", name, axis=Y)
        sp.add(Hinge(f"{name}_bearing", f"b_{name}", f"hub_{w}"))
        # the axle differential's +z (vehicle +y, left) output drives the left wheel
        out = outs[axle][1] if w[1] == "l" else outs[axle][0]
        sp.add(TorsionalSpringDamper(f"halfshaft_{w}", out, f"hub_{w}",
                                     stiffness=sh.halfshaft_stiffness,
                                     damping=sh.halfshaft_damping))
        sp.add_visual(link(f"hub_{w}", out, 0.015, label=f"halfshaft_{w}"))  # 30 mm shaft
        sp.add(TyreContact(f"tyre_{w}", f"hub_{w}", tyres[w[1]], mu=getattr(p.road.mu, w),
                           patches=patches[w], transition=p.road.transition,
                           relaxation=p.wheels.relaxation,
                           low_speed_damping=p.wheels.low_speed_damping,
                           vertical_damping=p.wheels.vertical_damping))
        lay.wheels[w] = name
        lay.tyres[w] = f"tyre_{w}"
        lay.halfshafts[w] = f"halfshaft_{w}"
    lay.driveline = {n: bd.mass for n, bd in sp.bodies.items()
                     if n != "body" and not n.startswith("wheel_")}
    # weights: the car body, wheels, shafts and differential housings; the gears inside the
    # differentials carry none (in the pocket clearances their weight makes them rattle at
    # low speed, a cost without effect on the torques: below 0.5 % of the static load)
    for name, bd in list(sp.bodies.items()):
        if "_" in name and name.split("_", 1)[0] in POSITIONS \
                and name.split("_", 1)[1] not in CARRIED:
            continue
        sp.add_marker(f"{name}_cg", name, position=bd.com)
        sp.add(Force(f"{name}_weight", f"{name}_cg", vector=(0.0, 0.0, -G * bd.mass)))
    return sp, lay


def _final_drive_geometry(fd) -> dict[str, float]:
    """Cone angles [rad] and the distances [m] of the pinion and ring markers (centres of the
    mean pitch circles) from the cone apex, shaft angle 90 deg."""
    gp = math.atan2(fd.teeth_pinion, fd.teeth_ring)
    gr = math.atan2(fd.teeth_ring, fd.teeth_pinion)
    rm = fd.teeth_pinion * fd.module / 2 / math.sin(gp)
    return {"cone_pinion": gp, "cone_ring": gr, "d_pinion": rm * math.cos(gp),
            "d_ring": rm * math.cos(gr)}
