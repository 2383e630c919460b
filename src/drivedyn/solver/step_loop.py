"""The time-stepping loop of :func:`~drivedyn.solver.simulate.simulate` as one compiled call
per output time.

With the Newton step compiled (:mod:`~drivedyn.solver.newton_kernel`), what was left in
Python around each step (its call and the unboxing of its 50 arrays, the error estimate,
the groups' commits, the energy account, the copy of the state, the step-size control) cost
about 50 us per step: 15-25 % of the TORSEN runs' wall time, and more than the whole
budget of a step for faster than real time at 5000 steps per simulated second
(measured). :func:`run_steps` does all of that between two output
times without returning to Python: it runs the Newton iterations (inlined), the error
estimate and the step-size control of :mod:`~drivedyn.solver.step_control` (the same
functions the Python loop calls), copies the committed columns of the elements' outputs into
their states (``Group.commit_cols``), integrates the energy account
(:func:`~drivedyn.results.recorder.advance_energy`) and copies the trial state into the
accepted one. It stores the outputs of each output time in arrays that Python empties into
the :class:`~drivedyn.results.recorder.Recorder` when the loop returns: when they are full
(:class:`StepLoop` sizes them for about :data:`BATCH_WALL` seconds of wall time between
returns), at the end, when the sparse LU must factorise (in Python, as for the compiled
step), when the run fails, and, with ``every`` set (step logging at DEBUG level), after
every attempt. Returning at every output time cost 50-60 us each (the call's unboxing of
about 60 arrays, the record in Python): 6-8 % of the Type C vehicle configuration's run at
its 1.44 ms output interval.

This loop is drivedyn's one stepping engine. A Python transcription of the same algorithm
(``tests/internals/reference_stepper.py``) is the tests' oracle: both give the same steps,
states and outputs bit for bit (``tests/internals/test_step_loop.py``).

Arrays of the loop (the ``control`` argument)::

    touts (float64): output times [s]
    ctl, cs (float64): the step-size control's settings and memory (step_control)
    ls (float64, NLS): time of the accepted state [s], time of the one before (NaN: none),
        resume (1: after the caller's factorisation, 2: the caller's factorisation failed
        or the singular matrix has no new dependent constraint rows: reject the attempt),
        size of the last attempted step [s], its error estimate
    lo (int64, NLO): the last attempt's Newton code (or ERROR_TOO_LARGE), iterations,
        factorisations, dof of the largest error, accepted (0/1)
    stats (float64, NSTATS): steps, rejected steps, Newton iterations, smallest and largest
        accepted step [s]
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from numba import njit

from drivedyn.elements.framework.group import COMMIT_TIME, aux_offset
from drivedyn.model.model import Model, State
from drivedyn.results.recorder import EnergyAccount, advance_energy, total
from drivedyn.solver import newton_kernel as nk
from drivedyn.solver.kernel_calls import borrow
from drivedyn.solver.newton_kernel import I_NEVAL, I_PHASE, _forget, newton_iterations
from drivedyn.solver.redundancy import watched
from drivedyn.solver.step_control import (
    CS_IOUT,
    CT_TEND,
    accept_step,
    next_step,
    reject_step,
    step_error,
)

# wall time [s] between two returns of the loop that StepLoop sizes its output batches for:
# short enough for a progress display and for Ctrl-C (handled between returns) to respond
BATCH_WALL = 0.05
BATCH_MAX = 64  # outputs per batch at most (and 4 in the first)

# return codes of run_steps (RUN_SINGULAR: a factorisation was singular; the caller looks
# for constraint rows that became dependent, :mod:`~drivedyn.solver.redundancy`)
# RUN_WATCH: a constraint row set aside is violated beyond its watch limit after an accepted
# step; the caller finds the dependent rows again
(RUN_END, RUN_OUTPUT, RUN_NEED_FACTOR, RUN_FAILED, RUN_ATTEMPT, RUN_SINGULAR,
 RUN_WATCH) = range(7)
# lo[LO_CODE] of a step rejected by its error estimate (beyond newton_kernel's codes)
ERROR_TOO_LARGE = 7

LS_T, LS_PREV_T, LS_RESUME, LS_HTRY, LS_ERR = range(5)
NLS = 5
LO_CODE, LO_IT, LO_NFAC, LO_IERR, LO_ACCEPTED = range(5)
NLO = 5
ST_STEPS, ST_REJECTED, ST_NEWTON, ST_HMIN, ST_HMAX = range(5)
NSTATS = 5


@njit(cache=True)
def _copy(src, dst):
    """``dst[:] = src`` for 1-D arrays of one size (a slice assignment would compile numba's
    shape check with its formatted message: seconds of compilation)."""
    for i in range(src.shape[0]):
        dst[i] = src[i]


@njit(cache=True)
def _copy_state(x, R, v, vd, a, lam, es, x1, R1, v1, vd1, a1, lam1, es1):
    """Copy the state ``(x, R, v, vd, a, lam, es)`` into ``(x1, ...)`` (same sizes)."""
    for i in range(x.shape[0]):
        for j in range(3):
            x1[i, j] = x[i, j]
            for k in range(3):
                R1[i, j, k] = R[i, j, k]
    _copy(v, v1)
    _copy(vd, vd1)
    _copy(a, a1)
    _copy(lam, lam1)
    _copy(es, es1)


@njit(cache=True)
def _snapshot(k, t, h, x, R, v, aux_all, diss, eacc, snaps):
    """Store the outputs at time ``t`` [s] (reached by a step of ``h`` [s]) in row ``k`` of
    the snapshot arrays (see :func:`run_steps`): what ``Recorder.record`` copies, the
    recorder's selection only (``snaps[9]``: nodes, entries of ``aux_all``, elements' energy
    dissipated)."""
    sx, sR, sv, saux, sdiss, sacc, sh, stt, _, sel = snaps
    nodes, aidx, didx = sel
    for i in range(nodes.shape[0]):
        n = nodes[i]
        for j in range(3):
            sx[k, i, j] = x[n, j]
            for m in range(3):
                sR[k, i, j, m] = R[n, j, m]
        for j in range(6):
            sv[k, 6 * i + j] = v[6 * n + j]
    for i in range(aidx.shape[0]):
        saux[k, i] = aux_all[aidx[i]]
    for i in range(didx.shape[0]):
        sdiss[k, i] = diss[didx[i]]
    for i in range(eacc.shape[0]):
        sacc[k, i] = eacc[i]
    sacc[k, eacc.shape[0]] = total(diss)
    sh[k] = h
    stt[k] = t


@njit(cache=True)
def run_steps(G, sizes, accepted, trial, arrays, linear, sparse, par, istate, fstate, control,
              energy, commits, snaps):
    """Steps from the accepted state until the output arrays ``snaps`` are full (or the
    end, a failure, a factorisation left to the caller, or after one attempt if ``every``);
    returns a RUN_* code. Arguments::

        sizes = (nn, nd, every)
        accepted = (x0, R0, v0, vd0, a0, lam0, es0, prev_vd, prev_a)   # the accepted
                                                   # state, vd and a of the one before
        trial = (x, R, v, vd, a, lam, es, hdq)                 # as newton_iterations
        arrays, linear, sparse, par, istate, fstate            # as newton_iterations
        control = (touts, ctl, cs, ls, lo, stats)              # module docstring
        energy = (eout, gstart, gdriver, pin, pd, diss, eacc)  # as advance_energy
        commits = (dst, src, aux_all)  # es[dst[k]] = aux_all[src[k]] (time if src[k] < 0)
        snaps = (sx, sR, sv, saux, sdiss, sacc, sh, st, sk, sel)  # outputs for Python

    ``snaps`` holds the outputs of up to K output times (rows 0..K-1) of what the recorder
    keeps, ``sel = (nodes, aidx, didx)`` (:class:`~drivedyn.results.recorder.Selection`):
    positions (K, n, 3), rotations (K, n, 3, 3) and velocities (K, 6 n) of the n nodes
    ``nodes``, the entries ``aidx`` of ``aux_all``, the energies dissipated by the elements
    ``didx``, the energy account ``eacc`` and the total energy dissipated (K, 6), step sizes
    (K,) and times (K,); ``sk[0]`` counts the rows filled (the caller empties them). The
    loop returns RUN_OUTPUT when they are full; with K = 0 at every output time (the caller
    then records).

    ``prev_vd`` and ``prev_a`` hold the accelerations and pseudo-accelerations of the state
    before the accepted one (the predictor's and the error estimate's history, time
    ``ls[LS_PREV_T]``).
    """
    # the caller holds every array throughout and the loop keeps none: borrowed, its views
    # and the functions it passes them to count no references
    (accepted, trial, arrays, linear, sparse, par, istate, fstate, control, energy, commits,
     snaps) = borrow((accepted, trial, arrays, linear, sparse, par, istate, fstate, control,
                      energy, commits, snaps))
    nn, nd, every = sizes
    x0, R0, v0, vd0, a0, lam0, es0, prev_vd, prev_a = accepted
    x, R, v, vd, a, lam, es, hdq = trial
    touts, ctl, cs, ls, lo, stats = control
    eout, gstart, gdriver, pin, pd, diss, eacc = energy
    dst, src, aux_all = commits
    sk = snaps[8]
    nsnap = snaps[7].shape[0]
    roff = linear[5]
    red = arrays[12]
    while True:
        t = ls[LS_T]
        resume = ls[LS_RESUME]
        ls[LS_RESUME] = 0.0
        w = 0.0
        if resume != 0.0:  # the same attempt, after the caller's factorisation
            h_try = ls[LS_HTRY]
        else:
            h_try = next_step(cs, ctl, t, touts)
            if h_try == 0.0:
                return RUN_END
            _copy_state(x0, R0, v0, vd0, a0, lam0, es0, x, R, v, vd, a, lam, es)
            # predictor weight (Stepper.step)
            pt = ls[LS_PREV_T]
            if pt == pt and t > pt:
                w = min(h_try / (t - pt), 1.0)
            istate[I_PHASE] = 0
        t1 = t + h_try
        if resume == 2.0:  # the caller's factorisation failed: singular matrix
            code, it, nfac = nk.SINGULAR, lo[LO_IT], lo[LO_NFAC]
        else:
            # one call site: the step is inlined, and each site would be a copy
            code, it, nfac = newton_iterations(
                G, (nn, nd, w, t1, h_try), (x0, R0, v0, vd0, a0, prev_vd), trial, arrays,
                linear, sparse, par, istate, fstate)
        ls[LS_HTRY] = h_try
        lo[LO_IT] = it
        lo[LO_NFAC] = nfac
        if code == nk.NEED_FACTOR:
            ls[LS_RESUME] = 1.0
            return RUN_NEED_FACTOR
        if code == nk.SINGULAR and resume != 2.0:
            # the caller checks for constraint rows that became dependent: it sets them
            # aside and the attempt is made again, or resumes with 2 (a rejection)
            return RUN_SINGULAR
        stats[ST_NEWTON] += it
        err = 0.0
        ierr = -1
        ok = code == nk.SUCCESS
        if ok:
            pt = ls[LS_PREV_T]
            err, ierr = step_error(ctl, a, a0, prev_a, hdq, h_try,
                                   t - pt if pt == pt and t > pt else 0.0)
            if err > 1.0:
                ok = False
                code = ERROR_TOO_LARGE
        lo[LO_CODE] = code
        lo[LO_IERR] = ierr
        ls[LS_ERR] = err
        if ok:
            for k in range(dst.shape[0]):
                es[dst[k]] = t1 if src[k] < 0 else aux_all[src[k]]
            advance_energy(eout, gstart, gdriver, pin, pd, diss, eacc, h_try)
            ls[LS_PREV_T] = t
            _copy(vd0, prev_vd)
            _copy(a0, prev_a)
            _copy_state(x, R, v, vd, a, lam, es, x0, R0, v0, vd0, a0, lam0, es0)
            stats[ST_STEPS] += 1.0
            stats[ST_HMIN] = min(stats[ST_HMIN], h_try)
            stats[ST_HMAX] = max(stats[ST_HMAX], h_try)
            t1, landed = accept_step(cs, ctl, t1, h_try, err, it, touts)
            ls[LS_T] = t1
            lo[LO_ACCEPTED] = 1
            if landed:
                k = sk[0]
                if k >= nsnap:
                    return RUN_OUTPUT
                _snapshot(k, t1, h_try, x0, R0, v0, aux_all, diss, eacc, snaps)
                sk[0] = k + 1
                if k + 1 == nsnap:
                    return RUN_OUTPUT
            if watched(red):
                return RUN_WATCH
        else:
            stats[ST_REJECTED] += 1.0
            _forget(istate, roff)
            lo[LO_ACCEPTED] = 0
            if reject_step(cs, ctl, t, h_try, err, code == ERROR_TOO_LARGE):
                return RUN_FAILED
        if every:
            return RUN_ATTEMPT


def commit_table(model: Model) -> tuple[np.ndarray, np.ndarray] | None:
    """``(dst, src)`` of every group's commit (``Group.commit_cols``) into ``State.es``, from
    ``model.aux_all`` (``src`` -1: the time).

    Raises:
        ModelError: a group that commits otherwise than by copying columns, or whose
            outputs are not views of ``model.aux_all`` (a group built outside
            :func:`~drivedyn.model.compile.compile_model`).
    """
    from drivedyn.errors import ModelError

    aux_all = model.aux_all
    if aux_all is None:
        raise ModelError("the model has no output table (aux_all): compile it with "
                         "compile_model")
    dst: list[int] = []
    src: list[int] = []
    for g in model.groups:
        if g.commit is None:
            continue
        if not g.commit_cols:
            raise ModelError(f"element family {g.family!r} commits its state by a function: "
                             "the stepping loop copies columns (declare Group.commit_cols)")
        off = aux_offset(g, aux_all)
        if off < 0:
            raise ModelError(f"the outputs of the {g.family!r} group are not a view of the "
                             "model's output table (aux_all)")
        ncol = g.aux.shape[1]
        for e in range(g.nel):
            for j, c in enumerate(g.commit_cols):
                dst.append(int(g.eoff[e]) + j)
                src.append(-1 if c == COMMIT_TIME else off + e * ncol + c)
    return np.array(dst, np.int64), np.array(src, np.int64)


def _head(stepper: Any, st: State, prev_vd: np.ndarray, prev_a: np.ndarray,
          every: bool) -> tuple:
    """The ``sizes``, ``accepted``, ``trial`` and ``arrays`` arguments of run_steps."""
    m, tr = stepper.model, stepper.trial
    return ((int(m.nn), int(m.nd), bool(every)),
            (st.x, st.R, st.v, st.vd, st.a, st.lam, st.es, prev_vd, prev_a),
            (tr.x, tr.R, tr.v, tr.vd, tr.a, tr.lam, tr.es, stepper.hdq),
            stepper._state_args(st)[2])


#: the selection of a loop that stores no outputs (it returns at each output time)
_NO_SELECTION = (np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0, np.int64))


def _snapshot_arrays(k: int, sel: tuple, nacc: int) -> tuple:
    """The ``snaps`` argument of :func:`run_steps` for ``k`` output times of the recorder's
    selection ``sel`` (nodes, entries of ``aux_all``, elements) and an energy account of
    ``nacc`` terms."""
    nodes, aidx, didx = sel
    n = nodes.shape[0]
    return (np.empty((k, n, 3)), np.empty((k, n, 3, 3)), np.empty((k, 6 * n)),
            np.empty((k, aidx.shape[0])), np.empty((k, didx.shape[0])),
            np.empty((k, nacc + 1)), np.empty(k), np.empty(k), np.zeros(1, np.int64), sel)


def _energy_args(energy: EnergyAccount) -> tuple:
    return (energy.eout, energy.gstart, energy.gdriver, energy.pin, energy.pd, energy.diss,
            energy.acc)


def precompile_loop(stepper: Any, st: State, energy: EnergyAccount) -> None:
    """Hand :func:`run_steps`' signature for this run (the stepper's model, its state ``st``
    and energy account) to the System's first-evaluation precompile (parallel workers,
    :mod:`~drivedyn.solver.precompile`), when the run will use the compiled loop: a first
    run then compiles it while the kernels compile. Its types do not depend on the kernels'
    addresses nor on the sizes of the arrays."""
    from drivedyn.elements.framework.contract import MODE_DYN
    from drivedyn.solver.kernel_calls import KernelTable

    m, sys = stepper.model, stepper.sys
    commits = commit_table(m)
    try:
        G = KernelTable([(0, pre, post) for _k, pre, _mid, post
                         in sys._kernel_args(st, 1.0, 1.0, 1.0, MODE_DYN, True)])
        f = np.zeros(1)
        control = (f, f, f, f, np.zeros(1, np.int64), f)
        lu, piv, ib, tr = stepper._no_dense
        args = (G, *_head(stepper, st, np.zeros(m.nd), np.zeros(m.nd), False),
                (lu, piv, ib, tr, stepper._delta, stepper.roff, stepper._no_roff,
                 stepper.frames),
                stepper._no_sparse, stepper._par, stepper._istate, stepper._fstate, control,
                _energy_args(energy), (*commits, m.aux_all),
                _snapshot_arrays(0, _NO_SELECTION, 5))
        sig = tuple(run_steps.typeof_pyval(a) for a in args)
    except (AttributeError, TypeError, ValueError):  # not typeable: compiled on first use
        return
    sys.precompile_also.append((run_steps, sig))


class StepLoop:
    """Drives :func:`run_steps` for :func:`~drivedyn.solver.simulate.simulate`: holds its
    argument tuples (built once) and factorises for the sparse LU between calls.

    Args:
        stepper: the run's :class:`~drivedyn.solver.stepper.Stepper`.
        st: the accepted state (updated in place; its ``t`` after every call).
        touts: output times [s].
        ctl, cs: the step-size control's arrays (:mod:`~drivedyn.solver.step_control`).
        energy: the run's energy account (advanced in place).
        stats: the run's counters so far (steps, rejected, Newton iterations, h used).
        buffered: the loop stores the outputs for :meth:`flush` (else it returns at every
            output time, and the caller records the state).
    """

    def __init__(self, stepper: Any, st: State, touts: np.ndarray, ctl: np.ndarray,
                 cs: np.ndarray, energy: EnergyAccount, commits: tuple[np.ndarray, np.ndarray],
                 every: bool, buffered: bool = True, selection: tuple | None = None) -> None:
        self.stepper = stepper
        self.st = st
        m = stepper.model
        self.ls = np.array([st.t, np.nan, 0.0, 0.0, 0.0])
        self.lo = np.zeros(NLO, np.int64)
        self.stats = np.array([0.0, 0.0, 0.0, np.inf, 0.0])
        self.prev_vd = np.zeros(m.nd)
        self.prev_a = np.zeros(m.nd)
        self.control = (touts, ctl, cs, self.ls, self.lo, self.stats)
        self.t_end = float(ctl[CT_TEND])
        self.energy = _energy_args(energy)
        self.commits = (commits[0], commits[1], m.aux_all)
        self.head = _head(stepper, st, self.prev_vd, self.prev_a, every)
        self._sel = _NO_SELECTION if selection is None else selection
        self._nacc = int(energy.acc.size)
        self.buffered = buffered
        self._wall = time.perf_counter()
        self.snaps = _snapshot_arrays(4 if buffered else 0, self._sel, self._nacc)

    @classmethod
    def create(cls, stepper: Any, st: State, touts: np.ndarray, ctl: np.ndarray,
               cs: np.ndarray, energy: EnergyAccount, every: bool,
               buffered: bool = True, selection: tuple | None = None) -> StepLoop:
        """The loop for this run (the kernels bound in the stepper's kernel table);
        ``selection``: what the recorder keeps (``Selection.arrays``), for ``buffered``."""
        commits = commit_table(stepper.model)
        stepper.kernel_table(st)
        return cls(stepper, st, touts, ctl, cs, energy, commits, every, buffered, selection)

    def retarget(self, touts: np.ndarray, t_end: float) -> None:
        """Run on to ``t_end`` [s] through the output times ``touts`` [s] (sorted, after the
        accepted state's time): the step size, the factorisation and the history of the
        accepted steps carry over."""
        _, ctl, cs, ls, lo, stats = self.control
        ctl[CT_TEND] = t_end
        cs[CS_IOUT] = 0.0
        self.t_end = t_end
        self.control = (touts, ctl, cs, ls, lo, stats)

    def forget_history(self) -> None:
        """The next step starts afresh, as the first of a run: without the state before the
        accepted one (its predictor holds the accelerations; its error estimate compares
        with the accepted state only). After a discontinuity of the inputs, where
        extrapolating across it misleads both."""
        self.ls[LS_PREV_T] = np.nan

    def _call(self) -> int:
        s = self.stepper
        lin = s._linear_arrays()
        return run_steps(s._G, *self.head, *lin, s._par, s._istate, s._fstate, self.control,
                         self.energy, self.commits, self.snaps)

    def run(self) -> int:
        """Run to the next return (RUN_END, RUN_OUTPUT, RUN_FAILED or RUN_ATTEMPT); the
        accepted state's time is set on return."""
        s = self.stepper
        n0 = int(s._istate[I_NEVAL])
        try:
            while True:
                code = self._call()
                if code == RUN_SINGULAR:
                    self._singular()
                    continue
                if code in (RUN_OUTPUT, RUN_END, RUN_WATCH) and s.sys.redundancy_restore(
                        self.st, float(self.ls[LS_T])):
                    self._redundancy_changed()
                if code == RUN_WATCH:
                    continue
                if code != RUN_NEED_FACTOR:
                    return code
                try:
                    s.sys.factor(s.lin)
                except (np.linalg.LinAlgError, ValueError):
                    s._istate[I_PHASE] = 0
                    s._forget()
                    self._singular()
        finally:
            self.st.t = float(self.ls[LS_T])
            s.sys.nevals += int(s._istate[I_NEVAL]) - n0

    def _singular(self) -> None:
        """A singular factorisation in the attempt from ``ls[LS_T]``: set aside the
        constraint rows that became dependent and make the attempt again, or reject it."""
        s = self.stepper
        t = float(self.ls[LS_T] + self.ls[LS_HTRY])
        if s.sys.redundancy_on_singular(s.trial, t):
            self._redundancy_changed()
            self.ls[LS_RESUME] = 0.0
        else:
            self.ls[LS_RESUME] = 2.0

    def _redundancy_changed(self) -> None:
        """The rows set aside changed: new arrays for the loop, no factorisation."""
        s = self.stepper
        s._istate[I_PHASE] = 0
        s._forget()
        self.head = _head(s, self.st, self.prev_vd, self.prev_a, self.head[0][2])

    def flush(self, rec: Any) -> int:
        """Hand the outputs the loop stored since the last call to ``rec`` (a
        :class:`~drivedyn.results.recorder.Recorder`) and size the next batch; returns how
        many."""
        snaps = self.snaps
        n = int(snaps[8][0])  # 0 without a buffer (the loop returned at the output time)
        if n == 0:
            return 0
        snaps[8][0] = 0  # first: a flush interrupted (Ctrl-C) and repeated adds nothing twice
        sx, sR, sv, saux, sdiss, sacc, sh, stt, _, _ = snaps
        rec.extend(stt[:n], sx[:n], sR[:n], sv[:n].reshape(n, sx.shape[1], 6), saux[:n],
                   sacc[:n], sdiss[:n], sh[:n])
        now = time.perf_counter()
        per = (now - self._wall) / n
        self._wall = now
        k = int(min(BATCH_MAX, max(1.0, BATCH_WALL / max(per, 1e-9))))
        # new arrays: the recorder keeps views of the rows just handed over
        self.snaps = _snapshot_arrays(k, self._sel, self._nacc)
        return n

    def outcome(self) -> Any:
        """The last attempt as a :class:`~drivedyn.solver.settings.StepOutcome`."""
        from drivedyn.solver.settings import StepOutcome, StepStatus

        code, it, nfac = int(self.lo[LO_CODE]), int(self.lo[LO_IT]), int(self.lo[LO_NFAC])
        err, ierr = float(self.ls[LS_ERR]), int(self.lo[LO_IERR])
        if code == ERROR_TOO_LARGE:
            return StepOutcome(StepStatus.ERROR_TOO_LARGE, it, nfac, error=err,
                               worst_eq=ierr, residual=err)
        out = self.stepper.outcome_of(code, it, nfac)
        if out.ok:  # the error estimate of the accepted step and the dof that set it
            out.error, out.worst_eq = err, ierr
        return out

    @property
    def steps(self) -> int:
        """Steps accepted so far by this loop."""
        return int(self.stats[ST_STEPS])

    def add_stats(self, stats: Any) -> None:
        """Add this loop's counters to ``stats`` (a
        :class:`~drivedyn.results.results.RunStats`)."""
        s = self.stats
        stats.steps += int(s[ST_STEPS])
        stats.rejected += int(s[ST_REJECTED])
        stats.newton_iterations += int(s[ST_NEWTON])
        stats.h_min_used = min(stats.h_min_used, float(s[ST_HMIN]))
        stats.h_max_used = max(stats.h_max_used, float(s[ST_HMAX]))

    def pieces(self) -> tuple[float, bool, int, int]:
        """Of the last attempt: step size [s], accepted, Newton iterations, factorisations."""
        return (float(self.ls[LS_HTRY]), bool(self.lo[LO_ACCEPTED]), int(self.lo[LO_IT]),
                int(self.lo[LO_NFAC]))
