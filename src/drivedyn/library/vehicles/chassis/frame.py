"""A flexible ladder frame of geometrically exact beams in a :class:`~drivedyn.model.spec.Spec`,
with the body it carries and the markers other parts mount on.

The two rails run along x at ``y = +-track / 2`` and the cross members along y between them,
all on the plane of the rails' centroids (``z = 0`` in frame coordinates; frame axes are the
global axes, the frame's origin at ``origin``). A cross member shares the rail nodes at its
``x``: the joint is rigid (welded, no joint flexibility). Rail nodes lie at every station (rail
ends, cross members, body mounts, ``mesh.stations``) and ``mesh.elements_per_segment``
equal elements fill each gap; a cross member has a node on the centre line and as many
elements on each half. Rail node frames are the global axes; a cross member's inner node
frames have x along +y (its section frame).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from drivedyn.elements.beams.family import GeometricallyExactBeam, section_frame
from drivedyn.elements.framework.visuals import link, sphere
from drivedyn.elements.joints import Fixed
from drivedyn.errors import ModelError
from drivedyn.library.vehicles.chassis.body import carriers
from drivedyn.library.vehicles.chassis.schema import LadderFrameFile
from drivedyn.model.spec import Spec

#: the viewer's shape of a body carrier: a ball of this radius [m] on a post of this radius
CARRIER_BALL, CARRIER_POST = 0.06, 0.012
#: section orientation (global vector of the section's y axis): rails and cross members
#: have their section y horizontal and z vertical (``width`` across, ``height`` up)
RAIL_ORIENTATION = (0.0, 1.0, 0.0)
CROSS_ORIENTATION = (1.0, 0.0, 0.0)


@dataclass
class Frame:
    """A ladder frame built by :func:`add_ladder_frame`.

    Attributes:
        spec: the spec it was built in (``mount`` adds markers there).
        prefix: the prefix of its names.
        origin: (3,) global position of the frame's origin [m].
        left, right: the rails' node names, rear to front.
        cross_members: per cross member (in the order of ``cross_members``) its node names,
            right rail node first, left rail node last; the centre-line node in the middle.
        elements: the beam element names.
        carriers: the carrier bodies of the body (empty for a bare frame).
        joints: the ``Fixed`` joints holding the carriers on the rails.
        beam_mass: mass of the frame's members [kg].
        body_mass: mass of the body carried [kg] (0 for a bare frame).
    """

    spec: Spec
    prefix: str
    origin: np.ndarray
    left: list[str] = field(default_factory=list)
    right: list[str] = field(default_factory=list)
    cross_members: list[list[str]] = field(default_factory=list)
    elements: list[str] = field(default_factory=list)
    carriers: list[str] = field(default_factory=list)
    joints: list[str] = field(default_factory=list)
    beam_mass: float = 0.0
    body_mass: float = 0.0

    @property
    def nodes(self) -> list[str]:
        """Every node of the frame (rails first, then the cross members' inner nodes)."""
        inner = [n for cm in self.cross_members for n in cm[1:-1]]
        return [*self.left, *self.right, *inner]

    def position(self, node: str) -> np.ndarray:
        """Initial global position [m] of a frame node."""
        return self.spec.nodes[node].position.copy()

    def nearest_node(self, point: Any, rails_only: bool = False) -> str:
        """The frame node nearest to the global ``point`` [m] (on the rails only with
        ``rails_only``; ties go to the first in :attr:`nodes` order)."""
        p = _point(point, "nearest_node.point")
        names = [*self.left, *self.right] if rails_only else self.nodes
        d = [float(np.linalg.norm(self.spec.nodes[n].position - p)) for n in names]
        return names[int(np.argmin(d))]

    def mount(self, name: str, point: Any, rotation: Any = None,
              max_offset: float | None = None, rails_only: bool = False) -> str:
        """Add a marker ``name`` at the global ``point`` [m] on the nearest frame node (a rigid
        offset from the node), its axes the global axes at t = 0 (or ``rotation`` (3, 3),
        global). ``max_offset`` [m]: refuse a point farther than that from every node.
        Returns the marker name (for a bushing or joint on the frame)."""
        p = _point(point, f"mount {name!r}.point")
        node = self.nearest_node(p, rails_only)
        nd = self.spec.nodes[node]
        offset = float(np.linalg.norm(p - nd.position))
        if max_offset is not None and offset > max_offset:
            raise ModelError(f"mount {name!r}: point {p.tolist()} m is {offset:.4g} m from the "
                             f"nearest frame node {node!r} (max_offset = {max_offset:g} m); "
                             "add a station there (mesh.stations) or check the point")
        R = np.eye(3) if rotation is None else np.asarray(rotation, dtype=float)
        return self.spec.add_marker(name, node, position=nd.rotation.T @ (p - nd.position),
                                    rotation=nd.rotation.T @ R)


def _point(value: Any, what: str) -> np.ndarray:
    p = np.asarray(value, dtype=float)
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise ModelError(f"{what}: expected 3 finite numbers [m], got {value!r}")
    return p


def rail_stations(p: LadderFrameFile) -> np.ndarray:
    """The x positions [m] (frame coordinates) where the rails have nodes, rear to front."""
    L = p.rails.length
    xs = [0.0, L, *(c.x for c in p.cross_members), *p.mesh.stations]
    if p.body is not None:
        xs += list(p.body.mounts)
    xs = np.unique(np.round(np.asarray(xs, dtype=float), 12))
    n = p.mesh.elements_per_segment
    fine = [xs[0]]
    for a, b in itertools.pairwise(xs):
        fine += [a + (b - a) * (i / n) for i in range(1, n + 1)]
    return np.asarray(fine)


def _index_at(xs: np.ndarray, x: float) -> int:
    return int(np.argmin(np.abs(xs - x)))


def add_ladder_frame(sp: Spec, prefix: str, p: LadderFrameFile, origin: Any = (0.0, 0.0, 0.0),
                     carry_body: bool = True) -> Frame:
    """Add the ladder frame ``p`` to ``sp`` with its frame origin at the global ``origin``
    [m] (frame axes = global axes): nodes ``{prefix}.left.n{i}``, ``{prefix}.right.n{i}``
    (rear to front), ``{prefix}.cross{k}.n{j}`` (right to left), elements ``....e{i}``; with
    ``carry_body`` (and ``p.body``) the body's carriers ``{prefix}.body.{side}{k}`` fixed to the
    rails (see :mod:`~drivedyn.library.vehicles.chassis.body`). Returns the :class:`Frame`."""
    o = _point(origin, "add_ladder_frame.origin")
    mat = p.material.material()
    frame = Frame(sp, prefix, o)
    xs = rail_stations(p)
    half = 0.5 * p.rails.track
    rail_sec = p.rails.section.beam_section(mat)
    R_rail = section_frame(np.array([1.0, 0.0, 0.0]), RAIL_ORIENTATION, "rails")
    for side, y, nodes in (("left", half, frame.left), ("right", -half, frame.right)):
        for i, x in enumerate(xs):
            nodes.append(sp.add_node(f"{prefix}.{side}.n{i}", o + np.array([x, y, 0.0]),
                                     rotation=R_rail))
        for i in range(len(xs) - 1):
            frame.elements.append(sp.add(GeometricallyExactBeam(
                f"{prefix}.{side}.e{i}", nodes[i], nodes[i + 1], rail_sec, mat,
                orientation=RAIL_ORIENTATION)).name)
            frame.beam_mass += rail_sec.properties(mat).mass_per_length * (xs[i + 1] - xs[i])
    n = p.mesh.elements_per_segment
    R_cross = section_frame(np.array([0.0, 1.0, 0.0]), CROSS_ORIENTATION, "cross member")
    for k, cm in enumerate(p.cross_members):
        sec = cm.section.beam_section(mat)
        i = _index_at(xs, cm.x)
        names = [frame.right[i]]
        for j in range(1, 2 * n):
            y = -half + p.rails.track * j / (2 * n)
            names.append(sp.add_node(f"{prefix}.cross{k}.n{j}", o + np.array([xs[i], y, 0.0]),
                                     rotation=R_cross))
        names.append(frame.left[i])
        for j in range(2 * n):
            frame.elements.append(sp.add(GeometricallyExactBeam(
                f"{prefix}.cross{k}.e{j}", names[j], names[j + 1], sec, mat,
                orientation=CROSS_ORIENTATION)).name)
        frame.beam_mass += sec.properties(mat).mass_per_length * p.rails.track
        frame.cross_members.append(names)
    if carry_body and p.body is not None:
        _add_body(sp, frame, p, xs)
    return frame


def _add_body(sp: Spec, frame: Frame, p: LadderFrameFile, xs: np.ndarray) -> None:
    """The body's carriers, each fixed to the rail node below it."""
    b = p.body
    assert b is not None
    for c in carriers(b.mass, np.asarray(b.cg), b.inertia, list(b.mounts), p.rails.track):
        node = (frame.left if c.side == "left" else frame.right)[_index_at(xs, c.x_mount)]
        name = f"{frame.prefix}.body.{c.side}{c.station}"
        sp.add_rigid_body(name, c.mass, c.inertia, position=frame.origin + c.position)
        sp.add_marker(f"{name}.seat", name)
        nd = sp.nodes[node]
        sp.add_marker(f"{name}.mount", node,
                      position=nd.rotation.T @ (frame.origin + c.position - nd.position),
                      rotation=nd.rotation.T)
        frame.joints.append(sp.add(Fixed(f"{name}.fix", f"{name}.mount", f"{name}.seat")).name)
        frame.carriers.append(name)
        # drawn as a ball on a post from its rail node (not as its large inertia box)
        sp.add_marker(f"{name}.rail", node)
        sp.add_visual(link(f"{name}.rail", f"{name}.seat", CARRIER_POST, role="body",
                           label=name))
        sp.add_visual(sphere(f"{name}.seat", CARRIER_BALL, role="body", label=name))
        frame.body_mass += c.mass
