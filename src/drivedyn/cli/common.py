"""Helpers shared by every command: consoles, strict JSON, exit codes, checks of options and
output paths made before any work starts.

Exit codes of every command: 0 success, 1 failure of a run (a simulation or a validation
check; whatever was computed is kept), 2 bad input (file, key, value or option). A bad input
never shows a traceback; ``drivedyn --debug COMMAND`` shows it for an unexpected error.
"""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path
from typing import Any, NoReturn

import click

EXIT_FAILED = 1
EXIT_BAD_INPUT = 2


class BadInput(click.ClickException):
    """A bad input found by a command: printed as ``error: <message>``, exit code 2."""

    exit_code = EXIT_BAD_INPUT

    def show(self, file: Any = None) -> None:
        click.echo(f"error: {self.format_message()}", err=True)


def console(stderr: bool = False) -> Any:
    """A rich console; wide when not writing to a terminal, so tables are not squashed."""
    from rich.console import Console

    stream = sys.stderr if stderr else sys.stdout
    width = None
    if not stream.isatty() and "COLUMNS" not in os.environ:
        width = 160
    return Console(file=stream, width=width, highlight=False, soft_wrap=False)


def jsonable(obj: Any) -> Any:
    """Replace non-finite floats by None and numpy scalars by Python numbers so the output
    is strict JSON."""
    if isinstance(obj, dict):
        return {k: jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if hasattr(obj, "item") and not isinstance(obj, (str, bytes)):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def fmt(value: float, spec: str) -> str:
    """``format(value, spec)`` for finite values, ``nan``/``inf`` otherwise."""
    return format(value, spec) if math.isfinite(value) else str(value)


def err(message: str) -> None:
    """Print a line on standard error."""
    click.echo(message, err=True)


def bad_input(message: str) -> NoReturn:
    """Stop with exit code 2 and ``error: message`` (no traceback)."""
    raise BadInput(message)


class FiniteFloat(click.ParamType):
    """A float option that refuses NaN and infinities, optionally with bounds.

    ``low``/``high`` are inclusive unless ``low_open``/``high_open``; ``unit`` is named in the
    message (``--torque: expected a finite number > 0 [N m], got nan``).
    """

    name = "number"

    def __init__(self, low: float | None = None, high: float | None = None, *,
                 low_open: bool = False, high_open: bool = False, unit: str = "") -> None:
        self.low, self.high = low, high
        self.low_open, self.high_open = low_open, high_open
        self.unit = unit

    def _expected(self) -> str:
        parts = []
        if self.low is not None:
            parts.append(f"{'>' if self.low_open else '>='} {self.low:g}")
        if self.high is not None:
            parts.append(f"{'<' if self.high_open else '<='} {self.high:g}")
        unit = f" [{self.unit}]" if self.unit else ""
        return "a finite number" + (" " + " and ".join(parts) if parts else "") + unit

    def convert(self, value: Any, param: Any, ctx: Any) -> float:
        if isinstance(value, float) and math.isfinite(value):
            x = value
        else:
            try:
                x = float(value)
            except (TypeError, ValueError):
                self.fail(f"expected {self._expected()}, got {value!r}", param, ctx)
        ok = math.isfinite(x)
        if ok and self.low is not None:
            ok = x > self.low if self.low_open else x >= self.low
        if ok and self.high is not None:
            ok = x < self.high if self.high_open else x <= self.high
        if not ok:
            self.fail(f"expected {self._expected()}, got {value!r}", param, ctx)
        return x


def check_output_path(path: Path | None, option: str, *, directory: bool = False) -> None:
    """Refuse an output path that cannot be written, before any work starts (so a long run is
    never lost to a typo): a parent that is a file, a file where a folder is expected or the
    reverse, a folder without write permission."""
    if path is None:
        return
    path = Path(path)
    if directory:
        if path.exists() and not path.is_dir():
            bad_input(f"{option} {path}: exists and is not a folder")
        probe = path
    else:
        if path.is_dir():
            bad_input(f"{option} {path}: is a folder, expected a file name")
        probe = path.parent if str(path.parent) else Path(".")
    # walk up to the first existing ancestor: it must be a writable folder
    anc = probe
    while not anc.exists():
        if anc.parent == anc:
            break
        anc = anc.parent
    if anc.exists() and not anc.is_dir():
        bad_input(f"{option} {path}: {anc} is a file, not a folder")
    if anc.exists() and not os.access(anc, os.W_OK | os.X_OK):
        bad_input(f"{option} {path}: folder {anc} is not writable")
    if not directory and path.exists() and not os.access(path, os.W_OK):
        bad_input(f"{option} {path}: file exists and is not writable")
