"""Where the wall time of a run goes on the compiled Newton step.

The compiled step (``drivedyn.solver.newton_kernel``) runs a whole step in one call, so a
profiler sees one opaque call per step. This script measures the unit costs of its phases
in compiled loops (no Python in between) at a state taken from the run (the middle of the
first mode's window: contacts closed, planets sliding), counts how often the run pays each
of them, and prints the product next to the measured wall time:

* residual evaluation, all groups (``call_groups`` with ``want=False``), and per group;
* residual with the iteration matrix (``want=True``), all groups and per group;
* the factorisation of the assembled matrix and one solve, with the linear solver the run
  settled on (``default_linear_solver``; ``AutoLU`` decides at the run's first
  factorisation): the dense LU (``dense_factor_csc``, ``dense_solve``),
  or the sparse LU (``SparseLU.factor_csc``, called from Python as the run does, and the
  compiled ``sparse_lu_solve``);
* the rest of the step (predictor, Lie updates, norms, the Python around each call):
  measured wall time minus the phases above.

Counts come from the run's statistics: evaluations with the matrix = factorisations (the
matrix is assembled for a factorisation only); residual-only evaluations = the remaining
evaluations; solves = Newton iterations.

Usage::

    python benchmarks/compiled_step_costs.py                 # Type C bench, rear side
    python benchmarks/compiled_step_costs.py torsen-c --side front
    python benchmarks/compiled_step_costs.py torsen-b --side right
    python benchmarks/compiled_step_costs.py vehicle-4wd --t-end 3   # launch, state at 2 s
    python benchmarks/compiled_step_costs.py torsen-c --set flexible.washers=true
    python benchmarks/compiled_step_costs.py vehicle-rwd --config torsen-b --t-end 1

Prints a table and one JSON line.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
from _common import library_run
from numba import njit

from drivedyn.config import read_library_file
from drivedyn.elements.framework.contract import MODE_DYN
from drivedyn.solver.kernel_calls import KernelTable, call_groups
from drivedyn.solver.lapack import dense_factor_csc, dense_solve, workspace
from drivedyn.solver.linear import DenseLU, default_linear_solver
from drivedyn.solver.simulate import simulate
from drivedyn.solver.sparse_lu import sparse_lu_solve
from drivedyn.solver.step_loop import StepLoop
from drivedyn.solver.system import System


@njit
def _evaluations(G, x, R, v, vd, lam, es, tfv, t, Tn, r, rabs, data, want, n):
    for _ in range(n):
        r[:] = 0.0
        rabs[:] = 0.0
        if want:
            data[:] = 0.0
        call_groups(G, x, R, v, vd, lam, es, tfv, t, Tn, 1e6, 1e3, 1.0, MODE_DYN, want)


@njit
def _factorisations(data, indices, indptr, lu, piv, ib, n):
    for _ in range(n):
        dense_factor_csc(data, indices, indptr, lu, piv, ib)


@njit
def _solves(lu, piv, b, ib, tr, n):
    for _ in range(n):
        dense_solve(lu, piv, b, ib, tr)


@njit
def _sparse_solves(Lp, Li, Lx, Up, Ui, Ux, perm_r, perm_c, tail, b, z, x, n):
    for _ in range(n):
        sparse_lu_solve(Lp, Li, Lx, Up, Ui, Ux, perm_r, perm_c, tail, b, z, x)


def _sparse_factorisations(lin, data, indices, indptr, n):
    for _ in range(n):
        lin.factor_csc(data, indices, indptr, indptr.size - 1)


def _per_call(fn, *args, n: int) -> float:
    """Seconds per repetition of ``fn(*args, n)`` (compiled first, best of three)."""
    fn(*args, 1)
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        fn(*args, n)
        best = min(best, (time.perf_counter() - t0) / n)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("model", nargs="?", default="torsen-c")
    ap.add_argument("--side", default="rear")
    ap.add_argument("--n", type=int, default=20000, help="repetitions per unit cost")
    ap.add_argument("--t-end", type=float, default=3.0,
                    help="vehicle-4wd, vehicle-rwd: simulated [s]")
    ap.add_argument("--config", default="open",
                    help="vehicle-rwd: the rear differential (open, locked, clutch, torsen-b)")
    ap.add_argument("--set", dest="overrides", action="append", default=[],
                    metavar="KEY=VALUE", help="model-file override (repeatable)")
    args = ap.parse_args()
    model, settings, t_end, output_dt, what = library_run(
        args.model, args.overrides, args.side, args.config, args.t_end)
    if args.model.startswith("vehicle-"):
        t_probe = 2.0 * args.t_end / 3.0
        args.n = min(args.n, 2000 if args.model == "vehicle-4wd" else 1000)
    else:
        # the middle of the first mode's window: contacts closed, gears loaded, planets
        # sliding
        bench = read_library_file(args.model, args.overrides)[0].bench
        t_probe = 0.5 * sum(bench.window_drive)
    # compile or load every kernel; one output (outputs 1 us apart would force steps that
    # small, where the 4WD start fails: see the note in benchmarks/README.md)
    simulate(model, 1e-3, output_dt=1e-3, **settings)
    # the unit costs are measured at a state of the run: the accepted state of a run up to
    # t_probe, which the stepping loop updates in place (kept from StepLoop.create)
    kept = []
    create = StepLoop.create.__func__

    def keep(cls, stepper, st, *rest, **kw):
        kept.append(st)
        return create(cls, stepper, st, *rest, **kw)

    StepLoop.create = classmethod(keep)
    try:
        simulate(model, t_probe, **settings)
    finally:
        StepLoop.create = classmethod(create)
    # the run whose wall time and counts the unit costs are set against (compiled loop),
    # with its linear solver kept: AutoLU settles on sparse or dense at the run's first
    # factorisation, and the unit cost is measured with the one it settled on (decided at
    # the probe's state instead, the flexible washers' bench took the dense LU, 138 us,
    # where its run factorises sparse, 38 us)
    run_lin = default_linear_solver(model.neq)
    res = simulate(model, t_end, **settings, output_dt=output_dt, linear_solver=run_lin)
    st_ = res.stats
    sys = System(model)
    st = kept[-1]
    sys.evaluate(st, 1e6, 1e3, 1.0, MODE_DYN, True)
    mid = (st.x, st.R, st.v, st.vd, st.lam, st.es, sys.tfv, st.t, sys.Tn, sys.r, sys.rabs,
           sys.data)
    full = sys.kernel_table(st)
    groups = [KernelTable([(a, pre, post)]) for a, pre, post in _table_rows(sys, st)]
    cost = {}
    for want in (False, True):
        cost[want] = _per_call(_evaluations, full, *mid, want, n=args.n)
    per_group = {}
    for g, G in zip(model.groups, groups, strict=True):
        per_group[g.family] = [_per_call(_evaluations, G, *mid, w, n=args.n)
                               for w in (False, True)]
    sys.evaluate(st, 1e6, 1e3, 1.0, MODE_DYN, True)
    lin = getattr(run_lin, "active", run_lin)  # AutoLU: the solver the run settled on
    lin.factor_csc(sys.data, model.indices, model.indptr, model.neq)
    b = np.ones(model.neq)
    if isinstance(lin, DenseLU):
        lu, piv, ib, tr = workspace(model.neq)
        c_fac = _per_call(_factorisations, sys.data, model.indices, model.indptr, lu, piv,
                          ib, n=max(1, args.n // 4))
        c_sol = _per_call(_solves, lu, piv, b, ib, tr, n=args.n)
        lu_name = "dense LU"
    else:
        c_fac = _per_call(_sparse_factorisations, lin, sys.data, model.indices,
                          model.indptr, n=max(1, args.n // 4))
        c_sol = _per_call(_sparse_solves, *lin._f, b, np.empty_like(b), np.empty_like(b),
                          n=args.n)
        lu_name = f"sparse LU ({lin.order}, {lin.fill} entries)"
    n_mat = st_.factorizations
    n_res = st_.residual_evaluations - n_mat
    rows = [("residual evaluations", n_res, cost[False]),
            ("residual + matrix evaluations", n_mat, cost[True]),
            (lu_name, st_.factorizations, c_fac),
            ("solves", st_.newton_iterations, c_sol)]
    wall = st_.wall_s
    print(f"{args.model} {what}: {model.neq} unknowns, wall {wall:.3f} s, "
          f"{st_.steps} steps, {st_.rejected} rejected, {st_.newton_iterations} Newton it., "
          f"{st_.factorizations} factorisations, {st_.residual_evaluations} evaluations")
    print(f"{'phase':34s} {'calls':>8s} {'us/call':>8s} {'s':>7s} {'share':>6s}")
    total = 0.0
    out = {}
    for name, n, c in rows:
        s = n * c
        total += s
        out[name] = {"calls": int(n), "us_per_call": round(c * 1e6, 2), "s": round(s, 3)}
        print(f"{name:34s} {n:8d} {c * 1e6:8.2f} {s:7.3f} {s / wall:6.1%}")
    rest = wall - total
    print(f"{'rest (step logic, Python per step)':34s} {'':8s} {'':8s} {rest:7.3f} "
          f"{rest / wall:6.1%}")
    print("per group, us per call (residual / residual + matrix):")
    for fam, (a, b_) in per_group.items():
        print(f"  {fam:24s} {a * 1e6:7.2f} / {b_ * 1e6:7.2f}")
    print(json.dumps({"benchmark": "compiled_step_costs", "model": args.model,
                      "side": args.side, "wall_s": round(wall, 3), "phases": out,
                      "rest_s": round(rest, 3),
                      "per_group_us": {k: [round(a * 1e6, 2), round(b_ * 1e6, 2)]
                                       for k, (a, b_) in per_group.items()}}))


def _table_rows(sys: System, st) -> list:
    """(address, leading, trailing arguments) of every group, as in ``kernel_table``."""
    from drivedyn.solver.kernel_calls import entry_address

    rows = []
    for k, pre, mid, post in sys._kernel_args(st, 1.0, 1.0, 1.0, MODE_DYN, True):
        rows.append((entry_address(k, sys._signature(k, pre, mid, post)), pre, post))
    return rows


if __name__ == "__main__":
    main()
