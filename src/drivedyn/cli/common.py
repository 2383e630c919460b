"""Helpers shared by every command: consoles, strict JSON, exit codes, checks of options and
output paths made before any work starts.

Exit codes of every command: 0 success, 1 failure of a run (a simulation or a validation
check; whatever was computed is kept) or an output written to a fallback file because its
path refused the write after the run, 2 bad input (file, key, value or option, an output
path that cannot be written). A bad input never shows a traceback; ``drivedyn --debug
COMMAND`` shows it for an unexpected error.
"""

from __future__ import annotations

import math
import os
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any, NoReturn, TypeVar

import click

EXIT_FAILED = 1
EXIT_BAD_INPUT = 2

T = TypeVar("T")


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


def _reason(exc: OSError) -> str:
    """The operating system's reason of ``exc`` (``Permission denied``), without the file name
    that the message names already."""
    return exc.strerror or str(exc)


def _first_existing(path: Path) -> Path:
    """``path`` or its nearest ancestor that exists."""
    anc = path
    while not anc.exists() and anc.parent != anc:
        anc = anc.parent
    return anc


def _probe(folder: Path) -> OSError | None:
    """Create and delete a temporary file in the existing ``folder``: the only test that
    answers as the later write will (permission bits, read-only file systems, /proc and
    /sys, access control lists, root); ``os.access`` says yes to several of them."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=".drivedyn-probe-", dir=folder)
    except OSError as exc:
        return exc
    os.close(fd)
    try:
        os.unlink(tmp)
    except OSError:  # created but not removable: the folder takes files, which is what counts
        pass
    return None


def _probe_mkdir(folder: Path) -> OSError | None:
    """Create and remove a temporary folder in the existing ``folder``: the missing folders
    of an output path can be created there."""
    try:
        tmp = tempfile.mkdtemp(prefix=".drivedyn-probe-", dir=folder)
    except OSError as exc:
        return exc
    try:
        os.rmdir(tmp)
    except OSError:
        pass
    return None


def check_output_path(path: Path | None, option: str, *, directory: bool = False) -> None:
    """Refuse an output path that cannot be written, before any work starts (so a long run is
    never lost to a typo): a parent that is a file, a file where a folder is expected or the
    reverse, a folder that does not take a new file (a temporary file is created and deleted
    there; for a folder still to be created, a temporary folder in its first existing
    ancestor), a file that exists and is read-only. Exit code 2, the message names the
    option, the path and the operating system's reason."""
    if path is None:
        return
    path = Path(path)
    if directory:
        if path.exists() and not path.is_dir():
            bad_input(f"{option} {path}: exists and is not a folder")
        folder = path
    else:
        if path.is_dir():
            bad_input(f"{option} {path}: is a folder, expected a file name")
        folder = path.parent if str(path.parent) else Path(".")
    anc = _first_existing(folder)
    if not anc.exists():  # nothing exists up to the root: a broken file system
        bad_input(f"{option} {path}: no existing folder on the path")
    if not anc.is_dir():
        bad_input(f"{option} {path}: {anc} is a file, not a folder")
    if anc == folder:
        exc = _probe(anc)
        if exc is not None:
            bad_input(f"{option} {path}: cannot create a file in {anc} ({_reason(exc)})")
    else:
        exc = _probe_mkdir(anc)
        if exc is not None:
            bad_input(f"{option} {path}: cannot create the folder {folder} "
                      f"(in {anc}: {_reason(exc)})")
    if not directory and path.exists() and not os.access(path, os.W_OK):
        bad_input(f"{option} {path}: file exists and is not writable")


class OutputFiles:
    """The output files of one command, written after its work, so that a result is never
    lost: a write that fails although its path passed :func:`check_output_path` (the folder
    was removed or made read-only during the run, a network share went away: any
    ``OSError``) is redone into a fallback of the same name in the current folder, else in the
    system's temporary folder, never over an existing file; the message names both paths and
    :meth:`exit_if_failed` ends the command with exit code 1 once its other outputs are
    written. Later writes into a folder that fell back go to its fallback."""

    def __init__(self) -> None:
        self.fallbacks: list[tuple[str, Path, Path]] = []
        self._redirect: dict[Path, Path] = {}

    @property
    def failed(self) -> bool:
        """Whether an output went to a fallback."""
        return bool(self.fallbacks)

    def write(self, write: Callable[[Path], T], target: Path, option: str, *,
              directory: bool = False) -> T:
        """Call ``write(path)`` with ``path`` = ``target`` (a file, or a folder with
        ``directory``; the missing folders are created first), or with a fallback if that
        raises ``OSError``; returns what ``write`` returns (writers return the path they
        wrote). If the fallbacks fail too, the error names every path tried and the command
        stops with exit code 1."""
        target = Path(target)
        if target in self._redirect:
            return self._write(write, self._redirect[target], directory)
        try:
            return self._write(write, target, directory)
        except OSError as exc:
            first = exc
        tried = [f"{option} {target} ({_reason(first)})"]
        for folder in _fallback_folders(target):
            fallback = _free_name(folder, target.name)
            try:
                written = self._write(write, fallback, directory)
            except OSError as exc:
                tried.append(f"{fallback} ({_reason(exc)})")
                continue
            self._redirect[target] = fallback
            self.fallbacks.append((option, target, fallback))
            err(f"error: could not write {option} {target} ({_reason(first)}); written to "
                f"{fallback} instead")
            return written
        err(f"error: could not write {'; nor '.join(tried)}: this output is lost")
        sys.exit(EXIT_FAILED)

    @staticmethod
    def _write(write: Callable[[Path], T], path: Path, directory: bool) -> T:
        (path if directory else path.parent).mkdir(parents=True, exist_ok=True)
        return write(path)

    def path(self, target: Path) -> Path:
        """Where the outputs for ``target`` go: its fallback once a write to it failed."""
        return self._redirect.get(Path(target), Path(target))

    def exit_if_failed(self) -> None:
        """Exit with code 1 if an output went to a fallback (the command's other outputs
        are written by then)."""
        if self.fallbacks:
            sys.exit(EXIT_FAILED)


def _fallback_folders(target: Path) -> list[Path]:
    """Where an output that could not be written goes: the current folder (unless the
    target was there, or the current folder is gone), then the system's temporary folder."""
    folders = []
    try:
        cwd = Path.cwd()
    except OSError:  # the current folder was removed
        cwd = None
    try:
        here = Path(os.path.abspath(target)).parent
    except OSError:
        here = None
    if cwd is not None and cwd != here:
        folders.append(cwd)
    tmp = Path(tempfile.gettempdir())
    if tmp not in folders and tmp != here:
        folders.append(tmp)
    return folders


def _free_name(folder: Path, name: str) -> Path:
    """``folder/name``, or ``folder/<stem>-1<suffix>``, ``-2``... the first that does not
    exist (a fallback never replaces a file)."""
    path = folder / name
    stem, suffix = Path(name).stem, Path(name).suffix
    i = 1
    while path.exists() or path.is_symlink():
        path = folder / f"{stem}-{i}{suffix}"
        i += 1
    return path
