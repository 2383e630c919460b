"""Parametric TORSEN Type B (parallel-axis, front/rear axle) differential, after seed 003
(Figure 3, "Front or rear differential") and the slides of seed 002.

Parts (axis = global z, left = -z, forward rotation = +z)::

    housing    carries the ring gear (driven by the final drive) and one pocket per element
               gear; hinge to the ground
    left       left side gear (helical, hand of ``gears.helix_angle``), splined to the left
               half-axle; cylindrical joint to the ground bearing (turns, slides)
    right      right side gear, the mirror image (opposite hand); cylindrical joint
    a{k}, b{k} pair k of element gears (k = 1..n) in their pockets: a{k} meshes the left side
               gear, b{k} the right one, and a{k} meshes b{k} at both ends, beyond the side
               gears (the middle of each element gear is relieved below its root where it
               passes the other side gear). Each element gear keeps its axis parallel to the
               housing axis (ParallelAxes joint: tilts held, centre and spin free); its tip
               rubs on the pocket bore (JournalContact, tip friction) and its end faces on the
               pocket floors (thrust-washer contacts, end-face friction).

Meshes: 2 n side meshes and 2 n end meshes (20 for the seeds' five pairs), ISO 6336 stiffness,
with mesh-stiffness variation over the mesh cycle, backlash and tooth friction as the model
file says. Thrust washers: ``left`` (housing behind the left gear), ``right`` (housing behind
the right gear) and ``middle`` (between the side gears, turning with the left gear), one
shared friction coefficient; optionally a squeeze film on each.

Thrust paths. A mesh pushes a helical gear axially by ``-tan(beta) T / r`` (``T`` the mesh
torque on the gear about +z, ``beta`` its helix angle, > 0 right hand). The side gears, of
opposite hands, are both loaded with the same torque sign on the bench and in the vehicle, so
they are pushed together (onto the middle washer) in one direction of the torque and apart
(onto the housing washers) in the other: drive and coast load different washers, which is
why their TDRs differ (seed 003, Table 2: 1.6 and 1.7). Each element gear's thrust from its
side mesh and from its end meshes goes to one of its end faces.

Bench and vehicle scenarios: :mod:`drivedyn.library.differentials.scenarios`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from drivedyn.elements import Cylindrical, GearPair, Hinge, ParallelAxes
from drivedyn.elements.contact import (
    FrictionLaw,
    JournalContact,
    JournalFilm,
    NormalLaw,
    ThrustWasherContact,
)
from drivedyn.elements.contact.squeeze_film import SqueezeFilm
from drivedyn.elements.framework.visuals import cylinder
from drivedyn.elements.gears.geometry import CylindricalPair, top_land, undercut_limits
from drivedyn.library.differentials.end_faces import add_end_faces
from drivedyn.library.differentials.flexible_washers import add_flexible_washer
from drivedyn.library.differentials.torsen_b.schema import TorsenBFile
from drivedyn.model.spec import ModelError, Spec

Z = (0.0, 0.0, 1.0)
MZ = (0.0, 0.0, -1.0)
WASHERS = ("left", "middle", "right")

#: the four locking modes: (number, name, favoured = loaded output, drive?)
MODES = (
    (1, "drive, bias right", "right", True),
    (2, "coast, bias right", "right", False),
    (3, "drive, bias left", "left", True),
    (4, "coast, bias left", "left", False),
)


def washer_friction_radius(r_int: float, r_ext: float) -> float:
    """r_m = 2 (r_ext^3 - r_int^3) / (3 (r_ext^2 - r_int^2)) [m] (uniform pressure)."""
    return 2 * (r_ext**3 - r_int**3) / (3 * (r_ext**2 - r_int**2)) if r_ext > r_int else 0.0


@dataclass(frozen=True)
class Geometry:
    """Derived geometry [m, rad] of a parameter set.

    Attributes:
        r_side, r_element: reference (pitch) radii.
        r_tip_element: element-gear tip radius (addendum = module).
        r_root_element: element-gear root radius (dedendum 1.25 module): the relieved middle.
        centre: distance of the element-gear axes from the main axis (``r_side + r_element``).
        spread: angle between the two element gears of a pair seen from the main axis
            (their centres are ``2 r_element`` apart).
        z_side: axial position of the right side gear's centre (the left one at ``-z_side``).
        z_end: axial position of the right end mesh (the left one at ``-z_end``).
        length: element-gear length between its end faces.
        hand: +1 right-hand left side gear, -1 left-hand.
        washer_radius: friction radius of each washer (name -> m), and ``"end"`` of the
            element-gear end faces.
        eps_side, eps_end: transverse contact ratios of the side and end meshes.
    """

    r_side: float
    r_element: float
    r_tip_element: float
    r_root_element: float
    centre: float
    spread: float
    z_side: float
    z_end: float
    length: float
    hand: float
    washer_radius: dict[str, float]
    eps_side: float
    eps_end: float

    def element_angles(self, pairs: int) -> list[tuple[float, float]]:
        """(angle of a{k}, angle of b{k}) [rad] about z of each pair's element gears."""
        return [(2 * math.pi * k / pairs - self.spread / 2,
                 2 * math.pi * k / pairs + self.spread / 2) for k in range(pairs)]


