"""Draw the dashboard a library model declares (:mod:`drivedyn.library.dashboards`) for one
of its runs.

The run's ``model_file`` attribute names the library model (``[model] library``); its
parameters are validated again with that model's schema and the model's registry gives the
dashboard: :func:`drivedyn.library.differentials.dashboard_of` for a differential,
:func:`drivedyn.library.vehicles.dashboard_of` for a vehicle. Each page becomes one figure of
panels; a curve whose variables the run lacks is left out, a panel without curves too.
Windows (TDR windows) are shaded where the run covers them, with each curve's window mean
written above (for ratio curves the ratio of the window means, as the TDR is measured) and the
window's reference value (a measured TDR) dashed. A panel with an abscissa (a vehicle's path)
draws its curves against it, the start dotted.
"""

from __future__ import annotations

import fnmatch
import json
import warnings
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.transforms import blended_transform_factory

from drivedyn.library.dashboards import Curve, Dashboard, Panel, Term, Window
from drivedyn.plots.panels import finish_panel, panel_grid, time_axis
from drivedyn.plots.units import display_scale, peak

#: a ratio is not drawn where its denominator (larger_over_smaller: the larger magnitude)
#: is below this fraction of its largest magnitude: nothing is transmitted there
RATIO_FLOOR = 0.05


def declared_dashboard(ds: Any) -> Dashboard | None:
    """The dashboard of the library model a run comes from, None for a plain mechanism file
    or a library model that declares none. ``ValueError`` when the recorded model file does
    not validate any more."""
    try:
        data = json.loads(ds.attrs.get("model_file", "") or "{}")
    except ValueError:
        return None
    model = data.get("model") if isinstance(data, dict) else None
    lib = model.get("library") if isinstance(model, dict) else None
    if not lib:
        return None
    from drivedyn.library import differentials, vehicles

    if lib in differentials.TYPES:
        params = differentials.get(lib).schema.model_validate(data)
        return differentials.dashboard_of(params)
    if lib in vehicles.TYPES:
        params = vehicles.get(lib).SCHEMA.model_validate(data)
        return vehicles.dashboard_of(params)
    return None


def _term(ds: Any, names: list[str], term: Term) -> np.ndarray | None:
    total = None
    for n in names:
        if not fnmatch.fnmatchcase(n, term.pattern):
            continue
        v = np.asarray(ds.variables[n].values, dtype=float)
        if term.component is not None:
            if v.ndim != 2:
                continue
            v = v[:, term.component]
        elif v.ndim != 1:
            continue
        v = term.coefficient * v
        if total is None:
            total = v
        else:
            total = np.fmax(total, v) if term.reduce == "max" else total + v
    return total


def _sum(ds: Any, names: list[str], terms: tuple[Term, ...]) -> np.ndarray | None:
    parts = [v for v in (_term(ds, names, tm) for tm in terms) if v is not None]
    return sum(parts[1:], parts[0]) if parts else None


def _quotient(num: np.ndarray, den: np.ndarray, ratio: str) -> np.ndarray:
    """``num / den`` as ``ratio`` says, NaN where nothing is transmitted (RATIO_FLOOR)."""
    a, b = np.abs(num), np.abs(den)
    with np.errstate(divide="ignore", invalid="ignore"):
        if ratio == "larger_over_smaller":
            big = np.maximum(a, b)
            q = big / np.minimum(a, b)
            ok = big >= RATIO_FLOOR * peak(big)
        else:
            q = num / den
            q = np.abs(q) if ratio == "magnitude" else q
            ok = b >= RATIO_FLOOR * peak(b)
    return np.where(ok, q, np.nan)


