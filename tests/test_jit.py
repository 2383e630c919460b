"""The fix of numba's IR inliner (drivedyn.jit): installed on the supported numba, and
inlined code computes what the Python functions compute."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit
from numba.core.inline_closurecall import InlineWorker

from drivedyn import jit


def test_inliner_fix_is_installed() -> None:
    import drivedyn.elements  # noqa: F401 - kernel modules apply it at import

    assert jit.apply() is True
    assert getattr(InlineWorker.inline_ir, "__drivedyn_fixed__", False)


@njit(inline="always")
def _clip(x, lo, hi):
    if x < lo:
        return lo
    if x > hi:
        return hi
    return x


@njit(inline="always")
def _norm_clipped(v, lo, hi):
    s = 0.0
    for i in range(v.shape[0]):
        c = _clip(v[i], lo, hi)  # a helper inlined into an inlined helper
        s += c * c
    return np.sqrt(s)


@njit
def _caller(v):
    # two call sites of a helper with several blocks and a loop
    return _norm_clipped(v, -1.0, 1.0) + 2.0 * _norm_clipped(v[::-1], 0.0, 0.5)


def test_inlined_helpers_compute_what_numpy_computes() -> None:
    v = np.array([-3.0, 0.2, 0.7, 1.5, -0.1, 0.45])
    ref = np.linalg.norm(np.clip(v, -1.0, 1.0)) + 2.0 * np.linalg.norm(np.clip(v, 0.0, 0.5))
    assert _caller(v) == pytest.approx(ref, rel=1e-15)


def test_callee_ir_is_built_once_per_function(monkeypatch) -> None:
    """The inliner builds an inlined helper's untyped IR once, not at every call site (the
    memo of ``drivedyn.jit``): a fresh caller with three call sites of a fresh helper runs the
    helper's untyped pipeline once, and computes what Python computes."""
    jit.apply()
    built = []
    run = InlineWorker.run_untyped_passes

    def counting(self, func, enable_ssa=False):
        built.append(func.__name__)
        return run(self, func, enable_ssa)

    monkeypatch.setattr(InlineWorker, "run_untyped_passes", counting)

    @njit(inline="always")
    def _twice_clipped(x):
        return 2.0 * min(max(x, -1.0), 1.0)

    @njit
    def three_sites(a, b, c):
        return _twice_clipped(a) + 10.0 * _twice_clipped(b) + 100.0 * _twice_clipped(c)

    assert three_sites(0.25, -3.0, 7.0) == 0.5 - 20.0 + 200.0
    assert built.count("_twice_clipped") == 1


# --- element loops compiled once, inlined by LLVM (jit.outlined) ------------------------------


@njit(_dbg_optnone=True)  # optnone + noinline: stays a call, whose sites the test counts
def _matrix_part(K, i, xi):
    K[i, i] += xi * xi


@jit.outlined(cache=False)
def _loop(x, r, K, full):
    for i in range(x.shape[0]):
        r[i] += 2.0 * x[i]
        if full:
            _matrix_part(K, i, x[i])


@njit
def _kernel(x, r, K, want):
    full = want
    if full:
        _loop(x, r, K, full)
    else:
        _loop(x, r, K, full)


def _calls(llvm: str, name: str) -> int:
    return sum(1 for line in llvm.splitlines() if " call " in line and f"@{name}(" in line)


def test_outlined_loop_is_inlined_specialised_and_computes_the_same() -> None:
    """The loop is inlined at both call sites of the kernel (no call left), the copy where
    ``full`` is false has no matrix code (one call of the matrix part: the full copy's), the
    loop itself counts no references, and both copies compute what Python computes."""
    x = np.array([1.0, -2.0, 3.0])
    for want in (False, True):
        r = np.ones(3)
        K = np.zeros((3, 3))
        _kernel(x, r, K, want)
        assert np.array_equal(r, 1.0 + 2.0 * x)
        assert np.array_equal(K, np.diag(x * x) if want else np.zeros((3, 3)))
    sig = _kernel.signatures[0]
    ll = _kernel.inspect_llvm(sig)
    loop_name = next(iter(_loop.overloads.values())).fndesc.mangled_name
    part_name = next(iter(_matrix_part.overloads.values())).fndesc.mangled_name
    assert _calls(ll, loop_name) == 0
    assert _calls(ll, part_name) == 1
    loop_ll = _loop.inspect_llvm(_loop.signatures[0])
    assert "NRT_incref" not in loop_ll and "NRT_decref" not in loop_ll


