"""Builders of reduced flexible bodies in a :class:`~drivedyn.model.spec.Spec`."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from drivedyn.elements.flexible.family import FlexibleBody
from drivedyn.elements.flexible.interface import FlexibleInterface
from drivedyn.errors import ModelError
from drivedyn.model.spec import GROUND, Spec
from drivedyn.rotations import exp_so3


def marker_frame(spec: Spec, marker: str) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                   np.ndarray]:
    """Global origin (3,), rotation (3, 3), velocity (3,) and angular velocity (3,) of a
    marker in the initial configuration of ``spec``."""
    m = spec.markers.get(marker)
    if m is None:
        raise ModelError(f"unknown marker {marker!r}")
    if m.body == GROUND:
        return m.position, m.rotation, np.zeros(3), np.zeros(3)
    host = spec.bodies.get(m.body) or spec.nodes.get(m.body)
    if host is None:
        raise ModelError(f"marker {marker!r}: unknown body or node {m.body!r}")
    arm = host.rotation @ m.position
    return (host.position + arm, host.rotation @ m.rotation,
            host.velocity + np.cross(host.angular_velocity, arm), host.angular_velocity)


def add_flexible_body(spec: Spec, name: str, part: Any, marker: str, damping: float = 0.0,
                      q0: Any = None) -> FlexibleBody:
    """Mount the reduced ``part`` (:func:`drivedyn.fe.craig_bampton`) on ``marker``: its
    interface 0 follows the marker frame. Adds the coordinate nodes ``{name}.q{j}`` (three
    elastic coordinates each, initial values ``q0`` (nq,), default zero), the
    :class:`FlexibleBody` element ``name`` and, for every further interface ``I``, a node
    ``{name}.{I}`` at the interface (frame: the part axes) tied to it by the
    :class:`FlexibleInterface` ``{name}.{I}.tie``: markers on that node attach joints,
    contacts and gears to the part. Returns the body element."""
    nq = part.nq
    q = np.zeros(3 * max(1, math.ceil(nq / 3)))
    if q0 is not None:
        q0 = np.asarray(q0, float)
        if q0.shape != (nq,) or not np.all(np.isfinite(q0)):
            raise ModelError(f"flexible body {name!r}.q0: expected {nq} finite numbers")
        q[:nq] = q0
    coords = tuple(spec.add_node(f"{name}.q{j}", position=q[3 * j: 3 * j + 3])
                   for j in range(math.ceil(nq / 3)))
    body = spec.add(FlexibleBody(name, marker, part, coords, damping))
    if len(part.interfaces) > 1:
        x0, R0, v0, w0 = marker_frame(spec, marker)
        for k, itf in enumerate(part.interfaces[1:], start=1):
            # at the interface displaced by its constraint-mode coordinates (exact for the
            # translation, to second order in theta for the rotation rows)
            tth = part.maps[k - 1] @ q[:nq]
            t0, th0 = tth[:3], tth[3:]
            arm = R0 @ (itf.point + t0)
            node = spec.add_node(f"{name}.{itf.name}", x0 + arm, R0 @ exp_so3(th0),
                                 v0 + np.cross(w0, arm), w0)
            spec.add(FlexibleInterface(f"{node}.tie", name, k, node))
    return body
