"""Dense LU factorisation and solve callable from compiled code (LAPACK ``dgetrf``/``dgetrs``).

The dense LU of the iteration matrix (models up to a few hundred unknowns) is called from
Python (:class:`~drivedyn.solver.linear.DenseLU`) and from the compiled Newton iteration
(:mod:`drivedyn.solver.newton_kernel`); both go through the two functions below, so both
paths compute the same factors and corrections to the last bit.

LAPACK comes from SciPy (``scipy.linalg.cython_lapack``, the library SciPy itself calls):
the addresses of ``dgetrf``/``dgetrs`` are registered with LLVM under the names
``drivedyn_dgetrf``/``drivedyn_dgetrs`` when this module is imported, and the compiled
functions call them by name, so numba's on-disk cache keeps them (a function that embedded
an address could not be cached). numba's own ``np.linalg`` exposes no factorisation that
can be reused for several right-hand sides, hence this module.
"""

from __future__ import annotations

import llvmlite.binding as llb
import numpy as np
from numba import njit, types
from numba.extending import get_cython_function_address

for _name in ("dgetrf", "dgetrs"):
    llb.add_symbol(f"drivedyn_{_name}",
                   get_cython_function_address("scipy.linalg.cython_lapack", _name))
_P = types.voidptr
# Fortran calling convention: every argument by address
#   dgetrf(m, n, a, lda, ipiv, info)
_dgetrf = types.ExternalFunction("drivedyn_dgetrf", types.void(_P, _P, _P, _P, _P, _P))
#   dgetrs(trans, n, nrhs, a, lda, ipiv, b, ldb, info)
_dgetrs = types.ExternalFunction("drivedyn_dgetrs",
                                 types.void(_P, _P, _P, _P, _P, _P, _P, _P, _P))


def workspace(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Arrays for an ``n`` x ``n`` factorisation: ``(lu, piv, ib, tr)``: the factors
    (column-major), the pivots, integer scratch for LAPACK's by-address arguments and the
    character ``'N'``."""
    return (np.zeros((n, n), order="F"), np.zeros(max(n, 1), np.int32),
            np.zeros(4, np.int32), np.array([ord("N")], np.uint8))


@njit(cache=True)
def dense_factor_csc(data, indices, indptr, lu, piv, ib):
    """LU with partial pivoting of the n x n matrix given by its CSC arrays (duplicates
    summed) into ``lu`` (n, n, column-major) and ``piv`` (n,); returns 0, or -1 if the
    matrix is singular or the factors are not finite."""
    n = lu.shape[1]
    lu[:, :] = 0.0
    for j in range(n):
        for k in range(indptr[j], indptr[j + 1]):
            lu[indices[k], j] += data[k]
    return dense_factor(lu, piv, ib)


@njit(cache=True)
def dense_factor(lu, piv, ib):
    """LU with partial pivoting of the n x n matrix ``lu`` (column-major) in place, pivots
    into ``piv`` (n,); returns 0, or -1 if the matrix is singular or the factors are not
    finite."""
    n = lu.shape[1]
    if n == 0:
        return 0
    ib[0] = n
    ib[1] = 0
    _dgetrf(ib[0:1].ctypes, ib[0:1].ctypes, lu.ctypes, ib[0:1].ctypes, piv.ctypes,
            ib[1:2].ctypes)
    if ib[1] != 0:
        return -1
    for j in range(n):
        for i in range(n):
            if not np.isfinite(lu[i, j]):
                return -1
    return 0


@njit(cache=True)
def dense_solve(lu, piv, b, ib, tr):
    """Solve ``A x = b`` in place (``b`` (n,) becomes ``x``) with the factors of
    :func:`dense_factor_csc`."""
    n = lu.shape[1]
    if n == 0:
        return
    ib[0] = n
    ib[2] = 1
    ib[3] = 0
    _dgetrs(tr.ctypes, ib[0:1].ctypes, ib[2:3].ctypes, lu.ctypes, ib[0:1].ctypes,
            piv.ctypes, b.ctypes, ib[0:1].ctypes, ib[3:4].ctypes)
