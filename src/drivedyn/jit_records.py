"""What numba records during a compilation that no drivedyn run reads, left out (a
compile-time saving, installed by :func:`drivedyn.jit.apply`).

- **LLVM-lock events.** numba registers two callbacks on llvmlite's LLVM lock
  (``numba.core.base._initialize_llvm_lock_event``), so every call into LLVM's C API
  broadcasts a ``numba:llvm_lock`` start and end event: 31 000 calls in the Type C bench's
  first compilation (building, parsing, optimising, linking and finalising modules, reading
  names). Their listeners are the timers each nested compilation installs to add up
  ``cres.metadata["timers"]["llvm_lock"]``, a figure for numba's own compile reports. Without
  the callbacks that timer reads 0; the lock itself is kept (it is what makes LLVM's C API
  thread-safe), and so is the compiler-lock timer (``numba:compiler_lock``).
- **Type annotations in cache entries.** numba writes into each cache entry the function's
  source annotated with the type of every variable (``str(cres.type_annotation)`` in
  ``CompileResult._reduce``), which only ``Dispatcher.inspect_types`` reads back, for a
  function loaded from the cache. Building that text annotates every line of every
  compiled function. An entry now holds :data:`NOTE` instead; ``inspect_types`` of a
  function compiled in the process is numba's, and ``DRIVEDYN_JIT_RECORDS=0`` brings the
  annotations back into new entries.

Measured on the Type C bench's kernels compiled serially in simultaneous pairs (issue 16
sixteenth round, benchmarks/README.md): 38.4 -> 36.8 s of CPU on average over six pairs
(five faster), 39.9 -> 39.1 s over six more (four faster): 2-4 %, about 0.5 s per compile
worker, below the spread of a cold start. The compiled code is the same: neither record
reaches LLVM.

Each is installed only if numba's source holds the passage it relies on; otherwise numba
records as before. ``DRIVEDYN_JIT_RECORDS=0`` (read when the first kernel module is
imported) leaves both in place.
"""

from __future__ import annotations

import inspect
import os

_state: dict = {"events": None, "annotations": None}

#: what a cache entry holds in place of the annotated source
NOTE = ("(type annotation not stored in the cache: drivedyn.jit_records; set "
        "DRIVEDYN_JIT_RECORDS=0 and remove the cache to keep it)")


def install() -> bool:
    """Remove numba's LLVM-lock event callbacks and its type annotations of cache entries
    (once); True if both are removed."""
    if _state["events"] is None:
        if os.environ.get("DRIVEDYN_JIT_RECORDS", "1") == "0":
            _state["events"] = _state["annotations"] = False
        else:
            _state["events"] = _remove_lock_events()
            _state["annotations"] = _install_plain_cache_entries()
    return bool(_state["events"] and _state["annotations"])


def _numba_lock_callbacks() -> list:
    """numba's ``(enter_fn, exit_fn)`` pairs on llvmlite's LLVM lock (none if this numba
    registers other callbacks)."""
    import llvmlite.binding as ll
    from numba.core import base  # noqa: F401 - registers the callbacks on import

    owner = "_initialize_llvm_lock_event.<locals>."
    return [(acq, rel) for acq, rel in list(ll.ffi.lib._lock._cblist)
            if getattr(acq, "__qualname__", "") == owner + "enter_fn"
            and getattr(rel, "__qualname__", "") == owner + "exit_fn"
            and getattr(acq, "__module__", "") == "numba.core.base"]


def _remove_lock_events() -> bool:
    """Unregister numba's two LLVM-lock callbacks; True if they were found and removed."""
    try:
        import llvmlite.binding as ll

        pairs = _numba_lock_callbacks()
        for acq, rel in pairs:
            ll.ffi.unregister_lock_callback(acq, rel)
    except (ImportError, AttributeError, ValueError):  # pragma: no cover - other llvmlite
        return False
    return bool(pairs)


def _install_plain_cache_entries() -> bool:
    """Wrap ``CompileResult._reduce`` so that a cache entry holds :data:`NOTE` instead of the
    annotated source; True if installed."""
    try:
        from numba.core import compiler

        reduce_ = compiler.CompileResult._reduce
        src = inspect.getsource(reduce_)
    except (ImportError, AttributeError, OSError, TypeError):  # pragma: no cover
        return False
    if "typeann = str(self.type_annotation)" not in src:
        return False  # pragma: no cover - another numba

    def _reduce(self):
        return reduce_(self._replace(type_annotation=NOTE))

    _reduce.__wrapped__ = reduce_
    _reduce.__doc__ = reduce_.__doc__
    compiler.CompileResult._reduce = _reduce
    return True
