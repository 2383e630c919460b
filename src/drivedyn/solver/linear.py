"""Linear solvers for the iteration matrix: sparse LU on the fixed pattern, or dense."""

from __future__ import annotations

import abc
from typing import TYPE_CHECKING

import numpy as np

from drivedyn.solver import lapack
from drivedyn.solver.sparse_lu import (
    compact_factors,
    gp_factor,
    gp_refactor,
    sparse_lu_solve,
    tail_arrays,
    tail_size,
)

if TYPE_CHECKING:
    import scipy.sparse as sp


def _csc(*args, **kw) -> sp.csc_matrix:
    """``scipy.sparse.csc_matrix(*args, **kw)``. SciPy's sparse package is imported here, on
    first use, not with this module: importing it costs 0.3-0.4 s (most of it SciPy's
    array-API layer) on the way of every command that simulates, before its compile workers
    are forked, and the dense LU and the compiled sparse LU never need it."""
    import scipy.sparse as sp

    return sp.csc_matrix(*args, **kw)


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
        self.factor(_csc((data.copy(), indices, indptr), shape=(n, n)))

    def compiled_calls(self, indices: np.ndarray, indptr: np.ndarray) -> list[tuple]:
        """``(dispatcher, argument types)`` of the compiled functions that ``factor_csc`` and
        ``solve`` call from Python for a matrix of this CSC pattern, for the first-run
        precompile (:mod:`~drivedyn.solver.precompile`): without this the first run would
        compile them in its own process after the workers."""
        return []


#: the minimum degree of A^T + A with every zero-diagonal column (a constraint's multiplier)
#: moved after the last of its neighbours (:func:`saddle_point_order`)
SADDLE = "MMD_AT_PLUS_A_SADDLE"

#: the column orders ``SparseLU("auto")`` compares: the approximate minimum degree of A's
#: columns, and the minimum degree of A^T A and of A^T + A (SuperLU's), and :data:`SADDLE`
ORDERS = ("COLAMD", "MMD_ATA", "MMD_AT_PLUS_A", SADDLE)


def saddle_point_order(order: np.ndarray, A: sp.csc_matrix) -> np.ndarray:
    """``order`` (the column at each position) with every column whose diagonal is zero
    moved to just after the last of its neighbours (entries of A or A^T) whose diagonal is
    not; such columns without one go to the end, each group in its order in ``order``.

    In the iteration matrix the zero-diagonal columns are the constraints' multipliers. A
    symmetric order (the minimum degree of A^T + A) may reach one before any of its
    coordinates is eliminated: a zero pivot, a row interchange, and the fill of a pivot off
    the order's diagonal (the RWD vehicle's TORSEN matrix: 2.0 million multiply-adds per
    refactorisation). Reached after its coordinates, its pivot is the Schur complement
    ``-G K^-1 G^T`` of its row: there the same order took every pivot on the diagonal, at
    0.72 million against 0.95 million for the minimum degree of A^T A (benchmarks/README.md).
    """
    n = A.shape[0]
    zero = A.diagonal() == 0.0
    S = (abs(A) + abs(A).T).tocsc()
    pos = np.empty(n, np.int64)
    pos[order] = np.arange(n)
    after: dict[int, list[int]] = {}
    tail = []
    for c in order:
        if not zero[c]:
            continue
        nb = S.indices[S.indptr[c]:S.indptr[c + 1]]
        nb = nb[~zero[nb]]
        if nb.size:
            after.setdefault(int(nb[np.argmax(pos[nb])]), []).append(int(c))
        else:
            tail.append(int(c))
    new: list[int] = []
    for c in order:
        if not zero[c]:
            new.append(int(c))
            new += after.get(int(c), [])
    return np.array(new + tail, np.int64)


