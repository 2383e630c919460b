"""Involute gear geometry (plain numpy, build time only).

Everything here is SI (m, rad) unless a name says otherwise.

Conventions (ISO 21771): wheel 1 is external; wheel 2 is external (``z2 > 0``) or an internal
(ring) gear, written with a *negative* tooth number ``z2 < 0``. Radii and the centre distance
of an internal pair then come out negative (the "negative centre distance" convention);
:class:`CylindricalPair` stores them signed and also gives positive magnitudes. The profile
shift of an internal gear follows the same signed formulas (ISO 21771).

Contents:

* :func:`involute`, :func:`inverse_involute`: ``inv a = tan a - a`` and its inverse.
* :class:`CylindricalPair`: transverse/base quantities, working pressure angle and centre
  distance, transverse contact ratio ``eps_alpha`` and the addendum contact ratios.
* :func:`effective_sliding_arm`: mean distance of the loaded contact from the pitch point,
  the arm of the mean tooth friction loss (Ohlendorf / ISO/TR 14179-2 gear loss factor).

The mesh stiffness (ISO 6336-1) is in :mod:`drivedyn.elements.gears.stiffness`.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise

import numpy as np


def involute(alpha: float) -> float:
    """``inv alpha = tan alpha - alpha`` [rad] for ``0 <= alpha < pi/2``."""
    return float(np.tan(alpha) - alpha)


def inverse_involute(value: float) -> float:
    """The angle ``alpha`` [rad] in ``[0, pi/2)`` with ``inv alpha = value`` (Newton)."""
    if value < 0.0:
        raise ValueError(f"involute function value must be >= 0, got {value}")
    if value == 0.0:
        return 0.0
    a = min(1.4, (3.0 * value) ** (1.0 / 3.0))  # inv a ~ a^3/3 for small a
    for _ in range(60):
        f = np.tan(a) - a - value
        da = f / np.tan(a) ** 2  # d(inv a)/da = tan^2 a
        a -= da
        a = min(max(a, 1e-12), 1.5707963)
        if abs(da) < 1e-15:
            break
    return float(a)


def transverse_pressure_angle(alpha_n: float, beta: float) -> float:
    """``alpha_t = atan(tan alpha_n / cos beta)`` [rad]."""
    return float(np.arctan(np.tan(alpha_n) / np.cos(beta)))


def undercut_limits(teeth: float, alpha_n: float, beta: float = 0.0,
                    addendum: float = 1.0) -> tuple[float, float, float]:
    """Undercut limits of an external cylindrical gear cut by a rack (ISO 21771, DIN 3960).

    Args:
        teeth: number of teeth z (a bevel gear: its virtual number z / cos(delta)).
        alpha_n: normal pressure angle [rad].
        beta: helix angle [rad].
        addendum: rack addendum over the module, h_aP / m_n (the tool's dedendum).

    Returns:
        ``(z_g, x_theoretical, x_practical)``: the limit number of teeth without undercut at
        zero profile shift, ``z_g = 2 h_a cos(beta) / sin^2(alpha_t)``; the smallest profile
        shift coefficient without undercut, ``h_a (1 - z / z_g)``; and the smallest with the
        slight undercut accepted in practice (DIN 3960, Niemann: limit number of teeth
        ``z'_g = 5/6 z_g``, 14 for a 20 deg spur gear), ``h_a (5/6 - z / z_g)``.
    """
    alpha_t = transverse_pressure_angle(alpha_n, beta)
    z_g = 2.0 * addendum * np.cos(beta) / np.sin(alpha_t) ** 2
    return float(z_g), float(addendum * (1.0 - teeth / z_g)), \
        float(addendum * (5.0 / 6.0 - teeth / z_g))


def top_land(teeth: int, mn: float, alpha_n: float, beta: float = 0.0, x: float = 0.0,
             addendum: float = 1.0) -> tuple[float, float]:
    """Top land of an external cylindrical gear (ISO 21771): ``(s_na, beta_a)``, its width
    normal to the tooth trace on the tip cylinder [m] and the helix angle there [rad].

    ``s_at = d_a (s_t / d + inv alpha_t - inv alpha_at)`` with ``s_t = m_t (pi/2 + 2 x tan
    alpha_n)``, ``cos alpha_at = d_b / d_a``, ``tan beta_a = tan beta d_a / d`` and
    ``s_na = s_at cos beta_a``; ``teeth`` z, normal module ``mn`` [m], normal pressure
    angle ``alpha_n`` and reference helix angle ``beta`` [rad], profile shift coefficient
    ``x``, addendum coefficient ``addendum`` (tip radius ``d/2 + (addendum + x) mn``).
    """
    beta = abs(beta)
    alpha_t = transverse_pressure_angle(alpha_n, beta)
    mt = mn / np.cos(beta)
    d = teeth * mt
    da = d + 2.0 * (addendum + x) * mn
    db = d * np.cos(alpha_t)
    alpha_at = float(np.arccos(db / da))
    st = mt * (0.5 * np.pi + 2.0 * x * np.tan(alpha_n))
    sat = da * (st / d + involute(alpha_t) - involute(alpha_at))
    beta_a = float(np.arctan(np.tan(beta) * da / d))
    return float(sat * np.cos(beta_a)), beta_a


def base_helix_angle(alpha_n: float, beta: float) -> float:
    """``beta_b = asin(sin beta cos alpha_n)`` [rad] (signed like ``beta``)."""
    return float(np.arcsin(np.sin(beta) * np.cos(alpha_n)))


@dataclass(frozen=True)
class CylindricalPair:
    """Geometry of a spur or helical pair with parallel axes (ISO 21771 formulas).

    Attributes (lengths in m, angles in rad; ``2`` is negative for an internal gear):
        z1, z2: tooth numbers (``z2 < 0``: internal gear).
        mn: normal module.
        alpha_n: normal pressure angle.
        beta: helix angle at the reference cylinder (magnitude; hands are checked elsewhere).
        x1, x2: profile shift coefficients.
        ha: addendum coefficient of the basic rack (h_aP / m_n).
        alpha_t: transverse pressure angle.
        beta_b: base helix angle.
        mt: transverse module.
        r1, r2: reference (pitch) radii, signed.
        rb1, rb2: base radii, signed.
        ra1, ra2: tip radii, signed.
        a: reference centre distance ``r1 + r2``, signed.
        alpha_wt: working transverse pressure angle.
        aw: working centre distance, signed.
        p_bt: transverse base pitch.
        eps_alpha: transverse contact ratio.
        eps_1, eps_2: addendum contact ratios of wheels 1 and 2 (``eps_1 + eps_2 =
            eps_alpha``).
    """

    z1: int
    z2: int
    mn: float
    alpha_n: float
    beta: float
    x1: float
    x2: float
    ha: float
    alpha_t: float
    beta_b: float
    mt: float
    r1: float
    r2: float
    rb1: float
    rb2: float
    ra1: float
    ra2: float
    a: float
    alpha_wt: float
    aw: float
    p_bt: float
    eps_alpha: float
    eps_1: float
    eps_2: float

    @property
    def internal(self) -> bool:
        return self.z2 < 0

    @property
    def centre_distance(self) -> float:
        """Working centre distance, positive [m]."""
        return abs(self.aw)

    @classmethod
    def build(cls, z1: int, z2: int, mn: float, alpha_n: float, beta: float = 0.0,
              x1: float = 0.0, x2: float = 0.0, ha: float = 1.0) -> CylindricalPair:
        """Compute the pair (``z2 < 0`` for an internal gear)."""
        if z1 <= 0 or z2 == 0 or (z2 < 0 and -z2 <= z1):
            raise ValueError(f"invalid tooth numbers z1 = {z1}, z2 = {z2} (internal gears: "
                             "z2 < 0 with |z2| > z1)")
        beta = abs(float(beta))
        alpha_t = transverse_pressure_angle(alpha_n, beta)
        beta_b = base_helix_angle(alpha_n, beta)
        mt = mn / np.cos(beta)
        r1, r2 = 0.5 * z1 * mt, 0.5 * z2 * mt
        rb1, rb2 = r1 * np.cos(alpha_t), r2 * np.cos(alpha_t)
        ra1 = r1 + mn * (ha + x1)
        ra2 = r2 + mn * (ha + x2)  # signed: an internal gear's tips lie inside r2
        inv_wt = involute(alpha_t) + 2.0 * np.tan(alpha_n) * (x1 + x2) / (z1 + z2)
        alpha_wt = inverse_involute(inv_wt)
        a = r1 + r2
        aw = a * np.cos(alpha_t) / np.cos(alpha_wt)
        p_bt = np.pi * mt * np.cos(alpha_t)
        sgn = 1.0 if z2 > 0 else -1.0
        g1 = np.sqrt(max(ra1**2 - rb1**2, 0.0))
        g2 = np.sqrt(max(ra2**2 - rb2**2, 0.0))
        eps_1 = (g1 - rb1 * np.tan(alpha_wt)) / p_bt
        eps_2 = sgn * (g2 - abs(rb2) * np.tan(alpha_wt)) / p_bt
        return cls(z1, z2, mn, alpha_n, beta, x1, x2, ha, alpha_t, beta_b, mt, r1, r2, rb1,
                   rb2, ra1, ra2, a, alpha_wt, aw, p_bt, eps_1 + eps_2, eps_1, eps_2)


def effective_sliding_arm(eps_1: float, eps_2: float, p_bt: float) -> float:
    """Mean load-weighted distance of the contact from the pitch point [m].

    The path of contact runs from ``-eps_2 p_bt`` (start, on wheel 2's tip) to ``eps_1 p_bt``
    (end); contacts follow each other at one base pitch and share the load equally. The mean
    over a mesh cycle of ``sum_i |s_i| F_i / F`` is the arm ``s_eff`` of the mean friction
    loss ``P = mu F_n s_eff |omega_rel|``; for ``1 <= eps_alpha < 2`` it equals Ohlendorf's
    ``p_bt (1 - eps_alpha + eps_1^2 + eps_2^2) / 2`` (ISO/TR 14179-2 gear loss factor H_V).
    Integrated exactly: between the phases where a contact enters or leaves the path or
    passes the pitch point the integrand is linear in the phase (midpoint rule is exact).
    """
    s0, s1 = -eps_2 * p_bt, eps_1 * p_bt
    if s1 <= s0:
        return 0.0
    nmax = int(np.ceil((s1 - s0) / p_bt)) + 1
    j = np.arange(nmax)
    # contact j sits at s0 + (tau + j) p_bt for the cycle phase tau in [0, 1)
    cuts = np.concatenate([[0.0, 1.0], (s1 - s0) / p_bt - j, -s0 / p_bt - j])
    cuts = np.unique(cuts[(cuts >= 0.0) & (cuts <= 1.0)])
    total = 0.0
    for ta, tb in pairwise(cuts):
        pos = s0 + (0.5 * (ta + tb) + j) * p_bt
        pos = pos[pos < s1]
        if pos.size:
            total += (tb - ta) * np.abs(pos).sum() / pos.size
    return float(total)
