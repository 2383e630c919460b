"""Editable description of a mechanism: nodes, rigid bodies, markers and elements.

A :class:`Spec` is what a user builds (in Python or from a model file). ``compile(spec)``
(:mod:`drivedyn.model.compile`) checks it and turns it into a frozen
:class:`drivedyn.model.model.Model`. Units are SI throughout: m, kg, kg m^2, s, rad, N, N m.

Frames: every body and node has a frame (origin ``position`` [m] in the global frame and
orientation ``rotation`` (3, 3) mapping body to global components). Markers are frames fixed
on a body, a node or the ground; every element attaches to markers. A marker's ``position``
and ``rotation`` are given in its body's frame (in the global frame for ground markers).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from drivedyn.errors import ModelError
from drivedyn.rotations import frame_from_axis

GROUND = "ground"
"""Name of the ground: markers on it are given in the global frame."""


def _vec3(value: Any, what: str) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise ModelError(f"{what}: expected 3 finite numbers, got {value!r}")
    return arr


def _rotation(value: Any, what: str) -> np.ndarray:
    if value is None:
        return np.eye(3)
    R = np.asarray(value, dtype=float)
    if R.shape != (3, 3) or not np.all(np.isfinite(R)):
        raise ModelError(f"{what}: expected a 3x3 rotation matrix, got {value!r}")
    if not np.allclose(R.T @ R, np.eye(3), atol=1e-9) or np.linalg.det(R) < 0:
        raise ModelError(f"{what}: matrix is not a proper rotation (R^T R != I or det < 0)")
    return R


def _frame(rotation: Any, axis: Any, what: str) -> np.ndarray:
    if axis is not None:
        if rotation is not None:
            raise ModelError(f"{what}: give either 'rotation' or 'axis', not both")
        try:
            return frame_from_axis(_vec3(axis, what + ".axis"))
        except ValueError as exc:
            raise ModelError(f"{what}.axis: {exc}") from None
    return _rotation(rotation, what + ".rotation")


@dataclass(frozen=True)
class Node:
    """A 6-dof frame without mass of its own (carries elements' mass, e.g. beams later).

    Attributes:
        name: unique name.
        position: (3,) origin [m], global frame.
        rotation: (3, 3) orientation, body-to-global.
        velocity: (3,) initial velocity of the origin [m/s], global frame.
        angular_velocity: (3,) initial angular velocity [rad/s], global frame.
    """

    name: str
    position: np.ndarray
    rotation: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray


@dataclass(frozen=True)
class RigidBody:
    """A rigid body. Its node is placed at the centre of mass with the body's orientation.

    Attributes:
        name: unique name.
        mass: [kg], > 0.
        inertia: (3, 3) inertia tensor about the centre of mass in the body frame [kg m^2];
            symmetric positive definite, principal moments obeying the triangle inequality.
        com: (3,) centre of mass in the body frame [m].
        position: (3,) body frame origin [m], global frame.
        rotation: (3, 3) body orientation.
        velocity: (3,) initial velocity of the body frame origin [m/s], global frame.
        angular_velocity: (3,) initial angular velocity [rad/s], global frame.
    """

    name: str
    mass: float
    inertia: np.ndarray
    com: np.ndarray
    position: np.ndarray
    rotation: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray


@dataclass(frozen=True)
class Marker:
    """A frame fixed on a body, node or the ground that elements attach to.

    Attributes:
        name: unique name.
        body: name of a rigid body, a node, or ``"ground"``.
        position: (3,) origin [m] in the body frame (global frame for ground).
        rotation: (3, 3) orientation relative to the body frame.
    """

    name: str
    body: str
    position: np.ndarray
    rotation: np.ndarray


@dataclass
class Settings:
    """Model-wide settings.

    Attributes:
        gravity: (3,) gravitational acceleration [m/s^2], global frame.
        constraint_scaling: scaling factor k of the augmented Lagrangian, one value for all
            joints without their own; ``None`` chooses it from the mass scale (see compile).
        constraint_penalty: penalty factor p; ``None`` sets p = k.
        assembly_tolerance: largest initial constraint violation accepted [m or rad].
    """

    gravity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    constraint_scaling: float | None = None
    constraint_penalty: float | None = None
    assembly_tolerance: float = 1e-6


def check_inertia(J: np.ndarray, what: str) -> None:
    """Refuse an inertia tensor that is not symmetric positive definite or violates the
    triangle inequality of the principal moments (J1 + J2 >= J3 and permutations)."""
    if J.shape != (3, 3) or not np.all(np.isfinite(J)):
        raise ModelError(f"{what}: inertia must be a 3x3 matrix of finite numbers [kg m^2]")
    if not np.allclose(J, J.T, rtol=1e-9, atol=1e-12 * max(1.0, np.abs(J).max())):
        raise ModelError(f"{what}: inertia tensor is not symmetric")
    ev = np.linalg.eigvalsh(0.5 * (J + J.T))
    if ev[0] <= 0.0:
        raise ModelError(
            f"{what}: inertia tensor is not positive definite "
            f"(principal moments {ev.tolist()} kg m^2)"
        )
    tol = 1e-9 * ev[2]
    if ev[0] + ev[1] < ev[2] - tol:
        raise ModelError(
            f"{what}: inertia: principal moments {ev.tolist()} kg m^2 violate the triangle "
            "inequality "
            "J1 + J2 >= J3 (no real mass distribution has them)"
        )


class Spec:
    """An editable mechanism description.

    Example::

        spec = Spec(gravity=(0, 0, -9.81))
        spec.add_rigid_body("link", mass=1.0, inertia=np.diag([1e-3, 1e-2, 1e-2]))
        spec.add_marker("pivot", "ground", axis=(0, 1, 0))
        spec.add_marker("link_end", "link", position=(-0.5, 0, 0), axis=(0, 1, 0))
        spec.add(Hinge("hinge", "pivot", "link_end"))
    """

    def __init__(self, gravity: Any = (0.0, 0.0, 0.0), **settings: Any) -> None:
        self.settings = Settings(gravity=_vec3(gravity, "gravity"), **settings)
        self.nodes: dict[str, Node] = {}
        self.bodies: dict[str, RigidBody] = {}
        self.markers: dict[str, Marker] = {}
        self.elements: list[Any] = []
        self.visuals: list[Any] = []
        self._names: set[str] = {GROUND}

    # -- bodies and nodes ------------------------------------------------------------------
    def _claim(self, name: str, kind: str) -> None:
        if not isinstance(name, str) or not name:
            raise ModelError(f"{kind}: name must be a non-empty string, got {name!r}")
        if name in self._names:
            raise ModelError(f"{kind} {name!r}: duplicate name (already used by a body, node or "
                             "the ground)")
        self._names.add(name)

    def add_node(
        self,
        name: str,
        position: Any = (0.0, 0.0, 0.0),
        rotation: Any = None,
        velocity: Any = (0.0, 0.0, 0.0),
        angular_velocity: Any = (0.0, 0.0, 0.0),
    ) -> str:
        """Add a massless 6-dof node; returns its name."""
        what = f"node {name!r}"
        self._claim(name, "node")
        self.nodes[name] = Node(
            name,
            _vec3(position, what + ".position"),
            _rotation(rotation, what + ".rotation"),
            _vec3(velocity, what + ".velocity"),
            _vec3(angular_velocity, what + ".angular_velocity"),
        )
        return name

    def add_rigid_body(
        self,
        name: str,
        mass: float,
        inertia: Any,
        com: Any = (0.0, 0.0, 0.0),
        position: Any = (0.0, 0.0, 0.0),
        rotation: Any = None,
        velocity: Any = (0.0, 0.0, 0.0),
        angular_velocity: Any = (0.0, 0.0, 0.0),
    ) -> str:
        """Add a rigid body (see :class:`RigidBody`); ``inertia`` may be (3,) principal
        moments or a (3, 3) tensor about the centre of mass. Returns its name."""
        what = f"rigid body {name!r}"
        self._claim(name, "rigid body")
        try:
            m = float(mass)
        except (TypeError, ValueError):
            raise ModelError(f"{what}.mass: expected a number [kg], got {mass!r}") from None
        if not np.isfinite(m) or m <= 0.0:
            raise ModelError(f"{what}.mass: must be > 0 kg, got {mass!r}")
        J = np.asarray(inertia, dtype=float)
        if J.shape == (3,):
            J = np.diag(J)
        check_inertia(J, what)
        self.bodies[name] = RigidBody(
            name,
            m,
            0.5 * (J + J.T),
            _vec3(com, what + ".com"),
            _vec3(position, what + ".position"),
            _rotation(rotation, what + ".rotation"),
            _vec3(velocity, what + ".velocity"),
            _vec3(angular_velocity, what + ".angular_velocity"),
        )
        return name

    def add_marker(
        self,
        name: str,
        body: str,
        position: Any = (0.0, 0.0, 0.0),
        rotation: Any = None,
        axis: Any = None,
    ) -> str:
        """Add a marker on ``body`` (a rigid body, node or ``"ground"``).

        ``axis`` (3,) builds a frame whose z axis is ``axis`` (joint axes are z axes);
        otherwise ``rotation`` (3, 3) or identity. Returns its name.
        """
        what = f"marker {name!r}"
        if name in self.markers:
            raise ModelError(f"{what}: duplicate name (already used by another marker)")
        if not isinstance(name, str) or not name:
            raise ModelError(f"marker: name must be a non-empty string, got {name!r}")
        self.markers[name] = Marker(
            name, body, _vec3(position, what + ".position"), _frame(rotation, axis, what)
        )
        return name

    def add_visual(self, visual: Any) -> Any:
        """Add a shape for the 3-D viewer (:class:`drivedyn.elements.framework.visuals.Visual`, e.g.
        ``cylinder("case_axis", 0.06, 0.1, role="case")``) on an existing marker; returns it.
        Elements declare their own shapes; this is for what only the assembly knows (cases,
        housings, shafts)."""
        from drivedyn.elements.framework.visuals import Visual

        if not isinstance(visual, Visual):
            raise ModelError(f"add_visual: expected a Visual, got {type(visual).__name__}")
        if visual.marker not in self.markers:
            raise ModelError(f"add_visual: marker {visual.marker!r} does not exist")
        self.visuals.append(visual)
        return visual

    # -- elements --------------------------------------------------------------------------
    def add(self, element: Any) -> Any:
        """Add an element (joint, force element, load, driver...); returns it."""
        name = getattr(element, "name", None)
        kind = type(element).__name__
        if not isinstance(name, str) or not name:
            raise ModelError(f"{kind}: name must be a non-empty string, got {name!r}")
        if any(e.name == name for e in self.elements):
            raise ModelError(f"{kind} {name!r}: duplicate name (already used by another element)")
        self.elements.append(element)
        return element

    def element(self, name: str) -> Any:
        """The element called ``name``."""
        for e in self.elements:
            if e.name == name:
                return e
        raise KeyError(name)
