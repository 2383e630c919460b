"""Commands on the parametric differential models: ``drivedyn tdr`` and ``drivedyn calibrate``.

Exit codes: 0 success, 1 a simulation failed (the TDRs computed so far are printed), 2 bad
input (file, key, value).
"""

from __future__ import annotations

import json
import math
import shlex
import sys
import time
from pathlib import Path

import click

from drivedyn.cli.common import (
    FiniteFloat,
    OutputFiles,
    bad_input,
    check_output_path,
    console,
    err,
    jsonable,
)
from drivedyn.units import UNITS

RPM = UNITS["rpm"][0]  # rad/s per rpm


def _params(model_file: str, sets: tuple[str, ...]):
    from drivedyn.config import read_library_file
    from drivedyn.config.loader import ModelFileError
    from drivedyn.library import differentials
    from drivedyn.model.spec import ModelError

    source = model_file
    try:
        p, _, source = read_library_file(model_file, list(sets))
        if p.model.library not in differentials.TYPES:
            bad_input(f"{source}: model.library = {p.model.library!r} is not a differential "
                      f"(differentials: {', '.join(differentials.TYPES)}); vehicles run with "
                      "`drivedyn vehicle` or `drivedyn run`")
        differentials.of(p).check(p)
    except ModelFileError as exc:  # names the file already
        bad_input(str(exc))
    except ModelError as exc:
        bad_input(f"{source}: {exc}")
    return p, source


@click.command()
@click.argument("model_file", metavar="FILE", default="torsen-c")
@click.option("--mode", "mode", type=click.Choice(["1", "2", "3", "4", "all"]), default="all",
              show_default=True, help="Locking mode: Type C 1 drive/bias rear, 2 coast/bias "
              "rear, 3 drive/bias front, 4 coast/bias front; Type B 1 drive/bias right, 2 "
              "coast/bias right, 3 drive/bias left, 4 coast/bias left.")
@click.option("--torque", type=FiniteFloat(0.0, low_open=True, unit="N m"), default=None,
              metavar="NM",
              help="Applied torque [N m] (default: the file's bench.torque, 125 N m).")
@click.option("--speed-diff", type=FiniteFloat(0.0, low_open=True, unit="rpm"), default=None,
              metavar="RPM",
              help="Output speed difference [rpm] (default: the file's bench.speed_diff, "
                   "20 rpm).")
@click.option("--friction-scale", type=FiniteFloat(0.0), default=1.0, show_default=True,
              metavar="F",
              help="Multiply every friction coefficient of the model by F.")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE",
              help="Override a parameter by its dotted key, e.g. --set pockets.mu=0.12 "
                   "--set 'gears.helix_angle=\"28 deg\"'. Repeatable.")
@click.option("--analytic-only", is_flag=True,
              help="Only the analytic quasi-static TDR (no simulation).")
@click.option("--sequential", is_flag=True,
              help="Run the two bench sides one after the other (default: at the same time "
                   "with two or more CPUs; the results are the same).")
