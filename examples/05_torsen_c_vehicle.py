"""Example 05: the TORSEN Type C central differential in the vehicle (seed 003, Fig. 10-11).

The shipped parametric model ``torsen-c`` is loaded and run in its vehicle configuration: the
engine torque acts on the housing and steps through the levels of ``[vehicle]``
(``torque_levels``, intermediate levels and sign reversals), while both output speeds are
prescribed (front = sun, rear = coupling; the rear turns 2 rad/s slower in the first half,
2 rad/s faster in the second). So the differential passes through its four locking modes:

    mode 1  drive, rear slower  (bias rear)     mode 2  coast, rear faster  (bias rear)
    mode 3  drive, front slower (bias front)    mode 4  coast, front faster (bias front)

For each held level the script prints the window means of the housing torque and the two
output torques delivered to the axles (front + rear = housing), the mode, and the torque
distribution ratio (favoured axle over the other) next to the quasi-static analytic value
of :mod:`drivedyn.library.differentials.torsen_c.analytic` at the same speeds; at each
torque reversal, the
axial travel of sun, coupling and internal gear (sun and coupling move together, the gear
the other way). Figures (PNG) go to ``out_dir`` (default ``torsen_c_vehicle``).

Run it with::

    python examples/05_torsen_c_vehicle.py [out_dir] [--full] [--set KEY=VALUE ...]

By default a short version of the profile runs (about 15 s once the numba kernels are
compiled): the same levels, zero-torque holds included, held 0.12 s with 0.05 s ramps.
``--full`` runs the shipped profile as it is (15 levels, 0.6 s holds, 0.25 s ramps; see the
README for its wall time). ``--set`` overrides any key of the model file, e.g.
``--set vehicle.hold=0.3``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from drivedyn.analysis.vehicle import reversals, run_vehicle
from drivedyn.config import read_library_file
from drivedyn.plots import vehicle_figures

QUICK_HOLD = 0.12  # [s]
QUICK_RAMP = 0.05  # [s]


def quick_overrides(params) -> list[str]:
    """The shipped profile with short holds and ramps."""
    return [f"vehicle.hold={QUICK_HOLD}", f"vehicle.ramp={QUICK_RAMP}"]


def parse(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out_dir", nargs="?", default="torsen_c_vehicle", type=Path,
                    help="folder for the figures")
    ap.add_argument("--full", action="store_true", help="run the shipped profile as it is")
    ap.add_argument("--set", dest="overrides", action="append", default=[],
                    metavar="KEY=VALUE", help="override a key of the model file")
    return ap.parse_args(argv)


def print_levels(levels: list[dict]) -> None:
    print(f"{'level':>5} {'t [s]':>11} {'housing':>8} {'front':>8} {'rear':>8} {'mode':>4}  "
          f"{'TDR sim':>8} {'analytic':>8} {'diff':>7} {'balance':>8}")
    for lv in levels:
        mode = f"{lv['mode']}" if lv["mode"] else "-"
        tdr = f"{lv['tdr']:8.3f}" if lv["tdr"] is not None else f"{'-':>8}"
        tda = f"{lv['tdr_analytic']:8.3f}" if lv["tdr_analytic"] is not None else f"{'-':>8}"
        err = f"{lv['tdr_error'] * 100:+6.2f}%" if lv["tdr_error"] is not None else f"{'-':>7}"
        bal = f"{lv['balance_error']:8.1e}" if lv["balance_error"] is not None else f"{'-':>8}"
        print(f"{lv['level']:5d} {lv['t0']:5.2f}-{lv['t1']:5.2f} {lv['housing']:8.2f} "
              f"{lv['front']:8.2f} {lv['rear']:8.2f} {mode:>4}  {tdr} {tda} {err} {bal}")
    print("(torques in N m, window means over the last 60 % of each hold; output torques "
          "as delivered to the axles; TDR = favoured axle / other axle; balance = "
          "|T_h - (T_f + T_r)| / |T_h|)")


def print_reversals(rev: list[dict]) -> None:
    print("\naxial travel at the torque reversals [um] (front = -z):")
    for r in rev:
        print(f"  level {r['from_level']} -> {r['to_level']} ({r['from_torque']:+.0f} -> "
              f"{r['to_torque']:+.0f} N m): sun {r['d_sun'] * 1e6:+7.1f}, coupling "
              f"{r['d_coupling'] * 1e6:+7.1f}, internal gear {r['d_ring'] * 1e6:+7.1f}")


def main(argv: list[str] | None = None) -> dict:
    """Run, print and plot; returns the levels, reversals and run figures."""
    args = parse(argv)
    params = read_library_file("torsen-c")[0]
    overrides = ([] if args.full else quick_overrides(params)) + args.overrides
    params = read_library_file("torsen-c", overrides)[0]
    v = params.vehicle
    print(f"TORSEN C, vehicle configuration: {len(v.torque_levels)} levels, hold {v.hold} s, "
          f"ramp {v.ramp} s ({'shipped profile' if args.full else 'short profile'})")
    t0 = time.perf_counter()
    run = run_vehicle(params)
    st = run.results.stats
    print(f"run: {'ok' if run.success else 'FAILED: ' + run.message}; "
          f"{time.perf_counter() - t0:.1f} s wall, {st.steps} steps ({st.rejected} rejected), "
          f"{st.newton_iterations} Newton iterations\n")
    print_levels(run.levels)
    rev = reversals(run.levels, run.results)
    print_reversals(rev)
    paths = vehicle_figures(run, args.out_dir)
    print("\nfigures: " + ", ".join(str(p) for p in paths))
    if not run.success:
        raise SystemExit(1)
    return {"levels": run.levels, "reversals": rev, "wall_s": run.wall_s, "figures": paths}


if __name__ == "__main__":
    main(sys.argv[1:])
