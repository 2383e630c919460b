"""CLI commands on model and results files: ``run``, ``plot``, ``models``.

Exit codes: 0 success, 1 simulation failure or interruption (partial results are still
written), or an output that its path refused after the run (written to a fallback file, named
in the message), 2 bad input (unreadable or invalid model file, impossible model, bad option,
an output path that cannot be written: refused before the run starts).
"""

from __future__ import annotations

import fnmatch
import json
import logging
import math
import sys
import warnings
from pathlib import Path

import click
import numpy as np

from drivedyn.cli.common import (
    EXIT_FAILED,
    FiniteFloat,
    OutputFiles,
    bad_input,
    check_output_path,
    err,
)
from drivedyn.errors import did_you_mean


def _finite(x: float) -> float | None:
    return x if math.isfinite(x) else None


def _summary(res, out: Path | None) -> dict:
    ds = res.dataset
    final = {}
    for name, var in ds.data_vars.items():
        vals = np.asarray(var.values)
        if vals.size and vals.ndim <= 2:
            last = vals[-1]
            final[str(name)] = ([_finite(float(v)) for v in np.atleast_1d(last)]
                                if np.ndim(last) else _finite(float(last)))
    from drivedyn.results.metrics import run_metrics

    st = res.stats
    metrics = run_metrics(res)
    return {
        "success": res.success,
        "message": res.message,
        "t_final": float(res.time[-1]) if len(res.time) else None,
        "steps": st.steps,
        "rejected_steps": st.rejected,
        "newton_iterations": st.newton_iterations,
        "factorizations": st.factorizations,
        "wall_s": st.wall_s,
        "energy_balance_error": _finite(float(ds["energy.balance_error"].values[-1]))
        if len(res.time) else None,
        "dissipated_energy": _finite(metrics["dissipated_energy"]),
        "peak_pressure": _finite(metrics["peak_pressure"]),
        "peak_pressure_at": metrics["peak_pressure_at"] or None,
        "results_file": str(out) if out else None,
        "redundant_constraints": [r for r in ds.attrs.get("redundant_constraints",
                                                           "").split("; ") if r],
        "redundant_constraints_changes": ds.attrs.get("redundant_constraints_changes", ""),
        "final": final,
    }


@click.command()
@click.argument("model_file", metavar="FILE")
@click.option("--out", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Results file (netCDF). Default: <model name>.nc in the current folder; a "
                   "failed or interrupted run writes <name>.partial.nc instead.")
@click.option("--t-end", type=FiniteFloat(0.0, low_open=True, unit="s"), default=None,
              help="Final time [s] (overrides the file).")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE",
              help="Override a value of the file by dotted key, e.g. --set solver.t_end=2 "
                   "--set 'bodies.rod.mass=\"2 kg\"' (list items by name). Repeatable.")
@click.option("--csv", "csv_path", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="Also write the time histories to this CSV file.")
@click.option("--json", "as_json", is_flag=True,
              help="Print a JSON summary (steps, Newton iterations, wall time, energy balance "
                   "error, final values of every sensor) instead of text.")
