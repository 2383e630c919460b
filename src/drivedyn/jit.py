"""Compile-time fix for numba's IR inliner, applied when a kernel module is imported.

drivedyn's kernels inline their helpers at numba's IR level (``inline="always"``): the
helpers' arithmetic then sits in the element loops, where LLVM optimises it with the loop
(measured: 13 % faster stepping than leaving the inlining to LLVM). numba's inliner copies
the callee's IR at every call site, block by block with ``copy.deepcopy``, and every
variable copies the function's whole scope with it: the cost of one copy grows with the
number of blocks times the number of variables. A copy also is made a second time only to be
returned to callers that discard it (numba issues 8989 and 9204; NVIDIA/numba-cuda#689 removes
the same two costs). On the Type C bench these copies took half of the first compilation.

:func:`apply` replaces ``InlineWorker.inline_ir`` by the same method with the two copies
fixed: the blocks are deep-copied in one call (one memo: the scope is copied once, and all
blocks share it, as they share it in the original; :func:`deepcopy_ir` makes
``copy.deepcopy``'s copy with fewer Python calls), and the unmutated input is returned
instead of a second copy. The method is rebuilt from numba's own source, and only if both
passages are found exactly as expected; otherwise numba is left as it is (slower first
compilation, same results). The compiled machine code is the same either way.

It also replaces ``InlineWorker.inline_function``, which runs the callee's whole untyped
pipeline (bytecode to IR, and its own nested inlining) at every call site, by the same
method with that IR computed once per function (:func:`_inline_function`): 7 % of the Type C
bench's first compilation (82 s -> 76 s of CPU, measured).

Inlining at numba's IR level is what costs first compilation: every inlined call site is
typed and lowered again. Helpers of a few statements that LLVM inlines anyway (``mv``,
``cross``, ``unwrap``...) are therefore plain ``njit`` functions: LLVM inlines them in the
final module (checked in the optimised IR; only the gear's ``_smoothstep`` stays a call),
stepping costs the same, and the Type C bench's first compilation fell from 76 s to 58 s of
CPU. Helpers LLVM would not inline (the projections, the scatter, the contact laws) or whose
literal ``full`` argument matters stay ``inline="always"``: left to LLVM they cost 12-15 % of
the stepping (measured).

The element loops themselves are compiled once each by numba and inlined by LLVM
(:func:`outlined`): numba's IR inlining with a literal ``full`` typed and lowered each loop
twice. And numba's typing is spared its repeats: the signature a call of a function (an
operator, a builtin, a numpy function) resolves to is remembered by argument types
(:func:`_install_call_type_memo`).

Finally, a function compiled because a compiled caller calls it is compiled only to be linked
into that caller: no entry points, no module passes and no machine code of its own
(:mod:`drivedyn.jit_linked`, installed by :func:`apply`): a third of the Type C bench's first
compilation.

The IR numba hands to LLVM is leaner where reference counting has nothing to do
(:func:`_install_lean_variables`): a variable whose decref is a no-op (every variable of a
loop compiled without reference counting, numbers elsewhere) gets no zero fill, no load
before a store and nothing at its ``del``, and a structure numba builds (a view, a slice)
is zero-filled once, where it is made, not also in the entry block. Those dead memory
operations made LLVM's SROA and instruction combiner carry zeros through phi nodes of whole
array structures: LLVM's share of the Type C bench's first compilation fell by a fifth
(26.9 -> 21.2 s of CPU), the whole by 11-15 %, with the same machine behaviour (same steps,
iterations and TDRs to all printed digits).

numba's SSA reconstruction rewrites only the blocks that name each variable, and its
post-processing computes the block-entry liveness only when something reads it
(:mod:`drivedyn.jit_passes`, installed by :func:`apply`): the same IR, a third less time in
numba's passes other than lowering.

Structures (arrays, slices, iterators) that numba only reads stay LLVM values instead of
stack slots (:mod:`drivedyn.jit_structs`), and reference counting reads only the members of
a structure that hold counted memory (:func:`_install_lean_meminfos`): a fifth fewer
instructions handed to LLVM, the same optimised code.

Array indexing reads each shape and stride only where it is used and writes no wraparound
for a constant index (:mod:`drivedyn.jit_indexing`): 14 % fewer instructions handed to LLVM,
the same optimised code.

What numba records for its own reports and nobody reads here is left out
(:mod:`drivedyn.jit_records`): the LLVM-lock events of each call into LLVM and the
annotated source in each cache entry (2-4 % of the first compilation).
"""

from __future__ import annotations

import glob
import importlib.machinery
import importlib.util
import inspect
import os
import sys
import textwrap
from types import ModuleType
from typing import Any

from drivedyn import jit_indexing, jit_irtext, jit_linked, jit_passes, jit_records, jit_structs

