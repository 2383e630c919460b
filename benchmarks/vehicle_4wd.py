"""Benchmark: the 4WD vehicle of seed 003 on split-mu, a launch from rest with the full
dynamic differentials (TORSEN Type C central, Type B front and rear: 387 unknowns).

The shipped ``vehicle-4wd`` model file (100 N m on the central housing from t = 0, ramped over
0.3 s; ice under the front left wheel) is run to ``--t-end`` (default 10 s) with its
``[solver]``/``[run]`` settings. Prints the wall time, the real-time factor (wall /
simulated), steps per second of wall time, Newton iterations, factorisations, rejected steps
and the peak RSS, the wheel torques over the last second, then where the time went (cProfile
of the run: the top functions by own time, grouped: linear algebra, element kernels, Python
around them) and one JSON line. A warm-up (a 1 ms run) compiles or loads the kernels first.

Usage::

    python benchmarks/vehicle_4wd.py                  # 10 s launch, TORSEN
    python benchmarks/vehicle_4wd.py --t-end 2 --config open
    python benchmarks/vehicle_4wd.py --no-profile
    python benchmarks/vehicle_4wd.py --no-profile --t-end 3 --speed 2   # rolling start
"""

from __future__ import annotations

import argparse
import cProfile
import json
import pstats
import resource
import time

import drivedyn.analysis.vehicle_4wd as V  # noqa: N812
from drivedyn.config import read_library_file
from drivedyn.library.vehicles.vehicle_4wd import build_spec
from drivedyn.model.compile import compile_model
from drivedyn.solver import simulate

GROUPS = {
    "linear algebra (factorise, solve)": ("getrf", "getrs", "gstrf", "sparse_lu_solve", "factor",
                                          "_scatter_dense", "solve"),
    "element kernels": ("kernel",),
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--t-end", type=float, default=10.0)
    ap.add_argument("--config", default="torsen", choices=sorted(V.CONFIGS))
    ap.add_argument("--no-profile", action="store_true")
    ap.add_argument("--speed", type=float, default=0.0,
                    help="initial vehicle speed [m/s] (body.speed; 0: launch from rest)")
    ap.add_argument("--set", dest="overrides", action="append", default=[],
                    metavar="KEY=VALUE", help="model-file override (repeatable)")
    a = ap.parse_args()
    p, _, _ = read_library_file("vehicle-4wd", [f"body.speed={a.speed}", *a.overrides])
    p = V.configure(p, a.config)
    tc, _, _ = read_library_file("torsen-c")
    tb, _, _ = read_library_file("torsen-b")
    t0 = time.perf_counter()
    spec, lay = build_spec(p, {"torsen-c": tc, "torsen-b": tb})
    model = compile_model(spec)
    build = time.perf_counter() - t0
    kw = p.solver.settings(h_max=p.run.h_max)
    t0 = time.perf_counter()
    simulate(model, 1e-3, output_dt=1e-3, **kw)  # one output: steps of 1 us fail (README)
    warm = time.perf_counter() - t0
    prof = None if a.no_profile else cProfile.Profile()
    t0 = time.perf_counter()
    if prof:
        prof.enable()
    res = simulate(model, a.t_end, output_dt=0.01, **kw)
    if prof:
        prof.disable()
    wall = time.perf_counter() - t0
    st = res.stats
    t_done = float(res.time[-1])
    out = {
        "config": a.config, "speed0": a.speed, "unknowns": model.neq, "t_end": t_done,
        "success": res.success,
        "wall_s": round(wall, 2), "real_time_factor": round(wall / max(t_done, 1e-12), 2),
        "steps": st.steps, "steps_per_s": round(st.steps / wall, 1), "rejected": st.rejected,
        "newton_iterations": st.newton_iterations, "factorizations": st.factorizations,
        "build_s": round(build, 3), "warmup_s": round(warm, 2),
        "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1),
        "profiled": prof is not None,
    }
    start = "launch from rest" if a.speed == 0 else f"rolling start at {a.speed:g} m/s"
    print(f"4WD vehicle on split-mu, {a.config}, {model.neq} unknowns, {start}")
    print(f"  simulated {t_done:g} s in {wall:.1f} s wall: real-time factor "
          f"{out['real_time_factor']:g} (wall / simulated)" + (" under cProfile" if prof else ""))
    print(f"  steps {st.steps} ({out['steps_per_s']} /s of wall), rejected {st.rejected}, "
          f"Newton iterations {st.newton_iterations}, factorisations {st.factorizations}, "
          f"peak RSS {out['peak_rss_mb']} MB")
    if t_done > 1.0:
        w = (t_done - 1.0, t_done)
        s = V.summarize(res, lay, w)
        print(f"  wheel torques over {w[0]:g}-{w[1]:g} s [N m]: " + ", ".join(
            f"{k} {x.torque:.2f}" for k, x in s.wheels.items())
            + f"; vehicle speed {s.speed:.3f} m/s")
        out["wheel_torques"] = {k: round(x.torque, 3) for k, x in s.wheels.items()}
        out["speed"] = round(s.speed, 4)
    if prof:
        stats = pstats.Stats(prof)
        total = sum(v[2] for v in stats.stats.values())
        shares = {g: 0.0 for g in GROUPS}
        top = sorted(stats.stats.items(), key=lambda kv: -kv[1][2])[:12]
        for (_, _, fn), v in stats.stats.items():
            for g, keys in GROUPS.items():
                if any(k in fn for k in keys):
                    shares[g] += v[2]
                    break
        print("  where the time goes (own time, cProfile):")
        for g, tt in shares.items():
            print(f"    {g:40s} {tt:7.1f} s  {100 * tt / total:5.1f} %")
        print(f"    {'the rest (Python around them)':40s} {total - sum(shares.values()):7.1f} s"
              f"  {100 * (total - sum(shares.values())) / total:5.1f} %")
        print("  top functions:")
        for (file, line, fn), v in top:
            print(f"    {v[2]:7.2f} s  {v[1]:8d} calls  {fn} ({file.split('/')[-1]}:{line})")
        out["profile"] = {g: round(tt, 2) for g, tt in shares.items()}
    print(json.dumps(out))


if __name__ == "__main__":
    main()