@click.option("--verbose", "-v", is_flag=True, help="Log every step's Newton statistics.")
def run(model_file: str, out: Path | None, t_end: float | None, sets: tuple[str, ...],
        csv_path: Path | None, as_json: bool, verbose: bool) -> None:
    """Simulate the scenario of a model FILE (TOML, or the name of a shipped model).

    \b
    Example:
        drivedyn run pendulum --t-end 5 --set solver.rho_inf=0.8 --out pendulum.nc
    """
    from drivedyn.cli.progress import progress_bar
    from drivedyn.config import ModelFileError, UnitError, load_model
    from drivedyn.model.spec import ModelError
    from drivedyn.results.provenance import record_provenance
    from drivedyn.results.results import write_netcdf_atomic
    from drivedyn.solver.simulate import MAX_OUTPUTS, InitializationError, simulate

    if verbose:
        logging.basicConfig(level=logging.DEBUG, format="%(message)s", stream=sys.stderr)
        logging.getLogger("drivedyn").setLevel(logging.DEBUG)
    # output paths are checked before anything runs, so a long run is never lost to a typo
    check_output_path(out, "--out")
    check_output_path(csv_path, "--csv")
    try:
        with warnings.catch_warnings():  # the deprecation notes are printed below
            warnings.simplefilter("ignore", DeprecationWarning)
            model = load_model(model_file, list(sets))
    except (ModelFileError, ModelError, UnitError) as exc:
        bad_input(str(exc))
    for note in model.meta.get("notes", ()):
        err(f"note: {note}")
    scenario = model.meta["scenario"]
    t_final = t_end if t_end is not None else scenario.t_end
    h_fixed = getattr(scenario.step, "h", None)
    if h_fixed is not None and h_fixed > t_final:
        bad_input(f"--t-end {t_final:g} s is shorter than the step solver.step.h = "
                  f"{h_fixed:g} s")
    if scenario.output_dt is not None and t_final / scenario.output_dt > MAX_OUTPUTS:
        key = "solver.output_dt" if model.meta.get("library") is not None else "output.dt"
        bad_input(f"{model.meta['source']}: {key} = {scenario.output_dt:g} s records "
                  f"{t_final / scenario.output_dt:.3g} samples up to t = {t_final:g} s (at most "
                  f"{MAX_OUTPUTS:.0e}); a longer output interval")
    name = model.meta.get("model_name", "model")
    target = out or Path(f"{name}.nc")
    check_output_path(target, "--out")
    for g in model.groups:
        for part in g.extra.get("parts", ()):
            err(part.check_text())
    err(f"simulating {name} to t = {t_final:g} s")
    try:
        with progress_bar(t_final) as cb:
            res = simulate(model, t_final, progress=cb)
    except InitializationError as exc:
        bad_input(str(exc))
    except KeyboardInterrupt:  # before the time loop (kernel loading, initial state)
        err("interrupted before the first step: nothing to write")
        sys.exit(EXIT_FAILED)
    record_provenance(res, model_file=model.meta["model_file"],
                      source=model.meta["source"], overrides=list(sets),
                      library_model=model.meta.get("library_model"),
                      configuration=model.meta.get("configuration"))
    if not res.success:
        target = target.with_name(target.stem + ".partial.nc")
    outputs = OutputFiles()  # a path that refuses the write now: the run goes to a fallback
    target = outputs.write(lambda p: write_netcdf_atomic(res.dataset, p), target, "--out")
    if csv_path is not None:
        csv_path = outputs.write(res.to_csv, csv_path, "--csv")
    summary = _summary(res, target)
    if as_json:
        click.echo(json.dumps(summary))
    else:
        state = "done" if res.success else f"FAILED: {res.message}"
        st = res.stats
        click.echo(f"{state}\n  steps {st.steps} (rejected {st.rejected}), Newton iterations "
                   f"{st.newton_iterations}, factorizations {st.factorizations}, wall "
                   f"{st.wall_s:.3g} s\n  energy balance error "
                   f"{summary['energy_balance_error']:.3g} J\n  results: {target}")
        red = summary["redundant_constraints"]
        if red:
            click.echo(f"  {len(red)} redundant constraint row(s) set aside (their joints' "
                       f"reactions are not unique): {', '.join(red)}")
    if not res.success:
        sys.exit(EXIT_FAILED)
    outputs.exit_if_failed()


def _sweep_dataset(path: Path):
    """The Dataset of a ``drivedyn sweep`` results file, or None for any other file."""
    import xarray as xr

    try:
        with xr.open_dataset(path) as ds:
            if ds.attrs.get("drivedyn_kind") != "sweep":
                return None
            return ds.load()
    except (OSError, ValueError):
        return None


@click.command()
@click.argument("results_file", type=click.Path(exists=True, dir_okay=False, path_type=Path),
                metavar="RESULTS.nc")
@click.option("--out", "out_dir", type=click.Path(file_okay=False, path_type=Path),
              default=Path("plots"), show_default=True, help="Folder for the PNG files.")
@click.option("--vars", "patterns", multiple=True, metavar="PATTERN",
              help="Variables to plot (glob patterns, e.g. 'crank.*' or '*.torque'), drawn "
                   "with the same quantity and unit rules; default: the engineering figures "
                   "(energy budget, bodies, joints, contacts, gears...) and the dashboard of "
                   "the library model the run comes from.")
@click.option("--stress", "stress_elements", multiple=True, metavar="ELEMENT",
              help="Beam element whose outer-fibre stresses and section forces to draw "
                   "(repeatable; 'list' lists the beam elements).")
@click.option("--shape", is_flag=True, help="Snapshots of the deformed beams.")
@click.option("--scale", type=FiniteFloat(), default=1.0, show_default=True,
              help="Deformation scale factor of --shape.")
@click.option("--snapshots", type=click.IntRange(1, 50), default=4, show_default=True,
              help="Number of instants drawn by --shape and --part.")
@click.option("--pressure", "pressure_contacts", multiple=True, metavar="CONTACT",
              help="Flexible washer contact whose pressure map and history to draw "
                   "(repeatable; 'list' lists them).")
