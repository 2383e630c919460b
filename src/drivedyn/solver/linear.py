"""Linear solvers for the iteration matrix: sparse LU on the fixed pattern, or dense."""

from __future__ import annotations

import abc

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit

from drivedyn.solver import lapack


class LinearSolver(abc.ABC):
    """Factorise once, solve many times. ``factor`` raises ``np.linalg.LinAlgError`` on a
    singular matrix."""

    @abc.abstractmethod
    def factor(self, A: sp.csc_matrix) -> None:
        """Factorise ``A`` (neq x neq, CSC)."""

    @abc.abstractmethod
    def solve(self, b: np.ndarray) -> np.ndarray:
        """Solve with the last factorisation; ``b`` (neq,)."""

    def factor_csc(self, data: np.ndarray, indices: np.ndarray, indptr: np.ndarray,
                   n: int) -> None:
        """Factorise the n x n matrix given by its CSC arrays (the model's fixed pattern);
        ``data`` is not kept."""
        self.factor(sp.csc_matrix((data.copy(), indices, indptr), shape=(n, n)))


@njit(cache=True)
def sparse_lu_solve(Lp, Li, Lx, Up, Ui, Ux, perm_r, perm_c, b, z, x):
    """Solve ``A x = b`` with SuperLU's factors ``Pr A Pc = L U`` (CSC, sorted indices,
    L unit lower triangular with its diagonal stored)."""
    n = b.shape[0]
    for i in range(n):
        z[perm_r[i]] = b[i]
    for j in range(n):  # forward, unit diagonal (first entry of column j)
        zj = z[j]
        if zj != 0.0:
            for k in range(Lp[j], Lp[j + 1]):
                i = Li[k]
                if i > j:
                    z[i] -= Lx[k] * zj
    for j in range(n - 1, -1, -1):  # backward, diagonal is the last entry of column j
        kd = Up[j + 1] - 1
        zj = z[j] / Ux[kd]
        z[j] = zj
        if zj != 0.0:
            for k in range(Up[j], kd):
                z[Ui[k]] -= Ux[k] * zj
    for i in range(n):
        x[i] = z[perm_c[i]]


class SparseLU(LinearSolver):
    """SuperLU factorisation (COLAMD column ordering from the fixed pattern) with the
    triangular solves done by a compiled routine on the extracted factors.

    The iteration matrix is a saddle-point matrix (zero multiplier block), so partial pivoting
    is kept on (``diag_pivot_thresh``) rather than forcing diagonal pivots. The solves are
    our own because ``SuperLU.solve`` costs about 16 ns per factor entry through scipy
    (90 us for a 2200-unknown chain) against about 10 us here.
    """

    def __init__(self, permc_spec: str = "COLAMD", diag_pivot_thresh: float = 0.1) -> None:
        self.permc_spec = permc_spec
        self.diag_pivot_thresh = diag_pivot_thresh
        self._f: tuple | None = None

    def factor(self, A: sp.csc_matrix) -> None:
        try:
            lu = spla.splu(A, permc_spec=self.permc_spec,
                           diag_pivot_thresh=self.diag_pivot_thresh)
        except RuntimeError as exc:  # "Factor is exactly singular"
            raise np.linalg.LinAlgError(str(exc)) from None
        L = lu.L.tocsc()
        U = lu.U.tocsc()
        L.sort_indices()
        U.sort_indices()
        n = A.shape[0]
        self._f = (L.indptr.astype(np.int64), L.indices.astype(np.int64), L.data,
                   U.indptr.astype(np.int64), U.indices.astype(np.int64), U.data,
                   lu.perm_r.astype(np.int64), lu.perm_c.astype(np.int64))
        self._z = np.empty(n)

    def solve(self, b: np.ndarray) -> np.ndarray:
        x = np.empty_like(b)
        sparse_lu_solve(*self._f, np.ascontiguousarray(b, dtype=float), self._z, x)
        return x