@njit
def _fresh_copy(a):
    return a.copy()


def test_outlined_loop_that_allocates_does_not_compile() -> None:
    """Without reference counting an allocation cannot be freed: a loop that allocates, or
    gets a new array from a call or an operator (here from functions already compiled with
    reference counting, which numba would call silently), is refused at compile time."""
    a = np.arange(3.0)
    assert np.zeros(2)[0] == 0.0 and _fresh_copy(a)[1] == 1.0  # compiled with counting
    njit(lambda n: np.zeros(n))(2)

    @jit.outlined(cache=False)
    def allocating(n, full):
        return np.zeros(n)[0] if full else 0.0

    @jit.outlined(cache=False)
    def copying(x, full):
        return _fresh_copy(x)[0] if full else 0.0

    @jit.outlined(cache=False)
    def negating(x, out, full):
        out[0] = (-x)[0]

    for fn, args in ((allocating, (3, True)), (copying, (a, True)),
                     (negating, (a, np.zeros(1), True))):
        with pytest.raises(Exception, match="makes a new array"):
            fn(*args)


# --- the memo of call signatures -----------------------------------------------------------------


def test_remembered_signatures_are_what_numba_resolves_again() -> None:
    """Every signature the memo holds (after compiling the kernels above and whatever the
    session compiled before) is the one numba's own resolution computes again for the same
    function and argument types; a fresh call site of a remembered pair is a hit."""
    from numba.core.types.functions import Function

    jit.apply()
    resolve = Function.get_call_type.__wrapped__  # installed: numba's own method wrapped
    assert resolve is not Function.get_call_type
    x = np.array([1.0, 2.0])
    _kernel(x, np.zeros(2), np.zeros((2, 2)), True)
    assert len(jit._call_types) > 20
    for (fnty, ctx, args, kws), sig in list(jit._call_types.items())[:500]:
        assert resolve(fnty, ctx, args, dict(kws)) == sig

    import operator

    from numba import types

    def is_float_add(k):
        return k[0].typing_key is operator.add and k[2] == (types.float64, types.float64)

    @njit
    def first(a, b):
        return a + b

    assert first(1.5, 2.0) == 3.5
    assert sum(1 for k in jit._call_types if is_float_add(k)) == 1
    hits, misses = jit.memo_counts

    @njit
    def again(a, b):
        return a + b + a  # two float additions: remembered

    assert again(1.5, 2.0) == 5.0
    assert jit.memo_counts[1] == misses
    assert jit.memo_counts[0] >= hits + 2


# --- lean lowering of uncounted variables, plain markup -----------------------------------------


@njit(_nrt=False, cache=False)
def _lean_loop(a, n):
    s = 0.0
    last = 0.0
    for i in range(n):
        row = a[i]  # an array view held across blocks
        if row[0] > 0.0:
            last = row[1]
        s += row[0] * last
    return s


@njit(cache=False)
def _counted_loop(a, n):
    s = 0.0
    for i in range(n):
        row = a[i]
        if row[0] > 0.0:
            s += row[1]
    return s


def _zero_filled_variables(monkeypatch, fn, *args) -> tuple[set, set, dict]:
    """(user variables with a stack slot, those of them stored zeros, zero stores per slot)
    in the unoptimised LLVM IR numba hands to LLVM when compiling ``fn(*args)``."""
    import re

    from numba.core import codegen

    texts = []
    add = codegen.CPUCodeLibrary.add_ir_module

    def grab(self, ir_module):
        if fn.py_func.__name__ in self.name:
            texts.append(str(ir_module))
        return add(self, ir_module)

    monkeypatch.setattr(codegen.CPUCodeLibrary, "add_ir_module", grab)
    fn(*args)
    ir = "\n".join(texts)
    slots = {n for n in re.findall(r'%"([A-Za-z_]\w*(?:\.\d+)?)" = alloca', ir)
             if n not in ("excinfo", "try_state")}
    zeroed = {n for n in slots if re.search(rf'zeroinitializer, [^\n]*%"{re.escape(n)}"$', ir,
                                            re.M)}
    stores: dict = {}
    for m in re.finditer(r'zeroinitializer, [^\n]*\* (%"?[^"\s]+"?)$', ir, re.M):
        stores[m.group(1)] = stores.get(m.group(1), 0) + 1
    return slots, zeroed, stores


