"""``drivedyn fmu``: build an FMI 2.0 co-simulation FMU of a model (:mod:`drivedyn.fmu`)."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from drivedyn.cli.common import EXIT_FAILED, OutputFiles, bad_input, check_output_path, err


@click.command()
@click.argument("model_file", metavar="MODEL")
@click.option("--out", type=click.Path(dir_okay=False, path_type=Path), default=None,
              metavar="NAME.fmu",
              help="The FMU to write (default: the model's name with '_' for '-', .fmu, in "
                   "the current folder); its name, less .fmu, is the FMU's model identifier.")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE",
              help="Override a parameter of the model file by its dotted key before the "
                   "export, e.g. --set pockets.mu=0.12. Repeatable.")
def fmu(model_file: str, out: Path | None, sets: tuple[str, ...]) -> None:
    """Build an FMI 2.0 co-simulation FMU of a model, for FMPy, Simulink, Dymola,
    OpenModelica, CarMaker and other FMI tools.

    MODEL is a differential, 4WD or RWD vehicle model file or a shipped one by name
    (torsen-b, torsen-c, vehicle-4wd, vehicle-rwd). A differential's inputs: input_torque
    [N m] on the housing and the output speeds [rad/s] (left_speed, right_speed; Type C:
    front_speed, rear_speed),
    held over each communication step; outputs: the torques the outputs deliver to their
    shafts [N m], input_speed [rad/s] of the housing, tdr and the thrust washers' normal
    forces [N]; parameters: the model file's friction coefficients (the initial speeds are
    the speed inputs' values at initialisation, see docs/fmu.md). The
    4WD vehicle's inputs: engine_torque [N m] and the road friction under each wheel (mu_fl
    ... mu_rr); outputs: the wheels' drive torques and spin rates, vehicle_speed [m/s]. The
    RWD vehicle's inputs: throttle [1] (0 to 1, on the engine's maps) and the road friction
    under each wheel; outputs: the rear wheels' drive torques, every wheel's spin rate, tyre
    force fx and load fz [N], vehicle_speed [m/s] and yaw_rate [rad/s]; it starts from the
    parked vehicle's static equilibrium as drivedyn vehicle does. Between communication
    points the FMU integrates the model with drivedyn's own step control. The FMU runs
    drivedyn in Python: drivedyn (with pythonfmu) must be installed in the Python that
    loads it (see docs/fmu.md).

    \b
    Examples:
        drivedyn fmu torsen-b --out torsen_b.fmu
        drivedyn fmu torsen-c --out torsen_c.fmu --set pockets.mu=0.15
        drivedyn fmu vehicle-4wd --out vehicle_4wd.fmu
        drivedyn fmu vehicle-rwd --out rwd.fmu --set differentials.rear=open
    """
    from drivedyn.config import ModelFileError
    from drivedyn.fmu import FmuError, build_fmu, model_identifier
    from drivedyn.fmu.build import fmu_kind, parse_overrides
    from drivedyn.model.spec import ModelError

    if out is None:
        out = Path(f"{Path(model_file).stem.replace('-', '_')}.fmu")
    check_output_path(out, "--out")
    if out.suffix.lower() != ".fmu":
        bad_input(f"--out {out}: expected a file name ending in .fmu")
    try:
        import pythonfmu  # noqa: F401
    except ImportError:
        err("error: building an FMU needs pythonfmu: pip install 'drivedyn[fmu]'")
        sys.exit(EXIT_FAILED)
    try:
        overrides = parse_overrides(sets)
        _, cosim = fmu_kind(model_file, overrides)
    except (ModelFileError, FmuError) as exc:  # name the file already
        bad_input(str(exc))
    except ModelError as exc:
        bad_input(f"{model_file}: {exc}")
    outputs = OutputFiles()
    written = outputs.write(lambda path: build_fmu(model_file, path, overrides), out, "--out")
    click.echo(f"FMU written to {written} (model identifier {model_identifier(written)}, "
               f"FMI 2.0 co-simulation): {cosim.title}")
    for causality in ("input", "output", "parameter"):
        items = [v for v in cosim.variables() if v.causality == causality]
        if items:
            click.echo(f"  {causality}s: " + ", ".join(f"{v.name} [{v.unit}]" for v in items))
    click.echo("  drivedyn (with pythonfmu) must be installed in the Python that loads it")
    outputs.exit_if_failed()
