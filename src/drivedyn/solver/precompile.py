"""First compilation of a model's element kernels in parallel processes.

A kernel is compiled by numba on its first call, for the argument types of that call, and
kept in numba's on-disk cache (``cache=True``): later runs load it in milliseconds. The first
run after an install compiles every kernel the model uses, one after the other, in the
process that runs the simulation (for the Type C bench 33-45 s of CPU on the 2-core reference
machine, issue 16 tenth round, fast to slow hour, 11-15 % less since the eleventh round's
leaner IR, :mod:`drivedyn.jit`, and about 10 % less again since the twelfth round's lighter
SSA and liveness passes, :mod:`drivedyn.jit_passes`, and 10 % less again since the
thirteenth round's structures held as values, :mod:`drivedyn.jit_structs`, and reference
counting without dead reads, 4.5 % less since the fifteenth round's lean array indexing,
:mod:`drivedyn.jit_indexing`, 2-4 % less since the sixteenth round's records left out,
:mod:`drivedyn.jit_records`: the stepping loop and gear pairs the longest; functions
compiled for a compiled caller are linked, :mod:`drivedyn.jit_linked`).
:func:`precompile_kernels` finds the kernels that are neither compiled in this
process nor in the cache and, when there are two or more and more than one CPU, compiles them
in worker processes at the same time (each worker writes numba's cache); the process then
loads them from the cache. Anything that goes wrong on the way (no process pool in a daemonic
worker, a cache directory that cannot be written, a numba without the cache API used here)
leaves the kernels to numba's usual compilation on first call: slower, same machine code.
Workers compile with Python's cyclic garbage collector off, and a compilation in the process
itself with rare collections (10-20 % of the compilation's CPU, see :func:`_compile_one`).

``DRIVEDYN_COMPILE_WORKERS`` sets the number of worker processes (default: the number of
CPUs; 0 or 1 compiles in the process itself). Workers are forked, so this runs on Linux and from a
single-threaded process; otherwise the kernels compile in the process.
"""

from __future__ import annotations

import concurrent.futures as cf
import gc
import importlib
import logging
import multiprocessing as mp
import os
import pickle
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

from drivedyn.jit_linked import is_linked

log = logging.getLogger("drivedyn")

#: measured first-compilation times [s] (2-core reference machine, the first kernel of a
#: compile worker, issue 16 tenth round; the general gear kernel and the Newton step alone
#: as measured in the ninth round), used only to start the longest compilations first;
#: other kernels count 3 s. The Type C bench's kernels on two workers: stepping loop, journal
#: contacts, washers, time functions (25.5 s) | gear pairs, joints, rigid bodies, loads (25.5 s)
COMPILE_SECONDS = {"run_steps": 12.1, "gear_kernel": 17.0, "parallel_gear_kernel": 13.9,
                   "constraint_kernel": 6.9, "journal_contact_kernel": 7.9,
                   "newton_iterations": 7.0, "washer_contact_kernel": 5.0,
                   "rigid_body_kernel": 2.6, "load_kernel": 2.1,
                   # compiled with the stepping loop (its worker writes it to the cache first)
                   "eval_time_functions": 0.5,
                   # the dense LU of small models (its helpers compiled with the stepping
                   # loop's): last, after the element kernels (issue 16 twelfth round)
                   "dense_factor_csc": 0.5, "dense_solve": 0.3}


#: resident memory [MB] above which a compile worker collects garbage before its next kernel
#: (its collector is off otherwise). Type C bench: a worker holds 390-400 MB after its first
#: kernel, 60-140 MB more after each next one, 670 MB after its four (no collection); a
#: model with more kernels keeps its workers near this bound plus one kernel's growth
WORKER_RSS_MB = 700.0

#: the cyclic garbage collector's thresholds while kernels compile in the process itself
#: (Python's default is (700, 10, 10); two Type C kernels in one process: 10-20 % less CPU,
#: +45 MB, where the collector off saved as much for +85 MB)
GC_THRESHOLDS = (100_000, 50, 100)
_GC_LOCK = threading.Lock()

_FORK = sys.platform.startswith("linux") and "fork" in mp.get_all_start_methods()


def workers_default() -> int:
    """Worker processes for a first compilation: ``DRIVEDYN_COMPILE_WORKERS`` or the CPU
    count."""
    env = os.environ.get("DRIVEDYN_COMPILE_WORKERS")
    if env is not None:
        try:
            return max(0, int(env))
        except ValueError:
            log.warning("DRIVEDYN_COMPILE_WORKERS=%r is not an integer; compiling in process",
                        env)
            return 0
    return os.cpu_count() or 1


def _loaded(disp: Any, sig: tuple) -> bool:
    """True if ``disp`` has an overload for ``sig`` in memory, or loads it from the cache."""
    cres = disp.overloads.get(sig)
    if cres is not None and not is_linked(cres):  # a linked overload cannot be called
        return True
    cache = getattr(disp, "_cache", None)
    if cache is None:
        return False
    cres = cache.load_overload(sig, disp.targetctx)
    if cres is None:
        return False
    # as numba's Dispatcher does on a cache hit: register the overload's lowering too, or a
    # compiled function calling this kernel fails with "No definition for lowering"
    if not cres.objectmode:
        disp.targetctx.insert_user_function(cres.entry_point, cres.fndesc, [cres.library])
    disp.add_overload(cres)
    disp._cache_hits[sig] += 1
    return True


