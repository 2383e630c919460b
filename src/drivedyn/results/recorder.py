"""Samples node states, element outputs and the energy account at output times.

The solver hands this module plain arrays only (the state and each group's per-element
``eout``/``aux`` arrays, see :mod:`drivedyn.elements.framework.group`); results never import
the solver."""

from __future__ import annotations

import json
from typing import Any

import numpy as np
from numba import njit

from drivedyn.elements.framework.group import aux_offset
from drivedyn.model.model import Model, State

# fields of EnergyAccount.acc
E_WORK_IN, E_WORK_LOADS, E_WORK_DRIVERS, E_KINETIC, E_POTENTIAL = range(5)


@njit(cache=True)
def advance_energy(eout, gstart, gdriver, pin, pd, diss, acc, h):
    """Trapezoidal integration of the powers over an accepted step of size ``h`` [s].

    ``eout`` (nel, 4): every element's kinetic and potential energy [J], input and
    dissipated power [W] at the new state, group ``g`` in rows ``gstart[g]:gstart[g+1]``
    (``gdriver[g]``: its work counts as drivers', else as loads'); ``pin``, ``pd`` (nel,):
    the powers at the previous state, updated; ``diss`` (nel,): energies dissipated so far
    [J], updated; ``acc``: work in, of loads, of drivers [J] (updated), kinetic and potential
    energy [J] (set)."""
    ek = 0.0
    ep = 0.0
    for gi in range(gstart.shape[0] - 1):
        dw = 0.0
        k = 0.0
        p = 0.0
        for e in range(gstart[gi], gstart[gi + 1]):
            dw += 0.5 * h * (pin[e] + eout[e, 2])
            diss[e] += 0.5 * h * (pd[e] + eout[e, 3])
            pin[e] = eout[e, 2]
            pd[e] = eout[e, 3]
            k += eout[e, 0]
            p += eout[e, 1]
        acc[E_WORK_IN] += dw
        # constraint elements (drivers, rheonomic joints) vs applied loads
        if gdriver[gi]:
            acc[E_WORK_DRIVERS] += dw
        else:
            acc[E_WORK_LOADS] += dw
        ek += k
        ep += p
    acc[E_KINETIC] = ek
    acc[E_POTENTIAL] = ep


@njit(cache=True)
def total(diss):
    """Sum of the energies dissipated by all elements [J], in index order (the compiled loop
    and :meth:`Recorder.record` add them alike)."""
    d = 0.0
    for i in range(diss.shape[0]):
        d += diss[i]
    return d


def import_dataset_stack() -> None:
    """Import what :meth:`Recorder.dataset` imports on first use: xarray, pandas, and the
    duck-array modules xarray looks for when it wraps the first array (``dask.array``, when
    dask is installed). 0.9 s on the 2-core reference machine, which the first compilation
    of a model's kernels does while its workers compile
    (:func:`drivedyn.solver.precompile.precompile_kernels`), not after them."""
    import xarray as xr

    xr.Variable(("time",), np.zeros(1))


def _fields(m: Model, g, ei: int, en: str, A: np.ndarray) -> dict[str, tuple]:
    """Field variables of element ``ei`` of group ``g`` (meshed flexible parts and their
    contacts) from its aux history ``A`` (nt, naux)."""
    if "parts" in g.extra:
        from drivedyn.results.flexible_fields import part_variables

        mount = g.extra["mounts"][ei]
        return part_variables(en, g.extra["parts"][ei], mount,
                              m.nodes[mount["node"]].name, A, g.extra["q_column"])
    if "fields" in g.extra:
        f = g.extra["fields"][ei]
        pd = f"{en}.point"
        return {f"{en}.{f['name']}": (("time", pd), A[:, f["column"]:f["column"] + f["count"]],
                                      f["units"], f["description"]),
                f"{en}.face_points": ((pd, "xyz"), f["points"], "m", f["points_description"])}
    return {}