class DenseLU(LinearSolver):
    """LAPACK LU (getrf/getrs with partial pivoting); faster than SuperLU up to about 150
    unknowns: for the 113 unknowns of the TORSEN Type B, getrf takes about 60 us where
    SuperLU with its factor extraction takes about 470 us (benchmarks/README.md).

    The factors live in ``lu``/``piv`` (:func:`drivedyn.solver.lapack.workspace`); the
    compiled Newton iteration factorises and solves in the same arrays with the same
    functions.
    """

    def __init__(self) -> None:
        self.n = -1
        self.ws: tuple | None = None  # (lu, piv, ib, tr) for the current size

    def factor(self, A: sp.csc_matrix) -> None:
        A = sp.csc_matrix(A)
        self.factor_csc(A.data, A.indices, A.indptr, A.shape[0])

    def workspace(self, n: int) -> tuple:
        """The factor arrays for an ``n`` x ``n`` matrix (allocated on first use)."""
        if self.ws is None or self.n != n:
            self.ws = lapack.workspace(n)
            self.n = n
        return self.ws

    def factor_csc(self, data: np.ndarray, indices: np.ndarray, indptr: np.ndarray,
                   n: int) -> None:
        lu, piv, ib, _tr = self.workspace(n)
        if lapack.dense_factor_csc(data, indices, indptr, lu, piv, ib) != 0:
            raise np.linalg.LinAlgError("singular matrix")

    def solve(self, b: np.ndarray) -> np.ndarray:
        x = np.array(b, dtype=float)
        lu, piv, ib, tr = self.ws
        lapack.dense_solve(lu, piv, x, ib, tr)
        return x


#: largest system solved by the dense LU: the TORSEN benches (92 and 113 unknowns) run 1.7-1.8x
#: faster with it than with SuperLU (benchmarks/README.md); LAPACK's getrf grows as n^3 and
#: loses to the sparse LU of the long chains (hundreds to thousands of unknowns)
DENSE_MAX = 150
#: above DENSE_MAX, the dense LU still wins when SuperLU's factors fill more than this share
#: of the dense matrix (a body that every joint hangs on couples all unknowns: the 387 of the
#: 4WD vehicle fill 87 % with COLAMD, 3.7 ms per factorisation against 1.5 ms dense), up to
#: DENSE_FILL_MAX unknowns; a banded chain of 330-396 unknowns fills a few % and SuperLU takes
#: 0.5 ms against 1.2-1.9 ms dense (measured 2026-11-26)
DENSE_FILL = 0.3
DENSE_FILL_MAX = 1500


class AutoLU(LinearSolver):
    """SuperLU, switching for good to the dense LU after the first factorisation if its
    factors fill more than :data:`DENSE_FILL` of the dense matrix (the choice depends on the
    model's pattern and first matrix only, so it is the same in every run of a model)."""

    def __init__(self) -> None:
        self.sparse: SparseLU | None = SparseLU()
        self.dense: DenseLU | None = None

    @property
    def active(self) -> LinearSolver:
        return self.dense if self.dense is not None else self.sparse

    def factor(self, A: sp.csc_matrix) -> None:
        A = sp.csc_matrix(A)
        self.factor_csc(A.data, A.indices, A.indptr, A.shape[0])

    def factor_csc(self, data: np.ndarray, indices: np.ndarray, indptr: np.ndarray,
                   n: int) -> None:
        if self.dense is not None:
            self.dense.factor_csc(data, indices, indptr, n)
            return
        self.sparse.factor_csc(data, indices, indptr, n)
        fill = self.sparse._f[1].size + self.sparse._f[4].size
        if n <= DENSE_FILL_MAX and fill > DENSE_FILL * n * n:
            self.dense = DenseLU()
            self.sparse = None
            self.dense.factor_csc(data, indices, indptr, n)

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self.active.solve(b)


def default_linear_solver(neq: int) -> LinearSolver:
    """Dense LU up to :data:`DENSE_MAX` unknowns, :class:`AutoLU` above."""
    return DenseLU() if neq <= DENSE_MAX else AutoLU()