_COPY_PER_BLOCK = """\
        kernel_copy.blocks = {}
        for block_label, block in the_ir.blocks.items():
            new_block = copy.deepcopy(the_ir.blocks[block_label])
            kernel_copy.blocks[block_label] = new_block
"""
_COPY_ONCE = """\
        # one deepcopy of all blocks: the scope they share is copied once
        kernel_copy.blocks = _drivedyn_deepcopy(the_ir.blocks, {})
"""
_FIRST_COPY = "    callee_ir = copy_ir(callee_ir)\n"
_FIRST_COPY_KEEP = "    callee_ir_original = callee_ir\n    callee_ir = copy_ir(callee_ir)\n"
_SECOND_COPY = "    callee_ir_original = copy_ir(callee_ir)\n"

_state = {"applied": None}

#: untyped IR of inlined functions, by (function, untyped pipeline): see :func:`apply`
_untyped_ir: dict = {}


def _inline_function(self, caller_ir, block, i, function, arg_typs=None):
    """``InlineWorker.inline_function`` with the callee's untyped IR computed once per
    function (numba runs the callee's whole untyped pipeline, nested inlining included, at
    every call site). Safe because :meth:`inline_ir` copies the IR before it changes it
    ("Always copy the callee IR, it gets mutated") and returns that unchanged input."""
    key = (function, self._compiler_pipeline)
    callee_ir = _untyped_ir.get(key)
    if callee_ir is None:
        callee_ir = self.run_untyped_passes(function)
        _untyped_ir[key] = callee_ir
    return self.inline_ir(caller_ir, block, i, callee_ir, function.__code__.co_freevars,
                          arg_typs=arg_typs)


#: signatures of resolved calls, by (function type, typing context, argument types): see
#: :func:`_install_call_type_memo`
_call_types: dict = {}
#: [hits, misses] of that memo (for the tests and a compile profile)
memo_counts = [0, 0]


def _install_call_type_memo() -> None:
    """Remember the signatures numba's typing resolves for calls of functions (operators,
    builtins, numpy functions, overloads), by function type and argument types.

    numba resolves a call by trying the function's templates one after the other (a float
    addition tries dozens, each failure recorded with its message) at every call site and
    every pass of type inference; the element kernels have thousands of sites with a few
    hundred distinct (function, argument types) pairs. In the Type C bench's first
    compilation 95 % of the resolutions were repeats, 8.6 s of its 89 s of CPU (measured).
    A repeat now returns the signature of the first resolution. That is what numba computes
    again: the templates' result depends only on the argument types (literal values
    included: they are part of the types), and the first resolution did the side effects
    (the implementation key of the signature, the compiled ``@overload``). Failures are not
    remembered (they raise, as before)."""
    if _state.get("memo") is not None:
        return
    _state["memo"] = False
    try:
        from numba.core.types.functions import Function

        resolve = Function.get_call_type
    except (ImportError, AttributeError):  # pragma: no cover - other numba
        return

    def get_call_type(self, context, args, kws):
        try:
            key = (self, context, args, tuple(sorted(kws.items())) if kws else ())
            sig = _call_types.get(key)
        except TypeError:  # an unhashable argument type: resolve as numba does
            return resolve(self, context, args, kws)
        if sig is None:
            sig = resolve(self, context, args, kws)
            if sig is not None:
                _call_types[key] = sig
            memo_counts[1] += 1
        else:
            memo_counts[0] += 1
        return sig

    get_call_type.__wrapped__ = resolve
    get_call_type.__doc__ = resolve.__doc__
    Function.get_call_type = get_call_type
    _state["memo"] = True


#: (data model manager id, numba type) -> the type's values hold no reference-counted
#: memory (:func:`_install_lean_variables`)
_uncounted: dict = {}