def geometry(p: TorsenBFile) -> Geometry:
    """The derived geometry of ``p`` (no checks; see :func:`check_parameters`)."""
    g = p.gears
    cb = math.cos(g.helix_angle)
    rs, re = (z * g.module / (2 * cb) for z in (g.teeth_side, g.teeth_element))
    a = rs + re
    spread = 2 * math.asin(min(1.0, re / a))
    z_side = g.side_gap / 2 + g.face_width / 2
    z_end = g.side_gap / 2 + g.face_width + g.end_width / 2
    length = g.side_gap + 2 * g.face_width + 2 * g.end_width
    w = p.washers
    wr = {n: washer_friction_radius(getattr(w, n).r_int, getattr(w, n).r_ext) for n in WASHERS}
    wr["end"] = washer_friction_radius(p.pockets.end_r_int, p.pockets.end_r_ext)
    beta = abs(g.helix_angle)
    side = CylindricalPair.build(g.teeth_side, g.teeth_element, g.module, g.pressure_angle, beta)
    end = CylindricalPair.build(g.teeth_element, g.teeth_element, g.module, g.pressure_angle,
                                beta)
    return Geometry(rs, re, re + g.module, re - 1.25 * g.module, a, spread, z_side, z_end,
                    length, 1.0 if g.helix_angle >= 0 else -1.0, wr, float(side.eps_alpha),
                    float(end.eps_alpha))


