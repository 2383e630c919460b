"""Validation of the TORSEN Type B model against seed 003 (Table 2), its independent analytic
model and the identities of the differential: bench TDR of the four modes, left/right
symmetry, and the vehicle configuration with backwards motion (torque balance, backward TDR
equal to forward)."""

from __future__ import annotations

import time

import numpy as np

from drivedyn.validation.base import CaseResult, compare, register_case


@register_case("torsen_b_bench")
def torsen_b_bench(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """TORSEN Type B on the test bench (seed 003 protocol): TDR of the four modes against the
    measurements (3 %), against the analytic quasi-static model (1 %), the mirror symmetry
    (mode 1 = mode 3, mode 2 = mode 4, 0.5 %) and the torque balance of the bench.

    Errors it catches: a simulator/analytic disagreement in a mechanism the two models share
    (seen: the element gears' tooth-friction couple with the wrong sign in the analytic
    moment equations puts the simulated TDRs 17-19.5 % above it), and a calibration that no
    longer matches Table 2 (the fitted coefficient moved by 10 %, 0.1086 to 0.1195, moves
    the analytic mode 1 from 1.632 to 1.701: 6.3 % off the measurement)."""
    from drivedyn.analysis.tdr import experimental, mode_name, run_bench, side_modes
    from drivedyn.analysis.tdr import seeds_simulation as seeds_of
    from drivedyn.config import read_library_file
    from drivedyn.library.differentials.torsen_b import analytic as at
    from drivedyn.validation.common import failed_check, finish_case, save_figure

    t0 = time.perf_counter()
    case = "torsen_b_bench"
    p, _, _ = read_library_file("torsen-b")
    exp, seeds = experimental(p), seeds_of(p)
    out: list[CaseResult] = []
    sim: dict[int, float] = {}
    runs = {}
    for side, modes in side_modes(p).items():
        run = run_bench(p, side)
        runs[side] = run
        if not run.success:
            for m in modes:
                out.append(failed_check(case, f"mode {m} TDR", "1", 0.03, "seed 003",
                                        run.results))
            continue
        sim.update(run.tdr)
        res = run.results
        t = res["time"].values
        win = p.bench.window_drive
        k = (t >= win[0]) & (t <= win[1])
        ta = res["applied_torque.torque_z"].values[k].mean()
        tr = res["speed_control.torque"].values[k].mean()
        th = res["hold_housing.torque"].values[k].mean()
        out.append(compare(case, f"bench torque balance, {side} side (sum / applied torque)",
                           0.0, float((ta + tr + th) / abs(ta)), "1", 1e-5,
                           "moment balance of the whole differential at steady speed (the "
                           "mesh-stiffness ripple leaves a window-mean inertia torque)"))
    for m in sorted(sim):
        e, s = exp.get(m), seeds.get(m)
        if e:
            beside = f" [seeds' simulation {s}]" if s else ""
            out.append(compare(case, f"mode {m} TDR ({mode_name(p, m)}) vs measured{beside}",
                               e, sim[m], "1", 0.03, "seed 003 Table 2, test bench; one "
                               "friction coefficient (washers and pockets) fitted to the four "
                               "modes"))
        out.append(compare(case, f"mode {m} TDR vs analytic quasi-static",
                           at.bench_tdr(p, m), sim[m], "1", 0.01,
                           "drivedyn.library.differentials.torsen_b.analytic"))
    for a, b in ((1, 3), (2, 4)):
        if a in sim and b in sim:
            out.append(compare(case, f"mirror symmetry: mode {b} TDR vs mode {a}", sim[a],
                               sim[b], "1", 0.005, "left/right mirror-image geometry"))
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
            ax.set_ylim(1.0, None)
            ax.set_title("TORSEN Type B: torque distribution ratio on the test bench")
            ax.legend()

        figures += save_figure(figure_dir, "torsen_b_tdr", bars)
    return finish_case(out, t0, figures)


@register_case("torsen_b_vehicle")
def torsen_b_vehicle(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """TORSEN Type B in vehicle configuration (seed 003 Fig. 13): torque on the housing, both
    side-gear speeds prescribed, the four modes forward, then the speeds reversed and the same
    torques in backwards motion (each favours the other side). Output torques sum to the
    housing torque (0.5 %) in every window, each backward TDR equals the forward TDR of the
    same torque level (1 %), and every TDR the quasi-static model at the window's speeds
    (0.1 %: fails if the element gears whirl in their pockets, as they do without the
    pockets' oil film, 0.2-0.5 %).
    Quick: two levels (125 and -125 N m) held 0.3 s instead of the file's four."""
    from drivedyn.analysis.vehicle import run_vehicle
    from drivedyn.config import read_library_file
    from drivedyn.plots.vehicle import vehicle_figures
    from drivedyn.validation.common import failed_check, finish_case

    t0 = time.perf_counter()
    case = "torsen_b_vehicle"
    sets = ["vehicle.torque_levels=[125, -125]", "vehicle.speed_diff=[-2, -2]",
            "vehicle.hold=0.3"] if quick else []
    p, _, _ = read_library_file("torsen-b", sets)
    run = run_vehicle(p)
    out: list[CaseResult] = []
    if not run.success:
        out.append(failed_check(case, "vehicle configuration run", "1", 5e-3,
                                "torque balance", run.results))
    fwd: dict[int, dict] = {}
    for lv in run.levels:
        if lv["mode"] is None:
            continue
        label = f"{lv['direction']} level {lv['level'] + 1} (mode {lv['mode']}, " \
                f"{lv['housing']:+.0f} N m)"
        out.append(compare(case, f"{label}: |T_h - (T_l + T_r)| / |T_h|", 0.0,
                           lv["balance_error"], "1", 5e-3, "torque balance of the housing"))
        if lv["tdr_analytic"] is not None:
            # measured within 0.04 % with the pocket oil film (pockets.oil_film); without it
            # the element gears whirl in the forward levels and come out 0.2-0.5 % low
            out.append(compare(case, f"{label}: TDR vs quasi-static", lv["tdr_analytic"],
                               lv["tdr"], "1", 0.001, "analytic model at the window's "
                               "speeds"))
        if lv["direction"] == "forward":
            fwd[lv["level"]] = lv
        elif lv["level"] in fwd:
            f = fwd[lv["level"]]
            out.append(compare(case, f"{lv['housing']:+.0f} N m: TDR backwards (mode "
                               f"{lv['mode']}) vs forwards (mode {f['mode']})", f["tdr"],
                               lv["tdr"], "1", 0.01,
                               "seed 003: the same TDRs in backwards motion"))
    figures: list[str] = []
    if figure_dir and run.levels:
        import os

        paths = vehicle_figures(run, os.path.join(figure_dir, "torsen_b_vehicle"))
        figures = [str(x) for x in paths]
    return finish_case(out, t0, figures)