def _install_lean_variables() -> None:
    """Lower the variables whose reference counting is a no-op without its dead memory
    operations (once).

    numba keeps every variable of a function that spans blocks in a stack slot and, so that
    a decref of a variable never assigned is harmless, it fills each slot with zeros on
    entry, loads the old value before every store to decref it, and at every ``del`` (numba
    emits one after each variable's last use: half the statements of an element loop) loads
    the value, decrefs it and stores zeros again. For a function compiled without reference
    counting (the :func:`outlined` loops and their helpers), or a variable whose type holds
    no counted memory (numbers, booleans, tuples of them), every decref is a no-op, so these
    loads and stores are dead: LLVM removes them, but only after its SROA pass has rewritten
    each aggregate (an array is a structure of seven fields) through them. Here they are
    not emitted: no zero fill, no load before a store, nothing at a ``del``. Variables that
    hold counted memory in a function compiled with reference counting are lowered as numba
    lowers them; so is everything when numba lowers with debug information. The only value
    that changes is that of a variable read before its first assignment (numba's zero, now
    undefined), which Python itself refuses.

    Measured on the Type C bench's first compilation (issue 16, eleventh round): LLVM's
    function passes 8.6 -> 6.8 s of CPU, the gear loop's unoptimised IR 30 282 -> 28 642
    lines. The methods are replaced only if numba's ``delvar`` and ``storevar`` contain the
    passages this reimplements; otherwise numba is left as it is."""
    if _state.get("lean") is not None:
        return
    _state["lean"] = False
    try:
        from numba.core import debuginfo
        from numba.core.lowering import Lower

        src_del = inspect.getsource(Lower.delvar)
        src_store = inspect.getsource(Lower.storevar)
    except (ImportError, AttributeError, OSError, TypeError):  # pragma: no cover - other numba
        return
    if not ("self.decref(fetype, self.builder.load(ptr))" in src_del
            and "self.builder.store(Constant(ptr.type.pointee, None), ptr)" in src_del
            and "self._alloca_var(name, fetype)" in src_del
            and "old = self.loadvar(name)" in src_store
            and "self._blk_local_varmap[name] = value" in src_store
            and all(hasattr(Lower, a) for a in ("alloca", "_alloca_var", "getvar"))):
        return  # pragma: no cover - another numba: its own lowering
    delvar, storevar, alloca = Lower.delvar, Lower.storevar, Lower.alloca

    def lean(self, fetype) -> bool:
        """True if decrefs of ``fetype`` are no-ops here (and no debug information)."""
        if self._disable_sroa_like_opt:
            return False
        if not self.context.enable_nrt:
            return True
        dmm = self.context.data_model_manager  # one per target: part of the key
        key = (id(dmm), fetype)
        flag = _uncounted.get(key)
        if flag is None:
            flag = _uncounted[key] = not dmm[fetype].contains_nrt_meminfo()
        return flag

    def lean_delvar(self, name):
        fetype = self.typeof(name)
        if not lean(self, fetype):
            return delvar(self, name)
        # numba's bookkeeping without the load, decref and zero store
        if name not in self._blk_local_varmap:
            self._singly_assigned_vars.discard(name)
        self._alloca_var(name, fetype)

    def lean_storevar(self, value, name, argidx=None):
        fetype = self.typeof(name)
        if argidx is not None or not lean(self, fetype):
            return storevar(self, value, name, argidx)
        self._alloca_var(name, fetype)
        if name in self._singly_assigned_vars:
            self._blk_local_varmap[name] = value
            return
        ptr = self.getvar(name)  # no load of the old value: nothing to decref
        if value.type != ptr.type.pointee:
            raise AssertionError(f"Storing {value.type} to ptr of {ptr.type.pointee} "
                                 f"('{name}'). FE type {fetype}")
        self.builder.store(value, ptr)

    def lean_alloca(self, name, type):
        if not lean(self, type):
            return alloca(self, name, type)
        lltype = self.context.get_value_type(type)
        with debuginfo.suspend_emission(self.builder), self.builder.goto_entry_block():
            return self.builder.alloca(lltype, name=name)  # no zero fill

    for new, old in ((lean_delvar, delvar), (lean_storevar, storevar), (lean_alloca, alloca)):
        new.__wrapped__ = old
        new.__doc__ = old.__doc__
    Lower.delvar, Lower.storevar, Lower.alloca = lean_delvar, lean_storevar, lean_alloca
    _state["lean"] = True
    _install_lean_struct_slots()


def _install_lean_struct_slots() -> None:
    """Give the stack slot of a structure numba builds (an array view, a slice, an iterator:
    ``cgutils.create_struct_proxy``) one zero fill, where the structure is made, instead of
    two (once).

    numba's ``alloca_once(..., zfill=True)`` zero-fills a new slot twice: in the function's
    entry block ("always zero-fill at init-site") and where the structure is made. The slot
    is reachable only through the structure's proxy, which numba's lowering makes and fills
    in straight-line code at that point, so the zero fill kept there precedes every use and
    the one in the entry block initialises memory nobody reads first. It is not harmless for
    LLVM: each entry-block zero reaches the loop headers of the function, and SROA, the
    instruction combiner and value propagation carry it through phi nodes of whole
    structures (measured on the gear loop's function passes alone: 0.87-1.02 s with it,
    0.46-0.56 s without, the optimised code the same up to four lines of 3815). Replaced
    only if numba's method is the one this reimplements."""
    try:
        from numba.core import cgutils, debuginfo

        src = inspect.getsource(cgutils._StructProxy._make_refs)
        alloc = inspect.getsource(cgutils.alloca_once)
    except (ImportError, AttributeError, OSError, TypeError):  # pragma: no cover - other numba
        return
    if ("ref = alloca_once(self._builder, self._be_type, zfill=True)" not in src
            or "builder.store(ty(None), ptr)" not in alloc
            or "builder.store(ptr.type.pointee(None), ptr)" not in alloc):
        return  # pragma: no cover - another numba: its own lowering
    make_refs = cgutils._StructProxy._make_refs

    def _make_refs(self, ref):
        if ref is None:
            builder = self._builder
            with debuginfo.suspend_emission(builder):
                with builder.goto_entry_block():
                    ref = builder.alloca(self._be_type)
                builder.store(self._be_type(None), ref)  # numba's use-site zero fill
        return ref, ref

    _make_refs.__wrapped__ = make_refs
    _make_refs.__doc__ = make_refs.__doc__
    cgutils._StructProxy._make_refs = _make_refs
    _state["struct_slots"] = True