class EnergyAccount:
    """Energy bookkeeping of a run (trapezoidal integration of powers over accepted steps).

    ``balance_error = (T + V) - (T0 + V0) - W_in + D``: zero for an exact solution; what is
    left is numerical dissipation (or creation) of the integrator and constraint drift.

    Attributes:
        e0: kinetic + potential energy at the start [J].
        work_in: work supplied by loads and drivers [J].
        dissipated: (per group) arrays of energy dissipated by each element [J]: views of
            ``diss``, all elements group after group.
        acc: work in, of loads, of drivers, kinetic and potential energy [J] (``E_*``);
            ``work_in``, ``work_loads``... read it. The compiled stepping loop
            (:mod:`drivedyn.solver.step_loop`) advances ``acc``, ``pin``, ``pd`` and ``diss``
            with :func:`advance_energy` as :meth:`advance` does.
    """

    def __init__(self, model: Model) -> None:
        self.model = model
        groups = model.groups
        self.e0 = 0.0
        self.gstart = np.concatenate([[0], np.cumsum([g.nel for g in groups])]).astype(np.int64)
        self.gdriver = np.array([g.nmult > 0 for g in groups], dtype=np.bool_)
        # per element, all groups in one array (per group: views)
        n = int(self.gstart[-1])
        self.pin, self.pd, self.diss = np.zeros(n), np.zeros(n), np.zeros(n)
        self.dissipated = [self.diss[a:b] for a, b in zip(self.gstart[:-1], self.gstart[1:],
                                                          strict=True)]
        self.acc = np.zeros(5)
        if model.eout_all is not None:
            self.eout = model.eout_all
        else:  # a model compiled without model-wide output arrays
            self.eout = np.zeros((n, 4))

    work_in = property(lambda self: float(self.acc[E_WORK_IN]),
                       doc="work supplied by loads and drivers [J]")
    work_loads = property(lambda self: float(self.acc[E_WORK_LOADS]), doc="work of loads [J]")
    work_drivers = property(lambda self: float(self.acc[E_WORK_DRIVERS]),
                            doc="work of drivers and rheonomic joints [J]")
    kinetic = property(lambda self: float(self.acc[E_KINETIC]), doc="kinetic energy [J]")
    potential = property(lambda self: float(self.acc[E_POTENTIAL]), doc="potential energy [J]")

    def _gather(self) -> None:
        if self.model.eout_all is None:
            self.eout[:] = np.concatenate([g.eout for g in self.model.groups])

    def start(self) -> None:
        """Take the energies and powers at the start from the groups' ``eout`` arrays (after
        an evaluation at the initial state)."""
        self._gather()
        self.acc[E_KINETIC] = float(sum(g.eout[:, 0].sum() for g in self.model.groups))
        self.acc[E_POTENTIAL] = float(sum(g.eout[:, 1].sum() for g in self.model.groups))
        self.e0 = self.kinetic + self.potential
        self.pin[:] = self.eout[:, 2]
        self.pd[:] = self.eout[:, 3]

    def advance(self, h: float) -> None:
        """Integrate the powers over an accepted step of size ``h`` [s] (after evaluation at
        the new state, so the groups' ``eout`` hold the new powers)."""
        self._gather()
        advance_energy(self.eout, self.gstart, self.gdriver, self.pin, self.pd, self.diss,
                       self.acc, h)

    @property
    def total_dissipated(self) -> float:
        return float(self.diss.sum())

    @property
    def balance_error(self) -> float:
        return self.kinetic + self.potential - self.e0 - self.work_in + self.total_dissipated


def _aux_slices(model: Model) -> list[tuple[int, tuple[int, ...]]] | None:
    """(offset, shape) of each group's ``aux`` in ``model.aux_all``, or None unless every
    one is a C-contiguous view of it."""
    aux_all = model.aux_all
    if aux_all is None:
        return None
    out = [(aux_offset(g, aux_all), tuple(g.aux.shape)) for g in model.groups]
    return None if any(off < 0 for off, _ in out) else out


_NODE_VARIABLES = ("position", "rotation", "velocity", "angular_velocity")


