"""Tangent cases of the reduced flexible body (family ``flexible_body``)."""

from __future__ import annotations

from functools import cache

import numpy as np

from drivedyn.fe import Interface, SolidMaterial, SolidModel, box, craig_bampton
from drivedyn.model.flexible import add_flexible_body
from drivedyn.model.spec import Spec


@cache
def small_part(n_modes: int = 4, two_interfaces: bool = True):
    """A 1 x 0.3 x 0.2 block of a soft, light material (matrix entries of order one), clamped
    at x = 0, with a second interface at x = 1 (6 constraint modes) and ``n_modes``
    fixed-interface modes."""
    solid = SolidModel(box(1.0, 0.3, 0.2, 2, 1, 1), SolidMaterial(50.0, 0.3, 1.0))
    itf = [Interface("root", solid.select("x", 0.0), np.zeros(3))]
    if two_interfaces:
        itf.append(Interface("tip", solid.select("x", 1.0), np.array([1.0, 0.0, 0.0])))
    return craig_bampton(solid, itf, n_modes, "block", cache=False)


def free_case() -> Spec:
    """A free part mounted on a plain node, spinning, with gravity, damping and q != 0."""
    spec = Spec(gravity=(0.0, 0.0, -9.81))
    spec.add_node("hub", (0.1, 0.2, 0.3), angular_velocity=(0.3, 1.0, 2.0))
    spec.add_marker("mount", "hub")
    part = small_part()
    add_flexible_body(spec, "blk", part, "mount", damping=0.01,
                      q0=0.05 * np.sin(np.arange(part.nq) + 1.0))
    return spec


def body_case() -> Spec:
    """A part mounted on a rigid body through an offset, rotated marker."""
    spec = Spec(gravity=(0.0, -2.0, -9.81))
    spec.add_rigid_body("hub", 1.5, (0.2, 0.3, 0.35), angular_velocity=(1.0, 0.5, -2.0))
    c, s = np.cos(0.4), np.sin(0.4)
    spec.add_marker("mount", "hub", position=(0.1, -0.2, 0.05),
                    rotation=[[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    add_flexible_body(spec, "blk", small_part(2, False), "mount", damping=0.02)
    return spec


CASES = (free_case, body_case)


@cache
def small_washer(n_modes: int = 4):
    """A soft annular washer (r 0.5..1, thickness 0.2), mounted by its back face z = 0."""
    from drivedyn.fe import annular_washer

    solid = SolidModel(annular_washer(0.5, 1.0, 0.2, 1, 6, 1), SolidMaterial(200.0, 0.3, 1.0))
    return solid, craig_bampton(solid, [Interface("back", solid.select("z", 0.0),
                                                  np.zeros(3))], n_modes, "washer", cache=False)


def washer_case(quadrature: bool = False) -> Spec:
    """A spinning rigid face pressed on a flexible washer carried by another body, at the
    face nodes or at the points of a quadrature of the face (2 radii, 6 angles)."""
    from drivedyn.elements.contact import FrictionLaw, NormalLaw
    from drivedyn.elements.flexible import FlexibleWasherContact

    solid, part = small_washer()
    spec = Spec(gravity=(0.0, 0.0, -9.81))
    spec.add_rigid_body("carrier", 2.0, (0.3, 0.3, 0.5), angular_velocity=(0.1, -0.2, 1.0))
    spec.add_rigid_body("gear", 1.0, (0.2, 0.2, 0.3), position=(0.0, 0.0, 0.3),
                        angular_velocity=(0.0, 0.1, 3.0))
    spec.add_marker("mount", "carrier", position=(0.0, 0.0, 0.0))
    # face plane at z = 0.15 (penetration 0.05 at the washer face z = 0.2), normal -z
    spec.add_marker("face", "gear", position=(0.0, 0.0, -0.15), axis=(0.0, 0.0, -1.0))
    fb = add_flexible_body(spec, "washer", part, "mount", damping=0.01,
                           q0=0.01 * np.cos(np.arange(part.nq)))
    if quadrature:
        from drivedyn.fe import annulus_quadrature

        pts, areas = annulus_quadrature(0.5, 1.0, 0.2, 2, 6)
        where = {"points": pts, "weights": areas}
    else:
        where = {"face": solid.select("z", 0.2)}
    spec.add(FlexibleWasherContact(
        "contact", "mount", "face", body=fb.name, **where,
        law=NormalLaw(30.0, 1.5, law="hunt-crossley", restitution=0.7, damping=0.5),
        friction=FrictionLaw(0.3, eps_v=0.5)))
    return spec


def tie_case() -> Spec:
    """A part on a rigid body whose tip interface node is held by a spring to the ground
    (the tie's rows move with both the host and the elastic coordinates)."""
    from drivedyn.elements.springs import SpringDamper

    spec = Spec(gravity=(0.0, 0.0, -9.81))
    spec.add_rigid_body("hub", 1.5, (0.2, 0.3, 0.35), angular_velocity=(1.0, 0.5, -2.0))
    c, s = np.cos(0.4), np.sin(0.4)
    spec.add_marker("mount", "hub", position=(0.1, -0.2, 0.05),
                    rotation=[[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    add_flexible_body(spec, "blk", small_part(), "mount", damping=0.02)
    spec.add_marker("tip", "blk.tip", position=(0.05, 0.0, 0.0))
    spec.add_marker("anchor", "ground", position=(1.5, 0.3, 0.0))
    spec.add(SpringDamper("tether", "anchor", "tip", 3.0, 0.2, 0.3))
    return spec


@cache
def averaged_part():
    """The small block with an averaging (RBE3) interface at its tip: the tie's rows move
    with the averaged basis, not with constraint coordinates."""
    solid = SolidModel(box(1.0, 0.3, 0.2, 2, 1, 1), SolidMaterial(50.0, 0.3, 1.0))
    tip = solid.select("x", 1.0)
    itf = [Interface("root", solid.select("x", 0.0), np.zeros(3)),
           Interface("tip", tip, solid.nodes[tip].mean(axis=0), "average")]
    return craig_bampton(solid, itf, 3, "block", cache=False)


def average_tie_case() -> Spec:
    """A free spinning part whose averaged tip node is held by a spring."""
    from drivedyn.elements.springs import SpringDamper

    spec = Spec(gravity=(0.0, 0.0, -9.81))
    spec.add_node("hub", (0.1, 0.2, 0.3), angular_velocity=(0.3, 1.0, 2.0))
    spec.add_marker("mount", "hub")
    part = averaged_part()
    add_flexible_body(spec, "blk", part, "mount", damping=0.01,
                      q0=0.02 * np.cos(np.arange(part.nq)))
    spec.add_marker("tip", "blk.tip", position=(0.05, 0.0, 0.0))
    spec.add_marker("anchor", "ground", position=(1.5, 0.3, 0.0))
    spec.add(SpringDamper("tether", "anchor", "tip", 3.0, 0.2, 0.3))
    return spec


def washer_points_case() -> Spec:
    """:func:`washer_case` with the contact at the points of a face quadrature."""
    return washer_case(quadrature=True)
