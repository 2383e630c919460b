"""``drivedyn report``: the HTML report of a run (:mod:`drivedyn.report`)."""

from __future__ import annotations

import os
from pathlib import Path

import click

from drivedyn.cli.common import OutputFiles, bad_input, check_output_path, err


@click.command()
@click.argument("results_file", type=click.Path(exists=True, dir_okay=False, path_type=Path),
                metavar="RESULTS.nc")
@click.option("--out", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="HTML file to write [default: RESULTS-report.html beside the results].")
@click.option("--view/--no-view", "with_view", default=True, show_default=True,
              help="Also write the 3-D view (RESULTS-view.html beside the report) and link "
                   "it.")
def report(results_file: Path, out: Path | None, with_view: bool) -> None:
    """Write one HTML page about a run: the model summary (bodies, coordinates, elements by
    type), solver statistics (steps, rejections, Newton iterations, factorizations, wall
    time), the energy audit, the library model's dashboard, the engineering plots and a link
    to the 3-D view. Figures are embedded; the page opens offline.

    \b
    Examples:
        drivedyn run torsen-c --t-end 0.2 --out bench.nc
        drivedyn report bench.nc --out bench-report.html
    """
    import xarray as xr

    target = out or results_file.with_name(results_file.stem + "-report.html")
    check_output_path(target, "--out")
    try:
        with xr.open_dataset(results_file) as ds:
            ds = ds.load()
    except (OSError, ValueError) as exc:
        bad_input(f"{results_file}: not a drivedyn results file ({exc})")
    if ds.attrs.get("drivedyn_kind") == "sweep" or "time" not in ds.coords:
        bad_input(f"{results_file}: not the results of one run (a report needs "
                  "`drivedyn run ... --out RESULTS.nc`)")
    outputs = OutputFiles()  # a path that refuses the write now: the page goes to a fallback
    view_path = None
    if with_view:
        from drivedyn.cli.view import load_scene
        from drivedyn.viewer.html import write_html

        try:
            scene = load_scene(results_file, 400)
        except click.ClickException as exc:
            err(f"note: no 3-D view ({exc.message})")
        else:
            view_path = outputs.write(
                lambda p: write_html(scene, p),
                target.with_name(target.stem.removesuffix("-report") + "-view.html"), "--out")
            click.echo(f"view: {view_path}")
    from drivedyn.report import write_report

    def write(path: Path) -> Path:
        # the link to the view is relative to where the report lands (either may fall back)
        view = None
        if view_path is not None:
            try:
                view = os.path.relpath(view_path, path.parent)
            except ValueError:  # on another drive (Windows): no relative path
                view = Path(view_path).absolute().as_uri()
        return write_report(ds, path, view=view)

    click.echo(f"report: {outputs.write(write, target, '--out')}")
    outputs.exit_if_failed()
