"""Benchmark: the TORSEN Type C central differential on the test bench, all four modes.

The shipped ``torsen-c`` model file (``drivedyn.library.differentials.torsen_c``: housing
with one pocket per planet, sun, planets on planar guides with pocket contact and tip
friction, internal gear on a helical spline to the coupling, 2 n helical meshes, five thrust
washers) is run on
the seed 003 bench protocol of its ``[bench]`` table: housing held, 125 N m on one output,
the other output's speed prescribed for a 20 rpm speed difference; drive, then a smooth
reversal to coast (default ramp 0.3 s, reversal 1.2-2.0 s, end 3 s, steady windows 0.4-1.0 s
and 2.2-2.8 s). Two runs cover the four locking modes: torque on the rear output (modes 1,
2: drive and coast, bias rear) and on the front output (modes 3, 4, bias front). Solver:
the file's ``[solver]`` table (generalized-alpha, adaptive steps).

Prints a table (mode, simulated TDR, analytic quasi-static TDR of
``drivedyn.library.differentials.torsen_c.analytic``, the measured TDR of the file's
``[experiment]`` table,
the relative differences, window ripple), then per run the wall time of ``simulate``, the
model build time, steps, rejected steps, Newton iterations, LU factorizations, and the total
wall time and peak RSS; finally one JSON line with all of it. The warm-up (a 2 ms run of
the rear bench) compiles the numba kernels on the very first run on a machine (~1-2 min) and
loads them from the cache afterwards.

Usage::

    python benchmarks/torsen_c_bench.py
    python benchmarks/torsen_c_bench.py --set pockets.mu=0.1 --set bench.t_end=3.0
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import time

from _common import warmup

from drivedyn.analysis.tdr import experimental, mode_name, run_bench, side_modes
from drivedyn.config import read_library_file
from drivedyn.library.differentials import get
from drivedyn.library.differentials.protocol import bench_spec
from drivedyn.library.differentials.torsen_c.analytic import bench_tdr
from drivedyn.model.compile import compile_model
from drivedyn.solver.settings import AdaptiveStep, GeneralizedAlpha, Newton
from drivedyn.solver.simulate import simulate


def tiny_run(p) -> None:
    """2 ms of the rear bench: every element family of the model, compiled or loaded."""
    s = p.solver
    st, nw = s.step, s.newton
    model = compile_model(bench_spec(get("torsen_c"), p, "rear")[0])
    simulate(model, 2e-3, integrator=GeneralizedAlpha(s.rho_inf),
             step=AdaptiveStep(st.h0, st.h_min, st.h_max, st.rtol, st.atol),
             newton=Newton(nw.strategy, nw.tol, nw.phi_tol, nw.max_iter), output_dt=1e-3)


def run_side(p, side: str) -> tuple[object, dict]:
    """One bench run; returns (BenchRun, figures of the run)."""
    run = run_bench(p, side)
    st = run.results.stats
    return run, {
        "side": side,
        "modes": list(side_modes(p)[side]),
        "wall_s": round(st.wall_s, 3),
        "build_s": round(run.wall_s - st.wall_s, 3),
        "steps": st.steps,
        "rejected": st.rejected,
        "newton_iterations": st.newton_iterations,
        "factorizations": st.factorizations,
        "residual_evaluations": st.residual_evaluations,
        "success": run.success,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--model", default="torsen-c", help="model file (default: torsen-c)")
    parser.add_argument("--set", dest="overrides", action="append", default=[],
                        metavar="KEY=VALUE", help="override a model-file value (repeatable)")
    args = parser.parse_args()

    p, _, source = read_library_file(args.model, args.overrides)
    t_warm = warmup(lambda: tiny_run(p))
    bn = p.bench
    print(f"TORSEN Type C bench: {source}; {bn.torque:g} N m, speed difference "
          f"{bn.speed_diff * 30 / math.pi:g} rpm, t_end {bn.t_end:g} s, "
          f"windows {tuple(bn.window_drive)} / {tuple(bn.window_coast)} s "
          f"(warm-up {t_warm:.2f} s)", flush=True)

    t0 = time.perf_counter()
    runs, figures = {}, []
    for side in ("rear", "front"):
        run, fig = run_side(p, side)
        runs[side] = run
        figures.append(fig)
    total = time.perf_counter() - t0
    rss = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1)

    exp = experimental(p)
    modes = {}
    print()
    print(f"{'mode':<4} {'':<18} {'TDR sim':>9} {'analytic':>9} {'experiment':>10} "
          f"{'sim/ana-1':>10} {'sim/exp-1':>10} {'ripple':>8}")
    for side in ("rear", "front"):
        run = runs[side]
        for mode in side_modes(p)[side]:
            sim = run.tdr.get(mode, float("nan"))
            ana = bench_tdr(p, mode)
            ex = exp.get(mode, float("nan"))
            e_ana = 100 * (sim / ana - 1)
            e_exp = 100 * (sim / ex - 1)
            modes[str(mode)] = {"name": mode_name(p, mode), "tdr_sim": round(sim, 6),
                                "tdr_analytic": round(ana, 6), "tdr_experiment": ex,
                                "err_analytic_pct": round(e_ana, 4),
                                "err_experiment_pct": round(e_exp, 3),
                                "ripple": run.ripple.get(mode, float("nan"))}
            print(f"{mode:<4} {mode_name(p, mode):<18} {sim:9.4f} {ana:9.4f} {ex:10.3f} "
                  f"{e_ana:9.3f}% {e_exp:9.2f}% {modes[str(mode)]['ripple']:8.1e}")
    print()
    print(f"{'run':<6} {'modes':<6} {'wall [s]':>8} {'build [s]':>9} {'steps':>6} "
          f"{'rejected':>8} {'Newton it.':>10} {'LU':>6} {'success':>7}")
    for f in figures:
        ms = ", ".join(map(str, f["modes"]))
        print(f"{f['side']:<6} {ms:<6} {f['wall_s']:8.2f} "
              f"{f['build_s']:9.3f} {f['steps']:6d} {f['rejected']:8d} "
              f"{f['newton_iterations']:10d} {f['factorizations']:6d} {f['success']!s:>7}")
    print(f"total wall {total:.2f} s (both runs, build included); peak RSS {rss} MB")
    print(json.dumps({
        "benchmark": "torsen_c_bench",
        "model": source,
        "overrides": args.overrides,
        "warmup_compile_s": t_warm,
        "runs": figures,
        "modes": modes,
        "total_wall_s": round(total, 3),
        "peak_rss_mb": rss,
        "success": all(f["success"] for f in figures),
    }), flush=True)


if __name__ == "__main__":
    main()