def check_parameters(p: TorsenBFile) -> Geometry:
    """Refuse inconsistent or impossible parameter sets (:class:`ModelError` naming the key,
    the value and what is expected); returns the geometry."""
    g = p.gears

    def fail(key: str, value: Any, msg: str) -> None:
        raise ModelError(f"torsen_b: {key} = {value!r}: {msg}")

    # the angles first: the geometry (involutes of the pressure angle) needs them in range
    if not 0 < abs(g.helix_angle) < math.radians(45):
        fail("gears.helix_angle", g.helix_angle, "expected 0 < |beta| < 45 deg (helical gears "
             "make the thrusts that lock the differential)")
    if not math.radians(14) <= g.pressure_angle <= math.radians(30):
        fail("gears.pressure_angle", g.pressure_angle, "expected 14..30 deg")
    geo = geometry(p)
    z_lim = undercut_limits(g.teeth_element, g.pressure_angle, abs(g.helix_angle))[0]
    if g.teeth_element < 5 / 6 * z_lim:
        fail("gears.teeth_element", g.teeth_element, f"undercut: at least "
             f"{math.ceil(5 / 6 * z_lim)} teeth at gears.pressure_angle = "
             f"{g.pressure_angle:.4g} rad and gears.helix_angle = {g.helix_angle:.4g} rad "
             "without profile shift (DIN 3960 practical limit 5/6 z_g)")
    if g.teeth_element >= g.teeth_side:
        fail("gears.teeth_element", g.teeth_element, f"expected fewer teeth than the side gears "
             f"(gears.teeth_side = {g.teeth_side}): the pairs must fit around them")
    for key, eps in (("side", geo.eps_side), ("end", geo.eps_end)):
        if eps < 1.1:
            fail("gears.teeth_element", g.teeth_element, f"transverse contact ratio of the "
                 f"{key} meshes {eps:.2f} < 1.1 (with gears.teeth_side = {g.teeth_side}, "
                 f"gears.pressure_angle = {g.pressure_angle:.4g} rad, gears.helix_angle = "
                 f"{g.helix_angle:.4g} rad)")
    # the relieved middle of an element gear must clear the other side gear's tips
    clear = geo.centre - (geo.r_side + g.module) - geo.r_root_element
    if clear <= 0:
        fail("gears.teeth_element", g.teeth_element, "the element gear's relieved middle "
             f"(root radius) hits the other side gear's tips ({clear * 1e3:.2f} mm)")
    # neighbouring pockets of two pairs must not overlap
    gap_angle = 2 * math.pi / g.pairs - geo.spread
    gap = 2 * geo.centre * math.sin(gap_angle / 2) - 2 * (geo.r_tip_element + p.pockets.clearance)
    if gap_angle <= 0 or gap <= 0:
        fail("gears.pairs", g.pairs, f"the pockets of neighbouring pairs overlap "
             f"({gap * 1e3:.2f} mm with pockets.clearance = {p.pockets.clearance!r}); fewer "
             "pairs or smaller element gears")
    # the two pockets of a pair are joined where the element gears mesh; the housing webs
    # between the pairs carry the load
    w = p.washers
    for name in WASHERS:
        f = getattr(w, name)
        if f.r_int >= f.r_ext:
            fail(f"washers.{name}.r_int", f.r_int, f"must be < r_ext = {f.r_ext!r}")
        if f.r_ext > geo.r_side - 1.25 * g.module:
            fail(f"washers.{name}.r_ext", f.r_ext, "outside the side gear's root circle "
                 f"{(geo.r_side - 1.25 * g.module) * 1e3:.2f} mm (gears.teeth_side = "
                 f"{g.teeth_side}, gears.module = {g.module!r}: the face would cut the teeth)")
    if w.middle.gap >= g.side_gap:
        fail("washers.middle.gap", w.middle.gap, f"must be < gears.side_gap = {g.side_gap!r} "
             "(the middle washer fills the space between the side gears)")
    fx = p.flexible
    if fx.washers and fx.washer_thickness > g.side_gap - w.middle.gap:
        fail("flexible.washer_thickness", fx.washer_thickness, "the flexible middle washer "
             f"must fit between the side gears (<= gears.side_gap - washers.middle.gap = "
             f"{(g.side_gap - w.middle.gap) * 1e3:.2f} mm)")
    if fx.washers and w.squeeze_film:
        fail("washers.squeeze_film", w.squeeze_film, "false with flexible.washers = true "
             "(the oil film is not coupled to a flexible washer's face)")
    pk = p.pockets
    if pk.end_r_int >= pk.end_r_ext:
        fail("pockets.end_r_int", pk.end_r_int, f"must be < end_r_ext = {pk.end_r_ext!r}")
    if pk.end_r_ext > geo.r_root_element:
        fail("pockets.end_r_ext", pk.end_r_ext, "outside the element gear's root radius "
             f"{geo.r_root_element * 1e3:.2f} mm (gears.teeth_element = {g.teeth_element}, "
             f"gears.module = {g.module!r})")
    if pk.clearance > 0.2 * g.module:
        fail("pockets.clearance", pk.clearance, "expected a small radial clearance "
             f"(< 0.2 gears.module = {0.2 * g.module * 1e3:.3f} mm)")
    if g.backlash > 0.1 * g.module:
        fail("gears.backlash", g.backlash, f"expected < 0.1 gears.module = {0.1 * g.module:.2e} m")
    return geo


# -- building ----------------------------------------------------------------------------


def _friction(mu: float, p: TorsenBFile, scale: float) -> FrictionLaw | None:
    m = mu * scale
    return FrictionLaw(m, p.contact.eps_v) if m > 0 else None


def _law(p: TorsenBFile) -> NormalLaw:
    """Normal law of the pocket contacts (bores and end faces)."""
    return p.contact.law_of()


def _washer(sp: Spec, p: TorsenBFile, name: str, marker_a: str, marker_b: str, r_int: float,
            r_ext: float, friction) -> None:
    w = p.washers
    law = p.contact.washer_law(r_int, r_ext)
    if w.squeeze_film:
        sp.add(SqueezeFilm(name, marker_a, marker_b, viscosity=w.viscosity, r_int=r_int,
                           r_ext=r_ext, roughness=p.contact.elastic_washers.roughness, contact=law,
                           friction=friction, cavitation=True))
    else:
        sp.add(ThrustWasherContact(name, marker_a, marker_b, law=law, r_int=r_int,
                                   r_ext=r_ext, friction=friction))


