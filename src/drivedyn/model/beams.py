"""Builders of beam structures in a :class:`~drivedyn.model.spec.Spec`: straight shafts of N
elements between two points (sharing end nodes with other beams or bodies to make frames).

Node frames of a straight beam have x along the beam and y, z along the section axes, so a
marker on a node with the identity rotation is aligned with the section (a hinge axis
``axis=(1, 0, 0)`` is the shaft axis).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from drivedyn.elements.beams.family import GeometricallyExactBeam, section_frame
from drivedyn.errors import ModelError
from drivedyn.model.spec import Spec


def add_straight_beam(
    spec: Spec,
    name: str,
    start: Any,
    end: Any,
    n_elements: int,
    section: Any,
    material: Any = None,
    orientation: Any = None,
    damping: float = 0.0,
    node_a: str | None = None,
    node_b: str | None = None,
    velocity: Any = (0.0, 0.0, 0.0),
    angular_velocity: Any = (0.0, 0.0, 0.0),
    mass_matrix: str = "lumped",
) -> list[str]:
    """Add a straight beam of ``n_elements`` equal elements from ``start`` to ``end`` [m]
    (global frame); returns the names of its ``n_elements + 1`` nodes, start to end.

    New nodes are called ``{name}.n{i}`` and elements ``{name}.e{i}``. ``node_a`` /
    ``node_b`` reuse existing nodes (or rigid bodies) as the end nodes, so beams share
    nodes (frames) or end on a body's node; their frames keep their own orientation.
    ``velocity`` [m/s] and ``angular_velocity`` [rad/s] (global) give the new nodes the
    rigid motion about ``start`` of a body spinning with the beam. ``mass_matrix``:
    ``"lumped"`` or ``"consistent"`` (see :class:`GeometricallyExactBeam`).
    """
    what = f"beam {name!r}"
    try:
        n = int(n_elements)
    except (TypeError, ValueError):
        raise ModelError(f"{what}.n_elements: expected an integer >= 1, got "
                         f"{n_elements!r}") from None
    if n < 1 or n != n_elements:
        raise ModelError(f"{what}.n_elements: expected an integer >= 1, got {n_elements!r}")
    p0 = np.asarray(start, dtype=float)
    p1 = np.asarray(end, dtype=float)
    for label, p in (("start", p0), ("end", p1)):
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            raise ModelError(f"{what}.{label}: expected 3 finite numbers [m], got {p.tolist()}")
    if np.linalg.norm(p1 - p0) <= 1e-12 * max(1.0, float(np.abs(p0).max())):
        raise ModelError(f"{what}: zero length (start and end are both {p0.tolist()} m)")
    Rs = section_frame(p1 - p0, orientation, what)
    v0 = np.asarray(velocity, dtype=float)
    w0 = np.asarray(angular_velocity, dtype=float)
    nodes = []
    for i in range(n + 1):
        if i == 0 and node_a is not None:
            nodes.append(node_a)
            continue
        if i == n and node_b is not None:
            nodes.append(node_b)
            continue
        p = p0 + (p1 - p0) * (i / n)
        nodes.append(spec.add_node(f"{name}.n{i}", position=p, rotation=Rs,
                                   velocity=v0 + np.cross(w0, p - p0), angular_velocity=w0))
    for i in range(n):
        spec.add(GeometricallyExactBeam(f"{name}.e{i}", nodes[i], nodes[i + 1], section,
                                        material, orientation=Rs[:, 1], damping=damping,
                                        mass_matrix=mass_matrix))
    return nodes
