"""What every vehicle's analysis does the same way: run one vehicle file with several
differential configurations and summarise each run over the file's window.

A vehicle analysis module (:mod:`drivedyn.analysis.vehicle_4wd`,
:mod:`drivedyn.analysis.vehicle_rwd`) provides ``configure(p, name)`` (the file with the
configuration's differentials), ``run(p, torsen, base_dir, t_end=, progress=)`` (results and
layout) and ``summarize(results, layout, window)`` (a summary with a ``wall`` attribute);
:func:`compare` drives them.
"""

from __future__ import annotations

import time
from pathlib import Path
from types import ModuleType
from typing import Any


def compare(analysis: ModuleType, p: Any, torsen: dict, configs: list[str],
            base_dir: str | Path = ".", t_end: float | None = None, progress=None,
            window: tuple[float, float] | None = None) -> list[tuple[Any, Any]]:
    """The same vehicle ``p`` with each configuration of ``configs``: [(summary, results)].

    Args:
        analysis: the vehicle's analysis module (see the module docstring).
        torsen: TORSEN model parameters by name (as read from the vehicle's files).
        t_end: final time [s] (default: the file's ``run.t_end``).
        window: the summaries' window [s] (default: the file's ``run.window``).
    The summary's ``wall`` is the wall time [s] of build, compilation and run.
    """
    out = []
    for c in configs:
        q = analysis.configure(p, c)
        t0 = time.perf_counter()
        res, lay = analysis.run(q, torsen, base_dir, t_end=t_end, progress=progress)
        s = analysis.summarize(res, lay, window or q.run.window)
        s.wall = time.perf_counter() - t0
        out.append((s, res))
    return out


__all__ = ["compare"]
