"""Figures of small time-history panels shared by the engineering figures and the dashboards:
a grid of axes in a constrained layout (labels stay inside the figure), the time axis in s
or ms, titles wrapped to the panel width. PNG through the Agg canvas (no display needed)."""

from __future__ import annotations

import math
import textwrap
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from drivedyn.plots.units import si_scale


def panel_grid(title: str, n: int) -> tuple[Figure, list[Any]]:
    """A figure titled ``title`` with ``n`` panels (1 column up to 2 panels, 2 up to 6,
    3 beyond), constrained layout."""
    ncols = 1 if n <= 2 else 2 if n <= 6 else 3
    nrows = max(1, math.ceil(n / ncols))
    width = 9.0 if ncols == 1 else 5.6 * ncols
    fig = Figure(figsize=(width, 2.9 * nrows + 0.8), layout="constrained")
    FigureCanvasAgg(fig)
    axes = list(fig.subplots(nrows, ncols, squeeze=False).ravel())
    for ax in axes[n:]:
        fig.delaxes(ax)
    fig.suptitle(title)
    return fig, axes[:n]


def time_axis(t: np.ndarray) -> tuple[float, str]:
    """(scale, unit) of the time axis: ms for runs shorter than 1 s, else s."""
    scale, unit = si_scale(t, "s")
    return (scale, unit) if unit in ("s", "ms") else (1.0, "s")


def finish_panel(ax: Any, title: str, ylabel: str, time_unit: str, note: str = "",
                 legend: bool = True) -> None:
    """Title (with ``note`` below it, smaller), labels, grid and legend of a panel."""
    cols = max(1, len(ax.figure.axes))
    width = 90 if cols == 1 and ax.figure.get_figwidth() > 8 else 55
    heading = textwrap.fill(title, width)
    if note:  # under the title, in the blank lines the title leaves for it
        text = textwrap.fill(note, int(width * 1.3))
        ax.text(0.0, 1.01, text, transform=ax.transAxes, fontsize=6.5, color="0.35",
                va="bottom", ha="left")
        heading += "\n" * (text.count("\n") + 1)
    ax.set_title(heading, fontsize=9)
    ax.set_ylabel(ylabel)
    ax.set_xlabel(f"time [{time_unit}]")
    ax.grid(True, alpha=0.3)
    handles, _ = ax.get_legend_handles_labels()
    if legend and handles:
        ax.legend(fontsize=6.5, loc="best", ncol=2 if len(handles) > 4 else 1,
                  handlelength=1.5, framealpha=0.7)
