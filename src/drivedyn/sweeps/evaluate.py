"""What one point of a sweep computes, on whichever worker runs it.

:func:`evaluate_point` is the function Dask ships to the workers: it takes a :class:`Task`
(model file, overrides, what to compute) and returns a plain record (status, message, scalar
outputs), never raises for a problem of the point itself: an invalid value, an impossible
model or a solver failure is a result. The same code paths as ``drivedyn run`` and
``drivedyn tdr`` compute the outputs, so a sweep point equals the separate command bit for bit.

Kinds:

- ``run``: simulate the model file's scenario (``drivedyn run``); outputs :func:`~drivedyn.
  analysis.tdr.run_metrics` plus the requested :class:`Metric` reductions.
- ``tdr``: the TDR of each requested locking mode on the simulated bench (``drivedyn tdr``),
  with the analytic and measured values, dissipated energy and peak contact pressure.
"""

from __future__ import annotations

import hashlib
import math
import os
import re
import socket
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from drivedyn.sweeps.design import SweepInputError

REDUCERS = ("final", "mean", "max", "min", "absmax", "ptp", "rms")

# status of a point: computed (cached), or not (recomputed by the next run)
CACHED_STATUSES = ("ok", "failed", "invalid")


@dataclass(frozen=True)
class Metric:
    """A scalar reduction of a time history: ``VAR[INDEX][:REDUCER][@T0:T1]``.

    Attributes:
        text: the specification (also the output's name).
        variable: results variable (``rod.angle``, ``applied_torque.torque_z``).
        component: index of a vector variable's component, or None.
        reducer: one of :data:`REDUCERS` (default ``final``).
        window: (t0, t1) [s] to reduce over, or None for the whole run.
    """

    text: str
    variable: str
    component: int | None
    reducer: str
    window: tuple[float, float] | None

    def reduce(self, ds: Any) -> tuple[float, str]:
        """(value, units) of this metric on a results Dataset; NaN when the variable is
        missing or the window holds no sample."""
        if self.variable not in ds:
            return math.nan, ""
        var = ds[self.variable]
        units = str(var.attrs.get("units", ""))
        x = np.asarray(var.values, dtype=float)
        if self.component is not None:
            if x.ndim != 2 or not 0 <= self.component < x.shape[1]:
                return math.nan, units
            x = x[:, self.component]
        elif x.ndim != 1:
            return math.nan, units
        if self.window is not None:
            t = np.asarray(ds["time"].values)
            x = x[(t >= self.window[0] - 1e-12) & (t <= self.window[1] + 1e-12)]
        if x.size == 0:
            return math.nan, units
        r = self.reducer
        value = (x[-1] if r == "final" else x.mean() if r == "mean" else x.max() if r == "max"
                 else x.min() if r == "min" else np.abs(x).max() if r == "absmax"
                 else np.ptp(x) if r == "ptp" else math.sqrt(float(np.mean(x * x))))
        return float(value), units


_METRIC = re.compile(r"^([A-Za-z_][\w\-.]*?)(?:\[(\d+)\])?(?::(\w+))?(?:@([^:]+):([^:]+))?$")


def parse_metric(text: str) -> Metric:
    """``VAR[INDEX][:REDUCER][@T0:T1]`` -> :class:`Metric` (``rod.angle:max@1:2``)."""
    m = _METRIC.match(text.strip())
    if m is None:
        raise SweepInputError(f"--metric {text!r}: expected VAR[:REDUCER][@T0:T1], e.g. "
                              "rod.angle:max or applied_torque.torque_z:mean@1.5:2")
    var, comp, red, t0, t1 = m.groups()
    red = red or "final"
    if red not in REDUCERS:
        raise SweepInputError(f"--metric {text!r}: unknown reducer {red!r} (expected one of "
                              f"{', '.join(REDUCERS)})")
    window = None
    if t0 is not None:
        try:
            window = (float(t0), float(t1))
        except ValueError:
            raise SweepInputError(f"--metric {text!r}: the window @T0:T1 needs two numbers "
                                  "[s]") from None
        if not (math.isfinite(window[0]) and math.isfinite(window[1])
                and window[0] < window[1]):
            raise SweepInputError(f"--metric {text!r}: expected T0 < T1 [s]")
    return Metric(text.strip(), var, None if comp is None else int(comp), red, window)


@dataclass(frozen=True)
class Task:
    """One point to compute (picklable, shipped to a worker).

    Attributes:
        model: model file (absolute path, or a shipped model's name).
        model_sha256: hash of the model file's bytes read by the client; a worker that reads
            other bytes (no shared filesystem, an edited file) refuses the point.
        kind: ``"run"`` or ``"tdr"``.
        overrides: dotted key -> value (the sweep's ``--set`` values and the point's).
        options: ``run``: ``t_end`` [s] or None, ``metrics`` (specification texts);
            ``tdr``: ``modes``, ``torque`` [N m] or None, ``speed_diff`` [rad/s] or None,
            ``friction_scale``, ``analytic_only``.
        key: the point's cache key.
        run_file: path without suffix where the point's results are kept (``run``:
            ``<run_file>.nc``; ``tdr``: ``<run_file>-<side>.nc`` per bench run), with the
            run's provenance (:mod:`drivedyn.results.provenance`); empty: not kept.
    """

    model: str
    model_sha256: str
    kind: str
    overrides: dict = field(hash=False)
    options: dict = field(hash=False)
    key: str = ""
    run_file: str = ""