def _install_lean_meminfos() -> None:
    """Find the counted memory inside a structure without reading its uncounted members
    (once).

    To incref or decref a value, numba lists the reference-counted pointers (meminfos)
    inside it (``NRTContext.get_meminfos``): it reads *every* member of every structure
    with an ``extractvalue`` and recurses into it, though only the meminfo pointers are
    used. An array has one meminfo in seven fields; a tuple of arrays, or the stepping loop's
    kernel table (tuples of tuples of arrays), has hundreds of fields. On the Type C bench's
    kernels those dead reads were 49 425 of the 219 885 instructions numba handed to LLVM
    (numba builds them in Python, prints them as IR text and LLVM parses and deletes them).
    Here a member is read only if its type holds a meminfo
    (``DataModel.contains_nrt_meminfo``, remembered per type): the same meminfos in the
    same order, the same increfs and decrefs. Replaced only if numba's method is the one
    this reimplements."""
    if _state.get("meminfos") is not None:
        return
    _state["meminfos"] = False
    try:
        from numba.core.runtime import context as nrt_context

        ctx = nrt_context.NRTContext
        src = inspect.getsource(ctx.get_meminfos)
    except (ImportError, AttributeError, OSError, TypeError):  # pragma: no cover - other numba
        return
    if not ("members = datamodel.traverse(builder)" in src
            and "mi = datamodel.get_nrt_meminfo(builder, val)" in src
            and "field = getter(val)" in src
            and "inner_meminfos = self.get_meminfos(builder, mtyp, field)" in src):
        return  # pragma: no cover - another numba
    original = ctx.get_meminfos

    def get_meminfos(self, builder, ty, val):
        dmm = self._context.data_model_manager
        datamodel = dmm[ty]
        meminfos = []
        if datamodel.has_nrt_meminfo():
            meminfos.append((ty, datamodel.get_nrt_meminfo(builder, val)))
        for mtyp, getter in datamodel.traverse(builder):
            key = (id(dmm), mtyp)  # one data model manager per target: part of the key
            flag = _uncounted.get(key)
            if flag is None:
                flag = _uncounted[key] = not dmm[mtyp].contains_nrt_meminfo()
            if not flag:  # a member without counted memory has no meminfo to find
                meminfos.extend(self.get_meminfos(builder, mtyp, getter(val)))
        return meminfos

    get_meminfos.__wrapped__ = original
    get_meminfos.__doc__ = original.__doc__
    ctx.get_meminfos = get_meminfos
    _state["meminfos"] = True


def _install_plain_markup() -> None:
    """Build numba's highlighted message strings without re-initialising colorama (once).

    numba formats a message for every failed typing attempt and every value ``typeof``
    cannot type (about 39 000 in the Type C bench's first compilation), and each one wraps
    and unwraps ``sys.stdout`` and ``sys.stderr`` with colorama (``init``/``deinit``) around
    a string concatenation. The strings are the same without the wrapping: style codes,
    message, reset. Installed only where numba uses colorama and its method is as expected."""
    if _state.get("markup") is not None:
        return
    _state["markup"] = False
    try:
        from numba.core import errors

        scheme = errors.HighlightColorScheme
        src = inspect.getsource(scheme._markup)
        from colorama import Style
    except (ImportError, AttributeError, OSError, TypeError):  # no colorama: numba's plain
        return
    if "with ColorShell():" not in src or "mu += (msg).encode('utf-8')" not in src:
        return  # pragma: no cover - another numba
    reset = Style.RESET_ALL

    def _markup(self, msg, color=None, style=Style.BRIGHT):
        return f"{color or ''}{style or ''}{msg}{reset}"

    _markup.__wrapped__ = scheme._markup
    scheme._markup = _markup
    _state["markup"] = True


