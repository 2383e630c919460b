"""One step of the Lie-group generalized-alpha scheme with Newton iterations.

Scheme (Arnold & Bruls 2007; Bruls, Cardona & Arnold 2012), with ``vd`` the accelerations
and ``a`` the pseudo-accelerations::

    q_n+1 = q_n o exp(h dq),   h dq = h v_n + h^2 (1/2 - beta) a_n + h^2 beta a_n+1
    v_n+1 = v_n + h (1 - gamma) a_n + h gamma a_n+1
    (1 - alpha_m) a_n+1 + alpha_m a_n = (1 - alpha_f) vd_n+1 + alpha_f vd_n
    M vd_n+1 + f(q_n+1, v_n+1, t_n+1) + Phi_q^T (k lam + p Phi) = 0,   k Phi(q_n+1) = 0

Newton unknowns are the correction ``delta`` of the Lie-algebra increment ``h dq`` and of the
multipliers. With ``beta' = beta (1 - alpha_f)/(1 - alpha_m)`` and
``gamma' = gamma (1 - alpha_f)/(1 - alpha_m)`` the corrections of the other unknowns are
``d vd = delta / (beta' h^2)`` and ``d v = gamma' delta / (beta' h)``, so the iteration
matrix is ``[M / (beta' h^2) + gamma' C / (beta' h) + K T, G^T; G T, 0]`` where ``T`` is
the tangent operator of each node's rotation increment. Working on position corrections
(not accelerations) is the scaling by ``beta' h^2`` that keeps the matrix conditioned as
``h -> 0``.
"""

from __future__ import annotations

import logging
import os
from typing import Any

import numpy as np

from drivedyn.elements.framework.contract import MODE_DYN
from drivedyn.model.model import Model, State
from drivedyn.solver import lapack
from drivedyn.solver import newton_kernel as nk
from drivedyn.solver.linear import (
    AutoLU,
    DenseLU,
    LinearSolver,
    SparseLU,
    default_linear_solver,
)
from drivedyn.solver.newton_kernel import (
    EPS,
    F_FORCE,
    F_LU_H,
    FLOOR_REL,
    H_REUSE,
    I_DENSE,
    I_EXTERNAL,
    I_LU,
    I_NEVAL,
    I_NFAC,
    I_PHASE,
    I_ROFF,
    REFACTOR_AFTER,
    ROUNDOFF_ULPS,
    STALL_ULPS,
    absmax,
    newton_update,
    predict,
    residual_norms,
    roundoff_levels,
)
from drivedyn.solver.settings import GeneralizedAlpha, Newton, StepOutcome, StepStatus
from drivedyn.solver.system import System, lie_update, tangents

log = logging.getLogger("drivedyn")


def scaled_residual(sys: System, floor_rel: float = FLOOR_REL) -> tuple[np.ndarray, np.ndarray]:
    """Per-equation scaled residuals: node equations relative to the sum of absolute
    contributions (with a floor of ``floor_rel`` x the largest), constraint rows as
    violations [m or rad]."""
    nd = sys.model.nd
    r, ra = sys.r, sys.rabs
    rq = r[:nd]
    if nd:
        floor = floor_rel * max(float(ra[:nd].max()), 1e-300)
        sq = np.abs(rq) / (ra[:nd] + floor)
    else:
        sq = np.zeros(0)
    return sq, sys.constraint_violation()


