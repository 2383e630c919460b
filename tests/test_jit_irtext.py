"""llvmlite's IR text printed by :mod:`drivedyn.jit_irtext`: character for character
llvmlite's own."""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from llvmlite.ir import values
from numba import njit
from numba.core import codegen

from drivedyn import jit, jit_irtext


def _llvmlite_text(module: ir.Module) -> str:
    """``str(module)`` as llvmlite prints it, its instructions' cached texts dropped."""
    for fn in module.functions:
        for block in fn.blocks:
            for instr in block.instructions:
                instr.__dict__.pop(jit_irtext._STR, None)
    ours = values.Block.descr
    values.Block.descr = ours.__wrapped__
    try:
        return str(module)
    finally:
        values.Block.descr = ours


def _every_kind() -> ir.Module:
    """A module with each instruction the formatters print, with the variants of their
    text: flags, alignments, metadata, counts, several indices, names that need quotes."""
    m = ir.Module(name="kinds")
    dbl, i64, i32, i1 = ir.DoubleType(), ir.IntType(64), ir.IntType(32), ir.IntType(1)
    st = ir.LiteralStructType([dbl, ir.LiteralStructType([i64, i64]), ir.ArrayType(i32, 3)])
    fn = ir.Function(m, ir.FunctionType(dbl, [dbl, i64, st.as_pointer()]), name="f")
    x, n, p = fn.args
    n.name = 'n"quoted\\'
    entry = fn.append_basic_block("entry")
    then, other, join = (fn.append_basic_block(s) for s in ("then", "else", "join.1"))
    b = ir.IRBuilder(entry)
    slot = b.alloca(dbl, name="slot")
    many = b.alloca(i64, size=ir.Constant(i32, 4))
    many.align = 16
    b.store(x, slot)
    b.store(x, slot).align = 8
    agg = b.load(p, name="agg")
    ld = b.load(slot)
    ld.align = 8
    ld.set_metadata("tbaa", m.add_metadata([ir.MetaDataString(m, "x")]))
    a = b.extract_value(agg, 0)
    deep = b.extract_value(agg, [1, 0])
    agg2 = b.insert_value(agg, deep, [1, 1])
    b.insert_value(agg2, ir.Constant(i32, 7), [2, 1])
    b.gep(p, [ir.Constant(i32, 0), ir.Constant(i32, 1)], inbounds=True, source_etype=st)
    b.gep(p, [ir.Constant(i64, 2)], source_etype=st)
    s = b.fadd(a, ld, flags=("fast",))
    t = b.mul(n, deep, flags=("nsw",))
    b.sub(t, n)
    b.fmul(s, s)
    c = b.icmp_signed("<", t, n)
    fc = b.fcmp_ordered(">=", s, x, flags=("nnan",))
    b.select(c, s, x)
    b.select(fc, t, n, flags=())
    b.sitofp(t, dbl)
    b.trunc(n, i32)
    b.bitcast(slot, i64.as_pointer())
    br = b.cbranch(c, then, other)
    br.set_weights([1, 99])
    b.position_at_end(then)
    b.call(fn, [x, n, p])  # no formatter: llvmlite's text
    b.branch(join)
    b.position_at_end(other)
    b.branch(join)
    b.position_at_end(join)
    phi = b.phi(dbl, name="phi")
    phi.add_incoming(s, then)
    phi.add_incoming(x, other)
    b.ret(phi)
    g = ir.Function(m, ir.FunctionType(ir.VoidType(), [i1]), name="g")
    b = ir.IRBuilder(g.append_basic_block())
    b.ret_void()
    return m


def test_installed_with_every_formatter() -> None:
    assert jit.apply()
    assert jit_irtext.install() is True
    assert {c.__name__ for c in jit_irtext._fast} == {f[0] for f in jit_irtext._FORMATTERS}


def test_every_kind_prints_as_llvmlite_prints_it() -> None:
    jit.apply()
    m = _every_kind()
    ours = str(m)
    assert ours == _llvmlite_text(m)
    for needle in ("extractvalue", "insertvalue", "getelementptr inbounds", "icmp slt",
                   "fcmp nnan oge", "select  i1", "alloca i64, i32 4, align 16",
                   "align 8, !tbaa !0", "sitofp", "bitcast", "phi  double",
                   "br i1", "!prof", "ret void", "fadd fast", "mul nsw", '%"n\\22quoted\\5c"'):
        assert needle in ours, needle


def test_compiled_modules_print_as_llvmlite_prints_them(monkeypatch) -> None:
    """Every module numba hands to LLVM while compiling a few functions (array views, a loop,
    tuples, branches): the same text from both printers."""
    jit.apply()
    seen: list[int] = []
    add = codegen.CPUCodeLibrary.add_ir_module

    def checked(self, module):
        ours = str(module)
        assert ours == _llvmlite_text(module)
        seen.append(len(ours))
        return add(self, module)

    monkeypatch.setattr(codegen.CPUCodeLibrary, "add_ir_module", checked)

    def f(a, k):
        s = 0.0
        for i in range(a.shape[0]):
            row = a[i, 1:]
            if row[0] > k:
                s += row.sum()
            else:
                s -= float(i)
        return s, a[:, 0].copy()

    a = np.arange(12.0).reshape(4, 3)
    got = njit(cache=False)(f)(a, 4.0)
    want = f(a, 4.0)
    assert got[0] == want[0] and np.array_equal(got[1], want[1])
    assert len(seen) >= 2 and sum(seen) > 10_000
