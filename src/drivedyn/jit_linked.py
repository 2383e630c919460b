"""Functions that numba compiles only to link them into a caller: no entry points, no machine
code of their own (a compile-time saving, installed by :func:`drivedyn.jit.apply`).

When numba types a call from a compiled function to another ``njit`` function (a helper, an
element loop, numba's own ``@overload`` implementations), it compiles the callee completely,
as if Python were to call it: its LLVM module, then a CPython wrapper (the unboxing of every
argument) and a C wrapper, a full ``-O3`` pass over the result, machine code for it, and an
entry in the on-disk cache holding that machine code. The caller then links the callee's
module into its own, optimises the whole again at ``-O3`` and generates machine code for the
whole. For a callee that is only ever called from compiled code, the wrappers, the first
``-O3`` pass and the first machine code are never used: on the Type C bench they were a
third of the first compilation's CPU (measured, issue 16 tenth round).

:func:`install` makes numba compile a callee whose compilation another compilation asked for
(a *nested* compilation) as a *linked* overload:

- without the CPython and C wrappers (numba's ``no_cpython_wrapper`` and
  ``no_cfunc_wrapper``: what numba does for its own ``@overload`` implementations);
- its LLVM module optimised function by function (numba's function passes, as for every
  module) but not as a whole: the caller's final module runs the module passes over the
  callee's code with its own, after linking it in;
- no machine code: the module is never handed to the execution engine;
- cached on disk as LLVM bitcode, under its own key (numba's index key with ``"linked"``
  added to the code generator's description), so a linked overload is only ever loaded where
  a linked one is wanted;
- not callable from Python: it is not entered in the dispatcher's table of callable
  overloads, and its entry point raises ``TypeError`` if called.

A function compiled from Python (a call, ``Dispatcher.compile`` in the process or in a
compile worker) is compiled as before, with its wrappers, machine code and usual cache entry;
if the dispatcher only holds a linked overload for those argument types, the linked one is
replaced by a complete one (compiled, or loaded from the cache). The caller gets the callee's
code through the same linking and optimises it with the same module passes; only their order
of application differs (the callee's code was optimised twice before, once alone), so the
instructions differ in detail (register choices, layout) but compute the same numbers: LLVM
does not reassociate floating-point arithmetic without fast-math, which drivedyn does not
use. The Type C bench takes the same steps and Newton iterations to the same TDRs, all digits
printed, at the same element unit costs (benchmarks/README.md, issue 16 tenth round).

Everything is a wrapper of a numba method; if one of them is missing (another numba),
nothing is installed and numba compiles as before. ``DRIVEDYN_JIT_LINKED=0`` (read when the
first kernel module is imported) leaves numba as it is too: slower first compilation, same
results.
"""

from __future__ import annotations

import os
import sys
import threading
from typing import Any

_tls = threading.local()
_state: dict = {"installed": None}

#: marker added to the code generator's description in a linked overload's cache key
LINKED_KEY = "drivedyn-linked"


def _nested() -> bool:
    """True while this thread compiles a function another compilation asked for (the
    outermost compilation runs at depth 1)."""
    return getattr(_tls, "depth", 0) >= 2


def is_linked(cres: Any) -> bool:
    """True if the compile result ``cres`` is a linked overload (no entry points)."""
    return bool(getattr(getattr(cres, "library", None), "_drivedyn_linked", False))


def callable_overload(disp: Any, sig: tuple) -> Any:
    """The compile result of ``disp`` for the argument types ``sig`` with its entry points:
    the one the dispatcher holds, or a complete one compiled (or loaded from the cache) in
    place of a linked one."""
    cres = disp.overloads.get(tuple(sig))
    if cres is None or is_linked(cres):
        disp.compile(tuple(sig))
        cres = disp.overloads[tuple(sig)]
    return cres


def _linked_entry(qualname: str):
    """Entry point of a linked overload: a Python function that says why it cannot run."""

    def entry(*args, **kws):
        raise TypeError(f"{qualname}: this overload was compiled only to be linked into a "
                        "compiled caller (drivedyn.jit_linked); call the dispatcher instead")

    return entry