def _install_has_loc_memo() -> None:
    """Remember, per implementation function, whether numba's lowering may pass it a
    ``loc`` argument (once).

    numba wraps every lowering implementation it looks up (``_wrap_missing_loc``) and asks
    ``inspect.signature`` each time whether the function takes ``loc``: 7000 signatures in
    the Type C bench's first compilation, 1 % of it. A function's parameters do not change,
    so the answer is kept per function (weakly: a function that goes away takes its entry
    with it); a callable that cannot be weakly referenced is asked each time, as before."""
    if _state.get("has_loc") is not None:
        return
    _state["has_loc"] = False
    try:
        from numba.core import base

        src = inspect.getsource(base._has_loc)
        call_src = inspect.getsource(base._wrap_missing_loc.__call__)
    except (ImportError, AttributeError, OSError, TypeError):  # pragma: no cover - other numba
        return
    if "return 'loc' in sig.parameters" not in src or "_has_loc(fn)" not in call_src:
        return  # pragma: no cover - another numba
    import weakref

    has_loc = base._has_loc
    known: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()

    def _has_loc(fn):
        try:
            return known[fn]
        except KeyError:
            known[fn] = out = has_loc(fn)
            return out
        except TypeError:  # not weakly referable or not hashable: numba's answer each time
            return has_loc(fn)

    _has_loc.__wrapped__ = has_loc
    _has_loc.__doc__ = has_loc.__doc__
    base._has_loc = _has_loc  # _wrap_missing_loc reads the module global at each call
    _state["has_loc"] = True


def scipy_linalg_extension(name: str) -> ModuleType:
    """``scipy.linalg.<name>`` (a compiled module: ``cython_blas``, ``cython_lapack``),
    loaded from its file without running ``scipy.linalg``'s ``__init__``.

    That ``__init__`` imports the whole of ``scipy.linalg`` and SciPy's array-API layer:
    0.3-0.4 s, paid by every command that compiles or loads a kernel, before its compile
    workers fork, because numba's first context refresh imports ``scipy.linalg.cython_blas``
    only to see that BLAS is there (``numba.np.arraymath._HAVE_BLAS``), and the dense LU
    needs ``cython_lapack``'s LAPACK. The module is entered in ``sys.modules`` under its
    own name, as an import would, so numba's import and any later ``import scipy.linalg``
    find it there. Another layout of SciPy falls back to the usual import."""
    full = f"scipy.linalg.{name}"
    mod = sys.modules.get(full)
    if mod is not None:
        return mod
    if "scipy.linalg" in sys.modules:  # nothing to save: the usual import
        return importlib.import_module(full)
    try:
        spec = importlib.util.find_spec("scipy")  # the top-level package only
        folder = os.path.join(os.path.dirname(spec.origin), "linalg")
        suffixes = tuple(importlib.machinery.EXTENSION_SUFFIXES)
        files = [f for f in glob.glob(os.path.join(folder, f"{name}.*")) if f.endswith(suffixes)]
        if len(files) != 1:
            raise ImportError(f"{len(files)} {name} extension files in {folder}")
        loader = importlib.machinery.ExtensionFileLoader(full, files[0])
        spec = importlib.util.spec_from_file_location(full, files[0], loader=loader)
        mod = importlib.util.module_from_spec(spec)
        sys.modules[full] = mod
        try:
            loader.exec_module(mod)
        except BaseException:
            sys.modules.pop(full, None)
            raise
        mod.__pyx_capi__  # noqa: B018 - a Cython module's table of functions
    except Exception:  # any other layout: the usual import
        return importlib.import_module(full)
    _LinalgChildren.install()
    return mod


class _LinalgChildren:
    """A one-time import hook: when ``scipy.linalg`` is imported after
    :func:`scipy_linalg_extension` loaded some of its modules, they are bound as its
    attributes before its ``__init__`` runs, as the import system binds a submodule it loads
    itself (``scipy.linalg.cython_blas`` then works as an attribute too)."""

    @classmethod
    def install(cls) -> None:
        if not any(isinstance(f, cls) for f in sys.meta_path):
            sys.meta_path.insert(0, cls())

    def find_spec(self, fullname: str, path: Any, target: Any = None) -> Any:
        if fullname != "scipy.linalg":
            return None
        sys.meta_path.remove(self)
        spec = importlib.util.find_spec(fullname)  # found as it would be without this hook
        loader = getattr(spec, "loader", None)
        if loader is None or not hasattr(loader, "exec_module"):
            return spec  # pragma: no cover - another layout
        exec_module = loader.exec_module

        def bind_then_exec(module: ModuleType) -> None:
            for key, child in list(sys.modules.items()):
                if key.startswith("scipy.linalg.") and "." not in key[13:]:
                    setattr(module, key[13:], child)
            exec_module(module)

        loader.exec_module = bind_then_exec
        return spec

    def invalidate_caches(self) -> None:
        return None


# --- the inliner's deep copy ---------------------------------------------------------------

_NIL = object()
#: per class: how :func:`deepcopy_ir` copies its instances (see there)
_copy_kind: dict = {}
#: classes copy.deepcopy returns as they are
_ATOMIC = frozenset((type(None), int, float, bool, complex, str, bytes, type, range,
                     type(len), type(_copy_kind.get), type(lambda: None), property))


