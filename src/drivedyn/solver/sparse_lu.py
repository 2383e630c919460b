"""The compiled sparse LU of the iteration matrix: a left-looking LU with threshold partial
pivoting (Gilbert and Peierls), its refactorisation with the last pivots (KLU's refactor),
the copy of the factors without their exact zeros, and the triangular solves. The
:class:`~drivedyn.solver.linear.SparseLU` solver drives them from Python; the compiled
Newton iteration (:mod:`~drivedyn.solver.newton_kernel`) solves and refactorises with them
without returning to Python (:func:`refactor_in_place`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

# The compiled sparse LU's loops index with unsigned integers (``np.uint64``): numba wraps a
# negative signed index around, a branch per access that also keeps LLVM from vectorising a
# loop. The arithmetic is the same, in the same order. The RWD vehicle's matrix (799
# unknowns, 0.68 million multiply-adds): refactorisation 1.50-2.00 ms signed, 0.86-1.02 ms
# unsigned; solve 80-101 us against 48-56 us (benchmarks/README.md, compiled_step_costs.py).
U1 = np.uint64(1)


@njit(cache=True)
def sparse_lu_solve(Lp, Li, Lx, Up, Ui, Ux, perm_r, perm_c, b, z, x):
    """Solve ``A x = b`` with SuperLU's factors ``Pr A Pc = L U`` (CSC, sorted indices,
    L unit lower triangular with its diagonal stored)."""
    n = b.shape[0]
    for i in range(n):
        z[np.uint64(perm_r[i])] = b[i]
    for j in range(n):  # forward, unit diagonal (first entry of column j)
        zj = z[np.uint64(j)]
        if zj != 0.0:
            for k in range(np.uint64(Lp[j]), np.uint64(Lp[j + 1])):
                i = Li[k]
                if i > j:
                    z[np.uint64(i)] -= Lx[k] * zj
    for jj in range(n):  # backward, diagonal is the last entry of column j
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
              pstack, mark):
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
    ``pstack`` (n), ``mark`` (n). Returns ``(status, nnz(L), nnz(U))``: status 0, -1
    (singular or non-finite), -2 (L, U or reach arrays too short: enlarge, call again)."""
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
    for p in range(lnz):
        Li[p] = pinv[Lio[p]]
    return 0, lnz, unz


@njit(cache=True)
def gp_refactor(n, Ap, Ai, Ax, q, tol, Lp, Lio, Lx, Up, Ux, pinv, prow, Rp, Ri, x):
    """:func:`gp_factor` again for new values on the same pattern, with the pivots and the
    reaches of the last full factorisation (no search, no pivot choice: KLU's refactor).
    The same arithmetic in the same order, so the factors are those :func:`gp_factor` gives
    when it picks the same pivots. Returns -1 (and leaves ``x`` zero) when a kept pivot is
    below ``tol`` times its column's largest candidate, or not finite: factorise afresh."""
    for k in range(n):
        col = np.uint64(q[k])
        for p in range(np.uint64(Ap[col]), np.uint64(Ap[col + U1])):
            x[np.uint64(Ai[p])] += Ax[p]
        r_lo, r_hi = np.uint64(Rp[k]), np.uint64(Rp[k + 1])
        for r in range(r_lo, r_hi):
            j = np.uint64(Ri[r])
            J = pinv[j]
            if J >= k:
                continue
            xj = x[j]
            uJ = np.uint64(J)
            for p in range(np.uint64(Lp[uJ]) + U1, np.uint64(Lp[uJ + U1])):
                x[np.uint64(Lio[p])] -= Lx[p] * xj
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
    step's tuple ``(*SparseLU._f, z, refactor)`` with ``refactor`` =
    :meth:`~drivedyn.solver.linear.SparseLU.refactor_arrays`. Returns 0, or -1 when a kept
    pivot is refused (the caller factorises afresh, in Python)."""
    cLp, cLi, cLx, cUp, cUi, cUx, pinv, _qinv, _z, rf = sparse
    q, tol, Lp, Li, Lio, Lx, Up, Ui, Ux, prow, Rp, Ri, x = rf
    n = Lp.shape[0] - 1
    if gp_refactor(n, indptr, indices, data, q, tol[0], Lp, Lio, Lx, Up, Ux, pinv, prow, Rp,
                   Ri, x) != 0:
        return -1
    compact_factors(Lp, Li, Lx, Up, Ui, Ux, cLp, cLi, cLx, cUp, cUi, cUx)
    return 0
