"""Where the wall time of a run goes, per phase: element evaluation (residual only, and
residual with tangent, per element family), the rest of the assembly, factorisation, solve,
Newton bookkeeping (Lie update, corrections, convergence test), step bookkeeping (commit,
energy account, error estimate), recording, and the Python around them.

Each phase is timed by wrapping the function that performs it (``time.perf_counter`` around
each call, about 0.3 us per call, subtracted from nothing: the wrappers' own cost lands in
"Python around"). Python around = the wall time of ``simulate`` minus every timed phase.

Usage::

    python benchmarks/profile_phases.py                       # Type C bench, rear side
    python benchmarks/profile_phases.py torsen-b --side right
    python benchmarks/profile_phases.py vehicle-4wd --t-end 1
    python benchmarks/profile_phases.py torsen-c --vehicle    # vehicle configuration

Prints a table (phase, seconds, share, calls, microseconds per call) and one JSON line.
"""

from __future__ import annotations

import os

# the phases are timed by wrapping the Python Newton loop's calls; the compiled step
# (drivedyn.solver.newton_kernel) runs a whole step in one call, so this script profiles the
# Python loop, the same algorithm (compiled_step_costs.py breaks down the compiled step)
os.environ["DRIVEDYN_COMPILED_NEWTON"] = "0"

import argparse
import collections
import importlib
import json
import resource
import time

from drivedyn.config import load_model, read_library_file
from drivedyn.elements.framework.group import Group
from drivedyn.model.compile import compile_model
from drivedyn.results.recorder import EnergyAccount, Recorder
from drivedyn.solver.system import System

# the modules (the package exports functions of the same names)
simulate_mod = importlib.import_module("drivedyn.solver.simulate")
stepper_mod = importlib.import_module("drivedyn.solver.stepper")

TIMES: dict[str, float] = collections.defaultdict(float)
CALLS: dict[str, int] = collections.defaultdict(int)


def _timed(label, fn):
    def wrapper(*args, **kwargs):
        t0 = time.perf_counter()
        try:
            return fn(*args, **kwargs)
        finally:
            TIMES[label] += time.perf_counter() - t0
            CALLS[label] += 1
    return wrapper


def instrument() -> None:
    group_eval = Group.evaluate

    def evaluate(self, st, tfv, t, Tn, cM, cC, cK, mode, want, r, rabs, data):
        t0 = time.perf_counter()
        group_eval(self, st, tfv, t, Tn, cM, cC, cK, mode, want, r, rabs, data)
        label = f"elements: {self.family} ({'residual + tangent' if want else 'residual'})"
        TIMES[label] += time.perf_counter() - t0
        CALLS[label] += 1

    Group.evaluate = evaluate
    # after its first evaluation System.evaluate calls each group's compiled entry point
    # directly (bound calls): time those too, under the group's family
    bind = System._bind

    def bound(self, st, cM, cC, cK, mode, want):
        calls = bind(self, st, cM, cC, cK, mode, want)
        if not calls:
            return calls
        label = "residual + tangent" if want else "residual"
        return [(_timed(f"elements: {g.family} ({label})", entry), pre, post)
                for g, (entry, pre, post) in zip(self.model.groups, calls, strict=True)]

    System._bind = bound
    sys_eval = System.evaluate

    def system_evaluate(self, *args, **kwargs):
        before = sum(v for k, v in TIMES.items() if k.startswith("elements"))
        t0 = time.perf_counter()
        sys_eval(self, *args, **kwargs)
        inner = sum(v for k, v in TIMES.items() if k.startswith("elements")) - before
        TIMES["assembly around the kernels (zeroing, time functions)"] += (
            time.perf_counter() - t0 - inner)
        CALLS["assembly around the kernels (zeroing, time functions)"] += 1

    System.evaluate = system_evaluate
    System.factor = _timed("factorisation (incl. matrix hand-over)", System.factor)
    for name in ("lie_update", "newton_update", "residual_norms", "tangents",
                 "roundoff_levels"):
        if hasattr(stepper_mod, name):
            setattr(stepper_mod, name, _timed(f"Newton bookkeeping: {name}",
                                               getattr(stepper_mod, name)))
    simulate_mod.step_error = _timed("step control: error estimate", simulate_mod.step_error)
    EnergyAccount.advance = _timed("step bookkeeping: energy account", EnergyAccount.advance)
    Recorder.record = _timed("recording", Recorder.record)
    default = simulate_mod.default_linear_solver

    def linear_solver(n):
        lin = default(n)
        lin.solve = _timed("solve (forward/back substitution)", lin.solve)
        return lin

    simulate_mod.default_linear_solver = linear_solver
    stepper_mod.default_linear_solver = linear_solver


def build(args) -> tuple[object, float | None, dict]:
    """(model, t_end, simulate keyword arguments)."""
    if args.model.startswith("vehicle") or not args.model.startswith("torsen"):
        model = load_model(args.model)
        return model, args.t_end, {}
    from drivedyn.library import differentials
    from drivedyn.library.differentials.scenarios import bench_spec, vehicle_spec

    p, _, _ = read_library_file(args.model)
    diff = differentials.of(p)
    if args.vehicle:
        spec, _, t_end = vehicle_spec(diff, p)
        kw = p.solver.settings(h_max=p.vehicle.h_max)
    else:
        spec, _ = bench_spec(diff, p, args.side or diff.sides[0])
        t_end = p.bench.t_end
        kw = p.solver.settings()
    return compile_model(spec), args.t_end or t_end, {**kw, "output_dt": p.solver.output_dt}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("model", nargs="?", default="torsen-c")
    ap.add_argument("--side", default=None, help="bench side (differentials)")
    ap.add_argument("--vehicle", action="store_true",
                    help="differentials: the vehicle configuration instead of the bench")
    ap.add_argument("--t-end", type=float, default=None)
    args = ap.parse_args()
    model, t_end, kw = build(args)
    simulate_mod.simulate(model, min(2e-3, t_end or 2e-3), **kw)  # compile or load kernels
    instrument()
    TIMES.clear()
    CALLS.clear()
    res = simulate_mod.simulate(model, t_end, **kw)
    wall = res.stats.wall_s
    measured = sum(TIMES.values())
    rows = sorted(TIMES.items(), key=lambda kv: -kv[1])
    rows.append(("Python around (step and Newton loops, calls, wrappers)", wall - measured))
    st = res.stats
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"{args.model}: {model.neq} unknowns, simulated {res.time[-1]:g} s, wall {wall:.2f} s, "
          f"{st.steps} steps ({st.rejected} rejected), {st.newton_iterations} Newton "
          f"iterations, {st.factorizations} factorisations, {st.residual_evaluations} "
          f"evaluations, peak RSS {rss:.0f} MB")
    print(f"{'phase':62s} {'s':>7s} {'share':>6s} {'calls':>8s} {'us/call':>8s}")
    for label, sec in rows:
        n = CALLS.get(label, 0)
        per = f"{1e6 * sec / n:8.1f}" if n else "       -"
        print(f"{label:62s} {sec:7.3f} {sec / wall:6.1%} {n:8d} {per}")
    print(json.dumps({"benchmark": "profile_phases", "model": args.model,
                      "vehicle": args.vehicle, "side": args.side, "unknowns": model.neq,
                      "wall_s": round(wall, 3), "steps": st.steps, "rejected": st.rejected,
                      "newton_iterations": st.newton_iterations,
                      "factorizations": st.factorizations, "peak_rss_mb": round(rss, 1),
                      "phases": {k: round(v, 4) for k, v in rows},
                      "calls": dict(CALLS)}))


if __name__ == "__main__":
    main()