def curve_values(ds: Any, curve: Curve, names: list[str] | None = None
                 ) -> tuple[np.ndarray, np.ndarray | None] | None:
    """(values, denominator or None) of a curve [SI], None if the run lacks its variables.
    With a denominator, ``values`` is the quotient (``curve.ratio``)."""
    names = [str(n) for n in ds.data_vars] if names is None else names
    num = _sum(ds, names, curve.terms)
    if num is None:
        return None
    if curve.relative:
        num = num - num[0]
    if not curve.over:
        return num, None
    den = _sum(ds, names, curve.over)
    if den is None:
        return None
    return _quotient(num, den, curve.ratio), den


def window_mean(t: np.ndarray, ds: Any, curve: Curve, names: list[str], window: Window
                ) -> float | None:
    """Mean of a curve over a window [SI]; for a ratio the ratio of the window means (as
    the TDR of a mode is measured); None if the run does not cover the window."""
    k = (t >= window.t0 - 1e-12) & (t <= window.t1 + 1e-12)
    if k.sum() < 2 or t[-1] < window.t1 - 1e-9:
        return None
    num = _sum(ds, names, curve.terms)
    if num is None:
        return None
    if not curve.over:
        return float(np.mean((num - num[0] if curve.relative else num)[k]))
    den = _sum(ds, names, curve.over)
    if den is None:
        return None
    return float(_quotient(np.array([num[k].mean()]), np.array([den[k].mean()]),
                           curve.ratio)[0])


def _windows(ax: Any, t: np.ndarray, ds: Any, names: list[str], panel: Panel,
             drawn: list[tuple[Curve, Any]], t_scale: float, scale: float) -> int:
    """Shade the windows the run covers, write the window means; returns how many."""
    covered = [w for w in panel.windows if t[-1] >= w.t1 - 1e-9]
    many = len(covered) > 4
    trans = blended_transform_factory(ax.transData, ax.transAxes)
    for w in covered:
        a, b = w.t0 * t_scale, w.t1 * t_scale
        ax.axvspan(a, b, color="0.88", zorder=0)
        texts = [w.label] if w.label else []
        for curve, line in drawn:
            m = window_mean(t, ds, curve, names, w)
            if m is not None and np.isfinite(m):
                ax.hlines(m * scale, a, b, color=line.get_color(), lw=2.2)
                texts.append(f"{m * scale:#.3g}")
        if w.reference is not None:
            ax.hlines(w.reference * scale, a, b, color="k", ls="--", lw=1.2)
            texts.append(f"meas. {w.reference * scale:#.3g}")
        ax.text((a + b) / 2, 0.98, "\n".join(texts) if not many else ": ".join(texts),
                transform=trans, ha="center", va="top", fontsize=6,
                rotation=90 if many else 0)
    return len(covered)


def _clip_ratio(ax: Any, values: list[np.ndarray], scale: float) -> str:
    """Keep a ratio panel readable: the y axis stops at 3 times the median magnitude when
    transients (a ratio of two small torques at the start) reach beyond; returns a note."""
    v = np.abs(np.concatenate(values)) * abs(scale)
    v = v[np.isfinite(v)]
    if v.size < 3:
        return ""
    top = 3.0 * float(np.median(v))
    if not v.max() > top > 0:
        return ""
    lo = min(0.0, float(np.nanmin(np.concatenate(values)) * scale))
    ax.set_ylim(lo, top)
    return f"y axis clipped at {top:.3g} (transients reach {v.max():.3g})"


def _against(ax: Any, ds: Any, names: list[str], panel: Panel,
             values: list[tuple[Curve, np.ndarray]]) -> bool:
    """Draw a panel whose curves go against its abscissa (a path), the start dotted."""
    assert panel.abscissa is not None
    xs = curve_values(ds, panel.abscissa.curve, names)
    if xs is None:
        return False
    x = xs[0]
    x_scale, x_shown = display_scale(x, panel.abscissa.unit, None)
    scale, shown = display_scale(np.concatenate([v for _, v in values]), panel.unit,
                                 panel.display)
    for c, v in values:
        fmt = (c.style,) if c.style else ()
        (line,) = ax.plot(x_scale * x, scale * v, *fmt, lw=1.1, label=c.label)
        ax.plot(x_scale * x[0], scale * v[0], "o", ms=4, color=line.get_color())
    finish_panel(ax, panel.title, f"{panel.quantity} [{shown}]", "", panel.note)
    ax.set_xlabel(f"{panel.abscissa.quantity}: {panel.abscissa.curve.label} [{x_shown}] "
                  "(dot: start)")
    return True


