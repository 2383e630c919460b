"""The reference differentials of the vehicles: open, locked and clutch-pack limited-slip,
each a bevel-gear differential built from the engine's elements.

Geometry (in the differential's own frame, axis z, the cone apex at the origin): a housing
turning on a hinge to the ground (``housing_bearing``), two side gears (``a`` at -z, ``b`` at
+z), ``spiders`` spider (pinion) gears on radial pins, 2 x spiders straight bevel
:class:`~drivedyn.elements.GearPair` meshes with ISO 6336 stiffness.

* ``open``: side gears on hinges in the housing, spiders pinned in the housing: equal output
  torques whatever the speeds (up to mesh damping).
* ``locked``: the same with the spiders held on their pins (a joint driver at zero angle): the
  side gears turn with the housing, each output takes what its wheel can.
* ``clutch``: a ramp-type (Salisbury) limited-slip differential reduced to its mechanism. The
  spider pins sit in a cross that turns on a ramp against the housing (a :class:`Screw` of
  lead ``2 pi r_r tan(phi)``, ``phi`` the ramp angle from the circumferential direction,
  ``r_r`` its radius): the torque T through the cross pushes it axially with
  ``F_r = T / (r_r tan phi)`` (towards +z for drive, -z for coast) onto the inner face of one
  side gear, which presses its clutch pack against the housing wall. The side gears float
  axially (cylindrical joints); a preload spring pushes them apart onto both packs; the bevel
  meshes add their separating thrust. Each pack is a
  :class:`~drivedyn.elements.ThrustWasherContact` with ``faces`` friction faces of coefficient
  ``mu``; the inner faces have one. The quasi-static split is :func:`clutch_split`.
"""

from __future__ import annotations

import math
import re

import numpy as np

from drivedyn.elements import (
    Cylindrical,
    FrictionLaw,
    GearPair,
    Hinge,
    JointDriver,
    NormalLaw,
    Screw,
    SpringDamper,
    ThrustWasherContact,
)
from drivedyn.elements.gears.geometry import undercut_limits
from drivedyn.errors import ModelError
from drivedyn.model.spec import Spec

Z = (0.0, 0.0, 1.0)


def bevel_geometry(teeth_side: int, teeth_spider: int, module: float) -> dict[str, float]:
    """Cone angles [rad], mean cone distance and marker distances from the apex [m] of the
    side-gear / spider pair (shaft angle 90 deg)."""
    g_side = math.atan2(teeth_side, teeth_spider)
    g_spider = math.atan2(teeth_spider, teeth_side)
    r_side = teeth_side * module / 2
    rm = r_side / math.sin(g_side)
    return {"cone_side": g_side, "cone_spider": g_spider, "cone_distance": rm,
            "z_side": rm * math.cos(g_side), "x_spider": rm * math.cos(g_spider),
            "r_side": r_side, "r_spider": teeth_spider * module / 2}


def clutch_split(p, torque: float, ramp_on_fast: bool = True) -> tuple[float, float]:
    """Quasi-static output torques (fast side, slow side) [N m] of the clutch differential
    ``p`` (a :class:`BevelDifferential` section) at input torque ``torque`` [N m] > 0 with
    the outputs slipping.

    The spiders turn freely, so both meshes carry the same torque ``T_m``; the packs act
    between the side gears and the housing, the inner face between the cross and the side gear
    the ramp pushes (``ramp_on_fast``: the faster one)::

        fast:  T_f = T_m - f_pf - s f_i        slow:  T_s = T_m + f_ps + (1 - s) f_i
        cross: T_x = 2 T_m - (2 s - 1) f_i     ramp:  F_r = T_x / (r_r tan phi)
        f_pf = mu n r_m (F0 + F_r s' + F_g),   F_g = T_m tan(alpha) sin(gamma_side) / r_side

    (``s = 1`` if the ramp pushes the fast side, else 0; the pushed side's pack carries F_r),
    ``f_i = mu r_m F_r``; ``T_f + T_s`` is the input torque. Linear in ``T_m``: solved in
    closed form.
    """
    c = p.clutch
    geo = bevel_geometry(p.teeth_side, p.teeth_spider, p.module)
    rm = 2.0 / 3.0 * (c.r_ext**3 - c.r_int**3) / (c.r_ext**2 - c.r_int**2)
    mp, mi = c.mu * c.faces * rm, c.mu * rm
    kr = 1.0 / (c.ramp_radius * math.tan(c.ramp_angle))
    g = math.tan(p.pressure_angle) * math.sin(geo["cone_side"]) / geo["r_side"]
    s = 1.0 if ramp_on_fast else 0.0
    sig = 2 * s - 1  # the inner face drives (+) or brakes (-) the cross
    # F_r = kr T_x = kr (2 T_m - sig mi F_r)  ->  F_r = a T_m
    a = 2 * kr / (1 + kr * sig * mi)
    def split(tm: float) -> tuple[float, float]:
        f_pf = mp * (c.preload + s * a * tm + g * tm)
        f_ps = mp * (c.preload + (1 - s) * a * tm + g * tm)
        f_i = mi * a * tm
        return tm - f_pf - s * f_i, tm + f_ps + (1 - s) * f_i

    # T_f + T_s is affine in T_m: solve T_f + T_s = torque
    t0, t1 = sum(split(0.0)), sum(split(1.0))
    return split((torque - t0) / (t1 - t0))


