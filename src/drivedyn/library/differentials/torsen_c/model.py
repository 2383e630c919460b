"""Parametric TORSEN Type C (epicyclic, central) differential, after seed 003.

Parts (axis = global z, front = -z, forward rotation = +z)::

    housing   carrier with one pocket per planet; hinge to the ground (the gearbox)
    case      bolted to the housing (fixed joint); carries the rear thrust washers
    sun       front output; cylindrical joint to the ground bearing (turns, slides)
    planets   in the housing pockets: parallel-axes joint (held against tilting), radial
              load and tip friction by a JournalContact with the pocket bore, axial load
              and end-face friction by ThrustWasherContacts on the two pocket floors
              (``pockets.end_faces``; off: a planar joint holds them axially)
    ring      internal gear; helical spline to the coupling (the seeds' screw joint)
    coupling  rear output; cylindrical joint to the ground bearing

Gear pairs: sun-planet (external) and planet-ring (internal) for each planet: 2 n meshes
(8 for the seeds' four planets), ISO 6336 stiffness, helical.

Thrust washers (rigid, continuous contact law, friction on the face with the lower
coefficient; the washer is part of the body on its other face, as in the seeds)::

    W1 sun_housing     sun front face   on the housing washer     (relative spin sun - housing)
    W2 sun_coupling    sun rear washer  on the coupling front face (sun - coupling)
    W3 coupling_case   coupling rear    on the case washer         (coupling - housing)
    W4 ring_housing    ring front face  on the housing washer      (ring - housing)
    W5 ring_case       ring rear face   on the case washer         (ring - housing)

Thrust paths. A right-hand sun (``gears.helix_angle > 0``) is pushed to the front when it
drives forward (drive); the ring's mesh thrust is opposite. The torque through the helical
spline pushes the coupling the same way as the sun and the ring the other way, so the sun
and the coupling always travel together (seed 003, Fig. 11) and stay in contact:

    drive (sun, coupling -> front):  W1 = A_s + A_c,  W2 = A_c,  W5 = A_r + A_c
    coast (sun, coupling -> rear):   W2 = A_s,  W3 = A_s + A_c,  W4 = A_r + A_c

with ``A_s``, ``A_r`` the mesh thrusts of sun and ring (F_t tan beta summed over the planets)
and ``A_c = 2 pi T_spline / lead`` the spline thrust. A left-hand set mirrors this (drive and
coast exchange their washers); spline and sun must have the same hand.

The model is built from a validated :class:`~.schema.TorsenCFile` (the shipped ``torsen-c``
file); the bench and vehicle scenarios are the shared ones of
:mod:`drivedyn.library.differentials.scenarios`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from drivedyn.elements import (
    Cylindrical,
    Fixed,
    GearPair,
    Hinge,
    ParallelAxes,
    Planar,
    Prismatic,
    Screw,
)
from drivedyn.elements.contact import FrictionLaw, JournalContact, NormalLaw, ThrustWasherContact
from drivedyn.elements.contact.common import washer_friction_radius
from drivedyn.elements.contact.squeeze_film import SqueezeFilm
from drivedyn.elements.framework.visuals import cylinder
from drivedyn.elements.gears.geometry import undercut_limits
from drivedyn.library.differentials.end_faces import add_end_faces
from drivedyn.library.differentials.flexible_washers import add_flexible_washer
from drivedyn.library.differentials.torsen_c.schema import TorsenCFile
from drivedyn.model.spec import ModelError, Spec

Z = (0.0, 0.0, 1.0)
MZ = (0.0, 0.0, -1.0)
WASHERS = ("sun_housing", "sun_coupling", "coupling_case", "ring_housing", "ring_case")
COUPLING_LENGTH = 0.03  # axial length of the coupling hub [m] (position of its rear face)

#: the four locking modes: (number, name, loaded output, drive?)
MODES = (
    (1, "drive, bias rear", "rear", True),
    (2, "coast, bias rear", "rear", False),
    (3, "drive, bias front", "front", True),
    (4, "coast, bias front", "front", False),
)


@dataclass(frozen=True)
class Geometry:
    """Derived geometry [m, rad] of a parameter set.

    Attributes:
        r_sun, r_planet, r_ring: reference (pitch) radii.
        r_tip_planet: planet tip radius (addendum = module).
        carrier_radius: distance of the planet axes from the main axis.
        rho: z_ring / z_sun (nominal rear/front torque ratio).
        lead: spline lead [m/rev], signed like the spline helix (inf: straight spline).
        hand: +1 right-hand sun, -1 left-hand.
        washer_radius: friction radius r_m of each washer (name -> m).
        r_end: friction radius of a planet's end face on its pocket floor (0 without
            ``pockets.end_faces``).
    """

    r_sun: float
    r_planet: float
    r_ring: float
    r_tip_planet: float
    carrier_radius: float
    rho: float
    lead: float
    hand: float
    washer_radius: dict[str, float]
    r_end: float = 0.0


def geometry(p: TorsenCFile) -> Geometry:
    """The derived geometry of ``p`` (no checks; see :func:`check_parameters`)."""
    g = p.gears
    cb = math.cos(g.helix_angle)
    rs, rp, rr = (z * g.module / (2 * cb) for z in (g.teeth_sun, g.teeth_planet, g.teeth_ring))
    ts = math.tan(p.spline.helix_angle)
    lead = 2 * math.pi * p.spline.radius / ts if ts != 0 else math.inf
    def r_m(r_int: float, r_ext: float) -> float:  # 0 for an annulus check_parameters refuses
        return washer_friction_radius(r_int, r_ext) if r_ext > r_int else 0.0

    wr = {name: r_m(getattr(p.washers, name).r_int, getattr(p.washers, name).r_ext)
          for name in WASHERS}
    pk = p.pockets
    r_end = r_m(pk.end_r_int, pk.end_r_ext) if pk.end_faces else 0.0
    return Geometry(rs, rp, rr, rp + g.module, rs + rp, g.teeth_ring / g.teeth_sun, lead,
                    1.0 if g.helix_angle >= 0 else -1.0, wr, r_end)


def check_parameters(p: TorsenCFile) -> Geometry:
    """Refuse inconsistent or impossible parameter sets (:class:`ModelError` naming the key,
    the value and what is expected); returns the geometry."""
    g = p.gears
    geo = geometry(p)

    def fail(key: str, value: Any, msg: str) -> None:
        raise ModelError(f"torsen_c: {key} = {value!r}: {msg}")

    if g.teeth_ring != g.teeth_sun + 2 * g.teeth_planet:
        fail("gears.teeth_ring", g.teeth_ring,
             f"must equal teeth_sun + 2 teeth_planet = {g.teeth_sun + 2 * g.teeth_planet} "
             "(coaxial set without profile shift)")
    if (g.teeth_sun + g.teeth_ring) % g.planets:
        fail("gears.planets", g.planets,
             f"(teeth_sun + teeth_ring) = {g.teeth_sun + g.teeth_ring} must be divisible by the "
             "number of planets for equally spaced planets")
    if not 0 < abs(g.helix_angle) < math.radians(45):
        fail("gears.helix_angle", g.helix_angle, "expected 0 < |beta| < 45 deg (helical gears "
             "make the thrusts that lock the differential)")
    if not math.radians(10) < g.pressure_angle < math.radians(30):
        fail("gears.pressure_angle", g.pressure_angle, "expected 10..30 deg")
    # the external wheels without profile shift: the gear element's undercut limit
    for key in ("teeth_sun", "teeth_planet"):
        z = getattr(g, key)
        z_lim = undercut_limits(z, g.pressure_angle, abs(g.helix_angle))[0]
        if z < 5 / 6 * z_lim:
            fail(f"gears.{key}", z, f"undercut: at least {math.ceil(5 / 6 * z_lim)} teeth at "
                 f"gears.pressure_angle = {g.pressure_angle:.4g} rad and gears.helix_angle = "
                 f"{g.helix_angle:.4g} rad without profile shift (DIN 3960 practical limit "
                 "5/6 z_g)")
    gap = 2 * geo.carrier_radius * math.sin(math.pi / g.planets) - 2 * (
        geo.r_tip_planet + p.pockets.clearance)
    if gap <= 0:
        fail("gears.planets", g.planets, f"the pockets overlap ({gap * 1e3:.2f} mm between "
             f"neighbouring pockets, with gears.module = {g.module!r} and pockets.clearance = "
             f"{p.pockets.clearance!r}); fewer or smaller planets")
    if p.spline.helix_angle != 0 and math.copysign(1, p.spline.helix_angle) != geo.hand:
        fail("spline.helix_angle", p.spline.helix_angle,
             "must have the hand (sign) of gears.helix_angle so that the spline pushes the "
             "coupling with the sun (else the sun leaves the coupling)")
    if abs(p.spline.helix_angle) >= math.radians(60):
        fail("spline.helix_angle", p.spline.helix_angle, "expected |angle| < 60 deg")
    if p.spline.radius <= geo.r_ring:
        fail("spline.radius", p.spline.radius, f"must exceed the ring pitch radius "
             f"{geo.r_ring * 1e3:.2f} mm (gears.teeth_ring = {g.teeth_ring}, gears.module = "
             f"{g.module!r}; the spline is on the outside of the internal gear)")
    for name in WASHERS:
        w = getattr(p.washers, name)
        if w.r_int >= w.r_ext:
            fail(f"washers.{name}.r_int", w.r_int, f"must be < r_ext = {w.r_ext!r}")
    for name in ("sun_housing", "sun_coupling"):
        w = getattr(p.washers, name)
        if w.r_ext > geo.r_sun + g.module:
            fail(f"washers.{name}.r_ext", w.r_ext, "larger than the sun gear's tip radius "
                 f"{(geo.r_sun + g.module) * 1e3:.2f} mm (gears.teeth_sun = {g.teeth_sun}, "
                 f"gears.module = {g.module!r})")
    for name in ("ring_housing", "ring_case"):
        w = getattr(p.washers, name)
        if w.r_int < geo.r_ring - g.module:
            fail(f"washers.{name}.r_int", w.r_int, "inside the ring's tip circle "
                 f"{(geo.r_ring - g.module) * 1e3:.2f} mm (gears.teeth_ring = {g.teeth_ring}, "
                 f"gears.module = {g.module!r}: the face would cut the teeth)")
        if w.r_ext > p.spline.radius:
            fail(f"washers.{name}.r_ext", w.r_ext, "outside the internal gear, whose outer "
                 f"radius is the spline radius {p.spline.radius * 1e3:.2f} mm")
    if g.backlash > 0.1 * g.module:
        fail("gears.backlash", g.backlash, f"expected < 0.1 gears.module = {0.1 * g.module:.2e} m")
    pk = p.pockets
    if pk.end_faces:
        if pk.end_r_int >= pk.end_r_ext:
            fail("pockets.end_r_int", pk.end_r_int, f"must be < end_r_ext = {pk.end_r_ext!r}")
        root = geo.r_planet - 1.25 * g.module
        if pk.end_r_ext > root:
            fail("pockets.end_r_ext", pk.end_r_ext, "outside the planet's root radius "
                 f"{root * 1e3:.2f} mm (gears.teeth_planet = {g.teeth_planet}, gears.module = "
                 f"{g.module!r}): the end face is the planet's body inside its teeth")
    if p.pockets.clearance > 0.2 * g.module:
        fail("pockets.clearance", p.pockets.clearance, "expected a small radial clearance "
             f"(< 0.2 gears.module = {0.2 * g.module * 1e3:.3f} mm)")
    return geo


# -- building ----------------------------------------------------------------------------


def _friction(mu: float, p: TorsenCFile, scale: float) -> FrictionLaw | None:
    m = mu * scale
    return FrictionLaw(m, p.contact.eps_v) if m > 0 else None


def _law(p: TorsenCFile) -> NormalLaw:
    """Normal law of the pocket contacts."""
    return p.contact.law_of()


def build_spec(p: TorsenCFile, omega: tuple[float, float, float] = (0.0, 0.0, 0.0),
               friction_scale: float = 1.0) -> tuple[Spec, Geometry]:
    """The differential without loads or drivers.

    Args:
        p: validated parameters.
        omega: initial speeds (housing, sun, coupling) [rad/s] about +z; the planets' spin
            follows from Willis' equation so that the meshes start unloaded.
        friction_scale: factor on every friction coefficient (washers, pockets, teeth).
    Returns:
        (spec, geometry). Joints: ``housing_bearing`` (hinge), ``sun_bearing`` and
        ``coupling_bearing`` (cylindrical, to the ground), ``spline`` (screw ring/coupling).
    """
    geo = check_parameters(p)
    g, b = p.gears, p.gears.face_width
    wh, ws, wc = omega
    n = g.planets
    sp = Spec()
    B = p.bodies
    half = b / 2
    w = p.washers
    zc = half + w.sun_coupling.gap + COUPLING_LENGTH / 2
    sp.add_rigid_body("housing", B.housing.mass, B.housing.inertia,
                      angular_velocity=(0, 0, wh))
    if not p.flexible.case:
        sp.add_rigid_body("case", B.case.mass, B.case.inertia, position=(0, 0, zc),
                          angular_velocity=(0, 0, wh))
    sp.add_rigid_body("sun", B.sun.mass, B.sun.inertia, angular_velocity=(0, 0, ws))
    sp.add_rigid_body("ring", B.ring.mass, B.ring.inertia, angular_velocity=(0, 0, wc))
    sp.add_rigid_body("coupling", B.coupling.mass, B.coupling.inertia, position=(0, 0, zc),
                      angular_velocity=(0, 0, wc))
    # bearings and fixings
    sp.add_marker("g_housing", "ground", axis=Z)
    sp.add_marker("b_housing", "housing", axis=Z)
    sp.add(Hinge("housing_bearing", "g_housing", "b_housing"))
    fx = p.flexible
    for name, z, shaft, sign, speed in (("sun", 0.0, fx.shaft_front, -1.0, ws),
                                        ("coupling", zc, fx.shaft_rear, 1.0, wc)):
        if fx.shafts:
            _output_shaft(sp, p, name, z, shaft, sign, speed)
            continue
        sp.add_marker(f"g_{name}", "ground", position=(0, 0, z), axis=Z)
        sp.add_marker(f"b_{name}", name, axis=Z)
        sp.add(Cylindrical(f"{name}_bearing", f"g_{name}", f"b_{name}"))
    if not p.flexible.case:
        sp.add_marker("h_case", "housing", position=(0, 0, zc), axis=Z)
        sp.add_marker("c_case", "case", axis=Z)
        sp.add(Fixed("case_bolts", "h_case", "c_case"))
    sp.add_marker("cp_spline", "coupling", position=(0, 0, -zc), axis=Z)
    sp.add_marker("r_spline", "ring", axis=Z)
    if math.isinf(geo.lead):
        sp.add(Prismatic("spline", "cp_spline", "r_spline"))
    else:
        sp.add(Screw("spline", "cp_spline", "r_spline", pitch=geo.lead,
                     friction=p.spline.mu * friction_scale, radius=p.spline.radius,
                     stick_stiffness=p.spline.stick_stiffness,
                     stick_onset=p.spline.stick_onset))
    # gear markers
    sp.add_marker("m_sun", "sun", axis=Z)
    sp.add_marker("m_ring", "ring", axis=Z)
    a = geo.carrier_radius
    gear_kw = dict(module=g.module, face_width=b, pressure_angle=g.pressure_angle,
                   damping_ratio=g.damping_ratio, stiffness=g.stiffness,
                   youngs_modulus=g.youngs_modulus, stiffness_variation=g.stiffness_variation,
                   backlash=g.backlash, flank_onset=g.flank_onset,
                   friction=g.tooth_friction * friction_scale)
    wp = wh - (ws - wh) * g.teeth_sun / g.teeth_planet  # Willis, planet spin
    for k in range(n):
        th = 2 * math.pi * k / n
        pos = np.array([a * math.cos(th), a * math.sin(th), 0.0])
        vel = wh * np.cross(Z, pos)
        pl = f"planet{k + 1}"
        sp.add_rigid_body(pl, B.planet.mass, B.planet.inertia, position=pos, velocity=vel,
                          angular_velocity=(0, 0, wp))
        sp.add_marker(f"pocket{k + 1}", "housing", position=pos, axis=Z)
        sp.add_marker(f"m_{pl}", pl, axis=Z)
        pocket_friction = _friction(p.pockets.mu, p, friction_scale)
        if p.pockets.end_faces:
            sp.add(ParallelAxes(f"{pl}_guide", f"pocket{k + 1}", f"m_{pl}"))
            _end_faces(sp, p, pl, pos, b / 2, pocket_friction)
        else:
            sp.add(Planar(f"{pl}_guide", f"pocket{k + 1}", f"m_{pl}"))
        sp.add(JournalContact(f"{pl}_pocket", f"pocket{k + 1}", f"m_{pl}", law=_law(p),
                              bore_radius=geo.r_tip_planet + p.pockets.clearance,
                              pin_radius=geo.r_tip_planet, friction=pocket_friction))
        # mesh phases of a planet at th: the sun's and the ring's teeth passed since planet 1
        sp.add(GearPair(f"sun_{pl}", "m_sun", f"m_{pl}", g.teeth_sun, g.teeth_planet,
                        helix_angle=g.helix_angle, mesh_phase=(g.teeth_sun * k / n) % 1.0,
                        **gear_kw))
        sp.add(GearPair(f"{pl}_ring", f"m_{pl}", "m_ring", g.teeth_planet, g.teeth_ring,
                        helix_angle=-g.helix_angle, internal="b",
                        mesh_phase=(g.teeth_ring * k / n) % 1.0, **gear_kw))
    # thrust washers: marker A = washer face (z = normal towards B), marker B = the other face
    faces = {
        "sun_housing": (("housing", -half - w.sun_housing.gap, Z), ("sun", -half)),
        "sun_coupling": (("sun", half, Z), ("coupling", half + w.sun_coupling.gap)),
        "coupling_case": (("case", zc + COUPLING_LENGTH / 2 + w.coupling_case.gap, MZ),
                          ("coupling", zc + COUPLING_LENGTH / 2)),
        "ring_housing": (("housing", -half - w.ring_housing.gap, Z), ("ring", -half)),
        "ring_case": (("case", half + w.ring_case.gap, MZ), ("ring", half)),
    }
    z_body = {"housing": 0.0, "case": zc, "sun": 0.0, "ring": 0.0, "coupling": zc}
    case = _flexible_case(sp, p, faces) if p.flexible.case else None
    for name in WASHERS:
        (ba, za, axis), (bb, zb) = faces[name]
        wd = getattr(w, name)
        if case is not None and ba == "case":
            _seat_contact(sp, p, name, case, za, bb, zb - z_body[bb],
                          _friction(wd.mu, p, friction_scale))
            continue
        if p.flexible.washers:
            add_flexible_washer(sp, p.flexible, p.contact, name, ba, za - z_body[ba], axis[2],
                                bb, zb - z_body[bb], wd.r_int, wd.r_ext,
                                _friction(wd.mu, p, friction_scale))
            continue
        sp.add_marker(f"w_{name}", ba, position=(0, 0, za - z_body[ba]), axis=axis)
        sp.add_marker(f"f_{name}", bb, position=(0, 0, zb - z_body[bb]), axis=Z)
        sp.add(ThrustWasherContact(name, f"w_{name}", f"f_{name}",
                                   law=p.contact.washer_law(wd.r_int, wd.r_ext),
                                   r_int=wd.r_int, r_ext=wd.r_ext,
                                   friction=_friction(wd.mu, p, friction_scale)))
    _visuals(sp, p, geo, zc, flexible_case=p.flexible.case)
    return sp, geo


def _output_shaft(sp: Spec, p: TorsenCFile, body: str, z: float, shaft, sign: float,
                  speed: float) -> None:
    """Output ``body`` (its centre at ``z`` [m]) on its own bearing (``{body}_support``) and
    its shaft as beams ``{body}_shaft.e*`` out to ``z + sign * shaft.length``, where the
    output's bearing (``{body}_bearing``, the joint the bench and the vehicle drive) and
    its load marker (``b_{body}``) are; ``speed`` [rad/s] about +z at the start."""
    from drivedyn.elements.beams.section import HollowCircular, Material
    from drivedyn.model.beams import add_straight_beam

    fx = p.flexible
    sp.add_marker(f"g_{body}_support", "ground", position=(0, 0, z), axis=Z)
    sp.add_marker(f"s_{body}", body, axis=Z)
    sp.add(Cylindrical(f"{body}_support", f"g_{body}_support", f"s_{body}"))
    tip = z + sign * shaft.length
    nodes = add_straight_beam(
        sp, f"{body}_shaft", (0.0, 0.0, z), (0.0, 0.0, tip), shaft.elements,
        HollowCircular(shaft.outer_diameter, shaft.inner_diameter),
        Material.from_nu(fx.youngs_modulus, fx.poisson_ratio, fx.density),
        damping=fx.shaft_damping, node_a=body, angular_velocity=(0.0, 0.0, speed))
    # the beam nodes' x axis is the shaft axis (sign * global z)
    sp.add_marker(f"g_{body}", "ground", position=(0, 0, tip), axis=Z)
    sp.add_marker(f"b_{body}", nodes[-1], axis=(sign, 0.0, 0.0))
    sp.add(Cylindrical(f"{body}_bearing", f"g_{body}", f"b_{body}"))


def _end_faces(sp: Spec, p: TorsenCFile, planet: str, pos: np.ndarray, half: float,
               friction: FrictionLaw | None) -> None:
    """The planet's two end faces (at ``+-half`` [m] from its centre) on the pocket floors
    of the housing, ``pockets.end_gap`` beyond them, dry or with the oil film
    (``pockets.end_film``). Both floors belong to the housing body: with a flexible case the
    rear floor does not deform with it."""
    pk = p.pockets
    film = None
    if pk.end_film:
        def film(name: str, a: str, b: str) -> SqueezeFilm:
            return SqueezeFilm(name, a, b, viscosity=pk.viscosity, r_int=pk.end_r_int,
                               r_ext=pk.end_r_ext, roughness=p.contact.elastic_washers.roughness,
                               contact=_law(p), friction=friction, cavitation=True)
    add_end_faces(sp, planet, pos, half, pk.end_gap, pk.end_r_int, pk.end_r_ext, _law(p),
                  friction, tags=("f", "r"), film=film)


def _visuals(sp: Spec, p: TorsenCFile, geo: Geometry, zc: float, flexible_case: bool) -> None:
    """Shapes of the bodies that no element draws, for the 3-D viewer: the housing (planet
    carrier) and the case as semi-transparent shells around the ring gear, the coupling hub,
    and stubs of the front (sun) and rear (coupling) output shafts. Wall thicknesses and shaft
    lengths are illustrative (the model carries no such data)."""
    g = p.gears
    m, b = g.module, g.face_width
    r_in = geo.r_ring + 1.5 * m  # outside the ring gear's root
    wall = max(2.0 * m, 0.05 * geo.r_ring)
    front = b / 2 + p.washers.sun_housing.gap + wall
    sp.add_visual(cylinder("b_housing", r_in + wall, front + b / 2, inner_radius=r_in,
                           z0=-front, role="housing", label="housing"))
    sp.add_visual(cylinder("b_housing", r_in + wall, wall, z0=-front, role="housing",
                           inner_radius=0.6 * geo.r_sun, label="housing"))
    if not flexible_case:
        back = COUPLING_LENGTH / 2 + p.washers.coupling_case.gap  # case's rear face, from zc
        sp.add_visual(cylinder("c_case", r_in + wall, back + wall + zc - b / 2,
                               inner_radius=r_in, z0=-(zc - b / 2), role="case",
                               label="case"))
        sp.add_visual(cylinder("c_case", r_in + wall, wall, inner_radius=0.6 * geo.r_sun,
                               z0=back, role="case", label="case"))
    hub = "s_coupling" if p.flexible.shafts else "b_coupling"  # a marker at its centre
    sp.add_visual(cylinder(hub, 0.8 * geo.r_ring, COUPLING_LENGTH,
                           inner_radius=0.3 * geo.r_sun, role="pin", label="coupling",
                           opacity=0.6))
    if p.flexible.shafts:
        return  # the shafts are beams, drawn as such
    shaft = 1.5 * geo.r_ring
    sp.add_visual(cylinder("m_sun", 0.3 * geo.r_sun, shaft, z0=-b / 2 - shaft, role="shaft",
                           label="front output (sun)"))
    sp.add_visual(cylinder("b_coupling", 0.3 * geo.r_sun, shaft, z0=COUPLING_LENGTH / 2,
                           role="shaft", label="rear output (coupling)"))


def case_part(p: TorsenCFile, faces: dict):
    """(solid, reduced part, z of the bolting face [m]) of the flexible case (see
    :class:`~drivedyn.library.differentials.torsen_c.schema.FlexibleParts`): part frame z = 0
    on the bolting face, which is also the ring-gear seat; static modes of the pressures on
    both seats."""
    from drivedyn.fe import (
        Interface,
        SolidMaterial,
        SolidModel,
        craig_bampton,
        face_load_patterns,
        tube,
    )

    f = p.flexible
    w = p.washers
    z0 = faces["ring_case"][0][1]
    z_seat = faces["coupling_case"][0][1] - z0
    t = f.case_plate
    ri, ro = f.case_wall
    nr, nt = f.case_cells
    length = z_seat + t
    flanges = [(0.0, t, f.case_flange_radius), (0.0, t, w.ring_case.r_int),
               (z_seat, length, w.coupling_case.r_int)]
    stations = (w.ring_case.r_int, w.ring_case.r_ext, w.coupling_case.r_int,
                w.coupling_case.r_ext)
    solid = SolidModel(tube(ri, ro, length, flanges, nr, nt, max(3, round(length / t)),
                            r_stations=stations),
                       SolidMaterial(f.youngs_modulus, f.poisson_ratio, f.density))
    bolts = Interface("bolts", solid.select("z", 0.0, r_min=ro), np.zeros(3))
    seats = [solid.select("z", 0.0, w.ring_case.r_int, w.ring_case.r_ext),
             solid.select("z", z_seat, w.coupling_case.r_int, w.coupling_case.r_ext)]
    loads = np.hstack([face_load_patterns(solid, s, friction=f.friction_patterns)
                       for s in seats])
    return solid, craig_bampton(solid, [bolts], f.case_modes, "case", loads=loads), z0


def _flexible_case(sp: Spec, p: TorsenCFile, faces: dict) -> tuple:
    """Mount the flexible case on the housing (bolting face at the ring-gear seat)."""
    from drivedyn.model.flexible import add_flexible_body

    solid, part, z0 = case_part(p, faces)
    sp.add_marker("m_case", "housing", position=(0, 0, z0), axis=Z)
    add_flexible_body(sp, "case", part, "m_case")
    return solid, part, z0


def _seat_contact(sp: Spec, p: TorsenCFile, name: str, case: tuple, za: float, body_b: str,
                  zb: float, friction) -> None:
    """Washer ``name`` on the flexible case: ``body_b``'s face pressed on the case's seat
    nodes (the washer is part of the case, as in the rigid model)."""
    from drivedyn.elements.flexible import FlexibleWasherContact

    solid, _, z0 = case
    wd = getattr(p.washers, name)
    face = solid.select("z", za - z0, wd.r_int, wd.r_ext)
    sp.add_marker(f"f_{name}", body_b, position=(0, 0, zb), axis=Z)
    # the case's mesh carries the seat's elasticity: the law keeps only the rough faces
    sp.add(FlexibleWasherContact(name, "m_case", f"f_{name}", body="case", face=face,
                                 law=p.contact.washer_law(wd.r_int, wd.r_ext, layer=False),
                                 friction=friction))
