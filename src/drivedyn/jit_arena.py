"""Work arrays carved from one allocation: :func:`carve`.

An element kernel allocates its work arrays once per call (local residual and matrices, the
primitives' scratch, the gear loop's 30 arrays), never inside the element loop. Each
``np.zeros`` is still a ``malloc``, a zero fill and a ``free`` at the end of the call, and a
kernel is called a few hundred thousand times in a run: on the Type C vehicle configuration
``malloc``/``free`` and numba's allocation wrapper took 12-15 % of the run's time (``perf``,
benchmarks/README.md, issue 16 seventeenth round), more than the LU.

:func:`carve` makes a C-contiguous float64 view of ``shape`` into a 1-D float64 buffer at an
element offset, so that a kernel allocates one zeroed buffer and views it::

    buf = np.zeros(n1 + n2 * n2)
    a = carve(buf, 0, n1)              # (n1,)
    B = carve(buf, n1, (n2, n2))       # (n2, n2)

A view holds a reference to the buffer (its memory stays alive as long as any view does,
whatever numba's variable lifetimes: numba frees a variable after its last use, which may be
the last ``carve``), and views of disjoint ranges never alias. Bounds are the caller's: no
check at run time, so the offsets are constants or sums of the sizes carved before
(``drivedyn.elements.base.local_arrays``, ``drivedyn.elements.gears.kernel._work``).
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic
from numba.np.arrayobj import make_array, populate_array


def _dims(shape) -> int | None:
    if isinstance(shape, types.Integer):
        return 1
    if isinstance(shape, types.BaseTuple) and all(isinstance(s, types.Integer)
                                                  for s in shape):
        return len(shape)
    return None


@intrinsic
def carve(typingctx, buf, off, shape):
    """C-contiguous float64 view of ``shape`` (an int or a tuple of ints) into the 1-D
    C-contiguous float64 array ``buf``, starting at element ``off``. No bounds check: the
    caller's offsets and sizes fit its buffer (module docstring)."""
    nd = _dims(shape)
    if (nd is None or not isinstance(buf, types.Array) or buf.ndim != 1
            or buf.dtype != types.float64 or buf.layout != "C"
            or not isinstance(off, types.Integer)):
        return None
    retty = types.Array(types.float64, nd, "C")

    def codegen(context, builder, sig, args):
        bufv, offv, shp = args
        src = make_array(sig.args[0])(context, builder, bufv)
        dst = make_array(retty)(context, builder)
        intp = context.get_value_type(types.intp)
        if nd == 1 and isinstance(sig.args[2], types.Integer):
            dims = [context.cast(builder, shp, sig.args[2], types.intp)]
        else:
            dims = [context.cast(builder, v, t, types.intp)
                    for v, t in zip(cgutils.unpack_tuple(builder, shp), sig.args[2],
                                    strict=True)]
        strides = [ir.Constant(intp, 8)]
        for d in reversed(dims[1:]):
            strides.insert(0, builder.mul(strides[0], d))
        offi = context.cast(builder, offv, sig.args[1], types.intp)
        data = builder.gep(src.data, [offi])
        populate_array(dst, data=data, shape=dims, strides=strides,
                       itemsize=ir.Constant(intp, 8), meminfo=src.meminfo)
        # the view owns a reference to the buffer's memory
        context.nrt.incref(builder, sig.args[0], bufv)
        return dst._getvalue()

    return retty(buf, off, shape), codegen

