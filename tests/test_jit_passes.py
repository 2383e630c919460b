"""numba's SSA reconstruction and post-processing without their repeated work
(drivedyn.jit_passes): installed on the supported numba, the same IR as numba's own, and
compiled code that computes what Python computes."""

from __future__ import annotations

import copy
import io
import re

import numpy as np
from numba import njit
from numba.core import ir, postproc, ssa
from numba.core.compiler import run_frontend

from drivedyn import jit, jit_passes
from drivedyn.elements.gears.kernel import _gears
from drivedyn.elements.joints import _constraints


def _phi_in_loop_header(n, c):
    # x is assigned in the body only: its phi sits in the loop header, which never names it
    x = 0
    for i in range(n):
        if c:
            x = x + i
    return x


def _branches(a, n):
    s = 0.0
    t = 1.0
    for i in range(n):
        if a[i] > 0.0:
            s = s + a[i]
            t = t * 2.0
        elif a[i] < -1.0:
            s = s - 1.0
        else:
            t = 0.5 * t
            while t > 4.0:
                t = t - 1.0
    return s, t


def _dump(blocks: dict) -> str:
    out = io.StringIO()
    for label, block in blocks.items():
        out.write(f"label {label}\n")
        block.dump(file=out)
    return out.getvalue()


def test_passes_are_installed() -> None:
    assert jit.apply() is True
    assert jit_passes.install() is True
    assert ssa._run_ssa is jit_passes._run_ssa


def test_ssa_is_numbas_ir_statement_for_statement() -> None:
    """On small functions and on the joint and gear element loops (hundreds of violating
    variables), the rewrites over the naming blocks give numba's IR: same statements, same
    fresh names, same phi nodes in the same order."""
    jit.apply()
    numba_run_ssa = jit_passes._run_ssa.__wrapped__
    for func in (_phi_in_loop_header, _branches, _constraints.py_func, _gears.py_func):
        func_ir = run_frontend(func)
        ours = copy.deepcopy(func_ir.blocks)  # each copy has its own scope (names counter)
        theirs = copy.deepcopy(func_ir.blocks)
        got = jit_passes._run_ssa(ours)
        assert _dump(got) == _dump(numba_run_ssa(theirs)), func.__name__
        assert any(isinstance(s, ir.Assign) and isinstance(s.value, ir.Expr)
                   and s.value.op == "phi" for b in got.values() for s in b.body)


def test_a_phi_lands_in_a_block_that_does_not_name_its_variable() -> None:
    """The path that adds a block outside the rewritten ones: the loop header gets x's phi."""
    jit.apply()
    func_ir = run_frontend(_phi_in_loop_header)
    where = jit_passes._naming_blocks(func_ir.blocks)
    blocks = jit_passes._run_ssa(copy.deepcopy(func_ir.blocks))
    outside = [label for label, b in blocks.items() for s in b.body
               if isinstance(s, ir.Assign) and isinstance(s.value, ir.Expr)
               and s.value.op == "phi" and s.target.name.startswith("x.")
               and label not in where["x"]]
    assert outside


def _liveness(func_ir) -> dict:
    return {label: set(func_ir.block_entry_vars[b]) for label, b in func_ir.blocks.items()}


def test_entry_liveness_is_computed_when_read_and_is_numbas() -> None:
    jit.apply()
    numba_run = postproc.PostProcessor.run.__wrapped__
    for func in (_branches, _constraints.py_func):
        func_ir = run_frontend(func)  # post-processed by the replaced run
        entries = func_ir.block_entry_vars
        assert isinstance(entries, jit_passes.LazyEntryVars) and entries.pending
        # numba's own run on the same IR, built again
        ref = run_frontend(func)
        ref.block_entry_vars = {}
        numba_run(postproc.PostProcessor(ref))
        assert type(ref.block_entry_vars) is dict
        # a copy keeps the liveness pending and computes the same
        dup = func_ir.copy()
        assert dup.block_entry_vars.pending
        assert _liveness(dup) == _liveness(ref)
        assert _liveness(func_ir) == _liveness(ref)
        assert not entries.pending
        # deep-copied (as numba's inliner copies IR) as a plain mapping, with the same values
        assert type(copy.deepcopy(dup).block_entry_vars) is dict


