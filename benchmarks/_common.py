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


def library_run(name: str, overrides: list[str], side: str = "rear", config: str = "open",
                t_end: float = 3.0) -> tuple[dd.Model, dict, float, float, str]:
    """A library model's run as its benchmark makes it: ``torsen-c`` / ``torsen-b`` (one
    bench side, the file's profile), ``vehicle-4wd`` (the launch, ``t_end`` [s]) or
    ``vehicle-rwd`` (the split-mu launch with rear differential ``config`` from the parked
    vehicle's static equilibrium, ``t_end``); ``overrides``: model-file ``KEY=VALUE``.
    Returns (model, the keyword arguments of ``simulate`` but ``t_end`` and the outputs,
    t_end [s], output interval [s], what the run is)."""
    from drivedyn.config import read_library_file

    p = read_library_file(name, overrides)[0]
    if name == "vehicle-4wd":
        from drivedyn.library.vehicles.vehicle_4wd import build_spec

        sp = build_spec(p, {n: read_library_file(n)[0] for n in ("torsen-c", "torsen-b")})[0]
        return (dd.compile_model(sp), p.solver.settings(h_max=p.run.h_max), t_end, 0.01,
                "launch")
    if name == "vehicle-rwd":
        import drivedyn.analysis.vehicle_rwd as V  # noqa: N812
        from drivedyn.config.loader import read_vehicle_differentials, resolve_path
        from drivedyn.library.vehicles.vehicle_rwd import build_spec as rwd_spec

        base = resolve_path("vehicle-rwd").parent
        p = V.configure(p, config)
        torsen = read_vehicle_differentials(p, read_library_file(name)[2], base)
        sp, lay = rwd_spec(p, torsen, base)
        model = dd.compile_model(sp)
        state0 = V.static_start(p, torsen, base, model, lay)
        return (model, dict(p.solver.settings(h_max=p.run.h_max), state=state0), t_end,
                V.OUTPUT_DT, f"split-mu launch, {config} rear")
    from drivedyn.library.differentials import of
    from drivedyn.library.differentials.scenarios import bench_spec

    model = dd.compile_model(bench_spec(of(p), p, side)[0])
    return (model, p.solver.settings(), p.bench.t_end, p.solver.output_dt,
            f"bench, {side} side")
