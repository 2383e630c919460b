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


def _failed(name: str, what: str, msg: str | None, wall_s: float) -> Any:
    """One failed result of case ``name`` (``what`` happened; ``msg`` in its source)."""
    return _validation().CaseResult(name, what, math.nan, math.nan, "", math.inf, 0.0,
                                    source=msg or "", wall_s=wall_s)


def _run_case(name: str, quick: bool, figure_dir: str | None) -> tuple[list[Any], str | None]:
    """Results of one case and the error message (None without): a case that raises, or
    returns nothing, becomes one failed result whose ``source`` holds the message."""
    t0 = time.perf_counter()
    try:
        res = _validation().run_cases([name], quick, figure_dir)
    except Exception as exc:  # reported as a failed check, the others still run
        msg = f"{type(exc).__name__}: {exc}"
        return [_failed(name, "case raised an exception", msg, time.perf_counter() - t0)], msg
    if not res:
        return ([_failed(name, "case returned no results", None, time.perf_counter() - t0)],
                "the case returned no results")
    return res, None


def _one_blas_thread() -> None:
    """Initializer of a case process: one BLAS thread (OpenBLAS's threads wait spinning; two
    processes of two threads each on two cores slow each other down many times)."""
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1, user_api="blas")


def default_jobs() -> int:
    """Processes ``drivedyn validate`` uses by default: the CPUs this process may run on."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def _run(names: Sequence[str], quick: bool, figure_dir: str | None, err: Any,
         jobs: int = 1) -> tuple[list[Any], dict[str, str]]:
    """Run the cases, ``jobs`` at a time (each in its own process when ``jobs`` > 1, started
    fresh: ``spawn``), and return their results in the order of ``names`` with the error
    message of every case that raised. A case's figures are its own, so the results do
    not depend on ``jobs`` (``tests/files_cli/test_cli.py``)."""
    outcome: dict[str, tuple[list[Any], str | None]] = {}
    jobs = max(1, min(jobs, len(names)))
    if jobs == 1:
        for name in names:
            with err.status(f"running case [bold]{name}[/bold] ..."):
                outcome[name] = _run_case(name, quick, figure_dir)
    else:
        import concurrent.futures as cf
        import multiprocessing as mp

        with cf.ProcessPoolExecutor(max_workers=jobs, mp_context=mp.get_context("spawn"),
                                    initializer=_one_blas_thread) as pool, \
                err.status(f"running {len(names)} cases in {jobs} processes ...") as status:
            # the last cases registered (vehicles) are the longest: submitted first, the
            # processes end together instead of one running a vehicle alone at the end
            futures = {pool.submit(_run_case, name, quick, figure_dir): name
                       for name in reversed(names)}
            for future in cf.as_completed(futures):
                name = futures[future]
                try:
                    outcome[name] = future.result()
                except Exception as exc:  # the process died (killed, out of memory)
                    msg = f"{type(exc).__name__}: {exc}"
                    outcome[name] = ([_failed(name, "case raised an exception", msg, 0.0)],
                                     msg)
                status.update(f"{len(outcome)} of {len(names)} cases done in {jobs} "
                              f"processes (last: [bold]{name}[/bold]) ...")
    results: list[Any] = []
    errors: dict[str, str] = {}
    for name in names:
        res, msg = outcome[name]
        results += res
        if msg is not None:
            errors[name] = msg
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
            {"PASS": "[green]PASS[/green]", "GAP": "[yellow]GAP[/yellow]"}.get(
                r.status, "[bold red]FAIL[/bold red]"),
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
    gaps = [r for r in results if r.status == "GAP"]
    stamp = _dt.datetime.now().astimezone().isoformat(timespec="seconds")
    lines = [
        "# drivedyn validation report",
        "",
        f"drivedyn {_version()}, {stamp}, "
        f"{'quick' if quick else 'full'} run: **{npass} of {len(results)} checks passed**"
        + (f", of which {len(gaps)} documented gap(s) between a calibrated model and a "
           "measurement (GAP: reported, not a check; see their source)" if gaps else "") + ".",
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
            f"| {fmt(r.tolerance, '.1e')} | {r.status if r.passed else '**FAIL**'} "
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
@click.option("--jobs", "-j", type=click.IntRange(min=1), default=None, metavar="N",
              help="Run N cases at the same time, each in its own process "
                   "(default: one per CPU; 1: one after the other in this process).")
def validate(quick: bool, cases: tuple[str, ...], report: Path | None, as_json: bool,
             jobs: int | None) -> None:
    """Compare simulated quantities with exact or published references.

    Prints one row per checked quantity (reference, simulated value, error, tolerance,
    PASS/FAIL and the case's wall time). Exits with 0 if every check passes, 1 otherwise.
    The cases run one per CPU at the same time (--jobs); the table keeps their order.

    \b
    Examples:
        drivedyn validate
        drivedyn validate --quick --case pendulum --case gear_pair --report report
        drivedyn validate --jobs 1
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
    results, errors = _run(names, quick, figure_dir, err,
                           default_jobs() if jobs is None else jobs)
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
        gaps = sum(r.status == "GAP" for r in results)
        gap_txt = (f"; {gaps} documented gap(s) between a calibrated model and a measurement "
                   "(GAP: reported, not checks)" if gaps else "")
        out.print(f"{len(results) - len(failed)} of {len(results)} checks passed "
                  f"({verdict}{gap_txt}) in {wall:.1f} s")
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
