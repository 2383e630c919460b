"""Benchmark: the TORSEN bench through the differential FMUs (``drivedyn fmu``) against
``drivedyn tdr``.

For each model (``torsen-b``, ``torsen-c``) the FMU is built, then for each bench side (two
modes) the same bench run is made twice: by ``drivedyn tdr``'s ``run_bench`` (model build and
simulation, the kernels already loaded) and through the FMU by FMPy's ``simulate_fmu`` at a
communication step of ``--dt`` (default 1 ms; instantiation, initialisation and the steps,
inputs from :func:`drivedyn.fmu.bench.bench_inputs`). The two alternate ``--repeat`` times and
the smallest wall time of each is kept (the machine is shared). Prints the TDR of every mode
both ways with their difference, the wall times and their ratio per side, then one JSON
line. ``--halve`` also runs the FMU at half the step and prints the change of the steady
torques.

Usage::

    python benchmarks/fmu_bench.py
    python benchmarks/fmu_bench.py --models torsen-b --repeat 3 --halve
    python benchmarks/fmu_bench.py --short        # the 1.1 s bench of examples/08_torsen_b.py
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np
from fmpy import simulate_fmu

from drivedyn.analysis.tdr import run_bench
from drivedyn.config import read_library_file
from drivedyn.fmu import build_fmu
from drivedyn.fmu.bench import bench_inputs, window_tdrs
from drivedyn.library import differentials

SHORT = ["bench.ramp=0.1", "bench.transition=[0.5, 0.8]", "bench.t_end=1.1",
         "bench.window_drive=[0.25, 0.45]", "bench.window_coast=[0.9, 1.1]"]


def fmu_run(path: Path, p, side: str, dt: float) -> tuple[np.ndarray, float]:
    """FMPy's run of the bench side through the FMU: (results, wall time [s])."""
    inputs = bench_inputs(p, side, dt)
    t0 = time.perf_counter()
    res = simulate_fmu(str(path), start_time=0.0, stop_time=p.bench.t_end, step_size=dt,
                       output_interval=dt, input=inputs)
    return res, time.perf_counter() - t0


def torques(res: np.ndarray) -> dict[str, np.ndarray]:
    return {n: res[n] for n in res.dtype.names if n.endswith("_torque")}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--models", default="torsen-b,torsen-c")
    ap.add_argument("--dt", type=float, default=1e-3, help="communication step [s]")
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--short", action="store_true", help="the 1.1 s bench protocol")
    ap.add_argument("--halve", action="store_true", help="also at half the step")
    args = ap.parse_args()
    sets = SHORT if args.short else []
    rows, sides_out = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for model in args.models.split(","):
            p = read_library_file(model, sets)[0]
            diff = differentials.of(p)
            path = build_fmu(model, Path(tmp) / f"{model.replace('-', '_')}.fmu", sets)
            for side in diff.sides:
                run_bench(p, side, output_dt=0.1)  # loads the kernels of this model
                walls_tdr, walls_fmu = [], []
                for _ in range(args.repeat):
                    run = run_bench(p, side)
                    walls_tdr.append(run.wall_s)
                    res, wall = fmu_run(path, p, side, args.dt)
                    walls_fmu.append(wall)
                fmu = window_tdrs(p, side, res["time"], torques(res))
                out = {"model": model, "side": side, "tdr_wall_s": round(min(walls_tdr), 3),
                       "fmu_wall_s": round(min(walls_fmu), 3), "tdr_steps":
                       run.results.stats.steps}
                out["ratio"] = round(out["fmu_wall_s"] / out["tdr_wall_s"], 3)
                if args.halve:
                    half, _ = fmu_run(path, p, side, args.dt / 2)
                    a, b = p.bench.window_drive
                    k1 = (res["time"] >= a) & (res["time"] <= b)
                    k2 = (half["time"] >= a) & (half["time"] <= b)
                    out["halved_change"] = max(
                        abs(float(half[n][k2].mean()) / float(res[n][k1].mean()) - 1)
                        for n in torques(res))
                sides_out.append(out)
                for mode, tdr in run.tdr.items():
                    rows.append({"model": model, "mode": mode, "name": diff.mode(mode).name,
                                 "tdr": tdr, "fmu": fmu[mode],
                                 "diff_pct": 100 * (fmu[mode] / tdr - 1)})
    print(f"bench through the FMU at a {args.dt * 1e3:g} ms communication step against "
          f"drivedyn tdr ({'short' if args.short else 'full'} protocol)")
    print(f"  {'model':9} {'mode':4} {'':20} {'tdr':>8} {'FMU':>8} {'diff':>8}")
    for r in rows:
        print(f"  {r['model']:9} {r['mode']:4} {r['name']:20} {r['tdr']:8.4f} {r['fmu']:8.4f} "
              f"{r['diff_pct']:+7.3f} %")
    print(f"  {'model':9} {'side':6} {'tdr [s]':>8} {'FMU [s]':>8} {'FMU/tdr':>8}")
    for s in sides_out:
        extra = (f"   halving the step: steady torques {100 * s['halved_change']:.4f} %"
                 if "halved_change" in s else "")
        print(f"  {s['model']:9} {s['side']:6} {s['tdr_wall_s']:8.2f} {s['fmu_wall_s']:8.2f} "
              f"{s['ratio']:8.2f}{extra}")
    print(json.dumps({"benchmark": "fmu_bench", "dt": args.dt, "short": args.short,
                      "modes": rows, "sides": sides_out}))


if __name__ == "__main__":
    main()
