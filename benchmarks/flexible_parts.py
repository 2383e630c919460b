"""Benchmark: the TORSEN Type C bench with flexible parts next to the rigid model.

Runs ``benchmarks/torsen_c_bench.py`` (the four locking modes on the seed 003 bench
protocol) in a fresh process for each configuration, so that every peak memory figure is its
own: the rigid model, five flexible washers (``flexible.washers``: contact at the points of
the face quadrature, the default, and at every face node, ``face_quadrature = "nodes"``), and
flexible washers with the flexible case (``flexible.case``). Then times the Craig-Bampton
reduction of the parts cold (empty cache) and warm (loaded from the disk cache).

Prints one line per configuration (total wall time of both bench runs, build included,
steps, Newton iterations, LU factorizations, peak RSS, the TDR of the four modes and their
difference from the rigid model) and a JSON line with all of it.

Usage::

    python benchmarks/flexible_parts.py
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).parent
CONFIGS = {
    "rigid": [],
    "flexible washers": ["flexible.washers=true"],
    "flexible washers, face nodes": ["flexible.washers=true",
                                     'flexible.face_quadrature="nodes"'],
    "flexible washers + case": ["flexible.washers=true", "flexible.case=true"],
}


def bench(overrides: list[str]) -> dict:
    cmd = [sys.executable, str(HERE / "torsen_c_bench.py")]
    for o in overrides:
        cmd += ["--set", o]
    out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def reduction_times() -> dict:
    """Cold and warm reduction of the five washers and the case [s]."""
    code = (
        "import time; from drivedyn.config import read_library_file;"
        "from drivedyn.library.differentials.torsen_c.model import WASHERS, build_spec;"
        "from drivedyn.library.differentials.flexible_washers import washer_part;"
        "p, _, _ = read_library_file('torsen-c', ['flexible.washers=true', "
        "'flexible.case=true']);"
        "t = time.perf_counter(); [washer_part(p.flexible, w, getattr(p.washers, w).r_int, "
        "getattr(p.washers, w).r_ext) for w in WASHERS];"
        "tw = time.perf_counter() - t; t = time.perf_counter(); build_spec(p);"
        "print(tw, time.perf_counter() - t)"
    )
    out = {}
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, DRIVEDYN_CACHE=cache)
        for label in ("cold", "warm"):
            t0 = time.perf_counter()
            r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                               check=True, env=env).stdout.split()
            out[label] = {"washers_s": round(float(r[0]), 3),
                          "build_spec_s": round(float(r[1]), 3),
                          "process_s": round(time.perf_counter() - t0, 3)}
    return out


def main() -> None:
    results = {}
    for label, overrides in CONFIGS.items():
        r = bench(overrides)
        results[label] = r
        rigid = results["rigid"]["modes"]
        steps = sum(x["steps"] for x in r["runs"])
        its = sum(x["newton_iterations"] for x in r["runs"])
        lu = sum(x["factorizations"] for x in r["runs"])
        tdr = {m: v["tdr_sim"] for m, v in r["modes"].items()}
        diff = {m: round(100 * (tdr[m] / rigid[m]["tdr_sim"] - 1), 3) for m in tdr}
        print(f"{label:<26} wall {r['total_wall_s']:7.2f} s  steps {steps:6d}  Newton "
              f"{its:6d}  LU {lu:5d}  peak RSS {r['peak_rss_mb']:7.1f} MB  TDR "
              + " ".join(f"{tdr[m]:.4f} ({diff[m]:+.2f} %)" for m in sorted(tdr)), flush=True)
    red = reduction_times()
    print(f"reduction of the five washers: cold {red['cold']['washers_s']:.2f} s, warm "
          f"{red['warm']['washers_s']:.3f} s; build of the spec with washers and case: cold "
          f"{red['cold']['build_spec_s']:.2f} s, warm {red['warm']['build_spec_s']:.3f} s")
    print(json.dumps({"benchmark": "flexible_parts", "configs": results, "reduction": red}))


if __name__ == "__main__":
    main()