def kept_files(task: Task) -> list[Path]:
    """The results files a point with ``task.run_file`` has written (empty if none)."""
    if not task.run_file:
        return []
    stem = Path(task.run_file)
    return sorted(stem.parent.glob(stem.name + ".nc")) + sorted(
        stem.parent.glob(stem.name + "-*.nc"))


def file_sha256(path: str | Path) -> str:
    """SHA-256 of a file's bytes."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def evaluate_point(task: Task) -> dict:
    """Compute one point; never raises for the point's own problems.

    Returns:
        ``{"status", "message", "outputs", "units", "wall_s", "host"}``; status is ``ok``,
        ``failed`` (the solver stopped: outputs of the run so far), ``invalid`` (the point's
        model file or model is refused: the message says why) or ``error`` (an unexpected
        exception, its type and message; not cached, retried by the next run).
    """
    t0 = time.perf_counter()
    rec: dict[str, Any] = {"status": "ok", "message": "", "outputs": {}, "units": {},
                           "host": f"{socket.gethostname()}:{os.getpid()}"}
    try:
        from drivedyn.config.loader import resolve_path

        if file_sha256(resolve_path(task.model)) != task.model_sha256:
            rec.update(status="error", message=f"{task.model}: the worker reads a different "
                       "file than the client (edited during the sweep, or not on a shared "
                       "filesystem)")
        elif task.kind == "tdr":
            _tdr(task, rec)
        else:
            _run(task, rec)
    except Exception as exc:
        from drivedyn.config import ModelFileError, UnitError
        from drivedyn.errors import ModelError

        if isinstance(exc, (ModelFileError, ModelError, UnitError)):
            rec.update(status="invalid", message=str(exc))
        else:
            tb = traceback.extract_tb(exc.__traceback__)
            where = f" at {Path(tb[-1].filename).name}:{tb[-1].lineno}" if tb else ""
            rec.update(status="error", message=f"{type(exc).__name__}: {exc}{where}")
    rec["wall_s"] = time.perf_counter() - t0
    rec["outputs"]["wall_s"] = rec["wall_s"]
    rec["units"]["wall_s"] = "s"
    return rec


_RUN_UNITS = {"t_final": "s", "dissipated_energy": "J", "energy_balance_error": "J",
              "peak_pressure": "Pa", "peak_pressure_at": "", "steps": "1",
              "rejected_steps": "1", "newton_iterations": "1", "factorizations": "1",
              "wall_s": "s"}


def _run(task: Task, rec: dict) -> None:
    from drivedyn.config import load_model
    from drivedyn.results.metrics import run_metrics
    from drivedyn.solver.simulate import InitializationError, simulate

    model = load_model(task.model, dict(task.overrides))
    try:
        res = simulate(model, task.options.get("t_end"))
    except InitializationError as exc:
        rec.update(status="invalid", message=str(exc))
        return
    if task.run_file:
        from drivedyn.results.provenance import record_provenance
        from drivedyn.results.results import write_netcdf_atomic

        record_provenance(res, model_file=model.meta["model_file"],
                          source=model.meta["source"], overrides=task.overrides,
                          library_model=model.meta.get("library_model"),
                          configuration=model.meta.get("configuration"))
        write_netcdf_atomic(res.dataset, task.run_file + ".nc")
    m = run_metrics(res)
    m["simulation_wall_s"] = m.pop("wall_s")
    rec["outputs"].update(m)
    rec["units"].update(_RUN_UNITS, simulation_wall_s="s")
    for text in task.options.get("metrics", ()):
        value, units = parse_metric(text).reduce(res.dataset)
        rec["outputs"][text] = value
        rec["units"][text] = units
    if not res.success:
        rec.update(status="failed", message=str(res.message))


def _tdr(task: Task, rec: dict) -> None:
    from drivedyn.analysis.tdr import evaluate
    from drivedyn.config import read_library_file
    from drivedyn.library import differentials

    p, _, source = read_library_file(task.model, dict(task.overrides))
    if p.model.library not in differentials.TYPES:
        rec.update(status="invalid", message=f"{source}: not a differential model file")
        return
    differentials.of(p).check(p)
    o = task.options

    def keep(*args: Any) -> None:
        if len(args) == 1 and task.run_file:
            from drivedyn.results.results import write_netcdf_atomic

            write_netcdf_atomic(args[0].results.dataset, f"{task.run_file}-{args[0].side}.nc")

    ev = evaluate(p, list(o["modes"]), o.get("torque"), o.get("speed_diff"),
                  o.get("friction_scale", 1.0), o.get("analytic_only", False), on_run=keep,
                  source=source, overrides=task.overrides)
    out, units = rec["outputs"], rec["units"]
    for row in ev.rows:
        m = row["mode"]
        out[f"tdr.mode{m}"] = row["tdr"]
        units[f"tdr.mode{m}"] = "1"
        if not o.get("analytic_only", False):
            out[f"analytic.mode{m}"] = row["analytic"]
            units[f"analytic.mode{m}"] = "1"
        if row["experimental"]:
            out[f"error_pct.mode{m}"] = row["error_pct"] if row["error_pct"] is not None \
                else math.nan
            units[f"error_pct.mode{m}"] = "%"
    for k, v in ev.metrics.items():
        out[k] = v
        units[k] = _RUN_UNITS.get(k, "")
    out["simulation_wall_s"] = float(sum(r["wall_s"] for r in ev.runs))
    units["simulation_wall_s"] = "s"
    if ev.failed:
        rec.update(status="failed", message=ev.failed)