class Selection:
    """What a recorder stores of each snapshot: the variables that the glob patterns
    ``variables`` name (None: all), and no more.

    Attributes:
        nodes: indices of the nodes whose position, rotation and velocities are stored.
        aux: entries of ``model.aux_all`` stored (increasing; an element whose field
            variables are kept keeps its whole row, in one block).
        diss: elements (group after group) whose energy dissipated is stored.
        arrays: ``(nodes, aux, diss)``, the compiled loop's selection (int64 arrays).
        everything: no pattern (every variable is kept).

    The energy terms and the step size are always recorded (scalars per output).
    """

    def __init__(self, model: Model, variables: list[str] | None,
                 slices: list[tuple[int, tuple[int, ...]]] | None) -> None:
        import fnmatch

        self.everything = variables is None
        pats = [] if variables is None else list(variables)

        def kept(name: str) -> bool:
            return self.everything or any(fnmatch.fnmatchcase(name, p) for p in pats)

        nodes = [i for i, info in enumerate(model.nodes)
                 if any(kept(f"{info.name}.{q}") for q in _NODE_VARIABLES)]
        aux: set[int] = set()
        diss: list[int] = []
        start = 0
        for gi, g in enumerate(model.groups):
            naux = int(g.aux.shape[1]) if g.aux.ndim == 2 else 0
            off = slices[gi][0] if slices is not None else 0
            cols = list(g.outputs())
            for ei, en in enumerate(g.names):
                row = off + ei * naux
                if g.family == "rigid_body":
                    if kept(f"{en}.angular_momentum"):
                        aux.update(row + c for c in range(3))
                else:
                    wanted = [col for col, name, _u, _d in cols if kept(f"{en}.{name}")]
                    derived = g.derived.cols if g.derived is not None else ()
                    aux.update(row + col for col in wanted if col not in derived)
                    if any(col in derived for col in wanted):  # computed from these
                        aux.update(row + col for col in g.derived.inputs)
                if ("parts" in g.extra or "fields" in g.extra) and any(
                        kept(n) for n in _fields(model, g, ei, en, np.zeros((1, naux)))):
                    aux.update(range(row, row + naux))
                if g.dissipative and kept(f"{en}.dissipated_energy"):
                    diss.append(start + ei)
            start += g.nel
        self.nodes = np.array(nodes, np.int64)
        self.aux = np.array(sorted(aux), np.int64)
        self.diss = np.array(diss, np.int64)
        self.arrays = (self.nodes, self.aux, self.diss)
        size = int(model.aux_all.size) if model.aux_all is not None else 0
        self.aux_pos = np.full(size, -1, np.int64)
        self.aux_pos[self.aux] = np.arange(self.aux.size)
        self.diss_pos = np.full(start, -1, np.int64)
        self.diss_pos[self.diss] = np.arange(self.diss.size)


