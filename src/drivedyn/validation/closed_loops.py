"""Closed-loop mechanisms built the way an engineer builds them, every revolute a
:class:`~drivedyn.elements.Hinge`, and the same mechanisms built without redundant rows.

A planar loop of hinges has three redundant rows per loop (the out-of-plane translation and
the two tilts are imposed by every joint of the loop); the Bricard linkage is a spatial
six-hinge loop whose Grubler count gives no motion (30 rows, 30 coordinates) yet it moves
with one degree of freedom, so at least one of its rows is a combination of the others.
The engine sets the dependent rows aside (:mod:`drivedyn.solver.redundancy`); the
non-redundant builds (``joints="mixed"``: a spherical joint and a universal joint in place
of two hinges) are the reference its motion and unique reactions are compared with.

All bodies are slender rods (mass [kg], length [m]) with their frames parallel to the
global frame at the start, their centre of mass at mid-length; markers are placed at global
points (the body frames start at the global origin).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from drivedyn.elements import Hinge, JointDriver, Spherical, SpringDamper, Universal
from drivedyn.model import Model, Spec, compile_model
from drivedyn.validation.common import G


def rod_inertia(mass: float, p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Inertia tensor (3, 3) [kg m^2] about the centre of a slender rod from ``p`` to ``q``
    (global frame), with 1e-3 of the transverse moment about its axis (a rod of finite
    thickness: no zero moment)."""
    u = q - p
    L = float(np.linalg.norm(u))
    u = u / L
    It = mass * L * L / 12.0
    return It * (np.eye(3) - np.outer(u, u)) + 1e-3 * It * np.outer(u, u)


def _rod(spec: Spec, name: str, mass: float, p: Any, q: Any,
         omega: Any = (0.0, 0.0, 0.0)) -> None:
    """A rod from ``p`` to ``q`` turning at ``omega`` [rad/s] about ``p``."""
    p, q = np.asarray(p, float), np.asarray(q, float)
    w = np.asarray(omega, float)
    spec.add_rigid_body(name, mass, rod_inertia(mass, p, q), com=0.5 * (p + q),
                        velocity=np.cross(w, 0.5 * (q - p)), angular_velocity=w)


