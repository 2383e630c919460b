"""The Lie-group generalized-alpha scheme with Newton iterations: the run's Newton memory.

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

The steps run in one compiled engine, :func:`drivedyn.solver.step_loop.run_steps`, with the
Newton iterations of :func:`drivedyn.solver.newton_kernel.newton_iterations`. :class:`Stepper`
holds what that engine keeps between calls (the trial state, the Newton memory, the
integrator's coefficients, the linear solver's arrays, the kernel table) and turns its codes
into :class:`~drivedyn.solver.settings.StepOutcome` values. A Python transcription of the
same algorithm lives with the tests as their oracle (``tests/internals/reference_stepper.py``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from drivedyn.elements.framework.contract import MODE_DYN
from drivedyn.model.model import Model, State
from drivedyn.solver import lapack
from drivedyn.solver import newton_kernel as nk
from drivedyn.solver.factor_frames import frame_arrays
from drivedyn.solver.linear import (
    AutoLU,
    DenseLU,
    LinearSolver,
    SparseLU,
    default_linear_solver,
)
from drivedyn.solver.newton_kernel import (
    FLOOR_REL,
    I_DENSE,
    I_EXTERNAL,
    I_LU,
    I_NFAC,
    I_REFACTOR,
    I_ROFF,
    ROUNDOFF_ULPS,
    STALL_ULPS,
)
from drivedyn.solver.redundancy import RESTORE_FACTOR
from drivedyn.solver.settings import GeneralizedAlpha, Newton, StepOutcome, StepStatus
from drivedyn.solver.sparse_lu import tail_arrays
from drivedyn.solver.system import System


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
    """The Newton memory and arrays of a run, shared with the compiled stepping loop
    (:mod:`~drivedyn.solver.step_loop`); the factorisation is kept between steps (modified
    Newton).

    Args:
        model: the compiled model.
        integrator, newton: the run's settings.
        linear_solver: DenseLU, SparseLU or AutoLU (default: by the model's size).
    Raises:
        TypeError: another linear solver.

    Attributes:
        factorizations: factorisations so far.
    """

    def __init__(self, model: Model, integrator: GeneralizedAlpha, newton: Newton,
                 linear_solver: LinearSolver | None = None) -> None:
        self.model = model
        self.sys = System(model)
        self.sys.redundancy.watch_limit = RESTORE_FACTOR * newton.phi_tol
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
        self._prev_vd = np.zeros(model.nd)  # accelerations of the state before the accepted one
        self._par = np.array([am, af, g, b, self.bp, self.gp, newton.tol, newton.phi_tol,
                              newton.contraction, newton.max_iter,
                              1.0 if newton.strategy == "full" else 0.0, FLOOR_REL,
                              STALL_ULPS, ROUNDOFF_ULPS])
        self._delta = np.zeros(model.neq)
        # the node frames of the factorisation, for its solves at later configurations
        self.frames = frame_arrays(np.array([n.body is not None for n in model.nodes], bool),
                                   model.nnz, model.neq)
        # stand-ins for the factors the active solver does not use (the dense ones 2 x 2: a
        # smaller array is C- as well as F-contiguous, numba would type it as C and compile
        # another overload)
        self._no_dense = lapack.workspace(2)
        # None for a solver that is dense for good: the compiled loop is then built without
        # the sparse path (solver.lu_paths)
        i0, f0 = np.zeros(0, np.int64), np.zeros(0)
        p0 = np.zeros(1, np.int64)
        self._no_sparse = None if isinstance(self.lin, DenseLU) else (
            p0, i0, f0, p0, i0, f0, i0, i0, tail_arrays(0, 0), f0,
            (i0, np.zeros(1), p0, i0, i0, f0, p0, i0, f0, i0, p0, i0, f0))
        if self._solvers() is None:
            raise TypeError(f"linear_solver must be a DenseLU, SparseLU or AutoLU (got "
                            f"{type(self.lin).__name__}): the compiled stepping loop "
                            "factorises and solves with them")

    @property
    def factorizations(self) -> int:
        """Factorisations so far."""
        return int(self._istate[I_NFAC])

    def _forget(self) -> None:
        # the round-off levels describe the factorised matrix only
        self._istate[I_LU] = 0
        self._istate[I_ROFF] = 0
        self.roff[:] = 0.0

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

    def _state_args(self, sn: State) -> tuple:
        """The ``accepted``, ``trial`` and ``arrays`` arguments of the compiled step."""
        m, sys, st, tf = self.model, self.sys, self.trial, self.model.tf
        return ((sn.x, sn.R, sn.v, sn.vd, sn.a, self._prev_vd),
                (st.x, st.R, st.v, st.vd, st.a, st.lam, st.es, self.hdq),
                (sys.Tn, sys.r, sys.rabs, sys.data, sys.tfv, sys.kscale, tf.kind, tf.par,
                 tf.fstart, tf.tab, m.indices, m.indptr, sys.redundancy.arrays))

    def kernel_table(self, sn: State) -> Any:
        """The model's :class:`~drivedyn.solver.kernel_calls.KernelTable` for states of
        the arrays of ``sn`` (the kernels compiled or loaded first); kept as ``_G``."""
        sys = self.sys
        G = sys.kernel_table(sn)
        if G is None:  # kernels not compiled yet for these types: evaluate once
            sys.evaluate(sn, 0.0, 0.0, 1.0, MODE_DYN, False)
            G = sys.kernel_table(sn)
        if G is None:
            raise RuntimeError("the element kernels could not be bound for the compiled "
                               "stepping loop (an argument numba cannot type)")
        self._G = G
        return G

    def _linear_arrays(self) -> tuple[tuple, tuple | None]:
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
            sp_args = self._no_sparse if f is None else (*f, sparse._z,
                                                         sparse.refactor_arrays())
        self._istate[I_EXTERNAL] = 0 if dense is not None else 1
        self._istate[I_REFACTOR] = 0 if dense is not None or sparse._f is None else 1
        self._istate[I_DENSE] = 1 if dense is not None else 0
        return (lu, piv, ib, tr, self._delta, self.roff, self._no_roff, self.frames), sp_args

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
