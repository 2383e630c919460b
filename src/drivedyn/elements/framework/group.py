"""The :class:`Group`: all elements of one family in a compiled model, evaluated by one kernel
call (:mod:`drivedyn.elements.framework.contract`), with its per-element outputs and the
commit of its internal state after an accepted step."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

# ``Group.commit_cols`` entry for the time of the accepted state
COMMIT_TIME = -1


@dataclass(frozen=True)
class DerivedOutputs:
    """Outputs of a family that are functions of its other outputs and constant parameters,
    computed when they are read (the recorder, :func:`~drivedyn.solver.system.element_outputs`)
    instead of by the kernel at every evaluation (a beam's outer-fibre stresses were 10 % of
    the wall time of a spinning 100-element shaft).

    Attributes:
        cols: the aux columns computed here (the kernel leaves them zero).
        inputs: the aux columns they are computed from.
        fn: ``fn(ei, A)`` -> (nt, len(cols)) for element ``ei`` from ``A`` (nt, len(inputs)),
            the inputs' values over time; picklable (a module-level function, or a
            ``functools.partial`` of one with arrays): results computed in a forked process
            travel with it.
    """

    cols: tuple[int, ...]
    inputs: tuple[int, ...]
    fn: Callable[[int, np.ndarray], np.ndarray]

    def at(self, ei: int, row: np.ndarray) -> np.ndarray:
        """The derived columns (len(cols),) of element ``ei`` from its aux row ``row``."""
        return self.fn(ei, np.asarray(row, float)[list(self.inputs)][None, :])[0]


@dataclass
class Group:
    """All elements of one family in a compiled model, evaluated by one kernel call.

    Attributes:
        family: family name (registry key).
        names: element names, length ``nel``.
        kernel: the compiled numba kernel.
        params: tuple of the family's parameter arrays passed first to the kernel.
        lnodes: (nel, nnode) node index of each local node (``nn`` means ground).
        nmult: multipliers per element.
        dofs: (nel, nloc) global equation indices of the local dofs (-1: none).
        eoff: (nel,) offset of each element's internal state in ``State.es``.
        nstate: internal state floats per element.
        aux_names: names of the per-element outputs written into ``aux``.
        aux_units: their units.
        aux_desc: their descriptions.
        kmap: (nel, nloc*nloc) CSC data index of each local matrix entry (set by compile).
        commit_cols: per internal state slot ``j`` of an element, the aux column copied into
            ``es[eoff + j]`` after an accepted step (:data:`COMMIT_TIME`: the step's end
            time); a family with such a commit declares it here, and the compiled stepping
            loop (:mod:`drivedyn.solver.step_loop`) does it without Python.
        commit: optional ``commit(group, state)`` updating internal state after an accepted
            step; :func:`commit_columns` when ``commit_cols`` is given. A family whose commit
            is not a copy of columns sets its own (the stepping loop then runs in Python).
        extra: family-specific data (for outputs, sensors and commit).
        derived: outputs computed when read, from other outputs (:class:`DerivedOutputs`).
    """

    family: str
    names: list[str]
    kernel: Callable[..., Any]
    params: tuple
    lnodes: np.ndarray
    nmult: int
    dofs: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), np.int64))
    eoff: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    nstate: int = 0
    aux_names: tuple[str, ...] = ()
    aux_units: tuple[str, ...] = ()
    aux_desc: tuple[str, ...] = ()
    kmap: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), np.int64))
    commit_cols: tuple[int, ...] = ()
    commit: Callable[..., None] | None = None
    extra: dict = field(default_factory=dict)
    eout: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))
    aux: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    naux: int = 0  # columns the kernel writes into aux (0: len(aux_names))
    aux_cols: tuple[int, ...] = ()  # aux column of each exported output (empty: in order)
    dissipative: bool = False
    derived: DerivedOutputs | None = None  # outputs computed when read

    def __post_init__(self) -> None:
        if self.commit_cols and self.commit is None:
            self.commit = commit_columns

    def outputs(self) -> list[tuple[int, str, str, str]]:
        """Exported per-element outputs: (aux column, name, unit, description)."""
        cols = self.aux_cols or tuple(range(len(self.aux_names)))
        return list(zip(cols, self.aux_names, self.aux_units, self.aux_desc, strict=True))

    @property
    def nel(self) -> int:
        return len(self.names)

    @property
    def nnode(self) -> int:
        return self.lnodes.shape[1]

    @property
    def nloc(self) -> int:
        return 6 * self.nnode + self.nmult

    def allocate(self) -> None:
        """Allocate the per-element output arrays."""
        self.eout = np.zeros((self.nel, 4))
        self.aux = np.zeros((self.nel, max(1, self.naux, len(self.aux_names))))

    def evaluate(self, st, tfv, t, Tn, cM, cC, cK, mode, want, r, rabs, data) -> None:
        """Run the kernel on state ``st`` (a :class:`drivedyn.model.State`)."""
        self.kernel(
            *self.params, self.lnodes, self.dofs, self.kmap, self.eoff,
            st.x, st.R, st.v, st.vd, st.lam, st.es, tfv, t, Tn,
            cM, cC, cK, mode, want, r, rabs, data, self.eout, self.aux,
        )


def commit_columns(group: Group, state) -> None:
    """The commit of ``group.commit_cols``: ``es[eoff[e] + j] = aux[e, commit_cols[j]]``
    (the state's time for :data:`COMMIT_TIME`)."""
    for j, c in enumerate(group.commit_cols):
        state.es[group.eoff + j] = state.t if c == COMMIT_TIME else group.aux[:, c]


def allocate_outputs(groups: Sequence[Group]) -> tuple[np.ndarray, np.ndarray]:
    """Allocate every group's ``eout`` and ``aux`` as views of two model-wide arrays, returned
    as ``(eout_all (sum nel, 4), aux_all (sum nel naux,))``, group after group: the compiled
    stepping loop reads the outputs of all groups from them."""
    for g in groups:
        g.allocate()
    eout_all = np.zeros((sum(g.nel for g in groups), 4))
    aux_all = np.zeros(sum(g.aux.size for g in groups))
    e0 = a0 = 0
    for g in groups:
        g.eout = eout_all[e0:e0 + g.nel]
        g.aux = aux_all[a0:a0 + g.aux.size].reshape(g.aux.shape)
        e0 += g.nel
        a0 += g.aux.size
    return eout_all, aux_all


def aux_offset(g: Group, aux_all: np.ndarray) -> int:
    """Offset [entries] of group ``g``'s ``aux`` in ``aux_all`` (:func:`allocate_outputs`),
    or -1 if it is not a C-contiguous view of it (a group replaced since); 0 for an empty
    ``aux``."""
    a = g.aux
    if a.size == 0:
        return 0
    if not (np.shares_memory(a, aux_all) and a.flags.c_contiguous):
        return -1
    return (a.ctypes.data - aux_all.ctypes.data) // aux_all.itemsize
