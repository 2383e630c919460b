"""Validation of the TORSEN Type C model against seed 003 (Table 1) and the analytic model.

The full seed protocol runs in both the quick and the full validation (two bench runs of
3 s simulated time, about 10 s with cached kernels): the TDR is a steady-state quantity and a
shorter protocol would not be a cheaper check of the same thing.
"""

from __future__ import annotations

import time

import numpy as np

from drivedyn.validation.base import CaseResult, compare, register_case


@register_case("torsen_c_tdr")
def torsen_c_tdr(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """TORSEN Type C on the test bench (seed 003 protocol): TDR of the four locking modes
    against the measurements (goal 3 %), their order as measured, against the analytic
    quasi-static model (2 %), and the torque balance of the bench.

    A mode the calibration states it misses (its recorded simulated TDR more than 3 % off
    the measurement, ``[calibration] result``) is reported as a GAP, not a check: with one
    in-range friction coefficient the model locks mode 1 12.5 % less and modes 2 and 4 8 %
    more than measured (docs/torsen_c.md). The gating checks catch: an analytic/simulator
    disagreement in a shared mechanism (the tooth-friction couples raise the TDRs by 4.6-5.8
    %, the planets' end faces by 2.8-3.3 % and the spline's friction lowers them by 2.8-7.0
    %, so any of them left out of one model fails the 2 %; seen, with the former
    calibration: the end faces' friction missing from the analytic moment equation put the
    simulation 3.7 % above it in mode 1: 3.724 against 3.590), a bench that leaks torque
    (balance), and a differential that does not lock as measured (order of the modes: an
    open differential ties modes 1 and 2, a tie counts as out of order)."""
    from drivedyn.analysis.tdr import experimental, mode_name, run_bench, side_modes
    from drivedyn.analysis.tdr import seeds_simulation as seeds_of
    from drivedyn.config import read_library_file
    from drivedyn.library.differentials.torsen_c import analytic as at
    from drivedyn.validation.common import failed_check, finish_case, save_figure

    t0 = time.perf_counter()
    case = "torsen_c_tdr"
    p, _, _ = read_library_file("torsen-c")
    exp = experimental(p)
    seeds = seeds_of(p)
    out: list[CaseResult] = []
    runs = {}
    sim: dict[int, float] = {}
    for side, modes in side_modes(p).items():
        run = run_bench(p, side)
        runs[side] = run
        if not run.success:
            for m in modes:
                out.append(failed_check(case, f"mode {m} TDR", "1", 0.03, "seed 003", run.results))
            continue
        sim.update(run.tdr)
        res = run.results
        t = res["time"].values
        # torque balance of the held differential: applied + resistant + housing = 0
        win = p.bench.window_drive
        k = (t >= win[0]) & (t <= win[1])
        ta = res["applied_torque.torque_z"].values[k].mean()
        tr = res["speed_control.torque"].values[k].mean()
        th = res["hold_housing.torque"].values[k].mean()
        out.append(compare(case, f"bench torque balance, {side} side (sum / applied torque)",
                           0.0, float((ta + tr + th) / abs(ta)), "1", 4e-5,
                           "moment balance of the whole differential at steady speed (the "
                           "mesh-stiffness ripple and the axial ripple on the elastic "
                           "washers leave a window-mean inertia torque, "
                           "measured 1.9e-5 rear; 4.6e-6 with the former Hertz washers)"))
    for m in sorted(sim):
        e = exp.get(m)
        s = seeds.get(m)
        if e:
            seed_txt = f"; the seeds' simulation {s} ({100 * (s / e - 1):+.2f} %)" if s else ""
            beside = f" [seeds' simulation {s}]" if s else ""
            row = compare(case, f"mode {m} TDR ({mode_name(p, m)}) vs measured{beside}", e,
                          sim[m], "1", 0.03, f"seed 003 Table 1, test bench (one friction "
                          f"number fitted to the four modes){seed_txt}")
            row.gap = calibration_gap(p, m, e, 0.03)
            out.append(row)
        ana = at.bench_tdr(p, m)
        out.append(compare(case, f"mode {m} TDR vs analytic quasi-static", ana, sim[m], "1",
                           0.02, "drivedyn.library.differentials.torsen_c.analytic (equilibrium of "
                           "each part)"))
    if len(sim) == 4 and len(exp) == 4:
        out.append(compare(case, "order of the four modes' TDRs as measured (pairs out of "
                           "order)", 0.0, order_mismatches(sim, exp), "1", 0.0,
                           "seed 003 Table 1: mode 1 > mode 2 > mode 4 > mode 3"))
    figures: list[str] = []
    if sim:
        def bars(fig):
            ax = fig.add_subplot(111)
            ms = sorted(sim)
            x = np.arange(len(ms))
            for i, (lab, vals) in enumerate((
                    ("simulated", [sim[m] for m in ms]),
                    ("analytic", [at.bench_tdr(p, m) for m in ms]),
                    ("measured (seed 003)", [exp.get(m, np.nan) for m in ms]),
                    ("seeds' simulation", [seeds.get(m, np.nan) for m in ms]))):
                ax.bar(x + (i - 1.5) * 0.2, vals, 0.2, label=lab)
            ax.set_xticks(x, [f"mode {m}\n{mode_name(p, m)}" for m in ms])
            ax.set_ylabel("TDR [-]")
            ax.set_title("TORSEN Type C: torque distribution ratio on the test bench")
            ax.legend()

        figures += save_figure(figure_dir, "torsen_c_tdr", bars)
        if "rear" in runs and runs["rear"].success:
            res = runs["rear"].results

            def history(fig):
                ax = fig.add_subplot(111)
                t = res["time"].values
                ax.plot(t, res["applied_torque.torque_z"].values, label="applied (coupling)")
                ax.plot(t, res["speed_control.torque"].values, label="resistant (sun)")
                for w in (p.bench.window_drive, p.bench.window_coast):
                    ax.axvspan(*w, color="0.9")
                ax.set_xlabel("time [s]")
                ax.set_ylabel("torque [N m]")
                ax.set_title("Type C bench, drive then coast to rear (seed 003, Fig. 8)")
                ax.legend()

            figures += save_figure(figure_dir, "torsen_c_bench_rear", history)
    return finish_case(out, t0, figures)


def calibration_gap(p, mode: int, measured: float, goal: float) -> str:
    """The documented gap of ``mode``: non-empty when the file's calibration record states a
    simulated TDR more than ``goal`` (relative) off the measurement."""
    rec = p.calibration.result.get(f"mode{mode}_simulated")
    if rec is None or abs(rec / measured - 1) <= goal:
        return ""
    return (f"the calibration ({p.calibration.command}) states {100 * (rec / measured - 1):+.1f} "
            "% with in-range friction: a mechanism or datum the model lacks, see the model's "
            "docs ('What the calibration can claim')")


def order_mismatches(sim: dict[int, float], ref: dict[int, float]) -> float:
    """Pairs of modes whose TDRs are ordered differently (a tie counts as out of order)."""
    ms = sorted(ref)
    return float(sum(np.sign(sim[a] - sim[b]) != np.sign(ref[a] - ref[b])
                     for i, a in enumerate(ms) for b in ms[i + 1:]))
