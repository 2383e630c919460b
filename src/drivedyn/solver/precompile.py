"""First compilation of a model's element kernels in parallel processes.

A kernel is compiled by numba on its first call, for the argument types of that call, and
kept in numba's on-disk cache (``cache=True``): later runs load it in milliseconds. The first
run after an install compiles every kernel the model uses; one after the other in one
process that takes the sum of their times (the Type C bench: about a minute of CPU on 2
cores). :func:`precompile_kernels` compiles the kernels this machine has not compiled yet in
worker processes at the same time (each worker writes numba's cache), then loads them here
from the cache with ``Dispatcher.compile``, numba's public entry point, which finds them
there.

Which kernels are compiled is recorded in a small file of drivedyn's cache folder
(:func:`drivedyn.settings.cache_dir`, ``compiled-kernels.json``): per kernel and argument
types, the numba version, numba's cache folder, the size and modification time of the
kernel's source file (numba's own cache key checks that file only) and the seconds its
compilation took here. The workers take the kernels longest first (the schedule whose last
kernel ends soonest, as a rule): by the seconds of the record, or, on a machine that has
compiled none of them yet, by the size of their code (:func:`code_size`). A record
that is stale (a cache folder emptied by hand) costs only time: ``Dispatcher.compile`` then
compiles in the process. Anything that goes wrong on the way (no process pool in a daemonic
worker, a cache folder that cannot be written) leaves the kernels to numba's usual
compilation on first call: slower, the same machine code.

Workers compile with Python's cyclic garbage collector off (numba's compiler allocates
millions of small objects; the collections cost 14-16 % of a worker's CPU, measured), and a
compilation in the process itself with rare collections (:data:`GC_THRESHOLDS`).

The number of workers is a setting (:func:`drivedyn.settings.configure`, ``drivedyn
--compile-workers N``; default one per CPU, 0 or 1 compiles in the process). Workers are
forked, so this runs on Linux and from a single-threaded process; otherwise the kernels
compile in the process. Progress goes to the ``drivedyn`` logger (INFO: one line per
kernel) and to an optional callback, which the command line shows.
"""

from __future__ import annotations

import concurrent.futures as cf
import gc
import importlib
import json
import logging
import multiprocessing as mp
import os
import pickle
import sys
import threading
import time
import types
from collections.abc import Callable
from pathlib import Path
from typing import Any

from drivedyn import settings

log = logging.getLogger("drivedyn")

#: resident memory [MB] above which a compile worker collects garbage before its next kernel
#: (its collector is off otherwise): a worker grows by 60-140 MB per kernel
WORKER_RSS_MB = 700.0

#: the cyclic garbage collector's thresholds while kernels compile in the process itself
#: (Python's default is (700, 10, 10); two Type C kernels in one process: 10-20 % less CPU)
GC_THRESHOLDS = (100_000, 50, 100)
_GC_LOCK = threading.Lock()

_FORK = sys.platform.startswith("linux") and "fork" in mp.get_all_start_methods()

#: compile seconds per byte of bytecode (:func:`code_size`), to order kernels the record
#: does not know: 1.0-1.3 ms/byte for the eight kernels of the Type C bench, each compiled
#: alone (5.7 s for 6 750 bytes to 31 s for 24 600; measured on 2 cores)
SECONDS_PER_BYTE = 1.2e-3

#: name of the record of compiled kernels in drivedyn's cache folder
RECORD_NAME = "compiled-kernels.json"

#: compile-progress callback: ``(kernels done, kernels to compile, name of the last one)``
Progress = Callable[[int, int, str], Any]


def _source_stamp(disp: Any) -> str:
    """numba version, numba's cache folder and the size and modification time of the
    function's source file: what invalidates numba's cached entry."""
    import numba

    path = disp.py_func.__code__.co_filename
    try:
        st = os.stat(path)
        src = f"{path}:{st.st_size}:{st.st_mtime_ns}"
    except OSError:
        src = "?"
    return f"{numba.__version__}|{numba.config.CACHE_DIR or ''}|{src}"