class Recorder:
    """Stores snapshots at output times and turns them into an ``xarray.Dataset``: only
    what ``variables`` (glob patterns, None: everything) asks for (:class:`Selection`)."""

    def __init__(self, model: Model, energy: EnergyAccount,
                 variables: list[str] | None = None) -> None:
        self.model = model
        self.energy = energy
        self.variables = None if variables is None else list(variables)
        self.t: list[float] = []
        self.x: list[np.ndarray] = []
        self.R: list[np.ndarray] = []
        self.v: list[np.ndarray] = []
        self.aux: list = []  # copies of model.aux_all, or per group (see _aux_slices)
        self.en: list[tuple[float, ...]] = []
        self.diss: list[np.ndarray] = []  # all elements, group after group
        self.h: list[float] = []
        # all groups' outputs in one copy of model.aux_all per output when every group's
        # aux is a view of it (the compiled model's layout): one copy instead of one per
        # group, 3.7 % of the Type C vehicle configuration's run (benchmarks/README.md);
        # ``_slices[gi]``: (offset, shape) of group gi in it
        self._slices = _aux_slices(model)
        # a model whose outputs are not views of aux_all keeps every output (per group)
        self.selection = Selection(model, self.variables, self._slices)

    def record(self, st: State, h: float = 0.0) -> None:
        nn = self.model.nn
        sel = self.selection
        self.t.append(st.t)
        self.x.append(st.x[sel.nodes])
        self.R.append(st.R[sel.nodes])
        self.v.append(st.v.reshape(nn, 6)[sel.nodes] if nn else np.zeros((0, 6)))
        if self._slices is not None:
            self.aux.append(self.model.aux_all[sel.aux])
        else:
            self.aux.append([g.aux.copy() for g in self.model.groups])
        e = self.energy
        self.en.append(self._energies(e.acc, total(e.diss)))
        self.diss.append(e.diss[sel.diss])
        self.h.append(h)

    def extend(self, t: np.ndarray, x: np.ndarray, R: np.ndarray, v: np.ndarray,
               aux_all: np.ndarray, acc: np.ndarray, diss: np.ndarray,
               h: np.ndarray) -> None:
        """Snapshots stored by the compiled stepping loop (:mod:`drivedyn.solver.step_loop`),
        one per row, of the :class:`Selection` only: times (n,) [s], positions (n, k, 3),
        rotations (n, k, 3, 3), velocities (n, k, 6) of its k nodes, its entries of
        ``model.aux_all`` (n, a), the energy account's ``acc`` with the total energy
        dissipated appended (n, 6), its elements' energies dissipated (n, d), step sizes
        (n,) [s]. The same values as :meth:`record` at each of those times; the rows are
        kept as views."""
        if self._slices is None:  # the loop stores model.aux_all only for such models
            raise ValueError("Recorder.extend: the groups' outputs are not views of "
                             "model.aux_all")
        for i in range(t.shape[0]):
            self.t.append(float(t[i]))
            self.x.append(x[i])
            self.R.append(R[i])
            self.v.append(v[i])
            self.aux.append(aux_all[i])
            self.en.append(self._energies(acc[i], float(acc[i, -1])))
            self.diss.append(diss[i])
            self.h.append(float(h[i]))

    def _energies(self, acc: np.ndarray, d: float) -> tuple[float, ...]:
        """The recorded energy terms (kinetic, potential, work in, dissipated, balance error,
        work of loads, of drivers) [J] from an energy account's ``acc`` and the total energy
        dissipated ``d`` [J]."""
        kin, pot, w_in = float(acc[E_KINETIC]), float(acc[E_POTENTIAL]), float(acc[E_WORK_IN])
        return (kin, pot, w_in, d, kin + pot - self.energy.e0 - w_in + d,
                float(acc[E_WORK_LOADS]), float(acc[E_WORK_DRIVERS]))

    @property
    def extendable(self) -> bool:
        """:meth:`extend` can take this model's snapshots."""
        return self._slices is not None

    def _group_aux(self, gi: int, stacked: np.ndarray | None) -> np.ndarray:
        """Outputs of group ``gi`` at every output time, (nt, nel, naux); ``stacked``: the
        recorded copies of ``aux_all`` as one array (nt, size) when they are such copies."""
        if stacked is None or self._slices is None:
            return np.asarray([a[gi] for a in self.aux])
        off, shape = self._slices[gi]
        n = int(np.prod(shape))
        return stacked[:, off:off + n].reshape((stacked.shape[0], *shape))

    def _series(self) -> tuple[list, ...]:
        return self.t, self.x, self.R, self.v, self.aux, self.en, self.diss, self.h

    def drop_partial(self) -> None:
        """Drop a snapshot that :meth:`record` left incomplete: a Ctrl-C (KeyboardInterrupt)
        can arrive between two of its appends, and the partial results are then written
        from snapshots of unequal lengths otherwise."""
        n = min(len(s) for s in self._series())
        for s in self._series():
            del s[n:]

    def __len__(self) -> int:
        return len(self.t)

    def dataset(self, attrs: dict | None = None, variables: list[str] | None = None):
        """The recorded data as an ``xarray.Dataset`` (one variable per sensor): the
        contents of :meth:`contents`."""
        import xarray as xr

        from drivedyn.results.results import resolved

        data_vars, coords, attrs = self.contents(attrs, variables)
        return xr.Dataset(resolved(data_vars), coords=coords, attrs=attrs)

    def contents(self, attrs: dict | None = None, variables: list[str] | None = None,
                 ) -> tuple[dict, dict, dict]:
        """The recorded data as plain arrays, xarray not imported: ``(data_vars, coords,
        attrs)`` with ``data_vars[name] = (dims, values, {"units", "description"...})`` (one
        per sensor), the coordinates as ``(dims, values[, attrs])`` and the dataset's
        attributes, ready for ``xarray.Dataset(data_vars, coords=coords, attrs=attrs)``.

        ``variables``: glob patterns (``"crank.*"``, ``"*.torque"``) of the variables to keep
        (default: the recorder's own); the energy terms are always kept. None keeps
        everything recorded."""
        if variables is None:
            variables = self.variables
        self.drop_partial()
        m = self.model
        t = np.asarray(self.t, dtype=float)
        nt = len(t)
        data_vars: dict[str, tuple] = {}

        def put(name, dims, values, units, desc):
            data_vars[name] = (dims, values, {"units": units, "description": desc})

        sel = self.selection
        if sel.nodes.size and nt:
            X = np.asarray(self.x)
            Rm = np.asarray(self.R)
            V = np.asarray(self.v)
            omega_g = np.einsum("tnij,tnj->tni", Rm, V[:, :, 3:])
            for i, node in enumerate(sel.nodes):
                info = m.nodes[int(node)]
                n = info.name
                what = "centre of mass" if info.body else "node origin"
                put(f"{n}.position", ("time", "xyz"), X[:, i], "m",
                    f"position of the {what} of {n}, global frame")
                put(f"{n}.rotation", ("time", "row", "col"), Rm[:, i], "1",
                    f"rotation matrix of {n} (body to global)")
                put(f"{n}.velocity", ("time", "xyz"), V[:, i, :3], "m/s",
                    f"velocity of the {what} of {n}, global frame")
                put(f"{n}.angular_velocity", ("time", "xyz"), omega_g[:, i], "rad/s",
                    f"angular velocity of {n}, global frame")
        Dall = np.asarray(self.diss).reshape(nt, sel.diss.size)  # (nt, selected elements)
        stacked = np.asarray(self.aux) if self._slices is not None and nt else None
        for gi, g in enumerate(m.groups):
            if nt == 0:
                break
            A = None
            if stacked is None:
                A = np.asarray([a[gi] for a in self.aux])  # (nt, nel, naux), every output
                off, naux = 0, A.shape[2]
            else:
                off, shape = self._slices[gi]
                naux = shape[1] if len(shape) == 2 else 0
            column = _ColumnReader(A, stacked, sel.aux_pos, off, naux)
            for ei, en in enumerate(g.names):
                if g.family != "rigid_body":
                    derived = _derived_columns(g, ei, column)
                    for col, name, unit, desc in g.outputs():
                        c = derived[col] if col in derived else column.output(ei, col)
                        if c is not None:
                            put(f"{en}.{name}", ("time",), c, unit, f"{desc} ({g.family})")
                if g.dissipative:
                    p = sel.diss_pos[self.energy.gstart[gi] + ei]
                    if p >= 0:
                        put(f"{en}.dissipated_energy", ("time",), Dall[:, p], "J",
                            f"energy dissipated by {en} since the start")
            if "parts" in g.extra or "fields" in g.extra:
                for ei, en in enumerate(g.names):
                    # fields of meshed parts (stresses, pressures), see flexible_fields
                    Ar = column.row(ei)
                    if Ar is None:
                        continue
                    for name, spec in _fields(m, g, ei, en, Ar).items():
                        put(name, spec[0], spec[1], spec[2], spec[3])
                        if len(spec) > 4:
                            data_vars[name][2].update(spec[4])
            if g.family == "rigid_body":
                for ei, en in enumerate(g.names):
                    cs = [column.output(ei, c) for c in range(3)]
                    if all(c is not None for c in cs):
                        put(f"{en}.angular_momentum", ("time", "xyz"), np.stack(cs, axis=1),
                            "kg m^2/s", f"angular momentum of {en} about its centre of "
                            "mass, global frame")
        E = np.asarray(self.en).reshape(nt, 7)
        for j, (name, desc) in enumerate((
            ("kinetic", "kinetic energy of all bodies"),
            ("potential", "potential energy (gravity and springs)"),
            ("work_in", "work supplied by loads and drivers since the start"),
            ("dissipated", "energy dissipated by all dissipative elements since the start"),
            ("balance_error", "(T + V) - (T0 + V0) - W_in + D: numerical energy error"),
            ("work_loads", "work of the applied forces and torques since the start"),
            ("work_drivers", "work of drivers (rheonomic constraints) since the start"),
        )):
            put(f"energy.{name}", ("time",), E[:, j], "J", desc)
        put("solver.step_size", ("time",), np.asarray(self.h, dtype=float), "s",
            "step size of the step that reached this output time")
        if variables is not None:
            import fnmatch

            data_vars = {k: v for k, v in data_vars.items()
                         if k.startswith(("energy.", "solver."))
                         or any(fnmatch.fnmatchcase(k, p) for p in variables)}
        coords = {"time": ("time", t, {"units": "s", "description": "simulated time"}),
                  "xyz": ("xyz", ["x", "y", "z"]), "row": ("row", [0, 1, 2]),
                  "col": ("col", [0, 1, 2])}
        attrs = dict(attrs or {})
        beams = {en: [m.nodes[int(n)].name for n in g.lnodes[ei]]
                 for g in m.groups if g.family == "beam" for ei, en in enumerate(g.names)}
        if beams:
            # the beams' topology, for the deformed-shape plots: element -> [node_a, node_b]
            attrs["beam_elements"] = json.dumps(beams)
        attrs["scene"] = _scene_json(m)
        attrs["model_summary"] = json.dumps(model_summary(m))
        return data_vars, coords, attrs


