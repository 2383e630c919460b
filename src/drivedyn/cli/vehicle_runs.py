"""The part of ``drivedyn vehicle`` every vehicle shares: simulate each configuration with a
progress bar, write its results to ``--out`` (a ``.partial.nc`` for a run that failed, a
fallback folder for one the folder refuses), summarise the runs that finished, and print
the acceptance checks."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from types import ModuleType
from typing import Any

from drivedyn.cli.common import OutputFiles, bad_input, err


def simulate_configurations(analysis: ModuleType, name: str, variants: Sequence[Any],
                            torsen: dict, base: Path, t_final: float,
                            window: Callable[[Any], tuple[float, float]] | tuple[float, float],
                            source: str, sets: Sequence[str], out: Path | None,
                            outputs: OutputFiles, what: str = ""
                            ) -> tuple[list[Any], list[tuple[str, Any]], bool]:
    """Run each file of ``variants`` (one per configuration) with ``analysis.run`` to
    ``t_final`` [s]; summaries over ``window`` [s] (or ``window(file)``).

    Returns (summaries of the finished runs, [(configuration, results)] of them, whether a
    run failed). A run that fails is reported with its reason and its partial results are
    kept; a model the builder refuses is bad input (exit 2)."""
    from drivedyn.cli.progress import progress_bar
    from drivedyn.model.spec import ModelError
    from drivedyn.results.results import write_netcdf_atomic

    summaries, runs, failed = [], [], False
    for q in variants:
        label = analysis.config_name(q)
        err(f"simulating {name} [{label}]{' ' + what if what else ''} to t = {t_final:g} s")
        try:
            with progress_bar(t_final) as cb:
                res, lay = analysis.run(q, torsen, base, t_end=t_final, progress=cb,
                                        source=source, overrides=list(sets))
        except ModelError as exc:
            bad_input(f"{source}: {exc}")
        if out is not None:
            fname = f"{name}-{label}" + (".nc" if res.success else ".partial.nc")
            outputs.write(lambda d, res=res, fname=fname:
                          write_netcdf_atomic(res.dataset, d / fname),
                          out, "--out", directory=True)
        if not res.success:
            err(f"[{label}] FAILED: {res.message}")
            failed = True
            continue
        summaries.append(analysis.summarize(res, lay, window(q) if callable(window)
                                            else window))
        runs.append((label, res))
    return summaries, runs, failed


def print_checks(con: Any, analysis: ModuleType, summaries: Sequence[Any]) -> None:
    """The acceptance checks of each summary, one line each (``ok`` or ``FAIL``)."""
    for s in summaries:
        for check, value, limit, passed in analysis.checks(s):
            mark = "ok  " if passed else "FAIL"
            con.print(f"  {mark} {check}: {value:.4g} (limit {limit:.4g})")


def check_dicts(checks: Sequence[tuple[str, float, float, bool]]) -> list[dict[str, Any]]:
    """Checks as JSON objects ``{check, value, limit, passed}``."""
    return [dict(zip(("check", "value", "limit", "passed"), c, strict=True)) for c in checks]


__all__ = ["check_dicts", "print_checks", "simulate_configurations"]
