"""The results of a sweep as one xarray Dataset: one dimension per varied key (``sample`` for
Monte Carlo draws; ``parameter`` x ``offset`` for a sensitivity study), every scalar output
of the points as a variable over those dimensions (NaN where a point has no value), each
point's ``status``, ``message``, ``host`` and whether it came from the cache; Monte Carlo
statistics (mean, standard deviation, quantiles over ``sample``) and sensitivities
(central differences at the nominal point, and elasticities) are derived here.
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from drivedyn.sweeps.design import Design

# outputs describing the computation rather than the mechanism (no sensitivities or
# statistics of these)
BOOKKEEPING = ("wall_s", "simulation_wall_s", "steps", "rejected_steps", "newton_iterations",
               "factorizations", "t_final", "energy_balance_error")
QUANTILES = (0.05, 0.25, 0.5, 0.75, 0.95)


def physical_outputs(ds: Any) -> list[str]:
    """The numeric outputs of a sweep Dataset that describe the model (not the computation,
    not derived statistics, not NaN at every point), in order."""
    return [str(n) for n, v in ds.data_vars.items()
            if v.attrs.get("role") == "output"
            and np.issubdtype(v.dtype, np.number) and np.isfinite(v.values).any()]


def _slots(design: Design, index: tuple[int, ...]) -> list[tuple[int, ...]]:
    """Array positions a point fills (the nominal point of a sensitivity study fills offset 0
    of every parameter row)."""
    if design.kind == "sensitivity" and index[0] == -1:
        return [(i, 1) for i in range(design.shape[0])]
    return [index]


def assemble(design: Design, records: list[dict | None], cached: list[bool],
             attrs: dict) -> Any:
    """Build the sweep Dataset from the point records (None: not computed, ``missing``)."""
    import xarray as xr

    shape = design.shape
    names: list[str] = []
    units: dict[str, str] = {}
    strings: set[str] = set()
    for rec in records:
        if rec is None:
            continue
        for k, v in rec.get("outputs", {}).items():
            if k not in units:
                names.append(k)
                units[k] = rec.get("units", {}).get(k, "")
            if isinstance(v, str):
                strings.add(k)
    data: dict[str, np.ndarray] = {
        k: np.full(shape, "", dtype=object) if k in strings else np.full(shape, np.nan)
        for k in names}
    status = np.full(shape, "missing", dtype=object)
    message = np.full(shape, "", dtype=object)
    host = np.full(shape, "", dtype=object)
    from_cache = np.zeros(shape, dtype=bool)
    for p, rec, c in zip(design.points, records, cached, strict=True):
        if rec is None:
            continue
        for slot in _slots(design, p.index):
            status[slot] = rec["status"]
            message[slot] = rec.get("message", "")
            host[slot] = rec.get("host", "")
            from_cache[slot] = c
            for k, v in rec.get("outputs", {}).items():
                if k in strings:
                    data[k][slot] = "" if v is None else str(v)
                else:
                    data[k][slot] = math.nan if v is None else float(v)
    dims = design.dims
    coords = {name: (d, np.asarray(v), a) for name, (d, v, a) in design.coords.items()}
    variables: dict[str, Any] = {}
    for k in names:
        arr = data[k].astype(str) if k in strings else data[k]
        # role: "output" describes the model, "computation" the run (plots and statistics
        # take the outputs only)
        variables[k] = (dims, arr, {"units": units[k] or "1",
                                    "role": "computation" if k in BOOKKEEPING else "output"})
    variables["status"] = (dims, status.astype(str), {
        "description": "ok; failed (the solver stopped; outputs of the run so far); invalid "
        "(the point's model is refused, see message); error (unexpected, retried on rerun); "
        "lost (its worker died, retried on rerun); missing (not computed)"})
    variables["message"] = (dims, message.astype(str), {})
    variables["host"] = (dims, host.astype(str), {"description": "worker host:pid"})
    variables["cached"] = (dims, from_cache, {"description": "taken from the point cache"})
    ds = xr.Dataset(variables, coords=coords)
    counts = {s: int((status == s).sum()) for s in
              ("ok", "failed", "invalid", "error", "lost", "missing")}
    ds.attrs.update({k: json.dumps(v) if isinstance(v, (dict, list, tuple)) else v
                     for k, v in attrs.items() if v is not None})
    ds.attrs.update({"drivedyn_kind": "sweep", "design": design.kind,
                     "dims": json.dumps(list(dims)),
                     "points": len(design.points), "status_counts": json.dumps(counts)})
    ds.attrs.update({k: json.dumps(v) if isinstance(v, dict) else v
                     for k, v in design.attrs.items() if v is not None})
    if design.kind == "sensitivity":
        _add_sensitivities(ds)
    elif "sample" in dims:
        _add_statistics(ds)
    return ds


def _add_sensitivities(ds: Any) -> None:
    """``sensitivity.O`` = (O(+) - O(-)) / (2 step) per parameter [units of O per unit of the
    parameter, SI unless the key was given with a unit] and ``elasticity.O`` = sensitivity
    * nominal / O(nominal) (relative change of O per relative change of the parameter)."""
    step = ds["step"].values
    nominal = ds["nominal"].values
    # not of the errors against measurements: the relative change of a percentage that is
    # near zero says nothing (their derivative is 100/measured times the TDR's)
    for name in [n for n in physical_outputs(ds) if not n.startswith("error_pct.")]:
        o = ds[name].values
        d = (o[:, 2] - o[:, 0]) / (2 * step)
        ds[f"sensitivity.{name}"] = (("parameter",), d, {
            "units": f"{ds[name].attrs.get('units', '1')} per parameter unit",
            "role": "sensitivity", "output": name,
            "description": f"d({name})/d(parameter) by central difference"})
        with np.errstate(divide="ignore", invalid="ignore"):
            e = d * nominal / o[:, 1]
        ds[f"elasticity.{name}"] = (("parameter",), e, {
            "units": "1", "role": "elasticity", "output": name,
            "description": f"(p/{name}) d({name})/dp: relative change of the output per "
                           "relative change of the parameter"})


def _add_statistics(ds: Any) -> None:
    """``mean.O``, ``std.O`` (sample standard deviation) and ``quantiles.O`` over the
    ``sample`` dimension of the points with status ok."""
    ok = ds["status"] == "ok"
    ds.coords["quantile"] = ("quantile", np.asarray(QUANTILES))
    for name in physical_outputs(ds):
        x = ds[name].where(ok)
        u = ds[name].attrs.get("units", "1")
        ds[f"mean.{name}"] = x.mean("sample", skipna=True).assign_attrs(
            units=u, role="statistic", output=name)
        ds[f"std.{name}"] = x.std("sample", skipna=True, ddof=1).assign_attrs(
            units=u, role="statistic", output=name)
        q = x.quantile(list(QUANTILES), dim="sample", skipna=True)
        ds[f"quantiles.{name}"] = q.assign_attrs(units=u, role="statistic", output=name)
