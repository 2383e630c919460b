"""Cold start: the first ``drivedyn tdr torsen-c --mode all`` after an install.

Runs the command in a new process with ``NUMBA_CACHE_DIR`` pointing to an empty folder, so
every kernel it needs is compiled as after a fresh install (the package's own cache next to
the sources is neither read nor touched), then once more with the same folder (warm: every
kernel loaded from the cache), then ``drivedyn --help``. Prints, per run, the wall time, the
CPU time of the process and its children (the first run compiles in worker processes, see
``drivedyn.solver.precompile``) and the peak RSS of the largest process, then one JSON line.

Usage::

    python benchmarks/cold_start.py             # torsen-c, all four modes
    python benchmarks/cold_start.py torsen-b
    python benchmarks/cold_start.py --repeat 2  # two cold runs, each in a new empty cache
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time


def _run(args: list[str], cache: str) -> dict:
    """Run ``python -m drivedyn.cli <args>`` with the numba cache in ``cache``."""
    # drivedyn's own cache (its record of compiled kernels) beside numba's, so a cold run
    # finds neither
    env = {**os.environ, "NUMBA_CACHE_DIR": cache,
           "DRIVEDYN_CACHE": os.path.join(cache, "drivedyn")}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "drivedyn.cli", *args], env=env,
                          capture_output=True, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise SystemExit(f"drivedyn {' '.join(args)} failed ({proc.returncode}):\n"
                         f"{proc.stderr[-2000:]}")
    return {"wall_s": round(wall, 2),
            "cpu_s": round(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, 1),
            # ru_maxrss of children: the largest child process so far [kB]
            "peak_rss_mb": round(after.ru_maxrss / 1024, 1)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("model", nargs="?", default="torsen-c")
    ap.add_argument("--repeat", type=int, default=1, help="cold runs (each with a new cache)")
    a = ap.parse_args()
    cmd = ["tdr", a.model, "--mode", "all"]
    out: dict = {"benchmark": "cold_start", "command": "drivedyn " + " ".join(cmd),
                 "cold": [], "warm": None}
    for _ in range(a.repeat):
        with tempfile.TemporaryDirectory(prefix="drivedyn-cold-") as cache:
            cold = _run(cmd, cache)
            out["cold"].append(cold)
            print(f"cold {out['command']}: {cold['wall_s']:.1f} s wall, {cold['cpu_s']:.1f} s "
                  f"CPU (workers included), peak RSS {cold['peak_rss_mb']:.0f} MB", flush=True)
            if out["warm"] is None:
                warm = _run(cmd, cache)
                out["warm"] = warm
                print(f"warm {out['command']}: {warm['wall_s']:.1f} s wall, {warm['cpu_s']:.1f} "
                      f"s CPU", flush=True)
    with tempfile.TemporaryDirectory(prefix="drivedyn-cold-") as cache:
        out["help"] = _run(["--help"], cache)
    print(f"drivedyn --help: {out['help']['wall_s']:.2f} s wall")
    print(json.dumps(out))


if __name__ == "__main__":
    main()