def test_uncounted_variables_are_lowered_without_zero_fills(monkeypatch) -> None:
    """Without reference counting no variable slot is zero-filled or nulled at its ``del``,
    and the structures numba builds are zero-filled once; with reference counting, only the
    slots of counted values (arrays) are; both compute what Python computes, a loop not
    entered included."""
    jit.apply()
    assert jit._state["lean"] is True
    a = np.array([[1.0, 2.0], [-1.0, 5.0], [3.0, 4.0], [0.5, -2.0]])
    slots, zeroed, stores = _zero_filled_variables(monkeypatch, _lean_loop, a, 4)
    assert {"a", "row"} <= slots and any(s.startswith("last") for s in slots)
    assert zeroed == set()
    # the structures numba builds (views, the range iterator...) are zero-filled once, where
    # they are made, not also in the entry block
    assert jit._state.get("struct_slots") is True
    assert len(stores) >= 5 and set(stores.values()) == {1}
    slots, zeroed, _ = _zero_filled_variables(monkeypatch, _counted_loop, a, 4)
    assert {"a", "row"} <= zeroed  # counted: numba's own lowering
    assert any(s.startswith("s.") for s in slots)
    assert not any(s.startswith("s.") for s in zeroed)  # a float: lean
    for n in (0, 1, 3, 4):
        assert _lean_loop(a, n) == _lean_loop.py_func(a, n)
        assert _counted_loop(a, n) == _counted_loop.py_func(a, n)


def _meminfo_paths(found: list) -> list:
    """``(type, extractvalue index path from the argument)`` of each meminfo found."""
    from llvmlite import ir as llir

    out = []
    for ty, v in found:
        path = []
        while isinstance(v, llir.ExtractValue):
            path = [*v.indices, *path]
            v = v.aggregate
        out.append((ty, tuple(path), type(v).__name__))
    return out


def test_meminfos_are_found_without_reading_uncounted_members(monkeypatch) -> None:
    """numba's reference counting of a tuple of arrays, numbers and nested tuples finds the
    same meminfos (types, places, order) with the members that hold none left unread."""
    from llvmlite import ir as llir
    from numba.core import types
    from numba.core.registry import cpu_target

    jit.apply()
    assert jit._state["meminfos"] is True
    # a copy with reference counting on: the target's own context caches its runtime
    # context (``nrt``) when first read, and its copies inherit that one
    ctx = cpu_target.target_context.subtarget(enable_nrt=True)
    arr = types.Array(types.float64, 2, "C")
    ty = types.Tuple((arr, types.float64, types.UniTuple(types.intp, 3),
                      types.Tuple((types.int64, arr, types.UniTuple(arr, 2))), arr))
    nrt = type(ctx.nrt)
    ours = nrt.get_meminfos

    def find() -> tuple[list, int]:
        fn = llir.Function(llir.Module(), llir.FunctionType(llir.VoidType(),
                                                            [ctx.get_value_type(ty)]), "f")
        b = llir.IRBuilder(fn.append_basic_block("entry"))
        found = ctx.nrt.get_meminfos(b, ty, fn.args[0])
        return (_meminfo_paths(found),
                sum(isinstance(i, llir.ExtractValue) for i in b.block.instructions))

    found, reads = find()
    monkeypatch.setattr(nrt, "get_meminfos", ours.__wrapped__)  # numba's, recursion included
    numbas, numba_reads = find()
    assert found == numbas and len(found) == 5
    meminfo = types.MemInfoPointer(types.float64)
    assert [(t, kind) for t, _, kind in found] == [(meminfo, "Argument")] * 5
    assert [p for _, p, _ in found] == [(0, 0), (3, 1, 0), (3, 2, 0, 0), (3, 2, 1, 0), (4, 0)]
    # one read per meminfo and per tuple on its path, against every member of everything
    # (numba: 11 reads per 2-d array: 7 fields, 2 shape, 2 strides)
    assert reads == 12 and numba_reads == 68


def test_markup_builds_the_strings_numba_builds() -> None:
    """numba's message highlighting gives the same strings without colorama's stream
    wrapping."""
    from numba.core import errors

    jit.apply()
    if not jit._state["markup"]:
        pytest.skip("numba does not use colorama here")
    scheme = errors.termcolor()
    plain = type(scheme)._markup
    for msg in ("Cannot determine Numba type of <class 'module'>", "", "a\nb"):
        for color in (None, "\x1b[31m"):
            assert plain(scheme, msg, color) == plain.__wrapped__(scheme, msg, color)
        assert plain(scheme, msg, None, None) == plain.__wrapped__(scheme, msg, None, None)
    assert scheme.errmsg("x").endswith("x\x1b[0m")