def pocket_film(p: TorsenBFile, geo: Geometry, name: str, bore: str, pin: str) -> JournalFilm:
    """The oil film in the pocket of one element gear (``pockets.oil_film``).

    The element gear's tips are the film's lands: ``teeth_element`` lands of the top land's
    width normal to the tooth trace, each of length (the toothed length: the end meshes and
    the side mesh, not the relieved middle nor the side gap) / cos(tip helix angle); the
    oil is the washers' (``washers.viscosity``). The film floor is the clearance of the lands
    next to a land that touches the bore, ``c (1 - cos(2 pi / z))``: a touching land's film
    does not squeeze (its asperities carry the load) and the film damps metal contact
    through its neighbours only.
    """
    g, pk = p.gears, p.pockets
    land, beta_a = top_land(g.teeth_element, g.module, g.pressure_angle, g.helix_angle)
    toothed = 2 * g.end_width + g.face_width
    return JournalFilm(name, bore, pin, viscosity=p.washers.viscosity,
                       length=toothed / math.cos(beta_a),
                       bore_radius=geo.r_tip_element + pk.clearance,
                       pin_radius=geo.r_tip_element, lands=g.teeth_element, land_width=land,
                       min_film=pk.clearance * (1 - math.cos(2 * math.pi / g.teeth_element)))


def build_spec(p: TorsenBFile, omega: tuple[float, float, float] = (0.0, 0.0, 0.0),
               friction_scale: float = 1.0) -> tuple[Spec, Geometry]:
    """The differential without loads or drivers.

    Args:
        p: validated parameters.
        omega: initial speeds (housing, left, right) [rad/s] about +z; the element gears'
            spins follow from the left side gear so that the meshes start unloaded.
        friction_scale: factor on every friction coefficient (washers, pockets, teeth).
    Returns:
        (spec, geometry). Joints: ``housing_bearing`` (hinge), ``left_bearing`` and
        ``right_bearing`` (cylindrical, to the ground), ``{a,b}{k}_guide`` (parallel axes).
    """
    geo = check_parameters(p)
    g, B, w, pk = p.gears, p.bodies, p.washers, p.pockets
    wh, wl, _ = omega
    sp = Spec()
    zs = geo.z_side
    sp.add_rigid_body("housing", B.housing.mass, B.housing.inertia, angular_velocity=(0, 0, wh))
    sp.add_marker("g_housing", "ground", axis=Z)
    sp.add_marker("b_housing", "housing", axis=Z)
    sp.add(Hinge("housing_bearing", "g_housing", "b_housing"))
    for name, z, speed in (("left", -zs, omega[1]), ("right", zs, omega[2])):
        sp.add_rigid_body(name, B.side.mass, B.side.inertia, position=(0, 0, z),
                          angular_velocity=(0, 0, speed))
        sp.add_marker(f"g_{name}", "ground", position=(0, 0, z), axis=Z)
        sp.add_marker(f"b_{name}", name, axis=Z)
        sp.add(Cylindrical(f"{name}_bearing", f"g_{name}", f"b_{name}"))
    mesh_kw = dict(module=g.module, pressure_angle=g.pressure_angle,
                   damping_ratio=g.damping_ratio, stiffness=g.stiffness,
                   youngs_modulus=g.youngs_modulus, stiffness_variation=g.stiffness_variation,
                   backlash=g.backlash, flank_onset=g.flank_onset,
                   friction=g.tooth_friction * friction_scale)
    beta_l = g.helix_angle
    ratio = g.teeth_side / g.teeth_element
    w_rel = (wl - wh) * ratio  # spin of b relative to the housing (a: the opposite)
    tip, end = _friction(pk.mu, p, friction_scale), _friction(pk.mu, p, friction_scale)
    half = geo.length / 2
    for k, (tha, thb) in enumerate(geo.element_angles(g.pairs)):
        for el, th, side, z_mesh, beta, spin in (
                ("a", tha, "left", -zs, -beta_l, -w_rel), ("b", thb, "right", zs, beta_l, w_rel)):
            name = f"{el}{k + 1}"
            pos = np.array([geo.centre * math.cos(th), geo.centre * math.sin(th), 0.0])
            sp.add_rigid_body(name, B.element.mass, B.element.inertia, position=pos,
                              velocity=wh * np.cross(Z, pos), angular_velocity=(0, 0, wh + spin))
            sp.add_marker(f"pocket_{name}", "housing", position=pos, axis=Z)
            sp.add_marker(f"m_{name}", name, axis=Z)
            sp.add(ParallelAxes(f"{name}_guide", f"pocket_{name}", f"m_{name}"))
            sp.add(JournalContact(f"{name}_pocket", f"pocket_{name}", f"m_{name}",
                                  law=_law(p), bore_radius=geo.r_tip_element + pk.clearance,
                                  pin_radius=geo.r_tip_element, friction=tip))
            if pk.oil_film:
                sp.add(pocket_film(p, geo, f"{name}_film", f"pocket_{name}", f"m_{name}"))
            # end faces on the pocket floors
            add_end_faces(sp, name, pos, half, pk.end_gap, pk.end_r_int, pk.end_r_ext,
                          _law(p), end, tags=("l", "r"))
            # side mesh, in the side gear's mid-face plane
            sp.add_marker(f"ms_{name}", name, position=(0, 0, z_mesh), axis=Z)
            phase = (g.teeth_side * th / (2 * math.pi)) % 1.0
            sp.add(GearPair(f"{side}_{name}", f"b_{side}", f"ms_{name}", g.teeth_side,
                            g.teeth_element, face_width=g.face_width,
                            helix_angle=-beta, mesh_phase=phase, **mesh_kw))
            for tag, ze in (("l", -geo.z_end), ("r", geo.z_end)):
                sp.add_marker(f"me_{name}{tag}", name, position=(0, 0, ze), axis=Z)
        for tag in ("l", "r"):
            sp.add(GearPair(f"a{k + 1}_b{k + 1}_{tag}", f"me_a{k + 1}{tag}", f"me_b{k + 1}{tag}",
                            g.teeth_element, g.teeth_element, face_width=g.end_width,
                            helix_angle=-beta_l, **mesh_kw))
    # thrust washers (marker A = washer face, z = normal towards the face of marker B)
    fw = _friction(w.mu, p, friction_scale)
    hb = g.face_width / 2
    # washer face: (body, z in its frame, normal along z); counter face: (body, z)
    faces = {
        "left": (("housing", -zs - hb - w.left.gap, 1.0), ("left", -hb)),
        "right": (("housing", zs + hb + w.right.gap, -1.0), ("right", hb)),
        # the middle washer turns with the left gear and fills the side gap but for its play
        "middle": (("left", hb + g.side_gap - w.middle.gap, 1.0), ("right", -hb)),
    }
    for name in WASHERS:
        f = getattr(w, name)
        (ba, za, normal), (bb, zb) = faces[name]
        if p.flexible.washers:
            add_flexible_washer(sp, p.flexible, p.contact, name, ba, za, normal, bb, zb,
                                f.r_int, f.r_ext, fw)
            continue
        sp.add_marker(f"w_{name}", ba, position=(0, 0, za), axis=(0.0, 0.0, normal))
        sp.add_marker(f"f_{name}", bb, position=(0, 0, zb), axis=Z)
        _washer(sp, p, name, f"w_{name}", f"f_{name}", f.r_int, f.r_ext, fw)
    _visuals(sp, p, geo)
    return sp, geo


