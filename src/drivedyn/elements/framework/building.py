"""What every ``Family.build`` does besides its own parameters: marker lookup, node and dof
index maps, and the :class:`~drivedyn.elements.framework.group.Group` with its named outputs.

``ctx`` is the :class:`drivedyn.model.compile.BuildContext` of the model being compiled
(``ctx.marker(name, what)`` gives ``(node, offset, rotation)`` of a marker, ``ctx.nn`` is the
ground's node index, ``ctx.local_dofs(nodes, m0, nm)`` the global equation indices).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from drivedyn.elements.framework.group import Group
from drivedyn.errors import ModelError

CLASH = "{what}: both markers {a!r} and {b!r} are on {where}; {noun} must connect two " \
        "different bodies"

Output = tuple[str, str, str]  # (name, unit, description) of a per-element output


def what_of(spec: Any) -> str:
    """How messages name an element: ``"Hinge 'h1'"``."""
    return f"{type(spec).__name__} {spec.name!r}"


def two_markers(specs: Sequence[Any], ctx: Any, noun: str = "an element",
                clash: str = CLASH) -> tuple[np.ndarray, ...]:
    """Marker offsets ``pA, pB`` (nel, 3) and frames ``RmA, RmB`` (nel, 3, 3) in their node
    frames, and the node pairs ``lnodes`` (nel, 2) of two-marker elements (``markers()[:2]``;
    either may be on the ground, not both on one body: :class:`ModelError` from the template
    ``clash`` with ``what, a, b, where, noun``)."""
    nel = len(specs)
    pA = np.zeros((nel, 3))
    pB = np.zeros((nel, 3))
    RmA = np.zeros((nel, 3, 3))
    RmB = np.zeros((nel, 3, 3))
    lnodes = np.zeros((nel, 2), np.int64)
    for e, s in enumerate(specs):
        what = what_of(s)
        ma, mb = s.markers()[:2]
        nA, pA[e], RmA[e] = ctx.marker(ma, what)
        nB, pB[e], RmB[e] = ctx.marker(mb, what)
        if nA == nB:
            where = "the ground" if nA == ctx.nn else f"body {ctx.spec.markers[ma].body!r}"
            raise ModelError(clash.format(what=what, a=ma, b=mb, where=where, noun=noun))
        lnodes[e] = (nA, nB)
    return pA, pB, RmA, RmB, lnodes


def node_dofs(ctx: Any, lnodes: np.ndarray) -> np.ndarray:
    """Global equation indices (nel, 6 nnode) of the node dofs of elements without
    multipliers."""
    nel, nnode = lnodes.shape
    return np.array([ctx.local_dofs(list(ln), 0, 0) for ln in lnodes],
                    np.int64).reshape(nel, 6 * nnode)


def make_group(family: str, specs: Sequence[Any], kernel: Callable[..., Any], params: tuple,
               lnodes: np.ndarray, dofs: np.ndarray, outputs: Sequence[Output] = (),
               **kw: Any) -> Group:
    """The :class:`Group` of ``specs`` (names from the specs) with the per-element
    ``outputs`` ``(name, unit, description)``; ``kw``: the other :class:`Group` fields
    (``nmult``, ``eoff``, ``nstate``, ``commit``...; ``eoff`` defaults to zeros)."""
    kw.setdefault("eoff", np.zeros(len(specs), np.int64))
    kw.setdefault("nmult", 0)
    return Group(family=family, names=[s.name for s in specs], kernel=kernel, params=params,
                 lnodes=lnodes, dofs=dofs, aux_names=tuple(o[0] for o in outputs),
                 aux_units=tuple(o[1] for o in outputs),
                 aux_desc=tuple(o[2] for o in outputs), **kw)
