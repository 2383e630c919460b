"""Finite-difference helpers shared by the tangent tests (registry and contact-specific).

Node rotations are perturbed through the Lie-group update ``R <- R exp(eps e_i)``, exactly
the right perturbation the kernels differentiate for; translations and multipliers
additively.
"""

from __future__ import annotations

import numpy as np

from drivedyn.elements.base import MODE_DYN
from drivedyn.rotations import exp_so3

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
