"""Example 10: sweeps on Dask: a TDR map of the TORSEN Type C, a tolerance study and the
sensitivities of its four locking modes to each friction coefficient.

``drivedyn.sweep`` runs each point of a grid, of a Monte Carlo sample or of a
finite-difference stencil as an independent run on a Dask cluster (here a local cluster of
two worker processes, made by the script as a notebook user would) and returns one xarray
Dataset with a dimension per varied key. By default the points use the analytic
quasi-static TDR (milliseconds each) so that the script runs in seconds; ``--simulate``
computes them on the simulated bench (about 13 s per point of four modes, the numbers of
docs/sweeps.md). Figures go to ``out_dir`` (default ``sweeps``); finished points are cached
there, so a second run reads them back.

Run it with::

    python examples/10_sweeps.py [out_dir] [--simulate] [--workers 2]
"""

from __future__ import annotations

import argparse
import logging
import time
from pathlib import Path

import numpy as np
from distributed import Client, LocalCluster

import drivedyn as dd
from drivedyn.plots.sweeps import plot_sweep

FRICTIONS = ["pockets.mu", "washers.sun_housing.mu", "washers.sun_coupling.mu",
             "washers.coupling_case.mu", "washers.ring_housing.mu", "washers.ring_case.mu"]


def main(out_dir: str = "sweeps", simulate: bool = False, workers: int = 2) -> dict:
    out = Path(out_dir)
    analytic = not simulate
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, dashboard_address=":0",
                           silence_logs=logging.ERROR)
    client = Client(cluster)  # sweeps use the client made here, like in a notebook
    t0 = time.perf_counter()
    try:
        # 1. a map: TDR over the pocket friction and the ring gear's case washer
        tdr_map = dd.sweep("torsen-c", {"pockets.mu": "0.15:0.19:5",
                                        "washers.ring_case.mu": "0.15:0.22:4"},
                           tdr=True, analytic_only=analytic, cache=out / "map.cache")
        # 2. a tolerance study: 5 % scatter (one sd) on three coefficients
        tol = dd.sweep("torsen-c", sample={"pockets.mu": "normal(0.173,0.0087)",
                                           "washers.ring_case.mu": "normal(0.185,0.0092)",
                                           "washers.sun_housing.mu": "normal(0.30,0.015)"},
                       samples=200 if analytic else 32, seed=1, tdr=True,
                       analytic_only=analytic, cache=out / "tolerance.cache")
        # 3. sensitivities of each mode to every friction coefficient (central differences)
        sens = dd.sweep("torsen-c", sensitivity_keys=FRICTIONS, tdr=True,
                        analytic_only=analytic, cache=out / "sensitivity.cache")
    finally:
        client.close()
        cluster.close()
    wall = time.perf_counter() - t0
    figures = [p for ds in (tdr_map, tol, sens) for p in plot_sweep(ds, out)]

    print("TDR mode 1 over pockets.mu (rows) and washers.ring_case.mu (columns):")
    print(np.array2string(tdr_map["tdr.mode1"].values, precision=3))
    print("\ntolerance study (5 % friction scatter): TDR mean, sd, 5-95 % band")
    for m in (1, 2, 3, 4):
        q = tol[f"quantiles.tdr.mode{m}"].values
        print(f"  mode {m}: {float(tol[f'mean.tdr.mode{m}']):.3f} "
              f"sd {float(tol[f'std.tdr.mode{m}']):.3f}  [{q[0]:.3f}, {q[-1]:.3f}]")
    print("\nelasticities (relative TDR change per relative friction change):")
    print(f"  {'':26s}" + "".join(f"mode {m:<4d}" for m in (1, 2, 3, 4)))
    for i, key in enumerate(sens["parameter"].values):
        print(f"  {key:26s}" + "".join(f"{sens[f'elasticity.tdr.mode{m}'].values[i]:<9.3f}"
                                       for m in (1, 2, 3, 4)))
    print(f"\n{wall:.1f} s on {workers} workers; figures: "
          + ", ".join(str(f) for f in figures))
    return {"map": tdr_map, "tolerance": tol, "sensitivity": sens, "figures": figures}


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out_dir", nargs="?", default="sweeps")
    ap.add_argument("--simulate", action="store_true")
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args()
    main(a.out_dir, a.simulate, a.workers)