def _panel(ax: Any, ds: Any, names: list[str], panel: Panel, t_raw: np.ndarray,
           t_scale: float, t_unit: str) -> bool:
    """Draw one panel; False (nothing drawn) when the run has none of its curves."""
    values = [(c, curve_values(ds, c, names)) for c in panel.curves]
    values = [(c, v[0]) for c, v in values if v is not None]
    if not values:
        return False
    if panel.abscissa is not None:
        return _against(ax, ds, names, panel, values)
    scale, shown = display_scale(np.concatenate([v for _, v in values]), panel.unit,
                                 panel.display)
    drawn = []
    for c, v in values:
        fmt = (c.style,) if c.style else ()
        (line,) = ax.plot(t_raw * t_scale, scale * v, *fmt, lw=1.1, label=c.label)
        drawn.append((c, line))
    note = panel.note
    if panel.windows and _windows(ax, t_raw, ds, names, panel, drawn, t_scale, scale) == 0:
        first = min(w.t1 for w in panel.windows)
        note = (f"the run (to {t_raw[-1]:.3g} s) ends before the first window closes "
                f"(t = {first:.3g} s): no window mean")
    notes = [note]
    if any(c.over for c, _ in values):
        notes.append(_clip_ratio(ax, [v for c, v in values if c.over], scale))
    finish_panel(ax, panel.title, f"{panel.quantity} [{shown}]", t_unit,
                 "; ".join(n for n in notes if n))
    return True


def dashboard_figures(ds: Any) -> list[tuple[str, Figure]]:
    """The dashboard pages of the run's library model as ``(title, figure)`` (title:
    ``"<dashboard name>: <page title>"``); an empty list for results of a plain mechanism
    file (or of a model file that no longer validates: a warning says so)."""
    try:
        dash = declared_dashboard(ds)
    except ValueError as exc:
        warnings.warn(f"no dashboard: the recorded model file does not validate ({exc})",
                      stacklevel=2)
        return []
    t_raw = np.asarray(ds["time"].values, dtype=float)
    if dash is None or t_raw.size < 2:  # nothing to draw over time
        return []
    names = [str(n) for n in ds.data_vars]
    t_scale, t_unit = time_axis(t_raw)
    out = []
    for page in dash.pages:
        usable = [p for p in page.panels
                  if any(curve_values(ds, c, names) is not None for c in p.curves)
                  and (p.abscissa is None
                       or curve_values(ds, p.abscissa.curve, names) is not None)]
        if not usable:
            continue
        fig, axes = panel_grid(f"{dash.title}: {page.title}", len(usable))
        for ax, panel in zip(axes, usable, strict=True):
            _panel(ax, ds, names, panel, t_raw, t_scale, t_unit)
        out.append((f"{dash.name}: {page.title}", fig))
    return out


def save_dashboard(ds: Any, folder: Path, stem: str, dpi: int = 110) -> list[Path]:
    """Write the dashboard pages of a run as ``folder/<stem>-dashboard.png`` (several pages:
    ``-dashboard-1.png``, ``-2``...); returns the paths written (none for a run without a
    dashboard or without two output times)."""
    figs = dashboard_figures(ds)
    paths = []
    for k, (_, fig) in enumerate(figs, 1):
        path = Path(folder) / (f"{stem}-dashboard.png" if len(figs) == 1
                               else f"{stem}-dashboard-{k}.png")
        fig.savefig(path, dpi=dpi)
        paths.append(path)
    return paths
