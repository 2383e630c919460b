"""``compile(spec) -> Model``: checks a Spec and builds flat arrays, groups and index maps."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from drivedyn.elements.framework.group import allocate_outputs
from drivedyn.elements.framework.registry import REGISTRY, family_of
from drivedyn.errors import did_you_mean
from drivedyn.model.model import Model, NodeInfo, State
from drivedyn.model.spec import GROUND, ModelError, Spec
from drivedyn.timefunctions import TimeFunctionPool, as_time_function

_DOF_NAMES = ("ux", "uy", "uz", "rx", "ry", "rz")
H_REF = 1e-3  # [s] reference step for the automatic constraint scaling


class BuildContext:
    """What an element family needs while building its group (see :class:`Family`)."""

    def __init__(self, spec: Spec, node_index: dict[str, int], marker_frames, nn: int,
                 x0: np.ndarray, R0: np.ndarray, k_default: tuple[float, float]) -> None:
        self.spec = spec
        self.node_index = node_index
        self.marker_frames = marker_frames
        self.nn = nn
        self.nd = 6 * nn
        self.x0 = x0
        self.R0 = R0
        self.k_default = k_default
        self.nm = 0
        self.mult_labels: list[str] = []
        self.mult_k: list[float] = []
        self.mult_bilateral: list[bool] = []
        self.es0: list[float] = []
        self.tf_pool = TimeFunctionPool()

    @property
    def gravity(self) -> np.ndarray:
        return self.spec.settings.gravity

    def marker(self, name: str, owner: str) -> tuple[int, np.ndarray, np.ndarray]:
        """(node index, offset (3,) in node frame, rotation (3, 3) in node frame) of a marker;
        ground markers have node index ``nn`` and global offset/rotation."""
        try:
            return self.marker_frames[name]
        except KeyError:
            raise ModelError(f"{owner}: unknown marker {name!r}"
                             f"{did_you_mean(name, self.marker_frames)}") from None

    def node_dof(self, node: int) -> int:
        """First global dof of ``node`` or -1 for the ground."""
        return -1 if node == self.nn else 6 * node

    def alloc_mult(self, n: int, owner: str, k: Sequence[float],
                   bilateral: bool = True) -> int:
        """Allocate ``n`` multipliers with scaling factors ``k``; returns the first equation.
        ``bilateral``: rows of a constraint that always holds (a joint, a driver), which
        the solver may set aside when they are redundant
        (:mod:`~drivedyn.solver.redundancy`); False for rows that choose their own state
        (a unilateral contact)."""
        start = self.nd + self.nm
        self.nm += n
        self.mult_labels += [f"{owner}: constraint {i}" for i in range(n)]
        self.mult_k += list(k)
        self.mult_bilateral += [bool(bilateral)] * n
        return start

    def alloc_state(self, values: Sequence[float]) -> int:
        """Allocate internal state initialised to ``values``; returns its offset."""
        off = len(self.es0)
        self.es0 += [float(v) for v in values]
        return off

    def time_function(self, f: Any) -> int:
        """Register a time function (number, TimeFunction or dict); returns its id."""
        try:
            return self.tf_pool.add(as_time_function(f))
        except (TypeError, ValueError) as exc:
            raise ModelError(f"time function {f!r}: {exc}") from None

    def scaling(self, k: float | None, p: float | None, rotational: bool) -> tuple[float, float]:
        """Scaling k and penalty p of a constraint row (explicit, model-wide, or automatic)."""
        s = self.spec.settings
        kk = k if k is not None else s.constraint_scaling
        if kk is None:
            kk = self.k_default[1 if rotational else 0]
        pp = p if p is not None else s.constraint_penalty
        if pp is None:
            pp = kk
        if not (kk > 0.0 and np.isfinite(kk)) or not (pp >= 0.0 and np.isfinite(pp)):
            raise ModelError(f"constraint scaling k must be > 0 and penalty p >= 0, got {kk}, {pp}")
        return float(kk), float(pp)

    def local_dofs(self, nodes: Sequence[int], mult_start: int, nmult: int) -> np.ndarray:
        out = []
        for nd_ in nodes:
            d0 = self.node_dof(nd_)
            out += [-1] * 6 if d0 < 0 else list(range(d0, d0 + 6))
        out += list(range(mult_start, mult_start + nmult))
        return np.asarray(out, dtype=np.int64)


def _node_layout(spec: Spec):
    """Nodes from bodies (at their centre of mass) and plain nodes, with initial state."""
    names, infos, xs, Rs, vs = [], [], [], [], []
    for b in spec.bodies.values():
        c = b.rotation @ b.com
        names.append(b.name)
        infos.append(NodeInfo(b.name, b.name, b.mass, b.inertia.copy()))
        xs.append(b.position + c)
        Rs.append(b.rotation)
        vs.append(np.concatenate([b.velocity + np.cross(b.angular_velocity, c),
                                  b.rotation.T @ b.angular_velocity]))
    for n in spec.nodes.values():
        names.append(n.name)
        infos.append(NodeInfo(n.name, None, 0.0, np.zeros((3, 3))))
        xs.append(n.position)
        Rs.append(n.rotation)
        vs.append(np.concatenate([n.velocity, n.rotation.T @ n.angular_velocity]))
    return names, infos, xs, Rs, vs


def _local_pairs(g, neq: int) -> tuple[np.ndarray, np.ndarray]:
    """CSC keys ``col * neq + row`` of every local matrix entry of a group (nel, nloc^2) and
    the mask of those stored (both dofs exist; multiplier-multiplier entries are zero and
    left out, except the diagonal, unless the group sets ``extra["coupled_multipliers"]``:
    a frictional contact's slip rows depend on its normal multiplier)."""
    d = g.dofs
    rows = np.repeat(d, g.nloc, axis=1)
    cols = np.tile(d, (1, g.nloc))
    nodal = 6 * g.nnode
    li = np.repeat(np.arange(g.nloc), g.nloc)
    lj = np.tile(np.arange(g.nloc), g.nloc)
    both_mult = (li >= nodal) & (lj >= nodal) & (li != lj)
    if g.extra.get("coupled_multipliers", False):
        both_mult[:] = False
    mask = (rows >= 0) & (cols >= 0) & ~both_mult[None, :]
    return cols * neq + rows, mask


def compile_model(spec: Spec) -> Model:
    """Check ``spec`` and build the frozen :class:`Model`.

    Raises :class:`ModelError` naming the element for unknown markers, joints with both
    markers on one body, elements of unregistered types and invalid parameters, and for a
    model with nothing to simulate (no bodies or nodes).

    Automatic constraint scaling: ``k = p = m_mean / h_ref^2`` for translation rows and
    ``J_mean / h_ref^2`` for rotation rows (h_ref = 1 ms), i.e. of the order of the inertia
    terms of the iteration matrix, which keeps the saddle-point matrix balanced.
    """
    # make sure every element family is registered
    import drivedyn.elements  # noqa: F401

    names, infos, xs, Rs, vs = _node_layout(spec)
    nn = len(names)
    if nn == 0:
        raise ModelError("nothing to simulate: the model has no bodies or nodes")
    node_index = {n: i for i, n in enumerate(names)}
    x0 = np.zeros((nn + 1, 3))
    R0 = np.tile(np.eye(3), (nn + 1, 1, 1))
    if nn:
        x0[:nn] = np.asarray(xs)
        R0[:nn] = np.asarray(Rs)
    nd = 6 * nn
    v0 = np.concatenate(vs) if nn else np.zeros(0)

    # markers in node frames
    marker_frames: dict[str, tuple[int, np.ndarray, np.ndarray]] = {}
    for m in spec.markers.values():
        if m.body == GROUND:
            marker_frames[m.name] = (nn, m.position.copy(), m.rotation.copy())
        elif m.body in spec.bodies:
            b = spec.bodies[m.body]
            marker_frames[m.name] = (node_index[m.body], m.position - b.com, m.rotation.copy())
        elif m.body in spec.nodes:
            marker_frames[m.name] = (node_index[m.body], m.position.copy(), m.rotation.copy())
        else:
            raise ModelError(f"marker {m.name!r}: unknown body or node {m.body!r}"
                             f"{did_you_mean(m.body, [*spec.bodies, *spec.nodes, GROUND])}")

    masses = [i.mass for i in infos if i.mass > 0]
    inert = [float(np.trace(i.inertia)) / 3 for i in infos if i.mass > 0]
    m_ref = float(np.mean(masses)) if masses else 1.0
    J_ref = float(np.mean(inert)) if inert else 1.0
    k_default = (m_ref / H_REF**2, J_ref / H_REF**2)
    ctx = BuildContext(spec, node_index, marker_frames, nn, x0, R0, k_default)

    # validate elements and group them by family (in order of first appearance)
    by_family: dict[str, list[Any]] = {}
    for e in spec.elements:
        fam = family_of(e)
        for mk in e.markers():
            if mk not in marker_frames:
                raise ModelError(f"{type(e).__name__} {e.name!r}: unknown marker {mk!r}"
                                 f"{did_you_mean(mk, marker_frames)}")
        e.validate()
        by_family.setdefault(fam.name, []).append(e)

    groups = []
    if nn and any(i.mass > 0 for i in infos):
        groups.append(REGISTRY["rigid_body"].build(infos, ctx))
    for fam_name, specs in by_family.items():
        groups.append(REGISTRY[fam_name].build(specs, ctx))

    nm = ctx.nm
    neq = nd + nm
    eout_all, aux_all = allocate_outputs(groups)

    # CSC pattern from all element-local pairs (plus the full diagonal)
    pairs = [_local_pairs(g, neq) for g in groups]
    keys = [np.arange(neq, dtype=np.int64) * (neq + 1)] + [k[m] for k, m in pairs]
    allkeys = np.unique(np.concatenate(keys))
    indices = (allkeys % neq).astype(np.int32)
    colsum = np.bincount((allkeys // neq).astype(np.int64), minlength=neq)
    indptr = np.concatenate([[0], np.cumsum(colsum)]).astype(np.int32)
    for g, (k, m) in zip(groups, pairs, strict=True):
        g.kmap = np.where(m, np.searchsorted(allkeys, k), -1).astype(np.int64)
        if g.kmap.size == 0:
            g.kmap = np.zeros((g.nel, g.nloc * g.nloc), np.int64) - 1

    labels = [f"node {names[i // 6]}: {_DOF_NAMES[i % 6]}" for i in range(nd)] + ctx.mult_labels
    group_of = {}
    for gi, g in enumerate(groups):
        for ei, n in enumerate(g.names):
            if g.family != "rigid_body":
                group_of[n] = (gi, ei)

    es0 = np.asarray(ctx.es0, dtype=float)
    state0 = State(0.0, x0, R0, v0.astype(float), np.zeros(nd), np.zeros(nd), np.zeros(nm),
                   es0 if es0.size else np.zeros(0))
    kscale = np.concatenate([np.ones(nd), np.asarray(ctx.mult_k, dtype=float)])
    return Model(
        spec=spec, nodes=infos, node_index=node_index, groups=groups, group_of=group_of,
        nn=nn, nd=nd, nm=nm, neq=neq, nstate=len(ctx.es0), indptr=indptr, indices=indices,
        eq_labels=labels, tf=ctx.tf_pool.pack(), gravity=spec.settings.gravity.copy(),
        state0=state0, marker_frames=marker_frames, k_default=k_default,
        meta={"kscale": kscale, "tf_pool": ctx.tf_pool,
              "bilateral": np.array(ctx.mult_bilateral, dtype=bool)},
        eout_all=eout_all, aux_all=aux_all,
    )


def compile(spec: Spec) -> Model:
    """Alias of :func:`compile_model`."""
    return compile_model(spec)