def _compile_one(module: str, qualname: str, sig_bytes: bytes) -> float:
    """Worker: compile ``module.qualname`` for the pickled signature (numba caches it).

    The worker compiles with the cyclic garbage collector off: numba's compiler allocates
    millions of small objects, and the collections they trigger took 14-16 % of the Type C
    bench's first compilation (eight kernels, two workers, a slow hour: 174-183 -> 153-155 s
    of CPU, 91-96 -> 80-81 s wall). A collection (1.4-2 s in a worker that has compiled
    kernels) runs only before a kernel when the worker holds more than :data:`WORKER_RSS_MB`,
    which bounds its memory whatever the number of kernels."""
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


def _compile_here(todo: dict) -> None:
    """Compile the missing kernels in this process, the cyclic garbage collector run rarely
    meanwhile (as in :func:`_compile_one`; its thresholds are restored afterwards)."""
    with _GC_LOCK:  # the thresholds are the process's: two threads must not interleave
        thresholds = gc.get_threshold()
        gc.set_threshold(*GC_THRESHOLDS)
        try:
            for disp, sig in todo.values():
                try:
                    disp.compile(sig)
                except Exception as exc:  # compiled (its error raised) on first call instead
                    log.debug("precompile: %s failed (%s)", disp.py_func.__qualname__, exc)
        finally:
            gc.set_threshold(*thresholds)


def precompile_kernels(calls: list[tuple[Any, tuple]], workers: int | None = None,
                       while_waiting: Callable[[], Any] | None = None) -> dict:
    """Make sure each ``(dispatcher, signature)`` is compiled, compiling the missing ones in
    parallel worker processes.

    Args:
        calls: numba dispatchers with the argument-type tuples they will be called with.
        workers: worker processes (default :func:`workers_default`).
        while_waiting: called once in this process while the workers compile (work the run
            needs later, such as its lazy imports, taken off the critical path); an
            exception it raises is logged and ignored.
    Returns:
        ``{"missing": n, "compiled_in_workers": n, "wall_s": s}`` (for the log and tests).
    """
    t0 = time.perf_counter()
    workers = workers_default() if workers is None else workers
    todo: dict[tuple[str, str, bytes], tuple[Any, tuple]] = {}
    try:
        for disp, sig in calls:
            if _loaded(disp, sig):
                continue
            fn = disp.py_func
            key = (fn.__module__, fn.__qualname__, pickle.dumps(sig))
            todo.setdefault(key, (disp, sig))
    except Exception as exc:  # numba without this cache API: compile on first call
        log.debug("precompile: cache lookup unavailable (%s)", exc)
        return {"missing": 0, "compiled_in_workers": 0, "wall_s": time.perf_counter() - t0}
    done = 0
    # fork only: a spawned worker would import the user's script again (one without a
    # ``__main__`` guard would run its simulation in every worker); forked workers start from
    # this process as it is (no kernel is being compiled at this point, so no numba lock is
    # held), and only from a single-threaded process (a lock held by another thread at the
    # fork would stay held in the worker)
    if len(todo) >= 2 and workers >= 2 and _FORK and threading.active_count() == 1:
        order = sorted(todo, key=lambda k: -COMPILE_SECONDS.get(k[1], 3.0))
        log.info("first compilation of %d kernels in %d processes", len(todo),
                 min(workers, len(todo)))
        try:
            with cf.ProcessPoolExecutor(max_workers=min(workers, len(todo)),
                                        mp_context=mp.get_context("fork")) as pool:
                futures = {pool.submit(_compile_one, *k): k for k in order}
                if while_waiting is not None:
                    try:
                        while_waiting()
                    except Exception as exc:  # its work is redone where it is needed
                        log.debug("precompile: while_waiting failed (%s)", exc)
                for fut in cf.as_completed(futures):
                    try:
                        seconds = fut.result()
                        done += 1
                        log.debug("precompile: %s compiled in %.1f s (at %.1f s)",
                                  futures[fut][1], seconds, time.perf_counter() - t0)
                    except Exception as exc:  # this one compiles on first call instead
                        log.debug("precompile: %s failed in a worker (%s)", futures[fut][1],
                                  exc)
                        continue
                    # load it now, while the others compile: only the last one's load is
                    # left on the critical path (0.4 s for the Type C's eight kernels)
                    try:
                        _loaded(*todo[futures[fut]])
                    except Exception as exc:  # pragma: no cover - retried below
                        log.debug("precompile: cache load failed (%s)", exc)
        except Exception as exc:  # no process pool here (e.g. a daemonic worker)
            log.debug("precompile: no worker processes (%s)", exc)
        for disp, sig in todo.values():
            try:
                _loaded(disp, sig)
            except Exception as exc:  # pragma: no cover - compiled on first call instead
                log.debug("precompile: cache load failed (%s)", exc)
    elif todo:
        _compile_here(todo)
    return {"missing": len(todo), "compiled_in_workers": done,
            "wall_s": time.perf_counter() - t0}
