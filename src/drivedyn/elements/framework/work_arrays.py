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
element ``off``: a slice and, for a tuple shape, a reshape (numba's own, no copy). Views of
disjoint ranges never alias. Offsets are constants or sums of the sizes carved before
(:func:`drivedyn.elements.framework.contract.local_arrays_at`,
``drivedyn.elements.gears.kernel._work``);
numba checks no bounds, so a short buffer is the caller's error: the ``work_buffer`` helpers
size it from the same numbers.
"""

from __future__ import annotations

import numpy as np
from numba import types
from numba.extending import overload


def carve(buf: np.ndarray, off: int, shape: int | tuple[int, ...]) -> np.ndarray:
    """C-contiguous view of ``shape`` (an int or a tuple of ints) into the 1-D float64
    array ``buf`` from element ``off`` (Python version of the compiled one)."""
    n = int(np.prod(shape))
    return buf[off:off + n].reshape(shape)


@overload(carve, inline="always")
def _carve(buf, off, shape):
    if not (isinstance(buf, types.Array) and buf.ndim == 1 and buf.layout == "C"
            and buf.dtype == types.float64):
        return None
    if isinstance(shape, types.Integer):
        def view1(buf, off, shape):
            return buf[off:off + shape]
        return view1
    if isinstance(shape, types.BaseTuple) and all(isinstance(s, types.Integer)
                                                  for s in shape):
        nd = len(shape)
        if nd == 2:
            def view2(buf, off, shape):
                return buf[off:off + shape[0] * shape[1]].reshape(shape)
            return view2
        if nd == 3:
            def view3(buf, off, shape):
                return buf[off:off + shape[0] * shape[1] * shape[2]].reshape(shape)
            return view3
    return None