def _visuals(sp: Spec, p: TorsenBFile, geo: Geometry) -> None:
    """Shapes of the bodies that no element draws, for the 3-D viewer: the housing as a
    semi-transparent shell around the element gears with end walls, and stubs of the two
    output shafts. Wall thickness and shaft lengths are illustrative (the model carries no
    such data)."""
    g, w = p.gears, p.washers
    hb = g.face_width / 2
    r_in = geo.centre + geo.r_tip_element + p.pockets.clearance + 0.5 * g.module
    wall = max(2.0 * g.module, 0.08 * geo.centre)
    z0 = geo.z_side + hb + max(w.left.gap, w.right.gap)
    sp.add_visual(cylinder("b_housing", r_in + wall, 2 * z0, inner_radius=r_in,
                           role="housing", label="housing"))
    for z in (-z0 - wall, z0):
        sp.add_visual(cylinder("b_housing", r_in + wall, wall, z0=z,
                               inner_radius=0.35 * geo.r_side, role="housing",
                               label="housing"))
    shaft = 1.0 * r_in
    sp.add_visual(cylinder("b_left", 0.3 * geo.r_side, shaft, z0=-hb - shaft, role="shaft",
                           label="left output"))
    sp.add_visual(cylinder("b_right", 0.3 * geo.r_side, shaft, z0=hb, role="shaft",
                           label="right output"))
