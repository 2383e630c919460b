"""The body a frame carries, lumped on the rails at its mounts, and the mass properties of an
assembled model (to check what the lumping reproduces).

A body of mass ``M``, centre of gravity ``c`` and inertia ``I_c`` about it sits on ``n`` pairs
of mounts at ``x_k`` on the rails (``y = +-track / 2``). It becomes ``2 n`` carrier bodies, one
above each mount at the height of ``c``, each fixed (a ``Fixed`` joint) to the rail node
below it:

* station masses ``w_k``: the least change from equal shares ``M / n`` that keeps the first
  moment, ``sum w_k = M`` and ``sum w_k x_k = M c_x`` (``w_k = M / n + b (x_k - xbar)``,
  ``b = M (c_x - xbar) / sum (x_k - xbar)^2``); each split between the left and right rail
  as ``w_k (1/2 +- c_y / track)``, which keeps ``sum m_i y_i = M c_y``; the carriers' height
  is ``c_z``. Mass and centre of gravity are therefore exact.
* the point masses' second moments about ``c``, ``I_p = sum m_i (|d_i|^2 1 - d_i d_i^T)``,
  leave ``J = I_c - I_p``; each carrier gets its share ``(m_i / M) J`` as its own inertia
  (about its centre, in frame axes). The assembly's inertia about ``c`` is therefore exactly
  ``I_c`` (all six components).

``J`` must be an inertia itself: the mounts may not spread the mass wider than the body
does. With ``d_z = 0`` this asks ``sum m_i d_x^2 < (I_yy + I_zz - I_xx) / 2`` and ``sum m_i
d_y^2 < (I_xx + I_zz - I_yy) / 2`` (the body's own spreads along x and y) and ``J``
positive definite; otherwise :class:`~drivedyn.errors.ModelError` says which.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drivedyn.elements.framework.contract import MODE_DYN
from drivedyn.errors import ModelError
from drivedyn.model.model import Model, State
from drivedyn.solver.system import System


@dataclass(frozen=True)
class Carrier:
    """One lumped part of the body.

    Attributes:
        side: ``"left"`` or ``"right"`` rail.
        station: index of its mount station (in the order of ``body.mounts``).
        x_mount: x of the mount on the rail [m], frame coordinates.
        position: (3,) its centre of mass [m], frame coordinates.
        mass: [kg].
        inertia: (3, 3) about its centre of mass, frame axes [kg m^2].
    """

    side: str
    station: int
    x_mount: float
    position: np.ndarray
    mass: float
    inertia: np.ndarray


def _inertia_tensor(value: object) -> np.ndarray:
    J = np.asarray(value, dtype=float)
    return np.diag(J) if J.shape == (3,) else 0.5 * (J + J.T)


def carriers(mass: float, cg: np.ndarray, inertia: object, mounts: list[float],
             track: float) -> list[Carrier]:
    """The carriers of a body of ``mass`` [kg], centre of gravity ``cg`` (3,) [m] and
    ``inertia`` about it (3 principal moments or (3, 3), frame axes) [kg m^2] on ``mounts``
    (x positions [m]) on rails ``track`` [m] apart (see the module docstring). Raises
    :class:`ModelError` naming ``body.<key>`` when the mounts cannot carry the body."""
    c = np.asarray(cg, dtype=float)
    Ic = _inertia_tensor(inertia)
    xs = np.asarray(mounts, dtype=float)
    n = len(xs)
    xbar = float(xs.mean())
    spread = float(np.sum((xs - xbar) ** 2))
    if n < 2 or spread <= 0.0:
        raise ModelError(f"body.mounts = {list(mounts)}: expected at least two different x "
                         "positions [m]")
    b = mass * (c[0] - xbar) / spread
    w = mass / n + b * (xs - xbar)
    if np.any(w <= 0.0):
        k = int(np.argmin(w))
        raise ModelError(f"body.cg[0] = {c[0]:g} m lies too far from the mounts' middle "
                         f"({xbar:g} m): the mount at x = {xs[k]:g} m would carry "
                         f"{w[k]:.4g} kg; move the mounts or the centre of gravity")
    half = 0.5 * track
    if not abs(c[1]) < half:
        raise ModelError(f"body.cg[1] = {c[1]:g} m: the centre of gravity must lie between "
                         f"the rails (|y| < {half:g} m)")
    share = {"left": 0.5 + c[1] / track, "right": 0.5 - c[1] / track}
    sign = {"left": 1.0, "right": -1.0}
    raw = []
    for k, (x, wk) in enumerate(zip(xs, w, strict=True)):
        for side in ("left", "right"):
            raw.append((side, k, float(x), np.array([x, sign[side] * half, c[2]]),
                        float(wk * share[side])))
    Ip = np.zeros((3, 3))
    for *_, r, m in raw:
        d = r - c
        Ip += m * (d @ d * np.eye(3) - np.outer(d, d))
    J = Ic - Ip
    spread_x = 0.5 * (Ic[1, 1] + Ic[2, 2] - Ic[0, 0])
    spread_y = 0.5 * (Ic[0, 0] + Ic[2, 2] - Ic[1, 1])
    ev = np.linalg.eigvalsh(J)
    tol = 1e-12 * max(1.0, float(np.abs(Ic).max()))
    if ev[0] <= tol or ev[0] + ev[1] < ev[2] - tol:
        raise ModelError(
            "body.inertia: the mounts spread the mass more than the body does, so no "
            f"inertia is left for the carriers (left over {np.round(J, 4).tolist()} kg m^2, "
            f"principal moments {np.round(ev, 4).tolist()}); the mounts' spread along x is "
            f"{Ip[1, 1]:.4g} and along y {Ip[0, 0]:.4g} kg m^2 against the body's "
            f"{spread_x:.4g} and {spread_y:.4g}: move body.mounts inwards or check "
            "body.inertia")
    return [Carrier(side, k, x, r, m, (m / mass) * J) for side, k, x, r, m in raw]


@dataclass(frozen=True)
class MassProperties:
    """Mass [kg], centre of mass (3,) [m] and inertia about it (3, 3) [kg m^2], global."""

    mass: float
    cg: np.ndarray
    inertia: np.ndarray


def mass_matrix(model: Model, state: State | None = None) -> np.ndarray:
    """The assembled mass matrix on the node dofs (dense), as the element kernels build it:
    rows and columns ``6 i .. 6 i + 5`` are node ``i``'s velocity (global) and angular
    velocity (node frame)."""
    st = (state or model.initial_state()).copy()
    st.v[:] = 0.0
    sys = System(model)
    sys.reset_tangent()
    sys.evaluate(st, 1.0, 0.0, 0.0, MODE_DYN, True)
    nd = model.nd
    return sys.matrix().toarray()[:nd, :nd]


def mass_properties(model: Model, state: State | None = None) -> MassProperties:
    """Mass, centre of mass and inertia of everything in ``model`` that carries mass, from
    its assembled mass matrix ``M`` and the rigid motions of all its nodes: the kinetic
    energy of a translation ``V`` and a rotation ``w`` about the origin is
    ``1/2 [V; w]^T [[m 1, -m c~], [m c~, I_O]] [V; w]``."""
    st = state or model.initial_state()
    M = mass_matrix(model, st)
    nn = model.nn
    Ut = np.zeros((6 * nn, 3))
    Ur = np.zeros((6 * nn, 3))
    for i in range(nn):
        x = st.x[i]
        R = st.R[i]
        Ut[6 * i:6 * i + 3] = np.eye(3)
        # rotation w about the origin: node velocity w x x = -x~ w, node-frame spin R^T w
        Ur[6 * i:6 * i + 3] = -np.array([[0.0, -x[2], x[1]], [x[2], 0.0, -x[0]],
                                          [-x[1], x[0], 0.0]])
        Ur[6 * i + 3:6 * i + 6] = R.T
    Mt = Ut.T @ M @ Ut
    m = float(np.trace(Mt) / 3.0)
    S = Ut.T @ M @ Ur  # -m c~
    c = np.array([S[1, 2] - S[2, 1], S[2, 0] - S[0, 2], S[0, 1] - S[1, 0]]) / (2.0 * m)
    IO = Ur.T @ M @ Ur
    Ic = IO - m * (c @ c * np.eye(3) - np.outer(c, c))
    return MassProperties(m, c, 0.5 * (Ic + Ic.T))