def _frame(x: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Rotation (3, 3) with columns x, z x x, z (``x`` made orthogonal to ``z``)."""
    z = z / np.linalg.norm(z)
    x = x - np.dot(x, z) * z
    x = x / np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _hinge(spec: Spec, name: str, a: str, b: str, point: Any, axis: Any) -> None:
    """A hinge of bodies ``a`` and ``b`` (or "ground") at ``point`` about ``axis``."""
    spec.add_marker(f"{name}_a", a, position=point, axis=axis)
    spec.add_marker(f"{name}_b", b, position=point, axis=axis)
    spec.add(Hinge(name, f"{name}_a", f"{name}_b"))


def _pin(spec: Spec, name: str, a: str, b: str, point: Any) -> None:
    spec.add_marker(f"{name}_a", a, position=point)
    spec.add_marker(f"{name}_b", b, position=point)
    spec.add(Spherical(name, f"{name}_a", f"{name}_b"))


def _cardan(spec: Spec, name: str, a: str, b: str, point: Any, axis: np.ndarray,
            across: np.ndarray) -> None:
    """Universal joint at ``point``: ``a`` turns about ``axis``, ``b`` about ``across``
    (perpendicular to it)."""
    ra = _frame(axis, across)  # x = axis
    rb = np.column_stack([axis, across, np.cross(axis, across)])  # y = across
    spec.add_marker(f"{name}_a", a, position=point, rotation=ra)
    spec.add_marker(f"{name}_b", b, position=point, rotation=rb)
    spec.add(Universal(name, f"{name}_a", f"{name}_b"))


def four_bar_points(theta: float, a: float, b: float, c: float, d: float) -> tuple:
    """Joint points (2,) of a planar four-bar with ground pivots O2 = (0, 0), O4 = (d, 0),
    crank a at angle ``theta`` [rad] from +x, coupler b, rocker c (open branch, coupler
    above the line O2-O4): returns (O2, A, B, O4)."""
    O2, O4 = np.zeros(2), np.array([d, 0.0])
    A = a * np.array([np.cos(theta), np.sin(theta)])
    e = O4 - A
    r = float(np.linalg.norm(e))
    if not abs(b - c) <= r <= b + c:
        raise ValueError("four-bar cannot close at this crank angle")
    x = (b * b - c * c + r * r) / (2.0 * r)
    h = np.sqrt(max(b * b - x * x, 0.0))
    u = e / r
    B = A + x * u + h * np.array([-u[1], u[0]])
    return O2, A, B, O4


# crank-rocker four-bar (Grashof: 0.1 + 0.35 <= 0.3 + 0.3) [m], rods of 1 kg/m
FB_LINKS = (0.1, 0.35, 0.3, 0.3)


def four_bar_model(joints: str = "hinges", theta0: float = 0.3,
                   speed: float | None = 2.0 * np.pi, plane: str = "xy",
                   spring: tuple[float, float] | None = None,
                   links: tuple[float, float, float, float] = FB_LINKS,
                   omega0: float = 0.0) -> Model:
    """Planar four-bar: crank, coupler and rocker (rods of 1 kg/m) on ground pivots, under
    gravity in the plane (-y of the plane), crank at ``theta0`` [rad].

    Args:
        joints: ``"hinges"`` (four hinges: 20 rows for 18 coordinates, 3 redundant) or
            ``"mixed"`` (hinges at the ground pivots, a spherical crank pin and a universal
            coupler-rocker joint: 17 rows, none redundant).
        speed: crank speed [rad/s] imposed by a :class:`JointDriver` ``drive`` on the crank
            hinge (its driving torque is a unique reaction); None: free, from rest.
        plane: ``"xy"`` (hinge axes z) or ``"yz"`` (axes x: a double wishbone seen from
            the front, ground = chassis, crank = lower arm, rocker = upper arm, coupler =
            upright; the plane's x is global y, its y global z).
        spring: (stiffness [N/m], damping [N s/m]) of a spring-damper from the ground to
            the coupler's midpoint, free length its initial length (the suspension spring).
        links: crank, coupler, rocker, ground lengths [m].
        omega0: initial crank speed [rad/s] (without a driver; the other bodies start at
            rest, the consistent initial state projects the velocities onto the loop).
    """
    if joints not in ("hinges", "mixed"):
        raise ValueError(f"joints: expected 'hinges' or 'mixed', got {joints!r}")
    a, b, c, d = links
    P = four_bar_points(theta0, a, b, c, d)
    if plane == "xy":
        emb, ax = (lambda p: np.array([p[0], p[1], 0.0])), np.array([0.0, 0.0, 1.0])
        g = (0.0, -G, 0.0)
    elif plane == "yz":
        emb, ax = (lambda p: np.array([0.0, p[0], p[1]])), np.array([1.0, 0.0, 0.0])
        g = (0.0, 0.0, -G)
    else:
        raise ValueError(f"plane: expected 'xy' or 'yz', got {plane!r}")
    O2, A, B, O4 = (emb(p) for p in P)
    spec = Spec(gravity=g)
    _rod(spec, "crank", a, O2, A, omega0 * ax)
    _rod(spec, "coupler", b, A, B)
    _rod(spec, "rocker", c, O4, B)
    _hinge(spec, "main", "ground", "crank", O2, ax)
    _hinge(spec, "rocker_pivot", "ground", "rocker", O4, ax)
    if joints == "hinges":
        _hinge(spec, "crank_pin", "crank", "coupler", A, ax)
        _hinge(spec, "rocker_pin", "coupler", "rocker", B, ax)
    else:
        _pin(spec, "crank_pin", "crank", "coupler", A)
        u = (B - A) / np.linalg.norm(B - A)
        _cardan(spec, "rocker_pin", "coupler", "rocker", B, ax, np.cross(ax, u))
    if speed is not None:
        spec.add(JointDriver("drive", "main", speed, quantity="speed"))
    if spring is not None:
        mid = 0.5 * (A + B)
        anchor = mid - 0.25 * np.array(g) / G  # 0.25 m above
        spec.add_marker("spring_top", "ground", position=anchor)
        spec.add_marker("spring_bottom", "coupler", position=mid)
        spec.add(SpringDamper("spring", "spring_top", "spring_bottom", stiffness=spring[0],
                              damping=spring[1]))
    return compile_model(spec)


BRICARD_L = 1.0  # link length [m]
BRICARD_M = 1.0  # link mass [kg]


def bricard_model(L: float = BRICARD_L, mass: float = BRICARD_M) -> Model:
    """Bricard's orthogonal linkage: six links of length ``L`` along the edges of a cube
    (V0 = 0, V1 = L x, V2 = L (x + y), V3 = L (1, 1, 1), V4 = L (y + z), V5 = L z), each
    revolute axis perpendicular to the two links it joins (twists 90 deg, no offsets, equal
    lengths: Bricard's condition holds), link V5-V0 the ground, five links of ``mass`` [kg]
    released from rest under gravity -z.

    30 hinge rows for 30 coordinates, yet one degree of freedom: at least one row is a
    combination of the others at every configuration of the motion."""
    V = L * np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 1.0, 1.0],
                      [0.0, 1.0, 1.0], [0.0, 0.0, 1.0]])
    d = [V[(i + 1) % 6] - V[i] for i in range(6)]
    axes = [np.cross(d[i - 1], d[i]) / (L * L) for i in range(6)]
    spec = Spec(gravity=(0.0, 0.0, -G))
    names = [f"link{i}" for i in range(5)] + ["ground"]
    for i in range(5):
        _rod(spec, names[i], mass, V[i], V[i + 1])
    for i in range(6):
        _hinge(spec, f"joint{i}", names[i - 1], names[i], V[i], axes[i])
    return compile_model(spec)


def hinge_violations(res: Any, model: Model) -> np.ndarray:
    """Largest violation over the run of every hinge of ``model`` in ``res``: (n,) maxima
    of |p_A - p_B| [m] + |z_A x z_B| [rad] from the recorded node positions and rotations
    (every row of the joints, those set aside included)."""
    out = []
    for e in model.spec.elements:
        if not isinstance(e, Hinge):
            continue
        ends = []
        for mk in (e.marker_a, e.marker_b):
            node, off, rot = model.marker_frames[mk]
            if node == model.nn:
                ends.append((np.broadcast_to(off, (res.dataset.sizes["time"], 3)),
                             np.broadcast_to(rot[:, 2], (res.dataset.sizes["time"], 3))))
                continue
            name = model.nodes[node].name
            x = res[f"{name}.position"].values
            R = res[f"{name}.rotation"].values
            ends.append((x + R @ off, R @ rot[:, 2]))
        (pa, za), (pb, zb) = ends
        out.append(float((np.linalg.norm(pa - pb, axis=1)
                          + np.linalg.norm(np.cross(za, zb), axis=1)).max()))
    return np.array(out)
