"""Benchmark: a TDR sweep of the TORSEN Type C on Dask, one worker against two.

Eight simulated TDR evaluations (all four locking modes each: two bench runs per point) over
``pockets.mu`` = 0.15 ... 0.19, run by :func:`drivedyn.sweep` on a local cluster of one worker
process, then of two, each started fresh (its start-up is timed apart; the first point on
each worker also loads the numba kernels from the cache). The cache is off, so both runs
compute every point. Then the per-point overhead of the scheduler is measured with points
that cost almost nothing (200 analytic-only TDRs, about 3 ms each): (sweep wall time - the
sum of the points' own wall times) / points, on one worker.

Prints a table and JSON lines: wall time, speed-up (the issue aims at 1.8 on two cores),
parallel efficiency, per-point overhead, peak RSS of the client and of each worker.
Usage::

    python benchmarks/sweep_tdr.py               # 8 points
    python benchmarks/sweep_tdr.py --points 4
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import resource
import time

import numpy as np


def _peak_rss_mb() -> float:
    return round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1)


def run(points: int, workers: int) -> dict:
    from distributed import Client, LocalCluster

    import drivedyn as dd

    t0 = time.perf_counter()
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                           dashboard_address=":0", silence_logs=logging.ERROR)
    client = Client(cluster)
    client.run(lambda: __import__("drivedyn.sweeps.evaluate"))  # imports, not kernels
    startup = time.perf_counter() - t0
    try:
        t0 = time.perf_counter()
        ds = dd.sweep("torsen-c", [f"pockets.mu=0.15:0.19:{points}"], tdr=True,
                      client=client)
        wall = time.perf_counter() - t0
        worker_rss = client.run(_peak_rss_mb)
    finally:
        client.close()
        cluster.close()
    status = ds["status"].values.tolist()
    return {"workers": workers, "points": points, "wall_s": round(wall, 2),
            "cluster_startup_s": round(startup, 2),
            "point_wall_s_mean": round(float(ds["wall_s"].mean()), 2),
            "steps": int(ds["steps"].sum()),
            "newton_iterations": int(ds["newton_iterations"].sum()),
            "rejected_steps": int(ds["rejected_steps"].sum()),
            "ok": status.count("ok"),
            "tdr_mode1": [round(float(x), 6) for x in ds["tdr.mode1"].values],
            "peak_rss_mb_client": _peak_rss_mb(),
            "peak_rss_mb_workers": sorted(worker_rss.values())}


def overhead(n: int = 200) -> dict:
    from distributed import Client, LocalCluster

    import drivedyn as dd

    cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                           dashboard_address=":0", silence_logs=logging.ERROR)
    client = Client(cluster)
    try:
        dd.sweep("torsen-c", ["pockets.mu=0.15:0.19:4"], tdr=True, analytic_only=True,
                 client=client)  # warm the worker
        t0 = time.perf_counter()
        ds = dd.sweep("torsen-c", [f"pockets.mu=0.15:0.19:{n}"], tdr=True,
                      analytic_only=True, client=client)
        wall = time.perf_counter() - t0
    finally:
        client.close()
        cluster.close()
    own = float(ds["wall_s"].sum())
    return {"overhead_points": n, "wall_s": round(wall, 3), "points_own_s": round(own, 3),
            "overhead_ms_per_point": round(1e3 * (wall - own) / n, 2)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--points", type=int, default=8)
    args = ap.parse_args()
    print(f"CPUs: {os.cpu_count()}")
    one = run(args.points, 1)
    print(json.dumps(one))
    two = run(args.points, 2)
    print(json.dumps(two))
    same = np.array_equal(one["tdr_mode1"], two["tdr_mode1"])
    speedup = one["wall_s"] / two["wall_s"]
    ov = overhead()
    print(json.dumps(ov))
    summary = {"speedup": round(speedup, 3), "efficiency": round(speedup / 2, 3),
               "identical_results": bool(same), **{k: ov[k] for k in
                                                   ("overhead_ms_per_point",)}}
    print(json.dumps(summary))
    print(f"\n{args.points} Type C TDR points (4 modes each)")
    print("workers  wall [s]  start-up [s]  mean point [s]  peak RSS client/workers [MB]")
    for r in (one, two):
        print(f"{r['workers']:>7}  {r['wall_s']:>8.1f}  {r['cluster_startup_s']:>12.1f}  "
              f"{r['point_wall_s_mean']:>14.2f}  {r['peak_rss_mb_client']:.0f} / "
              f"{', '.join(f'{x:.0f}' for x in r['peak_rss_mb_workers'])}")
    print(f"speed-up {speedup:.2f} (efficiency {speedup / 2:.0%}); results identical: {same}; "
          f"scheduler overhead {ov['overhead_ms_per_point']:.1f} ms per point")


if __name__ == "__main__":
    main()
