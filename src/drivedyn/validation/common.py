"""Helpers shared by the validation cases: one-sided checks, figures, failed-run results,
zero crossings, peaks, small rotations."""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from drivedyn.validation.base import CaseResult

G = 9.81  # [m/s^2] gravitational acceleration used by all cases


# ---------------------------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------------------------


def at_most(case: str, quantity: str, value: float, limit: float, unit: str,
            source: str) -> CaseResult:
    """A check ``value <= limit``: error = relative excess (0 when it holds; a NaN value
    fails)."""
    err = max(0.0, (value - limit) / abs(limit)) if value == value else float("inf")
    return CaseResult(case, quantity, limit, value, unit, err, 0.0, source)


def at_least(case: str, quantity: str, value: float, limit: float, unit: str,
             source: str) -> CaseResult:
    """A check ``value >= limit``: error = relative shortfall (0 when it holds; a NaN value
    fails)."""
    err = max(0.0, (limit - value) / abs(limit)) if value == value else float("inf")
    return CaseResult(case, quantity, limit, value, unit, err, 0.0, source)


def rot_z(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rot_y(a: float) -> np.ndarray:
    """Rotation about y by ``a``: maps x to (cos a, 0, -sin a)."""
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def crossings(t: np.ndarray, y: np.ndarray, direction: int = 0) -> np.ndarray:
    """Times where ``y`` crosses zero, linearly interpolated between samples.

    ``direction`` +1: upward only, -1: downward only, 0: both.
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    up = (y[:-1] < 0.0) & (y[1:] >= 0.0)
    down = (y[:-1] > 0.0) & (y[1:] <= 0.0)
    sel = up if direction > 0 else down if direction < 0 else (up | down)
    i = np.nonzero(sel)[0]
    return t[i] + (t[i + 1] - t[i]) * y[i] / (y[i] - y[i + 1])


def peak(t: np.ndarray, y: np.ndarray) -> float:
    """Largest value of a sampled smooth signal, refined by a parabola through the three
    samples around the largest sample."""
    i = int(np.argmax(y))
    if i == 0 or i == len(y) - 1:
        return float(y[i])
    y0, y1, y2 = y[i - 1], y[i], y[i + 1]
    den = y0 - 2.0 * y1 + y2
    if den >= 0.0:
        return float(y1)
    return float(y1 - 0.125 * (y2 - y0) ** 2 / den)


def failed_check(case: str, quantity: str, unit: str, tol: float, source: str,
            res: Any) -> CaseResult:
    """A failed check for a run that did not reach its end time."""
    r = CaseResult(case, quantity, np.nan, np.nan, unit, np.inf, tol,
                   f"{source}; RUN FAILED: {getattr(res, 'message', res)}")
    return r


def save_figure(figure_dir: str | None, name: str, draw: Callable[[Any], None]) -> list[str]:
    """Draw a figure with ``draw(fig)`` and save it as ``figure_dir/name.png`` (Agg canvas,
    no pyplot state: safe in tests and without a display)."""
    if not figure_dir:
        return []
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    os.makedirs(figure_dir, exist_ok=True)
    fig = Figure(figsize=(8, 5))
    FigureCanvasAgg(fig)
    draw(fig)
    fig.tight_layout()
    path = os.path.join(figure_dir, f"{name}.png")
    fig.savefig(path, dpi=110)
    return [path]


def finish_case(results: list[CaseResult], t0: float, figures: list[str]) -> list[CaseResult]:
    wall = time.perf_counter() - t0
    for r in results:
        r.wall_s = wall
        r.figures = list(figures)
    return results