def test_a_pending_mapping_reads_and_changes_as_the_computed_dict() -> None:
    calls = []
    made = []

    def compute():
        calls.append(1)
        return {"b": {2}, "c": {3}}

    def fresh():
        made.append(1)
        return jit_passes.LazyEntryVars({"a": {1}}, compute)

    full = {"a": {1}, "b": {2}, "c": {3}}
    assert fresh() == full and not (fresh() != full) and len(fresh()) == 3
    assert list(fresh()) == list(full) and dict(fresh()) == full and "c" in fresh()
    assert fresh().get("b") == {2} and fresh().pop("c") == {3}
    m = fresh()
    m.update({"d": set()})
    assert m == {**full, "d": set()} and not m.pending
    m = fresh()
    m["b"] = {9}  # a change after the computation, not overwritten by it
    assert m["b"] == {9}
    assert (fresh() | {"e": {5}}) == {**full, "e": {5}}
    assert len(calls) == len(made) == 11  # once per mapping


def _squares(n):
    for i in range(n):
        yield i * i


def test_generators_get_their_liveness_at_once_and_still_compile() -> None:
    jit.apply()
    func_ir = run_frontend(_squares)
    assert not func_ir.block_entry_vars.pending
    ref = run_frontend(_squares)
    assert func_ir.generator_info.state_vars == ref.generator_info.state_vars
    assert list(njit(_squares)(5)) == [0, 1, 4, 9, 16]


def test_compiled_code_computes_what_python_computes() -> None:
    a = np.array([0.5, -2.0, 0.1, -0.3, 3.0, -1.5, 0.0])
    for n in (0, 3, 7):
        assert njit(_branches)(a, n) == _branches(a, n)
        assert njit(_phi_in_loop_header)(n, True) == _phi_in_loop_header(n, True)
        assert njit(_phi_in_loop_header)(n, False) == 0


def test_position_before_the_last_instruction_is_llvmlites() -> None:
    """Positioning before a block's last instruction (the entry block's terminator, where
    numba puts stack slots) gives the index llvmlite's search gives, and so does any other
    instruction (searched as before)."""
    from llvmlite import ir as llir
    from llvmlite.ir.builder import IRBuilder

    jit.apply()
    assert IRBuilder.position_before is not IRBuilder.position_before.__wrapped__
    fn = llir.Function(llir.Module(), llir.FunctionType(llir.VoidType(), []), "f")
    b = IRBuilder(fn.append_basic_block("entry"))
    slots = [b.alloca(llir.DoubleType()) for _ in range(5)]
    term = b.ret_void()
    for instr in (term, slots[0], slots[3]):
        for method in (IRBuilder.position_before, IRBuilder.position_before.__wrapped__):
            method(b, instr)
            got = (b.block, b._anchor)
            assert got == (instr.parent, instr.parent.instructions.index(instr))
    b.position_before(term)
    new = b.alloca(llir.DoubleType())  # inserted before the terminator, as numba's slots
    assert b.block.instructions[-2:] == [new, term]


