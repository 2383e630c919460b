"""Redundant constraint rows: found from the constraint Jacobian, and set aside in the solve.

A closed loop of revolute joints modelled as any planar mechanism is (every joint a
:class:`~drivedyn.elements.Hinge`) has more constraint rows than independent ones: a planar
four-bar of four hinges has 20 rows for 18 coordinates and one degree of freedom, so 3 rows
are combinations of the others. The iteration matrix ``[M', G^T; G, 0]`` is then singular
(the multipliers of the dependent rows are not determined), and a run cannot start.

:func:`dependent_rows` finds the dependent rows by a rank-revealing QR factorisation (column
pivoting) of the constraint Jacobian ``G`` (rows ``nd..neq`` of the assembled matrix,
dof columns), one group of rows that share no dof at a time (a block of a block-diagonal
matrix factorises alone), scaled so that the decision does not depend on the model's
units or size:
rotation columns are divided by the model's characteristic length (they hold lever arms
[m] where translation columns hold numbers), and every row is normalised. A row whose
independent part is below :data:`RANK_TOL` of the largest is dependent.

A dependent row ``i`` is set aside (:func:`set_aside`): its multiplier is held at zero (the
row of the iteration matrix becomes ``k_i`` on the diagonal, its residual zero). The motion
is unchanged, because the remaining rows define the same configurations where the rank is
constant; the reactions of the joints concerned are *not unique*: what the results report
for them is one solution of the equilibrium, the one where the set-aside rows carry nothing.
Only bilateral rows (joints, drivers, flexible interfaces) are candidates; the rows of
unilateral contacts choose their own state.

:class:`Redundancy` holds the rows set aside for a :class:`~drivedyn.solver.system.System`
and the arrays the compiled loop uses. Rows are found when a run or an analysis starts, and
again when a factorisation is singular during a run (a configuration where the rank drops).
A row set aside keeps being watched through its own violation: implied by the others, it
stays at their level; when it exceeds :data:`RESTORE_FACTOR` x ``Newton.phi_tol`` after
an accepted step (the row was dependent only near a configuration), the compiled loop
returns to Python, the rows are found again and the independent ones given back (if none
is, the limit doubles: the rows stay aside).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
from numba import njit

log = logging.getLogger("drivedyn")

# Relative size of the smallest independent part of a constraint row (the diagonal of the
# pivoted QR factor of the scaled Jacobian against its largest): below it a row is a
# combination of the others. Exact redundancy (a planar loop of hinges) leaves 1e-16-1e-14
# there; a row independent only at 1e-8 would give multipliers amplified 1e8 times, no
# physical reaction. Between the two any value separates the cases; sqrt(eps) is used.
RANK_TOL = float(np.sqrt(np.finfo(float).eps))


# A row set aside is implied by the others, each held to Newton.phi_tol: its own violation
# stays within a few times that (the rows are normalised combinations); a hundred times
# means it is no longer implied
RESTORE_FACTOR = 100.0


def characteristic_length(x: np.ndarray) -> float:
    """Size [m] of a model from its node positions ``x`` (nn, 3) (the ground row excluded
    by the caller): the largest distance of a node from their centroid; 1 m for a model of
    one point."""
    if x.shape[0] < 2:
        return 1.0
    d = float(np.sqrt(((x - x.mean(axis=0)) ** 2).sum(axis=1)).max())
    return d if d > 0.0 else 1.0


def jacobian(data: np.ndarray, indices: np.ndarray, indptr: np.ndarray,
             nd: int) -> np.ndarray:
    """Dense constraint Jacobian (nm, nd) from the CSC arrays of an assembled matrix
    (rows ``nd..``, dof columns ``..nd``)."""
    neq = indptr.shape[0] - 1
    G = np.zeros((neq - nd, nd))
    cols = np.repeat(np.arange(neq), np.diff(indptr))
    sel = (cols < nd) & (indices >= nd)
    np.add.at(G, (indices[sel] - nd, cols[sel]), data[sel])
    return G


def dependent_rows(G: np.ndarray, candidates: np.ndarray, length: float,
                   tol: float = RANK_TOL) -> np.ndarray:
    """Rows of ``G`` (nm, nd) among ``candidates`` (bool, nm) that are combinations of the
    other candidate rows, as indices into ``G`` (sorted). ``length`` [m] scales the rotation
    columns (dofs ``6 i + 3..5``); each row is normalised; a row of zeros is dependent.

    Rows of the pivoted QR factorisation of the scaled ``G^T`` come in the order of their
    independent parts; those after the numerical rank are dependent."""
    idx = np.flatnonzero(candidates)
    if idx.size == 0:
        return idx
    A = G[idx].copy()
    nd = A.shape[1]
    rot = (np.arange(nd) % 6) >= 3
    A[:, rot] /= length
    norms = np.sqrt((A * A).sum(axis=1))
    zero = norms <= 0.0
    A[~zero] /= norms[~zero, None]
    live = np.flatnonzero(~zero)
    dep = list(idx[zero])
    if live.size:
        from scipy.linalg.lapack import dgeqp3  # here: SciPy off every run's start

        # the rows fall into groups that share no dof (connected parts of the mechanism's
        # constraints); the pivoted QR of a block-diagonal matrix is that of each block, so
        # each group is factorised alone and its independent parts compared with the
        # largest of all (the shaft chain's 200 hinges to the ground: 1000 rows in groups
        # of one, 0.074 -> 0.016 s per search). A (normalised) row alone is independent.
        blocks = []
        for rows in _row_groups(A[live] != 0.0):
            if rows.size == 1:
                blocks.append((rows, np.ones(1), np.zeros(1, np.int64)))
                continue
            sub = A[live[rows]]
            cols = np.flatnonzero((sub != 0.0).any(axis=0))
            Rf, jpvt, _tau, _work, _info = dgeqp3(sub[:, cols].T)
            k = min(Rf.shape)
            blocks.append((rows, np.abs(np.diagonal(Rf)[:k]), jpvt - 1))
        d0 = max(float(d[0]) for _, d, _ in blocks)
        for rows, d, piv in blocks:
            rank = int((d > tol * d0).sum())
            dep += list(idx[live[rows[piv[rank:]]]])
    return np.array(sorted(int(i) for i in dep), np.int64)


def _row_groups(nz: np.ndarray) -> list[np.ndarray]:
    """The rows of the pattern ``nz`` (bool, rows x columns) in groups connected through
    shared columns (each sorted), from the connected components of the bipartite graph."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components

    nr = nz.shape[0]
    B = sp.csr_matrix(nz)
    graph = sp.bmat([[None, B], [B.T, None]], format="csr")
    _n, label = connected_components(graph, directed=False)
    row_label = label[:nr]
    order = np.argsort(row_label, kind="stable")
    cuts = np.flatnonzero(np.diff(row_label[order])) + 1
    return np.split(order, cuts)


