"""The RWD vehicle's part of ``drivedyn vehicle``: the ``static`` and ``split-mu-launch``
scenarios, with one or several rear differentials (``--compare``)."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import click

from drivedyn.cli.common import EXIT_FAILED, OutputFiles, bad_input, console, err, jsonable

#: interval [s] of the rear wheel torques' time history in the JSON output
HISTORY_DT = 0.05


def _thinned(history: dict[str, list[float]]) -> dict[str, list[float]]:
    """The time history (``time``, ``torque_rl``, ``torque_rr``, ``spin_*``, ``kappa_*``,
    ``speed``, ``yaw_rate``, ``drift``) every :data:`HISTORY_DT`."""
    t = history.get("time", [])
    keep, next_t = [], -1.0
    for i, ti in enumerate(t):
        if ti >= next_t - 1e-9:
            keep.append(i)
            next_t = ti + HISTORY_DT
    return {k: [v[i] for i in keep] for k, v in history.items()}


def run_rwd(p: Any, source: str, model_file: str, configs: str | None, t_end: float | None,
            sets: tuple[str, ...], out: Path | None, as_json: bool,
            scenario: str | None) -> None:
    """Run ``scenario`` of the RWD vehicle ``p`` (read from ``source``); print a table or
    one JSON object; exit 1 when a run fails or a check does not pass, 2 on bad input."""
    import drivedyn.analysis.vehicle_rwd as V  # noqa: N812 - short name for the analysis
    from drivedyn.cli.vehicle_runs import check_dicts, print_checks, simulate_configurations
    from drivedyn.config import ModelFileError, UnitError
    from drivedyn.config.loader import read_vehicle_differentials, resolve_path
    from drivedyn.library.vehicles.vehicle_rwd import check_parameters, tyre_notes
    from drivedyn.model.spec import ModelError
    from drivedyn.plots.dashboard import save_dashboard
    from drivedyn.solver.statics import StaticsError

    scenario = scenario or "split-mu-launch"
    if scenario not in V.SCENARIOS:
        bad_input(f"--scenario: unknown scenario {scenario!r} (expected one of "
                  f"{', '.join(V.SCENARIOS)})")
    names = [c.strip() for c in configs.split(",")] if configs else []
    for c in names:
        if c not in V.CONFIGS:
            bad_input(f"--compare: unknown configuration {c!r} (expected a comma-separated "
                      f"list of {', '.join(V.CONFIGS)})")
    base = resolve_path(model_file).parent
    variants = [V.configure(p, c) for c in names] or [p]
    torsen: dict[str, Any] = {}
    try:
        for q in variants:
            torsen.update(read_vehicle_differentials(q, source, base))
            check_parameters(q, base)
        notes = tyre_notes(p, base)
    except ModelFileError as exc:
        bad_input(str(exc))
    except (ModelError, UnitError) as exc:
        bad_input(f"{source}: {exc}")
    for note in notes:
        err(f"note: {note}")
    if scenario == "power-on-cornering":
        from drivedyn.cli.vehicle_rwd_cornering import run_cornering

        return run_cornering(p, source, variants, torsen, base, t_end, sets, out, as_json)
    if scenario == "static":
        results = []
        for q in variants:
            try:
                s = V.static(q, torsen, base)
            except StaticsError as exc:
                err(f"[{V.config_name(q)}] FAILED: {exc}")
                sys.exit(EXIT_FAILED)
            results.append({"configuration": V.config_name(q), "mass": s.mass, "cg": s.cg,
                            "loads": s.loads, "rear_share": s.rear_share,
                            "rear_share_cg": s.rear_share_cg, "unknowns": s.unknowns,
                            "wall": s.wall, "note": s.note,
                            "wheel_centres": s.wheel_centres,
                            "checks": check_dicts(V.static_checks(s))})
        ok = all(c["passed"] for r in results for c in r["checks"])
        if as_json:
            click.echo(json.dumps(jsonable({"model": p.model.name, "scenario": scenario,
                                            "runs": results, "passed": ok})))
        else:
            con = console()
            for r in results:
                con.print(f"[{r['configuration']}] mass {r['mass']:.2f} kg, cg "
                          f"{', '.join(f'{c:.4f}' for c in r['cg'])} m")
                con.print("  wheel loads [N]: " + ", ".join(f"{w} {f:.1f}"
                                                            for w, f in r["loads"].items()))
                for c in r["checks"]:
                    mark = "ok  " if c["passed"] else "FAIL"
                    con.print(f"  {mark} {c['check']}: {c['value']:.3g} (limit "
                              f"{c['limit']:.3g})")
        if not ok:
            sys.exit(EXIT_FAILED)
        return
    t_final = p.run.t_end if t_end is None else t_end
    if p.run.window[1] > t_final + 1e-12:
        window = (min(p.run.window[0], 0.5 * t_final), t_final)
        err(f"run.window = {list(p.run.window)} s ends after the final time {t_final:g} s: "
            f"the means are taken over {window[0]:g}-{window[1]:g} s")
    else:
        window = p.run.window
    outputs = OutputFiles()
    summaries, runs, failed = simulate_configurations(V, p.model.name, variants, torsen, base,
                                                      t_final, window, source, sets, out,
                                                      outputs, what=scenario)
    for label, res in runs if out is not None else ():  # the dashboard beside each .nc
        stem = f"{p.model.name}-{label}"
        outputs.write(lambda d, res=res, stem=stem: save_dashboard(res.dataset, d, stem),
                      out, "--out", directory=True)
    results = [{"configuration": s.name, "wheels": {w: vars(x) for w, x in s.wheels.items()},
                "axle_ratio": s.axle_ratio, "left_share": s.left_share, "speed": s.speed,
                "yaw_rate": s.yaw_rate, "drift": s.drift, "tdr": s.tdr, "wall": s.wall,
                "steps": s.steps, "rejected": s.rejected,
                "unknowns": s.unknowns, "history": _thinned(s.history),
                "checks": check_dicts(V.checks(s))}
               for s in summaries]
    ok = not failed and all(c["passed"] for r in results for c in r["checks"])
    if as_json:
        click.echo(json.dumps(jsonable({"model": p.model.name, "scenario": scenario,
                                        "window": window, "runs": results, "passed": ok})))
    else:
        con = console()
        con.print(f"window {window[0]:g}-{window[1]:g} s (means)\n")
        con.print(V.table(summaries))
        print_checks(con, V, summaries)
    if not ok:
        sys.exit(EXIT_FAILED)
    outputs.exit_if_failed()