def check_mesh(pair: GearPair, section: str, keys: dict[str, str], values: object) -> None:
    """Refuse what the gear element refuses in a mesh built from a file's ``section``,
    naming the key of that section its parameter comes from (``keys``: element parameter
    -> key; ``values``: the section, for the key's value)."""
    try:
        pair.validate()
    except ModelError as exc:
        m = re.match(r"GearPair '[^']*'\.(\w+): (.*)$", str(exc), re.S)
        key = keys.get(m.group(1)) if m else None
        if m is None or key is None:
            raise ModelError(f"{section}: {exc}") from None
        raise ModelError(f"{section}.{key} = {getattr(values, key)!r}: "
                         f"{m.group(2)}") from None


def undercut_shift(teeth: int, cone: float, pressure_angle: float) -> float:
    """Smallest profile shift coefficient of a straight bevel gear of ``teeth`` on a pitch
    cone of ``cone`` [rad] at ``pressure_angle`` [rad] without undercut beyond the practical
    limit (DIN 3960, on Tredgold's virtual spur gear: the check of
    :class:`~drivedyn.elements.GearPair`)."""
    return undercut_limits(teeth / math.cos(cone), pressure_angle)[2]


def check_bevel(p, section: str = "differentials.bevel") -> None:
    """Refuse a bevel differential section ``p`` whose meshes cannot be built: spiders or
    side gears that undercut at its ``profile_shift`` (DIN 3960 practical limit, as
    :class:`~drivedyn.elements.GearPair` checks it), then anything else the gear element
    refuses; :class:`ModelError` naming ``section`` and the key."""
    if not 0.0 < p.pressure_angle < math.radians(45.0):
        raise ModelError(f"{section}.pressure_angle = {p.pressure_angle!r}: expected 0 < "
                         "angle < 45 deg")
    geo = bevel_geometry(p.teeth_side, p.teeth_spider, p.module)
    # the spider takes +x, the side gear -x: the shift is bounded on both sides
    for key, z, cone, sign in (("teeth_spider", p.teeth_spider, geo["cone_spider"], 1.0),
                               ("teeth_side", p.teeth_side, geo["cone_side"], -1.0)):
        x_min = undercut_shift(z, cone, p.pressure_angle)
        if sign * p.profile_shift < x_min - 1e-12:
            bound = (f">= {x_min:.3f}" if sign > 0 else f"<= {-x_min:.3f}")
            raise ModelError(f"{section}.profile_shift = {p.profile_shift!r}: the "
                             f"{key.removeprefix('teeth_')} gears undercut; expected "
                             f"profile_shift {bound} with {section}.teeth_spider = "
                             f"{p.teeth_spider}, {section}.teeth_side = {p.teeth_side} and "
                             f"{section}.pressure_angle = "
                             f"{math.degrees(p.pressure_angle):.4g} deg (DIN 3960 practical "
                             "limit)")
    pair = GearPair("check", "spider", "side", p.teeth_spider, p.teeth_side,
                    cone_angle_a=geo["cone_spider"], cone_angle_b=geo["cone_side"],
                    profile_shift_a=p.profile_shift, profile_shift_b=-p.profile_shift,
                    module=p.module, face_width=p.face_width, pressure_angle=p.pressure_angle,
                    kind="bevel", damping_ratio=p.damping_ratio)
    check_mesh(pair, section, MESH_KEYS, p)


#: the parameters of a spider/side-gear mesh and the keys of the section they come from
MESH_KEYS = {"teeth_a": "teeth_spider", "teeth_b": "teeth_side",
             "profile_shift_a": "profile_shift", "profile_shift_b": "profile_shift",
             "module": "module", "face_width": "face_width",
             "pressure_angle": "pressure_angle", "damping_ratio": "damping_ratio"}


