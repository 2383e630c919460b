"""Benchmark: a row of N spur gears on hinges, meshing with the full 3-D gear element.

N spur gears (pitch radius 0.05 m: 50 teeth, module 2 mm; mass 1 kg, inertia 1e-3 kg m^2
about every axis), 0.1 m apart along the global x axis, each on a hinge to the ground about
z; neighbours mesh externally (``GearPair``, mesh stiffness 1e8 N/m, damping 1e3 N s/m, no
backlash, no transmission error, no friction); 100 N m on gear 1 from t = 0; a torsional
damper (1 N m s/rad, no stiffness) from the last gear to the ground. Starts at rest, no
gravity. 1 s is simulated with GeneralizedAlpha(rho_inf=0.9) at FixedStep(1e-4).

Prints JSON lines: first ``{"warmup_compile_s": ...}`` (a tiny N = 2 run that compiles or
loads the numba kernels), then one line per N with the keys of the shaft-chain benchmark
(``N``, ``step_mode``, ``wall_s``, ``steps``, ``newton_iterations``, ``factorizations``,
``omega_last``, ``peak_rss_mb``, ``build_s``, ``rejected``, ``success``) plus
``mesh_torque_first`` (torque of the first mesh on gear 1 [N m]) and ``mesh_torque_last``
(torque of the last mesh on the last gear [N m]), both at t = 1 s.

Usage::

    python benchmarks/gear_chain.py                  # N = 10, 50, 200
    python benchmarks/gear_chain.py --n 10 50 --t-end 0.5
"""

from __future__ import annotations

import argparse
import json

from _common import record, timed_run, warmup

import drivedyn as dd

MASS = 1.0  # [kg]
INERTIA = 1e-3  # [kg m^2], about every axis
SPACING = 0.1  # [m] along global x: the centre distance of two pitch radii
TEETH = 50
MODULE = 2e-3  # [m]: pitch radius TEETH * MODULE / 2 = 0.05 m
FACE_WIDTH = 0.02  # [m] (not used: the stiffness is given)
MESH_STIFFNESS = 1e8  # [N/m]
MESH_DAMPING = 1e3  # [N s/m]
TORQUE = 100.0  # [N m] on gear 1
DAMPER = 1.0  # [N m s/rad] from the last gear to the ground
OUTPUT_DT = 0.01  # [s] sparse recording, so that recording does not dominate

FIXED = dd.FixedStep(1e-4)
INTEGRATOR = dd.GeneralizedAlpha(rho_inf=0.9)


def build_spec(n: int) -> dd.Spec:
    """The row of ``n`` gears; gear ``i`` is body ``gear{i}`` (``gear0`` is driven) and
    ``mesh{i}`` joins gears ``i - 1`` and ``i``."""
    spec = dd.Spec(gravity=(0.0, 0.0, 0.0))
    axis = (0.0, 0.0, 1.0)
    for i in range(n):
        pos = (SPACING * i, 0.0, 0.0)
        spec.add_rigid_body(f"gear{i}", MASS, (INERTIA, INERTIA, INERTIA), position=pos)
        spec.add_marker(f"g{i}", dd.GROUND, position=pos, axis=axis)
        spec.add_marker(f"m{i}", f"gear{i}", axis=axis)
        spec.add(dd.Hinge(f"hinge{i}", f"g{i}", f"m{i}"))
        if i > 0:
            spec.add(dd.GearPair(f"mesh{i}", f"m{i - 1}", f"m{i}", TEETH, TEETH, MODULE,
                                 FACE_WIDTH, stiffness=MESH_STIFFNESS, damping=MESH_DAMPING))
    spec.add(dd.Torque("drive", "m0", vector=(0.0, 0.0, TORQUE)))
    spec.add_marker("g_damper", dd.GROUND, position=(SPACING * (n - 1), 0.0, 0.0), axis=axis)
    spec.add(dd.TorsionalSpringDamper("ground_damper", "g_damper", f"m{n - 1}",
                                      stiffness=0.0, damping=DAMPER))
    return spec


def run(n: int, step: dd.FixedStep, t_end: float) -> dict:
    """Build and simulate the row; return the figures of the run."""
    res, build_s, wall = timed_run(build_spec(n), t_end, integrator=INTEGRATOR, step=step,
                                   output_dt=OUTPUT_DT)
    omega_last = float(res.final(f"gear{n - 1}.angular_velocity")[2])
    out = record(n, step, res, build_s, wall, omega_last)
    out["mesh_torque_first"] = float(res.final("mesh1.torque_a"))
    out["mesh_torque_last"] = float(res.final(f"mesh{n - 1}.torque_b"))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, nargs="+", default=[10, 50, 200],
                        help="numbers of gears (default: 10 50 200)")
    parser.add_argument("--t-end", type=float, default=1.0, help="simulated time [s]")
    args = parser.parse_args()

    # Warm-up: compiles (first run ever) or loads (cached) the numba kernels and the stepping
    # loop at every size (a long chain runs on the sparse LU, whose loop is another
    # compilation), so that the timed runs below measure the simulation only.
    t = warmup(*(lambda n=n: run(n, dd.FixedStep(1e-4), 5e-4) for n in args.n))
    print(json.dumps({"warmup_compile_s": t}), flush=True)

    for n in args.n:
        print(json.dumps(run(n, FIXED, args.t_end)), flush=True)


if __name__ == "__main__":
    main()
