"""Calling the element kernels of a model from compiled code, by address.

The compiled Newton step (:mod:`drivedyn.solver.newton_kernel`) evaluates every element group
of the model without returning to Python. numba could call a kernel from another compiled
function only if the kernel were a compile-time constant there, and it would then link the
kernel's code into the caller and optimise it again: about 5 s per kernel combination, paid
again for each model with another set of element families (measured). Instead a
:class:`KernelTable` holds, per group, the address of its kernel's C entry point (numba
compiles one for every function: ``cfunc.<name>``, the kernel with its arguments passed by
value) and its fixed arguments, and :func:`call_groups` calls through those addresses. The
caller is compiled once per combination of *argument types* and cached like any kernel (an
address is data, not code); the kernels stay compiled and cached once each. Measured on the
Type C bench: first compilation of the Newton step 3.7 s, instead of 19 s with the kernels
linked in.

Safety rests on one rule: the address of a group is the entry point of the kernel overload
compiled for exactly the argument types the group is called with (:func:`entry_address`
looks it up by those types, and :meth:`~drivedyn.solver.system.System.kernel_table` builds
the table from the same arrays); :func:`call_groups` converts literal constants to the types
they have as Python values (``int`` to int64, ``float`` to float64), as numba's dispatcher
does. The table keeps the arrays alive; a group whose arrays are replaced needs a new table.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import (
    NativeValue,
    intrinsic,
    models,
    register_model,
    typeof_impl,
    unbox,
)


class KernelTableType(types.Type):
    """numba type of a :class:`KernelTable`: the argument types of every group's fixed
    leading and trailing arguments (the compiled caller depends on these only)."""

    def __init__(self, groups: tuple) -> None:
        self.groups = groups  # ((leading types...), (trailing types...)) per group
        super().__init__(name=f"KernelTable{groups}")


class KernelTable:
    """Every group's kernel entry address with its fixed leading and trailing arguments,
    as one int64 table: per group the address, then per argument the array's data pointer,
    shape and strides (in elements of bytes, as numpy gives them), or a scalar's value.

    The compiled caller rebuilds the array descriptors from the table (no reference count:
    the table keeps the arrays alive through :attr:`arrays`), so it takes one argument
    instead of a few hundred arrays: unboxing those and cleaning up after each possible
    unboxing failure made the caller's wrapper ten thousand LLVM lines long, 9 s to compile
    for a TORSEN model (measured).

    Args:
        groups: per group ``(address, leading arguments, trailing arguments)``.
    Raises:
        TypeError: an argument that is neither an array nor an int, float or bool.
    """

    def __init__(self, groups: list[tuple[int, tuple, tuple]]) -> None:
        from numba import typeof

        words: list[int] = []
        kinds = []
        self.arrays = []
        for addr, pre, post in groups:
            words.append(int(addr))
            tys = []
            for args in (pre, post):
                tt = []
                for a in args:
                    t = typeof(a)
                    if isinstance(t, types.Array):
                        words.append(a.ctypes.data)
                        words += list(a.shape)
                        words += list(a.strides)
                        self.arrays.append(a)
                    elif isinstance(t, types.Boolean):
                        words.append(int(bool(a)))
                    elif isinstance(t, types.Integer):
                        words.append(int(a))
                    elif isinstance(t, types.Float):
                        words.append(int(np.float64(a).view(np.int64)))
                    else:
                        raise TypeError(f"kernel argument of type {t} is not supported")
                    tt.append(t)
                tys.append(tuple(tt))
            kinds.append(tuple(tys))
        self.table = np.array(words, dtype=np.int64)
        self.address = int(self.table.ctypes.data)
        self.numba_type = KernelTableType(tuple(kinds))


@typeof_impl.register(KernelTable)
def _typeof_table(val, c):
    return val.numba_type


@register_model(KernelTableType)
class _KernelTableModel(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, ir.IntType(64))


@unbox(KernelTableType)
def _unbox_table(typ, obj, c):
    addr = c.pyapi.object_getattr_string(obj, "address")
    val = c.pyapi.long_as_longlong(addr)
    c.pyapi.decref(addr)
    return NativeValue(val, is_error=cgutils.is_not_null(c.builder, c.pyapi.err_occurred()))


def _load_argument(context, builder, t, word):
    """One fixed argument of type ``t`` from the table (``word()`` loads the next int64)."""
    if isinstance(t, types.Array):
        data = builder.inttoptr(word(), context.get_data_type(t.dtype).as_pointer())
        shape = [word() for _ in range(t.ndim)]
        strides = [word() for _ in range(t.ndim)]
        intp = context.get_value_type(types.intp)
        ary = context.make_array(t)(context, builder)
        nitems = shape[0] if shape else intp(1)
        for s in shape[1:]:
            nitems = builder.mul(nitems, s)
        ary.data = data
        ary.shape = cgutils.pack_array(builder, shape)
        ary.strides = cgutils.pack_array(builder, strides)
        ary.itemsize = intp(context.get_abi_sizeof(context.get_data_type(t.dtype)))
        ary.nitems = nitems
        ary.meminfo = cgutils.get_null_value(ary.meminfo.type)
        ary.parent = cgutils.get_null_value(ary.parent.type)
        return ary._getvalue()
    v = word()
    if isinstance(t, types.Boolean):
        return builder.icmp_unsigned("!=", v, v.type(0))
    if isinstance(t, types.Integer):
        return builder.trunc(v, context.get_value_type(t)) if t.bitwidth < 64 else v
    f = builder.bitcast(v, ir.DoubleType())
    return builder.fptrunc(f, context.get_value_type(t)) if t.bitwidth < 64 else f


def _borrowed(context, builder, t, value):
    """The array ``value`` of type ``t`` without its memory owner: the kernel borrows it for
    the call (the caller holds it throughout), so the views a kernel takes of it (``x[n]``,
    ``R[n]``, per element and row) count no references. With the owner, each view paid an
    atomic increment and decrement: 7 % of the Type C bench's run in NRT_incref and
    NRT_decref (perf)."""
    ary = context.make_array(t)(context, builder, value=value)
    ary.meminfo = cgutils.get_null_value(ary.meminfo.type)
    ary.parent = cgutils.get_null_value(ary.parent.type)
    return ary._getvalue()


def _borrowed_value(context, builder, t, value):
    """``value`` of type ``t`` with every array in it (nested tuples included) borrowed."""
    if isinstance(t, types.Array):
        return _borrowed(context, builder, t, value)
    if isinstance(t, types.BaseTuple):
        out = value
        for i, ti in enumerate(t.types):
            item = builder.extract_value(value, i)
            out = builder.insert_value(out, _borrowed_value(context, builder, ti, item), i)
        return out
    return value


@intrinsic
def borrow(typingctx, value):
    """``value`` (an array, or a tuple of arrays, tuples and other values) with its arrays'
    memory owners left out: for a compiled function that works on its arguments while its
    caller holds them, and keeps none of them beyond the call. Its views and the arrays it
    passes on then count no references (an atomic increment and decrement each, per view
    and per call of a function that takes the array)."""
    def codegen(context, builder, sig, args):
        return _borrowed_value(context, builder, sig.args[0], args[0])

    return value(value), codegen


@intrinsic
def call_groups(typingctx, G, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want):
    """Call every group's kernel: ``G`` is a :class:`KernelTable`, the other arguments are
    the middle ones of the kernel contract (:mod:`drivedyn.elements.framework.contract`)."""
    if not isinstance(G, KernelTableType):
        return None
    mid_types = (x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want)

    def codegen(context, builder, sig, llargs):
        base = builder.inttoptr(llargs[0], ir.IntType(64).as_pointer())
        pos = [0]

        def word():
            p = builder.gep(base, [ir.Constant(ir.IntType(64), pos[0])])
            pos[0] += 1
            return builder.load(p)

        mid = []
        for val, ty in zip(llargs[1:], mid_types, strict=True):
            u = types.unliteral(ty)
            val = context.cast(builder, val, ty, u) if u != ty else val
            if isinstance(u, types.Array):
                val = _borrowed(context, builder, u, val)
            mid.append((val, u))
        for pre_types, post_types in sig.args[0].groups:
            addr = word()
            args = [(_load_argument(context, builder, t, word), t) for t in pre_types]
            args += mid
            args += [(_load_argument(context, builder, t, word), t) for t in post_types]
            fnty = ir.FunctionType(context.get_value_type(types.none),
                                   [context.get_value_type(t) for _, t in args])
            builder.call(builder.inttoptr(addr, fnty.as_pointer()), [a for a, _ in args])
        return context.get_dummy_value()

    return types.none(G, *mid_types), codegen


def entry_address(kernel: Any, signature: tuple) -> int:
    """Address of the C entry point of ``kernel``'s overload for ``signature`` (numba
    types of every argument); KeyError if there is none."""
    cres = kernel.overloads[signature]
    return int(cres.library.get_pointer_to_function(cres.fndesc.llvm_cfunc_wrapper_name))
