"""Normal force laws of contacts: penalty and continuous impact (hysteresis damping).

Every force-type contact element (:mod:`drivedyn.elements.contact`,
:mod:`drivedyn.elements.contact.squeeze_film`) computes its normal force from a penetration
``delta`` [m] (positive in contact) and its rate ``deltadot`` [m/s] (positive while the bodies
approach) with one :class:`NormalLaw`::

    F = K delta^n [1 + chi deltadot / v_s] + c deltadot     for delta > 0, else 0
    F = max(F, 0)                                           (a contact never pulls)

``K`` [N/m^n] stiffness, ``n`` exponent (1.5: Hertz), ``c`` [N s/m] linear damping (plain
penalty law), ``chi`` [-] the hysteresis damping factor of a continuous-impact law and ``v_s``
[m/s] the approach speed at first contact, kept per contact in the State (physics.md 3; seeds
000, 001). The laws differ only in ``chi`` as a function of the restitution coefficient ``e``:

====================  ===========================  ===========================================
law                   chi                          reference
====================  ===========================  ===========================================
penalty               0 (linear damping ``c``)     seeds: spring in compression only
hunt-crossley         3 (1 - e) / 2                Hunt & Crossley 1975
lankarani-nikravesh   3 (1 - e^2) / 4              Lankarani & Nikravesh 1994 (the seeds' law)
flores                8 (1 - e) / (5 e)            Flores et al. 2011
gonthier              (1 - e^2) / e                Gonthier et al. 2004
hu-guo                3 (1 - e) / (2 e)            Hu & Guo 2015
exact                 root of the exact relation   derived (below)
====================  ===========================  ===========================================

**Exact restitution relation** (derived; checked against numerical integration in the tests).
With ``s = K delta^(n+1) / (n+1)`` and ``u = deltadot / v_s`` the impact of a mass ``m``
reduces to ``m v_s^2 u du/ds = -(1 + chi u)``; integrating the compression (u: 1 -> 0) and the
restitution (u: 0 -> -e) between the same values of ``s`` gives, with
``phi(x) = x - ln(1 + x)``::

    phi(chi) = phi(-e chi)    i.e.   chi - ln(1 + chi) = -e chi - ln(1 - e chi)

so the achieved (kinematic) restitution ``e = rebound speed / approach speed`` depends on chi
alone, not on n, K, m or the impact speed. The closed-form laws come from approximations
(small damping, linearised energy loss), so the restitution they *achieve*,
:func:`restitution_from_chi` of their chi, differs from the ``e`` they are given: given
e = 0.5, Hunt-Crossley achieves 0.663, Lankarani-Nikravesh 0.725, Flores 0.470, Gonthier and
Hu-Guo 0.488; given 0.8 they achieve 0.833, 0.847, 0.789, 0.768 and 0.799. All approach the
target as e -> 1 (chi ~ 3 (1 - e)/2). The ``exact`` law inverts the relation
(:func:`chi_from_restitution`) and reproduces any target ``e`` in (0, 1).

The impact speed ``v_s`` used from the first step of a contact on is the speed at the crossing
of ``delta = 0`` extrapolated from the last accepted state before the contact with its
acceleration (exact in free flight; a constant within the step, so it does not enter the
tangent). It is floored at
``min_impact_speed``: a contact that starts at (nearly) zero speed, e.g. a body set down at
rest, gets a finite damping coefficient ``chi K delta^n / min_impact_speed``.

Energy: the potential ``K delta^(n+1) / (n+1)`` is reported as potential energy, and
``(F - K delta^n) deltadot`` (the hysteresis or damping force times the rate, also when the
force is clipped) as dissipated power, so the energy account closes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from drivedyn.elements.framework.checks import check_param, range_message
from drivedyn.errors import ModelError

LAW_NAMES = ("penalty", "hunt-crossley", "lankarani-nikravesh", "flores", "gonthier",
             "hu-guo", "exact")
"""Names accepted by :class:`NormalLaw` (``law=``)."""

IMPACT_LAWS = LAW_NAMES[1:]
"""The continuous-impact (hysteresis) laws, parametrised by a restitution coefficient."""


def _phi(x: float) -> float:
    """``x - ln(1 + x)`` for ``x > -1`` (+inf at and below -1), accurate near 0 (series
    below |x| = 1e-3)."""
    if x <= -1.0:
        return math.inf
    if abs(x) < 1e-3:
        # x^2/2 - x^3/3 + x^4/4 - x^5/5 + x^6/6
        return x * x * (0.5 - x * (1.0 / 3.0 - x * (0.25 - x * (0.2 - x / 6.0))))
    return x - math.log1p(x)


def restitution_from_chi(chi: float) -> float:
    """Restitution ``e`` achieved by a hysteresis law with damping factor ``chi`` >= 0.

    Solves ``phi(chi) = phi(-e chi)`` (module docstring) for ``e`` in (0, 1] by bisection
    on ``x = -e chi`` in (-1, 0]; ``chi = 0`` gives 1.
    """
    chi = float(chi)
    if not (chi >= 0.0 and math.isfinite(chi)):
        raise ValueError(f"damping factor chi must be finite and >= 0, got {chi}")
    if chi == 0.0:
        return 1.0
    target = _phi(chi)
    lo, hi = -1.0, 0.0  # phi decreasing on (-1, 0]: phi(lo) = inf > target > 0 = phi(hi)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid == lo or mid == hi:
            break
        if _phi(mid) > target:
            lo = mid
        else:
            hi = mid
    return -0.5 * (lo + hi) / chi


def chi_from_restitution(e: float) -> float:
    """Damping factor ``chi`` whose achieved restitution is exactly ``e`` in (0, 1).

    Root of ``phi(chi) - phi(-e chi)`` on (0, 1/e) (positive near 0 for e < 1, -> -inf at
    1/e), by bisection on the function divided by chi^2 so that the root stays bracketed for
    e close to 1.
    """
    e = float(e)
    if not 0.0 < e < 1.0:
        raise ValueError(f"restitution must be in (0, 1), got {e}")

    def f(c: float) -> float:
        return (_phi(c) - _phi(-e * c)) / (c * c)

    lo, hi = 0.0, 1.0 / e
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid == lo or mid == hi:
            break
        if mid == 0.0 or f(mid) > 0.0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def damping_factor(law: str, e: float) -> float:
    """The damping factor chi [-] of an impact law for restitution ``e`` (0 for penalty)."""
    if law == "penalty":
        return 0.0
    if law == "hunt-crossley":
        return 1.5 * (1.0 - e)
    if law == "lankarani-nikravesh":
        return 0.75 * (1.0 - e * e)
    if law == "flores":
        return 8.0 * (1.0 - e) / (5.0 * e)
    if law == "gonthier":
        return (1.0 - e * e) / e
    if law == "hu-guo":
        return 1.5 * (1.0 - e) / e
    if law == "exact":
        return chi_from_restitution(e)
    raise ValueError(f"unknown normal law {law!r} (known: {', '.join(LAW_NAMES)})")


def achieved_restitution(law: str, e: float) -> float:
    """Restitution the law actually produces when given ``e`` (exact relation)."""
    return restitution_from_chi(damping_factor(law, e))


@dataclass(frozen=True)
class NormalLaw:
    """Normal force law of a contact (see the module docstring).

    Attributes:
        stiffness: K [N/m^n] > 0.
        exponent: n [-] >= 1 (1: linear spring, 1.5: Hertz point contact).
        law: one of :data:`LAW_NAMES`; ``"penalty"`` is the plain penalty spring with linear
            damping ``damping``; the others are continuous-impact laws for ``restitution``.
        restitution: target restitution coefficient e in (0, 1) of an impact law.
        damping: linear damping c [N s/m] >= 0 added to any law (the penalty law's damper).
        min_impact_speed: floor of the approach speed at first contact v_s [m/s] > 0.
    """

    stiffness: float
    exponent: float = 1.5
    law: str = "lankarani-nikravesh"
    restitution: float = 0.8
    damping: float = 0.0
    min_impact_speed: float = 1e-4
    # the stiffness's unit depends on the exponent n: N/m^n (N/m^1.5 for Hertz)
    units: ClassVar[dict[str, str]] = {
        "stiffness": "N/m^{exponent}", "exponent": "1", "restitution": "1",
        "damping": "N s/m", "min_impact_speed": "m/s",
    }

    def validate(self, what: str) -> None:
        """Raise :class:`ModelError` naming ``what`` (the element) for impossible values."""
        w = f"{what}.law"
        if self.law not in LAW_NAMES:
            raise ModelError(f"{w}: unknown law {self.law!r} (known: {', '.join(LAW_NAMES)})")
        check_param(self, "exponent", 1.0, what=w)  # first: the stiffness's unit uses it
        check_param(self, "stiffness", 0.0, strict=True, what=w)
        check_param(self, "damping", 0.0, what=w)
        check_param(self, "min_impact_speed", 0.0, strict=True, what=w)
        if self.law != "penalty":
            e = check_param(self, "restitution", what=w)
            if not 0.0 < e < 1.0:
                rng = range_message(self, "restitution", "in (0, 1)")
                raise ModelError(f"{w}.restitution: {rng} for the {self.law} law, got "
                                 f"{self.restitution!r}")

    @property
    def chi(self) -> float:
        """Damping factor chi [-] of the hysteresis term (0 for the penalty law)."""
        return damping_factor(self.law, self.restitution)

    @property
    def achieved_restitution(self) -> float:
        """Restitution this law produces (exact relation; 1 for the undamped penalty law)."""
        return restitution_from_chi(self.chi)

    def params(self) -> tuple[float, float, float, float, float]:
        """(K, n, chi, c, min_impact_speed) as the kernels use them."""
        return (float(self.stiffness), float(self.exponent), float(self.chi),
                float(self.damping), float(self.min_impact_speed))


def law_table(laws: list[NormalLaw]) -> np.ndarray:
    """Per-element parameters (nel, 5) of a group: rows (K, n, chi, c, vmin)."""
    return np.array([law.params() for law in laws], dtype=float).reshape(-1, 5)


# --- compiled helpers ------------------------------------------------------------------------

# layout of the per-contact state block (NSTATE floats in State.es, see impact_state)
ST_FLAG = 0  # 1 while in contact (at the last accepted step)
ST_VS = 1  # approach speed at first contact of the current / last contact [m/s]
ST_PEN = 2  # penetration at the last accepted step [m]
ST_RATE = 3  # penetration rate at the last accepted step [m/s]
ST_REBOUND = 4  # separation speed of the last finished contact [m/s]
ST_COUNT = 5  # number of contacts started
ST_TIME = 6  # time of the last accepted step [s]
ST_ACC = 7  # penetration acceleration over the last accepted step [m/s^2]
NSTATE = 8


@njit(cache=True, inline="always")
def impact_speed(es, o, vmin):
    """Approach speed v_s [m/s] used by the hysteresis term (a constant within a step).

    In contact at the last accepted step: the stored value. Otherwise (first step of a
    contact): the speed at ``delta = 0`` extrapolated from the last accepted state (before the
    contact: penetration ``p0 <= 0``, rate ``r0``, acceleration ``a0`` over its step) with
    constant acceleration, ``v_s^2 = r0^2 - 2 a0 p0`` -- exact in free flight and independent
    of the Newton iterate. Floored at ``vmin``.
    """
    if es[o + ST_FLAG] > 0.5:
        return es[o + ST_VS]
    p0 = es[o + ST_PEN]
    r0 = es[o + ST_RATE]
    w = r0 * r0
    if p0 < 0.0:
        w -= 2.0 * es[o + ST_ACC] * p0
    if w <= vmin * vmin:
        return vmin
    return np.sqrt(w)


@njit(cache=True, inline="always")
def power(x, n):
    """``x**n`` of a contact law's exponent ``n`` (``x > 0``): Hertz's 1.5 as ``x sqrt(x)``,
    0.5 as ``sqrt(x)``, 1 and 0 exactly; others by ``pow`` (9 ns against 2 ns for a square
    root: a flexible washer's contact points take one or two per point and evaluation)."""
    if n == 1.5:
        return x * np.sqrt(x)
    if n == 0.5:
        return np.sqrt(x)
    if n == 1.0:
        return x
    if n == 0.0:
        return 1.0 + 0.0 * x
    return x**n


@njit(cache=True, inline="always")
def normal_force(delta, rate, K, n, chi, c, vs):
    """Normal force of the law and its partial derivatives.

    Returns ``(F, dF/ddelta, dF/drate, V, P)`` with ``V`` the potential energy
    ``K delta^(n+1)/(n+1)`` [J] and ``P = (F - K delta^n) rate`` the dissipated power [W].
    Zero for ``delta <= 0``; clipped at zero force (derivatives zero) when the damping term
    would make it pull.
    """
    if delta <= 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0
    dn1 = power(delta, n - 1.0)
    kdn = K * dn1 * delta
    V = kdn * delta / (n + 1.0)
    hyst = 1.0 + chi * rate / vs
    F = kdn * hyst + c * rate
    if F <= 0.0:
        return 0.0, 0.0, 0.0, V, -kdn * rate
    Fd = n * K * dn1 * hyst
    Fr = kdn * chi / vs + c
    return F, Fd, Fr, V, (F - kdn) * rate


@njit(cache=True, inline="always")
def impact_state(delta, rate, vs, t, es, o, aux, e, c0):
    """Write the values the contact state takes if this step is accepted into
    ``aux[e, c0:c0 + NSTATE]`` (copied into ``es`` by the group's commit): contact flag,
    approach speed of the current/last contact, penetration and rate, separation speed of the
    last finished contact, number of contacts started, time and the acceleration over the step.

    The separation speed is interpolated at ``delta = 0`` between the last state in contact
    and the first one out of it with ``v^2`` linear in ``delta`` (constant acceleration over
    that step; the contact force vanishes smoothly there).
    """
    was = es[o + ST_FLAG] > 0.5
    now = delta > 0.0
    aux[e, c0 + ST_FLAG] = 1.0 if now else 0.0
    aux[e, c0 + ST_VS] = vs if now else es[o + ST_VS]
    aux[e, c0 + ST_PEN] = delta
    aux[e, c0 + ST_RATE] = rate
    reb = es[o + ST_REBOUND]
    if was and not now:
        p0 = es[o + ST_PEN]
        r0 = es[o + ST_RATE]
        th = 1.0
        if p0 > 0.0:
            th = p0 / (p0 - delta)
        reb = np.sqrt(max(r0 * r0 + th * (rate * rate - r0 * r0), 0.0))
    aux[e, c0 + ST_REBOUND] = reb
    aux[e, c0 + ST_COUNT] = es[o + ST_COUNT] + (1.0 if now and not was else 0.0)
    dt = t - es[o + ST_TIME]
    aux[e, c0 + ST_ACC] = (rate - es[o + ST_RATE]) / dt if dt > 0.0 else es[o + ST_ACC]
    aux[e, c0 + ST_TIME] = t


def initial_state(delta0: float, rate0: float, vmin: float, t0: float = 0.0) -> list[float]:
    """State block of a contact in its initial configuration (penetration ``delta0`` [m],
    rate ``rate0`` [m/s] at time ``t0``); an initially penetrating contact is in contact with
    the floor approach speed (its impact speed is unknown)."""
    inside = delta0 > 0.0
    return [1.0 if inside else 0.0, vmin if inside else 0.0, delta0, rate0, 0.0, 0.0, t0, 0.0]
