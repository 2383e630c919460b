"""Tables summarising a sweep Dataset (printed by ``drivedyn sweep``, also as JSON):
one row per point for small grids, statistics per output for large ones, quantiles for Monte
Carlo studies, derivatives and elasticities for sensitivity studies."""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from drivedyn.sweeps.assemble import physical_outputs

MAX_POINT_ROWS = 30
MAX_COLUMNS = 8


def _g(x: Any) -> str:
    if isinstance(x, str):
        return x
    x = float(x)
    return "nan" if not math.isfinite(x) else f"{x:.5g}"


def _outputs(ds: Any) -> list[str]:
    """The columns of the per-point table: the TDRs first for TDR sweeps (their analytic and
    measured comparisons stay in the file), then the other outputs."""
    names = physical_outputs(ds)
    if ds.attrs.get("kind") == "tdr":
        names = [n for n in names if not n.startswith(("analytic.", "error_pct."))]
    return names[:MAX_COLUMNS]


def tables(ds: Any) -> list[tuple[str, list[str], list[list[str]]]]:
    """(title, column names, rows of strings) of the tables that summarise ``ds``."""
    design = ds.attrs.get("design")
    counts = json.loads(ds.attrs.get("status_counts", "{}"))
    status_line = ", ".join(f"{v} {k}" for k, v in counts.items() if v)
    out = []
    if design == "sensitivity":
        cols = ["output", "parameter", "nominal output", "d output / d parameter",
                "elasticity"]
        rows = []
        for name in [n for n in physical_outputs(ds) if f"sensitivity.{n}" in ds]:
            for i, p in enumerate(ds["parameter"].values):
                rows.append([name, str(p), _g(ds[name].values[i, 1]),
                             _g(ds[f"sensitivity.{name}"].values[i]),
                             _g(ds[f"elasticity.{name}"].values[i])])
        out.append((f"sensitivities at the nominal point ({status_line})", cols, rows))
        return out
    dims = json.loads(ds.attrs.get("dims", "[]"))
    if "sample" in dims:
        cols = ["output", "units", "n", "mean", "std", "5 %", "50 %", "95 %", "min", "max"]
        rows = []
        ok = (ds["status"] == "ok").values
        for name in physical_outputs(ds):
            x = ds[name].values[ok]
            x = x[np.isfinite(x)]
            if x.size == 0:
                rows.append([name, ds[name].attrs.get("units", ""), "0"] + ["-"] * 7)
                continue
            q = np.quantile(x, [0.05, 0.5, 0.95])
            rows.append([name, ds[name].attrs.get("units", ""), str(x.size), _g(x.mean()),
                         _g(x.std(ddof=1) if x.size > 1 else math.nan), *map(_g, q),
                         _g(x.min()), _g(x.max())])
        out.append((f"Monte Carlo over {ds.sizes['sample']} samples ({status_line}); "
                    "statistics over every point", cols, rows))
        return out
    names = _outputs(ds)
    n = int(np.prod([ds.sizes[d] for d in dims])) if dims else 0
    if n <= MAX_POINT_ROWS:
        cols = [*list(dims), "status", *names, "wall [s]"]
        rows = []
        for idx in np.ndindex(*[ds.sizes[d] for d in dims]):
            sel = dict(zip(dims, idx, strict=True))
            row = [_g(ds[d].values[i]) for d, i in sel.items()]
            st = str(ds["status"].isel(sel).values)
            row.append(st)
            row += [_g(ds[nm].isel(sel).values.item()) for nm in names]
            row.append(_g(ds["wall_s"].isel(sel).values.item()) if "wall_s" in ds else "-")
            rows.append(row)
        out.append((f"{n} points ({status_line})", cols, rows))
        return out
    cols = ["output", "units", "n ok", "min", "mean", "max"]
    ok = (ds["status"] == "ok").values
    rows = []
    for name in physical_outputs(ds):
        x = ds[name].values[ok]
        x = x[np.isfinite(x)]
        rows.append([name, ds[name].attrs.get("units", ""), str(x.size)]
                    + ([_g(x.min()), _g(x.mean()), _g(x.max())] if x.size else ["-"] * 3))
    out.append((f"{n} points ({status_line})", cols, rows))
    return out


def problems(ds: Any, limit: int = 10) -> list[str]:
    """One line per point that is not ok: its coordinates, status and message."""
    lines = []
    dims = json.loads(ds.attrs.get("dims", "[]"))
    status = ds["status"].values
    for idx in zip(*np.nonzero(status != "ok"), strict=False):
        sel = dict(zip(dims, idx, strict=True))
        where = ", ".join(f"{d}={_g(ds[d].values[i])}" for d, i in sel.items())
        lines.append(f"{where}: {status[idx]}: {ds['message'].values[idx]}")
    if len(lines) > limit:
        lines = [*lines[:limit], f"... and {len(lines) - limit} more"]
    return lines
