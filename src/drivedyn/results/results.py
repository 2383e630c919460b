"""Results of a run: an ``xarray.Dataset`` with units, the run status and statistics."""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np


def resolved(data_vars: dict[str, tuple]) -> dict[str, tuple]:
    """``data_vars`` of :meth:`Recorder.contents <drivedyn.results.recorder.Recorder.contents>`
    with every value an array: the deferred ones
    (:class:`~drivedyn.results.flexible_fields.Deferred`) computed."""
    return {k: (v[0], np.asarray(v[1]), *v[2:]) for k, v in data_vars.items()}


@dataclass
class RunStats:
    """Counters of a run (filled by the solver, kept with the results)."""

    steps: int = 0
    rejected: int = 0
    newton_iterations: int = 0
    factorizations: int = 0
    residual_evaluations: int = 0
    h_min_used: float = np.inf
    h_max_used: float = 0.0
    wall_s: float = 0.0
    extra: dict = field(default_factory=dict)



class Results:
    """What a simulation returns, also when it failed part-way.

    Attributes:
        dataset: ``xarray.Dataset``, coordinate ``time`` [s], one variable per sensor named
            ``"<body|node|element>.<quantity>"`` or ``"energy.<term>"``, each with ``units``
            and ``description`` attributes.
        success: False if the run stopped before ``t_end``.
        message: why it stopped (time, worst equation, residual), empty on success.
        stats: step, Newton and timing counters.
    """

    def __init__(self, dataset: Any, success: bool, message: str, stats: RunStats,
                 contents: tuple[dict, dict, dict] | None = None) -> None:
        self._dataset = dataset  # None: built from ``contents`` on first use
        self._contents = contents
        self.success = success
        self.message = message
        self.stats = stats
        self.attrs.update({
            "success": int(success),
            "message": message,
            "stats": json.dumps(_jsonable(asdict(stats))),
        })

    @classmethod
    def from_contents(cls, contents: tuple[dict, dict, dict], success: bool, message: str,
                      stats: RunStats) -> Results:
        """Results of a run's recorded arrays (``Recorder.contents``). The ``xarray.Dataset``
        is built on the first use of :attr:`dataset`; :meth:`values`, :attr:`time`,
        :attr:`attrs`, :meth:`variables` and ``in`` read the arrays without it, so a run
        whose figures are taken from a few variables (``drivedyn tdr``) never imports
        xarray and pandas (0.9 s)."""
        return cls(None, success, message, stats, contents)

    @property
    def dataset(self) -> Any:
        """The ``xarray.Dataset`` of the run (built from the arrays on first use)."""
        if self._dataset is None:
            import xarray as xr

            data_vars, coords, attrs = self._contents
            self._dataset = xr.Dataset(resolved(data_vars), coords=coords, attrs=attrs)
            self._contents = None
        return self._dataset

    @property
    def attrs(self) -> dict:
        """The dataset's attributes (run status, statistics, provenance)."""
        return self._contents[2] if self._dataset is None else self._dataset.attrs

    def variables(self, select: Callable[[str, dict], bool] | None = None,
                  ) -> list[tuple[str, dict, np.ndarray]]:
        """``(name, attributes, values)`` of every variable that is not a coordinate, or of
        those for which ``select(name, attributes)`` is true: the values of the others are
        not computed (a flexible part's stress fields are computed when read,
        :mod:`drivedyn.results.flexible_fields`)."""
        if self._dataset is None:
            return [(k, v[2], np.asarray(v[1])) for k, v in self._contents[0].items()
                    if select is None or select(k, v[2])]
        return [(str(k), v.attrs, v.values) for k, v in self._dataset.variables.items()
                if k not in self._dataset.coords and (select is None or select(str(k), v.attrs))]

    def names(self) -> list[str]:
        """The names of the variables that are not coordinates, in the dataset's order,
        without building it (``dataset.data_vars`` imports xarray, and on its first array
        xarray imports dask to check for dask arrays: 0.6 s of the Type C vehicle example's
        run)."""
        if self._dataset is None:
            return list(self._contents[0])
        return [str(k) for k in self._dataset.data_vars]

    def __getitem__(self, name: str) -> Any:
        return self.dataset[name]

    def values(self, name: str) -> np.ndarray:
        """The values of variable ``name`` (an array, time first), without building an
        ``xarray.DataArray``: ``results[name]`` looks through every variable of the dataset
        for coordinates (0.5 ms with the 450 variables of a TORSEN vehicle run; the analysis
        of its levels read 450 of them, 0.23 s)."""
        if self._dataset is None:
            data_vars, coords, _ = self._contents
            if name in data_vars:
                return np.asarray(data_vars[name][1])
            if name in coords:
                return np.asarray(coords[name][1])
            raise KeyError(name)
        return self._dataset.variables[name].values

    def __contains__(self, name: str) -> bool:
        if self._dataset is None:
            return name in self._contents[0] or name in self._contents[1]
        return name in self._dataset

    @property
    def time(self) -> np.ndarray:
        return self.values("time")

    def final(self, name: str) -> np.ndarray:
        """Last recorded value of a variable."""
        return np.asarray(self.dataset[name].isel(time=-1).values)

    def to_netcdf(self, path: str | os.PathLike) -> Path:
        """Write the dataset to netCDF atomically (temporary file, then rename)."""
        return write_netcdf_atomic(self.dataset, path)

    def to_csv(self, path: str | os.PathLike) -> Path:
        """Write all time histories to one CSV file (vector components as extra columns)."""
        import pandas as pd

        cols: dict[str, np.ndarray] = {"time [s]": self.time}
        for name, var in self.dataset.data_vars.items():
            unit = var.attrs.get("units", "")
            vals = np.asarray(var.values)
            if vals.ndim == 1:
                cols[f"{name} [{unit}]"] = vals
            else:
                flat = vals.reshape(vals.shape[0], -1)
                for j in range(flat.shape[1]):
                    cols[f"{name}[{j}] [{unit}]"] = flat[:, j]
        return _write_atomic(Path(path), lambda tmp: pd.DataFrame(cols).to_csv(tmp, index=False))

    def plot(self, names: list[str] | None = None, ax: Any = None) -> Any:
        """Plot time histories of ``names`` (default: the energy terms); returns the axes."""
        import matplotlib.pyplot as plt

        names = names or [n for n in self.dataset.data_vars if str(n).startswith("energy.")]
        if ax is None:
            _, ax = plt.subplots(figsize=(8, 4.5))
        for n in names:
            var = self.dataset[n]
            vals = np.asarray(var.values)
            label = f"{n} [{var.attrs.get('units', '')}]"
            if vals.ndim == 1:
                ax.plot(self.time, vals, label=label)
            else:
                flat = vals.reshape(vals.shape[0], -1)
                for j in range(flat.shape[1]):
                    ax.plot(self.time, flat[:, j], label=f"{label}[{j}]")
        ax.set_xlabel("time [s]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small")
        return ax

    def __repr__(self) -> str:
        state = "ok" if self.success else f"FAILED: {self.message}"
        return (f"Results({len(self.time)} outputs, {self.stats.steps} steps, "
                f"{self.stats.wall_s:.3g} s wall, {state})")


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {k: _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    return obj


def write_netcdf_atomic(dataset: Any, path: str | os.PathLike) -> Path:
    """Write ``dataset`` to ``path`` via a temporary file in the same folder and a rename, so
    that a crash never leaves a half-written file under the final name."""
    return _write_atomic(Path(path), dataset.to_netcdf)


def _write_atomic(path: Path, write: Any) -> Path:
    """``write(tmp)`` into a temporary file beside ``path``, then rename it to ``path`` (an
    atomic replace on POSIX and Windows); the temporary file never survives a failure."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".part", dir=path.parent)
    os.close(fd)
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


def load_results(path: str | os.PathLike) -> Results:
    """Read a results file written by :meth:`Results.to_netcdf`; ``ValueError`` for a
    netCDF file that drivedyn did not write, ``OSError`` for one that cannot be read."""
    import xarray as xr

    ds = xr.load_dataset(path)
    if "time" not in ds.coords or "stats" not in ds.attrs:
        raise ValueError("no 'time' coordinate or no run statistics: not written by drivedyn "
                         "(drivedyn results files come from `drivedyn run` or "
                         "Results.to_netcdf)")
    stats = RunStats(**{k: (np.inf if v is None else v)
                        for k, v in json.loads(ds.attrs.get("stats", "{}")).items()})
    return Results(ds, bool(ds.attrs.get("success", 1)), str(ds.attrs.get("message", "")), stats)