def build_bevel(p, kind: str, omega: float = 0.0) -> Spec:
    """The differential ``kind`` (``"open"``, ``"locked"``, ``"clutch"``) from the section
    ``p`` (:class:`~drivedyn.library.vehicles.vehicle_4wd.schema.BevelDifferential`), every
    body turning at ``omega`` [rad/s] about +z. Outputs: bodies ``a`` (-z) and ``b`` (+z)."""
    if kind not in ("open", "locked", "clutch"):
        raise ModelError(f"bevel differential: kind: expected open, locked or clutch, got "
                         f"{kind!r}")
    geo = bevel_geometry(p.teeth_side, p.teeth_spider, p.module)
    sp = Spec()
    w = np.array([0.0, 0.0, omega])
    B = p.bodies
    sp.add_rigid_body("housing", B.housing.mass, B.housing.inertia, angular_velocity=w)
    sp.add_marker("g_housing", "ground", axis=Z)
    sp.add_marker("b_housing", "housing", axis=Z)
    sp.add(Hinge("housing_bearing", "g_housing", "b_housing"))
    carrier = "housing"
    if kind == "clutch":
        c = p.clutch
        carrier = "cross"
        sp.add_rigid_body("cross", c.cross.mass, c.cross.inertia, angular_velocity=w)
        sp.add_marker("c_cross", "cross", axis=Z)
        lead = 2 * math.pi * c.ramp_radius * math.tan(c.ramp_angle)
        sp.add(Screw("ramp", "b_housing", "c_cross", pitch=lead))
    zs = geo["z_side"]
    gear_kw = dict(module=p.module, face_width=p.face_width, pressure_angle=p.pressure_angle,
                   kind="bevel", damping_ratio=p.damping_ratio)
    for side, sgn in (("a", -1.0), ("b", 1.0)):
        zpos = sgn * zs
        sp.add_rigid_body(side, B.side.mass, B.side.inertia, position=(0, 0, zpos),
                          angular_velocity=w)
        sp.add_marker(f"m_{side}", side, axis=Z)
        sp.add_marker(f"h_{side}", "housing", position=(0, 0, zpos), axis=Z)
        if kind == "clutch":
            sp.add(Cylindrical(f"{side}_bearing", f"h_{side}", f"m_{side}"))
            _packs(sp, p, side, sgn, zpos)
        else:
            sp.add(Hinge(f"{side}_bearing", f"h_{side}", f"m_{side}"))
    if kind == "clutch":
        # preload (Belleville) spring pushing the side gears apart onto their packs
        sp.add(SpringDamper("preload", "m_a", "m_b", stiffness=0.0,
                            preload=-p.clutch.preload))
    xs = geo["x_spider"]
    for k in range(p.spiders):
        th = 2 * math.pi * k / p.spiders
        u = np.array([math.cos(th), math.sin(th), 0.0])
        name = f"spider{k + 1}"
        pos = xs * u
        sp.add_rigid_body(name, B.spider.mass, B.spider.inertia, position=pos,
                          velocity=np.cross(w, pos), angular_velocity=w)
        sp.add_marker(f"pin{k + 1}", carrier, position=pos, axis=u)
        sp.add_marker(f"m_{name}", name, axis=u)
        sp.add(Hinge(f"{name}_pin", f"pin{k + 1}", f"m_{name}"))
        if kind == "locked":
            sp.add(JointDriver(f"{name}_lock", f"{name}_pin", function=0.0, quantity="angle"))
        for side in ("a", "b"):
            sp.add(GearPair(f"{name}_{side}", f"m_{name}", f"m_{side}", p.teeth_spider,
                            p.teeth_side, cone_angle_a=geo["cone_spider"],
                            cone_angle_b=geo["cone_side"], profile_shift_a=p.profile_shift,
                            profile_shift_b=-p.profile_shift, **gear_kw))
    return sp


def _packs(sp: Spec, p, side: str, sgn: float, zpos: float) -> None:
    """The pack of side gear ``side`` (its back face on the housing wall) and its inner face
    on the cross; both touch at zero load initially."""
    c = p.clutch
    law = NormalLaw(stiffness=c.stiffness, exponent=1.0, law="penalty", damping=c.damping)
    zb = zpos + sgn * c.back_offset  # back face of the side gear (away from the apex)
    sp.add_marker(f"w_{side}_pack", "housing", position=(0, 0, zb), axis=(0, 0, -sgn))
    sp.add_marker(f"f_{side}_pack", side, position=(0, 0, sgn * c.back_offset), axis=Z)
    sp.add(ThrustWasherContact(f"{side}_pack", f"w_{side}_pack", f"f_{side}_pack", law=law,
                               r_int=c.r_int, r_ext=c.r_ext,
                               friction=FrictionLaw(c.mu * c.faces, eps_v=c.eps_v)))
    zi = zpos - sgn * c.inner_offset  # inner face of the side gear (towards the apex)
    sp.add_marker(f"w_{side}_cross", "cross", position=(0, 0, zi), axis=(0, 0, sgn))
    sp.add_marker(f"f_{side}_cross", side, position=(0, 0, -sgn * c.inner_offset), axis=Z)
    sp.add(ThrustWasherContact(f"{side}_cross", f"w_{side}_cross", f"f_{side}_cross",
                               law=law, r_int=c.r_int, r_ext=c.r_ext,
                               friction=FrictionLaw(c.mu, eps_v=c.eps_v)))
