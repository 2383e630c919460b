"""``drivedyn validate``: run the validation cases, print the table, write the report."""

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

from drivedyn.cli.common import OutputFiles, check_output_path, console, fmt, jsonable


def _load_cases() -> dict[str, Any]:
    """Import the module that registers the validation cases and return the registry."""
    try:
        validation = importlib.import_module("drivedyn.validation")
    except Exception as exc:
        raise click.ClickException(
            f"cannot load the validation cases ({type(exc).__name__}: {exc})") from exc
    return validation.CASES


def _run(names: Sequence[str], quick: bool, figure_dir: str | None,
         err: Any) -> tuple[list[Any], dict[str, str]]:
    """Run the cases one by one (to show progress); a case that raises becomes a failed
    result whose ``source`` holds the exception."""
    case_result = _validation().CaseResult
    results: list[Any] = []
    errors: dict[str, str] = {}
    for name in names:
        t0 = time.perf_counter()
        with err.status(f"running case [bold]{name}[/bold] ..."):
            try:
                res = _validation().run_cases([name], quick, figure_dir)
            except Exception as exc:  # reported as a failed check, the others still run
                msg = f"{type(exc).__name__}: {exc}"
                errors[name] = msg
                res = [case_result(name, "case raised an exception", math.nan, math.nan, "",
                                   math.inf, 0.0, source=msg, wall_s=time.perf_counter() - t0)]
        if not res:
            errors[name] = "the case returned no results"
            res = [case_result(name, "case returned no results", math.nan, math.nan, "",
                               math.inf, 0.0, wall_s=time.perf_counter() - t0)]
        results += res
    return results, errors


def _table(results: list[Any]) -> Any:
    from rich.table import Table

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
            fmt(r.reference, ".7g"),
            fmt(r.simulated, ".7g"),
            r.unit,
            fmt(r.error, ".2e"),
            fmt(r.tolerance, ".1e"),
            "[green]PASS[/green]" if r.passed else "[bold red]FAIL[/bold red]",
            f"{r.wall_s:.2f}" if first else "",
        )
    return table


def _md(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def write_report(directory: Path, results: list[Any], errors: dict[str, str],
                 quick: bool) -> Path:
    """Write ``directory/report.md``: the results table and links to the case figures."""
    directory.mkdir(parents=True, exist_ok=True)
    npass = sum(r.passed for r in results)
    stamp = _dt.datetime.now().astimezone().isoformat(timespec="seconds")
    lines = [
        "# drivedyn validation report",
        "",
        f"drivedyn {_version()}, {stamp}, "
        f"{'quick' if quick else 'full'} run: **{npass} of {len(results)} checks passed**.",
        "",
        "Each row compares a quantity simulated by drivedyn with an exact solution or a "
        "published value (the *source* column). *error* is relative (absolute when the "
        "reference is 0); *tolerance* is the accuracy the integrator should reach at the step "
        "size the case uses, stated and justified next to each check in `src/drivedyn/validation/` "
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
            f"| {_md(r.case)} | {_md(r.quantity)} | {fmt(r.reference, '.7g')} "
            f"| {fmt(r.simulated, '.7g')} | {_md(r.unit)} | {fmt(r.error, '.2e')} "
            f"| {fmt(r.tolerance, '.1e')} | {'PASS' if r.passed else '**FAIL**'} "
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


@click.command()
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

    \b
    Examples:
        drivedyn validate
        drivedyn validate --quick --case pendulum --case gear_pair --report report
    """
    check_output_path(report, "--report", directory=True)
    out = console()
    err = console(stderr=True)
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
    figure_dir = None
    if report is not None:
        report.mkdir(parents=True, exist_ok=True)
        figure_dir = str(report)
    t0 = time.perf_counter()
    results, errors = _run(names, quick, figure_dir, err)
    wall = time.perf_counter() - t0
    failed = [r for r in results if not r.passed]
    if as_json:
        click.echo(json.dumps(jsonable([r.as_dict() for r in results]), indent=2))
    else:
        out.print(_table(results))
        for name, msg in errors.items():
            out.print(f"[red]case {name}: {msg}[/red]")
        verdict = "[green]all passed[/green]" if not failed else \
            f"[bold red]{len(failed)} failed[/bold red]"
        out.print(f"{len(results) - len(failed)} of {len(results)} checks passed "
                  f"({verdict}) in {wall:.1f} s")
    outputs = OutputFiles()  # a folder that refuses the report now: it goes to a fallback
    if report is not None:
        path = outputs.write(lambda d: write_report(d, results, errors, quick), report,
                             "--report", directory=True)
        err.print(f"report written to {path}", soft_wrap=True)  # a path is never wrapped
    if failed:
        sys.exit(1)
    outputs.exit_if_failed()




def _validation() -> Any:
    import drivedyn.validation

    return drivedyn.validation


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("drivedyn")
    except PackageNotFoundError:  # pragma: no cover - a source checkout
        return "unknown"
