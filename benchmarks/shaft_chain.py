"""Benchmark: a torsional chain of N rigid disks on hinges, driven by a constant torque.

N disks (m = 1 kg, inertia 1e-3 kg m^2 about every axis), 0.1 m apart along the global x
axis, each on a hinge to the ground about x; neighbours coupled by torsional spring-dampers
(1e4 N m/rad, 1 N m s/rad); 100 N m on disk 1 from t = 0; a torsional damper
(1 N m s/rad, no stiffness) from the last disk to the ground. Starts at rest, no gravity.
1 s is simulated with GeneralizedAlpha(rho_inf=0.9), first at FixedStep(1e-4), then with
AdaptiveStep (settings in ADAPTIVE below).

Prints JSON lines: first ``{"warmup_compile_s": ...}`` (a tiny N = 2 run that compiles or
loads the numba kernels), then one line per N and step mode with the keys ``N``,
``step_mode``, ``wall_s``, ``steps``, ``newton_iterations``, ``factorizations``,
``omega_last``, ``peak_rss_mb`` (and ``build_s``, ``rejected``, ``success``).

Usage::

    python benchmarks/shaft_chain.py                 # N = 10, 50, 200
    python benchmarks/shaft_chain.py --n 10 50 --t-end 0.5
"""

from __future__ import annotations

import argparse
import json

from _common import record, timed_run, warmup

import drivedyn as dd

MASS = 1.0  # [kg]
INERTIA = 1e-3  # [kg m^2], about every axis
SPACING = 0.1  # [m] along global x
STIFFNESS = 1e4  # [N m/rad] between neighbours
DAMPING = 1.0  # [N m s/rad] between neighbours and from the last disk to the ground
TORQUE = 100.0  # [N m] on disk 1
OUTPUT_DT = 0.01  # [s] sparse recording, so that recording does not dominate

FIXED = dd.FixedStep(1e-4)
# Adaptive: start at the fixed step, allow steps up to the output interval; rtol = 1e-4 of
# the motion within a step, atol = 1e-8 rad (the spring angles are about 1e-2 rad).
ADAPTIVE = dd.AdaptiveStep(h0=1e-4, h_min=1e-9, h_max=OUTPUT_DT, rtol=1e-4, atol=1e-8)
INTEGRATOR = dd.GeneralizedAlpha(rho_inf=0.9)


def build_spec(n: int) -> dd.Spec:
    """The chain of ``n`` disks; disk ``i`` is body ``disk{i}`` (``disk0`` is driven)."""
    spec = dd.Spec(gravity=(0.0, 0.0, 0.0))
    axis = (1.0, 0.0, 0.0)
    for i in range(n):
        pos = (SPACING * i, 0.0, 0.0)
        spec.add_rigid_body(f"disk{i}", MASS, (INERTIA, INERTIA, INERTIA), position=pos)
        spec.add_marker(f"g{i}", dd.GROUND, position=pos, axis=axis)
        spec.add_marker(f"m{i}", f"disk{i}", axis=axis)
        spec.add(dd.Hinge(f"hinge{i}", f"g{i}", f"m{i}"))
        if i > 0:
            spec.add(dd.TorsionalSpringDamper(f"shaft{i}", f"m{i - 1}", f"m{i}",
                                              stiffness=STIFFNESS, damping=DAMPING))
    spec.add(dd.Torque("drive", "m0", vector=(TORQUE, 0.0, 0.0)))
    spec.add_marker("g_damper", dd.GROUND, position=(SPACING * (n - 1), 0.0, 0.0), axis=axis)
    spec.add(dd.TorsionalSpringDamper("ground_damper", "g_damper", f"m{n - 1}",
                                      stiffness=0.0, damping=DAMPING))
    return spec


def run(n: int, step: dd.FixedStep | dd.AdaptiveStep, t_end: float) -> dict:
    """Build and simulate the chain; return the figures of the run."""
    res, build_s, wall = timed_run(build_spec(n), t_end, integrator=INTEGRATOR, step=step,
                                   output_dt=OUTPUT_DT)
    omega_last = float(res.final(f"disk{n - 1}.angular_velocity")[0])
    out = record(n, step, res, build_s, wall, omega_last)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, nargs="+", default=[10, 50, 200],
                        help="chain lengths (default: 10 50 200)")
    parser.add_argument("--t-end", type=float, default=1.0, help="simulated time [s]")
    args = parser.parse_args()

    # Warm-up: compiles (first run ever) or loads (cached) the numba kernels and the stepping
    # loop of both step modes, at every length (a long chain runs on the sparse LU, whose
    # loop is another compilation), so that the timed runs below measure the simulation only.
    t = warmup(*(lambda n=n, s=s: run(n, s, 5e-4) for n in args.n
                 for s in (dd.FixedStep(1e-4), dd.AdaptiveStep(h0=1e-4, h_max=1e-4))))
    print(json.dumps({"warmup_compile_s": t}), flush=True)

    for n in args.n:
        for step in (FIXED, ADAPTIVE):
            print(json.dumps(run(n, step, args.t_end)), flush=True)


if __name__ == "__main__":
    main()