def _kind(cls: type) -> str:
    """``"plain"`` for a class whose instances ``copy.deepcopy`` rebuilds from their
    ``__dict__`` alone (``object``'s own reduction, no slots, no ``__setstate__``, no
    ``__deepcopy__``, nothing in ``copyreg``'s table), ``"var"``, ``"const"``,
    ``"global"`` and ``"freevar"`` for numba's IR classes whose ``__deepcopy__`` is
    reproduced in :func:`deepcopy_ir`, ``"other"`` for everything else."""
    import copyreg

    from numba.core import ir

    special = {ir.Var: "var", ir.Const: "const", ir.Global: "global", ir.FreeVar: "freevar"}
    if cls in special and _state.get("ir_copies_checked"):
        return special[cls]
    if (cls in copyreg.dispatch_table or issubclass(cls, type)
            or getattr(cls, "__deepcopy__", None) is not None
            or cls.__reduce_ex__ is not object.__reduce_ex__
            or cls.__reduce__ is not object.__reduce__
            or getattr(cls, "__getstate__", object.__getstate__) is not object.__getstate__
            or hasattr(cls, "__setstate__") or copyreg._slotnames(cls)
            or "__dict__" not in dir(cls)):
        return "other"
    return "plain"


def deepcopy_ir(x: Any, memo: dict) -> Any:
    """``copy.deepcopy(x, memo)`` of numba IR (blocks, statements, expressions, variables,
    scopes, locations), the same copy made with fewer Python calls.

    numba's inliner deep-copies the callee's blocks at every call site (0.8 s of the Type C
    bench's first compilation, measured, issue 16 fourteenth round). ``copy.deepcopy`` finds
    out how to copy each object by several lookups (a copier table, ``__deepcopy__``,
    ``copyreg``, ``__reduce_ex__``) and copies an instance through its reduction tuple. Here
    a class's way is decided once (:func:`_kind`): atomic values are returned, lists,
    tuples and dicts copied as ``copy`` copies them, plain instances rebuilt from their
    ``__dict__``, numba's ``Var``, ``Const``, ``Global`` and ``FreeVar`` copied as their
    ``__deepcopy__`` methods copy them (checked against their source), and anything else
    goes to ``copy.deepcopy`` with the same memo. The memo holds the same entries, so
    objects shared in the original (the scope, a variable used twice) are shared in the
    copy as before."""
    d = id(x)
    y = memo.get(d, _NIL)
    if y is not _NIL:
        return y
    cls = type(x)
    if cls in _ATOMIC:
        return x
    if cls is list:
        y = memo[d] = []
        append = y.append
        for a in x:
            append(deepcopy_ir(a, memo))
        return y
    if cls is dict:
        y = memo[d] = {}
        for k, v in x.items():
            y[deepcopy_ir(k, memo)] = deepcopy_ir(v, memo)
        return y
    if cls is tuple:
        items = [deepcopy_ir(a, memo) for a in x]
        y = memo.get(d, _NIL)  # a tuple that holds itself, through a list
        if y is not _NIL:
            return y
        for a, b in zip(x, items, strict=True):
            if a is not b:
                y = memo[d] = tuple(items)
                return y
        return x  # copy returns (and does not remember) a tuple of atomic values
    kind = _copy_kind.get(cls)
    if kind is None:
        kind = _copy_kind[cls] = _kind(cls)
    if kind == "plain":
        y = memo[d] = cls.__new__(cls)
        state = x.__dict__
        if state:
            new = memo[id(state)] = {}
            for k, v in state.items():
                new[k] = deepcopy_ir(v, memo)
            y.__dict__.update(new)
        return y
    if kind == "var":  # ir.Var.__deepcopy__
        y = memo[d] = cls(deepcopy_ir(x.scope, memo), x.name, x.loc)
        return y
    if kind == "const":  # ir.Const.__deepcopy__: the value and location are shared
        y = memo[d] = cls(value=x.value, loc=x.loc, use_literal_type=x.use_literal_type)
        return y
    if kind == "global":  # ir.Global.__deepcopy__: the location copied with a memo of its own
        y = memo[d] = cls(x.name, x.value, deepcopy_ir(x.loc, {}))
        return y
    if kind == "freevar":  # ir.FreeVar.__deepcopy__
        y = memo[d] = cls(index=x.index, name=x.name, value=x.value, loc=x.loc)
        return y
    import copy

    return copy.deepcopy(x, memo)


#: the bodies of numba's __deepcopy__ methods deepcopy_ir reproduces
_IR_COPIES = {
    "Var": "out = Var(copy.deepcopy(self.scope, memo), self.name, self.loc)",
    "Const": "value=self.value, loc=self.loc,",
    "Global": "return Global(self.name, self.value, copy.deepcopy(self.loc))",
    "FreeVar": "return FreeVar(index=self.index, name=self.name, value=self.value,",
}


