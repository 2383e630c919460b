"""``drivedyn bounce``: the seeds' bouncing-ball benchmark of continuous impact."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click

from drivedyn.cli.common import FiniteFloat, OutputFiles, check_output_path, console, jsonable

_BOUNCE_LAWS = ("hunt-crossley", "lankarani-nikravesh", "flores", "gonthier", "hu-guo",
                "exact")
_POSITIVE = FiniteFloat(0.0, low_open=True)


@click.command()
@click.option("--law", type=click.Choice(_BOUNCE_LAWS), default="lankarani-nikravesh",
              show_default=True, help="Continuous-impact law of the contact.")
@click.option("--e", "e", type=FiniteFloat(0.0, 1.0, low_open=True, high_open=True),
              default=0.8, show_default=True, help="Restitution coefficient given to the law.")
@click.option("--n", "n", type=FiniteFloat(1.0), default=1.5, show_default=True,
              help="Exponent of the contact force K delta^n.")
@click.option("--k", "k", type=_POSITIVE, default=1e10, show_default=True,
              help="Contact stiffness K [N/m^n].")
@click.option("--mass", type=_POSITIVE, default=0.85, show_default=True, help="Ball mass [kg].")
@click.option("--h0", type=_POSITIVE, default=1.0, show_default=True,
              help="Drop height [m].")
@click.option("--gravity", type=_POSITIVE, default=10.0, show_default=True,
              help="Gravitational acceleration [m/s^2].")
@click.option("--t-end", "t_end", type=_POSITIVE, default=3.0, show_default=True,
              help="Simulated time [s].")
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON object (law, e_target, apex_heights, restitution, steps, "
                   "wall_s, ...) instead of the table.")
@click.option("--plot", "plot", type=click.Path(dir_okay=False, path_type=Path), default=None,
              metavar="PNG", help="Also write height against time to this PNG file.")
def bounce(law: str, e: float, n: float, k: float, mass: float, h0: float, gravity: float,
           t_end: float, as_json: bool, plot: Path | None) -> None:
    """The seeds' bouncing-ball benchmark of continuous impact.

    A ball dropped from H0 bounces on a rigid floor with the contact force
    K delta^n [1 + chi deltadot / v_s]; chi is the law's damping factor for E. Prints, per
    bounce, the approach and rebound speeds, the restitution (rebound over approach speed)
    and the apex height of the next flight, with the restitution the exact relation predicts
    for the law's chi, the number of steps and the wall time. Exits with 1 if the simulation
    fails.

    \b
    Examples:
        drivedyn bounce
        drivedyn bounce --law hunt-crossley --e 0.5 --json --plot bounce.png
    """
    from drivedyn.library.bouncing_ball import plot_height, run_bounce

    check_output_path(plot, "--plot")

    outputs = OutputFiles()  # a path that refuses the figure now: it goes to a fallback
    err = console(stderr=True)
    with err.status("simulating the bouncing ball ..."):
        run = run_bounce(law=law, e=e, n=n, k=k, mass=mass, h0=h0, gravity=gravity,
                         t_end=t_end)
    if plot is not None and run.results is not None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        fig = Figure(figsize=(8, 4.5))
        FigureCanvasAgg(fig)
        plot_height(run, fig)
        fig.tight_layout()

        def write(path: Path) -> Path:
            fig.savefig(path, dpi=110)
            return path

        plot = outputs.write(write, plot, "--plot")
    if as_json:
        click.echo(json.dumps(jsonable(run.as_dict())))
    else:
        from rich.table import Table

        out = console()
        table = Table(title=f"bouncing ball: {law} law, e = {e:g}, n = {n:g}, K = {k:g} "
                            f"N/m^n, m = {mass:g} kg, h0 = {h0:g} m, g = {gravity:g} m/s^2",
                      title_justify="left")
        for col in ("bounce", "approach speed \\[m/s]", "rebound speed \\[m/s]",
                    "restitution", "apex after \\[m]"):
            table.add_column(col, justify="right")
        for i, (vi, vo, ei) in enumerate(zip(run.impact_speeds, run.rebound_speeds,
                                             run.restitution, strict=True)):
            apex = f"{run.apex_heights[i]:.6f}" if i < len(run.apex_heights) else "-"
            table.add_row(str(i + 1), f"{vi:.6f}", f"{vo:.6f}", f"{ei:.6f}", apex)
        out.print(table)
        out.print(f"damping factor chi = {run.chi:.6g}; restitution predicted by the exact "
                  f"relation: {run.e_predicted:.6f} (given e = {e:g}); gravity acting during "
                  "the contact lowers it slightly, more for slow impacts")
        out.print(f"{run.steps} steps ({run.rejected} rejected), wall time {run.wall_s:.3f} s,"
                  f" energy balance error {run.energy_balance_error:.3g} J")
        if plot is not None:
            out.print(f"figure written to {plot}", soft_wrap=True)  # a path is never wrapped
    if not run.success:
        err.print(f"[red]simulation failed: {run.message}[/red]")
        sys.exit(1)
    outputs.exit_if_failed()


