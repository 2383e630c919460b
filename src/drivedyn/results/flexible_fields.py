"""Fields of meshed flexible parts over time: stresses from the elastic coordinates, deformed
node positions, contact pressures; export for ParaView (VTU series with a PVD index).

Variables written into a run's Dataset (by :meth:`Recorder.dataset`) for each
:class:`~drivedyn.elements.flexible.FlexibleBody` ``P`` and flexible washer contact ``W``:

==============================  =================  ==========================================
``P.q``                         (time, mode)       elastic coordinates
``P.von_mises``                 (time, P.node)     nodal von Mises stress [Pa]
``P.principal_max/min``         (time, P.node)     largest / smallest principal stress [Pa]
``P.max_von_mises``             (time,)            largest nodal von Mises stress [Pa]
``P.basis``                     (P.node, 3, mode)  displacement per coordinate, host frame [m]
``P.mesh_points``               (P.node, 3)        undeformed nodes, host frame [m]
``P.mesh_cells``                (P.cell, 8 or 4)   vertex indices of the linear cells
``W.contact_pressure``          (time, W.point)    pressure at the contact points [Pa]
``W.face_points``               (W.point, 3)       contact points, washer part frame [m]
==============================  =================  ==========================================

The host node of a part is named by the attribute ``host`` of ``P.mesh_points``; its
``position`` and ``rotation`` variables place the part: ``r = x + R (X + u)``.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from drivedyn.fe.solid import principal_stresses, von_mises

CHUNK = 64  # outputs per block of the stress post-processing (bounds its memory)


def displacement(ds: Any, part: str) -> np.ndarray:
    """Elastic displacements (time, node, 3) [m], host frame, of ``part`` in results ``ds``."""
    return np.einsum("ndk,tk->tnd", ds[f"{part}.basis"].values, ds[f"{part}.q"].values)


def stress_of(part: Any, q: np.ndarray) -> np.ndarray:
    """Nodal stresses (n, 6) [Pa] (part frame, Voigt ``xx yy zz yz xz xy``) of the elastic
    coordinates ``q`` (nq,): they depend on ``q`` only, not on the rigid motion."""
    return np.einsum("nck,k->nc", part.stress, np.asarray(q, float))


class PartStresses:
    """The nodal stress fields of a part over a run, computed on first use: a TDR run reads
    none of them, and they were most of the post-processing of the flexible benches (0.19 s of
    a Type C bench side with five washers). Picklable (a forked bench side returns its
    results to the parent): it holds the arrays, not a function.

    Attributes:
        stress: (n, 6, nq) nodal stresses of the basis [Pa per unit coordinate].
        q: (nt, nq) elastic coordinates at the output times.
    """

    def __init__(self, stress: np.ndarray, q: np.ndarray) -> None:
        self.stress = stress
        self.q = q
        self._fields: dict[str, np.ndarray] | None = None

    def field(self, key: str) -> np.ndarray:
        """``von_mises``, ``principal_max``, ``principal_min`` (nt, n) or ``max_von_mises``
        (nt,) [Pa]."""
        if self._fields is None:
            nt, n = self.q.shape[0], self.stress.shape[0]
            vm = np.empty((nt, n))
            pmax = np.empty((nt, n))
            pmin = np.empty((nt, n))
            # by chunks of outputs: the stress tensors of every node at every output would
            # not fit
            for k0 in range(0, nt, CHUNK):
                S = np.einsum("nck,tk->tnc", self.stress, self.q[k0:k0 + CHUNK])
                vm[k0:k0 + CHUNK] = von_mises(S)
                pr = principal_stresses(S)
                pmax[k0:k0 + CHUNK] = pr[..., 0]
                pmin[k0:k0 + CHUNK] = pr[..., 2]
            self._fields = {"von_mises": vm, "principal_max": pmax, "principal_min": pmin,
                            "max_von_mises": vm.max(axis=1)}
        return self._fields[key]


class Deferred:
    """A variable's values computed on first use (``np.asarray(d)``): one field of a
    :class:`PartStresses`. :class:`~drivedyn.results.results.Results` resolves it when a
    variable is read or the dataset is built."""

    def __init__(self, source: PartStresses, key: str) -> None:
        self.source = source
        self.key = key

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        a = self.source.field(self.key)
        return a if dtype is None else a.astype(dtype)


def part_variables(name: str, part: Any, mount: dict, host: str, A: np.ndarray,
                   q_col: int) -> dict[str, tuple]:
    """Dataset variables ``name -> (dims, values, units, description)`` of a flexible part
    from its recorded aux rows ``A`` (nt, naux); the stress fields are :class:`Deferred`."""
    q = A[:, q_col:q_col + part.nq]
    stresses = PartStresses(part.stress, q)
    vm, pmax, pmin, vmax = (Deferred(stresses, k) for k in
                            ("von_mises", "principal_max", "principal_min", "max_von_mises"))
    nd, cd = f"{name}.node", f"{name}.cell"
    return {
        f"{name}.q": (("time", f"{name}.mode"), q, "1",
                      "elastic coordinates (constraint modes [m, rad], then modal)"),
        f"{name}.von_mises": (("time", nd), vm, "Pa", "nodal von Mises stress"),
        f"{name}.principal_max": (("time", nd), pmax, "Pa", "largest principal stress"),
        f"{name}.principal_min": (("time", nd), pmin, "Pa", "smallest principal stress"),
        f"{name}.max_von_mises": (("time",), vmax, "Pa",
                                  "largest nodal von Mises stress of the part"),
        f"{name}.basis": ((nd, "xyz", f"{name}.mode"), mount["Phi"], "m",
                          "nodal displacement of each elastic coordinate, host frame "
                          "(displacement = basis . q)"),
        f"{name}.mesh_points": ((nd, "xyz"), mount["X"], "m",
                                f"undeformed nodes in the frame of node {host}", {"host": host}),
        f"{name}.mesh_cells": ((cd, f"{name}.vertex"), np.asarray(part.cells), "1",
                               f"linear cells ({'hexahedron' if part.kind == 'hex' else 'tetra'}"
                               "), node indices", {"cell_type": "hexahedron" if part.kind ==
                                                  "hex" else "tetra"}),
    }


def write_vtu_series(ds: Any, part: str, out_dir: str | os.PathLike,
                     scale: float = 1.0) -> Path:
    """Write the deformed, stress-coloured ``part`` of the results ``ds`` at every output
    time as VTU files plus a ``{part}.pvd`` index for ParaView (global frame, displacements
    magnified by ``scale``); returns the PVD path."""
    import meshio

    from drivedyn.errors import ModelError

    key = f"{part}.mesh_points"
    if key not in ds:
        parts = sorted(k[:-12] for k in ds.data_vars if k.endswith(".mesh_points"))
        raise ModelError(f"no flexible part {part!r} in the results (parts: "
                         f"{', '.join(parts) or 'none'})")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    X = ds[key].values
    host = ds[key].attrs["host"]
    cells = ds[f"{part}.mesh_cells"].values
    ctype = ds[f"{part}.mesh_cells"].attrs["cell_type"]
    nv = int(cells.max()) + 1
    xs = ds[f"{host}.position"].values
    Rs = ds[f"{host}.rotation"].values
    U = displacement(ds, part)
    vm = ds[f"{part}.von_mises"].values
    entries = []
    for k, t in enumerate(ds["time"].values):
        r = xs[k] + (X[:nv] + scale * U[k, :nv]) @ Rs[k].T
        f = out / f"{part}_{k:05d}.vtu"
        meshio.write(f, meshio.Mesh(r, [(ctype, cells)], point_data={
            "von_mises": vm[k, :nv], "displacement": U[k, :nv] @ Rs[k].T,
            "principal_max": ds[f"{part}.principal_max"].values[k, :nv]}))
        entries.append(f'    <DataSet timestep="{float(t)!r}" file="{f.name}"/>')
    pvd = out / f"{part}.pvd"
    pvd.write_text('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
                   "  <Collection>\n" + "\n".join(entries) + "\n  </Collection>\n</VTKFile>\n")
    return pvd
