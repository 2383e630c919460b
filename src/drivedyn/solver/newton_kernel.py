"""The Newton iteration of one step as one compiled function.

:func:`newton_iterations` runs the predictor, the Newton iterations, the factorisations and
the convergence tests of a step, inside the compiled stepping loop
(:func:`drivedyn.solver.step_loop.run_steps`). In Python that orchestration (seven group calls
per evaluation with 29 arguments to unbox each, the norms, the solve, the update) took about
40 % of the Type C bench's wall time. It calls the element kernels through their addresses
(:mod:`drivedyn.solver.kernel_calls`), so it is compiled once per combination of argument
types and cached; the kernels stay compiled and cached once each.

A Python transcription of the algorithm, statement for statement, is the tests' oracle
(``tests/internals/reference_stepper.py``); a test runs models both ways and compares every
step bit for bit (``tests/internals/test_step_loop.py``), so a change to the algorithm goes
into both.

Arrays shared with :class:`~drivedyn.solver.stepper.Stepper` (its Newton memory):
    ``istate`` (int64, NISTATE): factorisation valid (0/1), round-off levels valid (0/1),
        factorisations so far, residual evaluations so far, and the fields of a
        factorisation done by the caller (see :func:`newton_iterations` and I_* below).
    ``fstate`` (float64, NFSTATE): step size of the factorisation [s], force scale (largest
        sum of absolute contributions of an accepted state) [N or N m], saved loop state.
    ``par`` (float64, 14): alpha_m, alpha_f, gamma, beta, beta', gamma', tol, phi_tol,
        contraction, max_iter, full Newton (0/1), FLOOR_REL, STALL_ULPS, ROUNDOFF_ULPS.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from drivedyn.elements.framework.contract import MODE_DYN
from drivedyn.solver.factor_frames import choose_frames, from_frames, to_frames
from drivedyn.solver.kernel_calls import call_groups
from drivedyn.solver.lu_paths import FACTOR_OUTSIDE, FACTOR_SINGULAR, lu_factor, lu_solve
from drivedyn.solver.redundancy import hold_multipliers, set_aside
from drivedyn.solver.system import lie_update, tangents
from drivedyn.timefunctions import eval_time_functions

# Residual of an equation is measured against the sum of the absolute values of its terms;
# for an equation with (nearly) no terms of its own, against FLOOR_REL x the largest such sum
# in the model (the accuracy a solve can deliver there is set by the model's force scale).
# 1e-2: such an equation is solved to 1e-10 of the model's largest force sum. With 1e-4 a
# floating part (the Type C internal gear between its washers at zero torque, 1 kg, 5.8 kN
# the largest sum) was iterated to 6e-9 N, a position change of 1e-16 m per step, below the
# round-off of its coordinates: zero-torque holds took 3 Newton iterations per step where
# loaded ones take 2.2 (1.5-1.7 with 1e-2); bench TDRs moved by at most 4e-5 relative.
FLOOR_REL = 1e-2



# Round-off of the unknowns, in units of the machine epsilon: the Lie update and the solve
# leave each coordinate (and multiplier) uncertain by a few ulps of its magnitude.
ROUNDOFF_ULPS = 16.0
# Newton stagnates when its correction is below this many ulps of its unknowns' scales
# (correction_size): the largest coordinate for translations [m], max(1 rad, that) for
# rotations. One scale of max(1 m, largest coordinate) for all unknowns stopped a 7 cm
# mechanism moving 1e-6 m per step before it converged (an error floor at h < 1e-6 s)
STALL_ULPS = 64.0
# A correction that grows while within NOISE_FACTOR x the stall level is round-off noise (the
# residual of stiff constraint penalties and contacts at the last bits of the positions), not
# divergence: Newton goes on (Andrews' squeezer at tol 1e-10 and h = 0.6 us stopped there).
# It does not count as stagnation: accepting such an iterate on its round-off levels left a
# TORSEN Type C bench's coast window with a ripple of 2.6e-5 (steady: 6e-9)
NOISE_FACTOR = 1024.0


@njit(cache=True)
def residual_norms(r, rabs, kscale, nd, floor_rel, roff, amin=0.0):
    """Largest scaled node residual and constraint violation beyond the round-off level
    ``roff`` of each equation (see :func:`roundoff_levels`; zeros for none); returns
    (rq_max, phi_max, finite). Node equations are scaled as in
    :func:`~drivedyn.solver.stepper.scaled_residual`, constraint rows are violations [m or
    rad]."""
    amax = max(amin, 1e-300)
    for i in range(nd):
        if rabs[i] > amax:
            amax = rabs[i]
    floor = floor_rel * amax
    rq = 0.0
    finite = True
    for i in range(nd):
        v = max(abs(r[i]) - roff[i], 0.0) / (rabs[i] + floor)
        if not np.isfinite(r[i]):
            finite = False
        if v > rq:
            rq = v
    ph = 0.0
    for i in range(nd, r.shape[0]):
        v = max(abs(r[i]) - roff[i], 0.0) / kscale[i]
        if not np.isfinite(r[i]):
            finite = False
        if v > ph:
            ph = v
    return rq, ph, finite


@njit(cache=True)
def roundoff_levels(data, indices, indptr, nd, xmax, lam, ulps, out):
    """Residual each equation shows when every unknown is off by its round-off, the row sums
    ``sum_j |A_ij| eps_j`` of the iteration matrix ``A`` (CSC arrays) with
    ``eps_j = ulps eps xmax`` for the translation increments (``xmax`` [m]: the largest
    coordinate, which sets the round-off of all of them), ``ulps eps`` [rad] for the
    rotation increments (rotations are stored as matrices of entries up to 1) and
    ``ulps eps |lam_j|`` for the multipliers. A residual below it cannot be reduced in
    floating point (a stiff constraint or contact turns the last bit of a position into a
    large force), so it is not counted against the tolerance. ``out`` (neq,) receives the
    levels. Nothing here is in metres of the model's own choosing: a 1 cm mechanism and the
    same mechanism 100 times larger get levels in proportion."""
    eps = 2.220446049250313e-16
    ex = ulps * eps * xmax
    er = ulps * eps
    out[:] = 0.0
    for j in range(indptr.shape[0] - 1):
        if j < nd:
            ej = ex if j % 6 < 3 else er
        else:
            ej = ulps * eps * abs(lam[j - nd])
        for k in range(indptr[j], indptr[j + 1]):
            out[indices[k]] += abs(data[k]) * ej


@njit(cache=True)
def correction_size(delta, nd, xmax):
    """Size of a Newton correction in units of its unknowns' own scales: the largest of
    ``|delta_j| / xmax`` over the translation increments (``xmax`` [m], the largest
    coordinate) and ``|delta_j| / max(1, xmax)`` over the rotation increments (dofs
    ``6 i + 3..5``: a radian, or the largest coordinate in metres where that is larger, as
    the rotations of a large model couple with its translations through lever arms of that
    size; with one radian, a spinning 1.2 m rod's rotation corrections stayed at 70-100
    ulps and 326 of its 5000 steps failed). Below ``STALL_ULPS eps`` the correction is at
    the round-off of the unknowns (Newton stagnates)."""
    xs = xmax if xmax > 0.0 else 1e-300
    xr = max(1.0, xmax)
    m = 0.0
    for j in range(nd):
        d = abs(delta[j]) / (xs if j % 6 < 3 else xr)
        if d > m:
            m = d
    return m


EPS = float(np.finfo(float).eps)


@njit(cache=True)
def absmax(x):
    """max |x| over all entries (0 for an empty array)."""
    m = 0.0
    for v in x.ravel():
        if abs(v) > m:
            m = abs(v)
    return m


@njit(cache=True)
def predict(vd, a, v, vd_prev, w, h, af, am, gamma, beta, vd1, a1, v1, hdq):
    """Predictor of a step from (vd, a, v): accelerations ``vd1 = vd + w (vd - vd_prev)``
    (``w`` = 0: constant), pseudo-accelerations ``a1``, velocities ``v1`` and the Lie-algebra
    increment ``hdq`` of the generalized-alpha scheme (one pass, no temporaries)."""
    for i in range(vd.shape[0]):
        x = vd[i] + w * (vd[i] - vd_prev[i]) if w > 0.0 else vd[i]
        vd1[i] = x
        ai = (af * vd[i] + (1.0 - af) * x - am * a[i]) / (1.0 - am)
        a1[i] = ai
        v1[i] = v[i] + h * ((1.0 - gamma) * a[i] + gamma * ai)
        hdq[i] = h * v[i] + h * h * ((0.5 - beta) * a[i] + beta * ai)


@njit(cache=True)
def error_norm(a1, a0, hdq, c, atol, rtol, atol_rot=-1.0, nnode=0):
    """Weighted max norm of the local position error estimate ``c |a1 - a0|`` (``c`` =
    |beta - 1/6| h^2) with weights ``atol + rtol |hdq|`` (``atol_rot`` instead of ``atol``
    for the rotation coordinates of the ``nnode`` nodes, dofs ``6 i + 3..5``; a negative
    ``atol_rot``: ``atol``), and the first dof where it is largest (a NaN counts as largest);
    (0, -1) for no dofs."""
    qmax = 0.0
    imax = -1
    arot = atol_rot if atol_rot > 0.0 else atol
    for i in range(a1.shape[0]):
        at = arot if i < 6 * nnode and i % 6 >= 3 else atol
        q = c * abs(a1[i] - a0[i]) / (at + rtol * abs(hdq[i]))
        if imax < 0 or q > qmax or (q != q and qmax == qmax):
            qmax = q
            imax = i
    return qmax, imax


@njit(cache=True)
def newton_update(delta, nd, hdq, vd, a, v, lam, cM, ca, cC):
    """Apply a Newton correction; returns (max |dx|, all finite)."""
    nrm = 0.0
    finite = True
    for i in range(nd):
        dx = delta[i]
        if not np.isfinite(dx):
            finite = False
        hdq[i] += dx
        vd[i] += cM * dx
        a[i] += ca * dx
        v[i] += cC * dx
        if abs(dx) > nrm:
            nrm = abs(dx)
    for i in range(lam.shape[0]):
        if not np.isfinite(delta[nd + i]):
            finite = False
        lam[i] += delta[nd + i]
    return nrm, finite



# modified Newton: a factorisation is kept for a step size within H_REUSE of its own, and
# refreshed after REFACTOR_AFTER iterations on it (the configuration moved on: refresh it
# rather than creep along). With the step compiled, a factorisation of the Type C (matrix
# 62 us + LU 45 us) costs eight iterations (residual 11 us + solve 2 us), so it pays to
# iterate longer on one: 1e-2 / 3 -> 0.1 / 4 with Newton.contraction 0.3 -> 0.5 gives the
# Type C bench -25 % factorisations for +17 % iterations (benchmarks/README.md). Five
# iterations were faster still, but left the beam_energy validation case's energy rise at
# 8.8e-7 of E0 (tolerance 3e-7; 6.8e-8 with four): converged to the tolerance, not below.
H_REUSE = 0.1
REFACTOR_AFTER = 4
# A step converged in three or more iterations on a factorisation of an earlier step refreshes
# it for the next step if one of its corrections contracted by less than SLOW_CONTRACTION
# (ratio above it: the matrix has gone stale), or once the steps on it have taken EXCESS_MAX
# iterations beyond one each (the price of a factorisation in iterations: a matrix that
# costs every step a second iteration, as one taken with gear flanks apart, is refreshed
# after EXCESS_MAX steps, not kept for the run). Three iterations at good contraction come
# from the predictor's distance, which a fresh matrix does not shorten much.
SLOW_CONTRACTION = 0.1
EXCESS_MAX = 8
# A correction that did not contract (ratio above Newton.contraction) marks the factorisation
# stale; it is refreshed at the next iteration only if that iteration has not converged. A
# step converged on a factorisation of an earlier step keeps it: near a zero-torque hold's
# convergence the last correction is small and its ratio to the one before is noise (the
# gear flanks within their onset). One converged on its own new factorisation does not: the
# matrix changed within the step (a block sticking on a slope failed without this).
# Refreshing there cost the Type C's zero holds 0.42 factorisations per step against 0.13 in
# loaded holds; deferred, 0.10. The price: a
# stale step that has not converged assembles its matrix in an evaluation of its own.

# The closing correction: a converged step takes the correction of its last residual (one solve
# with the factorisation at hand, no evaluation), which makes the remaining error the
# contraction ratio times smaller. Modified Newton converges from the predictor's side, so
# the error a step leaves within the tolerance has one sign from step to step and adds up:
# at the default tol 1e-8 Andrews' squeezer (7 cm) kept a bias of +1e-7 rad on the crank over
# 0.03 s whatever the step, and its error stopped falling as h^2 below 1 us (1.3e-6, 2.5e-7,
# 5.5e-9 at h = 1.25, 0.625, 0.3125 us; with the correction 1.41e-6, 3.52e-7, 8.8e-8, order
# 2.00 as at tol 1e-10). The outputs and element states committed are those of the last
# evaluation, within the tolerance of the corrected state. Cost: one back substitution per
# step (the Type C bench: the same steps, iterations and factorisations within 1 %). Taken
# only where the factorisation contracted, or below contraction x the last correction, the
# correction gave back part of the bias (errors 1.33e-6, 2.9e-7, 7.7e-8: ratios 4.6, 3.8).

# outcome codes of newton_iterations (mapped to StepStatus by the stepper)
SUCCESS = 0
NONFINITE_RESIDUAL = 1
NONFINITE_CORRECTION = 2
SINGULAR = 3
DIVERGED = 4
MAX_ITER = 5
NEED_FACTOR = 6

# istate fields: factorisation valid, round-off levels valid, factorisations, evaluations,
# factorise outside (1: return NEED_FACTOR), factors in the dense workspace (1) or SparseLU's
# arrays (0), resuming after an outside factorisation, the saved iteration and factorisation
# count at the start of the step, and SparseLU's pivots at hand (1: refactorise here, return
# NEED_FACTOR only when a kept pivot is refused), and the iterations beyond one per step
# taken on the present factorisation (EXCESS_MAX)
(I_LU, I_ROFF, I_NFAC, I_NEVAL, I_EXTERNAL, I_DENSE, I_PHASE, I_IT, I_NFAC0,
 I_REFACTOR, I_EXCESS) = range(11)
NISTATE = 11
# fstate fields: step size of the factorisation, force scale, and the saved correction
# sizes and largest coordinate of an iteration left for an outside factorisation
F_LU_H, F_FORCE, F_PREV, F_LAST, F_XMAX = range(5)
NFSTATE = 5


@njit(cache=True)
def _evaluate(G, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, want, r, rabs, data, red, nd):
    """All groups' contributions at the trial state (``call_groups`` in dynamics mode), with
    the constraint rows set aside in ``red`` (:mod:`~drivedyn.solver.redundancy`:
    ``(rows, diag, rptr, rpos, dscale, viol)``) held at zero multiplier. One
    function for the Newton loop's three call sites: the calls through the kernel table are
    generated once (Type C bench: the stepping loop's final module 18 688 -> 12 372 LLVM
    instructions) and LLVM keeps it a call (one per evaluation, nanoseconds against the
    13 us of the groups)."""
    rows, diag, rptr, rpos, dscale, viol, _watch = red
    if rows.shape[0]:
        hold_multipliers(lam, rows, nd)
    call_groups(G, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, 1.0, MODE_DYN, want)
    if rows.shape[0]:
        set_aside(r, rabs, data, want, rows, diag, rptr, rpos, dscale, viol)


@njit(cache=True, inline="always")
def _forget(istate, roff):
    """No factorisation (the round-off levels describe the factorised matrix only)."""
    istate[I_LU] = 0
    istate[I_ROFF] = 0
    roff[:] = 0.0


@njit(cache=True, inline="always")
def _clear(r, rabs, data, want, hdq, nn, Tn, istate):
    """Before an evaluation: zero the residual, its scales and (if ``want``) the matrix, with
    the tangent operators of ``hdq`` for it; returns ``want``. (The kernels are called at the
    call site: ``G`` passed into a helper would be copied, with a reference count update of
    each of its arrays.)"""
    r[:] = 0.0
    rabs[:] = 0.0
    if want:
        data[:] = 0.0
        tangents(hdq, nn, Tn)
    istate[I_NEVAL] += 1
    return want


@njit(cache=True, inline="always")
def _factorised(istate, fstate, h):
    """Bookkeeping of a new factorisation for step size ``h``."""
    istate[I_LU] = 1
    istate[I_ROFF] = 0  # computed from this matrix when Newton first stagnates on it
    istate[I_EXCESS] = 0
    fstate[F_LU_H] = h
    istate[I_NFAC] += 1


# inline: the compiled stepping loop (step_loop.run_steps) inlines it, instead of linking a
# separately compiled copy and optimising it again with the loop (seconds of compilation)
@njit(cache=True, inline="always")
def newton_iterations(G, sizes, accepted, trial, arrays, linear, sparse, par, istate,
                      fstate):
    """Newton iterations of the step from the accepted state ``(x0, R0, v0, vd0, a0)`` to
    time ``t`` = t_n + ``h``; the trial state ``(x, R, v, vd, a, lam)`` holds a copy of the
    accepted one on entry and the result on return; ``es`` the element states. Arguments
    come in tuples (fewer arguments to unbox per call)::

        sizes = (nn, nd, w, t, h)            # w: predictor weight (Stepper.step)
        accepted = (x0, R0, v0, vd0, a0, prev_vd)
        trial = (x, R, v, vd, a, lam, es, hdq)
        arrays = (Tn, r, rabs, data, tfv, kscale, tf_kind, tf_par, tf_fstart, tf_tab,
                  indices, indptr, red)      # System's arrays, the time functions, CSC
                                             # pattern, the rows set aside (redundancy)
        linear = (lu, piv, ib, tr, delta, roff, no_roff, frames)  # lapack.workspace,
                                             # scratch, factor_frames' arrays
        sparse = (Lp, Li, Lx, Up, Ui, Ux, perm_r, perm_c, tail, z, refactor)  # SparseLU's
                                             # factors and its refactor_arrays(), or None
                                             # for a dense LU only (lu_paths)

    ``G`` (a :class:`~drivedyn.solver.kernel_calls.KernelTable`) holds the groups' kernels
    and arguments; they add their contributions into ``r, rabs, data``. Returns ``(code,
    iterations, factorisations of this step)`` with the codes of this module; ``r`` holds the
    last residual.

    With ``istate[I_EXTERNAL]`` set, the sparse LU refactorises here with its last pivots
    (``istate[I_REFACTOR]``, :func:`~drivedyn.solver.sparse_lu.refactor_in_place`); a first
    factorisation, or one whose kept pivots are refused, is left to the caller (the sparse
    LU takes its column order from SuperLU and grows its arrays in Python): the function
    returns ``NEED_FACTOR`` with the matrix assembled in ``data`` and its loop state saved;
    the caller factorises, sets ``istate[I_DENSE]`` (factors in ``linear``'s dense
    workspace, or in ``sparse``) and calls again, and the iteration goes on from the
    factorisation. A return to Python cost the RWD vehicle 0.2-0.4 ms per factorisation
    (the unboxing of the loop's arguments), a third of the refactorisation itself.
    """
    nn, nd, w, t, h = sizes
    x0, R0, v0, vd0, a0, prev_vd = accepted
    x, R, v, vd, a, lam, es, hdq = trial
    (Tn, r, rabs, data, tfv, kscale, tf_kind, tf_par, tf_fstart, tf_tab, indices, indptr,
     red) = arrays
    delta, roff, no_roff, frames = linear[4], linear[5], linear[6], linear[7]
    am, af, gamma, beta, bp, gp = par[0], par[1], par[2], par[3], par[4], par[5]
    tol, phi_tol, contraction = par[6], par[7], par[8]
    max_iter = int(par[9])
    full = par[10] != 0.0
    floor_rel, stall_ulps, roundoff_ulps = par[11], par[12], par[13]
    cM = 1.0 / (bp * h * h)
    cC = gp / (bp * h)
    ca = (1.0 - af) / (1.0 - am) * cM
    resumed = istate[I_PHASE] != 0
    if resumed:
        # back from the caller's factorisation: go on from there
        istate[I_PHASE] = 0
        it = istate[I_IT]
        nfac0 = istate[I_NFAC0]
        prev = fstate[F_PREV]
        last = fstate[F_LAST]
        xmax = fstate[F_XMAX]
        assembled = True
        _factorised(istate, fstate, h)
        choose_frames(data, indices, indptr, R, frames)
        fresh = True
        since_factor = 0
        stale = False
        worst = 0.0
    else:
        predict(vd0, a0, v0, prev_vd, w, h, af, am, gamma, beta, vd, a, v, hdq)
        lie_update(x0, R0, hdq, nn, x, R, Tn, False)
        # a factorisation for a step size within H_REUSE of h still converges
        # well; the contraction monitor below refactors if it does not
        if istate[I_LU] != 0 and abs(fstate[F_LU_H] - h) > H_REUSE * h:
            _forget(istate, roff)
        eval_time_functions(t, tf_kind, tf_par, tf_fstart, tf_tab, tfv)
        assembled = _clear(r, rabs, data, full or istate[I_LU] == 0, hdq, nn, Tn, istate)
        _evaluate(G, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, assembled, r, rabs, data,
                  red, nd)
        it = 0
        nfac0 = istate[I_NFAC]
        prev = np.inf
        fresh = False
        since_factor = 0
        xmax = absmax(x)
        last = np.inf
        stale = False
        worst = 0.0
    while True:
        if not resumed:
            rq_max, ph_max, finite = residual_norms(r, rabs, kscale, nd, floor_rel, no_roff,
                                                    fstate[F_FORCE])
            if not finite:
                return NONFINITE_RESIDUAL, it, istate[I_NFAC] - nfac0
            if (rq_max > tol or ph_max > phi_tol) and last <= stall_ulps * EPS:
                # stagnation at the round-off of the positions: discount the residual a
                # round-off change of the unknowns produces (the tests' reference stepper
                # explains)
                if istate[I_LU] != 0 and istate[I_ROFF] == 0:
                    # from the matrix without inertia and damping (cM = cC = 0): those
                    # terms act through the increments, which carry no position round-off
                    # (the residual and outputs are those of the same state again)
                    _clear(r, rabs, data, True, hdq, nn, Tn, istate)
                    _evaluate(G, x, R, v, vd, lam, es, tfv, t, Tn, 0.0, 0.0,
                              bool(True), r, rabs, data, red, nd)  # noqa: UP018
                    assembled = False
                    roundoff_levels(data, indices, indptr, nd, xmax, lam, roundoff_ulps,
                                    roff)
                    istate[I_ROFF] = 1
                rq_max, ph_max, finite = residual_norms(r, rabs, kscale, nd, floor_rel, roff,
                                                        fstate[F_FORCE])
            if rq_max <= tol and ph_max <= phi_tol:
                if stale and istate[I_NFAC] != nfac0:
                    # no contraction on this step's own factorisation: an event (contact,
                    # stick-slip) within the step; refresh it next step
                    _forget(istate, roff)
                elif istate[I_NFAC] == nfac0 and it > 1:
                    # slow convergence on an old factorisation (SLOW_CONTRACTION)
                    istate[I_EXCESS] += it - 1
                    if (it >= 3 and worst > SLOW_CONTRACTION) or \
                            istate[I_EXCESS] >= EXCESS_MAX:
                        _forget(istate, roff)
                if nd:
                    fstate[F_FORCE] = max(fstate[F_FORCE], absmax(rabs[:nd]))
                if istate[I_LU] != 0:
                    # the closing correction (the note above the outcome codes)
                    for i in range(r.shape[0]):
                        delta[i] = -r[i]
                    to_frames(delta, R, frames)
                    lu_solve(linear, sparse, istate[I_DENSE] != 0, delta)
                    from_frames(delta, R, frames)
                    newton_update(delta, nd, hdq, vd, a, v, lam, cM, ca, cC)
                    lie_update(x0, R0, hdq, nn, x, R, Tn, False)
                return SUCCESS, it, istate[I_NFAC] - nfac0
            if it == max_iter:
                break
            if stale:
                _forget(istate, roff)
                stale = False
            if full or istate[I_LU] == 0 or since_factor >= REFACTOR_AFTER:
                if not assembled:
                    _clear(r, rabs, data, True, hdq, nn, Tn, istate)
                    # bool(True) types as a boolean, True as a literal: a second overload
                    _evaluate(G, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC,
                              bool(True), r, rabs, data, red, nd)  # noqa: UP018
                # the sparse LU with its last pivots here; afresh (pivot search, arrays
                # grown) in Python
                factored = lu_factor(data, indices, indptr, linear, sparse,
                                     istate[I_EXTERNAL] != 0, istate[I_REFACTOR] != 0)
                if factored == FACTOR_OUTSIDE:
                    istate[I_PHASE] = 1
                    istate[I_IT] = it
                    istate[I_NFAC0] = nfac0
                    fstate[F_PREV] = prev
                    fstate[F_LAST] = last
                    fstate[F_XMAX] = xmax
                    return NEED_FACTOR, it, istate[I_NFAC] - nfac0
                elif factored == FACTOR_SINGULAR:
                    _forget(istate, roff)
                    return SINGULAR, it, istate[I_NFAC] - nfac0
                _factorised(istate, fstate, h)
                choose_frames(data, indices, indptr, R, frames)
                fresh = True
                since_factor = 0
        resumed = False
        since_factor += 1
        for i in range(r.shape[0]):
            delta[i] = -r[i]
        to_frames(delta, R, frames)
        lu_solve(linear, sparse, istate[I_DENSE] != 0, delta)
        from_frames(delta, R, frames)
        nrm, finite = newton_update(delta, nd, hdq, vd, a, v, lam, cM, ca, cC)
        if not finite:
            return NONFINITE_CORRECTION, it, istate[I_NFAC] - nfac0
        ratio = nrm / prev if 0.0 < prev < np.inf else 0.0
        if ratio > worst:
            worst = ratio
        last = correction_size(delta, nd, xmax)
        if it > 0 and ratio > contraction:
            # a correction within the round-off noise that grows is not divergence
            if ratio > 2.0 and fresh and last > NOISE_FACTOR * stall_ulps * EPS:
                return DIVERGED, it + 1, istate[I_NFAC] - nfac0
            # refactor at the next iteration unless it has converged (note at REFACTOR_AFTER)
            stale = True
        if nrm > 0:
            prev = nrm
        fresh = False
        lie_update(x0, R0, hdq, nn, x, R, Tn, False)
        assembled = _clear(r, rabs, data, full or istate[I_LU] == 0, hdq, nn, Tn, istate)
        _evaluate(G, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, assembled, r, rabs, data,
                  red, nd)
        it += 1
    return MAX_ITER, max_iter, istate[I_NFAC] - nfac0
