"""``drivedyn vehicle vehicle-rwd --scenario power-on-cornering``: the steady circle and the
throttle ramp for each configuration, a table or one JSON object
(:mod:`drivedyn.analysis.vehicle_rwd_cornering`).

JSON: ``{"model", "scenario", "runs": [...], "passed"}``; each run has ``configuration``,
the power window's ``wheels.{fl,fr,rl,rr}.{torque,fx,fy,fz,spin,kappa,alpha}``,
``axle_ratio.rear``, ``inner_share``, ``yaw_rate``, ``lateral_acceleration``, ``radius``,
``speed``, the same of the steady circle under ``steady``, ``tdr``, cost, a ``history``
every :data:`HISTORY_DT` and ``checks[j].{check,value,limit,passed}``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import click
from pydantic import ValidationError

from drivedyn.cli.common import EXIT_FAILED, OutputFiles, bad_input, console, err, jsonable

#: interval [s] of the time history in the JSON output
HISTORY_DT = 0.05


def _thinned(history: dict[str, list[float]]) -> dict[str, list[float]]:
    """The time history every :data:`HISTORY_DT`."""
    t = history.get("time", [])
    keep, next_t = [], -1.0
    for i, ti in enumerate(t):
        if ti >= next_t - 1e-9:
            keep.append(i)
            next_t = ti + HISTORY_DT
    return {k: [v[i] for i in keep] for k, v in history.items()}


def _run_dict(s: Any, checks: list[tuple[str, float, float, bool]]) -> dict[str, Any]:
    from drivedyn.analysis.vehicle_rwd_cornering import window_dict

    power = window_dict(s.power)
    return {"configuration": s.name, **power, "steady": window_dict(s.steady), "tdr": s.tdr,
            "wall": s.wall, "steps": s.steps, "rejected": s.rejected, "unknowns": s.unknowns,
            "history": _thinned(s.history),
            "checks": [dict(zip(("check", "value", "limit", "passed"), c, strict=True))
                       for c in checks]}


def with_t_end(p: Any, t_end: float | None) -> Any:
    """``p`` with the scenario's ``t_end`` replaced by ``--t-end`` (checked against its
    windows: exit 2 naming the keys)."""
    from drivedyn.library.vehicles.vehicle_rwd.scenario_schema import PowerOnCornering

    if t_end is None:
        return p
    c = p.scenarios.power_on_cornering
    try:
        c = PowerOnCornering.model_validate({**c.model_dump(), "t_end": t_end})
    except ValidationError as exc:
        msg = "; ".join(e["msg"].removeprefix("Value error, ") for e in exc.errors())
        bad_input(f"--t-end {t_end:g}: scenarios.power_on_cornering: {msg}")
    sc = p.scenarios.model_copy(update={"power_on_cornering": c})
    return p.model_copy(update={"scenarios": sc})


def run_cornering(p: Any, source: str, variants: list[Any], torsen: dict, base: Path,
                  t_end: float | None, sets: tuple[str, ...], out: Path | None,
                  as_json: bool) -> None:
    """Run the scenario for each of ``variants`` (``p`` with each configuration); print a
    table or one JSON object; exit 1 when a run fails or a check does not pass."""
    import drivedyn.analysis.vehicle_rwd_cornering as C  # noqa: N812 - the analysis
    from drivedyn.cli.progress import progress_bar
    from drivedyn.library.vehicles.vehicle_rwd.configurations import config_name
    from drivedyn.model.spec import ModelError
    from drivedyn.results.results import write_netcdf_atomic

    summaries, failed = [], False
    outputs = OutputFiles()
    for q in variants:
        q = with_t_end(q, t_end)
        c = q.scenarios.power_on_cornering
        label = config_name(q)
        err(f"simulating {p.model.name} [{label}] {C.SCENARIO} to t = {c.t_end:g} s")
        try:
            with progress_bar(c.t_end) as cb:
                res, lay, cor = C.run(q, torsen, base, progress=cb, source=source,
                                      overrides=list(sets))
        except ModelError as exc:
            bad_input(f"{source}: {exc}")
        if out is not None:
            name = f"{p.model.name}-{C.SCENARIO}-{label}" + (".nc" if res.success
                                                               else ".partial.nc")
            outputs.write(lambda d, res=res, name=name: write_netcdf_atomic(res.dataset, d / name),
                          out, "--out", directory=True)
        if not res.success:
            err(f"[{label}] FAILED: {res.message}")
            failed = True
            continue
        summaries.append(C.summarize(res, lay, cor, c))
    results = [_run_dict(s, C.checks(s)) for s in summaries]
    ok = not failed and all(c["passed"] for r in results for c in r["checks"])
    if as_json:
        click.echo(json.dumps(jsonable({"model": p.model.name, "scenario": C.SCENARIO,
                                        "runs": results, "passed": ok})))
    else:
        con = console()
        con.print(C.table(summaries), markup=False)  # the units' brackets are not markup
        for s in summaries:
            for name, value, limit, passed in C.checks(s):
                mark = "ok  " if passed else "FAIL"
                con.print(f"  {mark} [{s.name}] {name}: {value:.4g} (limit {limit:.4g})",
                          markup=False)
    if not ok:
        sys.exit(EXIT_FAILED)
    outputs.exit_if_failed()