def code_size(fn: Callable, _seen: set | None = None) -> int:
    """Bytes of bytecode of the Python function ``fn`` and of every numba function it reaches
    through its module's globals (``name`` or ``module.name``), each counted once: what
    numba compiles with it (its compile time grows about in proportion)."""
    seen = set() if _seen is None else _seen
    code = fn.__code__
    if code in seen:
        return 0
    seen.add(code)
    size = len(code.co_code)
    glob = fn.__globals__
    for name in code.co_names:
        obj = glob.get(name)
        if isinstance(obj, types.ModuleType):
            found = [getattr(obj, attr, None) for attr in code.co_names]
        else:
            found = [obj]
        for f in found:
            py = getattr(f, "py_func", None)
            if callable(py) and hasattr(py, "__code__"):
                size += code_size(py, seen)
    return size


def expected_seconds(key: str, disp: Any, record: dict) -> float:
    """Expected compile time of the kernel ``disp`` [s]: the seconds the record of compiled
    kernels holds for ``key``, else :data:`SECONDS_PER_BYTE` times its :func:`code_size`."""
    seconds = record.get(key, {}).get("seconds")
    if seconds is not None:
        return float(seconds)
    return SECONDS_PER_BYTE * code_size(disp.py_func)


def _key(disp: Any, sig: tuple) -> str:
    fn = disp.py_func
    return f"{fn.__module__}.{fn.__qualname__}{sig}"


def _record_path() -> Path:
    return settings.cache_dir() / RECORD_NAME


def _read_record() -> dict:
    try:
        with open(_record_path()) as f:
            data = json.load(f)
        return data if isinstance(data, dict) else {}
    except (OSError, ValueError):
        return {}


def _write_record(entries: dict) -> None:
    """Merge ``entries`` into the record (atomic replace; a failure only costs time); a
    warm run, with nothing new, writes nothing."""
    if not entries:
        return
    path = _record_path()
    try:
        data = _read_record()
        data.update(entries)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
        with open(tmp, "w") as f:
            json.dump(data, f, indent=0, sort_keys=True)
        os.replace(tmp, path)
    except OSError as exc:
        log.debug("precompile: record not written (%s)", exc)


def _compile_one(module: str, qualname: str, sig_bytes: bytes) -> float:
    """Worker: compile ``module.qualname`` for the pickled signature (numba caches it);
    returns the seconds it took. The collector is off; a collection runs only before a
    kernel when the worker holds more than :data:`WORKER_RSS_MB`."""
    gc.disable()
    if _rss_mb() > WORKER_RSS_MB:
        gc.collect()
    t0 = time.perf_counter()
    disp = getattr(importlib.import_module(module), qualname)
    disp.compile(pickle.loads(sig_bytes))
    return time.perf_counter() - t0


