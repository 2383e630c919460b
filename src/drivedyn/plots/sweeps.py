"""Figures of a sweep Dataset (``drivedyn sweep``, ``drivedyn plot sweep.nc``):

* one varied key: each output against the key (line plots; points that are not ok marked);
* two varied keys: a heat map of each output over the two keys, values written in the cells;
* three or more: each output against the first key, one line per combination of the others;
* Monte Carlo samples: a histogram of each output with its 5/50/95 % quantiles;
* a sensitivity study: a tornado chart of the elasticities of each output.

Only the outputs that describe the model are drawn (role ``output``, not the wall times or
step counts of role ``computation``), up to
:data:`MAX_OUTPUTS`, one panel each. PNG through the Agg canvas (no display needed).
"""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

MAX_OUTPUTS = 15
MAX_LINES = 12


def _outputs(ds: Any) -> list[str]:
    """The outputs drawn: the model's numeric outputs with a value somewhere; for TDR sweeps
    the TDRs, their analytic values and the other outputs before the errors against the
    measurements."""
    names = _numeric_outputs(ds)
    if ds.attrs.get("kind") == "tdr":
        rank = {"tdr.": 0, "analytic.": 1, "error_pct.": 3}
        names.sort(key=lambda n: next((r for p, r in rank.items() if n.startswith(p)), 2))
    return names[:MAX_OUTPUTS]


def _numeric_outputs(ds: Any) -> list[str]:
    return [str(n) for n, v in ds.data_vars.items()
            if v.attrs.get("role") == "output"  # not "computation" (wall times, counts)
            and np.issubdtype(v.dtype, np.number)
            and np.isfinite(v.values).any()]


def _label(ds: Any, name: str) -> str:
    u = ds[name].attrs.get("units", "1") if name in ds.variables else "1"
    return name if u in ("1", "", "SI") else f"{name} [{u}]"