def _check_ir_copies() -> bool:
    """True if numba's IR classes copy themselves as :func:`deepcopy_ir` copies them."""
    try:
        from numba.core import ir

        for name, passage in _IR_COPIES.items():
            if passage not in inspect.getsource(getattr(ir, name).__deepcopy__):
                return False  # pragma: no cover - another numba: copy.deepcopy for them
    except (ImportError, AttributeError, OSError, TypeError):  # pragma: no cover
        return False
    return True


def apply() -> bool:
    """Install the fixed ``InlineWorker.inline_ir`` (once); True if it is installed. Also
    installs the memo of call signatures (:func:`_install_call_type_memo`), the lean
    lowering of uncounted variables (:func:`_install_lean_variables`), the meminfo search
    without uncounted members (:func:`_install_lean_meminfos`), numba's message
    markup without colorama's stream wrapping (:func:`_install_plain_markup`), the memo of
    ``loc`` parameters (:func:`_install_has_loc_memo`), the lighter
    SSA and post-processing passes (:func:`drivedyn.jit_passes.install`), the faster IR
    text (:func:`drivedyn.jit_irtext.install`), the structures
    held as values (:func:`drivedyn.jit_structs.install`; ``DRIVEDYN_JIT_VALUES=0`` leaves
    it out), the lean array indexing (:func:`drivedyn.jit_indexing.install`;
    ``DRIVEDYN_JIT_INDEXING=0`` leaves it out) and the linked compilation of nested functions
    (:func:`drivedyn.jit_linked.install`; ``DRIVEDYN_JIT_LINKED=0`` leaves it out), and
    compiles without numba's LLVM-lock events and the type annotations of cache entries
    (:func:`drivedyn.jit_records.install`; ``DRIVEDYN_JIT_RECORDS=0`` leaves them)."""
    if _state["applied"] is not None:
        return _state["applied"]
    _install_call_type_memo()
    _install_lean_variables()
    _install_lean_meminfos()
    _install_plain_markup()
    _install_has_loc_memo()
    try:  # before numba's first refresh imports it with scipy.linalg's package
        scipy_linalg_extension("cython_blas")
    except ImportError:  # no SciPy: numba does without BLAS
        pass
    jit_passes.install()
    jit_irtext.install()
    jit_structs.install()
    jit_indexing.install()
    jit_linked.install()
    jit_records.install()
    ok = False
    try:
        from numba.core import inline_closurecall as icc

        src = textwrap.dedent(inspect.getsource(icc.InlineWorker.inline_ir))
        body = src.split("\n", 1)[1]  # after the def line; the passages are indented once
        if (src.count(_COPY_PER_BLOCK) == 1 and src.count(_SECOND_COPY) == 1
                and body.count(_FIRST_COPY) == 1):
            new = (src.replace(_COPY_PER_BLOCK, _COPY_ONCE)
                   .replace(_SECOND_COPY, "")
                   .replace(_FIRST_COPY, _FIRST_COPY_KEEP))
            ns = dict(vars(icc))
            _state["ir_copies_checked"] = _check_ir_copies()
            _copy_kind.clear()
            ns["_drivedyn_deepcopy"] = deepcopy_ir
            exec(compile(new, icc.__file__, "exec"), ns)  # numba's own source, edited above
            fixed = ns["inline_ir"]
            fixed.__doc__ = icc.InlineWorker.inline_ir.__doc__
            fixed.__drivedyn_fixed__ = True
            icc.InlineWorker.inline_ir = fixed
            icc.InlineWorker.inline_function = _inline_function
            ok = True
    except (ImportError, OSError, TypeError, SyntaxError):  # pragma: no cover - other numba
        ok = False
    _state["applied"] = ok
    return ok


# --- element loops: compiled once by numba, inlined by LLVM ------------------------------------

#: dispatchers whose call sites LLVM must inline (:func:`outlined`)
_OUTLINED: list = []


def outlined(fn=None, *, cache: bool = True):
    """``njit(cache=True)`` for an element loop: numba compiles it once, without reference
    counting, and LLVM inlines it at every call site (the call carries LLVM's
    ``alwaysinline``).

    A kernel calls its loop at two sites, where ``full`` (matrices wanted) is true at one and
    false at the other (:func:`drivedyn.elements.scaffold.run`). Inlined at numba's IR level
    with ``full`` a literal, the loop was typed and lowered twice, once per copy. Compiled
    once with ``full`` a run-time flag and inlined by LLVM at both sites, each copy is
    specialised by LLVM's constant propagation (the branches on ``full`` fold, the
    residual-only copy loses the matrix code) as numba specialised it before: the Type C
    bench takes the same steps and Newton iterations to the same TDRs (all digits printed),
    and numba types and lowers each loop once.

    The loop compiles without numba's reference counting (``_nrt=False``): it allocates
    nothing (its work arrays come from the kernel, which holds every array it touches for
    the whole call), so the counting only cost time, on entry (two atomic operations per
    array argument) and on every array view in the loop. A loop that allocates fails to
    compile, it does not leak: numba refuses an allocation it lowers itself ("NRT required"),
    and a pass added to numba's pipeline refuses any call or operator whose result holds an
    array (:func:`_install_new_array_check`: a function compiled earlier with reference
    counting would hand over a new array that nothing frees). Non-inlined helpers compiled
    from a loop inherit the setting; one that allocates internally says ``_nrt=True``.

    Measured on the Type C bench (benchmarks/README.md, issue 16 ninth round), with
    :func:`_install_call_type_memo`: first compilation of its kernels -37 % of CPU (cold
    start 64-67 -> 47-48 s), residual-only and matrix evaluations -15 %."""
    if fn is None:  # @outlined(cache=False)
        return lambda f: outlined(f, cache=cache)
    from numba import njit

    _install_new_array_check()
    disp = njit(cache=cache, _nrt=False)(fn)
    _OUTLINED.append(disp)
    _install_call_site_inlining()
    return disp


