"""Linearised free vibration of a model about a configuration: eigenfrequencies and modes.

The mass matrix ``M``, tangent stiffness ``K`` and damping ``C`` on the node dofs are
assembled by the element kernels themselves (``System.evaluate`` with ``cM, cC, cK`` = unit
vectors, tangent operators reset to identity, so the stiffness is the derivative for right
perturbations). Joints are eliminated with an orthonormal basis ``Z`` of the null space of
the constraint Jacobian ``G``; coordinates that carry no mass (plain nodes without beam
mass) are condensed statically (Guyan, exact for massless coordinates). Dense linear
algebra: meant for models up to a few thousand dofs.

The stiffness about a state that is not an equilibrium (or that carries constraint forces)
holds a non-symmetric geometric part; the undamped problem uses its symmetric part and
:attr:`Modes.asymmetry` reports how large the skew part was.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drivedyn.elements.framework.contract import MODE_DYN
from drivedyn.model.model import Model, State
from drivedyn.solver.system import System

_MASSLESS = 1e-12  # a mass eigenvalue below this x the largest is a massless coordinate


@dataclass
class Modes:
    """Result of :func:`linear_modes`.

    Attributes:
        frequencies: (n,) natural frequencies [Hz] (undamped, or damped for ``damped``);
            rigid-body modes are 0.
        omega: (n,) circular frequencies [rad/s].
        shapes: (nd, n) mode shapes on the node dofs (translations [m], rotations [rad];
            mass-normalised for the undamped problem, complex for the damped one).
        eigenvalues: (n,) ``omega^2`` [1/s^2] (undamped) or complex ``s`` [1/s] (damped).
        damping_ratio: (n,) or None.
        labels: (n,) the dof label with the largest amplitude of each mode.
        asymmetry: relative size of the skew part of the reduced stiffness.
    """

    frequencies: np.ndarray
    omega: np.ndarray
    shapes: np.ndarray
    eigenvalues: np.ndarray
    damping_ratio: np.ndarray | None
    labels: list[str]
    asymmetry: float

    def table(self) -> str:
        """A printable table: mode, frequency [Hz], damping ratio, dominant dof."""
        rows = [f"{'mode':>4}  {'f [Hz]':>12}  {'zeta':>8}  dominant dof"]
        for k, f in enumerate(self.frequencies):
            z = "" if self.damping_ratio is None else f"{self.damping_ratio[k]:8.4f}"
            rows.append(f"{k + 1:4d}  {f:12.5g}  {z:>8}  {self.labels[k]}")
        return "\n".join(rows)


def _matrices(model: Model, st: State) -> tuple[np.ndarray, ...]:
    sys = System(model)
    sys.reset_tangent()
    nd = model.nd
    out = []
    for cM, cC, cK in ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)):
        sys.evaluate(st, cM, cC, cK, MODE_DYN, True)
        out.append(sys.matrix().toarray())
    M, C, Kfull = out
    return M[:nd, :nd], C[:nd, :nd], Kfull[:nd, :nd], Kfull[nd:, :nd]


def linear_modes(model: Model, state: State | None = None, n_modes: int = 10, t: float = 0.0,
                 damped: bool = False) -> Modes:
    """The first ``n_modes`` modes of ``model`` linearised about ``state`` (default: the
    initial state; usually a static equilibrium from ``solve_static``) at time ``t`` [s].

    ``damped=False``: undamped modes of ``K y = w^2 M y`` (assembled with the velocities
    set to zero). ``damped=True``: eigenvalues of the first-order system with ``C`` (damping
    and the gyroscopic terms at the state's velocities); massless coordinates are condensed
    with their stiffness only.
    """
    st = (state or model.initial_state()).copy()
    st.t = t
    if not damped:
        st.v[:] = 0.0
    st.vd[:] = 0.0
    M, C, K, G = _matrices(model, st)
    import scipy.linalg as sla  # here: 0.3 s of import off every simulation's start

    Z = sla.null_space(G) if G.shape[0] else np.eye(model.nd)
    if Z.shape[1] == 0:
        raise ValueError("linear_modes: the model has no free coordinate left by its joints")
    Mr = Z.T @ M @ Z
    Kr = Z.T @ K @ Z
    Cr = Z.T @ C @ Z
    Mr = 0.5 * (Mr + Mr.T)
    skew = 0.5 * (Kr - Kr.T)
    ks = max(np.abs(Kr).max(), 1e-300)
    asym = float(np.abs(skew).max() / ks)
    # split into massive and massless coordinates (eigenvectors of the reduced mass)
    mu, V = np.linalg.eigh(Mr)
    keep = mu > _MASSLESS * max(mu.max(), 1e-300)
    Vm, V0 = V[:, keep], V[:, ~keep]
    if not keep.any():
        raise ValueError("linear_modes: the model has no mass on its free coordinates")

    def condense(A):
        """Massive-coordinate matrix after eliminating the massless ones statically."""
        if not V0.shape[1]:
            return Vm.T @ A @ Vm, Vm
        A00 = V0.T @ A @ V0
        A0m = V0.T @ A @ Vm
        X = -np.linalg.solve(A00, A0m)  # massless = X massive
        T = Vm + V0 @ X
        return T.T @ A @ T, T

    Kc, T = condense(0.5 * (Kr + Kr.T) if not damped else Kr)
    Mc = np.diag(mu[keep])
    if not damped:
        lam, Y = sla.eigh(0.5 * (Kc + Kc.T), Mc)
        tiny = 1e-9 * max(abs(lam).max(), 1e-300)
        lam = np.where(np.abs(lam) < tiny, 0.0, lam)
        n = min(n_modes, lam.size)
        lam, Y = lam[:n], Y[:, :n]
        omega = np.sqrt(np.maximum(lam, 0.0))
        shapes = Z @ (T @ Y)
        zeta = None
        eig = lam
    else:
        Cc = T.T @ Cr @ T
        m = Mc.shape[0]
        Mi = np.diag(1.0 / mu[keep])
        A = np.block([[np.zeros((m, m)), np.eye(m)], [-Mi @ Kc, -Mi @ Cc]])
        s, Y = np.linalg.eig(A)
        order = np.argsort(np.abs(s.imag) + 1e-12 * np.abs(s))
        s, Y = s[order], Y[:, order]
        sel = s.imag >= 0.0
        s, Y = s[sel][:n_modes], Y[:m, sel][:, :n_modes]
        wn = np.abs(s)
        zeta = np.where(wn > 0, -s.real / np.where(wn > 0, wn, 1.0), 0.0)
        omega = np.abs(s.imag)
        shapes = Z @ (T @ Y)
        eig = s
    labels = [model.eq_labels[int(np.argmax(np.abs(shapes[:, k])))]
              for k in range(shapes.shape[1])]
    return Modes(omega / (2 * np.pi), omega, shapes, eig, zeta, labels, asym)
