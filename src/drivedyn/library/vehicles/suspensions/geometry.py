"""Geometry shared by the suspension builders: mirror images, link frames, markers placed
at global points, and the wheel angles read from a hub frame.

Conventions (vehicle frame x forward, y left, z up):

* the right side is the mirror image of the left, ``y -> -y`` (:data:`MIRROR`);
* camber is the inclination of the wheel plane, positive with the top of the wheel outward;
  toe is the angle of the wheel's heading, positive toe-in (the front of the wheel towards
  the vehicle's centre line); steer is the heading's yaw about +z, positive to the left, on
  both sides (``steer = -toe`` on the left, ``+toe`` on the right).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np

from drivedyn.errors import ModelError
from drivedyn.model.spec import GROUND, Spec

#: reflection y -> -y taking the left corner to the right one
MIRROR = np.diag([1.0, -1.0, 1.0])
#: ``mount(name, point)``: a marker on the chassis at a global point [m]; returns its name
Mount = Callable[[str, np.ndarray], str]
#: shortest link accepted [m]
MIN_LINK = 1e-3


def side_sign(side: str, what: str) -> float:
    """+1 for ``"left"``, -1 for ``"right"``; :class:`ModelError` naming ``what`` else."""
    if side == "left":
        return 1.0
    if side == "right":
        return -1.0
    raise ModelError(f"{what}: side must be 'left' or 'right', got {side!r}")


def on_side(point: Iterable[float], side: str) -> np.ndarray:
    """A left-side point (3,) moved to ``side`` (mirrored for the right)."""
    p = np.asarray(point, dtype=float)
    return p if side == "left" else MIRROR @ p


def unit(v: np.ndarray, what: str) -> np.ndarray:
    """``v`` normalised; :class:`ModelError` naming ``what`` if it is shorter than
    :data:`MIN_LINK`."""
    n = float(np.linalg.norm(v))
    if n < MIN_LINK:
        raise ModelError(f"{what}: length {n:.6g} m is below {MIN_LINK:g} m (coincident "
                         "points)")
    return np.asarray(v, dtype=float) / n


def frame(u: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Rotation (3, 3) with z along ``w`` and x along ``u`` made orthogonal to it."""
    z = w / np.linalg.norm(w)
    x = u - (u @ z) * z
    x = x / np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def arm_frame(front: np.ndarray, rear: np.ndarray, joint: np.ndarray,
              what: str) -> np.ndarray:
    """Frame of a control arm: x along the pivot axis (``front - rear``), z normal to the
    plane of its two pickups and its ball joint (the arm's principal axes)."""
    u = unit(front - rear, f"{what}: pivot axis (front to rear pickup)")
    w = np.cross(rear - joint, front - joint)
    if np.linalg.norm(w) < MIN_LINK * MIN_LINK:
        raise ModelError(f"{what}: the ball joint lies on the pivot axis (the arm has no "
                         "lever)")
    z = w / np.linalg.norm(w)
    return np.column_stack([u, np.cross(z, u), z])


def rod_frame(a: np.ndarray, b: np.ndarray, what: str) -> np.ndarray:
    """Frame of a rod from ``a`` to ``b``: z along it, x the vehicle's x made orthogonal
    (the vehicle's z for a rod along x)."""
    w = unit(b - a, what)
    ref = np.array([1.0, 0.0, 0.0]) if abs(w[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    return frame(ref, w)


def marker_pose(sp: Spec, name: str) -> tuple[np.ndarray, np.ndarray]:
    """Global position (3,) and orientation (3, 3) of marker ``name`` in the initial
    configuration."""
    m = sp.markers[name]
    if m.body == GROUND:
        return m.position, m.rotation
    owner = sp.bodies.get(m.body) or sp.nodes.get(m.body)
    if owner is None:
        raise ModelError(f"marker {name!r}: body or node {m.body!r} does not exist")
    return owner.position + owner.rotation @ m.position, owner.rotation @ m.rotation


def marker_at(sp: Spec, name: str, body: str, point: np.ndarray,
              rotation: np.ndarray | None = None) -> str:
    """A marker on ``body`` (a rigid body, node or the ground) at the global ``point`` with
    the global orientation ``rotation`` (identity: the vehicle's axes)."""
    R = np.eye(3) if rotation is None else rotation
    if body == GROUND:
        return sp.add_marker(name, GROUND, position=point, rotation=R)
    owner = sp.bodies.get(body) or sp.nodes.get(body)
    if owner is None:
        raise ModelError(f"marker {name!r}: body or node {body!r} does not exist")
    Rb = owner.rotation
    return sp.add_marker(name, body, position=Rb.T @ (point - owner.position),
                         rotation=Rb.T @ R)


def chassis_marker(sp: Spec, mount: Mount, name: str, point: np.ndarray,
                   rotation: np.ndarray | None = None) -> str:
    """A marker on the chassis at the global ``point``: ``mount``'s marker, or, when an
    orientation is needed (a joint axis), one beside it on the same body or node."""
    base = mount(name, np.asarray(point, dtype=float))
    if base not in sp.markers:
        raise ModelError(f"mount({name!r}): returned {base!r}, which is not a marker")
    pos, _ = marker_pose(sp, base)
    if np.linalg.norm(pos - point) > 1e-9:
        raise ModelError(f"mount({name!r}): marker {base!r} is at {pos.tolist()} m, not at "
                         f"the requested point {np.asarray(point).tolist()} m")
    if rotation is None:
        return base
    return marker_at(sp, f"{base}_axis", sp.markers[base].body, pos, rotation)


def spin_axis(camber: float, toe: float, side: str) -> np.ndarray:
    """The outward spin axis (3,) of a wheel of ``side`` with static ``camber`` and ``toe``
    [rad] (see the module docstring for the signs)."""
    # positive camber tilts the top of the wheel outward, so the outward axis dips
    a = np.array([np.cos(camber) * np.sin(toe), np.cos(camber) * np.cos(toe),
                  -np.sin(camber)])
    return on_side(a, side)


def wheel_angles(axis_left: np.ndarray, side: str) -> tuple[float, float, float]:
    """Camber, toe and steer [rad] of a wheel of ``side`` whose hub axis (the hub marker's
    z, pointing to the vehicle's left on both sides) is ``axis_left`` (3,), global."""
    a = np.asarray(axis_left, dtype=float)
    out = a if side == "left" else MIRROR @ (-a)  # the outward axis seen as a left wheel
    toe = float(np.arctan2(out[0], out[1]))
    camber = float(np.arctan2(-out[2], np.hypot(out[0], out[1])))
    return camber, toe, (-toe if side == "left" else toe)
