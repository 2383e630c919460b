"""The element protocol: groups of elements evaluated by one compiled kernel each.

An element *family* (``Hinge``, ``SpringDamper``, ``RigidBody``...) is a frozen parameter
record (the spec the user writes) plus a :class:`Family` that turns every spec of that family in
a model into one :class:`Group`: parameters stored as arrays, local-to-global index maps, and a
numba kernel evaluated over all elements at once.

Kernel contract (every family's kernel has these trailing arguments, see :data:`COMMON_ARGS`)::

    kernel(<family params...>,
           lnodes,   # (nel, nnode)   node index of each local node (nn = ground)
           dofs,     # (nel, nloc)    global equation index of each local dof (-1: none)
           kmap,     # (nel, nloc*nloc) index into the CSC data array (-1: not stored)
           eoff,     # (nel,)         offset of the element's internal state in ``es``
           x, R,     # (nn+1, 3), (nn+1, 3, 3) node positions [m] / rotations (row nn = ground)
           v, vd,    # (ndof,) velocities / accelerations: per node [xdot (global), Omega (body)]
           lam,      # (nmult,) multipliers; constraint force sigma = k lam + p Phi
           es,       # (nstate,) element internal state (committed at step acceptance)
           tfv,      # (nfun, 4) time functions: value, d/dt, d2/dt2, integral from 0
           t,        # time [s]
           Tn,       # (nn+1, 3, 3) tangent operator of each node's rotation increment
           cM, cC, cK, mode, want,
           r, rabs,  # (neq,) residual and sum of |contributions| (for scaled convergence)
           data,     # (nnz,) CSC values of the iteration matrix
           eout,     # (nel, 4) kinetic energy, potential energy, power input, power dissipated
           aux)      # (nel, naux) named per-element outputs (forces, gaps, angles...)

Local dofs of an element are ``6 * nnode`` node dofs (per node: 3 translations [m] in the
global frame, 3 rotations [rad] as right (body-frame) increments) followed by its ``nmult``
multipliers. A kernel computes, per element, the local residual ``rq`` (generalised forces,
positive = internal/inertial, so ``r = M vd + f_int - f_ext``), the constraint residual ``rl``,
and the local matrices ``M = d rq / d vd``, ``C = d rq / d v``, ``K = d rq / d q`` (right
perturbations) and ``G = d rl / d q``, then calls :func:`scatter_local`.

Families write their kernels on :mod:`drivedyn.elements.framework.scaffold` (dispatch, common
arguments, scatter and outputs) and build their groups with :mod:`drivedyn.elements.framework.building`.

Modes: ``MODE_DYN`` (time step / statics: ``rl = k Phi``; matrix
``[cM M + cC C + cK K T, G^T; G T, 0]``), ``MODE_ACC`` (consistent accelerations:
``rl = k (dPhi/dq . vd + v^T H v + Phi_tt)``, matrix ``[M, G^T; G, 0]``) and ``MODE_VEL``
(velocity projection: ``rl = k (dPhi/dq . v + Phi_t)``, same matrix).
"""

from __future__ import annotations

import abc
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numba import njit

from drivedyn.elements.framework.work_arrays import carve

MODE_DYN = 0
MODE_ACC = 1
MODE_VEL = 2
# ``Group.commit_cols`` entry for the time of the accepted state
COMMIT_TIME = -1


@njit(cache=True, inline="always")
def scatter_local(
    rq, rl, M, C, K, G, nnode, lnodes, dofs, kmap, Tn, cM, cC, cK, mode, want, r, rabs, data
):
    """Add one element's local residual and matrices into the global arrays.

    ``rq`` (nd,), ``rl`` (nm,), ``M, C, K`` (nd, nd), ``G`` (nm, nd) with ``nd = 6 nnode``.
    In ``MODE_DYN`` the K and G columns of each node's rotation dofs are post-multiplied by
    the node's tangent operator ``Tn`` (Newton corrections are increments of the Lie-algebra
    step ``h dq``, not right perturbations of the new rotation).
    """
    nd = 6 * nnode
    nm = rl.shape[0]
    for i in range(nd):
        gi = dofs[i]
        if gi >= 0:
            r[gi] += rq[i]
            rabs[gi] += abs(rq[i])
    for i in range(nm):
        gi = dofs[nd + i]
        if gi >= 0:
            r[gi] += rl[i]
            rabs[gi] += abs(rl[i])
    if want:
        _scatter_matrix(M, C, K, G, nnode, nm, lnodes, kmap, Tn, cM, cC, cK, mode, data)


@njit(cache=True)
def local_arrays(nd, nm):
    """Work arrays of one element for :func:`scatter_local`: ``rq`` (nd,), ``rl`` (nm,),
    ``M, C, K`` (nd, nd) and ``G`` (nm, nd), zeroed; allocated once per kernel call, as views
    of one buffer (:mod:`drivedyn.elements.framework.work_arrays`)."""
    return local_arrays_at(np.zeros(local_size(nd, nm)), 0, nd, nm)


@njit(cache=True, inline="always")
def local_size(nd: int, nm: int) -> int:
    """Entries of :func:`local_arrays` ``(nd, nm)`` in one buffer."""
    return nd + nm + 3 * nd * nd + nm * nd


