"""numba's array indexing lowered without dead reads and trivial arithmetic (a compile-time
saving, installed by :func:`drivedyn.jit.apply`).

Every ``a[i]``, ``a[i, j]``, ``a[i, :]`` numba compiles goes through
``numba.np.arrayobj.basic_indexing``. For an array held as a value
(:mod:`drivedyn.jit_structs`) it emits, per expression:

- the shape and the strides, each dimension one ``extractvalue``, then both again inside
  ``cgutils.get_item_pointer``: on a C-contiguous array the strides are never used and the
  second shapes duplicate the first (13 ``extractvalue`` for ``a[i, j]``, 4 needed);
- for an integer index the negative-index wraparound (compare, add, select), also for a
  constant such as the ``0`` of ``R[0, 2]``, where the select always takes the index;
- the offset of a C array as ``1 * shape[1]``, ``0 + i * step`` and ``j * 1``.

LLVM folds all of it in its first passes, but only after Python built it, printed it as IR
text and LLVM parsed it: on the Type C bench's kernels it was 26 000 of 178 000 instructions
(``extractvalue`` 57 000 -> 40 000, ``select`` 5300 -> 3900, wraparounds of constants
951 -> 112), and the replacement takes 4.5 % off their compilation's CPU.

:func:`install` replaces ``basic_indexing`` with one that computes the same pointer, shapes
and strides and reads each field only where it is used: the shape of a dimension when an
index needs its wraparound, its bounds check or its step, the strides only for a slice, a
dimension kept in a view or an array of any layout. A constant non-negative index, also one
read from a tuple of constants, is used as it is (``fix_integer_index``, also numba's in its
fancy indexing). The item pointer is numba's ``get_item_pointer2`` (C, F or any layout)
without the multiplications by one and the addition to zero. The other instructions are
numba's, the reads of a shape later (where first used).

The optimised LLVM IR of the Type C bench's kernels is numba's own, instruction for
instruction, up to the names of values (issue 16 fifteenth round, benchmarks/README.md); the
tests check it on a function with every kind of index and on an element kernel.

numba's functions are replaced only if their source is the one reproduced here (numba 0.68:
``basic_indexing``, ``fix_integer_index``, ``slicing.fix_index``,
``cgutils.get_item_pointer``, ``get_item_pointer2``, compared by SHA-256); otherwise nothing
is installed and numba lowers as before. ``DRIVEDYN_JIT_INDEXING=0`` (read when the first
kernel module is imported) leaves numba as it is too.
"""

from __future__ import annotations

import contextlib
import hashlib
import inspect
import os
from collections.abc import Callable, Iterator
from typing import Any

_state: dict = {"installed": None, "originals": None}

#: SHA-256 (first 16 hex digits) of the numba functions this module reproduces
_SOURCES = {
    ("numba.np.arrayobj", "basic_indexing"): "6000a5433cca5b60",
    ("numba.np.arrayobj", "fix_integer_index"): "05fc2c98f4721faa",
    ("numba.cpython.slicing", "fix_index"): "06b9094a2bb8005f",
    ("numba.core.cgutils", "get_item_pointer"): "2c411155d01c872e",
    ("numba.core.cgutils", "get_item_pointer2"): "7b168f0b301fb550",
}


def _sources_match() -> bool:
    """True if numba's functions are those reproduced here, character for character."""
    import importlib

    try:
        for (module, name), digest in _SOURCES.items():
            src = inspect.getsource(getattr(importlib.import_module(module), name))
            if hashlib.sha256(src.encode()).hexdigest()[:16] != digest:
                return False
    except (ImportError, AttributeError, OSError, TypeError):  # pragma: no cover
        return False
    return True


def _nonnegative_constant(value: Any) -> Any:
    """The constant integer ``value`` is known to be, if non-negative, else None: ``value``
    itself, or the constant an ``insertvalue`` chain put where an ``extractvalue`` reads (a
    tuple index such as ``(0, 2)`` is built so and unpacked so, just before the indexing)."""
    from llvmlite import ir
    from llvmlite.ir import instructions as ins

    if isinstance(value, ins.ExtractValue) and len(value.indices) == 1:
        (k,) = value.indices
        agg = value.aggregate
        while isinstance(agg, ins.InsertValue) and len(agg.indices) == 1:
            if agg.indices[0] == k:
                value = agg.value
                break
            agg = agg.aggregate
    if (isinstance(value, ir.Constant) and isinstance(value.constant, int)
            and not isinstance(value.constant, bool) and value.constant >= 0):
        return value
    return None


def _fixed_index(context: Any, builder: Any, idxty: Any, idx: Any,
                 size: Callable[[], Any]) -> Any:
    """The index as ``intp`` (``uintp`` if unsigned) with the wraparound of a negative one
    by the dimension's length ``size()``, asked for only if needed: a constant known
    non-negative is returned as it is (the select would always take it)."""
    from numba.core import types
    from numba.cpython import slicing

    if idxty.signed:
        ind = context.cast(builder, idx, idxty, types.intp)
        known = _nonnegative_constant(ind)
        if known is not None:
            return known
        ind = slicing.fix_index(builder, ind, size())
    else:
        ind = context.cast(builder, idx, idxty, types.uintp)
    return ind


def fix_integer_index(context: Any, builder: Any, idxty: Any, idx: Any, size: Any) -> Any:
    """numba's ``fix_integer_index`` (also used by its fancy indexing), without the
    wraparound of a constant known non-negative."""
    return _fixed_index(context, builder, idxty, idx, lambda: size)


