"""The frozen compiled :class:`Model` and the mutable :class:`State`.

Naming (used in all solver code):

===========  ===============================================================================
``nn``       number of nodes (ground is the extra row ``nn`` of ``x`` and ``R``)
``nd``       number of node dofs, ``6 nn`` (per node: 3 translations, 3 rotations)
``nm``       number of constraint multipliers
``neq``      number of equations / unknowns of the iteration matrix, ``nd + nm``
``x, R``     node positions (nn+1, 3) [m] and rotations (nn+1, 3, 3)
``v``        (nd,) velocities: per node ``[xdot (global) m/s, Omega (body frame) rad/s]``
``vd``       (nd,) accelerations (time derivative of ``v``)
``a``        (nd,) generalized-alpha pseudo-accelerations
``lam``      (nm,) multipliers; the constraint force of a row is ``sigma = k lam + p Phi``
``es``       (nstate,) internal states of elements (accumulated angles, impact speeds...)
===========  ===============================================================================
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from drivedyn.elements.framework.group import Group


@dataclass
class State:
    """Everything that changes in time.

    Attributes:
        t: time [s].
        x: (nn+1, 3) node positions [m], global frame; last row is the ground (zero).
        R: (nn+1, 3, 3) node rotations; last is the ground (identity).
        v: (nd,) velocities (see module docstring).
        vd: (nd,) accelerations.
        a: (nd,) pseudo-accelerations of the generalized-alpha scheme.
        lam: (nm,) constraint multipliers.
        es: (nstate,) element internal states.
    """

    t: float
    x: np.ndarray
    R: np.ndarray
    v: np.ndarray
    vd: np.ndarray
    a: np.ndarray
    lam: np.ndarray
    es: np.ndarray

    def copy(self) -> State:
        return State(
            self.t, self.x.copy(), self.R.copy(), self.v.copy(), self.vd.copy(),
            self.a.copy(), self.lam.copy(), self.es.copy(),
        )

    def assign(self, other: State) -> None:
        """Copy ``other`` into this state in place."""
        self.t = other.t
        self.x[:] = other.x
        self.R[:] = other.R
        self.v[:] = other.v
        self.vd[:] = other.vd
        self.a[:] = other.a
        self.lam[:] = other.lam
        self.es[:] = other.es


@dataclass(frozen=True)
class NodeInfo:
    """Node ``index``: its name, owning body (or ``None``) and mass properties."""

    name: str
    body: str | None
    mass: float
    inertia: np.ndarray  # (3, 3) about the node origin, node frame [kg m^2]


@dataclass(frozen=True)
class Model:
    """A compiled, frozen model.

    Attributes:
        spec: the Spec it was compiled from (kept for reference and results metadata).
        nodes: per node, :class:`NodeInfo`; node ``i`` owns dofs ``6 i .. 6 i + 5``.
        node_index: node name -> index; rigid bodies are found under their own name.
        groups: element groups, in evaluation order.
        group_of: element name -> (group index, element index in group).
        nn, nd, nm, neq, nstate: sizes (see module docstring).
        indptr, indices: CSC pattern (neq x neq) of the iteration matrix, fixed.
        eq_labels: (neq,) label of each equation, e.g. ``"node crank: ry"`` or
            ``"hinge h1: constraint 3"`` (used in failure reports).
        tf: packed time functions (see :mod:`drivedyn.timefunctions`).
        gravity: (3,) [m/s^2].
        state0: initial state (positions from the spec, velocities as given).
        marker_frames: marker name -> (node index, offset (3,), rotation (3, 3)).
        k_default: default scaling factors (translation rows, rotation rows).
        eout_all, aux_all: every group's ``eout`` and ``aux``, group after group, of which
            the groups' arrays are views
            (:func:`~drivedyn.elements.framework.group.allocate_outputs`).
    """

    spec: Any
    nodes: list[NodeInfo]
    node_index: dict[str, int]
    groups: list[Group]
    group_of: dict[str, tuple[int, int]]
    nn: int
    nd: int
    nm: int
    neq: int
    nstate: int
    indptr: np.ndarray
    indices: np.ndarray
    eq_labels: list[str]
    tf: Any
    gravity: np.ndarray
    state0: State
    marker_frames: dict[str, tuple[int, np.ndarray, np.ndarray]]
    k_default: tuple[float, float] = (1.0, 1.0)
    meta: dict = field(default_factory=dict)
    eout_all: np.ndarray | None = None
    aux_all: np.ndarray | None = None

    @property
    def nnz(self) -> int:
        return int(self.indptr[-1])

    def initial_state(self) -> State:
        """A fresh copy of the initial state."""
        return self.state0.copy()

    def group(self, element: str) -> tuple[Group, int]:
        """The group holding ``element`` and its index in it."""
        gi, ei = self.group_of[element]
        return self.groups[gi], ei