@njit(cache=True, inline="always")
def local_arrays_at(buf, o, nd, nm):
    """:func:`local_arrays` as views of ``buf`` from entry ``o`` (:func:`local_size` entries;
    zeroed by the caller)."""
    a = o + nd + nm
    return (carve(buf, o, nd), carve(buf, o + nd, nm), carve(buf, a, (nd, nd)),
            carve(buf, a + nd * nd, (nd, nd)), carve(buf, a + 2 * nd * nd, (nd, nd)),
            carve(buf, a + 3 * nd * nd, (nm, nd)))


@njit(cache=True, inline="always")
def scatter_element(
    rq, rl, M, C, K, G, nnode, lnodes, dofs, kmap, Tn, cM, cC, cK, mode, want, full, r, rabs,
    data,
):
    """:func:`scatter_local` from an element loop: with ``full`` false (a residual-only
    evaluation) no matrix is scattered."""
    scatter_local(rq, rl, M, C, K, G, nnode, lnodes, dofs, kmap, Tn, cM, cC, cK, mode,
                  want and full, r, rabs, data)


@njit(cache=True, inline="always")
def tangent_columns(A, nrows, c0, Tn, node):
    """``A[:nrows, c0:c0+3] <- A[:nrows, c0:c0+3] Tn[node]``: the columns of a node's rotation
    dofs times its tangent operator (``MODE_DYN``)."""
    for i in range(nrows):
        a0 = A[i, c0]
        a1 = A[i, c0 + 1]
        a2 = A[i, c0 + 2]
        for j in range(3):
            A[i, c0 + j] = a0 * Tn[node, 0, j] + a1 * Tn[node, 1, j] + a2 * Tn[node, 2, j]


@njit(cache=True)
def _scatter_matrix(M, C, K, G, nnode, nm, lnodes, kmap, Tn, cM, cC, cK, mode, data):
    """Matrix part of :func:`scatter_local` (out of line so that residual-only evaluations
    do not carry its code in their loops)."""
    nd = 6 * nnode
    nloc = nd + nm
    # multiplier columns: d rq / d lam = G^T (no tangent operator: lam is not on the group)
    for i in range(nm):
        for j in range(nd):
            p = kmap[j * nloc + nd + i]
            if p >= 0:
                data[p] += G[i, j]
    if mode == MODE_DYN:
        # K T and G T on rotation columns
        for a in range(nnode):
            tangent_columns(K, nd, 6 * a + 3, Tn, lnodes[a])
            tangent_columns(G, nm, 6 * a + 3, Tn, lnodes[a])
        for i in range(nd):
            for j in range(nd):
                p = kmap[i * nloc + j]
                if p >= 0:
                    data[p] += cM * M[i, j] + cC * C[i, j] + cK * K[i, j]
    else:
        for i in range(nd):
            for j in range(nd):
                p = kmap[i * nloc + j]
                if p >= 0:
                    data[p] += M[i, j]
    for i in range(nm):
        for j in range(nd):
            p = kmap[(nd + i) * nloc + j]
            if p >= 0:
                data[p] += G[i, j]


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


class ElementSpec:
    """Base class of element parameter records (frozen dataclasses).

    Subclasses set ``family`` (the registry key) and ``units`` (the SI unit of each
    dimensional parameter, used by model files), and implement ``markers()`` (names of the
    markers they attach to, used for validation) and ``validate()``.
    """

    family: ClassVar[str] = ""
    #: SI unit of each dimensional parameter (``{"stiffness": "N/m"}``); model files may give
    #: these with any unit of the same dimension, the others only as plain numbers.
    units: ClassVar[dict[str, str]] = {}
    name: str

    def markers(self) -> tuple[str, ...]:
        return ()

    def validate(self) -> None:  # pragma: no cover - default accepts
        return None

    def visuals(self) -> tuple:
        """The shapes the 3-D viewer draws for this element
        (:class:`drivedyn.elements.framework.visuals.Visual` records on its markers); none by default."""
        return ()


@dataclass(frozen=True)
class TwoMarkerSpec(ElementSpec):
    """Base of the elements between two markers: ``name``, ``marker_a``, ``marker_b`` first,
    then the family's own fields."""

    name: str
    marker_a: str
    marker_b: str

    def markers(self) -> tuple[str, ...]:
        return (self.marker_a, self.marker_b)


class Family(abc.ABC):
    """Registry entry: builds a :class:`Group` from all specs of one family.

    ``build(specs, ctx)`` receives the element specs (in model order) and a
    :class:`drivedyn.model.compile.BuildContext` giving marker frames, multiplier and state
    allocation and time-function ids. The small models that exercise each family for the
    registry tangent test are test fixtures (``tests/element_cases``), keyed by ``name``.
    """

    name: ClassVar[str] = ""
    spec_types: ClassVar[tuple[type, ...]] = ()

    @abc.abstractmethod
    def build(self, specs: Sequence[Any], ctx: Any) -> Group:
        """The group of all ``specs`` of this family."""


REGISTRY: dict[str, Family] = {}


def register(family: Family) -> Family:
    """Add a family to the registry (one line in each element module)."""
    if family.name in REGISTRY:
        raise ValueError(f"element family {family.name!r} registered twice")
    REGISTRY[family.name] = family
    return family


def family_of(spec: Any) -> Family:
    """Return the registered family of an element spec."""
    fam = REGISTRY.get(getattr(spec, "family", ""))
    if fam is None:
        raise TypeError(f"{type(spec).__name__} is not a registered element type")
    return fam
