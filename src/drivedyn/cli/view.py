"""``drivedyn view``: the 3-D animation of a run as one offline HTML page, and its exports
to glTF and VTK (:mod:`drivedyn.viewer`)."""

from __future__ import annotations

from pathlib import Path

import click

from drivedyn.cli.common import FiniteFloat, OutputFiles, bad_input, check_output_path, err


def load_scene(results_file: Path, frames: int):
    """The scene of a results file; unreadable files and files without a scene are input
    errors (exit 2)."""
    import xarray as xr

    from drivedyn.viewer.scene import build_scene

    try:
        with xr.open_dataset(results_file) as ds:
            if ds.attrs.get("drivedyn_kind") == "sweep":
                bad_input(f"{results_file}: a sweep file has no mechanism to show; view the "
                          "results file of one run (`drivedyn run ... --out run.nc`)")
            return build_scene(ds.load(), frames=frames)
    except (OSError, ValueError, KeyError) as exc:
        bad_input(f"{results_file}: cannot be viewed ({exc})")


@click.command()
@click.argument("results_file", type=click.Path(exists=True, dir_okay=False, path_type=Path),
                metavar="RESULTS.nc")
@click.option("--out", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="HTML file to write [default: RESULTS.html beside the results].")
@click.option("--frames", type=click.IntRange(2, 20000), default=400, show_default=True,
              help="Largest number of animation frames (outputs are picked evenly).")
@click.option("--gltf", "gltf_path", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="Also write the animated scene as binary glTF (.glb).")
@click.option("--vtk", "vtk_dir", type=click.Path(file_okay=False, path_type=Path),
              default=None, help="Also write one VTU file per frame and a PVD index into "
                                 "this folder (ParaView).")
@click.option("--scale", type=FiniteFloat(0.0), default=1.0, show_default=True,
              help="Deformation scale factor of beams and flexible parts in the VTK files "
                   "(the HTML page has its own control).")
def view(results_file: Path, out: Path | None, frames: int, gltf_path: Path | None,
         vtk_dir: Path | None, scale: float) -> None:
    """Write a self-contained HTML page that animates the mechanism of a results file in 3-D
    (works offline: three.js is inside the page).

    Bodies are drawn as the shapes their elements and library model declare (toothed gears
    with their helix, washers, shafts, semi-transparent cases), other bodies as the box of
    equal inertia; beams and meshed flexible parts deformed and coloured by von Mises
    stress; contact forces as arrows. The page has a time slider, play/pause and speed, a
    deformation scale factor, camera presets, a section plane, and toggles for markers and
    joint axes.

    \b
    Examples:
        drivedyn run torsen-c --t-end 0.2 --out bench.nc
        drivedyn view bench.nc --out bench.html
        drivedyn view bench.nc --gltf bench.glb --vtk bench-vtk
    """
    target = out or results_file.with_suffix(".html")
    check_output_path(target, "--out")
    check_output_path(gltf_path, "--gltf")
    check_output_path(vtk_dir, "--vtk", directory=True)
    scene = load_scene(results_file, frames)
    from drivedyn.viewer.html import write_html

    for w in scene.warnings:
        err(f"note: {w}")
    outputs = OutputFiles()  # a path that refuses the write now: the file goes to a fallback
    click.echo(f"view: {outputs.write(lambda p: write_html(scene, p), target, '--out')}")
    if gltf_path is not None:
        from drivedyn.viewer.gltf import write_glb

        glb = outputs.write(lambda p: write_glb(scene, p), gltf_path, "--gltf")
        click.echo(f"glTF: {glb}")
    if vtk_dir is not None:
        from drivedyn.viewer.vtk import write_vtk

        pvd = outputs.write(lambda d: write_vtk(scene, d, scale=scale, name=results_file.stem),
                            vtk_dir, "--vtk", directory=True)
        click.echo(f"VTK: {pvd}")
    outputs.exit_if_failed()
