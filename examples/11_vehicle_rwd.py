"""Example 11: the rear-wheel-drive vehicle (flexible ladder frame, double wishbones on
bushings, Magic Formula tyres, rear differential by name) at rest and pulling away on
split-mu.

The shipped parametric model ``vehicle-rwd`` (Project Chrono's HMMWV data): the script
solves the parked vehicle's static equilibrium (mass, centre of gravity, wheel loads and
their checks), then runs the launch with each rear differential asked for (the left rear
wheel on ice), prints the window-mean rear wheel torques and the checks, and plots the rear
wheel torques over time to ``out_dir`` (default ``vehicle_rwd``).

Run it with::

    python examples/11_vehicle_rwd.py [out_dir] [--full] [--configs open,locked,torsen-b]
                                      [--set KEY=VALUE ...]

By default only the open differential runs 0.8 s of the launch (about 10 s); ``--full``
runs the file's 3 s (from half a minute for ``open`` to four minutes for ``torsen-b``).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import drivedyn.analysis.vehicle_rwd as V  # noqa: N812
from drivedyn.config import read_library_file
from drivedyn.config.loader import read_vehicle_differentials, resolve_path

SHORT = ["run.t_end=0.8", "run.window=[0.5, 0.8]", 'engine.ramp="0.2 s"']


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out_dir", nargs="?", default="vehicle_rwd", type=Path)
    ap.add_argument("--full", action="store_true", help="the file's 3 s launch")
    ap.add_argument("--configs", default="open")
    ap.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE")
    a = ap.parse_args(argv)
    p, _, source = read_library_file("vehicle-rwd", ([] if a.full else SHORT) + a.sets)
    base = resolve_path("vehicle-rwd").parent
    configs = a.configs.split(",")
    torsen = {}
    for c in configs:
        torsen.update(read_vehicle_differentials(V.configure(p, c), source, base))
    st = V.static(V.configure(p, "open"), torsen, base)
    print(f"mass {st.mass:.2f} kg, cg {', '.join(f'{c:.4f}' for c in st.cg)} m")
    print("static wheel loads [N]: " + ", ".join(f"{w} {f:.1f}" for w, f in st.loads.items()))
    ok = True
    for name, value, limit, passed in V.static_checks(st):
        ok &= passed
        print(f"  {'ok  ' if passed else 'FAIL'} {name}: {value:.3g} (limit {limit:.3g})")
    t0 = time.perf_counter()
    runs = V.compare(p, torsen, configs, base)
    summaries = [s for s, _ in runs]
    print(f"\nlaunch: window {p.run.window[0]:g}-{p.run.window[1]:g} s, "
          f"wall {time.perf_counter() - t0:.0f} s")
    print(V.table(summaries))
    for s in summaries:
        for name, value, limit, passed in V.checks(s):
            ok &= passed
            print(f"  {'ok  ' if passed else 'FAIL'} {name}: {value:.4g} (limit {limit:.4g})")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4.5))
    for s in summaries:
        h = s.history
        line, = ax.plot(h["time"], h["torque_rr"], label=f"{s.name}: rear right (dry)")
        ax.plot(h["time"], h["torque_rl"], "--", color=line.get_color(),
                label=f"{s.name}: rear left (ice)")
    ax.axvspan(*p.run.window, color="0.9")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("drive torque [N m]")
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    a.out_dir.mkdir(parents=True, exist_ok=True)
    fig.savefig(a.out_dir / "rear_torques.png", dpi=120, bbox_inches="tight")
    print(f"figure: {a.out_dir / 'rear_torques.png'}")
    return {"passed": ok, "static": st, "summaries": summaries}


if __name__ == "__main__":
    raise SystemExit(0 if main()["passed"] else 1)
