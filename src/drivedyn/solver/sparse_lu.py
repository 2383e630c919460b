"""The compiled sparse LU of the iteration matrix: a left-looking LU with threshold partial
pivoting (Gilbert and Peierls), its refactorisation with the last pivots (KLU's refactor),
the copy of the factors without their exact zeros, and the triangular solves. The
:class:`~drivedyn.solver.linear.SparseLU` solver drives them from Python; the compiled
Newton iteration (:mod:`~drivedyn.solver.newton_kernel`) solves and refactorises with them
without returning to Python (:func:`refactor_in_place`).

The last columns of the order may be factorised as one dense block (the *tail*): the
columns ``k >= n0`` are reduced by the sparse columns only, which leaves the Schur
complement ``S = A22 - L21 U12`` of the rows not yet pivotal, and ``S`` is factorised by
LAPACK (``dgetrf``, its own partial pivoting). The fill of a vehicle's factors gathers in
its last columns (the RWD vehicle: the last 150 of 855 columns hold 45 % of the
refactorisation's multiply-adds, their block is 79 % full), where the left-looking loop
runs at its sparse speed and LAPACK's blocked kernels four to seven times faster
(:func:`tail_size`). ``tail = (S, ipiv, ib, tr, n0)``: the block (m, m, column-major, m =
n - n0), LAPACK's pivots, its integer scratch and the character ``'N'``
(:func:`~drivedyn.solver.lapack.workspace`), and ``n0`` (1,); ``m = 0``: no tail.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from drivedyn.solver.lapack import dense_factor, dense_solve, workspace

# The compiled sparse LU's loops index with unsigned integers (``np.uint64``): numba wraps a
# negative signed index around, a branch per access that also keeps LLVM from vectorising a
# loop. The arithmetic is the same, in the same order. The RWD vehicle's matrix (799
# unknowns, 0.68 million multiply-adds): refactorisation 1.50-2.00 ms signed, 0.86-1.02 ms
# unsigned; solve 80-101 us against 48-56 us (benchmarks/README.md, compiled_step_costs.py).
U1 = np.uint64(1)


def tail_arrays(n: int, m: int) -> tuple:
    """``tail`` for a dense block of the last ``m`` of ``n`` columns (``m = 0``: none; its
    block is then a 2 x 2 stand-in, never used: a smaller array is C- as well as
    F-contiguous, and numba would type it as C and compile another overload)."""
    S, ipiv, ib, tr = workspace(m if m >= 2 else 2)
    return S, ipiv, ib, tr, np.array([n - m], np.int64)


@njit(cache=True)
def sparse_lu_solve(Lp, Li, Lx, Up, Ui, Ux, perm_r, perm_c, tail, b, z, x):
    """Solve ``A x = b`` with the factors ``Pr A Pc = L U`` (CSC, L unit lower triangular
    with its diagonal first in each column, U with its diagonal last), the columns from
    ``n0`` on as the dense ``tail`` (module docstring: there L has no columns and U only the
    rows above ``n0``)."""
    n = b.shape[0]
    S, ipiv, ib, tr, n0a = tail
    n0 = n0a[0]
    for i in range(n):
        z[np.uint64(perm_r[i])] = b[i]
    for j in range(n0):  # forward, unit diagonal (first entry of column j)
        zj = z[np.uint64(j)]
        if zj != 0.0:
            for k in range(np.uint64(Lp[j]), np.uint64(Lp[j + 1])):
                i = Li[k]
                if i > j:
                    z[np.uint64(i)] -= Lx[k] * zj
    if n0 < n:  # the Schur complement's block: z[n0:] <- S^-1 z[n0:]
        dense_solve(S, ipiv, z[n0:], ib, tr)
    for jj in range(n - n0):  # the tail's columns of U: rows above n0 only
        j = np.uint64(n - 1 - jj)
        zj = z[j]
        if zj != 0.0:
            for k in range(np.uint64(Up[j]), np.uint64(Up[j + U1])):
                z[np.uint64(Ui[k])] -= Ux[k] * zj
    for jj in range(n - n0, n):  # backward, diagonal is the last entry of column j
        j = np.uint64(n - 1 - jj)
        kd = np.uint64(Up[j + U1]) - U1
        zj = z[j] / Ux[kd]
        z[j] = zj
        if zj != 0.0:
            for k in range(np.uint64(Up[j]), kd):
                z[np.uint64(Ui[k])] -= Ux[k] * zj
    for i in range(n):
        x[i] = z[np.uint64(perm_c[i])]


@njit(cache=True)
def _reach(j, Lp, Li, pinv, top, xi, pstack, mark, stamp):
    """Depth-first search from row ``j`` through the columns of L computed so far (row
    ``i`` is column ``pinv[i]`` of L once it is pivotal); the rows reached are pushed onto
    ``xi[top:]`` in topological order; returns the new ``top`` (CSparse ``cs_dfs``)."""
    head = 0
    xi[0] = j
    while head >= 0:
        j = xi[head]
        jnew = pinv[j]
        if mark[j] != stamp:
            mark[j] = stamp
            pstack[head] = 0 if jnew < 0 else Lp[jnew]
        done = True
        p2 = 0 if jnew < 0 else Lp[jnew + 1]
        for p in range(pstack[head], p2):
            i = Li[p]
            if mark[i] == stamp:
                continue
            pstack[head] = p
            head += 1
            xi[head] = i
            done = False
            break
        if done:
            head -= 1
            top -= 1
            xi[top] = j
    return top


@njit(cache=True)
def gp_factor(n, Ap, Ai, Ax, q, tol, Lp, Li, Lio, Lx, Up, Ui, Ux, pinv, prow, Rp, Ri, x, xi,
              pstack, mark, tail):
    """Left-looking sparse LU with threshold partial pivoting (Gilbert and Peierls; the
    algorithm of CSparse's ``cs_lu``): ``P A Q = L U`` for the CSC matrix ``(Ap, Ai, Ax)``
    with the column order ``q`` (``Q[:, k] = e_q[k]``). Each column is a sparse triangular
    solve on the columns of L computed so far; the pivot is the diagonal entry if it is at
    least ``tol`` times the largest candidate, else the largest.

    Output in the format :func:`sparse_lu_solve` takes: L unit lower triangular with its
    diagonal first in each column, U with its diagonal last, rows in pivot order;
    ``pinv[i]`` the pivot step of row ``i``. For :func:`gp_refactor`: ``Lio`` the rows of L
    in the original order, ``prow[k]`` the pivot row of step ``k``, ``Rp, Ri`` each column's
    reach in topological order. Work arrays ``x`` (n, zero on entry and exit), ``xi`` (2n),
    ``pstack`` (n), ``mark`` (n). The columns from ``n0`` on are reduced by the sparse ones
    only, and their rows not pivotal by then (numbered ``n0, n0 + 1, ...`` in their order)
    form the Schur complement in ``tail``, factorised by LAPACK (module docstring). Returns
    ``(status, nnz(L), nnz(U))``: status 0, -1 (singular or non-finite), -2 (L, U or reach
    arrays too short: enlarge, call again)."""
    S, tpiv, ib = tail[0], tail[1], tail[2]
    n0 = tail[4][0]
    lnz = 0
    unz = 0
    rnz = 0
    Lp[0] = 0
    Up[0] = 0
    Rp[0] = 0
    for i in range(n):
        pinv[i] = -1
        mark[i] = -1
    for k in range(n):
        col = q[k]
        if k == n0:  # the rows left for the tail, in their order (pinv -1 until the end)
            t = 0
            for i in range(n):
                if pinv[i] < 0:
                    prow[n0 + t] = i
                    t += 1
        top = n
        for p in range(Ap[col], Ap[col + 1]):
            i = Ai[p]
            if mark[i] != k:
                top = _reach(i, Lp, Lio, pinv, top, xi, pstack, mark, k)
        if (lnz + n - top + 1 > Li.shape[0] or unz + n - top + 1 > Ui.shape[0]
                or rnz + n - top > Ri.shape[0]):
            for px in range(top, n):
                x[xi[px]] = 0.0
            return -2, lnz, unz
        for p in range(Ap[col], Ap[col + 1]):
            x[Ai[p]] += Ax[p]
        for px in range(top, n):  # x = L \ A[:, col] on the reach, in topological order
            j = np.uint64(xi[px])
            J = pinv[j]
            if J < 0:
                continue
            xj = x[j]
            uJ = np.uint64(J)
            for p in range(np.uint64(Lp[uJ]) + U1, np.uint64(Lp[uJ + U1])):
                x[np.uint64(Lio[p])] -= Lx[p] * xj
        if k >= n0:  # a tail column: U above n0 (the Schur complement: _tail_factor)
            for px in range(top, n):
                i = xi[px]
                if pinv[i] >= 0:
                    Ui[unz] = pinv[i]
                    Ux[unz] = x[i]
                    unz += 1
                x[i] = 0.0
                Ri[rnz] = i
                rnz += 1
            Up[k + 1] = unz
            Lp[k + 1] = lnz
            Rp[k + 1] = rnz
            continue
        ipiv = -1
        amax = -1.0
        for px in range(top, n):
            i = xi[px]
            if pinv[i] < 0:
                t = abs(x[i])
                if t > amax:
                    amax = t
                    ipiv = i
            else:
                Ui[unz] = pinv[i]
                Ux[unz] = x[i]
                unz += 1
        if ipiv < 0 or not (amax > 0.0) or not np.isfinite(amax):
            for px in range(top, n):
                x[xi[px]] = 0.0
            return -1, lnz, unz
        if pinv[col] < 0 and abs(x[col]) >= amax * tol:
            ipiv = col  # the diagonal when it is large enough (keeps the fill of the order)
        pivot = x[ipiv]
        Ui[unz] = k
        Ux[unz] = pivot
        unz += 1
        Up[k + 1] = unz
        pinv[ipiv] = k
        prow[k] = ipiv
        Lio[lnz] = ipiv
        Lx[lnz] = 1.0
        lnz += 1
        for px in range(top, n):
            i = xi[px]
            if pinv[i] < 0:
                Lio[lnz] = i
                Lx[lnz] = x[i] / pivot
                lnz += 1
            x[i] = 0.0
            Ri[rnz] = i
            rnz += 1
        Lp[k + 1] = lnz
        Rp[k + 1] = rnz
    for t in range(n - n0):
        pinv[prow[n0 + t]] = n0 + t
    for p in range(lnz):
        Li[p] = pinv[Lio[p]]
    if n0 < n and _tail_factor(n, n0, q, Ap, Ai, Ax, Lp, Lio, Lx, Up, Ux, pinv, Rp, Ri, x, S,
                               tpiv, ib) != 0:
        return -1, lnz, unz
    return 0, lnz, unz


@njit(cache=True, inline="always")
def _reduce_column(col, Ap, Ai, Ax, r_lo, r_hi, Ri, pinv, stop, Lp, Lio, Lx, x):
    """Column ``col`` of A scattered into ``x`` and reduced by the columns of L before
    ``stop`` on its reach ``Ri[r_lo:r_hi]`` (topological order): the left-looking update
    of :func:`gp_refactor` (``stop`` = the column's own step) and of :func:`_tail_factor`
    (``stop`` = n0)."""
    for p in range(np.uint64(Ap[col]), np.uint64(Ap[col + U1])):
        x[np.uint64(Ai[p])] += Ax[p]
    for r in range(r_lo, r_hi):
        j = np.uint64(Ri[r])
        J = pinv[j]
        if J >= stop:
            continue
        xj = x[j]
        uJ = np.uint64(J)
        for p in range(np.uint64(Lp[uJ]) + U1, np.uint64(Lp[uJ + U1])):
            x[np.uint64(Lio[p])] -= Lx[p] * xj


@njit(cache=True)
def _tail_factor(n, n0, q, Ap, Ai, Ax, Lp, Lio, Lx, Up, Ux, pinv, Rp, Ri, x, S, ipiv, ib):
    """The tail's columns (``k >= n0``): each column of A reduced by the sparse columns on
    its reach ``Ri``, its rows above ``n0`` into U (in the reach's order, as
    :func:`gp_factor` stores them) and the others, the Schur complement, into ``S``; then
    the LU of ``S`` by LAPACK. Returns 0 or -1 (singular or not finite). ``x`` (n) zero on
    entry and exit."""
    S[:, :] = 0.0
    for k in range(n0, n):
        r_lo, r_hi = np.uint64(Rp[k]), np.uint64(Rp[k + 1])
        _reduce_column(np.uint64(q[k]), Ap, Ai, Ax, r_lo, r_hi, Ri, pinv, n0, Lp, Lio, Lx, x)
        u = np.uint64(Up[k])
        for r in range(r_lo, r_hi):
            i = np.uint64(Ri[r])
            if pinv[i] >= n0:
                S[pinv[i] - n0, k - n0] = x[i]
            else:
                Ux[u] = x[i]
                u += U1
            x[i] = 0.0
    return dense_factor(S, ipiv, ib)


@njit(cache=True)
def gp_refactor(n, Ap, Ai, Ax, q, tol, Lp, Lio, Lx, Up, Ux, pinv, prow, Rp, Ri, x, tail):
    """:func:`gp_factor` again for new values on the same pattern, with the pivots and the
    reaches of the last full factorisation (no search, no pivot choice: KLU's refactor).
    The same arithmetic in the same order, so the factors are those :func:`gp_factor` gives
    when it picks the same pivots (the tail's block is factorised afresh, with LAPACK's own
    pivots). Returns -1 (and leaves ``x`` zero) when a kept pivot is below ``tol`` times its
    column's largest candidate, or not finite, or the tail's block is singular: factorise
    afresh."""
    n0 = tail[4][0]
    for k in range(n0):
        r_lo, r_hi = np.uint64(Rp[k]), np.uint64(Rp[k + 1])
        _reduce_column(np.uint64(q[k]), Ap, Ai, Ax, r_lo, r_hi, Ri, pinv, k, Lp, Lio, Lx, x)
        u = np.uint64(Up[k])
        amax = 0.0
        for r in range(r_lo, r_hi):
            i = np.uint64(Ri[r])
            if pinv[i] < k:
                Ux[u] = x[i]
                u += U1
            elif abs(x[i]) > amax:
                amax = abs(x[i])
        pivot = x[np.uint64(prow[k])]
        if not (abs(pivot) >= tol * amax and abs(pivot) > 0.0 and np.isfinite(amax)):
            for r in range(r_lo, r_hi):
                x[np.uint64(Ri[r])] = 0.0
            return -1
        Ux[u] = pivot
        lo = np.uint64(Lp[k]) + U1
        for r in range(r_lo, r_hi):
            i = np.uint64(Ri[r])
            if pinv[i] > k:
                Lx[lo] = x[i] / pivot
                lo += U1
            x[i] = 0.0
    if n0 < n:
        return _tail_factor(n, n0, q, Ap, Ai, Ax, Lp, Lio, Lx, Up, Ux, pinv, Rp, Ri, x,
                            tail[0], tail[1], tail[2])
    return 0


@njit(cache=True)
def compact_factors(Lp, Li, Lx, Up, Ui, Ux, cLp, cLi, cLx, cUp, cUi, cUx):
    """Copy the factors without their exact zeros (entries of the fixed pattern that are zero
    for these values: the solves skip them; the diagonals are never zero); returns
    ``(nnz(L), nnz(U))`` of the copies."""
    n = Lp.shape[0] - 1
    lz = np.uint64(0)
    uz = np.uint64(0)
    cLp[0] = 0
    cUp[0] = 0
    for j in range(n):
        for p in range(np.uint64(Lp[j]), np.uint64(Lp[j + 1])):
            if Lx[p] != 0.0:
                cLi[lz] = Li[p]
                cLx[lz] = Lx[p]
                lz += U1
        cLp[j + 1] = lz
        last = np.uint64(Up[j + 1]) - U1
        for p in range(np.uint64(Up[j]), last + U1):
            if Ux[p] != 0.0 or p == last:
                cUi[uz] = Ui[p]
                cUx[uz] = Ux[p]
                uz += U1
        cUp[j + 1] = uz
    return int(lz), int(uz)


@njit(cache=True)
def refactor_in_place(data, indices, indptr, sparse):
    """The factorisation of the CSC matrix ``(data, indices, indptr)`` with the pivots of the
    last one, in compiled code (the Newton iteration of
    :mod:`~drivedyn.solver.newton_kernel`, without a return to Python): :func:`gp_refactor`
    and :func:`compact_factors` into the solve's arrays, as
    :meth:`~drivedyn.solver.linear.SparseLU.factor_csc` does. ``sparse`` is the compiled
    step's tuple ``(*SparseLU._f, z, refactor)`` (``_f`` ends with the ``tail``) with ``refactor`` =
    :meth:`~drivedyn.solver.linear.SparseLU.refactor_arrays`. Returns 0, or -1 when a kept
    pivot is refused (the caller factorises afresh, in Python)."""
    cLp, cLi, cLx, cUp, cUi, cUx, pinv, _qinv, tail, _z, rf = sparse
    q, tol, Lp, Li, Lio, Lx, Up, Ui, Ux, prow, Rp, Ri, x = rf
    n = Lp.shape[0] - 1
    if gp_refactor(n, indptr, indices, data, q, tol[0], Lp, Lio, Lx, Up, Ux, pinv, prow, Rp,
                   Ri, x, tail) != 0:
        return -1
    compact_factors(Lp, Li, Lx, Up, Ui, Ux, cLp, cLi, cLx, cUp, cUi, cUx)
    return 0


# The cost of LAPACK's dgetrf per multiply-add, in units of the sparse refactorisation's
# (gp_refactor, 0.58 ns each on the RWD vehicle's factors): 0.09 + DENSE_SMALL / m^2 for an
# m x m block, from dgetrf's measured 0.49, 0.21, 0.13, 0.095, 0.076 ns per multiply-add at
# m = 32, 64, 100, 150, 200 (one OpenBLAS thread). Operation counts, not timings, choose the
# tail, so every machine factorises the same way.
DENSE_RATIO = 0.09
DENSE_SMALL = 1000.0
# a tail is taken when it saves at least this share of the estimated refactorisation time;
# of TAIL_MIN columns at least and at most TAIL_MAX_SHARE of them (a matrix whose factors are
# dense throughout is the dense LU's, solver.linear.AutoLU; the sparse LU keeps its own
# pivots, which a refactorisation checks, for most of its columns)
TAIL_MIN_GAIN = 0.05
TAIL_MIN = 32
TAIL_MAX_SHARE = 0.5


def tail_size(Lp: np.ndarray, Up: np.ndarray, Ui: np.ndarray) -> int:
    """Columns ``m`` of the dense tail for factors of this pattern (:func:`gp_factor` without
    a tail: ``Lp``, ``Up`` (n + 1,), ``Ui`` the rows of U in pivot order, the diagonal last in
    each column), or 0: the ``m`` whose estimated refactorisation time is least, the
    multiply-adds kept in the sparse loop (each off-diagonal ``U[J, k]`` with ``J < n - m``
    applies column ``J`` of L) plus the dense block's ``m^3 / 3`` at LAPACK's cost
    (:data:`DENSE_RATIO`, :data:`DENSE_SMALL`), between :data:`TAIL_MIN` and
    :data:`TAIL_MAX_SHARE` of the columns; 0 when that saves less than
    :data:`TAIL_MIN_GAIN`."""
    n = Lp.shape[0] - 1
    m_max = int(TAIL_MAX_SHARE * n)
    if m_max < TAIL_MIN:
        return 0
    below = np.diff(Lp) - 1
    cols = np.repeat(np.arange(n), np.diff(Up))
    rows = Ui[:Up[-1]]
    off = rows != cols
    w = np.bincount(rows[off], weights=below[rows[off]], minlength=n)
    kept = np.concatenate(([0.0], np.cumsum(w)))  # kept[n0]: ops with J < n0
    full = kept[n]
    m = np.arange(TAIL_MIN, m_max + 1)
    cost = kept[n - m] + m.astype(float) ** 3 / 3.0 * (DENSE_RATIO + DENSE_SMALL / m ** 2)
    best = int(np.argmin(cost))
    if cost[best] > (1.0 - TAIL_MIN_GAIN) * full:
        return 0
    return int(m[best])
