"""Figures of the four-wheel-drive vehicle on split-mu (seed 003, Figure 15).

* :func:`wheel_torques_figure`: the drive torque of each wheel over time (Figure 15), the
  wheel spins with the vehicle speed, and the torque splits, one row per configuration;
* :func:`comparison_figure`: the window-mean wheel torques of each configuration side by side,
  the tyres' friction limits marked.

PNG through the Agg canvas (no display needed).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

WHEELS = ("fl", "fr", "rl", "rr")
LABELS = {"fl": "front left", "fr": "front right", "rl": "rear left", "rr": "rear right"}


def wheel_torques_figure(runs: list[tuple[str, Any]], window: tuple[float, float] | None = None
                         ) -> Figure:
    """For each ``(name, results)``: the drive torque [N m] of each wheel against time (the
    half-shaft torque, forward positive: Figure 15), the wheel spins [rad/s] with the vehicle
    speed, and the torque splits (front share, left share of each axle)."""
    from drivedyn.analysis.vehicle_4wd import time_histories

    fig = Figure(figsize=(11.0, 3.0 * len(runs) + 0.6), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(runs), 3, squeeze=False)
    for (name, res), (ax_t, ax_w, ax_s) in zip(runs, axes, strict=True):
        t = res.time
        h = time_histories(res)
        for w in WHEELS:
            mu = float(res[f"tyre_{w}.road_mu"].values[-1])
            ax_t.plot(t, h[f"torque_{w}"], lw=0.9, label=f"{LABELS[w]} (road {mu:g})")
            ax_w.plot(t, h[f"spin_{w}"], lw=0.9)
        ax_w2 = ax_w.twinx()
        ax_w2.plot(t, h["speed"], "k--", lw=0.8)
        ax_w2.set_ylabel("vehicle speed [m/s] (dashed)")
        ax_s.plot(t, h["front_share"], label="front / total")
        ax_s.plot(t, h["left_share_front"], label="left / front axle")
        ax_s.plot(t, h["left_share_rear"], label="left / rear axle")
        ax_t.set_title(f"{name}: wheel drive torques", fontsize=10)
        ax_t.set_ylabel("torque [N m]")
        ax_w.set_title(f"{name}: wheel spin", fontsize=10)
        ax_w.set_ylabel("spin [rad/s]")
        ax_s.set_title(f"{name}: torque splits", fontsize=10)
        ax_s.set_ylabel("share [-]")
        ax_s.set_ylim(0.0, 1.0)
        for ax in (ax_t, ax_w, ax_s):
            ax.set_xlabel("time [s]")
            ax.grid(True, alpha=0.3)
            if window is not None:
                ax.axvspan(*window, color="0.9", zorder=0)
        ax_t.legend(fontsize=7, loc="best")
        ax_s.legend(fontsize=7, loc="best")
    return fig


def comparison_figure(summaries: list[Any]) -> Figure:
    """Window-mean drive torque of each wheel for each configuration (bars), each wheel
    labelled with its road friction factor."""
    fig = Figure(figsize=(7.5, 4.0), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    n = len(summaries)
    x = np.arange(len(WHEELS))
    width = 0.8 / max(n, 1)
    for k, s in enumerate(summaries):
        vals = [s.wheels[w].torque for w in WHEELS]
        ax.bar(x + (k - (n - 1) / 2) * width, vals, width, label=s.name)
    ax.set_xticks(x, [f"{LABELS[w]}\nroad {summaries[0].wheels[w].mu_road:g}" for w in WHEELS]
                  if summaries else [LABELS[w] for w in WHEELS])
    ax.set_ylabel("drive torque [N m] (window mean)")
    ax.set_title("wheel torques on split-mu by differential type", fontsize=10)
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def save(fig: Figure, path: str | Path) -> Path:
    """Write ``fig`` as PNG; returns the path."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(p, dpi=120)
    return p
