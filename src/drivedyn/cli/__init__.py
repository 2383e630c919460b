"""Command line interface: the ``drivedyn`` group and its commands, one module per command
group (:mod:`~drivedyn.cli.validate`, :mod:`~drivedyn.cli.files` for ``run``/``plot``/
``models``, :mod:`~drivedyn.cli.differential` for ``tdr``/``calibrate``,
:mod:`~drivedyn.cli.bounce`, :mod:`~drivedyn.cli.fmu`, :mod:`~drivedyn.cli.sweep`,
:mod:`~drivedyn.cli.view`,
:mod:`~drivedyn.cli.report`), shared helpers in :mod:`~drivedyn.cli.common`.

Exit codes: 0 success, 1 failure of a run (partial results are written), 2 bad input. Errors
of the input (model files, keys, values, units, options) are reported in one message naming
the file, the key and what was expected, never as a traceback; ``--debug`` shows the
traceback of an unexpected error.
"""

from __future__ import annotations

import sys
from typing import Any

import click

from drivedyn.cli.bounce import bounce
from drivedyn.cli.common import EXIT_BAD_INPUT, EXIT_FAILED
from drivedyn.cli.differential import COMMANDS as DIFFERENTIAL_COMMANDS
from drivedyn.cli.files import COMMANDS as FILE_COMMANDS
from drivedyn.cli.fmu import fmu
from drivedyn.cli.report import report
from drivedyn.cli.sweep import sweep
from drivedyn.cli.validate import validate
from drivedyn.cli.vehicle import vehicle
from drivedyn.cli.view import view

HELP = """drivedyn: flexible multibody simulation of automotive drivelines.

A flexible multibody engine (rigid bodies and nodes, joints, spring-dampers, loads and
drivers, integrated by generalized-alpha on the rotation group) built for modelling
limited-slip (TORSEN) differentials and their test benches. `drivedyn validate` compares
simulated quantities with exact or published references and exits with 0 only if every check
passes; `drivedyn run` simulates a model file, `drivedyn plot` draws its results and
`drivedyn models` lists the shipped model files. Exit codes: 0 success, 1 failure (partial
results are written; an output whose path refuses it after the work goes to a fallback file
in the current or temporary folder), 2 bad input (including an output path where no file can
be created, refused before any work).

\b
Examples:
    drivedyn validate --quick --report validation-report
    drivedyn models --show pendulum > my_pendulum.toml
    drivedyn run my_pendulum.toml --set solver.t_end=10 --out pendulum.nc
    drivedyn plot pendulum.nc --out figures
    drivedyn view pendulum.nc --out pendulum.html
    drivedyn report pendulum.nc --out pendulum-report.html
    drivedyn vehicle --compare open,torsen --t-end 2 --out split-mu
    drivedyn sweep torsen-c --tdr --vary pockets.mu=0.10:0.20:5 --workers 2
    drivedyn fmu torsen-b --out torsen_b.fmu
"""


class _Group(click.Group):
    """The ``drivedyn`` group: input errors that escape a command (a model file, a unit, an
    impossible model) become ``error: ...`` with exit code 2; any other exception is an
    internal error reported in one line with exit code 1 (``--debug`` re-raises it)."""

    def invoke(self, ctx: click.Context) -> Any:
        from drivedyn.errors import ModelError

        try:
            return super().invoke(ctx)
        except (click.exceptions.ClickException, click.exceptions.Exit, click.exceptions.Abort,
                SystemExit, KeyboardInterrupt):
            raise
        except BrokenPipeError:  # output piped into `head` and the like: stop quietly
            import os

            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            sys.exit(EXIT_FAILED)
        except Exception as exc:
            if ctx.meta.get("drivedyn.debug"):
                raise
            if isinstance(exc, ModelError) or _is_input_error(exc):
                click.echo(f"error: {exc}", err=True)
                sys.exit(EXIT_BAD_INPUT)
            click.echo(f"error: internal error ({type(exc).__name__}: {exc}); please report "
                       "it, with the command; rerun with `drivedyn --debug ...` for the "
                       "traceback", err=True)
            sys.exit(EXIT_FAILED)


def _is_input_error(exc: Exception) -> bool:
    from drivedyn.config import ModelFileError, UnitError

    return isinstance(exc, (ModelFileError, UnitError))


@click.group(cls=_Group, help=HELP, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(None, "--version", "-V", package_name="drivedyn", prog_name="drivedyn")
@click.option("--debug", is_flag=True, help="Show the Python traceback of an unexpected error.")
@click.option("--compile-workers", type=click.IntRange(0), default=None, metavar="N",
              help="Processes that compile a model's kernels at the same time on a first run "
                   "(default: one per CPU; 0 compiles in this process).")
@click.option("--cache-dir", type=click.Path(file_okay=False), default=None, metavar="DIR",
              help="drivedyn's cache folder (reduced flexible parts, the record of compiled "
                   "kernels; default: $DRIVEDYN_CACHE or ~/.cache/drivedyn).")
@click.pass_context
def main(ctx: click.Context, debug: bool, compile_workers: int | None,
         cache_dir: str | None) -> None:
    """drivedyn command line (see HELP)."""
    from drivedyn import settings

    ctx.meta["drivedyn.debug"] = debug
    settings.configure(compile_workers=compile_workers, cache_dir=cache_dir,
                       compile_progress=_compile_progress)


def _compile_progress(done: int, total: int, name: str) -> None:
    """A first run's compilation, on stderr (stdout stays for results and JSON)."""
    if done == 0:
        what = "kernel" if total == 1 else "kernels"
        click.echo(f"first run: compiling {total} numba {what} for this model (cached "
                   "afterwards) ...", err=True)
    else:
        click.echo(f"  compiled {name} ({done} of {total})", err=True)


for _cmd in (validate, *FILE_COMMANDS, bounce, *DIFFERENTIAL_COMMANDS, fmu, vehicle, sweep,
             view, report):
    main.add_command(_cmd)

__all__ = ["main"]


def console() -> None:
    """The ``drivedyn`` console command (and ``python -m drivedyn.cli``): :func:`main`, then
    a quick interpreter exit.

    A command that ran a simulation leaves numba's compiler objects behind, several hundred
    thousand of them in reference cycles; the interpreter's last garbage collection at exit
    takes 0.5 s deallocating them (10 % of a warm ``drivedyn tdr torsen-c --mode all``). Here
    the garbage that exists when the command ends is collected (its finalisers run: files
    flush and close), then every object still alive is frozen (``gc.freeze``), so the exit's
    collection skips them; their memory goes back with the process. Objects freed by
    reference counting at exit are unaffected. Tests call :func:`main` in their own process,
    which this does not touch."""
    import gc

    try:
        main()
    finally:
        gc.collect()
        gc.freeze()
