"""Static equilibrium: ``f_int(q) + Phi_q^T (k lam + p Phi) = f_ext(t)``, ``Phi(q) = 0``.

Newton on the same residual as the dynamics with zero velocities and accelerations
(``cM = cC = 0``); position corrections are applied as ``x += dx``, ``R <- R exp(dtheta)``.
A backtracking line search on the residual norm keeps large first corrections safe.
Drivers hold their prescribed values at time ``t``, so this is also the kinetostatic
analysis of a driven mechanism at one instant.
"""

from __future__ import annotations

import numpy as np

from drivedyn.elements.framework.contract import MODE_DYN
from drivedyn.model.model import Model, State
from drivedyn.rotations import exp_so3
from drivedyn.solver.linear import LinearSolver, default_linear_solver
from drivedyn.solver.newton_kernel import STALL_ULPS, correction_size
from drivedyn.solver.settings import Newton
from drivedyn.solver.stepper import scaled_residual
from drivedyn.solver.system import System


class StaticsError(RuntimeError):
    """Static equilibrium not found; the message names the worst equation."""


def _apply(st: State, base: State, dx: np.ndarray, nn: int) -> None:
    st.x[:nn] = base.x[:nn] + dx.reshape(nn, 6)[:, :3]
    for i in range(nn):
        st.R[i] = base.R[i] @ exp_so3(dx[6 * i + 3 : 6 * i + 6])


def _block_norms(delta: np.ndarray, nd: int) -> tuple[float, float]:
    """Norms of the position part and of the multiplier part of a Newton correction."""
    return float(np.linalg.norm(delta[:nd])), float(np.linalg.norm(delta[nd:]))


def solve_static(model: Model, state: State | None = None, t: float = 0.0,
                 newton: Newton | None = None, max_iter: int = 50,
                 linear_solver: LinearSolver | None = None) -> State:
    """Static equilibrium at time ``t`` [s] from ``state`` (default initial state).

    Returns the equilibrium :class:`State` (velocities and accelerations zero, multipliers
    and element states set). Raises :class:`StaticsError` if Newton does not converge.
    """
    nw = newton or Newton(strategy="full")
    st = (state or model.initial_state()).copy()
    st.t = t
    st.v[:] = 0.0
    st.vd[:] = 0.0
    st.a[:] = 0.0
    sys = System(model)
    sys.detect_redundancy(st)
    sys.reset_tangent()
    lin = linear_solver or default_linear_solver(model.neq)
    nd, nn = model.nd, model.nn
    trial = st.copy()
    # corrections at round-off of the unknowns' own scales (newton_kernel.correction_size)
    stall = STALL_ULPS * np.finfo(float).eps
    xmax = float(np.abs(st.x).max())
    last = np.inf
    for _ in range(max_iter):
        sys.evaluate(st, 0.0, 0.0, 1.0, MODE_DYN, True)
        sq, sphi = scaled_residual(sys)
        rq_max = sq.max() if sq.size else 0.0
        ph_max = sphi.max() if sphi.size else 0.0
        if rq_max <= nw.tol and ph_max <= nw.phi_tol:
            for g in model.groups:
                if g.commit is not None:
                    g.commit(g, st)
            return st
        if last <= stall:  # corrections at round-off of the positions: converged
            for g in model.groups:
                if g.commit is not None:
                    g.commit(g, st)
            return st
        try:
            sys.factor(lin)
        except np.linalg.LinAlgError as exc:
            raise StaticsError(f"singular stiffness matrix ({exc}): the mechanism has a free "
                               "motion with no stiffness; constrain or drive it") from None
        delta = lin.solve(-sys.r)
        last = correction_size(delta, nd, xmax) if nd else 0.0
        # round-off floors of the two blocks: a block whose correction is already at
        # round-off (positions held by drivers, multipliers of a linear problem) does not vote
        # (the position block mixes metres and radians: the larger round-off of the two)
        floors = (stall * max(1.0, xmax), stall * max(1.0, float(np.abs(st.lam).max(
            initial=0.0)), float(np.abs(delta[nd:]).max(initial=0.0))))
        norm0 = _block_norms(delta, nd)
        alpha = 1.0
        for _ls in range(12):
            trial.assign(st)
            _apply(trial, st, alpha * delta[:nd], nn)
            trial.lam[:] = st.lam + alpha * delta[nd:]
            sys.evaluate(trial, 0.0, 0.0, 1.0, MODE_DYN, False)
            # natural monotonicity test (Deuflhard): the simplified Newton correction at the
            # trial point, with the same factorisation, must shrink, in the positions and in
            # the multipliers. Affine invariant, unlike the residual norm, whose rows mix
            # forces, moments and constraint violations of any scale (a beam's first step
            # raises its axial forces while it converges)
            nxt = lin.solve(-sys.r)
            shrinks = np.all(np.isfinite(nxt)) and all(
                n1 <= max((1.0 - 0.25 * alpha) * n0, 10.0 * f)
                for n0, n1, f in zip(norm0, _block_norms(nxt, nd), floors, strict=True))
            if shrinks or alpha < 1e-3:
                break
            alpha *= 0.5
        st.assign(trial)
    sys.evaluate(st, 0.0, 0.0, 1.0, MODE_DYN, False)
    sq, sphi = scaled_residual(sys)
    worst = int(np.argmax(np.concatenate([sq, sphi])))
    raise StaticsError(f"static equilibrium not found in {max_iter} iterations; worst "
                       f"equation: {model.eq_labels[worst]}")