@click.option("--part", "parts", multiple=True, metavar="PART",
              help="Meshed flexible part to draw deformed and stress-coloured (repeatable; "
                   "'list' lists them).")
@click.option("--vtu", "vtu_parts", multiple=True, metavar="PART",
              help="Write the deformed, stress-coloured PART at every output time as VTU "
                   "files with a PVD index for ParaView (into OUT/vtu).")
def plot(results_file: Path, out_dir: Path, patterns: tuple[str, ...],
         stress_elements: tuple[str, ...], shape: bool, scale: float, snapshots: int,
         pressure_contacts: tuple[str, ...], parts: tuple[str, ...],
         vtu_parts: tuple[str, ...]) -> None:
    """Write PNG figures of a results file: what an engineer reads (joint angles and speeds,
    forces and torques, gaps and pressures, dissipated power, the energy budget) in units
    with SI prefixes chosen by magnitude, one figure per category, and the dashboard of a
    library model (differential: torques, TDR, speeds, axial travel, washers, losses;
    vehicle: wheel torques, slips, speeds, splits); see docs/plots.md. For a `drivedyn
    sweep` file: line plots, heat maps, histograms or a tornado chart; for beams, the stress
    history of chosen elements and snapshots of the deformed shape; for meshed flexible
    parts, pressure maps, stress snapshots and ParaView files.

    \b
    Examples:
        drivedyn plot torsen-c.nc --out figs
        drivedyn plot pendulum.nc --vars 'rod.*' --vars 'energy.*' --out figs
        drivedyn plot shaft.nc --stress driveshaft.e6 --shape --scale 200
        drivedyn plot bench.nc --pressure ring_case --part washer_ring_case --vtu washer_ring_case
    """
    import matplotlib

    matplotlib.use("Agg")

    check_output_path(out_dir, "--out", directory=True)
    outputs = OutputFiles()  # a folder that refuses the figures now: they go to a fallback
    _plot(results_file, out_dir, outputs, patterns, stress_elements, shape, scale, snapshots,
          pressure_contacts, parts, vtu_parts)
    outputs.exit_if_failed()


def _plot(results_file: Path, out_dir: Path, outputs: OutputFiles, patterns: tuple[str, ...],
          stress_elements: tuple[str, ...], shape: bool, scale: float, snapshots: int,
          pressure_contacts: tuple[str, ...], parts: tuple[str, ...],
          vtu_parts: tuple[str, ...]) -> None:
    from drivedyn.results.results import load_results

    sweep_ds = _sweep_dataset(results_file)
    if sweep_ds is not None:  # a `drivedyn sweep` file: lines, maps, histograms, tornado
        from drivedyn.plots.sweeps import plot_sweep

        for path in outputs.write(lambda d: plot_sweep(sweep_ds, d), out_dir, "--out",
                                  directory=True):
            click.echo(f"figure: {path}")
        return
    try:
        res = load_results(results_file)
    except (OSError, ValueError) as exc:
        bad_input(f"{results_file}: not a drivedyn results file ({exc})")
    if stress_elements or shape:
        _beam_plots(res, out_dir, outputs, stress_elements, shape, scale, snapshots)
    if pressure_contacts or parts or vtu_parts:
        _flexible_plots(res, out_dir, outputs, pressure_contacts, parts, vtu_parts, scale,
                        snapshots)
    if (stress_elements or shape or pressure_contacts or parts or vtu_parts) and not patterns:
        return
    _engineering_plots(res.dataset, out_dir, outputs, patterns)


def _save_figures(figs: list, out_dir: Path, outputs: OutputFiles) -> None:
    """Save the figures ``(name, fig)`` as ``out_dir/<name>.png`` (or into the fallback folder
    if ``out_dir`` refuses them) and print their paths."""

    def save(folder: Path) -> list[Path]:
        paths = []
        for name, fig in figs:
            path = folder / f"{name}.png"
            fig.savefig(path, dpi=110)
            paths.append(path)
        return paths

    for path in outputs.write(save, out_dir, "--out", directory=True):
        click.echo(str(path))


