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


@njit(cache=True)
def residual_norms(r, rabs, kscale, nd, floor_rel):
    """Largest scaled node residual and constraint violation (see :func:`scaled_residual`);
    returns (rq_max, phi_max, finite)."""
    amax = 1e-300
    for i in range(nd):
        if rabs[i] > amax:
            amax = rabs[i]
    floor = floor_rel * amax
    rq = 0.0
    finite = True
    for i in range(nd):
        v = abs(r[i]) / (rabs[i] + floor)
        if not np.isfinite(v):
            finite = False
        if v > rq:
            rq = v
    ph = 0.0
    for i in range(nd, r.shape[0]):
        v = abs(r[i]) / kscale[i]
        if not np.isfinite(v):
            finite = False
        if v > ph:
            ph = v
    return rq, ph, finite


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
        self.lu_h = None

    def _factor(self, st: State, h: float) -> StepOutcome | None:
        sys = self.sys
        tangents(self.hdq, self.model.nn, sys.Tn)
        sys.evaluate(st, 1.0 / (self.bp * h * h), self.gp / (self.bp * h), 1.0, MODE_DYN, True)
        try:
            sys.factor(self.lin)
        except (np.linalg.LinAlgError, ValueError) as exc:
            self.lu_h = None
            return StepOutcome(StepStatus.SINGULAR, message=str(exc))
        self.lu_h = h
        self.factorizations += 1
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
        if self._prev_t is not None and sn.t > self._prev_t and self._prev_vd.shape == sn.vd.shape:
            w = h / (sn.t - self._prev_t)
            st.vd[:] = sn.vd + min(w, 1.0) * (sn.vd - self._prev_vd)
        else:
            st.vd[:] = sn.vd
        st.a[:] = (af * sn.vd + (1.0 - af) * st.vd - am * sn.a) / (1.0 - am)
        st.v[:] = sn.v + h * ((1.0 - gamma) * sn.a + gamma * st.a)
        hdq = self.hdq
        hdq[:] = h * sn.v + h * h * ((0.5 - beta) * sn.a + beta * st.a)
        lie_update(sn.x, sn.R, hdq, m.nn, st.x, st.R, sys.Tn, False)
        # a factorisation for a slightly different h (output-time clipping) still converges
        # well; the contraction monitor below refactors if it does not
        if self.lu_h is not None and abs(self.lu_h - h) > 1e-2 * h:
            self.lu_h = None
        full = nw.strategy == "full"
        cM = 1.0 / (self.bp * h * h)
        cC = self.gp / (self.bp * h)
        ca = (1.0 - af) / (1.0 - am) * cM
        sys.evaluate(st, cM, cC, 1.0, MODE_DYN, False)
        nfac0 = self.factorizations
        prev = np.inf
        fresh = False
        since_factor = 0
        worst, wval = -1, 0.0
        kscale = sys.kscale
        stall = 64.0 * np.finfo(float).eps * max(1.0, float(np.abs(st.x).max()))
        last = np.inf
        for it in range(nw.max_iter + 1):
            rq_max, ph_max, finite = residual_norms(sys.r, sys.rabs, kscale, nd, FLOOR_REL)
            if not finite:
                return StepOutcome(StepStatus.NONFINITE, it, self.factorizations - nfac0,
                                   message="non-finite residual")
            if rq_max <= nw.tol and ph_max <= nw.phi_tol:
                if it >= 3 and self.factorizations == nfac0:
                    # converged, but slowly, on a factorisation from an earlier step: it is
                    # stale (contacts or gear flanks changed since); refresh it next step
                    self.lu_h = None
                return StepOutcome(StepStatus.SUCCESS, it, self.factorizations - nfac0)
            if it > 0 and last <= stall:
                # the correction is at round-off of the positions: nothing left to gain
                return StepOutcome(StepStatus.SUCCESS, it, self.factorizations - nfac0)
            if it == nw.max_iter:
                break
            # modified Newton: a factorisation that needed several iterations already is
            # stale (the configuration moved on); refresh it rather than creep along
            if full or self.lu_h is None or since_factor >= 3:
                out = self._factor(st, h)
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
            ratio = nrm / prev if prev > 0 and np.isfinite(prev) else 0.0
            if it > 0 and ratio > nw.contraction:
                if ratio > 2.0 and fresh:
                    sq, sphi = scaled_residual(sys)
                    worst, wval = _worst(sys, sq, sphi)
                    return StepOutcome(StepStatus.NEWTON_DIVERGED, it + 1,
                                       self.factorizations - nfac0, worst_eq=worst,
                                       residual=wval, message="corrections grow")
                self.lu_h = None  # refactor at the next iteration
            prev = nrm if nrm > 0 else prev
            last = nrm
            fresh = False
            lie_update(sn.x, sn.R, hdq, m.nn, st.x, st.R, sys.Tn, False)
            sys.evaluate(st, cM, cC, 1.0, MODE_DYN, False)
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