def _rss_mb() -> float:
    """Resident memory of this process [MB] (Linux; 0 where unknown)."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20
    except (OSError, ValueError, IndexError):
        return 0.0


def _compile_here(calls: list[tuple[Any, tuple]]) -> None:
    """Compile (or load from the cache) in this process, the cyclic garbage collector run
    rarely meanwhile (its thresholds are restored afterwards)."""
    with _GC_LOCK:  # the thresholds are the process's: two threads must not interleave
        thresholds = gc.get_threshold()
        gc.set_threshold(*GC_THRESHOLDS)
        try:
            for disp, sig in calls:
                try:
                    disp.compile(sig)
                except Exception as exc:  # compiled (its error raised) on first call instead
                    log.debug("precompile: %s failed (%s)", disp.py_func.__qualname__, exc)
        finally:
            gc.set_threshold(*thresholds)


def precompile_kernels(calls: list[tuple[Any, tuple]], workers: int | None = None,
                       while_waiting: Callable[[], Any] | None = None,
                       progress: Progress | None = None) -> dict:
    """Make sure each ``(dispatcher, signature)`` is compiled, compiling the ones this
    machine has not compiled yet in parallel worker processes.

    Args:
        calls: numba dispatchers with the argument-type tuples they will be called with.
        workers: worker processes (default :func:`drivedyn.settings.compile_workers`).
        while_waiting: called once in this process while the workers compile (work the run
            needs later, such as its lazy imports, taken off the critical path); an
            exception it raises is logged and ignored.
        progress: called when a first run starts compiling (0 done) and after each kernel,
            with the number done, the number to compile and the kernel's name (default:
            the ``compile_progress`` setting, :mod:`drivedyn.settings`).
    Returns:
        ``{"missing": n, "compiled_in_workers": n, "wall_s": s}`` (for the log and tests).
    """
    t0 = time.perf_counter()
    workers = settings.compile_workers() if workers is None else workers
    if progress is None:
        progress = settings.current().compile_progress
    record = _read_record()
    todo: dict[str, tuple[Any, tuple, str]] = {}
    known: list[tuple[Any, tuple]] = []
    for disp, sig in calls:
        sig = tuple(sig)
        if sig in disp.overloads:
            continue
        key = _key(disp, sig)
        stamp = _source_stamp(disp)
        if record.get(key, {}).get("stamp") == stamp:
            known.append((disp, sig))
        else:
            todo.setdefault(key, (disp, sig, stamp))
    _compile_here(known)  # compiled here before: numba loads them from its cache
    if todo and progress is not None:
        progress(0, len(todo), "")
    done = 0
    seconds: dict[str, float] = {}
    # fork only: a spawned worker would import the user's script again (one without a
    # ``__main__`` guard would run its simulation in every worker); forked workers start from
    # this process as it is (no kernel is being compiled at this point, so no numba lock is
    # held), and only from a single-threaded process (a lock held by another thread at the
    # fork would stay held in the worker)
    if len(todo) >= 2 and workers >= 2 and _FORK and threading.active_count() == 1:
        order = sorted(todo, key=lambda k: -expected_seconds(k, todo[k][0], record))
        log.info("first compilation of %d kernels in %d processes", len(todo),
                 min(workers, len(todo)))
        try:
            with cf.ProcessPoolExecutor(max_workers=min(workers, len(todo)),
                                        mp_context=mp.get_context("fork")) as pool:
                futures = {}
                for k in order:
                    disp, sig, _stamp = todo[k]
                    fn = disp.py_func
                    futures[pool.submit(_compile_one, fn.__module__, fn.__qualname__,
                                        pickle.dumps(sig))] = k
                if while_waiting is not None:
                    try:
                        while_waiting()
                    except Exception as exc:  # its work is redone where it is needed
                        log.debug("precompile: while_waiting failed (%s)", exc)
                for fut in cf.as_completed(futures):
                    k = futures[fut]
                    try:
                        seconds[k] = fut.result()
                    except Exception as exc:  # this one compiles on first call instead
                        log.debug("precompile: %s failed in a worker (%s)", k, exc)
                        continue
                    done += 1
                    name = todo[k][0].py_func.__qualname__
                    log.info("compiled %s in %.1f s (%d of %d)", name, seconds[k], done,
                             len(todo))
                    if progress is not None:
                        progress(done, len(todo), name)
                    # load it now, while the others compile: only the last one's load is
                    # left on the critical path
                    _compile_here([todo[k][:2]])
        except Exception as exc:  # no process pool here (e.g. a daemonic worker)
            log.debug("precompile: no worker processes (%s)", exc)
    for k, (disp, sig, _stamp) in todo.items():
        if sig in disp.overloads:
            continue
        t1 = time.perf_counter()
        _compile_here([(disp, sig)])
        if k not in seconds:
            seconds[k] = time.perf_counter() - t1
            if progress is not None:
                progress(len(seconds), len(todo), disp.py_func.__qualname__)
    _write_record({k: {"stamp": todo[k][2], "seconds": round(s, 2)}
                   for k, s in seconds.items() if todo[k][1] in todo[k][0].overloads})
    return {"missing": len(todo), "compiled_in_workers": done,
            "wall_s": time.perf_counter() - t0}