def _engineering_plots(ds, out_dir: Path, outputs: OutputFiles,
                       patterns: tuple[str, ...]) -> None:
    """The engineering figures (only the variables of ``patterns`` when given, else with the
    library model's dashboard): one PNG each, paths printed."""
    from drivedyn.plots.engineering import dashboard_figures, engineering_figures, slug

    if patterns:
        names = [str(n) for n in ds.data_vars]
        if not any(fnmatch.fnmatchcase(n, p) for n in names for p in patterns):
            bad_input(f"no variable matches {', '.join(patterns)} (variables: "
                      f"{', '.join(sorted(names))})")
    if ds.sizes.get("time", 0) < 2:
        err("note: the results hold fewer than two output times: no time history to draw")
        return
    figs = engineering_figures(ds, patterns)
    if not patterns:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            figs += dashboard_figures(ds)
        for w in caught:
            err(f"note: {w.message}")
    if not figs and patterns:
        bad_input(f"nothing to draw for {', '.join(patterns)}: rotation matrices, solver "
                  "statistics and fields over meshes are not drawn as time histories (see the "
                  "bodies' angular velocities, the joints' angles, --part and --pressure)")
    if not figs:
        err("note: nothing to draw")
        return
    _save_figures([(slug(title), fig) for title, fig in figs], out_dir, outputs)


def _beam_plots(res, out_dir: Path, outputs: OutputFiles, elements: tuple[str, ...],
                shape: bool, scale: float, snapshots: int) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from drivedyn.plots.beams import beam_elements, beam_shape_figure, beam_stress_figure

    known = beam_elements(res)
    if not known:
        bad_input("the results hold no beam elements (--stress and --shape draw beams)")
    if "list" in elements:
        click.echo("\n".join(known))
        return
    if not scale > 0:
        bad_input(f"--scale: must be > 0, got {scale:g}")
    for e in elements:
        if e not in known:
            bad_input(f"--stress: {e!r} is not a beam element{did_you_mean(e, known)} "
                      f"(e.g. {', '.join(list(known)[:3])}; --stress list shows all)")
    figs = [(f"{e}.stress", beam_stress_figure(res, e)) for e in elements]
    if shape:
        figs.append(("beams.shape", beam_shape_figure(res, scale=scale, snapshots=snapshots)))
    for _, fig in figs:
        FigureCanvasAgg(fig)
    _save_figures(figs, out_dir, outputs)


def _flexible_plots(res, out_dir: Path, outputs: OutputFiles, contacts: tuple[str, ...],
                    parts: tuple[str, ...], vtu_parts: tuple[str, ...], scale: float,
                    snapshots: int) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from drivedyn.errors import ModelError
    from drivedyn.plots.flexible import (
        flexible_parts,
        part_stress_figure,
        pressure_contacts,
        pressure_map_figure,
    )
    from drivedyn.results.flexible_fields import write_vtu_series

    for opt, asked, known, kind in (("--pressure", contacts, pressure_contacts(res),
                                     "flexible washer contact"),
                                    ("--part", parts, flexible_parts(res), "flexible part"),
                                    ("--vtu", vtu_parts, flexible_parts(res), "flexible part")):
        if "list" in asked:
            click.echo("\n".join(known) or f"(no {kind})")
            return
        for a in asked:
            if a not in known:
                bad_input(f"{opt}: {a!r} is not a {kind} of this run{did_you_mean(a, known)}"
                          f" ({kind}s: {', '.join(known) or 'none'})")
    if not scale > 0:
        bad_input(f"--scale: must be > 0, got {scale:g}")
    figs = [(f"{c}.pressure", pressure_map_figure(res, c)) for c in contacts]
    figs += [(f"{p}.stress", part_stress_figure(res, p, snapshots, scale)) for p in parts]
    for _, fig in figs:
        FigureCanvasAgg(fig)
    if figs:
        _save_figures(figs, out_dir, outputs)
    for p in vtu_parts:
        try:
            pvd = outputs.write(lambda d, p=p: write_vtu_series(res.dataset, p, d / "vtu", scale),
                                out_dir, "--out", directory=True)
        except ModelError as exc:
            bad_input(str(exc))
        click.echo(str(pvd))


@click.command()
@click.option("--show", metavar="NAME", default=None,
              help="Print the file of one shipped model (redirect it to a file to edit it).")
def models(show: str | None) -> None:
    """List the model files shipped with drivedyn (run one with `drivedyn run NAME`).

    \b
    Example (copy a shipped model, edit it, run it):
        drivedyn models --show pendulum > my_pendulum.toml
        drivedyn run my_pendulum.toml --set solver.t_end=10
    """
    import tomllib

    from drivedyn.config import shipped_models

    shipped = shipped_models()
    if show is not None:
        if show not in shipped:
            bad_input(f"no shipped model {show!r} (shipped: {', '.join(shipped)})")
        click.echo(shipped[show].read_text(), nl=False)
        return
    for name, path in shipped.items():
        try:
            desc = tomllib.loads(path.read_text()).get("model", {}).get("description", "")
        except tomllib.TOMLDecodeError:
            desc = "(unreadable)"
        click.echo(f"{name:20s} {desc}\n{'':20s} {path}")


COMMANDS = (run, plot, models)
