"""Benchmark: the RWD vehicle's split-mu launch (HMMWV on a flexible ladder frame, engine
map, propeller shaft on universal joints), one run per rear differential.

The shipped ``vehicle-rwd`` model file, each configuration of ``--configs`` (default
``open,locked,torsen-b``) launched from the parked vehicle's static equilibrium
(``static_start``) to ``--t-end`` (default 5 s) with the file's ``[solver]``/``[run]``
settings. Each configuration runs in a process of its own, so that its peak RSS is its own:
build and compile, the static start (with the driveline's wind-up, ``run.wind_up``: its
time is printed as "start"), a warm-up (a 1 ms run, which compiles or loads the
kernels), then the timed run. Prints per configuration the wall time of the run, the
real-time factor (wall / simulated), steps, rejected steps, unknowns, Newton iterations,
factorisations, peak RSS of the process, and the rear wheel torques over the file's window
(clipped to the run); then one JSON line per configuration.

Usage::

    python benchmarks/vehicle_rwd.py                              # open, locked, torsen-b; 5 s
    python benchmarks/vehicle_rwd.py --configs open --t-end 2
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time

import drivedyn.analysis.vehicle_rwd as V  # noqa: N812
from drivedyn.config import read_library_file
from drivedyn.config.loader import read_vehicle_differentials, resolve_path
from drivedyn.library.vehicles.vehicle_rwd import build_spec
from drivedyn.model.compile import compile_model
from drivedyn.solver import simulate


def one(config: str, t_end: float) -> dict:
    """Build, warm up and time the launch of ``config``; its figures."""
    base = resolve_path("vehicle-rwd").parent
    p, _, source = read_library_file("vehicle-rwd")
    p = V.configure(p, config)
    torsen = read_vehicle_differentials(p, source, base)
    t0 = time.perf_counter()
    spec, lay = build_spec(p, torsen, base)
    model = compile_model(spec)
    build = time.perf_counter() - t0
    t0 = time.perf_counter()
    state = V.static_start(p, torsen, base, model, lay)  # with the driveline's wind-up
    start = time.perf_counter() - t0
    kw = p.solver.settings(h_max=p.run.h_max)
    t0 = time.perf_counter()
    simulate(model, 1e-3, state=state, output_dt=1e-3, **kw)
    warm = time.perf_counter() - t0
    t0 = time.perf_counter()
    res = simulate(model, t_end, state=state, output_dt=V.OUTPUT_DT, **kw)
    wall = time.perf_counter() - t0
    st = res.stats
    t_done = float(res.time[-1])
    out = {
        "config": config, "unknowns": model.neq, "t_end": t_done, "success": res.success,
        "wall_s": round(wall, 2), "real_time_factor": round(wall / max(t_done, 1e-12), 3),
        "steps": st.steps, "rejected": st.rejected,
        "newton_iterations": st.newton_iterations, "factorizations": st.factorizations,
        "build_s": round(build, 2), "start_s": round(start, 2), "warmup_s": round(warm, 2),
        "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1),
    }
    a, b = p.run.window
    if t_done > a:
        s = V.summarize(res, lay, (a, min(b, t_done)))
        out["window"] = [a, min(b, t_done)]
        out["torque_rl"] = round(s.wheels["rl"].torque, 2)
        out["torque_rr"] = round(s.wheels["rr"].torque, 2)
        out["speed"] = round(s.speed, 3)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--t-end", type=float, default=5.0, help="simulated time [s]")
    ap.add_argument("--configs", default="open,locked,torsen-b",
                    help=f"comma-separated rear differentials ({', '.join(V.CONFIGS)})")
    ap.add_argument("--child", default=None, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        print(json.dumps(one(a.child, a.t_end)))
        return
    configs = [c.strip() for c in a.configs.split(",") if c.strip()]
    bad = [c for c in configs if c not in V.CONFIGS]
    if bad:
        ap.error(f"--configs: unknown configuration {bad[0]!r} (expected {', '.join(V.CONFIGS)})")
    rows = []
    for c in configs:
        r = subprocess.run([sys.executable, __file__, "--child", c, "--t-end", str(a.t_end)],
                           capture_output=True, text=True, check=False)
        if r.returncode != 0:
            print(f"{c}: failed\n{r.stderr}", file=sys.stderr)
            sys.exit(1)
        rows.append(json.loads(r.stdout.strip().splitlines()[-1]))
    print(f"RWD vehicle, split-mu launch from 1.5 m/s, {a.t_end:g} s simulated")
    print("| rear | unknowns | start [s] | wall [s] | wall / simulated | steps | rejected | "
          "Newton iterations | factorisations | peak RSS [MB] | T_rl / T_rr [N m] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        tq = f"{r['torque_rl']:.1f} / {r['torque_rr']:.1f}" if "torque_rl" in r else "-"
        print(f"| {r['config']} | {r['unknowns']} | {r['start_s']:.2f} | {r['wall_s']:.1f} | "
              f"{r['real_time_factor']:.2f} | {r['steps']} | {r['rejected']} | "
              f"{r['newton_iterations']} | {r['factorizations']} | {r['peak_rss_mb']:.0f} | "
              f"{tq} |" + ("" if r["success"] else " FAILED"))
    for r in rows:
        print(json.dumps(r))


if __name__ == "__main__":
    main()
