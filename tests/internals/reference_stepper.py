"""The tests' oracle: the stepping algorithm of drivedyn's compiled engine, transcribed
statement for statement in Python.

drivedyn steps in one compiled loop (``drivedyn.solver.step_loop.run_steps`` with the Newton
iterations of ``drivedyn.solver.newton_kernel``). This module is the same algorithm in
Python: :class:`ReferenceStepper` (predictor, Newton iterations, factorisations, convergence
and stagnation tests of one step) and :func:`python_loop` (error estimate, step-size control,
commits, energy account, outputs). :func:`reference_runs` makes ``simulate`` run with them,
so a test can compare the engine with its oracle bit for bit (``test_step_loop.py``). A
change to the algorithm goes into both.
"""

from __future__ import annotations

import contextlib
import importlib
from collections.abc import Iterator

import numpy as np

from drivedyn.elements.framework.contract import MODE_DYN
from drivedyn.model.model import State
from drivedyn.solver.factor_frames import choose_frames, from_frames, to_frames
from drivedyn.solver.newton_kernel import (
    EPS,
    EXCESS_MAX,
    F_FORCE,
    F_LU_H,
    FLOOR_REL,
    H_REUSE,
    I_EXCESS,
    I_LU,
    I_NFAC,
    I_ROFF,
    NOISE_FACTOR,
    REFACTOR_AFTER,
    ROUNDOFF_ULPS,
    SLOW_CONTRACTION,
    STALL_ULPS,
    absmax,
    correction_size,
    newton_update,
    predict,
    residual_norms,
    roundoff_levels,
)
from drivedyn.solver.settings import StepOutcome, StepStatus
from drivedyn.solver.step_control import (
    CS_IOUT,
    CT_TEND,
    accept_step,
    next_step,
    reject_step,
    step_error,
)
from drivedyn.solver.stepper import Stepper, _worst, scaled_residual
from drivedyn.solver.system import lie_update, tangents

# the module of the resumable run that simulate advances
sim = importlib.import_module("drivedyn.solver.simulation")