def _derived_columns(g, ei: int, column: _ColumnReader) -> dict[int, Any]:
    """The derived outputs of element ``ei`` of group ``g``
    (:class:`~drivedyn.elements.framework.group.DerivedOutputs`) as
    :class:`~drivedyn.results.flexible_fields.Deferred` values computed on first use, by aux
    column; None for each if their inputs were not recorded; {} for a group without."""
    d = g.derived
    if d is None:
        return {}
    inputs = [column.output(ei, c) for c in d.inputs]
    if any(c is None for c in inputs):
        return dict.fromkeys(d.cols)
    from drivedyn.results.flexible_fields import Deferred

    source = DerivedSource(d.fn, ei, np.stack(inputs, axis=1), d.cols)
    return {c: Deferred(source, c) for c in d.cols}


class DerivedSource:
    """Derived outputs of one element over a run, computed on first use (a
    :class:`~drivedyn.results.flexible_fields.Deferred`'s source). Picklable with its
    function (a forked bench side returns its results to the parent)."""

    def __init__(self, fn, ei: int, inputs: np.ndarray, cols: tuple[int, ...]) -> None:
        self.fn, self.ei, self.inputs, self.cols = fn, ei, inputs, cols
        self._values: np.ndarray | None = None

    def field(self, col: int) -> np.ndarray:
        """The values (nt,) of aux column ``col``."""
        if self._values is None:
            self._values = self.fn(self.ei, self.inputs)
        return self._values[:, self.cols.index(col)]


