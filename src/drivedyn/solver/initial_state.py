"""The consistent initial state of a run: positions on the position constraints, velocities
that satisfy the velocity constraints, accelerations and multipliers from the equations of
motion (used by
:class:`~drivedyn.solver.simulation.Simulation` before its first step)."""

from __future__ import annotations

import numpy as np

from drivedyn.elements.framework.contract import MODE_ACC, MODE_DYN, MODE_VEL
from drivedyn.model.model import Model, State
from drivedyn.solver.linear import LinearSolver, default_linear_solver
from drivedyn.solver.newton_kernel import FLOOR_REL, residual_norms
from drivedyn.solver.system import System, lie_update


class InitializationError(RuntimeError):
    """The initial state cannot be made consistent (singular constraint Jacobian or mass)."""


def consistent_initial_state(model: Model, st: State, sys: System | None = None,
                             linear_solver: LinearSolver | None = None,
                             project_velocities: bool = True,
                             phi_tol: float | None = None) -> State:
    """Bring the positions onto the bilateral position constraints to ``phi_tol`` [m or rad]
    (:func:`project_positions`; None: no projection), make velocities satisfy the velocity
    constraints (M-orthogonal projection) and compute accelerations and multipliers from the
    equations of motion and the acceleration-level constraints
    ``Phi_q vd + v^T H v + Phi_tt = 0``. Modifies and returns ``st``.

    Constraint rows that are combinations of the others at ``st`` are found first and set
    aside (:meth:`~drivedyn.solver.system.System.detect_redundancy`): their multipliers are
    zero, the motion is that of the full set."""
    sys = sys or System(model)
    lin = linear_solver or default_linear_solver(model.neq)
    nd = model.nd
    sys.detect_redundancy(st)
    sys.reset_tangent()
    try:
        if phi_tol is not None and model.nm:
            project_positions(model, st, sys, lin, phi_tol)
        if project_velocities and model.nm:
            sys.evaluate(st, 1.0, 0.0, 0.0, MODE_VEL, True)
            rhs = np.zeros(model.neq)
            rhs[nd:] = -sys.r[nd:]
            sys.factor(lin)
            dv = lin.solve(rhs)
            st.v += dv[:nd]
        st.vd[:] = 0.0
        st.lam[:] = 0.0
        sys.evaluate(st, 1.0, 0.0, 0.0, MODE_ACC, True)
        sys.factor(lin)
        sol = lin.solve(-sys.r)
    except np.linalg.LinAlgError as exc:
        raise InitializationError(
            "cannot compute consistent initial accelerations: the mass matrix with the "
            f"constraint Jacobian is singular ({exc}); check for massless nodes or bodies "
            "without stiffness and for free rotations (redundant constraint rows are set "
            "aside)") from None
    st.vd[:] = sol[:nd]
    st.lam[:] = sol[nd:]
    if any(g.extra.get("active_set", False) for g in model.groups):
        _settle_active_set(model, st, sys, lin)
    st.a[:] = st.vd
    return st


def project_positions(model: Model, st: State, sys: System, lin: LinearSolver,
                      phi_tol: float, max_iter: int = 8) -> float:
    """Move the positions of ``st`` onto the bilateral position constraints: Newton on
    ``Phi(q) = 0`` with the correction of least kinetic metric, ``[M G^T; G 0] [dq; mu] =
    [0; -Phi]`` (the matrix of the velocity projection), applied on the rotation group, until
    the largest violation is at most ``phi_tol`` [m or rad]. Unilateral contact rows keep
    their gaps (their rows ask for no change). Returns the largest violation left.

    A run starts where the steps' Newton holds the constraints (``Newton.phi_tol``): a state
    assembled or solved to a looser tolerance (a static start from another model, a file's
    rounded positions) was otherwise corrected within the first step, which the step control
    counted as error: the RWD vehicle's static start violated a joint by 1.5e-7 m, and at a
    thirtieth of its file's tolerances (atol 3e-8 m) no step, down to 1e-9 s, met it."""
    nd = model.nd
    bilateral = np.zeros(model.nm, dtype=bool)
    bilateral[np.flatnonzero(sys.redundancy.candidates)] = True
    bilateral[sys.redundancy.rows - nd] = False  # set aside: implied by the others
    worst = 0.0
    for _ in range(max_iter + 1):
        sys.reset_tangent()
        sys.evaluate(st, 0.0, 0.0, 1.0, MODE_DYN, False)
        viol = sys.constraint_violation()[bilateral]
        worst = float(viol.max()) if viol.size else 0.0
        if worst <= phi_tol:
            break
        rhs = np.zeros(model.neq)
        rhs[nd:] = np.where(bilateral, -sys.r[nd:], 0.0)
        sys.evaluate(st, 1.0, 0.0, 0.0, MODE_VEL, True)
        sys.factor(lin)
        d = lin.solve(rhs)
        x0, R0 = st.x.copy(), st.R.copy()
        lie_update(x0, R0, d[:nd], model.nn, st.x, st.R, sys.Tn, False)
    sys.reset_tangent()
    return worst


def _settle_active_set(model: Model, st: State, sys: System, lin: LinearSolver,
                       max_iter: int = 20) -> None:
    """Re-solve the acceleration-level equations while elements whose rows depend on the
    multipliers (frictional contacts choosing stick or slip) change their choice: Newton on
    these piecewise-smooth equations from the linear solution (linear rows are already
    satisfied, so for them nothing changes)."""
    nd = model.nd
    for _ in range(max_iter):
        sys.evaluate(st, 1.0, 0.0, 0.0, MODE_ACC, True)
        rq, ph, finite = residual_norms(sys.r, sys.rabs, sys.kscale, nd, FLOOR_REL,
                                        np.zeros_like(sys.r))
        if not finite or (rq <= 1e-12 and ph <= 1e-14):
            return
        try:
            sys.factor(lin)
        except np.linalg.LinAlgError:
            return
        d = lin.solve(-sys.r)
        st.vd += d[:nd]
        st.lam += d[nd:]
