"""``drivedyn.sweep``: parameter sweeps, Monte Carlo tolerance studies and sensitivities of a
model file, computed point by point on Dask (or serially) with a resumable cache, returned as
one xarray Dataset (see :mod:`drivedyn.sweeps.assemble`)."""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from drivedyn.sweeps.assemble import assemble
from drivedyn.sweeps.cache import PointCache, code_fingerprint, point_key, referenced_files
from drivedyn.sweeps.design import (
    Design,
    Sample,
    SweepInputError,
    Vary,
    format_value,
    grid,
    parse_sample,
    parse_sensitivity,
    parse_vary,
    sensitivity,
)
from drivedyn.sweeps.evaluate import (
    CACHED_STATUSES,
    Task,
    file_sha256,
    kept_files,
    parse_metric,
)
from drivedyn.sweeps.execute import LOOPBACK, run_tasks
from drivedyn.units import split_quantity


class SweepInterrupted(KeyboardInterrupt):
    """The sweep was interrupted (Ctrl-C); ``dataset`` holds the points finished so far
    (the others ``missing``), all of them already in the cache."""

    def __init__(self, dataset: Any) -> None:
        super().__init__("sweep interrupted")
        self.dataset = dataset


def _varies(vary: Any) -> list[Vary]:
    if vary is None:
        return []
    if isinstance(vary, Mapping):
        out = []
        for k, v in vary.items():
            if isinstance(v, Vary):
                out.append(v)
            elif isinstance(v, str):
                out.append(parse_vary(f"{k}={v}"))
            else:
                vals = [x if isinstance(x, str) else float(x) for x in v]
                out.append(parse_vary(f"{k}=" + ",".join(
                    x if isinstance(x, str) else repr(x) for x in vals)))
        return out
    return [v if isinstance(v, Vary) else parse_vary(v) for v in vary]


def _samples(sample: Any) -> list[Sample]:
    if sample is None:
        return []
    if isinstance(sample, Mapping):
        return [v if isinstance(v, Sample) else parse_sample(f"{k}={v}")
                for k, v in sample.items()]
    return [s if isinstance(s, Sample) else parse_sample(s) for s in sample]


def _nominal(model: str, key: str, sets: dict) -> tuple[float, str]:
    """(number, unit) of a key's value in the model file (``"30 deg"`` -> (30, "deg"))."""
    from drivedyn.config.loader import read_value

    v = read_value(model, key, sets)
    if isinstance(v, bool) or not isinstance(v, (int, float, str)):
        raise SweepInputError(f"--sensitivity {key}: its value {v!r} is not a number")
    if isinstance(v, str):
        q = split_quantity(v)
        if q is None:
            raise SweepInputError(f"--sensitivity {key}: its value {v!r} is not a number "
                                  "or a quantity")
        return q
    return float(v), ""


def _check_metrics(path: Path, fixed: dict, metrics: list) -> None:
    """Refuse a metric of a variable the model does not record (before any point runs)."""
    from drivedyn.config import load_model
    from drivedyn.errors import did_you_mean
    from drivedyn.results.recorder import variable_names

    names = variable_names(load_model(path, fixed))
    for m in metrics:
        dims = names.get(m.variable)
        if dims is None:
            raise SweepInputError(f"--metric {m.text}: the model records no variable "
                                  f"{m.variable!r}{did_you_mean(m.variable, names)}")
        if (m.component is None) != (len(dims) == 1):
            raise SweepInputError(f"--metric {m.text}: {m.variable} has dimensions "
                                  f"{dims}: " + ("give a component, e.g. "
                                                 f"{m.variable}[0]" if m.component is None
                                                 else "it has no components"))
        if m.component is not None and len(dims) != 2:
            raise SweepInputError(f"--metric {m.text}: {m.variable} has dimensions {dims}; "
                                  "metrics reduce scalar or vector variables")
        if m.component is not None and m.component > 2:
            raise SweepInputError(f"--metric {m.text}: component {m.component} out of range "
                                  "(0-2)")