class _Fields:
    """An array's shape and strides, each dimension read (``extractvalue``) on first use,
    at the builder's position then: every later use comes after it in the same straight-line
    lowering, so the read dominates it."""

    def __init__(self, builder: Any, ary: Any, ndim: int) -> None:
        self.builder, self.ary, self.ndim = builder, ary, ndim
        self._shape: Any = None
        self._strides: Any = None
        self._dims: dict = {}

    def shape(self, ax: int) -> Any:
        key = ("shape", ax)
        if key not in self._dims:
            if self._shape is None:
                self._shape = self.ary.shape
            self._dims[key] = self.builder.extract_value(self._shape, ax)
        return self._dims[key]

    def strides(self) -> list:
        if self._strides is None:  # numba unpacks all of them at once
            from numba.core import cgutils

            self._strides = cgutils.unpack_tuple(self.builder, self.ary.strides, self.ndim)
        return self._strides


def item_pointer(builder: Any, data: Any, fields: _Fields, layout: str, indices: list) -> Any:
    """numba's ``get_item_pointer2`` without wraparound and bounds check (done before):
    the address of the item at ``indices`` (one per leading dimension), without the
    multiplications by one and the addition to zero numba writes for C and F layouts."""
    from numba.core import cgutils

    if not indices:
        return builder.gep(data, [cgutils.int32_t(0)])
    if layout in "CF":
        steps = []
        for i in range(len(indices)):
            dims = range(i + 1, fields.ndim) if layout == "C" else range(i)
            last = None
            for j in dims:
                s = fields.shape(j)
                last = s if last is None else builder.mul(last, s)
            steps.append(last)
        loc = None
        for i, s in zip(indices, steps, strict=True):
            tmp = i if s is None else builder.mul(i, s)
            loc = tmp if loc is None else builder.add(loc, tmp)
        return builder.gep(data, [loc])
    strides = fields.strides()
    dimoffs = [builder.mul(s, i) for s, i in zip(strides, indices, strict=False)]
    offset = dimoffs[0]
    for d in dimoffs[1:]:
        offset = builder.add(offset, d)
    return cgutils.pointer_add(builder, data, offset)


def basic_indexing(context: Any, builder: Any, aryty: Any, ary: Any, index_types: Any,
                   indices: Any, boundscheck: Any = None) -> tuple:
    """numba's ``basic_indexing``: ``(data pointer, shapes, strides)`` of the view (or item)
    ``ary[indices]``, each shape and stride read only where used."""
    from numba.core import cgutils, types
    from numba.cpython import slicing
    from numba.np import arrayobj

    zero = context.get_constant(types.intp, 0)
    one = context.get_constant(types.intp, 1)
    fields = _Fields(builder, ary, aryty.ndim)

    output_indices: list = []
    output_shapes: list = []
    output_strides: list = []

    num_newaxes = len([idx for idx in index_types if arrayobj.is_nonelike(idx)])
    ax = 0
    for indexval, idxty in zip(indices, index_types, strict=False):
        if idxty is types.ellipsis:
            n_missing = aryty.ndim - len(indices) + 1 + num_newaxes
            for _ in range(n_missing):
                output_indices.append(zero)
                output_shapes.append(fields.shape(ax))
                output_strides.append(fields.strides()[ax])
                ax += 1
            continue
        if isinstance(idxty, types.SliceType):
            slice_ = context.make_helper(builder, idxty, value=indexval)
            slicing.guard_invalid_slice(context, builder, idxty, slice_)
            slicing.fix_slice(builder, slice_, fields.shape(ax))
            output_indices.append(slice_.start)
            sh = slicing.get_slice_length(builder, slice_)
            st = slicing.fix_stride(builder, slice_, fields.strides()[ax])
            output_shapes.append(sh)
            output_strides.append(st)
        elif isinstance(idxty, types.Integer):
            ind = _fixed_index(context, builder, idxty, indexval,
                               lambda ax=ax: fields.shape(ax))
            if boundscheck:
                cgutils.do_boundscheck(context, builder, ind, fields.shape(ax), ax)
            output_indices.append(ind)
        elif arrayobj.is_nonelike(idxty):
            output_shapes.append(one)
            output_strides.append(zero)
            ax -= 1
        else:
            raise NotImplementedError(f"unexpected index type: {idxty}")
        ax += 1

    assert ax <= aryty.ndim
    while ax < aryty.ndim:
        output_shapes.append(fields.shape(ax))
        output_strides.append(fields.strides()[ax])
        ax += 1

    dataptr = item_pointer(builder, ary.data, fields, aryty.layout, output_indices)
    return (dataptr, output_shapes, output_strides)


def install() -> bool:
    """Install the lean indexing (once); True if installed."""
    if _state["installed"] is not None:
        return _state["installed"]
    _state["installed"] = False
    if os.environ.get("DRIVEDYN_JIT_INDEXING", "1") == "0" or not _sources_match():
        return False
    from numba.np import arrayobj

    originals = (arrayobj.basic_indexing, arrayobj.fix_integer_index)
    for fn, orig in zip((basic_indexing, fix_integer_index), originals, strict=True):
        fn.__wrapped__ = orig  # type: ignore[attr-defined]
    _state["originals"] = originals
    arrayobj.basic_indexing = basic_indexing
    arrayobj.fix_integer_index = fix_integer_index
    _state["installed"] = True
    return True


@contextlib.contextmanager
def suspended() -> Iterator[None]:
    """numba's own indexing inside the block (for comparisons in the tests)."""
    if not _state["installed"]:
        yield
        return
    from numba.np import arrayobj

    arrayobj.basic_indexing, arrayobj.fix_integer_index = _state["originals"]
    try:
        yield
    finally:
        arrayobj.basic_indexing = basic_indexing
        arrayobj.fix_integer_index = fix_integer_index
