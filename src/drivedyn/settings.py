"""Process-wide settings a user may choose: compile workers and the cache folder.

These are the settings of the process, not of a model or a run (those live in the model
file's ``[solver]`` table and :mod:`drivedyn.solver.settings`). Set them from Python with
:func:`configure`, or on the command line with ``drivedyn --compile-workers N --cache-dir
DIR COMMAND ...``. The only environment variables drivedyn reads are ``DRIVEDYN_CACHE`` (the
default cache folder, for a machine whose home folder is not writable) and numba's own
``NUMBA_CACHE_DIR`` (where numba keeps the compiled kernels; it must be set before numba is
imported), both listed in the README.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

__all__ = ["ProcessSettings", "cache_dir", "compile_workers", "configure", "current"]


@dataclass(frozen=True)
class ProcessSettings:
    """Settings of the drivedyn process.

    Attributes:
        compile_workers: worker processes that compile a model's missing kernels at the same
            time on a first run (None: one per CPU; 0 or 1: in the process itself). Forked
            workers, so Linux only; elsewhere the kernels compile in the process.
        cache_dir: folder of drivedyn's own caches (Craig-Bampton reductions, the record
            of compiled kernels); None: ``$DRIVEDYN_CACHE`` or ``~/.cache/drivedyn``.
        compile_progress: called as ``compile_progress(done, total, name)`` while a first
            run compiles a model's kernels (``done`` = 0 when it starts, then after each
            kernel); None: progress goes to the ``drivedyn`` logger only. The command line
            prints it on stderr.
    """

    compile_workers: int | None = None
    cache_dir: Path | None = None
    compile_progress: Callable[[int, int, str], Any] | None = None


_current = ProcessSettings()


def current() -> ProcessSettings:
    """The settings in force."""
    return _current


def configure(*, compile_workers: int | None = None,
              cache_dir: str | os.PathLike | None = None,
              compile_progress: Callable[[int, int, str], Any] | None = None,
              ) -> ProcessSettings:
    """Set process-wide settings (arguments left as None keep their value); returns the
    settings in force.

    Raises:
        ValueError: ``compile_workers`` negative.
    """
    global _current
    changes: dict = {}
    if compile_workers is not None:
        if int(compile_workers) < 0:
            raise ValueError(f"compile_workers must be >= 0 (got {compile_workers})")
        changes["compile_workers"] = int(compile_workers)
    if cache_dir is not None:
        changes["cache_dir"] = Path(cache_dir).expanduser()
    if compile_progress is not None:
        changes["compile_progress"] = compile_progress
    _current = replace(_current, **changes)
    return _current


def compile_workers() -> int:
    """Worker processes for a first compilation (the setting, or the CPU count)."""
    n = _current.compile_workers
    return (os.cpu_count() or 1) if n is None else n


def cache_dir() -> Path:
    """drivedyn's cache folder (the setting, ``$DRIVEDYN_CACHE`` or ``~/.cache/drivedyn``)."""
    if _current.cache_dir is not None:
        return _current.cache_dir
    env = os.environ.get("DRIVEDYN_CACHE")
    return Path(env).expanduser() if env else Path.home() / ".cache" / "drivedyn"