def _design(model: str, vary: Any, sample: Any, samples: int, seed: int,
            sensitivity_keys: Any, rel_step: float, fixed: dict) -> Design:
    """The sweep's points, after checking that every key names a value of the model file."""
    from drivedyn.config.loader import check_override_keys

    if sensitivity_keys:
        if vary or sample:
            raise SweepInputError("--sensitivity takes its keys from --vary KEY or "
                                  "KEY=NOMINAL, without ranges or --sample")
        items = sensitivity_keys.items() if isinstance(sensitivity_keys, Mapping) else \
            [parse_sensitivity(k)[:2] for k in sensitivity_keys]
        params = []
        for key, nominal in items:
            check_override_keys(model, {key: nominal if nominal is not None else 1.0},
                                "--vary")
            x, unit = (float(nominal), "") if nominal is not None else \
                _nominal(model, key, fixed)
            params.append((key, x, unit))
        return sensitivity(params, rel_step)
    varies, samp = _varies(vary), _samples(sample)
    design = grid(varies, samp, samples, seed)
    first = {v.key: v.model_value(v.values[0]) for v in varies}
    first.update({s.key: format_value(s.a, s.unit) for s in samp})
    check_override_keys(model, first, "--vary")
    return design


def _sets(sets: Any) -> dict[str, Any]:
    from drivedyn.config.loader import parse_override

    if sets is None:
        return {}
    if isinstance(sets, Mapping):
        return dict(sets)
    return dict(parse_override(s) for s in sets)


