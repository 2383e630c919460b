"""What the benchmark scripts share: timing a build and a run, and the JSON record."""

from __future__ import annotations

import resource
import time
from collections.abc import Callable

import drivedyn as dd


def timed_run(spec: dd.Spec, t_end: float, **simulate_kwargs) -> tuple[dd.Results, float, float]:
    """Compile ``spec`` and simulate it; returns (results, build time [s], run wall time [s])."""
    t0 = time.perf_counter()
    model = dd.compile_model(spec)
    build_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    res = dd.simulate(model, t_end, **simulate_kwargs)
    return res, build_s, time.perf_counter() - t0


def record(n: int, step: dd.FixedStep | dd.AdaptiveStep, res: dd.Results, build_s: float,
           wall: float, omega_last: float) -> dict:
    """The JSON line of one run (keys shared by all benchmarks)."""
    return {
        "N": n,
        "step_mode": "fixed" if isinstance(step, dd.FixedStep) else "adaptive",
        "wall_s": round(wall, 4),
        "steps": res.stats.steps,
        "newton_iterations": res.stats.newton_iterations,
        "factorizations": res.stats.factorizations,
        "omega_last": omega_last,
        "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1),
        "build_s": round(build_s, 4),
        "rejected": res.stats.rejected,
        "success": res.success,
    }


def warmup(*runs: Callable[[], object]) -> float:
    """Run tiny models once (compiles or loads the numba kernels); returns the time [s]."""
    t0 = time.perf_counter()
    for r in runs:
        r()
    return round(time.perf_counter() - t0, 3)
