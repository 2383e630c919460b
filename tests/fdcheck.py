"""Finite-difference helpers shared by the tangent tests (registry and contact-specific):
the pieces (``residual``, ``perturb``, ``assembled``, ``check``) and, for the contact tests,
``check_tangents`` on a given state (``random_state``) whose internal state can be set.

Node rotations are perturbed through the Lie-group update ``R <- R exp(eps e_i)``, exactly
the right perturbation the kernels differentiate for; translations and multipliers
additively.
"""

from __future__ import annotations

import numpy as np

from drivedyn.elements.framework.contract import MODE_ACC, MODE_DYN, MODE_VEL
from drivedyn.rotations import exp_so3
from drivedyn.solver.system import System

EPS = 1e-6
RTOL = 1e-6


def residual(sys, st, mode=MODE_DYN):
    sys.evaluate(st, 0.0, 0.0, 1.0, mode, False)
    return sys.r.copy()


def perturb(st, j, eps, nd):
    """Copy of ``st`` with unknown j moved by eps (Lie update for rotations)."""
    s = st.copy()
    if j < nd:
        node, c = divmod(j, 6)
        if c < 3:
            s.x[node, c] += eps
        else:
            e = np.zeros(3)
            e[c - 3] = eps
            s.R[node] = s.R[node] @ exp_so3(e)
    else:
        s.lam[j - nd] += eps
    return s


def assembled(sys, st, cM, cC, cK, mode=MODE_DYN):
    sys.reset_tangent()
    sys.evaluate(st, cM, cC, cK, mode, True)
    return sys.matrix().toarray()


def check(A, F, what, rmax=0.0):
    """``rmax``: largest residual magnitude; central differences lose about
    1e-16 * rmax / EPS to round-off, allowed for with a factor 10."""
    scale = max(1.0, np.abs(F).max())
    err = np.abs(A - F).max()
    i, j = np.unravel_index(np.argmax(np.abs(A - F)), A.shape)
    tol = RTOL * scale + 10 * 1e-16 * rmax / EPS
    assert err <= tol, (f"{what}: max |analytic - FD| = {err:.3g} at {(i, j)} (analytic "
                        f"{A[i, j]:.6g}, FD {F[i, j]:.6g}, scale {scale:.3g})")


def check_tangents(model, st, acc_vel: bool = False) -> None:
    """Stiffness (with multiplier columns), damping and mass blocks against central
    differences at state ``st``; with ``acc_vel`` also the acceleration- and velocity-level
    constraint Jacobians."""
    sys = System(model)
    nd, neq = model.nd, model.neq
    rmax = np.abs(residual(sys, st)).max()
    K = assembled(sys, st, 0.0, 0.0, 1.0)
    F = np.zeros((neq, neq))
    for j in range(neq):
        F[:, j] = (residual(sys, perturb(st, j, EPS, nd))
                   - residual(sys, perturb(st, j, -EPS, nd))) / (2 * EPS)
    check(K, F, "stiffness", rmax)
    C = assembled(sys, st, 0.0, 1.0, 0.0)[:nd, :nd]
    M = assembled(sys, st, 1.0, 0.0, 0.0)[:nd, :nd]
    for what, A, attr in (("damping", C, "v"), ("mass", M, "vd")):
        F = np.zeros((nd, nd))
        for j in range(nd):
            sp, sm = st.copy(), st.copy()
            getattr(sp, attr)[j] += EPS
            getattr(sm, attr)[j] -= EPS
            F[:, j] = (residual(sys, sp) - residual(sys, sm))[:nd] / (2 * EPS)
        check(A, F, what, rmax)
    if acc_vel:
        for mode, attr in ((MODE_ACC, "vd"), (MODE_VEL, "v")):
            A = assembled(sys, st, 1.0, 0.0, 0.0, mode)
            F = np.zeros((neq, neq))
            for j in range(neq):
                if j < nd:
                    sp, sm = st.copy(), st.copy()
                    getattr(sp, attr)[j] += EPS
                    getattr(sm, attr)[j] -= EPS
                else:
                    sp, sm = perturb(st, j, EPS, nd), perturb(st, j, -EPS, nd)
                F[:, j] = (residual(sys, sp, mode) - residual(sys, sm, mode)) / (2 * EPS)
            if mode == MODE_ACC:
                check(A, F, "acceleration-level matrix", rmax)
            else:  # velocity projection: constraint rows and multiplier columns
                check(A[nd:], F[nd:], "velocity-level rows", rmax)
                check(A[:nd, nd:], F[:nd, nd:], "velocity-level multiplier columns", rmax)


def random_state(model, seed=7, scale_v=1.0):
    """The initial state of ``model`` with random positions, rotations, velocities,
    accelerations and multipliers around it, at t = 0.37."""
    rng = np.random.default_rng(seed)
    st = model.initial_state()
    nn = model.nn
    st.x[:nn] += 1e-2 * rng.standard_normal((nn, 3))
    for i in range(nn):
        st.R[i] = st.R[i] @ exp_so3(0.05 * rng.standard_normal(3))
    st.v[:] = scale_v * rng.standard_normal(model.nd)
    st.vd[:] = rng.standard_normal(model.nd)
    if model.nm:
        st.lam[:] = 5.0 * rng.standard_normal(model.nm) / model.meta["kscale"][model.nd:]
    st.t = 0.37
    return st