@njit(cache=True)
def watched(red):
    """True if a row set aside in ``red`` (the arrays of :class:`Redundancy`) is violated
    beyond its watch limit at the last evaluation: it may no longer be implied by the
    others."""
    viol, watch = red[5], red[6]
    for k in range(viol.shape[0]):
        if viol[k] > watch[0]:
            return True
    return False


@njit(cache=True)
def hold_multipliers(lam, rows, nd):
    """Zero the multipliers of the rows set aside (equation indices ``rows``) before an
    evaluation: the elements then see no reaction on them."""
    for k in range(rows.shape[0]):
        lam[rows[k] - nd] = 0.0


@njit(cache=True)
def set_aside(r, rabs, data, want, rows, diag, rptr, rpos, dscale, viol):
    """After an evaluation: the equations ``rows`` become ``dscale_k lam_k = 0`` (residual
    zero, as its multiplier is held at zero; if ``want`` the matrix row is zero but for
    ``dscale_k`` on the diagonal). ``rpos[rptr[k]:rptr[k + 1]]`` are the CSC positions of
    row ``rows[k]``, ``diag[k]`` that of its diagonal entry. ``viol[k]`` receives the
    row's own violation ``|r_i| / dscale_k`` (|Phi_i| [m or rad] in the dynamics): a row
    implied by the others keeps it at their level."""
    for k in range(rows.shape[0]):
        i = rows[k]
        viol[k] = abs(r[i]) / dscale[k]
        r[i] = 0.0
        rabs[i] = 0.0
        if want:
            for p in range(rptr[k], rptr[k + 1]):
                data[rpos[p]] = 0.0
            data[diag[k]] = dscale[k]