#: threshold of the partial pivoting (a diagonal pivot is kept while it is at least this
#: share of its column's largest candidate): 0.01, the default of HSL's sparse LU and LDL^T
#: codes (MA48, MA57), which bounds the growth of a column's entries by 100 per step; the
#: Newton iteration computes its residual exactly, so a less accurate solve costs at most an
#: iteration. The 4WD vehicle's factors: 22 000 entries and 0.66 ms at 0.01, 31 300 entries
#: and 1.3 ms at 0.1 (benchmarks/README.md)
PIVOT_THRESHOLD = 0.01

#: threshold of a refactorisation with the last pivots (gp_refactor): a kept pivot is
#: refused, and the matrix factorised afresh with pivot search, only when it falls below this
#: share of its column's largest candidate. A tenth of PIVOT_THRESHOLD: a kept pivot may let
#: a column's entries grow by up to 1000 in a step (KLU's refactorisation tests no pivot but
#: zero; the Newton iteration computes its residual exactly, so a less accurate solve costs
#: at most an iteration). Measured (benchmarks/README.md, the RWD vehicle's TORSEN launch,
#: 3 s): factorisations afresh 276 -> 63 of about 4600 (each four refactorisations' work
#: and a return to Python), Newton iterations 24 082 -> 23 496; the 4WD launch 77 -> 20 of
#: 1930, iterations the same to 0.1 %
REFACTOR_THRESHOLD = 1e-3


