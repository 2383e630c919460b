"""Command line interface: ``drivedyn validate``, ``run``, ``plot``, ``models``, ``bounce``,
``--version``.

Exit codes: 0 success, 1 failure (a validation check failed or a case raised), 2 bad input
(unknown option or case name; click's usage errors).
"""

from __future__ import annotations

import datetime as _dt
import importlib
import json
import math
import os
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import click
from rich.console import Console
from rich.table import Table

import drivedyn
from drivedyn.validation import base as vbase

COMPILE_NOTE = ("note: the first run compiles the numba kernels (a few minutes); they are "
                "cached afterwards.")

HELP = """drivedyn: flexible multibody simulation of automotive drivelines.

A flexible multibody engine (rigid bodies and nodes, joints, spring-dampers, loads and
drivers, integrated by generalized-alpha on the rotation group) built for modelling
limited-slip (TORSEN) differentials and their test benches. `drivedyn validate` compares
simulated quantities with exact or published references and exits with 0 only if every check
passes; `drivedyn run` simulates a model file, `drivedyn plot` draws its results and
`drivedyn models` lists the shipped model files. Exit codes: 0 success, 1 failure (partial
results are written), 2 bad input.

\b
Examples:
    drivedyn validate --quick --report validation-report
    drivedyn models --show pendulum > my_pendulum.toml
    drivedyn run my_pendulum.toml --set solver.t_end=10 --out pendulum.nc
    drivedyn plot pendulum.nc --out figures
"""


def _console(stderr: bool = False) -> Console:
    """A rich console; wide when not writing to a terminal, so tables are not squashed."""
    stream = sys.stderr if stderr else sys.stdout
    width = None
    if not stream.isatty() and "COLUMNS" not in os.environ:
        width = 160
    return Console(file=stream, width=width, highlight=False, soft_wrap=False)


