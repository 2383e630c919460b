"""The compiled Newton iteration's factorisation and solve, chosen by the type of the sparse
factors.

The stepping loop (:func:`~drivedyn.solver.step_loop.run_steps`) receives the dense LU's
workspace ``linear = (lu, piv, ib, tr, ...)`` (:func:`~drivedyn.solver.lapack.workspace`) and
the sparse LU's factors ``sparse = (Lp, Li, Lx, Up, Ui, Ux, perm_r, perm_c, tail, z, refactor)``
(:meth:`~drivedyn.solver.linear.SparseLU.refactor_arrays`). A model factorised by the dense LU
alone (:class:`~drivedyn.solver.linear.DenseLU`) passes ``sparse=None``: numba then compiles
the dense path only, without the sparse solve and the refactorisation in place (the loop's
first compilation 8.1-8.8 -> 6.1-6.3 s on the Type C bench: the sparse functions' own
compilation and as much again for optimising their code inside the loop). A model whose solver
is or may become sparse (:class:`~drivedyn.solver.linear.SparseLU`,
:class:`~drivedyn.solver.linear.AutoLU`) passes the factors and both paths are compiled; the
Newton memory's ``I_DENSE`` field picks one at run time (AutoLU switches to the dense LU
during a run).

:func:`lu_solve` and :func:`lu_factor` pick their implementation from the type of
``sparse``: at run time in Python, at compile time in numba (an ``@overload`` of each).
"""

from __future__ import annotations

import numpy as np
from numba import types
from numba.extending import overload

from drivedyn.solver.lapack import dense_factor_csc, dense_solve
from drivedyn.solver.sparse_lu import refactor_in_place, sparse_lu_solve

#: outcomes of :func:`lu_factor`
FACTORED, FACTOR_OUTSIDE, FACTOR_SINGULAR = 0, 1, 2


def _solve_dense(linear, sparse, dense, delta):
    lu, piv, ib, tr = linear[0], linear[1], linear[2], linear[3]
    dense_solve(lu, piv, delta, ib, tr)


def _solve_either(linear, sparse, dense, delta):
    lu, piv, ib, tr = linear[0], linear[1], linear[2], linear[3]
    if dense:
        dense_solve(lu, piv, delta, ib, tr)
    else:
        Lp, Li, Lx, Up, Ui, Ux, perm_r, perm_c, tail, z, _ = sparse
        sparse_lu_solve(Lp, Li, Lx, Up, Ui, Ux, perm_r, perm_c, tail, delta, z, delta)


def _factor_dense(data, indices, indptr, linear, sparse, external, refactor):
    lu, piv, ib = linear[0], linear[1], linear[2]
    if dense_factor_csc(data, indices, indptr, lu, piv, ib) != 0:
        return FACTOR_SINGULAR
    return FACTORED


def _factor_either(data, indices, indptr, linear, sparse, external, refactor):
    if external:
        if not refactor or refactor_in_place(data, indices, indptr, sparse) != 0:
            return FACTOR_OUTSIDE
        return FACTORED
    lu, piv, ib = linear[0], linear[1], linear[2]
    if dense_factor_csc(data, indices, indptr, lu, piv, ib) != 0:
        return FACTOR_SINGULAR
    return FACTORED


def lu_solve(linear: tuple, sparse: tuple | None, dense: bool, delta: np.ndarray) -> None:
    """Solve ``A x = delta`` in place with the current factors: the dense LU's in
    ``linear`` if ``dense`` (or ``sparse`` is None), else the sparse LU's in ``sparse``.
    ``delta`` (neq,)."""
    (_solve_dense if sparse is None else _solve_either)(linear, sparse, dense, delta)


def lu_factor(data: np.ndarray, indices: np.ndarray, indptr: np.ndarray, linear: tuple,
              sparse: tuple | None, external: bool, refactor: bool) -> int:
    """Factorise the CSC matrix ``(data, indices, indptr)`` (nnz,), (nnz,), (neq + 1,):
    with the dense LU into ``linear``'s workspace, or, if ``external`` (the sparse LU is
    active), with the sparse LU's last pivots in place (``refactor``: pivots kept from a
    factorisation in Python). Returns :data:`FACTORED`, :data:`FACTOR_OUTSIDE` (the sparse
    LU must factorise afresh, in Python) or :data:`FACTOR_SINGULAR` (the dense LU found a
    zero pivot)."""
    impl = _factor_dense if sparse is None else _factor_either
    return impl(data, indices, indptr, linear, sparse, external, refactor)


# the overloads' parameters carry no annotations: numba compares them with the
# implementations', annotations included
@overload(lu_solve)
def _lu_solve_compiled(linear, sparse, dense, delta):
    return _solve_dense if isinstance(sparse, types.NoneType) else _solve_either


@overload(lu_factor)
def _lu_factor_compiled(data, indices, indptr, linear, sparse, external, refactor):
    return _factor_dense if isinstance(sparse, types.NoneType) else _factor_either