@click.option("--out", "out_dir", type=click.Path(file_okay=False, path_type=Path),
              default=None, metavar="DIR",
              help="Write each bench run's results to DIR/<model>-bench-<side>.nc (for "
                   "`drivedyn report`, `plot`, `view`: they find the differential's bench "
                   "dashboard).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
def tdr(model_file: str, mode: str, torque: float | None, speed_diff: float | None,
        friction_scale: float, sets: tuple[str, ...], analytic_only: bool, sequential: bool,
        out_dir: Path | None, as_json: bool) -> None:
    """Torque distribution ratio of a differential on the simulated test bench (seed 003).

    FILE is a differential model file or a shipped one by name (torsen-c, torsen-b).
    Housing held, torque on one output, speed of the other controlled for the speed
    difference; drive then coast in one run per side, TDR = applied / resistant torque
    averaged over the steady windows. Prints the simulated, analytic (quasi-static) and
    measured TDR of each mode. With two or more CPUs the two sides run at the same time
    (--sequential: one after the other; the results are the same).

    \b
    Examples:
        drivedyn tdr torsen-c
        drivedyn tdr torsen-b --mode all
        drivedyn tdr torsen-c --mode 1 --torque 250 --speed-diff 10
        drivedyn tdr torsen-c --friction-scale 0.8 --set pockets.mu=0.12 --json
        drivedyn tdr torsen-b --out bench && drivedyn report bench/torsen-b-bench-right.nc
    """
    from drivedyn.analysis.tdr import evaluate, size_text

    check_output_path(out_dir, "--out", directory=True)
    p, source = _params(model_file, sets)
    if torque is not None and not torque > 0:
        bad_input(f"--torque: expected a positive torque in N m, got {torque}")
    if speed_diff is not None and not speed_diff > 0:
        bad_input(f"--speed-diff: expected a positive speed difference in rpm, got "
                   f"{speed_diff}")
    if not (friction_scale >= 0 and math.isfinite(friction_scale)):
        bad_input(f"--friction-scale: expected a factor >= 0, got {friction_scale}")
    modes = [1, 2, 3, 4] if mode == "all" else [int(mode)]
    t0 = time.perf_counter()
    first = []
    written: list[str] = []
    outputs = OutputFiles()  # a folder that refuses a run's results now: they go to a fallback

    def on_run(*args) -> None:
        if len(args) == 1 and out_dir is not None:
            run = args[0]
            written.append(str(outputs.write(
                lambda d: _write_bench_run(run, d, p.model.name), out_dir, "--out",
                directory=True)))
        if as_json:
            return
        if len(args) == 2:
            side, pair = args
            click.echo(f"simulating the bench, torque on the {side} output "
                       f"(modes {pair[0]} and {pair[1]}) ...", err=True)
        elif not first:
            first.append(True)
            click.echo(size_text(args[0].size), err=True)

    ev = evaluate(p, modes, torque, None if speed_diff is None else speed_diff * RPM,
                  friction_scale, analytic_only, on_run=on_run, parallel=not sequential,
                  source=source, overrides=list(sets))
    T0, dw, rows, runs, failed = ev.torque, ev.speed_diff, ev.rows, ev.runs, ev.failed
    wall = time.perf_counter() - t0
    if as_json:
        out = {"model": p.model.name, "source": source, "torque": T0,
               "speed_diff": dw / RPM, "friction_scale": friction_scale,
               "simulated": not analytic_only, "modes": rows, "runs": runs,
               "metrics": ev.metrics, "results_files": written, "wall_s": round(wall, 3)}
        if failed:
            out["error"] = failed
        click.echo(json.dumps(jsonable(out)))
    else:
        _print_table(p.model.name, T0, dw, rows, wall, analytic_only)
        for f in written:
            click.echo(f"results: {f}")
    outputs.exit_if_failed()
    if failed:
        err(failed)
        sys.exit(1)


def _write_bench_run(run, out_dir: Path, name: str) -> Path:
    """Write one bench run's results to ``out_dir/<name>-bench-<side>.nc`` (``.partial.nc``
    when it stopped early)."""
    from drivedyn.results.results import write_netcdf_atomic

    target = out_dir / f"{name}-bench-{run.side}{'' if run.success else '.partial'}.nc"
    return write_netcdf_atomic(run.results.dataset, target)


def _print_table(name, T0, dw, rows, wall, analytic_only) -> None:
    from rich.table import Table

    table = Table(title=f"{name}: TDR on the test bench ({T0:g} N m, {dw / RPM:g} rpm)",
                  title_justify="left")
    for col in ("mode", "", "TDR simulated" if not analytic_only else "TDR (analytic only)",
                "analytic", "experimental", "error vs exp.", "sim. vs analytic"):
        table.add_column(col, justify="right")
    for r in rows:
        def pct(x):
            return f"{x:+.2f} %" if x is not None else "-"
        table.add_row(str(r["mode"]), r["name"], f"{r['tdr']:.3f}", f"{r['analytic']:.3f}",
                      f"{r['experimental']:.2f}" if r["experimental"] else "-",
                      pct(r["error_pct"]), pct(r["sim_vs_analytic_pct"]))
    out = console()
    out.print(table)
    out.print(f"wall time {wall:.1f} s")


@click.command()
@click.argument("model_file", metavar="FILE", default="torsen-c")
@click.option("--free", "free", multiple=True, metavar="KEY[,KEY...]",
              help="Friction coefficient to fit (dotted key, e.g. washers.ring_case.mu); keys "
                   "joined by commas share one fitted value. Repeatable. Default: the "
                   "model's declared free parameters ([calibration] tied/fitted).")
@click.option("--target", "targets", multiple=True, metavar="MODE=TDR",
              help="Measured TDR of a mode, e.g. --target 1=4.02 (default: the file's "
                   "[experiment] table, all four modes).")
@click.option("--bounds", nargs=2, type=FiniteFloat(0.0, 1.0), default=None,
              metavar="LOW HIGH",
              help="One range for every fitted coefficient, instead of the physical ranges "
                   "of the file's [calibration] bounds (the default).")
@click.option("--uncertainty", type=FiniteFloat(0.0, 0.5, low_open=True), default=None,
              metavar="S", help="Relative uncertainty of each measured TDR (0.03: +-3 %), for "
              "the cost profile and the spread (default: the file's [calibration] "
              "uncertainty).")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE",
              help="Override a parameter before fitting (dotted key). Repeatable.")