def sweep(model: str | Path, vary: Any = None, *, sample: Any = None, samples: int = 0,
          seed: int = 0, sensitivity_keys: Sequence[str] | Mapping[str, float | None] | None
          = None, rel_step: float = 0.01, tdr: bool = False,
          modes: Sequence[int] = (1, 2, 3, 4), torque: float | None = None,
          speed_diff: float | None = None, friction_scale: float = 1.0,
          analytic_only: bool = False, t_end: float | None = None,
          metrics: Sequence[str] = (), sets: Any = None, client: Any = None,
          scheduler: str | None = None, workers: int | None = None, host: str = LOOPBACK,
          timeout: float = 10.0, cache: str | Path | None = None, fresh: bool = False,
          keep_runs: str | Path | None = None,
          progress: Callable[[int, int, dict, bool], None] | None = None,
          on_cluster: Callable[[str], None] | None = None) -> Any:
    """Compute a model file over a grid of values, Monte Carlo samples or a finite-difference
    stencil, each point an independent run, and return one Dataset.

    Args:
        model: model file (path or shipped name, e.g. ``"torsen-c"``).
        vary: varied keys: ``{"pockets.mu": "0.10:0.20:5"}``, ``{"key": [v1, v2]}`` or
            ``["pockets.mu=0.10:0.20:5", "bench.torque=50:250:3 N m"]`` (see
            :mod:`drivedyn.sweeps.design`). One dimension per key, full factorial.
        sample: sampled keys: ``{"pockets.mu": "normal(0.17,0.01)"}`` or
            ``["pockets.mu=uniform(0.15,0.19)"]``; ``samples`` draws with ``seed``
            (dimension ``sample``, crossed with ``vary``).
        sensitivity_keys: keys (or key -> nominal) of a sensitivity study at the nominal
            point: central differences with ``rel_step`` (relative), computed in parallel.
        tdr: compute the TDR of ``modes`` on the bench (differential models) with
            ``torque`` [N m], ``speed_diff`` [rad/s], ``friction_scale``,
            ``analytic_only`` as ``drivedyn tdr``; otherwise simulate the file's scenario to
            ``t_end`` [s] (default the file's) and reduce ``metrics``
            (``"VAR[:REDUCER][@T0:T1]"``).
        sets: fixed overrides of every point (``{"key": value}`` or ``["key=value"]``).
        client: a ``distributed.Client`` to run on; ``scheduler``: ``"serial"``, an address
            or a scheduler file (``timeout`` [s] to answer); default: the caller's Dask
            client if any, else a local cluster of ``workers`` processes whose scheduler,
            workers and dashboard listen on ``host`` (default 127.0.0.1: this machine only).
        cache: folder of cached points (None: no cache); ``fresh`` recomputes them.
        keep_runs: folder where every point's results files are kept
            (``point-0000.nc``, ``point-0000-<side>.nc`` for ``tdr``, in submission order;
            ``points.json`` lists each file's overrides), each recording its library model
            and configuration so ``drivedyn report`` finds the dashboard. A cached point
            whose files are missing is computed again.
        progress: ``progress(done, total, record, from_cache)`` after each point.
        on_cluster: called with a description of the cluster.

    Returns:
        The sweep ``xarray.Dataset`` (attributes ``drivedyn_kind = "sweep"``, ``design``,
        ``status_counts``...).

    Raises:
        SweepInputError, ModelFileError: a malformed description or an unknown key (before
            any point runs).
        SweepInterrupted: on Ctrl-C, carrying the Dataset of the finished points.
    """
    from drivedyn import __version__
    from drivedyn.config.loader import (
        check_override_keys,
        resolve_path,
        shipped_models,
        validate_file,
    )

    path = resolve_path(model)
    model_ref = str(model) if str(model) in shipped_models() and not Path(model).is_file() \
        else str(path.resolve())
    fixed = _sets(sets)
    # the model as given must be valid: its errors are the command's, not every point's
    _, library = validate_file(str(model), fixed)
    if tdr:
        from drivedyn.library import differentials

        if library not in differentials.TYPES:
            raise SweepInputError(f"--tdr: {model} is not a differential model file "
                                  f"(differentials: {', '.join(differentials.TYPES)})")
        bad = [m for m in modes if m not in (1, 2, 3, 4)]
        if bad or not modes:
            raise SweepInputError(f"--mode {bad or list(modes)}: expected modes 1-4")
    if metrics:
        _check_metrics(path, fixed, [parse_metric(m) for m in metrics])
    design = _design(str(model), vary, sample, samples, seed, sensitivity_keys, rel_step,
                     fixed)
    if fixed:
        check_override_keys(str(model), fixed, "--set")

    kind = "tdr" if tdr else "run"
    options: dict[str, Any] = (
        {"modes": [int(m) for m in modes], "torque": torque, "speed_diff": speed_diff,
         "friction_scale": float(friction_scale), "analytic_only": bool(analytic_only)}
        if tdr else {"t_end": t_end, "metrics": list(metrics)})
    model_sha = file_sha256(path)
    refs = referenced_files(path, fixed)
    runs_dir = None if keep_runs is None else Path(keep_runs).resolve()
    tasks = []
    for i, p in enumerate(design.points):
        ov = {**fixed, **p.overrides}
        tasks.append(Task(model_ref, model_sha, kind, ov, options,
                          point_key(model_sha, refs, kind, options, ov),
                          str(runs_dir / f"point-{i:04d}") if runs_dir else ""))
    if runs_dir is not None:
        import json

        runs_dir.mkdir(parents=True, exist_ok=True)
        (runs_dir / "points.json").write_text(json.dumps(
            [{"file": Path(t.run_file).name, "overrides": t.overrides} for t in tasks],
            indent=1, default=str), encoding="utf-8")
    store = PointCache(cache)
    n = len(tasks)
    records: list[dict | None] = [None] * n
    cached = [False] * n
    done = 0
    todo = []
    for i, t in enumerate(tasks):
        rec = None if fresh else store.get(t.key)
        if rec is not None and t.run_file and not kept_files(t):
            rec = None  # its results files are wanted and missing
        if rec is not None and rec.get("status") in CACHED_STATUSES:
            records[i], cached[i] = rec, True
            done += 1
            if progress:
                progress(done, n, rec, True)
        else:
            todo.append(i)
    attrs = {"model": str(model), "model_path": str(path.resolve()), "model_sha256": model_sha,
             "kind": kind, "options": options, "sets": fixed,
             "drivedyn_version": __version__, "code_sha256": code_fingerprint(),
             "cache": str(cache) if cache is not None else None,
             "runs_dir": str(runs_dir) if runs_dir is not None else None,
             "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}
    t0 = time.perf_counter()
    try:
        for j, rec in run_tasks([tasks[i] for i in todo], client=client,
                                scheduler=scheduler, workers=workers, host=host,
                                timeout=timeout,
                                on_cluster=on_cluster):
            i = todo[j]
            records[i] = rec
            if rec["status"] in CACHED_STATUSES:
                store.put(tasks[i].key, rec, tasks[i].overrides, model_ref)
            done += 1
            if progress:
                progress(done, n, rec, False)
    except KeyboardInterrupt:
        attrs["wall_s"] = time.perf_counter() - t0
        attrs["interrupted"] = 1
        raise SweepInterrupted(assemble(design, records, cached, attrs)) from None
    attrs["wall_s"] = time.perf_counter() - t0
    attrs["computed"] = len(todo)
    return assemble(design, records, cached, attrs)