def test_list_vars_is_numbas() -> None:
    """The variables of every statement (expressions, calls with keyword arguments, phis,
    nested instructions) of the joint and gear loops, and of odd values (dict and tuple
    subclasses, instructions inside containers), in numba's order."""
    from collections import OrderedDict, namedtuple

    jit.apply()
    assert jit_passes._state["list_vars"] is True
    ours = ir.Inst._rec_list_vars
    numbas = ours.__wrapped__

    def numba_list(stmt, val):
        # numba's recursion calls the method through the instance: numba's all the way down
        ir.Inst._rec_list_vars = numbas
        try:
            return numbas(stmt, val)
        finally:
            ir.Inst._rec_list_vars = ours

    n = 0
    for func in (_constraints.py_func, _gears.py_func, _branches):
        func_ir = run_frontend(func)
        for block in func_ir.blocks.values():
            for stmt in block.body:
                got = stmt.list_vars()
                want = numba_list(stmt, stmt.__dict__ if not isinstance(stmt, ir.Expr)
                                  else stmt._kws)
                assert [v.name for v in got] == [v.name for v in want]
                assert all(a is b for a, b in zip(got, want, strict=True))
                n += 1
    assert n > 2000
    scope = ir.Scope(None, ir.Loc("f", 1))
    a, b, c = (ir.Var(scope, name, ir.Loc("f", 1)) for name in "abc")
    pair = namedtuple("pair", "x y")
    inner = ir.Assign(b, c, ir.Loc("f", 1))
    odd = {"k": OrderedDict(p=pair(a, [inner, 3.0]), q="s"), "t": (None, (c, {1: a}))}
    stmt = ir.Assign(a, a, ir.Loc("f", 1))
    assert [v.name for v in ours(stmt, odd)] == [v.name for v in numba_list(stmt, odd)] \
        == ["a", "b", "c", "c", "a"]


def _dels(fn, nrt: bool) -> int:
    """``del`` statements the legalisation leaves in ``fn``'s IR, compiled with or without
    reference counting."""
    from numba.core import typed_passes
    from numba.core.compiler import Flags

    flags = Flags()
    flags.nrt = nrt
    func_ir = run_frontend(fn)
    typed_passes.check_and_legalize_ir(func_ir, flags)
    return sum(1 for b in func_ir.blocks.values() for _ in b.find_insts(ir.Del))


def _branch_on_a_local(a):
    # the comparison's value is used by its block's branch only: numba deletes it in both
    # successors, and without dels it is never given a slot
    s = 0.0
    for x in a:
        if x > 0.0:
            s += x
        else:
            s -= 2.0 * x
    return s


def test_no_dels_without_reference_counting() -> None:
    """Functions compiled without reference counting are lowered without ``del`` statements
    (numba's legalisation otherwise); they compute what Python computes, and their optimised
    IR is the one numba makes with the ``del`` statements, up to the names of values."""
    from numba.core import typed_passes

    jit.apply()
    assert jit_passes._state["no_dels"] is True
    for fn in (_branches, _phi_in_loop_header, _branch_on_a_local):
        assert _dels(fn, nrt=True) > 0
        assert _dels(fn, nrt=False) == 0
    a = np.array([0.5, -2.0, 0.1, -0.3, 3.0, -1.5, 0.0])
    ours = njit(cache=False, _nrt=False)(_branches)
    assert ours(a, 7) == _branches(a, 7)
    assert njit(cache=False, _nrt=False)(_branch_on_a_local)(a) == _branch_on_a_local(a)
    for n in (0, 5):
        assert njit(cache=False, _nrt=False)(_phi_in_loop_header)(n, True) == \
            _phi_in_loop_header(n, True)
    legalize = typed_passes.check_and_legalize_ir
    typed_passes.check_and_legalize_ir = legalize.__wrapped__
    try:
        theirs = njit(cache=False, _nrt=False)(_branches)
        theirs(a, 7)
    finally:
        typed_passes.check_and_legalize_ir = legalize
    (sig,) = ours.signatures

    def bag(text: str) -> list[str]:
        # value names and the compilation's number in mangled names aside
        return sorted(re.sub(r"%\S+", "%v", re.sub(r"B\d+v\d+(?=B)", "Bv", line))
                      for line in text.splitlines()
                      if line and not line.startswith(("define", ";", "@", "!")))

    assert bag(ours.inspect_llvm(sig)) == bag(theirs.inspect_llvm(sig))