@click.option("--no-confirm", is_flag=True, help="Skip the confirmation by simulation.")
@click.option("--cross-validate", is_flag=True,
              help="Also refit leaving out each distinct measurement in turn (modes the "
                   "model cannot tell apart together) and report the error of its prediction; "
                   "with the cost profile of each fitted number and the spread under the "
                   "measurement uncertainty.")
@click.option("--out", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write the calibrated model file here (comments kept, [calibration] "
                   "table replaced).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
def calibrate(model_file: str, free: tuple[str, ...], targets: tuple[str, ...],
              bounds: tuple[float, float] | None, uncertainty: float | None,
              sets: tuple[str, ...], no_confirm: bool, cross_validate: bool, out: Path | None,
              as_json: bool) -> None:
    """Fit friction coefficients of a differential model to measured TDRs.

    Bounded least squares on log TDR with the analytic quasi-static model, each coefficient
    within its physical range (the file's [calibration] bounds), then the bench is simulated
    with the fitted values (and the fit corrected by the small model difference if needed).
    A fit that ends on a bound (within 1 % of the range) is a failed calibration: exit 1,
    nothing written. Fit fewer numbers than distinct measurements, or the fit reproduces
    the data by construction; --cross-validate gives the predictive error by distinct
    measurement, the cost profile and the spread. With --out, writes the model file with the
    fitted values and a [calibration] table stating what was fitted to which data, this
    command and what the fit can claim.

    \b
    Examples (reproduce the shipped files exactly):
        drivedyn calibrate torsen-c --cross-validate --out torsen-c.toml
        drivedyn calibrate torsen-b --cross-validate --out torsen-b.toml
    """
    from drivedyn.analysis import calibrate as C  # noqa: N812
    from drivedyn.analysis import calibration_study as S  # noqa: N812
    from drivedyn.analysis.tdr import experimental
    from drivedyn.config.loader import resolve_path
    from drivedyn.library import differentials

    check_output_path(out, "--out")
    outputs = OutputFiles()  # a path that refuses the fitted file: it goes to a fallback
    p, _ = _params(model_file, sets)
    diff = differentials.of(p)
    groups = C.groups_of(list(free)) if free else declared_free(p) or list(diff.free)
    goal: dict[int, float] = {}
    for t in targets:
        m, _, v = t.partition("=")
        try:
            mode_id, ratio = int(m), float(v)
        except ValueError:
            bad_input(f"--target {t!r}: expected MODE=TDR, e.g. 1=4.02")
        if mode_id not in (1, 2, 3, 4) or not (math.isfinite(ratio) and ratio >= 1.0):
            bad_input(f"--target {t!r}: expected a mode 1-4 and a finite TDR >= 1")
        goal[mode_id] = ratio
    if not goal:
        goal = experimental(p)
        if not goal:
            bad_input("no targets: give --target MODE=TDR or an [experiment] tdr table")
    if bounds is not None and not 0 <= bounds[0] < bounds[1] <= 1:
        bad_input(f"--bounds: expected 0 <= low < high <= 1, got {bounds[0]} {bounds[1]}")
    u = p.calibration.uncertainty if uncertainty is None else uncertainty
    t0 = time.perf_counter()

    def note(msg: str) -> None:
        if not as_json:
            click.echo(msg, err=True)

    study = None
    try:
        cal = C.calibrate(p, groups, goal, bounds=bounds, confirm=not no_confirm,
                          progress=note)
        if cross_validate:
            box = cal.bounds
            distinct = S.distinct_measurements(p, cal.groups, goal, box, u)
            study = {
                "distinct": distinct,
                "cross_validation": S.cross_validate(p, cal.groups, goal, box, distinct,
                                                     cal.offsets, progress=note),
                "profile": S.profile(p, cal.groups, goal, box, u, cal.offsets),
                "spread": S.spread(p, cal.groups, goal, box, u, cal.offsets),
            }
    except (KeyError, ValueError) as exc:
        bad_input(str(exc))
    except C.FitAtBoundError as exc:
        err(f"calibration failed: {exc}")
        sys.exit(1)
    except RuntimeError as exc:
        err(str(exc))
        sys.exit(1)
    wall = time.perf_counter() - t0
    final = cal.simulated or cal.analytic
    errors = C.relative_errors(final, goal)
    command = "drivedyn calibrate " + " ".join(shlex.quote(a) for a in sys.argv[2:]) \
        if len(sys.argv) > 2 else f"drivedyn calibrate {diff.name}"
    if out is not None:
        text = resolve_path(model_file).read_text()
        table = C.calibration_table(cal, p.experiment.source or "command-line targets",
                                    command, study)
        try:
            new = C.update_toml_text(text, cal.values, table)
        except KeyError as exc:
            bad_input(str(exc))

        def write(path: Path) -> Path:
            # with --set, overridden keys are written too so the file reproduces the fit
            tmp = path.with_suffix(path.suffix + ".tmp")
            tmp.write_text(new)
            tmp.replace(path)
            return path

        out = outputs.write(write, out, "--out")
    loo = {m: lo for lo in (study or {}).get("cross_validation", []) for m in lo.modes}
    if as_json:
        click.echo(json.dumps(jsonable({
            "model": p.model.name, "free": cal.values,
            "groups": [list(g) for g in cal.groups], "targets": goal,
            "bounds": {", ".join(g): list(b) for g, b in zip(cal.groups, cal.bounds,
                                                             strict=True)},
            "analytic": cal.analytic, "simulated": cal.simulated, "error_pct": errors,
            "cross_validation": {m: {"left_out": list(r.modes), "predicted": r.predicted[m],
                                     "target": goal[m], "error_pct": r.error_pct[m],
                                     "identifiable": r.identifiable, "values": r.values,
                                     "at_bound": r.at_bound} for m, r in loo.items()}
            if study else None,
            "distinct": [list(d) for d in study["distinct"]] if study else None,
            "profile": study["profile"] if study else None,
            "spread": study["spread"] if study else None, "uncertainty": u,
            "at_bound": cal.at_bound, "iterations": cal.iterations,
            "written": str(out) if out else None, "wall_s": round(wall, 3)})))
        outputs.exit_if_failed()
        return
    n_distinct = len(study["distinct"]) if study else len(goal)
    click.echo(f"fitted: {len(cal.groups)} number(s) for {len(goal)} measurement(s)"
               + (f" ({n_distinct} distinct)" if study else ""))
    for g, (lo, hi) in zip(cal.groups, cal.bounds, strict=True):
        label = ", ".join(g)
        prof = ""
        if study:
            a, b = study["profile"][label]["interval"]
            sp = study["spread"]["values"][label]
            prof = f"  profile [{a:.3f}, {b:.3f}], spread [{sp[0]:.3f}, {sp[1]:.3f}]"
        click.echo(f"  {cal.values[g[0]]:.4f}  {label}  (range [{lo:g}, {hi:g}]){prof}")
    click.echo("mode  target   analytic  simulated  error    leave-out (with)  spread")
    for m in sorted(goal):
        s = cal.simulated.get(m, math.nan)
        cv_txt, sp_txt = "-", ""
        if m in loo:
            r = loo[m]
            cv_txt = (f"{r.error_pct[m]:+6.2f} %" if r.identifiable else "not identifiable")
            cv_txt += f" ({','.join(map(str, r.modes))})"
            a, b = study["spread"]["tdr"][m]
            sp_txt = f"  [{a:.3f}, {b:.3f}]"
        click.echo(f"  {m}   {goal[m]:6.3f}   {cal.analytic[m]:8.4f}  {s:9.4f}  "
                   f"{errors.get(m, math.nan):+6.2f} %  {cv_txt}{sp_txt}")
    if out is not None:
        click.echo(f"model file written to {out}")
    click.echo(f"wall time {wall:.1f} s")
    outputs.exit_if_failed()


def declared_free(p) -> list[tuple[str, ...]]:
    """The free parameters the model file declares: its ``[calibration]`` ``tied`` groups and
    the other ``fitted`` keys alone (empty if the file declares none)."""
    cal = p.calibration
    tied = [tuple(g) for g in cal.tied]
    in_groups = {k for g in tied for k in g}
    return tied + [(k,) for k in cal.fitted if k not in in_groups]


COMMANDS = (tdr, calibrate)