class ReferenceStepper(Stepper):
    """:class:`~drivedyn.solver.stepper.Stepper` with the step in Python (:meth:`step`)."""

    _prev_t: float | None = None  # time of the state before the accepted one (None: none)

    def __init__(self, *args, **kw) -> None:
        super().__init__(*args, **kw)
        # pseudo-accelerations of the state before the accepted one (the error estimate's
        # history; the compiled loop keeps its own, StepLoop.prev_a)
        self._prev_a = np.zeros(self.model.nd)

    @property
    def lu_h(self) -> float | None:
        """Step size the current factorisation was built for (None: none)."""
        return float(self._fstate[F_LU_H]) if self._istate[I_LU] else None

    @property
    def force_scale(self) -> float:
        """Largest sum of absolute contributions of the node equations of an accepted state
        (the floor of the residual scales)."""
        return float(self._fstate[F_FORCE])

    def invalidate(self) -> None:
        """Forget the factorisation (after an event that changes the matrix a lot)."""
        self._forget()

    def accepted(self, sn: State) -> None:
        """Tell the stepper that the step from ``sn`` was accepted (for the predictor)."""
        self._prev_t = sn.t
        self._prev_vd[:] = sn.vd
        self._prev_a[:] = sn.a

    def _roundoff(self, st: State, xmax: float) -> tuple[np.ndarray, bool]:
        """Round-off levels of the residual at ``st`` for the factorisation, computed once
        per factorisation, when needed, from the matrix without inertia and damping (cM =
        cC = 0: those terms act through the increments, which carry no position round-off;
        ``sys.data`` holds it afterwards); zeros without a factorisation. Returns (levels,
        whether ``sys.data`` was reassembled)."""
        if self._istate[I_LU] and not self._istate[I_ROFF]:
            m = self.model
            tangents(self.hdq, m.nn, self.sys.Tn)
            self.sys.evaluate(st, 0.0, 0.0, 1.0, MODE_DYN, True)
            roundoff_levels(self.sys.data, m.indices, m.indptr, m.nd, xmax, st.lam,
                            ROUNDOFF_ULPS, self.roff)
            self._istate[I_ROFF] = 1
            return self.roff, True
        return self.roff, False

    def _evaluate(self, st: State, cM: float, cC: float, want: bool) -> bool:
        """Residual at ``st``, with the iteration matrix if ``want`` (the next iteration
        factorises: one evaluation gives both, instead of a residual now and residual and
        matrix again in :meth:`_factor`); returns ``want``."""
        if want:
            tangents(self.hdq, self.model.nn, self.sys.Tn)
        self.sys.evaluate(st, cM, cC, 1.0, MODE_DYN, want)
        return want

    def _factor(self, st: State, h: float, assembled: bool = False) -> StepOutcome | None:
        """Factorise the iteration matrix at ``st`` (assembled already if ``assembled``)."""
        sys = self.sys
        if not assembled:
            tangents(self.hdq, self.model.nn, sys.Tn)
            sys.evaluate(st, 1.0 / (self.bp * h * h), self.gp / (self.bp * h), 1.0, MODE_DYN,
                         True)
        try:
            sys.factor(self.lin)
        except (np.linalg.LinAlgError, ValueError) as exc:
            self._forget()
            return StepOutcome(StepStatus.SINGULAR, message=str(exc))
        self._istate[I_LU] = 1
        self._istate[I_ROFF] = 0  # computed from this matrix when Newton first stagnates on it
        self._istate[I_EXCESS] = 0
        self._fstate[F_LU_H] = h
        self._istate[I_NFAC] += 1
        m = self.model
        choose_frames(sys.data, m.indices, m.indptr, st.R, self.frames)
        return None

    def _solve(self, st: State) -> np.ndarray:
        """The correction for the residual at ``st`` with the factorisation at hand, in the
        node frames it was taken in (:mod:`~drivedyn.solver.factor_frames`)."""
        b = -self.sys.r
        to_frames(b, st.R, self.frames)
        delta = self.lin.solve(b)
        from_frames(delta, st.R, self.frames)
        return delta

    def step(self, sn: State, h: float) -> StepOutcome:
        """Attempt the step from ``sn`` to ``sn.t + h``; the result is left in ``self.trial``
        (converged or not). ``sn`` is not modified."""
        m = self.model
        nd = m.nd
        nw = self.newton
        sys = self.sys
        st = self.trial
        am, af, gamma, beta = self.am, self.af, self.gamma, self.beta
        st.assign(sn)
        st.t = sn.t + h
        # predictor: accelerations extrapolated linearly from the last two accepted steps
        # (constant at the start): halves the Newton iterations on smooth motion
        w = 0.0
        if self._prev_t is not None and sn.t > self._prev_t and self._prev_vd.shape == sn.vd.shape:
            w = min(h / (sn.t - self._prev_t), 1.0)
        hdq = self.hdq
        predict(sn.vd, sn.a, sn.v, self._prev_vd, w, h, af, am, gamma, beta, st.vd, st.a, st.v,
                hdq)
        lie_update(sn.x, sn.R, hdq, m.nn, st.x, st.R, sys.Tn, False)
        # a factorisation for a step size within H_REUSE of h still converges
        # well; the contraction monitor below refactors if it does not
        if self.lu_h is not None and abs(self.lu_h - h) > H_REUSE * h:
            self._forget()
        full = nw.strategy == "full"
        cM = 1.0 / (self.bp * h * h)
        cC = self.gp / (self.bp * h)
        ca = (1.0 - af) / (1.0 - am) * cM
        # without a factorisation the first iteration factorises (the predictor itself
        # converges in about 2 % of the steps)
        assembled = self._evaluate(st, cM, cC, full or self.lu_h is None)
        nfac0 = self.factorizations
        prev = np.inf
        fresh = False
        since_factor = 0
        worst, wval = -1, 0.0
        kscale = sys.kscale
        xmax = absmax(st.x)
        last = np.inf
        stale = False
        worst = 0.0  # the largest contraction ratio of this step's corrections
        for it in range(nw.max_iter + 1):
            rq_max, ph_max, finite = residual_norms(sys.r, sys.rabs, kscale, nd, FLOOR_REL,
                                                    self._no_roff, self.force_scale)
            if not finite:
                return StepOutcome(StepStatus.NONFINITE, it, self.factorizations - nfac0,
                                   message="non-finite residual")
            if (rq_max > nw.tol or ph_max > nw.phi_tol) and last <= STALL_ULPS * EPS:
                # Newton stagnates at the round-off of the positions: the part of the
                # residual that a round-off change of the unknowns produces (a stiff
                # constraint or contact turning the last bit of a position into a force)
                # cannot be reduced; the rest must still meet the criteria. A step is never
                # accepted on the size of the correction alone.
                roff, evaluated = self._roundoff(st, xmax)
                assembled = assembled and not evaluated
                rq_max, ph_max, _ = residual_norms(sys.r, sys.rabs, kscale, nd, FLOOR_REL,
                                                   roff, self.force_scale)
            if rq_max <= nw.tol and ph_max <= nw.phi_tol:
                if stale and self.factorizations != nfac0:
                    # no contraction on this step's own factorisation: an event (contact,
                    # stick-slip) within the step (newton_kernel's note on the deferral)
                    self._forget()
                elif self.factorizations == nfac0 and it > 1:
                    # converged, but slowly, on a factorisation from an earlier step: it is
                    # stale (contacts or gear flanks changed since), or its extra iterations
                    # add up to a factorisation's price; refresh it next step
                    self._istate[I_EXCESS] += it - 1
                    if ((it >= 3 and worst > SLOW_CONTRACTION)
                            or self._istate[I_EXCESS] >= EXCESS_MAX):
                        self._forget()
                if nd:
                    self._fstate[F_FORCE] = max(self.force_scale, float(sys.rabs[:nd].max()))
                if self.lu_h is not None:
                    # the closing correction (newton_kernel's note on it)
                    delta = self._solve(st)
                    newton_update(delta, nd, hdq, st.vd, st.a, st.v, st.lam, cM, ca, cC)
                    lie_update(sn.x, sn.R, hdq, m.nn, st.x, st.R, sys.Tn, False)
                return StepOutcome(StepStatus.SUCCESS, it, self.factorizations - nfac0)
            if it == nw.max_iter:
                break
            if stale:  # newton_kernel's note on the deferred refresh
                self._forget()
                stale = False
            # modified Newton: a factorisation that needed several iterations already is
            # stale (the configuration moved on); refresh it rather than creep along
            if full or self.lu_h is None or since_factor >= REFACTOR_AFTER:
                out = self._factor(st, h, assembled)
                if out is not None:
                    out.iterations = it
                    out.factorizations = self.factorizations - nfac0
                    return out
                fresh = True
                since_factor = 0
            since_factor += 1
            delta = self._solve(st)
            nrm, finite = newton_update(delta, nd, hdq, st.vd, st.a, st.v, st.lam, cM, ca, cC)
            if not finite:
                return StepOutcome(StepStatus.NONFINITE, it, self.factorizations - nfac0,
                                   message="non-finite Newton correction")
            ratio = nrm / prev if 0.0 < prev < np.inf else 0.0
            worst = max(worst, ratio)
            last = correction_size(delta, nd, xmax)
            if it > 0 and ratio > nw.contraction:
                # within the round-off noise a growing correction is not divergence
                if ratio > 2.0 and fresh and last > NOISE_FACTOR * STALL_ULPS * EPS:
                    sq, sphi = scaled_residual(sys)
                    worst, wval = _worst(sys, sq, sphi)
                    return StepOutcome(StepStatus.NEWTON_DIVERGED, it + 1,
                                       self.factorizations - nfac0, worst_eq=worst,
                                       residual=wval, message="corrections grow")
                stale = True  # refactor at the next iteration unless it has converged
            prev = nrm if nrm > 0 else prev
            fresh = False
            lie_update(sn.x, sn.R, hdq, m.nn, st.x, st.R, sys.Tn, False)
            # the matrix with the residual when the next iteration factorises for certain
            # (no factorisation); not after a correction that did not contract or after
            # three iterations on one factorisation, where the next check often converges
            assembled = self._evaluate(st, cM, cC, full or self.lu_h is None)
        sq, sphi = scaled_residual(sys)
        worst, wval = _worst(sys, sq, sphi)
        return StepOutcome(StepStatus.NEWTON_MAX_ITER, nw.max_iter, self.factorizations - nfac0,
                           worst_eq=worst, residual=wval)


