"""Global residual and iteration matrix of a compiled model (no element knowledge here)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit

from drivedyn.elements.base import MODE_DYN
from drivedyn.model.model import Model, State
from drivedyn.rotations import exp_so3, tangent
from drivedyn.timefunctions import eval_time_functions


@njit(cache=True)
def lie_update(x0, R0, hdq, nn, x, R, Tn, with_tangent):
    """Positions ``x = x0 + hdq_x`` and rotations ``R = R0 exp(hdq_theta)`` of all nodes.

    ``hdq`` (6 nn,) is the Lie-algebra increment of the step; ``Tn`` receives the tangent
    operators T(hdq_theta) (identity rows stay for the ground).
    """
    for i in range(nn):
        d = 6 * i
        for a in range(3):
            x[i, a] = x0[i, a] + hdq[d + a]
        phi = hdq[d + 3 : d + 6]
        R[i] = R0[i] @ exp_so3(phi)
        if with_tangent:
            Tn[i] = tangent(phi)


class System:
    """Evaluates the model's residual and iteration matrix into preallocated arrays.

    Attributes:
        r: (neq,) residual of the last evaluation.
        rabs: (neq,) sum of absolute element contributions per equation (scales for the
            convergence test).
        data: (nnz,) CSC values of the last assembled matrix.
        tfv: (nfun, 4) time-function values at the last evaluation time.
        Tn: (nn+1, 3, 3) tangent operators used in ``MODE_DYN`` assembly.
    """

    def __init__(self, model: Model) -> None:
        self.model = model
        self.r = np.zeros(model.neq)
        self.rabs = np.zeros(model.neq)
        self.data = np.zeros(model.nnz)
        tf = model.tf
        self.tfv = np.zeros((max(1, len(tf.fstart) - 1), 4))
        self.Tn = np.tile(np.eye(3), (model.nn + 1, 1, 1))
        self.kscale = model.meta["kscale"]
        self.nevals = 0

    def time_functions(self, t: float) -> None:
        tf = self.model.tf
        eval_time_functions(t, tf.kind, tf.par, tf.fstart, tf.tab, self.tfv)

    def evaluate(self, st: State, cM: float = 0.0, cC: float = 0.0, cK: float = 1.0,
                 mode: int = MODE_DYN, want: bool = False) -> None:
        """Residual (and matrix if ``want``) at state ``st`` and time ``st.t``."""
        self.r[:] = 0.0
        self.rabs[:] = 0.0
        if want:
            self.data[:] = 0.0
        self.time_functions(st.t)
        for g in self.model.groups:
            g.evaluate(st, self.tfv, st.t, self.Tn, cM, cC, cK, mode, want,
                       self.r, self.rabs, self.data)
        self.nevals += 1

    def matrix(self) -> sp.csc_matrix:
        m = self.model
        return sp.csc_matrix((self.data.copy(), m.indices, m.indptr), shape=(m.neq, m.neq))

    def reset_tangent(self) -> None:
        self.Tn[:] = np.eye(3)

    def constraint_violation(self, r: np.ndarray | None = None) -> np.ndarray:
        """|Phi| of every constraint row [m or rad] from a MODE_DYN residual."""
        r = self.r if r is None else r
        nd = self.model.nd
        return np.abs(r[nd:]) / self.kscale[nd:]

    def energies(self) -> dict[str, float]:
        """Kinetic, potential energy [J] and power input / dissipation [W] summed by kind."""
        ek = ep = pin = pdis = 0.0
        for g in self.model.groups:
            s = g.eout.sum(axis=0)
            ek += s[0]
            ep += s[1]
            pin += s[2]
            pdis += s[3]
        return {"kinetic": ek, "potential": ep, "power_in": pin, "power_dissipated": pdis}