class _ColumnReader:
    """A group's recorded outputs over time: from its full output history ``A`` (nt, nel,
    naux), or from the recorder's stacked selection ``stacked`` (nt, selected entries) with
    the positions ``pos`` of the entries of ``model.aux_all`` in it (-1: not stored), the
    group's table at offset ``off`` with ``naux`` columns per element."""

    def __init__(self, A, stacked, pos, off: int, naux: int) -> None:
        self.A, self.stacked, self.pos, self.off, self.naux = A, stacked, pos, off, naux

    def output(self, ei: int, col: int):
        """Output ``col`` of element ``ei`` over time (nt,), or None if not stored."""
        if self.A is not None:
            return self.A[:, ei, col]
        p = self.pos[self.off + ei * self.naux + col]
        return None if p < 0 else self.stacked[:, p]

    def row(self, ei: int):
        """Every output of element ``ei`` over time (nt, naux), or None if not stored."""
        if self.A is not None:
            return self.A[:, ei, :]
        p = self.pos[self.off + ei * self.naux] if self.naux else -1
        return None if p < 0 else self.stacked[:, p:p + self.naux]


def model_summary(model: Model) -> dict:
    """Size of a compiled model, kept in its results for the run report: rigid bodies,
    nodes without mass of their own, coordinates (6 per node), constraint multipliers,
    equations, and the elements by type (count and names)."""
    families: dict[str, list[str]] = {}
    for g in model.groups:
        # a group of mixed types (all joints are one group) is listed by type
        kinds = g.extra.get("kinds") or [g.family] * len(g.names)
        for kind, name in zip(kinds, g.names, strict=True):
            families.setdefault(kind, []).append(name)
    return {"bodies": sum(1 for n in model.nodes if n.body is not None),
            "nodes": sum(1 for n in model.nodes if n.body is None),
            "coordinates": int(model.nd), "multipliers": int(model.nm),
            "equations": int(model.neq), "internal_states": int(model.nstate),
            "elements": {f: {"count": len(n), "names": n} for f, n in families.items()}}


def _scene_json(model: Model) -> str:
    """The model's visual scene as JSON (:mod:`drivedyn.results.scene`); a shape that cannot
    be resolved must not cost the user the results of the run, so a failure is recorded in
    the scene instead of raised."""
    from drivedyn.results.scene import scene_description

    try:
        return json.dumps(scene_description(model))
    except Exception as exc:  # reported in the file: the run is kept
        return json.dumps({"version": 1, "error": f"{type(exc).__name__}: {exc}"})


def variable_names(model: Model) -> dict[str, tuple[str, ...]]:
    """Name -> dimensions of every variable a run of ``model`` records (from one snapshot of
    its initial state; no time step is taken)."""
    energy = EnergyAccount(model)
    energy.start()
    rec = Recorder(model, energy)
    rec.record(model.initial_state())
    return {str(k): tuple(v.dims) for k, v in rec.dataset().data_vars.items()}
