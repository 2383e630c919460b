"""Linear solvers for the iteration matrix: sparse LU on the fixed pattern, or dense."""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla


class LinearSolver:
    """Factorise once, solve many times. ``factor`` raises ``np.linalg.LinAlgError`` on a
    singular matrix."""

    def factor(self, A: sp.csc_matrix) -> None:
        raise NotImplementedError

    def solve(self, b: np.ndarray) -> np.ndarray:
        raise NotImplementedError


class SparseLU(LinearSolver):
    """SuperLU with a column ordering computed from the (fixed) pattern.

    The iteration matrix is a saddle-point matrix (zero multiplier block), so partial pivoting
    is kept on (``diag_pivot_thresh``) rather than forcing diagonal pivots.
    """

    def __init__(self, permc_spec: str = "COLAMD", diag_pivot_thresh: float = 0.1) -> None:
        self.permc_spec = permc_spec
        self.diag_pivot_thresh = diag_pivot_thresh
        self._lu = None

    def factor(self, A: sp.csc_matrix) -> None:
        try:
            self._lu = spla.splu(A, permc_spec=self.permc_spec,
                                 diag_pivot_thresh=self.diag_pivot_thresh)
        except RuntimeError as exc:  # "Factor is exactly singular"
            raise np.linalg.LinAlgError(str(exc)) from None

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self._lu.solve(b)


class DenseLU(LinearSolver):
    """LAPACK LU; faster than SuperLU for tiny systems (a few dozen unknowns)."""

    def __init__(self) -> None:
        self._lu = None

    def factor(self, A: sp.csc_matrix) -> None:
        Ad = A.toarray()
        lu, piv = sla.lu_factor(Ad, check_finite=False)
        if np.any(np.abs(np.diag(lu)) <= 1e-300) or not np.all(np.isfinite(lu)):
            raise np.linalg.LinAlgError("singular matrix")
        self._lu = (lu, piv)

    def solve(self, b: np.ndarray) -> np.ndarray:
        return sla.lu_solve(self._lu, b, check_finite=False)


def default_linear_solver(neq: int) -> LinearSolver:
    """Dense LU below 60 unknowns, sparse LU above."""
    return DenseLU() if neq < 60 else SparseLU()
