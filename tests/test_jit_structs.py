"""numba's structure proxies held as values until written (drivedyn.jit_structs): installed on
the supported numba, no stack slot while a proxy is only read, the slot filled where the
proxy was made when a write comes later (even in a branch), numba's own optimised IR, and
compiled code that computes what Python computes."""

from __future__ import annotations

import ctypes
import re

import llvmlite.binding as llvm
import numpy as np
import pytest
from llvmlite import ir as llir
from numba import njit, types
from numba.core import cgutils
from numba.core.registry import cpu_target
from numba.np import arrayobj

from drivedyn import jit, jit_structs
from ir_compare import norm_ir, rigid_body_kernel_ir

pytestmark = pytest.mark.skipif(not jit.apply() or not jit_structs.install(),
                                reason="numba without the proxies this replaces")

I64 = llir.IntType(64)
ARRAY = types.Array(types.float64, 2, "C")


def _function(args: list) -> tuple:
    """A new module with ``i64 f(args)``, its entry block and a builder at its end."""
    mod = llir.Module()
    fn = llir.Function(mod, llir.FunctionType(I64, args), "f")
    entry = fn.append_basic_block("entry")
    return mod, fn, entry, llir.IRBuilder(entry)


def _array_value(ctx, b, nitems) -> llir.Value:
    """An array structure value whose ``nitems`` is ``nitems`` (other fields zero)."""
    be = ctx.get_value_type(ARRAY)
    pos = ctx.data_model_manager[ARRAY].get_field_position("nitems")
    return b.insert_value(llir.Constant(be, None), nitems, pos)


def _run(mod: llir.Module, argtypes: list):
    """The module compiled without optimisation: ``f`` as a ctypes function."""
    m = llvm.parse_assembly(str(mod))
    m.verify()
    tm = llvm.Target.from_default_triple().create_target_machine(opt=0)
    engine = llvm.create_mcjit_compiler(m, tm)
    engine.finalize_object()
    f = ctypes.CFUNCTYPE(ctypes.c_int64, *argtypes)(engine.get_function_address("f"))
    f._engine = engine  # keep the code alive with the function
    return f


def test_installed() -> None:
    assert jit_structs._state["installed"] is True
    assert arrayobj.make_array is jit_structs._state["make_array"]
    ctx = cpu_target.target_context
    # one class per array type; a plain array skips numba's __array__ lookup
    assert ctx.make_array(ARRAY) is ctx.make_array(ARRAY)
    assert ctx.make_array(ARRAY)._drivedyn_values


def test_reads_make_no_slot() -> None:
    """Fields, the shape and the whole value of a proxy only read: extractvalues, no stack
    slot, no store, no load."""
    ctx = cpu_target.target_context
    mod, fn, _, b = _function([I64])
    before = jit_structs.STATS["values"]
    ary = ctx.make_array(ARRAY)(ctx, b, value=_array_value(ctx, b, fn.args[0]))
    assert jit_structs.STATS["values"] == before + 1
    n = ary.nitems
    shape = ary.shape
    whole = ary._getvalue()
    assert isinstance(shape.type, llir.ArrayType) and shape.type.count == 2
    b.ret(b.add(n, b.extract_value(b.extract_value(whole, 5), 1)))
    text = str(mod)
    assert "alloca" not in text and "store" not in text and "load" not in text
    assert text.count("extractvalue") == 4
    assert _run(mod, [ctypes.c_int64])(41) == 41


def test_a_write_in_a_branch_fills_the_slot_where_the_proxy_was_made() -> None:
    """The first write happens in one branch only; the read after the branches must see the
    value the proxy was made from on the other path: the slot is filled where the proxy was
    made, before the branch, then written in the branch."""
    ctx = cpu_target.target_context
    mod, fn, entry, b = _function([I64, llir.IntType(1)])
    body = fn.append_basic_block("body")
    b.branch(body)
    b.position_at_end(body)
    ary = ctx.make_array(ARRAY)(ctx, b, value=_array_value(ctx, b, fn.args[0]))
    made_after = body.instructions[-1]
    marker = b.add(fn.args[0], fn.args[0], name="marker")
    with b.if_then(fn.args[1]):
        ary.nitems = llir.Constant(I64, 7)  # materialises the proxy here
    b.ret(ary.nitems)
    # the slot in the entry block, the store right where the proxy was made
    assert isinstance(entry.instructions[0], llir.AllocaInstr)
    i = body.instructions.index(made_after)
    assert isinstance(body.instructions[i + 1], llir.StoreInstr)
    assert body.instructions[i + 2] is marker
    f = _run(mod, [ctypes.c_int64, ctypes.c_bool])
    assert f(5, False) == 5 and f(5, True) == 7


