"""Builders of reduced flexible bodies in a :class:`~drivedyn.model.spec.Spec`."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from drivedyn.elements.flexible.family import FlexibleBody
from drivedyn.errors import ModelError
from drivedyn.model.spec import Spec


def add_flexible_body(spec: Spec, name: str, part: Any, marker: str, damping: float = 0.0,
                      q0: Any = None) -> FlexibleBody:
    """Mount the reduced ``part`` (:func:`drivedyn.fe.craig_bampton`) on ``marker``: its
    interface 0 follows the marker frame. Adds the coordinate nodes ``{name}.q{j}`` (three
    elastic coordinates each, initial values ``q0`` (nq,), default zero) and the
    :class:`FlexibleBody` element ``name``; returns the element."""
    nq = part.nq
    q = np.zeros(3 * max(1, math.ceil(nq / 3)))
    if q0 is not None:
        q0 = np.asarray(q0, float)
        if q0.shape != (nq,) or not np.all(np.isfinite(q0)):
            raise ModelError(f"flexible body {name!r}.q0: expected {nq} finite numbers")
        q[:nq] = q0
    coords = tuple(spec.add_node(f"{name}.q{j}", position=q[3 * j: 3 * j + 3])
                   for j in range(math.ceil(nq / 3)))
    return spec.add(FlexibleBody(name, marker, part, coords, damping))
