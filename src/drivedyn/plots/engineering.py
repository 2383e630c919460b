"""The figures ``drivedyn plot`` draws for any results file: what an engineer reads (joint
angles and speeds, forces and torques, gaps and pressures, dissipated power, the energy
budget) in units with SI prefixes chosen by magnitude, and the dashboard of the library model
the run comes from.

* :func:`engineering_figures`: one figure per category (energy, bodies, joints, drivers and
  loads, springs, each contact family, gear meshes, tyres), small panels in a grid, the lines
  :func:`~drivedyn.plots.quantities.plot_quantities` chooses;
* :func:`dashboard_figures`: the pages of the run's library model's dashboard
  (:mod:`drivedyn.plots.dashboard`), none for a plain mechanism file.

Both take the run's ``xarray.Dataset`` and return ``(title, Figure)`` pairs (Agg canvas,
``fig.savefig(path)`` writes a PNG). Rules and dashboards: ``docs/plots.md``.
"""

from __future__ import annotations

import json
import re
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from drivedyn.plots.dashboard import dashboard_figures
from drivedyn.plots.panels import finish_panel, panel_grid, time_axis
from drivedyn.plots.quantities import PlotQuantity, figure_titles, plot_quantities


def model_name(ds: Any) -> str:
    """The model's name from the results' ``model_file`` attribute (empty if none)."""
    try:
        data = json.loads(ds.attrs.get("model_file", "") or "{}")
    except ValueError:
        return ""
    model = data.get("model", {}) if isinstance(data, dict) else {}
    return str(model.get("name", "")) if isinstance(model, dict) else ""


def slug(title: str) -> str:
    """A file stem for a figure title (``"contacts: thrust washer"`` ->
    ``"contacts_thrust_washer"``)."""
    return re.sub(r"[^a-z0-9]+", "_", title.lower()).strip("_") or "figure"


def _draw(ax: Any, t: np.ndarray, lines: list[PlotQuantity], time_unit: str) -> None:
    for q in lines:
        style = {"color": "k", "lw": 1.6} if q.label == "total" else {"lw": 1.0}
        ax.plot(t, q.scale * q.values, label=q.label, **style)
    first = lines[0]
    finish_panel(ax, first.panel, f"{first.quantity} [{first.display_unit}]", time_unit,
                 first.note, legend=len(lines) > 1 or first.label != first.quantity)


def engineering_figures(ds: Any, patterns: tuple[str, ...] = ()) -> list[tuple[str, Figure]]:
    """The engineering figures of a run: ``(title, figure)`` per category, in the order of
    :func:`~drivedyn.plots.quantities.plot_quantities` (``patterns``: only these variables,
    as ``drivedyn plot --vars``). Time in s (ms for runs shorter than 1 s); each panel in
    one display unit. Empty for results with fewer than two output times."""
    t_raw = np.asarray(ds["time"].values, dtype=float)
    if t_raw.size < 2:  # a run that stopped at its first step: no history to draw
        return []
    quantities = plot_quantities(ds, patterns)
    t_scale, t_unit = time_axis(t_raw)
    t = t_raw * t_scale
    name = model_name(ds)
    out = []
    for title in figure_titles(quantities):
        mine = [q for q in quantities if q.figure == title]
        panels = list(dict.fromkeys(q.panel for q in mine))
        fig, axes = panel_grid(f"{name}: {title}" if name else title, len(panels))
        for ax, panel in zip(axes, panels, strict=True):
            _draw(ax, t, [q for q in mine if q.panel == panel], t_unit)
        out.append((title, fig))
    return out


__all__ = ["PlotQuantity", "dashboard_figures", "engineering_figures", "model_name",
           "plot_quantities", "slug"]
