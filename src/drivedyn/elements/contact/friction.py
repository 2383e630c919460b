"""Friction laws of the contact elements: regularised Coulomb, tanh, Stribeck.

A :class:`FrictionLaw` gives the friction coefficient ``mu_R(v)`` as an odd function of the
sliding speed ``v`` [m/s]; the friction force is ``mu_R(v) |F_n|`` opposing the sliding
(seeds 000-002, physics.md 3)::

    coulomb (the seeds' law):  mu_R(v) = mu_v(|v|) (2 - |v|/eps_v) v/eps_v   for |v| < eps_v
                               mu_R(v) = mu_v(|v|) v/|v|                     for |v| >= eps_v
    tanh:                      mu_R(v) = mu_v(|v|) tanh(v/eps_v)

    mu_v(v) = mu + (mu_static - mu) exp(-(v/v_stribeck)^2)      (Stribeck; = mu by default)

``eps_v`` [m/s] is the regularisation speed: below it the law is a steep, smooth viscous-like
branch instead of Coulomb's set-valued law, so a body held by friction creeps slowly instead of
sticking (on an incline at ``tan(theta) < mu_static`` the creep speed is
``eps_v (1 - sqrt(1 - tan(theta)/mu_static))`` for the coulomb law and
``eps_v atanh(tan(theta)/mu_static)`` for tanh, with ``eps_v << v_stribeck``). Use the
augmented-Lagrangian :class:`~drivedyn.elements.contact.unilateral.UnilateralContact` where true
sticking matters.

With ``mu_static > mu`` the coefficient peaks near ``eps_v`` at about ``mu_static`` and falls
to ``mu`` above ``v_stribeck``: static friction exceeds kinetic friction.

Elements with a 2-D sliding velocity ``s`` (point on plane) use the vector form
``f = |F_n| phi(|s|) s`` with ``phi(v) = mu_R(v)/v``; :func:`friction_phi` returns ``phi`` and
its derivative, from which the Jacobian ``|F_n| (phi I + phi'(v) s s^T / v)`` follows.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from drivedyn.elements.framework.checks import check_param, check_param_optional
from drivedyn.errors import ModelError

FRICTION_LAWS = ("coulomb", "tanh")
KIND_COULOMB = 0
KIND_TANH = 1


@dataclass(frozen=True)
class FrictionLaw:
    """Regularised Coulomb friction with an optional Stribeck peak.

    Attributes:
        mu: kinetic (sliding) friction coefficient [-] >= 0.
        eps_v: regularisation speed [m/s] > 0.
        law: ``"coulomb"`` (the seeds' quadratic regularisation) or ``"tanh"``.
        mu_static: static friction coefficient [-] >= mu; None = mu (no Stribeck effect).
        stribeck_speed: speed [m/s] > 0 over which the coefficient falls from mu_static to mu.
    """

    mu: float
    eps_v: float = 1e-3
    law: str = "coulomb"
    mu_static: float | None = None
    stribeck_speed: float = 1e-2
    units: ClassVar[dict[str, str]] = {"mu": "1", "eps_v": "m/s", "mu_static": "1",
                                       "stribeck_speed": "m/s"}

    def validate(self, what: str) -> None:
        """Raise :class:`ModelError` naming ``what`` for impossible values."""
        w = f"{what}.friction"
        if self.law not in FRICTION_LAWS:
            raise ModelError(f"{w}.law: expected one of {', '.join(FRICTION_LAWS)}, got "
                             f"{self.law!r}")
        check_param(self, "mu", 0.0, what=w)
        check_param(self, "eps_v", 0.0, strict=True, what=w)
        check_param(self, "stribeck_speed", 0.0, strict=True, what=w)
        check_param_optional(self, "mu_static", 0.0, what=w)
        if self.mu_static is not None and self.mu_static < self.mu:
            raise ModelError(f"{w}.mu_static: must be >= mu = {self.mu!r}, got "
                             f"{self.mu_static!r}")

    def params(self) -> tuple[float, float, float, float, float]:
        """(kind, mu, mu_static, stribeck_speed, eps_v) as the kernels use them."""
        mus = self.mu if self.mu_static is None else self.mu_static
        kind = KIND_COULOMB if self.law == "coulomb" else KIND_TANH
        return (float(kind), float(self.mu), float(mus), float(self.stribeck_speed),
                float(self.eps_v))

    def coefficient(self, v: float | np.ndarray) -> np.ndarray:
        """mu_R(v) [-] for sliding speeds ``v`` [m/s] (plain numpy, for tests and plots)."""
        kind, mu, mus, vst, eps = self.params()
        va = np.abs(np.asarray(v, dtype=float))
        out = np.empty_like(va)
        for i, s in np.ndenumerate(va):
            out[i] = friction_phi(float(s), int(kind), mu, mus, vst, eps)[0] * s
        return np.sign(np.asarray(v, dtype=float)) * out


NO_FRICTION = FrictionLaw(0.0)


def friction_table(laws: list[FrictionLaw | None]) -> np.ndarray:
    """Per-element parameters (nel, 5) of a group: rows (kind, mu, mu_static,
    stribeck_speed, eps_v); elements without friction get mu = 0."""
    rows = [(law or NO_FRICTION).params() for law in laws]
    return np.array(rows, dtype=float).reshape(-1, 5)


@njit(cache=True, inline="always")
def friction_phi(v, kind, mu, mus, vst, eps):
    """``phi(v) = mu_R(v)/v`` and ``dphi/dv`` for a sliding speed ``v >= 0`` [m/s]
    (finite at v = 0: phi(0) = mu_R'(0))."""
    m = mu
    dm = 0.0
    if mus != mu:
        x = v / vst
        ex = np.exp(-x * x)
        m = mu + (mus - mu) * ex
        dm = -(mus - mu) * 2.0 * x * ex / vst
    if kind == KIND_COULOMB:
        if v < eps:
            rho = (2.0 - v / eps) / eps
            drho = -1.0 / (eps * eps)
        else:
            rho = 1.0 / v
            drho = -1.0 / (v * v)
    else:
        x = v / eps
        if x < 1e-3:
            x2 = x * x
            rho = (1.0 - x2 / 3.0 + 2.0 * x2 * x2 / 15.0) / eps
            drho = (-2.0 * x / 3.0 + 8.0 * x * x2 / 15.0) / (eps * eps)
        else:
            th = np.tanh(x)
            rho = th / v
            drho = ((1.0 - th * th) * x - th) / (v * v)
    return m * rho, dm * rho + m * drho


@njit(cache=True, inline="always")
def friction_scalar(s, kind, mu, mus, vst, eps):
    """Signed coefficient ``mu_R(s)`` and its derivative ``dmu_R/ds`` for a scalar sliding
    velocity ``s`` [m/s]."""
    va = abs(s)
    ph, dph = friction_phi(va, kind, mu, mus, vst, eps)
    return ph * s, ph + dph * va
