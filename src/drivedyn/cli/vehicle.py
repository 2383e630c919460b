"""``drivedyn vehicle``: a vehicle model with one or several differential configurations,
a wheel-torque table and the acceptance checks: the 4WD vehicle on split-mu (and its
figures), or the RWD vehicle's scenarios (``--scenario static``, ``split-mu-launch`` or
``power-on-cornering``).

Exit codes: 0 success (every check passed), 1 a run failed or a check did not pass, 2 bad
input (file, key, value, configuration name).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import click

from drivedyn.cli.common import (
    EXIT_FAILED,
    FiniteFloat,
    OutputFiles,
    bad_input,
    check_output_path,
    console,
    jsonable,
)


@click.command()
@click.argument("model_file", metavar="FILE", default="vehicle-4wd")
@click.option("--compare", "configs", default=None, metavar="LIST",
              help="Comma-separated configurations to run on the same vehicle: open, locked, "
                   "clutch, torsen (all three positions of that type; torsen = Type C "
                   "central, Type B front and rear). Default: the file's differentials.")
@click.option("--t-end", type=FiniteFloat(0.0, low_open=True, unit="s"), default=None,
              metavar="S", help="Final time [s] (default: the file's run.t_end).")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE",
              help="Override a value of the file by dotted key, e.g. --set road.mu.fl=0.01 "
                   "--set 'load.torque=\"150 N m\"'. Repeatable.")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Folder for the results (one .nc per configuration) and the figures "
                   "(vehicle-4wd: wheel_torques.png, comparison.png; vehicle-rwd: the "
                   "dashboard of each run, <name>-<configuration>-dashboard.png).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
@click.option("--scenario", default=None, metavar="NAME",
              help="Scenario of a vehicle that has several (vehicle-rwd: static, "
                   "split-mu-launch, power-on-cornering; default split-mu-launch).")
def vehicle(model_file: str, configs: str | None, t_end: float | None, sets: tuple[str, ...],
            out: Path | None, as_json: bool, scenario: str | None) -> None:
    """Simulate a vehicle model FILE (default: the shipped vehicle-4wd) on its road and print
    the wheel torques, torque splits and checks over the file's steady window.

    \b
    Examples:
        drivedyn vehicle --compare open,locked,clutch,torsen --t-end 2.5 --out split-mu
        drivedyn vehicle --set body.speed=2 --set run.window=[0.5,0.8] --t-end 0.8
    """
    import drivedyn.analysis.vehicle_4wd as V  # noqa: N812 - short name for the analysis
    from drivedyn.cli.vehicle_runs import check_dicts, print_checks, simulate_configurations
    from drivedyn.config import ModelFileError, UnitError, read_library_file
    from drivedyn.config.loader import read_vehicle_differentials, resolve_path
    from drivedyn.library import vehicles
    from drivedyn.model.spec import ModelError

    check_output_path(out, "--out", directory=True)
    source = model_file
    try:
        p, _, source = read_library_file(model_file, list(sets))
        if p.model.library not in vehicles.TYPES:
            bad_input(f"{source}: model.library = {p.model.library!r} is not a vehicle "
                      f"(vehicles: {', '.join(vehicles.TYPES)})")
        if p.model.library == "vehicle_rwd":
            from drivedyn.cli.vehicle_rwd import run_rwd

            run_rwd(p, source, model_file, configs, t_end, sets, out, as_json, scenario)
            return
        if scenario is not None:
            bad_input(f"--scenario: {source} has one scenario (split-mu); got {scenario!r}")
        names = [c.strip() for c in configs.split(",")] if configs else []
        for c in names:
            if c not in V.CONFIGS:
                bad_input(f"--compare: unknown configuration {c!r} (expected a comma-separated "
                          f"list of {', '.join(V.CONFIGS)})")
        base = resolve_path(model_file).parent
        variants = [V.configure(p, c) for c in names] or [p]
        torsen = {}
        for q in variants:
            torsen.update(read_vehicle_differentials(q, source, base))
            mod = vehicles.get(q.model.library)
            mod.check_parameters(q)
            mod.load_tyre(q, base)
    except ModelFileError as exc:  # names the file already
        bad_input(str(exc))
    except (ModelError, UnitError) as exc:
        bad_input(f"{source}: {exc}")
    t_final = p.run.t_end if t_end is None else t_end
    if p.run.window[1] > t_final + 1e-12:
        bad_input(f"{source}: run.window = {list(p.run.window)} s ends after the final time "
                  f"{t_final:g} s; set --t-end or run.window")
    a, b = (x / V.OUTPUT_DT for x in p.run.window)
    if math.floor(b + 1e-9) - math.ceil(a - 1e-9) + 1 < 3:
        bad_input(f"{source}: run.window = {list(p.run.window)} s holds fewer than 3 of the "
                  f"samples recorded every {V.OUTPUT_DT * 1e3:g} ms (the window means need "
                  "3); widen it")
    outputs = OutputFiles()  # a folder that refuses the results now: they go to a fallback
    summaries, runs, failed = simulate_configurations(
        V, p.model.name, variants, torsen, base, t_final, lambda q: q.run.window, source,
        sets, out, outputs)
    results = [{"configuration": s.name, "wheels": {w: vars(x) for w, x in s.wheels.items()},
                "front_share": s.front_share, "axle_ratio": s.axle_ratio,
                "central_ratio": s.central_ratio, "central_slip": s.central_slip,
                "traction": s.traction, "speed": s.speed,
                "torque_balance": s.torque_balance, "power_balance": s.power_balance,
                "energy_error": s.energy_error, "wall": s.wall, "steps": s.steps,
                "checks": check_dicts(V.checks(s))} for s in summaries]
    ok = not failed and all(c["passed"] for r in results for c in r["checks"])
    if out is not None and runs:
        from drivedyn.plots.vehicle_4wd import comparison_figure, save, wheel_torques_figure

        figures = {"wheel_torques.png": wheel_torques_figure(runs, p.run.window),
                   "comparison.png": comparison_figure(summaries)}
        outputs.write(lambda d: [save(f, d / n) for n, f in figures.items()], out, "--out",
                      directory=True)
    if as_json:
        click.echo(json.dumps(jsonable({"model": p.model.name, "window": p.run.window,
                                        "runs": results, "passed": ok})))
    else:
        con = console()
        con.print(f"window {p.run.window[0]:g}-{p.run.window[1]:g} s (means)\n")
        con.print(V.table(summaries))
        print_checks(con, V, summaries)
        if out is not None:
            where = outputs.path(out)
            con.print(f"\nresults and figures: {out}"  # paths are never wrapped
                      + (f"; what it refused: {where}" if where != out else ""), soft_wrap=True)
    if not ok:
        sys.exit(EXIT_FAILED)
    outputs.exit_if_failed()