class PythonLoop:
    """Stands in for ``StepLoop`` in :func:`reference_runs`: the run's pieces for
    :func:`python_loop`."""

    buffered = False

    def __init__(self, stepper, st, touts, ctl, cs, energy, every, buffered=True,
                 selection=None) -> None:
        self.stepper, self.st, self.touts = stepper, st, touts
        self.ctl, self.cs, self.energy = ctl, cs, energy
        self.t_end = float(ctl[CT_TEND])

    def forget_history(self) -> None:
        self.stepper._prev_t = None

    def retarget(self, touts, t_end: float) -> None:
        self.touts, self.t_end = touts, t_end
        self.ctl[CT_TEND] = t_end
        self.cs[CS_IOUT] = 0.0

    @classmethod
    def create(cls, *args, **kw) -> PythonLoop:
        return cls(*args, **kw)

    def flush(self, rec) -> int:
        return 0

    def add_stats(self, stats) -> None:
        return None


def python_loop(loop: PythonLoop, model, st: State, rec, stats, progress,
                debug: bool, trace=None) -> tuple[bool, str]:
    """simulate's stepping loop in Python, one :meth:`ReferenceStepper.step` per attempt;
    returns (success, message)."""
    stepper, touts, ctl, cs, energy = loop.stepper, loop.touts, loop.ctl, loop.cs, loop.energy
    while True:
        h_try = next_step(cs, ctl, st.t, touts)
        if h_try == 0.0:
            return True, ""
        out: StepOutcome = stepper.step(st, h_try)
        stats.newton_iterations += out.iterations
        err = 0.0
        if out.ok:
            pt = stepper._prev_t
            err, ierr = step_error(ctl, stepper.trial.a, st.a, stepper._prev_a, stepper.hdq,
                                   h_try, st.t - pt if pt is not None and st.t > pt else 0.0)
            out.error, out.worst_eq = float(err), int(ierr)
            if err > 1.0:
                out.status = StepStatus.ERROR_TOO_LARGE
                out.residual = float(err)
        if out.ok:
            trial = stepper.trial
            for g in model.groups:
                if g.commit is not None:
                    g.commit(g, trial)
            energy.advance(h_try)
            stepper.accepted(st)
            st.assign(trial)
            stats.steps += 1
            stats.h_min_used = min(stats.h_min_used, h_try)
            stats.h_max_used = max(stats.h_max_used, h_try)
            t, landed = accept_step(cs, ctl, st.t, h_try, err, out.iterations, touts)
            st.t = float(t)
            if landed:
                rec.record(st, h_try)
            if stepper.sys.redundancy_restore(st, st.t):
                stepper.invalidate()  # rows given back
            if debug:
                sim._log_attempt(model, st.t, h_try, out)
            if trace is not None:
                trace(st.t, h_try, out)
            if progress is not None:
                progress(st.t, h_try, stats.steps)
            continue
        if out.status is StepStatus.SINGULAR and stepper.sys.redundancy_on_singular(
                stepper.trial, st.t + h_try):
            stepper.invalidate()  # constraint rows set aside: the same attempt again
            continue
        if debug:
            sim._log_attempt(model, st.t, h_try, out)
        if trace is not None:
            trace(st.t, h_try, out)
        stats.rejected += 1
        stepper.invalidate()
        if reject_step(cs, ctl, st.t, h_try, err, out.status is StepStatus.ERROR_TOO_LARGE):
            message = sim._failure_message(model, st.t, h_try, out)
            sim.log.error(message)
            return False, message


@contextlib.contextmanager
def reference_runs(monkeypatch) -> Iterator[None]:
    """Within the block, ``simulate`` steps with the oracle (:class:`ReferenceStepper` and
    :func:`python_loop`) instead of the compiled engine."""
    with monkeypatch.context() as mp:
        mp.setattr(sim, "Stepper", ReferenceStepper)
        mp.setattr(sim, "StepLoop", PythonLoop)
        mp.setattr(sim, "_run_loop", python_loop)
        yield
