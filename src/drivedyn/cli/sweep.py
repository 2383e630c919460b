"""``drivedyn sweep``: parameter sweeps, Monte Carlo tolerance studies and sensitivities of a
model file on Dask (an embedded local cluster by default, any running scheduler with
``--scheduler``), resumable through a cache of finished points.

Exit codes: 0 every point was computed (a point whose simulation failed is a result, shown
in the table and the file), 1 some points are still missing (lost with a worker, an
unexpected error, or the sweep was interrupted: rerun the same command to complete them), 2 bad
input (malformed --vary/--sample/--metric, unknown key, invalid model file, unreachable
scheduler), refused before any point runs.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import click

from drivedyn.cli.common import (
    EXIT_FAILED,
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


@click.command()
@click.argument("model_file", metavar="MODEL")
@click.option("--vary", "varies", multiple=True, metavar="KEY=START:STOP:N",
              help="Vary a model-file key (the dotted keys of `run --set`) over N evenly "
                   "spaced values, or a list KEY=V1,V2,...; an optional unit follows "
                   "('bench.torque=50:250:5 N m'). Repeatable: full factorial, one dimension "
                   "per key. With --sensitivity: KEY or KEY=NOMINAL.")
@click.option("--sample", "samples_spec", multiple=True, metavar="KEY=DIST",
              help="Draw a key from normal(MEAN,SD) or uniform(LOW,HIGH) (optionally with a "
                   "unit), --samples times. Repeatable; crossed with --vary.")
@click.option("--samples", type=click.IntRange(1, 10**6), default=None, metavar="N",
              help="Number of Monte Carlo samples (with --sample).")
@click.option("--seed", type=int, default=0, show_default=True,
              help="Seed of the Monte Carlo draws (numpy default_rng).")
@click.option("--sensitivity", is_flag=True,
              help="Derivatives of every output with respect to each --vary KEY at the "
                   "nominal point (the file's value, or KEY=NOMINAL), by central differences "
                   "computed in parallel; table and tornado plot of the elasticities.")
@click.option("--rel-step", type=FiniteFloat(0.0, 0.5, low_open=True, high_open=True),
              default=0.01, show_default=True,
              help="Relative step of --sensitivity.")
@click.option("--tdr", is_flag=True,
              help="Differential models: the TDR of each locking mode on the simulated bench "
                   "(as `drivedyn tdr`) instead of the file's scenario.")
@click.option("--mode", "mode", default="all", show_default=True, metavar="LIST",
              help="With --tdr: locking modes, e.g. 1,3 or all.")
@click.option("--torque", type=FiniteFloat(0.0, low_open=True, unit="N m"), default=None,
              metavar="NM", help="With --tdr: applied torque [N m] (default the file's).")
@click.option("--speed-diff", type=FiniteFloat(0.0, low_open=True, unit="rpm"), default=None,
              metavar="RPM", help="With --tdr: output speed difference [rpm].")
@click.option("--friction-scale", type=FiniteFloat(0.0), default=1.0, show_default=True,
              metavar="F", help="With --tdr: factor on every friction coefficient.")
@click.option("--analytic-only", is_flag=True,
              help="With --tdr: the analytic quasi-static TDR only (no simulation).")
@click.option("--metric", "metrics", multiple=True, metavar="VAR[:REDUCER][@T0:T1]",
              help="Scalar output of a scenario run: a results variable reduced by final "
                   "(default), mean, max, min, absmax, ptp or rms, optionally over a time "
                   "window [s], e.g. hinge.angle:max or rod.position[2]:mean@1:2. "
                   "Repeatable.")
@click.option("--t-end", type=FiniteFloat(0.0, low_open=True, unit="s"), default=None,
              metavar="S", help="Final time of scenario runs [s] (default the file's).")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE",
              help="Fixed override of every point (dotted key). Repeatable.")
@click.option("--scheduler", default=None, metavar="ADDRESS",
              help="A running Dask scheduler (tcp://host:8786 or a scheduler file); "
                   "'serial' runs the points one after another in this process. Default: a "
                   "local cluster of --workers processes.")
@click.option("--connect-timeout", type=FiniteFloat(0.0, low_open=True, unit="s"),
              default=10.0, show_default=True, metavar="S",
              help="Seconds to wait for the --scheduler to answer.")
@click.option("--workers", type=click.IntRange(1, 1024), default=None, metavar="N",
              help="Worker processes of the local cluster (default: the number of CPUs).")
@click.option("--host", default="127.0.0.1", show_default=True, metavar="ADDRESS",
              help="Address the local cluster's scheduler, workers and dashboard listen on "
                   "(127.0.0.1: this machine only; 0.0.0.0: every network interface).")
@click.option("--out", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Results file (netCDF, written atomically). Default: "
                   "<model>-sweep.nc.")
@click.option("--cache", "cache_dir", type=click.Path(file_okay=False, path_type=Path),
              default=None, help="Folder of finished points (default: <out>.cache); "
              "rerunning the same command computes only what is missing.")
@click.option("--no-cache", is_flag=True, help="Neither read nor write the point cache.")
@click.option("--fresh", is_flag=True, help="Recompute every point (the cache is rewritten).")
@click.option("--keep-runs", "runs_dir", type=click.Path(file_okay=False, path_type=Path),
              default=None, metavar="DIR",
              help="Keep every point's results files in DIR (point-0000.nc ..., "
                   "points.json lists their overrides), for `drivedyn report`, `plot`, "
                   "`view`.")
@click.option("--plots", "plots_dir", type=click.Path(file_okay=False, path_type=Path),
              default=None, help="Also draw the sweep's figures into this folder.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
def sweep(model_file: str, varies: tuple[str, ...], samples_spec: tuple[str, ...],
          samples: int | None, seed: int, sensitivity: bool, rel_step: float, tdr: bool,
          mode: str, torque: float | None, speed_diff: float | None, friction_scale: float,
          analytic_only: bool, metrics: tuple[str, ...], t_end: float | None,
          sets: tuple[str, ...], scheduler: str | None, connect_timeout: float,
          workers: int | None, host: str,
          out: Path | None, cache_dir: Path | None, no_cache: bool, fresh: bool,
          runs_dir: Path | None, plots_dir: Path | None, as_json: bool) -> None:
    """Run a MODEL file (path or shipped name) over a grid of values, Monte Carlo samples or a
    sensitivity stencil, each point an independent run on a Dask cluster, and write one
    netCDF file with a dimension per varied key.

    \b
    Examples:
        drivedyn sweep torsen-c --tdr --vary pockets.mu=0.10:0.20:5 --workers 2
        drivedyn sweep torsen-c --tdr --mode 1 --vary pockets.mu=0.15:0.19:3 \\
            --vary washers.ring_case.mu=0.05:0.09:3 --out map.nc --plots map
        drivedyn sweep torsen-c --tdr --sample 'pockets.mu=normal(0.173,0.01)' \\
            --samples 40 --seed 1 --out tolerance.nc
        drivedyn sweep torsen-c --tdr --analytic-only --sensitivity --vary pockets.mu \\
            --vary washers.ring_case.mu
        drivedyn sweep pendulum --vary bodies.rod.mass=1:3:5 --metric hinge.angle:max \\
            --scheduler tcp://10.0.0.5:8786
        drivedyn sweep torsen-b --tdr --mode 1 --vary pockets.mu=0.10,0.14 \\
            --keep-runs runs && drivedyn report runs/point-0001-right.nc
    """
    from drivedyn.config import ModelFileError, UnitError
    from drivedyn.errors import ModelError
    from drivedyn.results.results import write_netcdf_atomic
    from drivedyn.sweeps import SweepInputError, SweepInterrupted
    from drivedyn.sweeps import sweep as run_sweep

    if samples_spec and samples is None:
        bad_input("--sample needs --samples N")
    if samples is not None and not samples_spec:
        bad_input("--samples needs at least one --sample KEY=DIST")
    if not tdr and (mode != "all" or torque is not None or speed_diff is not None
                    or friction_scale != 1.0 or analytic_only):
        bad_input("--mode, --torque, --speed-diff, --friction-scale and --analytic-only go "
                  "with --tdr")
    if tdr and (metrics or t_end is not None):
        bad_input("--metric and --t-end go with scenario runs, not --tdr")
    try:
        modes = [1, 2, 3, 4] if mode == "all" else [int(m) for m in mode.split(",")]
    except ValueError:
        bad_input(f"--mode {mode!r}: expected all or a list of modes such as 1,3")
    if any(m not in (1, 2, 3, 4) for m in modes) or len(set(modes)) != len(modes):
        bad_input(f"--mode {mode!r}: expected distinct modes among 1, 2, 3, 4")
    name = Path(model_file).stem
    target = out or Path(f"{name}-sweep.nc")
    check_output_path(target, "--out")
    cache = None if no_cache else (cache_dir or target.with_name(target.name + ".cache"))
    check_output_path(cache, "--cache", directory=True)
    check_output_path(plots_dir, "--plots", directory=True)
    check_output_path(runs_dir, "--keep-runs", directory=True)

    bar = _Bar(enabled=not as_json and sys.stderr.isatty())
    t0 = time.perf_counter()
    try:
        ds = run_sweep(
            model_file, None if sensitivity else list(varies), sample=list(samples_spec),
            samples=samples or 0, seed=seed,
            sensitivity_keys=list(varies) if sensitivity else None, rel_step=rel_step,
            tdr=tdr, modes=modes, torque=torque,
            speed_diff=None if speed_diff is None else speed_diff * RPM,
            friction_scale=friction_scale, analytic_only=analytic_only, t_end=t_end,
            metrics=list(metrics), sets=list(sets), scheduler=scheduler, workers=workers,
            host=host, timeout=connect_timeout,
            cache=cache, fresh=fresh, keep_runs=runs_dir, progress=bar.update,
            on_cluster=None if as_json else (lambda s: err(s)))
        interrupted = False
    except (SweepInputError, ModelFileError, ModelError, UnitError) as exc:
        bar.close()
        bad_input(str(exc))
    except SweepInterrupted as exc:
        ds, interrupted = exc.dataset, True
    bar.close()
    ds.attrs["command"] = "drivedyn sweep " + " ".join(sys.argv[2:])
    outputs = OutputFiles()  # a path that refuses the results now: they go to a fallback
    target = outputs.write(lambda p: write_netcdf_atomic(ds, p), target, "--out")
    figures = []
    if plots_dir is not None:
        from drivedyn.plots.sweeps import plot_sweep

        figures = [str(p) for p in outputs.write(lambda d: plot_sweep(ds, d), plots_dir,
                                                  "--plots", directory=True)]
    counts = json.loads(ds.attrs["status_counts"])
    incomplete = counts["lost"] + counts["missing"] + counts["error"]
    wall = time.perf_counter() - t0
    if as_json:
        from drivedyn.sweeps.summary import tables

        click.echo(json.dumps(jsonable({
            "results_file": str(target), "cache": str(cache) if cache else None,
            "points": int(ds.attrs["points"]), "computed": int(ds.attrs.get("computed", 0)),
            "status_counts": counts, "interrupted": interrupted, "wall_s": round(wall, 3),
            "figures": figures,
            "tables": [{"title": t, "columns": c, "rows": r} for t, c, r in tables(ds)]})))
    else:
        _print(ds, target, cache, wall, figures)
    if interrupted:
        err(f"interrupted: the finished points are in {target} and the cache; rerun the same "
            "command to compute the rest")
        sys.exit(EXIT_FAILED)
    if incomplete:
        err(f"{incomplete} point(s) not computed (lost, error or missing): rerun the same "
            "command to compute them")
        sys.exit(EXIT_FAILED)
    outputs.exit_if_failed()


def _print(ds, target: Path, cache: Path | None, wall: float, figures: list[str]) -> None:
    from rich.table import Table

    from drivedyn.sweeps.summary import problems, tables

    out = console()
    for title, cols, rows in tables(ds):
        table = Table(title=title, title_justify="left")
        for c in cols:
            table.add_column(c, justify="right")
        for r in rows:
            table.add_row(*r)
        out.print(table)
    for line in problems(ds):
        out.print("  " + line)
    computed = int(ds.attrs.get("computed", 0))
    n = int(ds.attrs["points"])
    out.print(f"{n} points: {computed} computed, {n - computed} from the cache"
              + (f" ({cache})" if cache else "") + f"; wall time {wall:.1f} s")
    out.print(f"results: {target}", soft_wrap=True)  # a path is never wrapped
    if ds.attrs.get("runs_dir"):
        out.print(f"results files of the points: {ds.attrs['runs_dir']}")
    for f in figures:
        out.print(f"figure: {f}")


class _Bar:
    """A rich progress bar over points on a terminal (silent elsewhere)."""

    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled
        self.progress = None
        self.task = None
        self.counts = {"cached": 0, "failed": 0}

    def update(self, done: int, total: int, rec: dict, from_cache: bool) -> None:
        if not self.enabled:
            return
        if self.progress is None:
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeElapsedColumn,
                TimeRemainingColumn,
            )

            self.progress = Progress(
                TextColumn("[bold]points"), BarColumn(), MofNCompleteColumn(),
                TextColumn("{task.fields[note]}"), TimeElapsedColumn(),
                TimeRemainingColumn(), console=console(stderr=True))
            self.task = self.progress.add_task("sweep", total=total, note="")
            self.progress.start()
        self.counts["cached"] += from_cache
        self.counts["failed"] += rec.get("status") != "ok"
        note = f"{self.counts['cached']} cached, {self.counts['failed']} not ok"
        self.progress.update(self.task, completed=done, note=note)

    def close(self) -> None:
        if self.progress is not None:
            self.progress.stop()
            self.progress = None
