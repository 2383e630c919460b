"""Work arrays carved from one allocation: :func:`carve`.

An element kernel needs a dozen or more work arrays per call (local residual and matrices,
the primitives' scratch, the gear loop's 30 arrays). A kernel is called a few hundred
thousand times in a run, and one ``np.zeros`` per array (a ``malloc``, a zero fill, a
``free``) cost more than the LU on the Type C vehicle configuration (``perf``, 12-15 % of
the run). So a group allocates one float64 buffer when it is built (its ``work`` parameter)
and the kernel views it::

    a = carve(buf, 0, n1)              # (n1,)
    B = carve(buf, n1, (n2, n2))       # (n2, n2)

:func:`carve` is a C-contiguous view of ``shape`` into the 1-D float64 buffer ``buf`` from
element ``off``, built in place (no copy). Views of
disjoint ranges never alias. Offsets are constants or sums of the sizes carved before
(:func:`drivedyn.elements.framework.contract.local_arrays_at`,
``drivedyn.elements.gears.kernel._work``);
numba checks no bounds, so a short buffer is the caller's error: the ``work_buffer`` helpers
size it from the same numbers.
"""

from __future__ import annotations

import numpy as np
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic, overload


def carve(buf: np.ndarray, off: int, shape: int | tuple[int, ...]) -> np.ndarray:
    """C-contiguous view of ``shape`` (an int or a tuple of ints) into the 1-D float64
    array ``buf`` from element ``off`` (Python version of the compiled one)."""
    n = int(np.prod(shape))
    return buf[off:off + n].reshape(shape)


# a call, not inlined by numba (``inline="always"``): numba's typed inlining of an overload
# types its body again at every call site (244 in the Type C bench's kernels), while LLVM
# inlines the call anyway (the same runs, the same speed); the first compilation of the
# Type C bench 1.6 s less CPU of 33 s (six pairs compiled side by side, -0.4 to -3.8 s)
@overload(carve)
def _carve(buf, off, shape):
    if not (isinstance(buf, types.Array) and buf.ndim == 1 and buf.layout == "C"
            and buf.dtype == types.float64):
        return None
    if isinstance(shape, types.Integer) or (
            isinstance(shape, types.BaseTuple) and len(shape) in (2, 3)
            and all(isinstance(s, types.Integer) for s in shape)):
        def view(buf, off, shape):
            return _c_view(buf, off, shape)
        return view
    return None


@intrinsic
def _c_view(typingctx, buf, off, shape):
    """The C-contiguous view of ``shape`` (an int or a tuple of two or three ints) into
    ``buf`` from element ``off``, built in place: the same array as ``buf[off:off +
    n].reshape(shape)`` (data, shape, strides, the buffer's owner with one more reference),
    without the slice's bounds arithmetic and numba's general reshape
    (``numba_attempt_nocopy_reshape``, a call per view: 1.3-1.9 % of a TORSEN run by perf;
    the Type C bench's run 14 % faster without them, its first compilation 16 % less CPU)."""
    nd = 1 if isinstance(shape, types.Integer) else len(shape)
    rt = types.Array(types.float64, nd, "C")

    def codegen(context, builder, sig, args):
        bty, oty, sty = sig.args
        intp = context.get_value_type(types.intp)
        src = context.make_array(bty)(context, builder, value=args[0])
        start = context.cast(builder, args[1], oty, types.intp)
        if isinstance(sty, types.Integer):
            dims = [context.cast(builder, args[2], sty, types.intp)]
        else:
            dims = [context.cast(builder, builder.extract_value(args[2], i), sty[i],
                                 types.intp) for i in range(nd)]
        itemsize = intp(context.get_abi_sizeof(context.get_data_type(types.float64)))
        strides = [itemsize] * nd
        for i in range(nd - 2, -1, -1):
            strides[i] = builder.mul(strides[i + 1], dims[i + 1])
        nitems = dims[0]
        for d in dims[1:]:
            nitems = builder.mul(nitems, d)
        out = context.make_array(rt)(context, builder)
        out.data = builder.gep(src.data, [start])
        out.shape = cgutils.pack_array(builder, dims)
        out.strides = cgutils.pack_array(builder, strides)
        out.itemsize = itemsize
        out.nitems = nitems
        out.meminfo = src.meminfo
        out.parent = cgutils.get_null_value(out.parent.type)
        value = out._getvalue()
        context.nrt.incref(builder, rt, value)
        return value

    return rt(buf, off, shape), codegen