class Stepper:
    """Advances a state by one step; keeps the factorisation between steps (modified Newton).

    A step runs as one compiled call (:mod:`~drivedyn.solver.newton_kernel`) with the dense
    LU, the sparse LU and AutoLU; the Python loop of :meth:`step` is the same algorithm, kept for
    other linear solvers and ``DRIVEDYN_COMPILED_NEWTON=0``, and the reference the compiled
    one is tested against. A change to one goes into both.

    Attributes:
        lu_h: step size the current factorisation was built for (None: none).
        factorizations: factorisations so far.
    """

    def __init__(self, model: Model, integrator: GeneralizedAlpha, newton: Newton,
                 linear_solver: LinearSolver | None = None, loop: bool = False) -> None:
        self.model = model
        self.sys = System(model)
        self.integrator = integrator
        self.newton = newton
        self.lin = linear_solver or default_linear_solver(model.neq)
        self.trial = model.initial_state()
        # Newton memory, in arrays shared with the compiled step (newton_kernel): istate =
        # (factorisation valid, round-off levels valid, factorisations, evaluations), fstate =
        # (step size of the factorisation [s], force scale)
        self._istate = np.zeros(nk.NISTATE, np.int64)
        self._fstate = np.zeros(nk.NFSTATE)
        am, af, g, b = integrator.coefficients
        self.am, self.af, self.gamma, self.beta = am, af, g, b
        self.bp = b * (1.0 - af) / (1.0 - am)
        self.gp = g * (1.0 - af) / (1.0 - am)
        self.hdq = np.zeros(model.nd)
        # round-off levels of the residual for the factorised matrix (zero: none yet)
        self.roff = np.zeros(model.neq)
        self._no_roff = np.zeros(model.neq)
        self._prev_t: float | None = None  # time and accelerations of the state before sn
        self._prev_vd = np.zeros(model.nd)
        self._compiled: Any = None  # the model's compiled step (False: Python loop)
        self._par = np.array([am, af, g, b, self.bp, self.gp, newton.tol, newton.phi_tol,
                              newton.contraction, newton.max_iter,
                              1.0 if newton.strategy == "full" else 0.0, FLOOR_REL,
                              STALL_ULPS, ROUNDOFF_ULPS])
        self._delta = np.zeros(model.neq)
        # stand-ins for the factors the active solver does not use (the dense ones 2 x 2: a
        # smaller array is C- as well as F-contiguous, numba would type it as C and compile
        # another overload)
        self._no_dense = lapack.workspace(2)
        i0, f0 = np.zeros(0, np.int64), np.zeros(0)
        self._no_sparse = (np.zeros(1, np.int64), i0, f0, np.zeros(1, np.int64), i0, f0, i0,
                           i0, f0)
        # the compiled stepping loop (step_loop) will run the steps: it has its compiled step
        # inlined, and simulate hands its signature to the precompile instead
        self.loop = loop and self._compiled_allowed()
        if self._compiled_allowed() and not self.loop:
            self._precompile_with_kernels()

    @property
    def lu_h(self) -> float | None:
        """Step size the current factorisation was built for (None: none)."""
        return float(self._fstate[F_LU_H]) if self._istate[I_LU] else None

    @property
    def factorizations(self) -> int:
        """Factorisations so far."""
        return int(self._istate[I_NFAC])

    @property
    def force_scale(self) -> float:
        """Largest sum of absolute contributions of the node equations of an accepted state
        (the floor of the residual scales)."""
        return float(self._fstate[F_FORCE])

    def accepted(self, sn: State) -> None:
        """Tell the stepper that the step from ``sn`` was accepted (for the predictor)."""
        self._prev_t = sn.t
        self._prev_vd[:] = sn.vd

    def reset_history(self) -> None:
        """Forget the previous step (after an event that breaks smoothness)."""
        self._prev_t = None

    def invalidate(self) -> None:
        """Forget the factorisation (after an event that changes the matrix a lot)."""
        self._forget()

    def _forget(self) -> None:
        # the round-off levels describe the factorised matrix only
        self._istate[I_LU] = 0
        self._istate[I_ROFF] = 0
        self.roff[:] = 0.0

    def _roundoff(self, st: State) -> np.ndarray:
        """Round-off levels of the residual for the factorised matrix (``sys.data`` holds
        it until the next factorisation), computed once per factorisation, when needed;
        zeros without a factorisation."""
        if self._istate[I_LU] and not self._istate[I_ROFF]:
            m = self.model
            roundoff_levels(self.sys.data, m.indices, m.indptr, m.nd,
                            absmax(st.x) if st.x.size else 1.0, st.lam,
                            ROUNDOFF_ULPS, self.roff)
            self._istate[I_ROFF] = 1
        return self.roff

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
        self._fstate[F_LU_H] = h
        self._istate[I_NFAC] += 1
        return None

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
        if self._compiled is None:
            self._compiled = self._compiled_step(sn)
        if self._compiled:
            out = self._step_compiled(sn, h, w)
            if out is not None:
                return out
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
        stall = STALL_ULPS * EPS * max(1.0, absmax(st.x))
        last = np.inf
        stale = False
        for it in range(nw.max_iter + 1):
            rq_max, ph_max, finite = residual_norms(sys.r, sys.rabs, kscale, nd, FLOOR_REL,
                                                    self._no_roff, self.force_scale)
            if not finite:
                return StepOutcome(StepStatus.NONFINITE, it, self.factorizations - nfac0,
                                   message="non-finite residual")
            if (rq_max > nw.tol or ph_max > nw.phi_tol) and last <= stall:
                # Newton stagnates at the round-off of the positions: the part of the
                # residual that a round-off change of the unknowns produces (a stiff
                # constraint or contact turning the last bit of a position into a force)
                # cannot be reduced; the rest must still meet the criteria. A step is never
                # accepted on the size of the correction alone.
                rq_max, ph_max, _ = residual_norms(sys.r, sys.rabs, kscale, nd, FLOOR_REL,
                                                   self._roundoff(st), self.force_scale)
            if rq_max <= nw.tol and ph_max <= nw.phi_tol:
                if stale and self.factorizations != nfac0:
                    # no contraction on this step's own factorisation: an event (contact,
                    # stick-slip) within the step (newton_kernel's note on the deferral)
                    self._forget()
                elif it >= 3 and self.factorizations == nfac0:
                    # converged, but slowly, on a factorisation from an earlier step: it is
                    # stale (contacts or gear flanks changed since); refresh it next step
                    self._forget()
                if nd:
                    self._fstate[F_FORCE] = max(self.force_scale, float(sys.rabs[:nd].max()))
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
            delta = self.lin.solve(-sys.r)
            nrm, finite = newton_update(delta, nd, hdq, st.vd, st.a, st.v, st.lam, cM, ca, cC)
            if not finite:
                return StepOutcome(StepStatus.NONFINITE, it, self.factorizations - nfac0,
                                   message="non-finite Newton correction")
            ratio = nrm / prev if 0.0 < prev < np.inf else 0.0
            if it > 0 and ratio > nw.contraction:
                if ratio > 2.0 and fresh:
                    sq, sphi = scaled_residual(sys)
                    worst, wval = _worst(sys, sq, sphi)
                    return StepOutcome(StepStatus.NEWTON_DIVERGED, it + 1,
                                       self.factorizations - nfac0, worst_eq=worst,
                                       residual=wval, message="corrections grow")
                stale = True  # refactor at the next iteration unless it has converged
            prev = nrm if nrm > 0 else prev
            last = nrm
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

    def _solvers(self) -> tuple[DenseLU | None, SparseLU | None] | None:
        """(dense LU, sparse LU) of the linear solver, one of them active and the other
        None; None for a solver the compiled step cannot use."""
        lin = self.lin
        if isinstance(lin, AutoLU):
            return lin.dense, lin.sparse
        if isinstance(lin, DenseLU):
            return lin, None
        if isinstance(lin, SparseLU):
            return None, lin
        return None

    def _compiled_allowed(self) -> bool:
        """The compiled step is used unless ``DRIVEDYN_COMPILED_NEWTON=0`` or the linear
        solver is not one of the dense LU, the sparse LU and AutoLU."""
        return (os.environ.get("DRIVEDYN_COMPILED_NEWTON", "1") != "0"
                and self._solvers() is not None)

    def _state_args(self, sn: State) -> tuple:
        """The ``accepted``, ``trial`` and ``arrays`` arguments of the compiled step."""
        m, sys, st, tf = self.model, self.sys, self.trial, self.model.tf
        return ((sn.x, sn.R, sn.v, sn.vd, sn.a, self._prev_vd),
                (st.x, st.R, st.v, st.vd, st.a, st.lam, st.es, self.hdq),
                (sys.Tn, sys.r, sys.rabs, sys.data, sys.tfv, sys.kscale, tf.kind, tf.par,
                 tf.fstart, tf.tab, m.indices, m.indptr))

    def _precompile_with_kernels(self) -> None:
        """Add the compiled step, for this model's argument types, to the compilations the
        System runs in parallel worker processes before its first evaluation
        (:mod:`~drivedyn.solver.precompile`): a first run then compiles it while the kernels
        compile, not after them. Its types do not depend on the kernels' addresses."""
        from drivedyn.solver.kernel_calls import KernelTable

        m, sys, st = self.model, self.sys, self.trial
        try:
            G = KernelTable([(0, pre, post) for _k, pre, _mid, post
                             in sys._kernel_args(st, 1.0, 1.0, 1.0, MODE_DYN, True)])
            lu, piv, ib, tr = self._no_dense
            args = (G, (int(m.nn), int(m.nd), 0.0, 0.0, 1.0), *self._state_args(st),
                    (lu, piv, ib, tr, self._delta, self.roff, self._no_roff), self._no_sparse,
                    self._par, self._istate, self._fstate)
            sig = tuple(nk.newton_iterations.typeof_pyval(a) for a in args)
        except (AttributeError, TypeError, ValueError):  # not typeable: compiled on first use
            return
        sys.precompile_also.append((nk.newton_iterations, sig))

    def _compiled_step(self, sn: State) -> Any:
        """The compiled Newton iterations (:func:`~drivedyn.solver.newton_kernel.
        newton_iterations`) with the model's kernel table, or False: with the dense LU,
        the sparse LU (factorised here, between two calls) or AutoLU, and unless
        ``DRIVEDYN_COMPILED_NEWTON=0``."""
        if not self._compiled_allowed():
            return False
        sys = self.sys
        G = sys.kernel_table(sn)
        if G is None:  # kernels not compiled yet for these types: evaluate once
            sys.evaluate(sn, 0.0, 0.0, 1.0, MODE_DYN, False)
            G = sys.kernel_table(sn)
        if G is None:
            return False
        self._G = G
        self._args_of = None
        self._entries: dict[tuple, Any] = {}
        return nk.newton_iterations

    def _linear_arrays(self) -> tuple[tuple, tuple]:
        """The ``linear`` and ``sparse`` arguments of the compiled step for the active
        factors; sets the solver fields of the Newton memory."""
        dense, sparse = self._solvers()
        n = self.model.neq
        if dense is not None:
            lu, piv, ib, tr = dense.workspace(n)
            sp_args = self._no_sparse
        else:
            lu, piv, ib, tr = self._no_dense
            f = sparse._f
            sp_args = self._no_sparse if f is None else (*f, sparse._z)
        self._istate[I_EXTERNAL] = 0 if dense is not None else 1
        self._istate[I_DENSE] = 1 if dense is not None else 0
        return (lu, piv, ib, tr, self._delta, self.roff, self._no_roff), sp_args

    def _call_compiled(self, args: tuple) -> tuple[int, int, int]:
        """One call of the compiled step. The first call with given argument types goes
        through the numba dispatcher; later ones straight to the overload it chose: the
        dispatcher types every argument at every call (the kernel table, a custom type, in
        Python: about 10 us per step, 15 % of the Python around a step). The types can only
        change with the state objects (:meth:`_step_compiled` then clears the entries) or the
        linear solver's arrays (the key below)."""
        lin = self._linear_arrays()
        key = (int(self._istate[I_DENSE]), lin[1] is self._no_sparse)
        entry = self._entries.get(key)
        if entry is not None:
            return entry(*args, *lin, self._par, self._istate, self._fstate)
        full = (*args, *lin, self._par, self._istate, self._fstate)
        out = self._compiled(*full)
        try:
            sig = tuple(self._compiled.typeof_pyval(a) for a in full)
            self._entries[key] = self._compiled.overloads[sig].entry_point
        except (AttributeError, KeyError, TypeError, ValueError):  # keep the dispatcher
            self._entries[key] = self._compiled
        return out

    def _step_compiled(self, sn: State, h: float, w: float) -> StepOutcome | None:
        """:meth:`step` by the compiled Newton iterations (the trial state is ``sn``
        copied, at time ``sn.t + h``); None if the compiled step cannot be used (then it
        is not tried again). A sparse factorisation is done here when the compiled
        iteration asks for it, and the iteration resumes."""
        m = self.model
        sys = self.sys
        st = self.trial
        n0 = int(self._istate[I_NEVAL])
        if sn is not self._args_of:  # the argument tuples of these states (built once)
            self._args_of = sn
            self._args = self._state_args(sn)
            self._entries = {}
        args = (self._G, (m.nn, m.nd, w, st.t, h), *self._args)
        self._istate[I_PHASE] = 0
        try:
            code, it, nfac = self._call_compiled(args)
        except Exception as exc:  # not compilable for these argument types: Python loop
            log.warning("compiled Newton step unavailable, using the Python loop (%s)", exc)
            self._compiled = False
            self._istate[I_PHASE] = 0
            st.assign(sn)
            st.t = sn.t + h
            return None
        while code == nk.NEED_FACTOR:
            try:
                sys.factor(self.lin)
            except (np.linalg.LinAlgError, ValueError) as exc:
                self._istate[I_PHASE] = 0
                self._forget()
                sys.nevals += int(self._istate[I_NEVAL]) - n0
                return StepOutcome(StepStatus.SINGULAR, it, nfac, message=str(exc))
            code, it, nfac = self._call_compiled(args)
        sys.nevals += int(self._istate[I_NEVAL]) - n0
        return self.outcome_of(code, it, nfac)

    def outcome_of(self, code: int, it: int, nfac: int) -> StepOutcome:
        """The :class:`StepOutcome` of a compiled step's code (newton_kernel), with the
        worst equation of the last residual for a step Newton did not converge."""
        sys = self.sys
        if code == nk.SUCCESS:
            return StepOutcome(StepStatus.SUCCESS, it, nfac)
        if code == nk.NONFINITE_RESIDUAL:
            return StepOutcome(StepStatus.NONFINITE, it, nfac, message="non-finite residual")
        if code == nk.NONFINITE_CORRECTION:
            return StepOutcome(StepStatus.NONFINITE, it, nfac,
                               message="non-finite Newton correction")
        if code == nk.SINGULAR:
            return StepOutcome(StepStatus.SINGULAR, it, nfac, message="singular matrix")
        sq, sphi = scaled_residual(sys)
        worst, wval = _worst(sys, sq, sphi)
        if code == nk.DIVERGED:
            return StepOutcome(StepStatus.NEWTON_DIVERGED, it, nfac, worst_eq=worst,
                               residual=wval, message="corrections grow")
        return StepOutcome(StepStatus.NEWTON_MAX_ITER, it, nfac, worst_eq=worst, residual=wval)


def _worst(sys: System, sq: np.ndarray, sphi: np.ndarray) -> tuple[int, float]:
    """Index and size of the worst equation (node equations first, then constraints)."""
    iq = int(np.argmax(sq)) if sq.size else -1
    ip = int(np.argmax(sphi)) if sphi.size else -1
    vq = float(sq[iq]) if iq >= 0 else 0.0
    vp = float(sphi[ip]) if ip >= 0 else 0.0
    if vp > vq and ip >= 0:
        return sys.model.nd + ip, vp
    return iq, vq