class SparseLU(LinearSolver):
    """Sparse LU on the model's fixed pattern: a column order computed once on the first
    matrix (SuperLU's, or :data:`SADDLE` built on one of them), then every factorisation a
    compiled left-looking LU with threshold partial pivoting
    (:func:`~drivedyn.solver.sparse_lu.gp_factor`), or, while the last pivots stay large
    enough, a refactorisation with them
    (:func:`~drivedyn.solver.sparse_lu.gp_refactor`); the triangular solves are compiled too
    (:func:`~drivedyn.solver.sparse_lu.sparse_lu_solve`).

    ``permc_spec``: SuperLU's name of the column order, :data:`SADDLE`, or ``"auto"``: each
    order of :data:`ORDERS` factorised once on the first matrix, the one whose
    refactorisation takes the fewest operations kept (:attr:`order`, :attr:`refactor_ops`),
    and chosen once more at the first refactorisation whose kept pivots are refused: the
    first matrix (a model at rest, its contacts open) need not stand for the run's (the 4WD
    vehicle's first matrix favours the minimum degree of A^T + A by 7 %, its loaded ones
    that of A^T A by a factor of 2). No one order suits every model: COLAMD keeps a chain of
    gears or beam elements banded, while a body that every joint hangs on (the car body of a
    vehicle) makes COLAMD's factors fill the matrix and the minimum-degree orders do not
    (the 4WD vehicle, 383 unknowns: 135 700 entries and 15.4 million operations with COLAMD,
    22 000 and 0.31 million with ``MMD_ATA``; benchmarks/README.md).

    The iteration matrix is a saddle-point matrix (zero multiplier block), so partial pivoting
    is kept on (``diag_pivot_thresh``: the diagonal is taken when it is at least this share
    of the column's largest candidate, :data:`PIVOT_THRESHOLD`) rather than forcing diagonal
    pivots. A refactorisation keeps the pivots so chosen while each stays at least
    ``refactor_thresh`` of its column's largest candidate (default
    :data:`REFACTOR_THRESHOLD`, a tenth of the search's). Not SuperLU for every
    factorisation: its ordering and setup cost 1.45 ms for the
    2200 unknowns of the 200-disk chain whose factors hold 5826 entries
    (benchmarks/README.md); and not its solves, which cost about 16 ns per factor entry
    through scipy.
    """

    def __init__(self, permc_spec: str = "auto",
                 diag_pivot_thresh: float = PIVOT_THRESHOLD,
                 refactor_thresh: float | None = None) -> None:
        known = (*ORDERS, "NATURAL")
        if permc_spec != "auto" and permc_spec not in known:
            raise ValueError(f"permc_spec = {permc_spec!r}: expected 'auto' or one of "
                             f"{', '.join(known)}")
        if not 0.0 <= diag_pivot_thresh <= 1.0:
            raise ValueError(f"diag_pivot_thresh = {diag_pivot_thresh!r}: expected a share "
                             "of the column's largest entry, in [0, 1]")
        if refactor_thresh is None:
            refactor_thresh = min(REFACTOR_THRESHOLD, diag_pivot_thresh)
        if not 0.0 <= refactor_thresh <= diag_pivot_thresh:
            raise ValueError(f"refactor_thresh = {refactor_thresh!r}: expected a share in "
                             f"[0, diag_pivot_thresh = {diag_pivot_thresh!r}] (a kept pivot "
                             "is held to at most the threshold it was chosen by)")
        self.permc_spec = permc_spec
        self.diag_pivot_thresh = diag_pivot_thresh
        #: a refactorisation keeps the last pivots while each is at least this share of its
        #: column's largest candidate (REFACTOR_THRESHOLD)
        self.refactor_thresh = refactor_thresh
        #: the column order in use (a name of ORDERS or "NATURAL"; None before the first
        #: factorisation)
        self.order: str | None = None
        self._chosen_again = False  # "auto": chosen a second time (at most once)
        self._f: tuple | None = None
        self._n = -1
        #: factorisations with pivot search (the others kept the last pivots; the trial
        #: factorisations of the orders ``"auto"`` compares not counted)
        self.fresh = 0

    def factor(self, A: sp.csc_matrix) -> None:
        A = _csc(A)  # duplicates are summed by the factorisation
        self.factor_csc(A.data, A.indices, A.indptr, A.shape[0])

    def _order(self, data: np.ndarray, indices: np.ndarray, indptr: np.ndarray,
               n: int) -> None:
        """The column order: the one asked for, or, with ``"auto"``, the order of
        :data:`ORDERS` whose factors of this first matrix take the fewest multiply-adds to
        refactorise (:attr:`refactor_ops`; ties: the fewest entries, then the first; an
        order SuperLU finds singular is skipped)."""
        specs = ORDERS if self.permc_spec == "auto" else (self.permc_spec,)
        best: tuple[int, int, str] | None = None
        for spec in specs:
            try:
                self._set_order(data, indices, indptr, n, spec)
                if len(specs) > 1:
                    self._factor_fresh(data, indices, indptr, n)
            except np.linalg.LinAlgError:
                if len(specs) == 1:
                    raise
                continue
            if len(specs) == 1:
                return
            cost = (self.refactor_ops, self.fill)
            if best is None or cost < best[:2]:
                best = (*cost, spec)
        if best is None:
            raise np.linalg.LinAlgError("singular matrix")
        self._set_order(data, indices, indptr, n, best[2])

    def _set_order(self, data: np.ndarray, indices: np.ndarray, indptr: np.ndarray, n: int,
                   spec: str) -> None:
        """Column order ``spec`` and work arrays from SuperLU's factorisation of the matrix
        (for :data:`SADDLE`, in the minimum degree of A^T + A)."""
        try:
            import scipy.sparse.linalg as spla

            A = _csc((data.copy(), indices.copy(), indptr.copy()), shape=(n, n))
            A.sum_duplicates()  # a copy: the caller's arrays stay as they are
            lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A" if spec == SADDLE else spec,
                           diag_pivot_thresh=self.diag_pivot_thresh)
        except RuntimeError as exc:  # "Factor is exactly singular"
            raise np.linalg.LinAlgError(str(exc)) from None
        q = np.empty(n, np.int64)
        q[lu.perm_c] = np.arange(n)  # SuperLU's column i goes to position perm_c[i]
        if spec == SADDLE:
            q = saddle_point_order(q, A)  # (the arrays grow if its fill is larger)
        qinv = np.empty(n, np.int64)
        qinv[q] = np.arange(n)
        self.order = spec
        self._f = None
        self._q = q
        self._qinv = qinv
        cap_l, cap_u = 2 * lu.L.nnz + n, 2 * lu.U.nnz + n
        self._Lp, self._Up = np.zeros(n + 1, np.int64), np.zeros(n + 1, np.int64)
        self._Li, self._Lx = np.zeros(cap_l, np.int64), np.zeros(cap_l)
        self._Lio = np.zeros(cap_l, np.int64)
        self._Ui, self._Ux = np.zeros(cap_u, np.int64), np.zeros(cap_u)
        self._Rp, self._Ri = np.zeros(n + 1, np.int64), np.zeros(cap_l + cap_u, np.int64)
        self._pinv, self._prow = np.zeros(n, np.int64), np.zeros(n, np.int64)
        self._cLp, self._cUp = np.zeros(n + 1, np.int64), np.zeros(n + 1, np.int64)
        self._cLi, self._cLx = np.zeros(0, np.int64), np.zeros(0)
        self._cUi, self._cUx = np.zeros(0, np.int64), np.zeros(0)
        self._x, self._xi = np.zeros(n), np.zeros(2 * n, np.int64)
        self._pstack, self._mark = np.zeros(n, np.int64), np.zeros(n, np.int64)
        self._z = np.empty(n)
        self._tail = tail_arrays(n, 0)
        self._tail_chosen = False
        self._n = n

    def factor_csc(self, data: np.ndarray, indices: np.ndarray, indptr: np.ndarray,
                   n: int) -> None:
        if self._n != n:
            self._order(data, indices, indptr, n)
            self._chosen_again = self.permc_spec != "auto"
        # the pivots of the last factorisation while they stay large enough (-1: afresh)
        if self._f is not None and gp_refactor(
                n, indptr, indices, data, self._q, self.refactor_thresh, self._Lp,
                self._Lio, self._Lx, self._Up, self._Ux, self._pinv, self._prow, self._Rp,
                self._Ri, self._x, self._tail) == 0:
            self._compact()
            return
        if self._f is not None and not self._chosen_again:
            # the first matrix's pivots no longer serve: its values (a model at rest,
            # contacts open) did not stand for the run's; the order is chosen once more
            self._chosen_again = True
            self._order(data, indices, indptr, n)
        self._factor_fresh(data, indices, indptr, n)
        if not self._tail_chosen:
            # the dense tail, from the first factors of the order in use
            self._tail_chosen = True
            m = tail_size(self._Lp, self._Up, self._Ui)
            if m:
                self._tail = tail_arrays(n, m)
                self._factor_fresh(data, indices, indptr, n)
        self.fresh += 1
        self._compact()

    def _factor_fresh(self, data: np.ndarray, indices: np.ndarray, indptr: np.ndarray,
                      n: int) -> None:
        """:func:`~drivedyn.solver.sparse_lu.gp_factor` with pivot search (arrays enlarged
        while too short)."""
        while True:
            status, lnz, unz = gp_factor(
                n, indptr, indices, data, self._q, self.diag_pivot_thresh, self._Lp,
                self._Li, self._Lio, self._Lx, self._Up, self._Ui, self._Ux, self._pinv,
                self._prow, self._Rp, self._Ri, self._x, self._xi, self._pstack, self._mark,
                self._tail)
            if status != -2:
                break
            cl, cu = 2 * self._Li.size, 2 * self._Ui.size
            self._Li, self._Lio, self._Lx = (np.zeros(cl, np.int64), np.zeros(cl, np.int64),
                                             np.zeros(cl))
            self._Ui, self._Ux = np.zeros(cu, np.int64), np.zeros(cu)
            self._Ri = np.zeros(cl + cu, np.int64)
        if status != 0:
            self._f = None
            raise np.linalg.LinAlgError("singular matrix")
        self._lnz, self._unz = lnz, unz

    @property
    def fill(self) -> int:
        """Entries of the factors' pattern (L and U, zeros of these values included, and the
        dense tail's block)."""
        return self._lnz + self._unz + self.tail ** 2

    @property
    def refactor_ops(self) -> int:
        """Multiply-adds of a refactorisation with the present pivots
        (:func:`~drivedyn.solver.sparse_lu.gp_refactor`: each off-diagonal entry ``U[J, k]``
        applies column ``J`` of L below its diagonal), which sets its time: 1.3-1.5 ns each
        for the vehicles' factors (measured). Fewer
        entries need not mean fewer operations: the RWD vehicle's factors hold 63 500
        entries with COLAMD and 55 500 with the minimum degree of A^T A, for 1.34 and 1.09
        million operations; those of A^T + A 119 700 entries and 6.4 million. With a dense
        tail (:attr:`tail`), those of the sparse loop only: the tail's block adds its
        ``m^3 / 3`` in LAPACK."""
        # entries of each column of L below its diagonal (a tail column has none)
        below = np.maximum(np.diff(self._Lp) - 1, 0)
        n0 = int(self._tail[4][0])
        return int(below[self._Ui[:self._unz]].sum() - below[:n0].sum())

    @property
    def tail(self) -> int:
        """Columns of the dense tail (:mod:`~drivedyn.solver.sparse_lu`); 0: none."""
        return self._n - int(self._tail[4][0]) if self._n > 0 else 0

    def _compact(self) -> None:
        """``_f``: the factors without exact zeros, for the solves (a chain of 200 gears has
        as many zeros as entries in its pattern's factors, and 5 solves per factorisation)."""
        lnz, unz = self._lnz, self._unz
        if self._cLi.size < lnz or self._cUi.size < unz:
            self._cLi, self._cLx = np.zeros(lnz, np.int64), np.zeros(lnz)
            self._cUi, self._cUx = np.zeros(unz, np.int64), np.zeros(unz)
        compact_factors(self._Lp, self._Li[:lnz], self._Lx[:lnz], self._Up, self._Ui[:unz],
                        self._Ux[:unz], self._cLp, self._cLi, self._cLx, self._cUp, self._cUi,
                        self._cUx)
        # whole arrays (the solves read the columns' ranges): a refactorisation in compiled
        # code (sparse_lu.refactor_in_place) compacts into them in place, with another count
        # of zeros
        self._f = (self._cLp, self._cLi, self._cLx, self._cUp, self._cUi, self._cUx,
                   self._pinv, self._qinv, self._tail)

    def refactor_arrays(self) -> tuple:
        """The arrays of a refactorisation in compiled code
        (:func:`~drivedyn.solver.sparse_lu.refactor_in_place`): ``(q, tol, Lp, Li, Lio, Lx,
        Up, Ui, Ux, prow, Rp, Ri, x)``, valid until the next factorisation with pivot search
        (which may enlarge them)."""
        return (self._q, np.array([self.refactor_thresh]), self._Lp, self._Li, self._Lio,
                self._Lx, self._Up, self._Ui, self._Ux, self._prow, self._Rp, self._Ri, self._x)

    def solve(self, b: np.ndarray) -> np.ndarray:
        x = np.empty_like(b)
        sparse_lu_solve(*self._f, np.ascontiguousarray(b, dtype=float), self._z, x)
        return x

    def compiled_calls(self, indices: np.ndarray, indptr: np.ndarray) -> list[tuple]:
        i, f = np.zeros(1, np.int64), np.zeros(1)
        args = (i, i, f, i, i, f, i, i, tail_arrays(1, 0), f, f, f)  # as _compact keeps them
        return [(sparse_lu_solve, tuple(sparse_lu_solve.typeof_pyval(a) for a in args))]


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
        A = _csc(A)
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

    def compiled_calls(self, indices: np.ndarray, indptr: np.ndarray) -> list[tuple]:
        lu, piv, ib, tr = lapack.workspace(2)  # 2 x 2: a 1 x 1 array would type as 'C'
        x = np.zeros(2)
        ty = lapack.dense_factor_csc.typeof_pyval
        return [(lapack.dense_factor_csc,
                 tuple(ty(a) for a in (x, indices, indptr, lu, piv, ib))),
                (lapack.dense_solve,
                 tuple(lapack.dense_solve.typeof_pyval(a) for a in (lu, piv, x, ib, tr)))]


