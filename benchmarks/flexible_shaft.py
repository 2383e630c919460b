"""Benchmark: a spinning flexible shaft with an unbalance (geometrically exact beams).

A steel tube (outer 40 mm, inner 30 mm, 1.2 m, material damping 5e-5 s) of N beam elements
along global x turns in two rigid bearings: a hinge at x = 0 (driven at 300 rad/s by a speed
driver) and a cylindrical joint at x = 1.2 m (free to slide axially); both hold the shaft's
end slopes, so it bends as a clamped-clamped beam. A 0.1 kg point mass (a small rigid body) is
fixed 50 mm off the axis at mid-span: the unbalance force m e w^2 = 450 N whirls the shaft at
the running speed, below the first bending critical speed (22.37/L^2 sqrt(EI/m) = 1004 rad/s),
with the deflection F L^3 / (192 EI) / (1 - (w / w_c)^2) = 0.25 mm. Gravity acts along -z.
The shaft starts turning rigidly at 300 rad/s; 1 s is simulated with
GeneralizedAlpha(rho_inf=0.9) at FixedStep(1e-4) (10 000 steps).

Prints JSON lines: ``{"warmup_compile_s": ...}`` (a few steps of each N, which compile or
load the kernels and the stepping loop), then one line per N with ``N``, ``step_mode``,
``wall_s``, ``steps``, ``newton_iterations``, ``factorizations``, ``steps_per_s``,
``whirl_mm`` (mean mid-span deflection over the second half of the run [mm], after the
start transient has died out), ``peak_rss_mb``, ``build_s``, ``success``.

Usage::

    python benchmarks/flexible_shaft.py                 # N = 100
    python benchmarks/flexible_shaft.py --n 20 100 --t-end 0.2
    python benchmarks/flexible_shaft.py --output-dt 1e-4   # an output at every step (memory)

The run records the mid-span node's position only (``variables=``), every ``--output-dt``
(default 1 ms: 1000 outputs); ``peak_rss_mb`` is the process's peak resident memory.
"""

from __future__ import annotations

import argparse
import json

import numpy as np
from _common import record, timed_run, warmup

import drivedyn as dd

LENGTH = 1.2  # [m]
SECTION = dd.HollowCircular(0.040, 0.030)
SPEED = 300.0  # [rad/s]
UNBALANCE_MASS = 0.1  # [kg]
UNBALANCE_RADIUS = 0.05  # [m]
DAMPING = 5e-5  # [s] stiffness-proportional: about 2.5 % of critical at the first mode
STEP = dd.FixedStep(1e-4)
INTEGRATOR = dd.GeneralizedAlpha(rho_inf=0.9)


def build_spec(n: int) -> tuple[dd.Spec, str]:
    """The shaft of ``n`` elements (``n`` even); returns the spec and the mid-span node."""
    spec = dd.Spec(gravity=(0.0, 0.0, -9.81))
    w = (SPEED, 0.0, 0.0)
    nodes = dd.add_straight_beam(spec, "shaft", (0, 0, 0), (LENGTH, 0, 0), n, SECTION, dd.STEEL,
                                 damping=DAMPING, angular_velocity=w)
    mid = nodes[n // 2]
    r = np.array([0.0, 0.0, UNBALANCE_RADIUS])
    pos = np.array([LENGTH / 2, 0.0, 0.0]) + r
    spec.add_rigid_body("unbalance", UNBALANCE_MASS, (1e-6, 1e-6, 1e-6), position=pos,
                        velocity=np.cross(w, r), angular_velocity=w)
    spec.add_marker("unbalance_seat", mid, position=r)
    spec.add_marker("unbalance_mass", "unbalance")
    spec.add(dd.Fixed("unbalance_fix", "unbalance_seat", "unbalance_mass"))
    for name, node, x, joint in (("left", nodes[0], 0.0, dd.Hinge),
                                 ("right", nodes[-1], LENGTH, dd.Cylindrical)):
        spec.add_marker(f"{name}_housing", dd.GROUND, position=(x, 0, 0), axis=(1, 0, 0))
        spec.add_marker(f"{name}_journal", node, axis=(1, 0, 0))
        spec.add(joint(f"{name}_bearing", f"{name}_housing", f"{name}_journal"))
    spec.add(dd.JointDriver("motor", "left_bearing", SPEED, quantity="speed"))
    return spec, mid


def run(n: int, t_end: float, output_dt: float = 1e-3) -> dict:
    spec, mid = build_spec(n)
    res, build_s, wall = timed_run(spec, t_end, integrator=INTEGRATOR, step=STEP,
                                   output_dt=output_dt, variables=[f"{mid}.position"])
    out = record(n, STEP, res, build_s, wall, float("nan"))
    del out["omega_last"]
    p = res[f"{mid}.position"].values
    half = len(p) // 2
    out["steps_per_s"] = round(res.stats.steps / wall, 1)
    out["whirl_mm"] = round(1e3 * float(np.hypot(p[half:, 1], p[half:, 2]).mean()), 4)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, nargs="+", default=[100])
    ap.add_argument("--t-end", type=float, default=1.0)
    ap.add_argument("--output-dt", type=float, default=1e-3, help="[s] between outputs")
    args = ap.parse_args()
    # a few steps of every size measured: a shaft of 4 elements would run on the dense LU,
    # and the stepping loop of the sparse one would compile inside the first timed run
    print(json.dumps({"warmup_compile_s": warmup(*(lambda n=n: run(n, 2e-3)
                                                   for n in args.n))}), flush=True)
    for n in args.n:
        print(json.dumps(run(n, args.t_end, args.output_dt)), flush=True)


if __name__ == "__main__":
    main()
