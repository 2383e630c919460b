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

import numpy as np
from numba import njit

from drivedyn.elements.base import MODE_DYN
from drivedyn.model.model import Model, State
from drivedyn.solver.assembly import System, lie_update, tangents
from drivedyn.solver.linear import LinearSolver, default_linear_solver
from drivedyn.solver.settings import GeneralizedAlpha, Newton, StepOutcome, StepStatus

# Residual of an equation is measured against the sum of the absolute values of its terms;
# for an equation with (nearly) no terms of its own, against FLOOR_REL x the largest such sum
# in the model (the accuracy a solve can deliver there is set by the model's force scale).
FLOOR_REL = 1e-4


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


# Round-off of the unknowns, in units of the machine epsilon: the Lie update and the solve
# leave each coordinate (and multiplier) uncertain by a few ulps of its magnitude.
ROUNDOFF_ULPS = 16.0
# Newton stagnates when its correction is below this many ulps of the largest coordinate
STALL_ULPS = 64.0


@njit(cache=True)
def residual_norms(r, rabs, kscale, nd, floor_rel, roff, amin=0.0):
    """Largest scaled node residual and constraint violation beyond the round-off level
    ``roff`` of each equation (see :func:`roundoff_levels`; zeros for none); returns
    (rq_max, phi_max, finite). Node equations are scaled as in :func:`scaled_residual`,
    constraint rows are violations [m or rad]."""
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
    ``eps_j = ulps eps max(1, xmax)`` for the position increments and ``ulps eps |lam_j|``
    for the multipliers. A residual below it cannot be reduced in floating point (a stiff
    constraint or contact turns the last bit of a position into a large force), so it is not
    counted against the tolerance. ``out`` (neq,) receives the levels."""
    eps = 2.220446049250313e-16
    ex = ulps * eps * max(1.0, xmax)
    out[:] = 0.0
    for j in range(indptr.shape[0] - 1):
        ej = ex if j < nd else ulps * eps * abs(lam[j - nd])
        for k in range(indptr[j], indptr[j + 1]):
            out[indices[k]] += abs(data[k]) * ej


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


class Stepper:
    """Advances a state by one step; keeps the factorisation between steps (modified Newton).

    Attributes:
        lu_h: step size the current factorisation was built for (None: none).
        factorizations: factorisations so far.
    """

    def __init__(self, model: Model, integrator: GeneralizedAlpha, newton: Newton,
                 linear_solver: LinearSolver | None = None) -> None:
        self.model = model
        self.sys = System(model)
        self.integrator = integrator
        self.newton = newton
        self.lin = linear_solver or default_linear_solver(model.neq)
        self.trial = model.initial_state()
        self.lu_h: float | None = None
        self.factorizations = 0
        am, af, g, b = integrator.coefficients
        self.am, self.af, self.gamma, self.beta = am, af, g, b
        self.bp = b * (1.0 - af) / (1.0 - am)
        self.gp = g * (1.0 - af) / (1.0 - am)
        self.hdq = np.zeros(model.nd)
        self.force_scale = 0.0
        # round-off levels of the residual for the factorised matrix (zero: none yet)
        self.roff = np.zeros(model.neq)
        self._roff_at: float | None = None
        self._no_roff = np.zeros(model.neq)
        self._prev_t: float | None = None  # time and accelerations of the state before sn
        self._prev_vd = np.zeros(model.nd)

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
        self.lu_h = None
        self.roff[:] = 0.0
        self._roff_at = None

    def _roundoff(self, st: State) -> np.ndarray:
        """Round-off levels of the residual for the factorised matrix (``sys.data`` holds
        it until the next factorisation), computed once per factorisation, when needed;
        zeros without a factorisation."""
        if self.lu_h is not None and self._roff_at is None:
            m = self.model
            roundoff_levels(self.sys.data, m.indices, m.indptr, m.nd,
                            absmax(st.x) if st.x.size else 1.0, st.lam,
                            ROUNDOFF_ULPS, self.roff)
            self._roff_at = self.lu_h
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
        self.lu_h = h
        self.factorizations += 1
        self._roff_at = None  # computed from this matrix when Newton first stagnates on it
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
        hdq = self.hdq
        predict(sn.vd, sn.a, sn.v, self._prev_vd, w, h, af, am, gamma, beta, st.vd, st.a, st.v,
                hdq)
        lie_update(sn.x, sn.R, hdq, m.nn, st.x, st.R, sys.Tn, False)
        # a factorisation for a slightly different h (output-time clipping) still converges
        # well; the contraction monitor below refactors if it does not
        if self.lu_h is not None and abs(self.lu_h - h) > 1e-2 * h:
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
                if it >= 3 and self.factorizations == nfac0:
                    # converged, but slowly, on a factorisation from an earlier step: it is
                    # stale (contacts or gear flanks changed since); refresh it next step
                    self._forget()
                if nd:
                    self.force_scale = max(self.force_scale, float(sys.rabs[:nd].max()))
                return StepOutcome(StepStatus.SUCCESS, it, self.factorizations - nfac0)
            if it == nw.max_iter:
                break
            # modified Newton: a factorisation that needed several iterations already is
            # stale (the configuration moved on); refresh it rather than creep along
            if full or self.lu_h is None or since_factor >= 3:
                out = self._factor(st, h, assembled)
                if out is not None:
                    out.iterations = it
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
                self._forget()  # refactor at the next iteration
            prev = nrm if nrm > 0 else prev
            last = nrm
            fresh = False
            lie_update(sn.x, sn.R, hdq, m.nn, st.x, st.R, sys.Tn, False)
            # the matrix with the residual when the next iteration factorises for certain
            # (a correction that did not contract); not after three iterations on one
            # factorisation, where the next check often converges
            assembled = self._evaluate(st, cM, cC, full or self.lu_h is None)
        sq, sphi = scaled_residual(sys)
        worst, wval = _worst(sys, sq, sphi)
        return StepOutcome(StepStatus.NEWTON_MAX_ITER, nw.max_iter, self.factorizations - nfac0,
                           worst_eq=worst, residual=wval)

    def error_estimate(self, sn: State, h: float, rtol: float, atol: float) -> tuple[float, int]:
        """Weighted max norm of the local position error estimate of the last trial step
        and the dof where it is largest (-1 if there are no dofs)."""
        e = abs(self.beta - 1.0 / 6.0) * h * h * np.abs(self.trial.a - sn.a)
        w = atol + rtol * np.abs(self.hdq)
        if not e.size:
            return 0.0, -1
        q = e / w
        i = int(np.argmax(q))
        return float(q[i]), i


def _worst(sys: System, sq: np.ndarray, sphi: np.ndarray) -> tuple[int, float]:
    """Index and size of the worst equation (node equations first, then constraints)."""
    iq = int(np.argmax(sq)) if sq.size else -1
    ip = int(np.argmax(sphi)) if sphi.size else -1
    vq = float(sq[iq]) if iq >= 0 else 0.0
    vp = float(sphi[ip]) if ip >= 0 else 0.0
    if vp > vq and ip >= 0:
        return sys.model.nd + ip, vp
    return iq, vq