def test_a_proxy_made_in_the_entry_block_gets_its_slot_before_its_store() -> None:
    ctx = cpu_target.target_context
    mod, fn, _, b = _function([I64, llir.IntType(1)])
    ary = ctx.make_array(ARRAY)(ctx, b, value=_array_value(ctx, b, fn.args[0]))
    with b.if_then(fn.args[1]):
        ptr = ary._getpointer()  # the address: materialised
        b.store(b.insert_value(b.load(ptr), llir.Constant(I64, 3), 2), ptr)
    b.ret(ary.nitems)
    f = _run(mod, [ctypes.c_int64, ctypes.c_bool])
    assert f(9, False) == 9 and f(9, True) == 3


def test_setvalue_in_a_branch() -> None:
    ctx = cpu_target.target_context
    mod, fn, _, b = _function([I64, llir.IntType(1)])
    ary = ctx.make_array(ARRAY)(ctx, b, value=_array_value(ctx, b, fn.args[0]))
    with b.if_then(fn.args[1]):
        ary._setvalue(_array_value(ctx, b, llir.Constant(I64, 11)))
    b.ret(ary.nitems)
    f = _run(mod, [ctypes.c_int64, ctypes.c_bool])
    assert f(4, False) == 4 and f(4, True) == 11


def test_a_proxy_made_without_a_value_is_numbas() -> None:
    """A structure numba fills field by field has its slot from the start."""
    ctx = cpu_target.target_context
    mod, fn, _, b = _function([I64])
    sl = cgutils.create_struct_proxy(types.slice2_type)(ctx, b)
    assert isinstance(sl._getpointer(), llir.AllocaInstr)
    sl.start = fn.args[0]
    sl.stop = fn.args[0]
    b.ret(sl.start)
    assert _run(mod, [ctypes.c_int64])(6) == 6


# --- compiled code ------------------------------------------------------------------------

def _views(a):
    # slices, strides, transposes, row iteration, writes through views
    s = 0.0
    b = a[1:, ::2]
    for row in b:
        s += row.sum()
    t = a.T
    c = np.empty_like(a)
    for i in range(a.shape[0]):
        c[i, :] = t[:, i] * 2.0
    c[0, 1:] += 1.0
    return s, c, a.reshape(-1)[3]


def _carried(a, n):
    # an array as a loop-carried variable (a phi of array structures) and 0-d arrays
    x = a[0]
    z = np.zeros(())
    for k in range(n):
        x = a[k % a.shape[0]] if k % 3 else x[::-1]
        z[()] += x[0]
    return x.copy(), z[()]


def test_compiled_code_computes_what_python_computes() -> None:
    rng = np.random.default_rng(3)
    a = rng.standard_normal((5, 4))
    got, want = njit(cache=False)(_views)(a), _views(a)
    assert got[0] == want[0] and np.array_equal(got[1], want[1]) and got[2] == want[2]
    for n in (0, 1, 7):
        got, want = njit(cache=False)(_carried)(a, n), _carried(a, n)
        assert np.array_equal(got[0], want[0]) and got[1] == want[1]


def test_optimised_ir_is_numbas_up_to_order() -> None:
    """The same function compiled with numba's own proxies: the same optimised instructions,
    up to the names of values and the place of the slots numba needs (the reshape takes an
    array's address). (An array carried by a loop is not covered: LLVM then may count the
    loop's trips another way, 3 instructions of 900 in ``_carried``; the values computed are
    the same, see the test above.)"""
    a = np.ones((5, 4))
    ours = njit(cache=False)(_views)
    ours(a)
    with jit_structs.suspended():
        theirs = njit(cache=False)(_views)
        theirs(a)
    (sig,) = ours.signatures

    def bag(text: str) -> list[str]:
        return sorted(re.sub(r"%v\d+", "%v", line) for line in norm_ir(text)
                      if "missing Environment" not in line)  # its length holds the number

    assert bag(ours.inspect_llvm(sig)) == bag(theirs.inspect_llvm(sig))


def test_an_element_kernels_optimised_ir_is_numbas(tmp_path) -> None:
    """The rigid-body kernel (its element loop and helpers) compiled in two new processes,
    each with an empty cache, with and without the proxies held as values: the same
    optimised IR, instruction for instruction, up to the names of values."""
    ours, theirs = rigid_body_kernel_ir(tmp_path, "DRIVEDYN_JIT_VALUES")
    assert len(ours.splitlines()) > 1000
    assert ours != theirs  # the switch took effect: numba numbered other values
    assert norm_ir(ours) == norm_ir(theirs)