#: largest system solved by the dense LU: the TORSEN benches (92 and 113 unknowns) run 1.7-1.8x
#: faster with it than with SuperLU (benchmarks/README.md); LAPACK's getrf grows as n^3 and
#: loses to the sparse LU of the long chains (hundreds to thousands of unknowns)
DENSE_MAX = 150
#: above DENSE_MAX, the dense LU still wins when the sparse LU's factors fill more than this
#: share of the dense matrix (the sparse LU's scalar loops then lose to LAPACK by far), up to
#: DENSE_FILL_MAX unknowns; with the column order SparseLU chooses, the 383 unknowns of the
#: 4WD vehicle fill 15 % and refactorise in 0.46 ms against 2.6 ms dense; a banded chain of
#: 330-396 unknowns fills a few % and SuperLU takes 0.5 ms against 1.2-1.9 ms dense; the
#: 2200-unknown chain's factors fill 0.9 % and refactorise in 0.37 ms (measured)
DENSE_FILL = 0.3
DENSE_FILL_MAX = 1500


class AutoLU(LinearSolver):
    """:class:`SparseLU`, or the dense LU for good when the factors of the first
    factorisation fill more than :data:`DENSE_FILL` of the dense matrix. The first
    factorisation decides, once: the model's initial matrix, the same in every run of a
    model. A later factorisation with pivot search (after kept pivots were refused) fills
    according to the values it meets, and the step at which that happens, hence the solver
    of the rest of the run, would follow the round-off of the run; so they do not switch.
    Measured on the flexible TORSEN benches, which switched at such a factorisation (4th to
    29th; fill 38-57 %): with the sparse LU kept, the Type C's flexible washers' sides took
    1.53-1.57 and 1.90-1.95 s against 1.87-1.97 and 2.17 s dense, the Type B's 1.22 and
    1.09-1.12 s against 1.25 and 1.21-1.22 s, TDRs within 5e-6."""

    def __init__(self) -> None:
        self.sparse: SparseLU | None = SparseLU()
        self.dense: DenseLU | None = None
        self._decided = False

    @property
    def active(self) -> LinearSolver:
        return self.dense if self.dense is not None else self.sparse

    def factor(self, A: sp.csc_matrix) -> None:
        A = _csc(A)
        self.factor_csc(A.data, A.indices, A.indptr, A.shape[0])

    def factor_csc(self, data: np.ndarray, indices: np.ndarray, indptr: np.ndarray,
                   n: int) -> None:
        if self.dense is not None:
            self.dense.factor_csc(data, indices, indptr, n)
            return
        self.sparse.factor_csc(data, indices, indptr, n)
        if self._decided:
            return
        self._decided = True
        fill = self.sparse.fill
        if n <= DENSE_FILL_MAX and fill > DENSE_FILL * n * n:
            self.dense = DenseLU()
            self.sparse = None
            self.dense.factor_csc(data, indices, indptr, n)

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self.active.solve(b)

    def compiled_calls(self, indices: np.ndarray, indptr: np.ndarray) -> list[tuple]:
        # sparse first; dense for good if the first factors fill the matrix
        return (SparseLU().compiled_calls(indices, indptr)
                + DenseLU().compiled_calls(indices, indptr))


def default_linear_solver(neq: int) -> LinearSolver:
    """Dense LU up to :data:`DENSE_MAX` unknowns, :class:`AutoLU` above."""
    return DenseLU() if neq <= DENSE_MAX else AutoLU()
