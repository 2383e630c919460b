"""A TORSEN differential in its vehicle configuration (shared by ``torsen_c_vehicle.py`` and
``torsen_b_vehicle.py``): wall time per simulated second of each held level, loaded holds
against zero-torque holds.

Prints one line per level (torque, mode, TDR, wall time per simulated second over the hold,
steps per simulated second), the totals (wall, real-time factor, steps, rejected steps,
Newton iterations, factorisations, peak RSS) and one JSON line.
"""

from __future__ import annotations

import argparse
import json
import resource
import time

import numpy as np
from _common import warmup

from drivedyn.analysis.vehicle import run_vehicle
from drivedyn.config import read_library_file
from drivedyn.solver import step_loop


def tiny_run(model: str) -> None:
    """Compile (or load) the kernels before timing."""
    p = read_library_file(model, ["vehicle.torque_levels=[60]", "vehicle.speed_diff=[-2]",
                                  "vehicle.hold=0.002", "vehicle.ramp=0.002",
                                  "vehicle.backward=false"])[0]
    run_vehicle(p)


def main(model: str, title: str) -> None:
    ap = argparse.ArgumentParser(description=title)
    ap.add_argument("--short", action="store_true", help="holds 0.12 s, ramps 0.05 s")
    ap.add_argument("--set", dest="overrides", action="append", default=[],
                    metavar="KEY=VALUE", help="override a key of the model file")
    args = ap.parse_args()
    overrides = (["vehicle.hold=0.12", "vehicle.ramp=0.05"] if args.short else [])
    overrides += args.overrides
    compile_s = warmup(lambda: tiny_run(model))
    p = read_library_file(model, overrides)[0]
    marks: list[tuple[float, float, int]] = []
    # progress marks every ~2 ms of wall (the compiled loop returns with a batch of outputs
    # about every 50 ms by default): the per-level figures need marks within each hold (a
    # short-profile hold takes ~50 ms). The extra returns cost about 1 % of the run.
    step_loop.BATCH_WALL = 0.002

    def progress(t: float, h: float, steps: int) -> None:
        marks.append((t, time.perf_counter(), steps))

    t0 = time.perf_counter()
    run = run_vehicle(p, progress=progress)
    wall = time.perf_counter() - t0
    st = run.results.stats
    T = np.array([m[0] for m in marks])
    W = np.array([m[1] for m in marks])
    N = np.array([m[2] for m in marks])
    rows = []
    print(f"{'level':>5} {'torque':>7} {'mode':>4} {'TDR':>7} {'wall/sim':>9} {'steps/sim-s':>11}")
    for lv in run.levels:
        a, b = np.searchsorted(T, lv["t0"]), np.searchsorted(T, lv["t1"]) - 1
        dt = T[b] - T[a]
        cost = (W[b] - W[a]) / dt if dt > 0 else float("nan")
        rate = (N[b] - N[a]) / dt if dt > 0 else float("nan")
        rows.append({"level": lv["level"], "torque": lv["housing"], "mode": lv["mode"],
                     "tdr": lv["tdr"], "wall_per_sim_s": cost, "steps_per_sim_s": rate})
        tdr = f"{lv['tdr']:7.4f}" if lv["tdr"] is not None else f"{'-':>7}"
        print(f"{lv['level']:5d} {lv['housing']:7.1f} {lv['mode'] or '-':>4} {tdr} "
              f"{cost:9.2f} {rate:11.0f}")
    loaded = [r["wall_per_sim_s"] for r in rows if r["mode"] is not None]
    zero = [r["wall_per_sim_s"] for r in rows if r["mode"] is None]
    t_sim = float(run.results.time[-1])
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"held levels: loaded {np.mean(loaded):.2f} s of wall per simulated second"
          + (f", zero torque {np.mean(zero):.2f}" if zero else ""))
    print(f"run: {'ok' if run.success else run.message}; {t_sim:.2f} s simulated in {wall:.1f} s "
          f"wall (real-time factor {wall / t_sim:.2f}), {st.steps} steps ({st.rejected} "
          f"rejected), {st.newton_iterations} Newton iterations, {st.factorizations} "
          f"factorisations, peak RSS {rss:.0f} MB")
    print(json.dumps({"benchmark": f"{model.replace('-', '_')}_vehicle", "overrides": overrides,
                      "warmup_compile_s": round(compile_s, 3), "simulated_s": t_sim,
                      "wall_s": round(wall, 3), "real_time_factor": round(wall / t_sim, 3),
                      "steps": st.steps, "rejected": st.rejected,
                      "newton_iterations": st.newton_iterations,
                      "factorizations": st.factorizations, "peak_rss_mb": round(rss, 1),
                      "success": bool(run.success), "levels": rows}))