def install() -> bool:
    """Install the linked compilation of nested functions (once); True if installed."""
    if _state["installed"] is not None:
        return _state["installed"]
    _state["installed"] = False
    if os.environ.get("DRIVEDYN_JIT_LINKED", "1") == "0":
        return False
    try:
        from numba.core import caching, codegen, cpu, dispatcher, typed_passes
        from numba.core.compiler_lock import global_compiler_lock

        Dispatcher = dispatcher.Dispatcher
        Library = codegen.JITCodeLibrary
        originals = (Dispatcher.compile, Dispatcher.add_overload, Library.__init__,
                     Library._optimize_final_module, Library._finalize_final_module,
                     Library.serialize_using_object_code, cpu.CPUContext.get_executable,
                     caching.Cache._index_key, codegen.JITCPUCodegen.set_env)
        # the two places a function's own library is made: its lowering, and its load from
        # the cache (numba makes other libraries, such as its runtime's, that must run)
        creators = (typed_passes.NativeLowering.run_pass.__code__,
                    codegen.CPUCodeLibrary._unserialize.__func__.__code__)
        Library.serialize_using_bitcode  # noqa: B018 - used by the linked serialisation
    except (ImportError, AttributeError):  # pragma: no cover - other numba
        return False
    (compile_, add_overload, lib_init, optimize_final, finalize_final, serialize_object,
     get_executable, index_key, set_env) = originals

    def compile(self, sig):
        # numba's (re-entrant) compiler lock around the whole: another thread must not
        # compile this dispatcher between the change of its options and their restoration
        with global_compiler_lock:
            return _compile(self, sig)

    def _compile(self, sig):
        depth = getattr(_tls, "depth", 0)
        saved = None
        if depth == 0:
            # asked for from Python: a linked overload for these types is replaced
            from numba.core import sigutils

            args, _ = sigutils.normalize_signature(sig)
            cres = self.overloads.get(tuple(args))
            if cres is not None and is_linked(cres):
                del self.overloads[tuple(args)]
        else:
            saved = {k: self.targetoptions.get(k, _MISSING)
                     for k in ("no_cpython_wrapper", "no_cfunc_wrapper")}
            self.targetoptions["no_cpython_wrapper"] = True
            self.targetoptions["no_cfunc_wrapper"] = True
        _tls.depth = depth + 1
        try:
            return compile_(self, sig)
        finally:
            _tls.depth = depth
            if saved is not None:
                for k, v in saved.items():
                    if v is _MISSING:
                        self.targetoptions.pop(k, None)
                    else:
                        self.targetoptions[k] = v

    def add_overload_(self, cres):
        if is_linked(cres):  # typing and lowering find it here; Python calls do not
            self.overloads[tuple(cres.signature.args)] = cres
            return
        add_overload(self, cres)

    def lib_init_(self, *args, **kws):
        lib_init(self, *args, **kws)
        # a nested compilation's own library (frames: this, create_library, its caller)
        self._drivedyn_linked = _nested() and sys._getframe(2).f_code in creators

    def optimize_final_(self):
        if self._drivedyn_linked:  # the caller's module passes optimise this code
            return
        optimize_final(self)

    def finalize_final_(self):
        if not self._drivedyn_linked:
            return finalize_final(self)
        # as numba's, without handing the module to the execution engine (no machine code)
        self._finalize_dynamic_globals()
        self._verify_declare_only_symbols()
        self._finalized = True
        return None

    def serialize_object_(self):
        if self._drivedyn_linked:  # no machine code: the bitcode is what callers link
            return self.serialize_using_bitcode()
        return serialize_object(self)

    def get_executable_(self, library, fndesc, env):
        if getattr(library, "_drivedyn_linked", False):
            return _linked_entry(fndesc.qualname)
        return get_executable(self, library, fndesc, env)

    def index_key_(self, sig, codegen_):
        key = index_key(self, sig, codegen_)
        if _nested():
            key = (key[0], (*key[1], LINKED_KEY), *key[2:])
        return key

    def set_env_(self, env_name, env):
        # a linked library's environment has no address (its module is not in the engine;
        # numba would write through a null pointer)
        if self._engine.get_global_value_address(env_name):
            set_env(self, env_name, env)

    for fn, orig in ((set_env_, set_env), (compile, compile_), (add_overload_, add_overload),
                     (lib_init_, lib_init), (optimize_final_, optimize_final),
                     (finalize_final_, finalize_final), (serialize_object_, serialize_object),
                     (get_executable_, get_executable), (index_key_, index_key)):
        fn.__wrapped__ = orig
        fn.__doc__ = orig.__doc__
    Dispatcher.compile = compile
    Dispatcher.add_overload = add_overload_
    Library.__init__ = lib_init_
    Library._optimize_final_module = optimize_final_
    Library._finalize_final_module = finalize_final_
    Library.serialize_using_object_code = serialize_object_
    cpu.CPUContext.get_executable = get_executable_
    caching.Cache._index_key = index_key_
    codegen.JITCPUCodegen.set_env = set_env_
    _state["installed"] = True
    return True


_MISSING = object()