def _jsonable(obj: Any) -> Any:
    """Replace non-finite floats by None and numpy scalars by Python numbers so the output
    is strict JSON."""
    if isinstance(obj, dict):
        return {k: _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if hasattr(obj, "item") and not isinstance(obj, (str, bytes)):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def _fmt(value: float, spec: str) -> str:
    return format(value, spec) if math.isfinite(value) else str(value)


def _load_cases() -> dict[str, Any]:
    """Import the module that registers the validation cases and return the registry."""
    try:
        importlib.import_module("drivedyn.validation.cases")
    except Exception as exc:
        raise click.ClickException(
            f"cannot load the validation cases ({type(exc).__name__}: {exc})") from exc
    return vbase.CASES


def _run(names: Sequence[str], quick: bool, figure_dir: str | None,
         err: Console) -> tuple[list[vbase.CaseResult], dict[str, str]]:
    """Run the cases one by one (to show progress); a case that raises becomes a failed
    result whose ``source`` holds the exception."""
    results: list[vbase.CaseResult] = []
    errors: dict[str, str] = {}
    for name in names:
        t0 = time.perf_counter()
        with err.status(f"running case [bold]{name}[/bold] ..."):
            try:
                res = drivedyn.validation.run_cases([name], quick, figure_dir)
            except Exception as exc:  # reported as a failed check, the others still run
                msg = f"{type(exc).__name__}: {exc}"
                errors[name] = msg
                res = [vbase.CaseResult(name, "case raised an exception", math.nan, math.nan,
                                        "", math.inf, 0.0, source=msg,
                                        wall_s=time.perf_counter() - t0)]
        if not res:
            errors[name] = "the case returned no results"
            res = [vbase.CaseResult(name, "case returned no results", math.nan, math.nan, "",
                                    math.inf, 0.0, wall_s=time.perf_counter() - t0)]
        results += res
    return results, errors


def _table(results: list[vbase.CaseResult]) -> Table:
    table = Table(title="drivedyn validation", title_justify="left")
    table.add_column("case")
    table.add_column("quantity")
    table.add_column("reference", justify="right")
    table.add_column("simulated", justify="right")
    table.add_column("unit")
    table.add_column("error", justify="right")
    table.add_column("tolerance", justify="right")
    table.add_column("result", justify="center")
    table.add_column("wall s", justify="right")
    prev = None
    for r in results:
        first = r.case != prev
        prev = r.case
        table.add_row(
            r.case if first else "",
            r.quantity,
            _fmt(r.reference, ".7g"),
            _fmt(r.simulated, ".7g"),
            r.unit,
            _fmt(r.error, ".2e"),
            _fmt(r.tolerance, ".1e"),
            "[green]PASS[/green]" if r.passed else "[bold red]FAIL[/bold red]",
            f"{r.wall_s:.2f}" if first else "",
        )
    return table


def _md(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def write_report(directory: Path, results: list[vbase.CaseResult], errors: dict[str, str],
                 quick: bool) -> Path:
    """Write ``directory/report.md``: the results table and links to the case figures."""
    directory.mkdir(parents=True, exist_ok=True)
    npass = sum(r.passed for r in results)
    stamp = _dt.datetime.now().astimezone().isoformat(timespec="seconds")
    lines = [
        "# drivedyn validation report",
        "",
        f"drivedyn {drivedyn.__version__}, {stamp}, "
        f"{'quick' if quick else 'full'} run: **{npass} of {len(results)} checks passed**.",
        "",
        "Each row compares a quantity simulated by drivedyn with an exact solution or a "
        "published value (the *source* column). *error* is relative (absolute when the "
        "reference is 0); *tolerance* is the accuracy the integrator should reach at the step "
        "size the case uses, stated and justified in `src/drivedyn/validation/cases.py` "
        "(second-order schemes: about (omega h)^2). Wall times include the case's every run. "
        "Figures of the main time histories follow the table. To reproduce: "
        f"`drivedyn validate{' --quick' if quick else ''} --report DIR`.",
        "",
        "| case | quantity | reference | simulated | unit | error | tolerance | result "
        "| wall s | source |",
        "|---|---|---:|---:|---|---:|---:|:---:|---:|---|",
    ]
    for r in results:
        lines.append(
            f"| {_md(r.case)} | {_md(r.quantity)} | {_fmt(r.reference, '.7g')} "
            f"| {_fmt(r.simulated, '.7g')} | {_md(r.unit)} | {_fmt(r.error, '.2e')} "
            f"| {_fmt(r.tolerance, '.1e')} | {'PASS' if r.passed else '**FAIL**'} "
            f"| {r.wall_s:.2f} | {_md(r.source)} |")
    if errors:
        lines += ["", "## Errors", ""]
        lines += [f"- `{name}`: {_md(msg)}" for name, msg in errors.items()]
    figures: dict[str, list[str]] = {}
    for r in results:
        for f in r.figures:
            if f not in figures.setdefault(r.case, []):
                figures[r.case].append(f)
    if any(figures.values()):
        lines += ["", "## Figures"]
        for case, figs in figures.items():
            if not figs:
                continue
            lines += ["", f"### {case}", ""]
            for f in figs:
                rel = Path(os.path.relpath(Path(f).resolve(), directory.resolve())).as_posix()
                lines.append(f"![{_md(case)}: {Path(f).name}]({rel})")
    path = directory / "report.md"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


@click.group(help=HELP, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(drivedyn.__version__, "--version", "-V", prog_name="drivedyn")
def main() -> None:
    """drivedyn command line (see HELP)."""


@main.command()
@click.option("--quick", is_flag=True, help="Run the short version of each case (a fast check).")
@click.option("--case", "cases", multiple=True, metavar="NAME",
              help="Run only this case (repeatable); default: all cases.")
@click.option("--report", "report", type=click.Path(file_okay=False, path_type=Path),
              default=None, metavar="DIR",
              help="Write DIR/report.md (table and figures; figures are written into DIR).")
@click.option("--json", "as_json", is_flag=True,
              help="Print the results as a JSON list instead of the table.")
def validate(quick: bool, cases: tuple[str, ...], report: Path | None, as_json: bool) -> None:
    """Compare simulated quantities with exact or published references.

    Prints one row per checked quantity (reference, simulated value, error, tolerance,
    PASS/FAIL and the case's wall time). Exits with 0 if every check passes, 1 otherwise.
    """
    out = _console()
    err = _console(stderr=True)
    registry = _load_cases()
    unknown = [c for c in cases if c not in registry]
    if unknown:
        avail = ", ".join(registry) or "none registered"
        raise click.BadParameter(f"unknown case(s) {', '.join(unknown)} (available: {avail})",
                                 param_hint="'--case'")
    names = list(dict.fromkeys(cases)) or list(registry)
    if not names:
        err.print("[yellow]note: no validation cases are registered yet; nothing was "
                  "checked.[/yellow]")
        if as_json:
            click.echo("[]")
        if report is not None:
            write_report(report, [], {}, quick)
        return
    err.print(COMPILE_NOTE)
    figure_dir = None
    if report is not None:
        report.mkdir(parents=True, exist_ok=True)
        figure_dir = str(report)
    t0 = time.perf_counter()
    results, errors = _run(names, quick, figure_dir, err)
    wall = time.perf_counter() - t0
    failed = [r for r in results if not r.passed]
    if as_json:
        click.echo(json.dumps(_jsonable([r.as_dict() for r in results]), indent=2))
    else:
        out.print(_table(results))
        for name, msg in errors.items():
            out.print(f"[red]case {name}: {msg}[/red]")
        verdict = "[green]all passed[/green]" if not failed else \
            f"[bold red]{len(failed)} failed[/bold red]"
        out.print(f"{len(results) - len(failed)} of {len(results)} checks passed "
                  f"({verdict}) in {wall:.1f} s")
    if report is not None:
        path = write_report(report, results, errors, quick)
        err.print(f"report written to {path}")
    if failed:
        sys.exit(1)


_BOUNCE_LAWS = ("hunt-crossley", "lankarani-nikravesh", "flores", "gonthier", "hu-guo",
                "exact")
_POSITIVE = click.FloatRange(min=0.0, min_open=True)


@main.command()
@click.option("--law", type=click.Choice(_BOUNCE_LAWS), default="lankarani-nikravesh",
              show_default=True, help="Continuous-impact law of the contact.")
@click.option("--e", "e", type=click.FloatRange(0.0, 1.0, min_open=True, max_open=True),
              default=0.8, show_default=True, help="Restitution coefficient given to the law.")
@click.option("--n", "n", type=click.FloatRange(min=1.0), default=1.5, show_default=True,
              help="Exponent of the contact force K delta^n.")
@click.option("--k", "k", type=_POSITIVE, default=1e10, show_default=True,
              help="Contact stiffness K [N/m^n].")
@click.option("--mass", type=_POSITIVE, default=0.85, show_default=True, help="Ball mass [kg].")
@click.option("--h0", type=_POSITIVE, default=1.0, show_default=True,
              help="Drop height [m].")
@click.option("--gravity", type=_POSITIVE, default=10.0, show_default=True,
              help="Gravitational acceleration [m/s^2].")
@click.option("--t-end", "t_end", type=_POSITIVE, default=3.0, show_default=True,
              help="Simulated time [s].")
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON object (law, e_target, apex_heights, restitution, steps, "
                   "wall_s, ...) instead of the table.")
@click.option("--plot", "plot", type=click.Path(dir_okay=False, path_type=Path), default=None,
              metavar="PNG", help="Also write height against time to this PNG file.")
def bounce(law: str, e: float, n: float, k: float, mass: float, h0: float, gravity: float,
           t_end: float, as_json: bool, plot: Path | None) -> None:
    """The seeds' bouncing-ball benchmark of continuous impact.

    A ball dropped from H0 bounces on a rigid floor with the contact force
    K delta^n [1 + chi deltadot / v_s]; chi is the law's damping factor for E. Prints, per
    bounce, the approach and rebound speeds, the restitution (rebound over approach speed)
    and the apex height of the next flight, with the restitution the exact relation predicts
    for the law's chi, the number of steps and the wall time. Exits with 1 if the simulation
    fails.
    """
    from drivedyn.library.bouncing_ball import plot_height, run_bounce

    err = _console(stderr=True)
    with err.status("simulating the bouncing ball ..."):
        run = run_bounce(law=law, e=e, n=n, k=k, mass=mass, h0=h0, gravity=gravity,
                         t_end=t_end)
    if plot is not None and run.results is not None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        fig = Figure(figsize=(8, 4.5))
        FigureCanvasAgg(fig)
        plot_height(run, fig)
        fig.tight_layout()
        plot.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(plot, dpi=110)
    if as_json:
        click.echo(json.dumps(_jsonable(run.as_dict())))
    else:
        out = _console()
        table = Table(title=f"bouncing ball: {law} law, e = {e:g}, n = {n:g}, K = {k:g} "
                            f"N/m^n, m = {mass:g} kg, h0 = {h0:g} m, g = {gravity:g} m/s^2",
                      title_justify="left")
        for col in ("bounce", "approach speed \\[m/s]", "rebound speed \\[m/s]",
                    "restitution", "apex after \\[m]"):
            table.add_column(col, justify="right")
        for i, (vi, vo, ei) in enumerate(zip(run.impact_speeds, run.rebound_speeds,
                                             run.restitution, strict=True)):
            apex = f"{run.apex_heights[i]:.6f}" if i < len(run.apex_heights) else "-"
            table.add_row(str(i + 1), f"{vi:.6f}", f"{vo:.6f}", f"{ei:.6f}", apex)
        out.print(table)
        out.print(f"damping factor chi = {run.chi:.6g}; restitution predicted by the exact "
                  f"relation: {run.e_predicted:.6f} (given e = {e:g}); gravity acting during "
                  "the contact lowers it slightly, more for slow impacts")
        out.print(f"{run.steps} steps ({run.rejected} rejected), wall time {run.wall_s:.3f} s,"
                  f" energy balance error {run.energy_balance_error:.3g} J")
        if plot is not None:
            out.print(f"figure written to {plot}")
    if not run.success:
        err.print(f"[red]simulation failed: {run.message}[/red]")
        sys.exit(1)


def _attach_commands() -> None:
    """Commands on model and results files live in :mod:`drivedyn.cli_commands`."""
    from drivedyn.cli_commands import COMMANDS
    from drivedyn.cli_torsen import COMMANDS as TORSEN_COMMANDS

    for cmd in COMMANDS + TORSEN_COMMANDS:
        main.add_command(cmd)


_attach_commands()


if __name__ == "__main__":  # pragma: no cover
    main()
