"""Where the steps of a run go: step sizes over time, the dofs that set them, the rejections.

Runs one of the library's benchmark runs (``_common.library_run``: a TORSEN bench side, the
4WD launch, the RWD split-mu launch) with ``simulate(trace=...)``, which reports every step
attempt with its outcome: an accepted step's weighted error estimate (1 = the tolerance) and
the dof where it is largest, a rejected step's cause (error estimate, Newton diverged or out
of iterations) and the dof or equation that caused it. Prints

* per window of simulated time: accepted and rejected steps, the median step size and the
  Newton iterations per accepted step;
* the dofs that set the step size: the accepted steps grouped by the dof where their error
  estimate was largest (node and element names with their numbers collapsed, ``rear_b#: rz``
  for the element gears' spins), counting only steps within a factor 2 of the tolerance
  (estimate above 0.5: the steps the control holds; the others end at an output time or at
  ``h_max``, or are growing);
* the rejections by cause and dof.

Then one JSON line. The trace returns to Python after every attempt, so the wall time is
not the benchmark's (the counts are). Use it before tuning a tolerance or a step-size rule:
it says which physics the steps follow.

Usage::

    python benchmarks/step_trace.py vehicle-rwd --config torsen-b --t-end 5
    python benchmarks/step_trace.py torsen-c --side front --windows 8
    python benchmarks/step_trace.py vehicle-4wd --t-end 3
"""

from __future__ import annotations

import argparse
import collections
import itertools
import json
import re

import numpy as np
from _common import library_run

from drivedyn.solver.simulate import simulate

#: error estimate [share of the tolerance] above which an accepted step counts as held by
#: the step-size control
HELD = 0.5


def group(label: str) -> str:
    """An equation label with its numbers collapsed (``node rear_b3: rz`` -> ``rear_b#: rz``;
    ``parallel_axes rear_a2_guide: constraint 4`` -> ``parallel_axes rear_a#_guide``)."""
    label = re.sub(r"\d+", "#", label)
    label = re.sub(r": constraint #$", "", label)
    return label.removeprefix("node ")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("model", nargs="?", default="torsen-c")
    ap.add_argument("--side", default="rear", help="bench: the side driven")
    ap.add_argument("--config", default="torsen-b", help="vehicle-rwd: the rear differential")
    ap.add_argument("--t-end", type=float, default=3.0, help="vehicles: simulated [s]")
    ap.add_argument("--windows", type=int, default=10, help="windows of simulated time")
    ap.add_argument("--top", type=int, default=8, help="dof groups listed")
    ap.add_argument("--set", dest="overrides", action="append", default=[],
                    metavar="KEY=VALUE", help="model-file override (repeatable)")
    args = ap.parse_args()
    model, settings, t_end, output_dt, what = library_run(
        args.model, args.overrides, args.side, args.config, args.t_end)
    attempts: list[tuple[float, float, object]] = []
    res = simulate(model, t_end, **settings, output_dt=output_dt,
                   trace=lambda t, h, out: attempts.append((t, h, out)))
    labels = model.eq_labels
    acc = [(t, h, o) for t, h, o in attempts if o.ok]
    rej = [(t, h, o) for t, h, o in attempts if not o.ok]
    print(f"{args.model} {what}: {model.neq} unknowns, {res.stats.steps} steps, "
          f"{res.stats.rejected} rejected, {res.stats.newton_iterations} Newton iterations, "
          f"{res.stats.factorizations} factorisations, to t = {res.time[-1]:.4g} s")
    t0 = float(res.time[0])
    edges = np.linspace(t0, float(res.time[-1]), args.windows + 1)
    windows = []
    print("| window [s] | steps | rejected | median h [s] | Newton it. per step |")
    print("|---|---|---|---|---|")
    for a, b in itertools.pairwise(edges):
        inside = [(h, o) for t, h, o in acc if a < t <= b or (t == a == t0)]
        nrej = sum(1 for t, _, _ in rej if a <= t < b)
        hs = [h for h, _ in inside]
        its = [o.iterations for _, o in inside]
        row = {"window": [round(float(a), 6), round(float(b), 6)], "steps": len(inside),
               "rejected": nrej,
               "median_h": float(np.median(hs)) if hs else None,
               "iterations_per_step": round(float(np.mean(its)), 2) if its else None}
        windows.append(row)
        print(f"| {a:.4g}-{b:.4g} | {len(inside)} | {nrej} | "
              f"{row['median_h'] if hs else float('nan'):.3g} | "
              f"{row['iterations_per_step'] if its else float('nan'):.2f} |")
    bands = (0.0, 0.1, 0.3, HELD, 1.0)
    shares = [sum(1 for _, _, o in acc if lo < o.error <= hi or (lo == 0.0 == o.error))
              for lo, hi in itertools.pairwise(bands)]
    print("\naccepted steps by error estimate (share of the tolerance): "
          + ", ".join(f"{lo:g}-{hi:g}: {n}" for (lo, hi), n in
                      zip(itertools.pairwise(bands), shares, strict=True)))
    held = [o for _, _, o in acc if o.error > HELD and o.worst_eq >= 0]
    setters = collections.Counter(group(labels[o.worst_eq]) for o in held)
    print(f"steps held by the error estimate (above {HELD} of the tolerance): "
          f"{len(held)} of {len(acc)}; the dof where it was largest:")
    for g, n in setters.most_common(args.top):
        print(f"  {g:44s} {n:7d}  {n / max(len(held), 1):6.1%}")
    causes = collections.Counter(
        (o.status.name, group(labels[o.worst_eq]) if o.worst_eq >= 0 else "-") for _, _, o in rej)
    print("rejections by cause and dof (error: the dof of the largest estimate; Newton: the "
          "equation of the largest scaled residual):")
    for (status, g), n in causes.most_common(args.top):
        print(f"  {status:18s} {g:44s} {n:6d}")
    print(json.dumps({
        "benchmark": "step_trace", "model": args.model, "what": what,
        "unknowns": model.neq, "steps": res.stats.steps, "rejected": res.stats.rejected,
        "newton_iterations": res.stats.newton_iterations,
        "factorizations": res.stats.factorizations, "windows": windows,
        "error_bands": {f"{lo:g}-{hi:g}": n for (lo, hi), n in
                        zip(itertools.pairwise(bands), shares, strict=True)},
        "held_steps": len(held),
        "step_setters": dict(setters.most_common(args.top)),
        "rejections": {f"{s} {g}": n for (s, g), n in causes.most_common(args.top)},
    }))


if __name__ == "__main__":
    main()