def test_loc_parameters_are_remembered_per_function() -> None:
    """numba's ``_has_loc`` answers are kept per function: the same answers, one signature
    per function, and callables that cannot be weakly referenced are asked each time."""
    import gc

    from numba.core import base

    assert jit.apply()
    assert jit._state["has_loc"] is True
    numbas = base._has_loc.__wrapped__

    def with_loc(context, builder, sig, args, loc=None):
        return None

    def without_loc(context, builder, sig, args):
        return None

    class NoWeakRef:  # a callable without weak references
        __slots__ = ()

        def __call__(self, context, builder, sig, args, loc=None):
            return None

    for fn in (with_loc, without_loc, len, NoWeakRef()):
        assert base._has_loc(fn) is numbas(fn)
        assert base._has_loc(fn) is numbas(fn)
    assert base._has_loc(with_loc) is True and base._has_loc(without_loc) is False
    # the answer for a function is its signature's at the first call (the parameters of a
    # function cannot change)
    calls = []
    original = base.utils.pysignature

    def counting(fn):
        calls.append(fn)
        return original(fn)

    def fresh(context, builder, sig, args, loc=None):
        return None

    base.utils.pysignature = counting
    try:
        assert [base._has_loc(fresh) for _ in range(3)] == [True] * 3
    finally:
        base.utils.pysignature = original
    assert calls == [fresh]
    # entries go with their functions
    import weakref

    ref = weakref.ref(fresh)
    calls.clear()
    del fresh
    gc.collect()
    assert ref() is None


def _identity_shape(root) -> list:
    """Every object reachable from ``root`` through numba IR objects and containers, in
    visit order, as the index of its first visit: two structures with the same shape share
    objects in the same places."""
    seen: dict[int, int] = {}
    order: list = []

    def walk(x) -> None:
        t = type(x)
        if t in (str, int, float, bool, type(None)):
            return
        if id(x) in seen:
            order.append(seen[id(x)])
            return
        seen[id(x)] = len(seen)
        order.append(t.__name__)
        if t is dict or t.__name__ == "defaultdict":
            for k, v in x.items():
                walk(k)
                walk(v)
        elif t in (list, tuple):
            for v in x:
                walk(v)
        elif t.__module__.startswith("numba.core.ir"):
            for _, v in sorted(vars(x).items()):
                walk(v)

    walk(root)
    return order


def test_inliner_copy_is_copy_deepcopy() -> None:
    """The inliner's copy of IR blocks (:func:`jit.deepcopy_ir`) is ``copy.deepcopy``'s: the
    same statements, the same objects shared (one scope, variables used twice), nothing
    shared with the original but what ``deepcopy`` shares (constants' values and locations);
    and objects of other classes go to ``copy.deepcopy`` with the same memo."""
    import copy
    import io

    from numba.core.compiler import run_frontend

    from drivedyn.elements.joints import _constraints

    assert jit.apply()
    assert jit._state["ir_copies_checked"] is True

    def dump(blocks) -> str:
        out = io.StringIO()
        for label, block in blocks.items():
            out.write(f"label {label}\n")
            block.dump(file=out)
        return out.getvalue()

    blocks = run_frontend(_constraints.py_func).blocks
    theirs = copy.deepcopy(blocks)
    ours = jit.deepcopy_ir(blocks, {})
    assert dump(ours) == dump(theirs) == dump(blocks)
    assert _identity_shape(ours) == _identity_shape(theirs)
    assert len(_identity_shape(ours)) > 5000
    assert not ({id(b) for b in ours.values()} & {id(b) for b in blocks.values()})

    class Slotted:
        __slots__ = ("a",)

        def __init__(self, a):
            self.a = a

    class Custom:
        def __init__(self):
            self.items = [1, [2]]

        def __deepcopy__(self, memo):
            return "custom"

    shared = [3]
    x = {"s": Slotted(shared), "c": Custom(), "t": (1, "a"), "u": (shared, shared),
         "l": shared, "n": np.arange(3.0)}
    y = jit.deepcopy_ir(x, {})
    z = copy.deepcopy(x)
    assert y["c"] == z["c"] == "custom"
    assert y["s"].a == [3] and y["s"].a is not shared and y["s"].a is y["l"]
    assert y["t"] is x["t"] and y["u"][0] is y["u"][1] is y["l"]
    assert np.array_equal(y["n"], x["n"]) and y["n"] is not x["n"]
    assert jit._copy_kind[Slotted] == jit._copy_kind[Custom] == "other"
