"""Calling the element kernels of a model from compiled code, by address.

The compiled Newton step (:mod:`drivedyn.solver.newton_kernel`) evaluates every element group
of the model without returning to Python. numba could call a kernel from another compiled
function only if the kernel were a compile-time constant there, and it would then link the
kernel's code into the caller and optimise it again: about 5 s per kernel combination, paid
again for each model with another set of element families (measured). Instead each group
carries the address of its kernel's C entry point (numba compiles one for every function:
``cfunc.<name>``, the kernel with its arguments passed by value), and :func:`call_groups`
calls through those addresses. The caller is compiled once per combination of *argument types*
and cached like any kernel (an address is data, not code); the kernels stay compiled and
cached once each.

Safety rests on one rule: the address of a group is the entry point of the kernel overload
compiled for exactly the argument types the group is called with (:func:`entry_address`
looks it up by those types, and :meth:`~drivedyn.solver.assembly.System.kernel_table` takes
the arguments from the same arrays); :func:`call_groups` converts literal constants to the types they have as Python
values (``int`` to int64, ``float`` to float64), as numba's dispatcher does.
"""

from __future__ import annotations

from typing import Any

from llvmlite import ir
from numba import types
from numba.extending import intrinsic


@intrinsic
def call_groups(typingctx, G, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want):
    """Call every group's kernel: ``G`` holds per group ``(leading arguments, trailing
    arguments, address)`` (:meth:`~drivedyn.solver.assembly.System.kernel_table`), the
    other arguments are the middle ones of the kernel contract (:mod:`drivedyn.elements.base`).

    The calls are emitted straight from the tuple's members (no tuple is built, so no
    reference counting of the few hundred arrays ``G`` holds: that made a generic loop over
    the groups 180 000 LLVM instructions long, 15 s to compile).
    """
    if not isinstance(G, types.BaseTuple):
        return None
    mid_types = (x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want)
    for g in G.types:
        if not (isinstance(g, types.BaseTuple) and len(g.types) == 3
                and isinstance(g.types[2], types.Integer)):
            return None

    def codegen(context, builder, sig, llargs):
        table, mid = llargs[0], llargs[1:]
        mid_vals = []
        for val, ty in zip(mid, mid_types, strict=True):
            u = types.unliteral(ty)
            mid_vals.append((context.cast(builder, val, ty, u) if u != ty else val, u))
        for i, gty in enumerate(sig.args[0].types):
            group = builder.extract_value(table, i)
            pre_ty, post_ty, addr_ty = gty.types
            pre = builder.extract_value(group, 0)
            post = builder.extract_value(group, 1)
            addr = context.cast(builder, builder.extract_value(group, 2), addr_ty, types.intp)
            args = [(builder.extract_value(pre, k), t) for k, t in enumerate(pre_ty.types)]
            args += mid_vals
            args += [(builder.extract_value(post, k), t) for k, t in enumerate(post_ty.types)]
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