def _holds_array(ty) -> bool:
    """True if a value of numba type ``ty`` is or contains an array."""
    from numba.core import types

    if isinstance(ty, types.Array):
        return True
    if isinstance(ty, types.BaseTuple):
        return any(_holds_array(t) for t in ty.types)
    return False


def _install_new_array_check() -> None:
    """Add one pass after type inference to numba's nopython pipeline (once): in a function
    compiled without reference counting (an :func:`outlined` loop, and the non-inlined
    helpers it compiles, which inherit the setting) it refuses a call or an arithmetic
    operator whose result holds an array. Such a result is a new array (views come from
    indexing, which is not a call), and nothing would free it. Functions compiled with
    reference counting (all others) are not looked at."""
    if _state.get("new_array_check") is not None:
        return
    _state["new_array_check"] = False
    try:
        from numba.core import ir
        from numba.core.compiler import DefaultPassBuilder
        from numba.core.compiler_machinery import FunctionPass, register_pass
        from numba.core.errors import TypingError
        from numba.core.typed_passes import NopythonTypeInference
    except ImportError:  # pragma: no cover - other numba: numba's own NRT errors only
        return

    @register_pass(mutates_CFG=False, analysis_only=True)
    class NoNewArrays(FunctionPass):
        _name = "drivedyn_no_new_arrays"

        def __init__(self):
            FunctionPass.__init__(self)

        def run_pass(self, state):
            if state.flags.nrt:
                return False
            for expr, sig in state.calltypes.items():
                if (isinstance(expr, ir.Expr)
                        and expr.op in ("call", "binop", "inplace_binop", "unary")
                        and sig is not None and _holds_array(sig.return_type)):
                    raise TypingError(
                        f"{state.func_id.func_qualname} makes a new array "
                        f"({sig.return_type}) but compiles without reference counting (an "
                        "element loop, or a helper it calls: drivedyn.jit.outlined), so "
                        "nothing would free it; write into a work array allocated by the "
                        "kernel, or give a helper that allocates internally _nrt=True",
                        loc=expr.loc)
            return False

    define = DefaultPassBuilder.define_nopython_pipeline

    def define_nopython_pipeline(state, name="nopython"):
        pm = define(state, name)
        pm.add_pass_after(NoNewArrays, NopythonTypeInference)
        pm.finalize()  # numba finalised it; adding a pass un-finalises it
        return pm

    DefaultPassBuilder.define_nopython_pipeline = staticmethod(define_nopython_pipeline)
    _state["new_array_check"] = True


def _outlined_names() -> set:
    """LLVM names of every compiled overload of the :func:`outlined` functions."""
    return {cres.fndesc.mangled_name for d in _OUTLINED for cres in list(d.overloads.values())}


def _install_call_site_inlining() -> None:
    """Wrap numba's ``CPUCodeLibrary.add_ir_module`` (once) so that a module calling an
    :func:`outlined` function marks those calls ``alwaysinline``. The callee's code is linked
    into the caller's final module, where LLVM's inliner honours the mark. Without this
    wrapper (a numba without ``add_ir_module``) the loops are plain calls: same results,
    slower residual-only evaluations."""
    if _state.get("inlining") is not None:
        return
    _state["inlining"] = False
    try:
        from llvmlite import ir as llvmir
        from numba.core import codegen

        orig = codegen.CPUCodeLibrary.add_ir_module
    except (ImportError, AttributeError):  # pragma: no cover - other numba
        return

    def add_ir_module(self, ir_module):
        names = _outlined_names()
        if names and any(n in ir_module.globals for n in names):
            for f in ir_module.functions:
                for bb in f.blocks:
                    for ins in bb.instructions:
                        if (isinstance(ins, llvmir.CallInstr)
                                and getattr(ins.callee, "name", None) in names):
                            ins.attributes.add("alwaysinline")
        return orig(self, ir_module)

    add_ir_module.__wrapped__ = orig
    codegen.CPUCodeLibrary.add_ir_module = add_ir_module
    _state["inlining"] = True
