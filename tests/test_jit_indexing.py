"""numba's array indexing without dead reads and trivial arithmetic (drivedyn.jit_indexing):
installed on the numba it reproduces, compiled code that computes what Python computes for
every kind of index and layout (negative and constant indices, slices, views, ellipsis,
new axes, C, F and any layout, bounds checks), fewer instructions handed to LLVM, and
numba's own optimised IR."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit
from numba.core import codegen
from numba.np import arrayobj

from drivedyn import jit, jit_indexing
from ir_compare import norm_ir, rigid_body_kernel_ir

pytestmark = pytest.mark.skipif(not jit.apply() or not jit_indexing.install(),
                                reason="numba without the indexing this replaces")


def _indexing(a, b3, f, g, i, j, u, k32):
    # a: C 2-D, b3: C 3-D, f: F 2-D, g: any layout 2-D; i, j: int64; u: uint64; k32: int32
    s = a[0, 1] + a[-1, -2] + a[i, j] + a[-i, j] + a[u, j] + a[k32, 0]
    s += b3[1, 2, 3] + b3[i, j, 4] + b3[-1, i, -1]
    s += f[1, 2] + f[i, -1] + f[-1, j]
    s += g[0, 1] + g[i, -1] + g[-2, j]
    row = a[i]  # a view keeping the last dimension
    s += row[2] + row[-1]
    col = a[:, j]  # slice and index: a view of any layout
    s += col[1] + col[-1]
    v = a[1:, ::2]
    s += v[1, 1] + v[-1, 0]
    e = b3[..., 1]
    s += e[2, 3] + e[-1, i]
    n = a[None, 1]
    s += n[0, 2]
    w = b3[1:3, :, ::2]
    s += w[1, i, 1] + w[-1, -1, -1]
    fr = f[1]  # a row of an F array: strided
    s += fr[0] + fr[-1]
    c = a.copy()
    c[0, 0] = 7.0
    c[i, -1] = 3.0
    c[-1, 1] = -4.0
    c[1:, 0] = 1.5
    r = c[::-1]
    r[0, 1] = -2.0
    t = b3.copy()
    t[2, -1, 0] = 9.0
    t[i] = 0.5
    return s, c, t


def _arrays():
    rng = np.random.default_rng(7)
    a = rng.standard_normal((5, 4))
    b3 = rng.standard_normal((3, 4, 5))
    f = np.asfortranarray(rng.standard_normal((4, 6)))
    g = rng.standard_normal((4, 9))[:, ::2]
    assert f.flags.f_contiguous and not (g.flags.c_contiguous or g.flags.f_contiguous)
    return a, b3, f, g


def test_installed() -> None:
    assert jit_indexing._state["installed"] is True
    assert arrayobj.basic_indexing is jit_indexing.basic_indexing
    assert arrayobj.fix_integer_index is jit_indexing.fix_integer_index
    assert jit_indexing._sources_match()


def test_another_numba_source_is_not_replaced(monkeypatch) -> None:
    key = ("numba.np.arrayobj", "basic_indexing")
    monkeypatch.setitem(jit_indexing._SOURCES, key, "0" * 16)
    assert not jit_indexing._sources_match()


def test_compiled_code_computes_what_python_computes() -> None:
    a, b3, f, g = _arrays()
    fn = njit(cache=False)(_indexing)
    for i, j in ((1, 2), (2, 0), (0, 3)):
        args = (a, b3, f, g, i, j, np.uint64(i + 1), np.int32(j))
        got, want = fn(*args), _indexing(*args)
        assert got[0] == want[0]  # the same sums in the same order
        assert np.array_equal(got[1], want[1]) and np.array_equal(got[2], want[2])


def test_bounds_checks_are_kept() -> None:
    """With ``boundscheck=True`` an index out of range raises, a negative one in range
    wraps around."""

    def get(a, i, j):
        return a[i, j]

    fn = njit(cache=False, boundscheck=True)(get)
    a = np.arange(12.0).reshape(3, 4)
    assert fn(a, -1, 2) == a[-1, 2]
    with pytest.raises(IndexError):
        fn(a, 3, 0)
    with pytest.raises(IndexError):
        fn(a, 0, -5)


def _compiled(monkeypatch) -> tuple[str, list[str]]:
    """``_indexing`` compiled anew: its optimised IR and the IR modules handed to LLVM."""
    handed: list[str] = []
    add = codegen.CPUCodeLibrary.add_ir_module

    def record(self, ir_module):
        handed.append(str(ir_module))
        return add(self, ir_module)

    monkeypatch.setattr(codegen.CPUCodeLibrary, "add_ir_module", record)
    fn = njit(cache=False)(_indexing)
    a, b3, f, g = _arrays()
    fn(a, b3, f, g, 1, 2, np.uint64(1), np.int32(2))
    (sig,) = fn.signatures
    monkeypatch.undo()
    return fn.inspect_llvm(sig), handed


def test_fewer_instructions_and_numbas_optimised_ir(monkeypatch) -> None:
    """The same function compiled with numba's own indexing: the same optimised IR, up to
    the names of values; handed to LLVM, 30 % fewer ``extractvalue`` (measured 730 against
    1081) and 20 % fewer ``select`` (measured 124 against 158: no wraparound of the
    constant indices; the others are the variable indices' and the slices')."""
    ours, ours_in = _compiled(monkeypatch)
    with jit_indexing.suspended():
        theirs, theirs_in = _compiled(monkeypatch)
    assert arrayobj.basic_indexing is jit_indexing.basic_indexing  # restored

    def count(texts: list[str], what: str) -> int:
        return sum(t.count(what) for t in texts)

    assert count(ours_in, " extractvalue ") < 0.70 * count(theirs_in, " extractvalue ")
    assert count(ours_in, " select ") < 0.80 * count(theirs_in, " select ")
    assert norm_ir(ours) == norm_ir(theirs)


def test_an_element_kernels_optimised_ir_is_numbas(tmp_path) -> None:
    """The rigid-body kernel (its element loop and helpers) compiled in two new processes,
    each with an empty cache, with and without the lean indexing: the same optimised IR,
    instruction for instruction, up to the names of values."""
    ours, theirs = rigid_body_kernel_ir(tmp_path, "DRIVEDYN_JIT_INDEXING")
    assert len(ours.splitlines()) > 1000
    assert ours != theirs  # the switch took effect: numba numbered other values
    assert norm_ir(ours) == norm_ir(theirs)