def _panels(n: int, width: float = 4.2, height: float = 3.2) -> tuple[Figure, list[Any]]:
    cols = min(n, 3)
    rows = math.ceil(n / cols)
    fig = Figure(figsize=(width * cols, height * rows + 0.5), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    for ax in axes[n:]:
        ax.set_visible(False)
    return fig, list(axes[:n])


def lines_figure(ds: Any) -> Figure:
    """Each output against the first varied key, one line per combination of the others."""
    dims = json.loads(ds.attrs["dims"])
    x_key, others = dims[0], dims[1:]
    names = _outputs(ds)
    fig, axes = _panels(len(names))
    combos = list(itertools.product(*(range(ds.sizes[d]) for d in others)))[:MAX_LINES]
    x = ds[x_key].values
    for ax, name in zip(axes, names, strict=True):
        for combo in combos:
            sel = dict(zip(others, combo, strict=True))
            y = ds[name].isel(sel).values
            bad = ds["status"].isel(sel).values != "ok"
            label = ", ".join(f"{d}={ds[d].values[i]:g}" if np.issubdtype(ds[d].dtype,
                              np.number) else f"{d}={ds[d].values[i]}"
                              for d, i in sel.items()) or None
            _line, = ax.plot(x, y, "o-", ms=4, lw=1.2, label=label)
            if bad.any():
                ax.plot(x[bad], np.where(np.isfinite(y[bad]), y[bad], np.nanmean(y)), "x",
                        color="red", ms=8, label="not ok" if combo == combos[0] else None)
        ax.set_xlabel(_label(ds, x_key))
        ax.set_ylabel(_label(ds, name))
        ax.grid(alpha=0.3)
    if others or (ds["status"] != "ok").any():
        axes[0].legend(fontsize=7)
    fig.suptitle(f"{ds.attrs.get('model', '')}: sweep over {', '.join(dims)}")
    return fig


def heatmap_figure(ds: Any) -> Figure:
    """A heat map of each output over the two varied keys (first key along x)."""
    kx, ky = json.loads(ds.attrs["dims"])[:2]
    names = _outputs(ds)
    fig, axes = _panels(len(names), 4.6, 3.8)
    xs, ys = ds[kx].values, ds[ky].values
    for ax, name in zip(axes, names, strict=True):
        z = ds[name].transpose(ky, kx).values
        im = ax.imshow(z, origin="lower", aspect="auto", cmap="viridis",
                       extent=None)
        ax.set_xticks(range(len(xs)), [f"{v:.4g}" if not isinstance(v, str) else v
                                       for v in xs], rotation=45, fontsize=7)
        ax.set_yticks(range(len(ys)), [f"{v:.4g}" if not isinstance(v, str) else v
                                       for v in ys], fontsize=7)
        if z.size <= 100:
            for (j, i), v in np.ndenumerate(z):
                ax.text(i, j, "x" if not np.isfinite(v) else f"{v:.3g}", ha="center",
                        va="center", fontsize=7, color="white" if np.isfinite(v) else "red")
        ax.set_xlabel(kx)
        ax.set_ylabel(ky)
        ax.set_title(_label(ds, name), fontsize=9)
        fig.colorbar(im, ax=ax, shrink=0.85)
    fig.suptitle(f"{ds.attrs.get('model', '')}: map over {kx} and {ky}")
    return fig


def histogram_figure(ds: Any) -> Figure:
    """A histogram of each output over the Monte Carlo samples (points ok), with the 5, 50
    and 95 % quantiles."""
    names = _outputs(ds)
    fig, axes = _panels(len(names))
    ok = (ds["status"] == "ok").values
    for ax, name in zip(axes, names, strict=True):
        x = ds[name].values[ok]
        x = x[np.isfinite(x)]
        if x.size:
            ax.hist(x, bins=max(5, min(40, int(math.sqrt(x.size)) + 2)), color="C0",
                    alpha=0.8)
            for q, ls in zip(np.quantile(x, [0.05, 0.5, 0.95]), (":", "-", ":"), strict=True):
                ax.axvline(q, color="k", ls=ls, lw=1)
            ax.set_title(f"mean {x.mean():.4g}, sd {x.std(ddof=1) if x.size > 1 else 0:.3g}",
                         fontsize=9)
        ax.set_xlabel(_label(ds, name))
        ax.set_ylabel("points")
    dist = json.loads(ds.attrs.get("distributions", "{}"))
    fig.suptitle(f"{ds.attrs.get('model', '')}: {int(ok.sum())} samples of "
                 + ", ".join(f"{k} ~ {v}" for k, v in dist.items())
                 + " (quantiles 5, 50, 95 %)", fontsize=10)
    return fig


def tornado_figure(ds: Any) -> Figure:
    """For each output, the elasticity (relative change of the output per relative change of
    the parameter) of every parameter, largest first."""
    names = [n for n in _outputs(ds) if f"elasticity.{n}" in ds]
    fig, axes = _panels(len(names), 4.6, 0.5 + 0.45 * ds.sizes["parameter"])
    params = [str(p) for p in ds["parameter"].values]
    for ax, name in zip(axes, names, strict=True):
        e = ds[f"elasticity.{name}"].values
        order = np.argsort(np.abs(np.nan_to_num(e)))
        ax.barh(range(len(order)), e[order],
                color=["C3" if v < 0 else "C0" for v in e[order]])
        ax.set_yticks(range(len(order)), [params[i] for i in order], fontsize=8)
        ax.axvline(0, color="k", lw=0.8)
        ax.set_title(name, fontsize=9)
        ax.set_xlabel("elasticity (p/y) dy/dp")
    fig.suptitle(f"{ds.attrs.get('model', '')}: sensitivities at the nominal point "
                 f"(central differences, step {float(ds.attrs.get('rel_step', 0)):.2%})",
                 fontsize=10)
    return fig


def plot_sweep(ds: Any, out_dir: str | Path) -> list[Path]:
    """Draw the figures suited to the sweep's design into ``out_dir``; returns the files."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    design = ds.attrs.get("design")
    dims = json.loads(ds.attrs.get("dims", "[]"))
    figs: list[tuple[str, Figure]] = []
    if not _outputs(ds):
        return []
    if design == "sensitivity":
        figs.append(("tornado.png", tornado_figure(ds)))
    else:
        if "sample" in dims:
            figs.append(("histograms.png", histogram_figure(ds)))
        grid_dims = [d for d in dims if d != "sample"]
        if grid_dims and "sample" not in dims:
            numeric = all(np.issubdtype(ds[d].dtype, np.number) for d in grid_dims)
            if len(grid_dims) == 2:
                figs.append(("heatmap.png", heatmap_figure(ds)))
            if numeric or len(grid_dims) != 2:
                figs.append(("lines.png", lines_figure(ds)))
    files = []
    for fname, fig in figs:
        path = out / fname
        fig.savefig(path, dpi=110)
        files.append(path)
    return files
