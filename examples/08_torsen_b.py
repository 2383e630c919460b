"""Example 08: the TORSEN Type B front/rear differential on the test bench and in the vehicle
(seed 003, Figure 3, Table 2 and Fig. 13).

The shipped parametric model ``torsen-b`` (two helical side gears, five pairs of element gears
in housing pockets, 20 meshes, three thrust washers) runs on the seed 003 bench protocol: the
housing held, a torque on one side gear, the other side gear's speed prescribed, drive then
coast. The script prints the TDR of the four locking modes next to the independent
quasi-static model (:mod:`drivedyn.library.differentials.torsen_b.analytic`) and the
measurements of Table 2:

    mode 1  drive, bias right     mode 2  coast, bias right
    mode 3  drive, bias left      mode 4  coast, bias left

With ``--vehicle`` it then runs the vehicle configuration (torque on the housing, both side
gears' speeds prescribed, the modes forwards, then the speeds reversed and the modes
backwards) and writes its figures to ``out_dir`` (default ``torsen_b``).

Run it with::

    python examples/08_torsen_b.py [out_dir] [--full] [--vehicle] [--set KEY=VALUE ...]

By default a shorter bench protocol runs (the same torque and speed difference, 1.1 s per
side instead of 3 s: the TDR is a steady-state quantity reached within 0.1 s); ``--full``
runs the seed protocol of the file.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from drivedyn.analysis.tdr import experimental, mode_name, run_bench, side_modes
from drivedyn.analysis.vehicle import run_vehicle
from drivedyn.config import read_library_file
from drivedyn.library.differentials.torsen_b import analytic
from drivedyn.plots import vehicle_figures

SHORT = ["bench.ramp=0.1", "bench.transition=[0.5, 0.8]", "bench.t_end=1.1",
         "bench.window_drive=[0.25, 0.45]", "bench.window_coast=[0.9, 1.1]"]


def parse(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out_dir", nargs="?", default="torsen_b", type=Path,
                    help="folder for the vehicle figures")
    ap.add_argument("--full", action="store_true", help="the file's seed bench protocol")
    ap.add_argument("--vehicle", action="store_true",
                    help="also run the vehicle configuration (forwards and backwards)")
    ap.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                    help="override a key of the model file (repeatable)")
    return ap.parse_args(argv)


def main(argv: list[str] | None = None) -> dict:
    args = parse(argv)
    p, _, _ = read_library_file("torsen-b", ([] if args.full else SHORT) + args.sets)
    exp = experimental(p)
    t0 = time.perf_counter()
    sim: dict[int, float] = {}
    for side in side_modes(p):
        run = run_bench(p, side)
        if not run.success:
            raise SystemExit(f"bench ({side}) failed: {run.message}")
        sim.update(run.tdr)
    print(f"TORSEN Type B on the bench ({p.bench.torque:g} N m), "
          f"{time.perf_counter() - t0:.1f} s wall")
    print("mode  name                simulated  analytic  measured  error")
    for m in sorted(sim):
        ana = analytic.bench_tdr(p, m)
        print(f"  {m}   {mode_name(p, m):18s}  {sim[m]:9.4f}  {ana:8.4f}  {exp[m]:8.2f}  "
              f"{100 * (sim[m] / exp[m] - 1):+6.2f} %")
    out = {"tdr": sim}
    if args.vehicle:
        run = run_vehicle(p)
        print(f"vehicle configuration: {run.wall_s:.1f} s wall, success {run.success}")
        for lv in run.levels:
            if lv["mode"]:
                print(f"  {lv['direction']:8s} {lv['housing']:+8.1f} N m  mode {lv['mode']}  "
                      f"TDR {lv['tdr']:.4f} (analytic {lv['tdr_analytic']:.4f})  balance "
                      f"{lv['balance_error']:.1e}")
        paths = vehicle_figures(run, args.out_dir)
        print("figures:", ", ".join(str(x) for x in paths))
        out["levels"] = run.levels
    return out


if __name__ == "__main__":
    main()
