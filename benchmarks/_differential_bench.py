"""The bench benchmark shared by the differential models (``torsen_c_bench.py``,
``torsen_b_bench.py``): all four modes on the seed 003 protocol of the model file, with the
simulated, analytic and measured TDR, then per run the wall time of ``simulate``, the model
build time, steps, rejected steps, Newton iterations, LU factorizations, and the total wall
time and peak memory; then the wall time of the same four modes computed as ``drivedyn tdr``
does (``analysis.tdr.evaluate``: both sides at the same time on two or more CPUs), checked to
give the same TDRs; one JSON line at the end."""

from __future__ import annotations

import argparse
import json
import math
import resource
import time

from _common import warmup

from drivedyn.analysis.tdr import (
    evaluate,
    experimental,
    mode_name,
    parallel_sides,
    run_bench,
    side_modes,
)
from drivedyn.config import read_library_file
from drivedyn.library.differentials import of
from drivedyn.library.differentials.scenarios import bench_spec
from drivedyn.model.compile import compile_model
from drivedyn.solver.settings import AdaptiveStep, GeneralizedAlpha, Newton
from drivedyn.solver.simulate import simulate


def tiny_run(p) -> None:
    """2 ms of the rear bench: every element family of the model, compiled or loaded."""
    s = p.solver
    st, nw = s.step, s.newton
    diff = of(p)
    model = compile_model(bench_spec(diff, p, diff.sides[0])[0])
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


def main(default_model: str, description: str) -> None:
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--model", default=default_model,
                        help=f"model file (default: {default_model})")
    parser.add_argument("--set", dest="overrides", action="append", default=[],
                        metavar="KEY=VALUE", help="override a model-file value (repeatable)")
    args = parser.parse_args()

    p, _, source = read_library_file(args.model, args.overrides)
    t_warm = warmup(lambda: tiny_run(p))
    bn = p.bench
    diff = of(p)
    print(f"{diff.title} bench: {source}; {bn.torque:g} N m, speed difference "
          f"{bn.speed_diff * 30 / math.pi:g} rpm, t_end {bn.t_end:g} s, "
          f"windows {tuple(bn.window_drive)} / {tuple(bn.window_coast)} s "
          f"(warm-up {t_warm:.2f} s)", flush=True)

    # one BLAS thread, as `drivedyn tdr` runs its sides (analysis.tdr._bench_runs): with
    # two, OpenBLAS sums the larger products (the flexible case's contacts) in another
    # order, and the comparison below saw that round-off instead of what it checks (that
    # the forked side gives the runs' TDRs)
    from threadpoolctl import threadpool_limits

    t0 = time.perf_counter()
    runs, figures = {}, []
    with threadpool_limits(limits=1, user_api="blas"):
        for side in diff.sides:
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
    for side in diff.sides:
        run = runs[side]
        for mode in side_modes(p)[side]:
            sim = run.tdr.get(mode, float("nan"))
            ana = diff.analytic_bench(p, mode)
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
    # the same four modes the way `drivedyn tdr` computes them: both sides at the same time
    # (the second in a forked process) when analysis.tdr.parallel_sides() allows
    t1 = time.perf_counter()
    ev = evaluate(p, [1, 2, 3, 4])
    tdr_wall = time.perf_counter() - t1
    tdr_of = {row["mode"]: row["tdr"] for row in ev.rows}
    same = all(tdr_of[m] == runs[s_].tdr[m] for s_ in diff.sides for m in side_modes(p)[s_])
    print(f"four modes as `drivedyn tdr` runs them (both sides at once: "
          f"{'yes' if parallel_sides() else 'no'}): {tdr_wall:.2f} s wall, build and a one-step "
          f"warm-up included; TDRs equal to the runs above: {same}")
    print(json.dumps({
        "benchmark": f"{diff.library}_bench",
        "model": source,
        "overrides": args.overrides,
        "warmup_compile_s": t_warm,
        "runs": figures,
        "modes": modes,
        "total_wall_s": round(total, 3),
        "tdr_wall_s": round(tdr_wall, 3),
        "tdr_parallel_sides": parallel_sides(),
        "tdr_same": same,
        "peak_rss_mb": rss,
        "success": all(f["success"] for f in figures) and same,
    }), flush=True)