@dataclass
class Redundancy:
    """The constraint rows a system sets aside, and the arrays of the compiled loop.

    Attributes:
        rows: (n,) equation indices set aside (int64, sorted).
        at_start: the rows found when the run or analysis started.
        events: what changed during a run: ``(t [s], "dropped" or "restored", labels)``.
        arrays: ``(rows, diag, rptr, rpos, dscale, viol, watch)``: those of
            :func:`set_aside`, and the violation [m or rad] of a row set aside above which
            the compiled loop returns to have the rows found again (``watch[0]``).
        watch_limit: the first value of ``watch`` [m or rad] (RESTORE_FACTOR x the run's
            ``Newton.phi_tol``).
    """

    indices: np.ndarray
    indptr: np.ndarray
    nd: int
    kscale: np.ndarray
    labels: list[str]
    candidates: np.ndarray
    rows: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    at_start: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    events: list[tuple[float, str, list[str]]] = field(default_factory=list)
    arrays: tuple = ()
    watch_limit: float = RESTORE_FACTOR * 1e-10

    def __post_init__(self) -> None:
        neq = self.indptr.shape[0] - 1
        self._rowof = self.indices.astype(np.int64)
        self._colof = np.repeat(np.arange(neq, dtype=np.int64), np.diff(self.indptr))
        self.set_rows(self.rows)

    def set_rows(self, rows: np.ndarray) -> None:
        """Set aside exactly ``rows`` (equation indices)."""
        rows = np.asarray(sorted(int(i) for i in rows), np.int64)
        self.rows = rows
        pos = [np.flatnonzero(self._rowof == i) for i in rows]
        diag = np.array([p[self._colof[p] == i][0] for p, i in zip(pos, rows, strict=True)],
                        np.int64)
        rptr = np.concatenate([[0], np.cumsum([p.size for p in pos])]).astype(np.int64)
        rpos = np.concatenate(pos).astype(np.int64) if pos else np.zeros(0, np.int64)
        self.arrays = (rows, diag, rptr, rpos, self.kscale[rows].astype(float),
                       np.zeros(rows.size), np.array([self.watch_limit]))

    @property
    def violation(self) -> float:
        """Largest violation [m or rad] of the rows set aside at the last evaluation in
        which they were set aside (0 for none)."""
        v = self.arrays[5]
        return float(v.max()) if v.size else 0.0

    def describe(self, rows: np.ndarray | None = None) -> list[str]:
        """Labels of ``rows`` (default: the rows set aside)."""
        rows = self.rows if rows is None else rows
        return [self.labels[int(i)] for i in rows]

    def found(self, G: np.ndarray, x: np.ndarray) -> np.ndarray:
        """Equation indices of the dependent rows of the Jacobian ``G`` (nm, nd) at node
        positions ``x`` (nn, 3)."""
        return self.nd + dependent_rows(G, self.candidates, characteristic_length(x))

    def attrs(self) -> dict[str, str]:
        """Results attributes: the rows set aside at the start and what changed after."""
        out = {}
        if self.at_start.size:
            out["redundant_constraints"] = "; ".join(self.describe(self.at_start))
        if self.events:
            out["redundant_constraints_changes"] = "; ".join(
                f"t = {t:.9g} s {what} {', '.join(lab)}" for t, what, lab in self.events)
        if out:
            out["redundant_constraints_note"] = (
                "rows set aside as combinations of the others: the motion is that of the "
                "full set, but the reactions of these joints are not unique (reported: the "
                "solution with zero multipliers on the rows set aside)")
        return out


def report_start(red: Redundancy) -> None:
    """Log the rows set aside when a run or analysis starts."""
    if red.at_start.size:
        log.warning("%d redundant constraint row(s) set aside (combinations of the other "
                    "rows; the motion is unchanged, these joints' reactions are not "
                    "unique): %s", red.at_start.size, ", ".join(red.describe(red.at_start)))
