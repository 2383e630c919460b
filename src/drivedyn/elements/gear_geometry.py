"""Involute gear geometry and ISO 6336-1 mesh stiffness (plain numpy, build time only).

Everything here is SI (m, rad, N/m) unless a name says otherwise; the ISO 6336 functions also
return the standard's own units (N/(mm um)) where the standard defines them, named ``*_iso``.

Conventions (ISO 21771): wheel 1 is external; wheel 2 is external (``z2 > 0``) or an internal
(ring) gear, written with a *negative* tooth number ``z2 < 0``. Radii and the centre distance
of an internal pair then come out negative (the "negative centre distance" convention);
:class:`CylindricalPair` stores them signed and also gives positive magnitudes. The profile
shift of an internal gear follows the same signed formulas (ISO 21771).

Contents:

* :func:`involute`, :func:`inverse_involute`: ``inv a = tan a - a`` and its inverse.
* :class:`CylindricalPair`: transverse/base quantities, working pressure angle and centre
  distance, transverse contact ratio ``eps_alpha`` and the addendum contact ratios.
* :func:`iso6336_single_stiffness`, :func:`iso6336_mesh_stiffness`: ISO 6336-1 method B
  (theoretical single stiffness from the C1..C9 series, ``C_M``, ``C_R``, ``C_B``, the helix
  factor and the mean mesh stiffness ``c_gamma_alpha = c' (0.75 eps_alpha + 0.25)``).
* :func:`mesh_cycle_levels`: the stiffness over the mesh cycle (pairs in contact).
* :func:`effective_sliding_arm`: mean distance of the loaded contact from the pitch point,
  the arm of the mean tooth friction loss (Ohlendorf / ISO/TR 14179-2 gear loss factor).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise

import numpy as np

E_STEEL = 206e9  # [Pa] Young's modulus of the steel/steel reference of ISO 6336-1
ISO_C = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)


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


@dataclass(frozen=True)
class IsoStiffness:
    """ISO 6336-1 method B result.

    Attributes:
        q_iso: minimum flexibility of a tooth pair q' [mm um/N].
        c_th_iso: theoretical single stiffness c'_th = 1/q' [N/(mm um)].
        c_single_iso: single stiffness c' [N/(mm um)].
        c_gamma_alpha_iso: mean mesh stiffness c_gamma_alpha [N/(mm um)].
        c_gamma_beta_iso: 0.85 c_gamma_alpha [N/(mm um)] (for the face load factor).
        k_single: c' times the face width [N/m] (one tooth pair).
        k_mesh: c_gamma_alpha times the face width [N/m] (the mesh stiffness k_m).
        c_m, c_r, c_b: the correction factors used.
    """

    q_iso: float
    c_th_iso: float
    c_single_iso: float
    c_gamma_alpha_iso: float
    c_gamma_beta_iso: float
    k_single: float
    k_mesh: float
    c_m: float
    c_r: float
    c_b: float


def iso6336_single_stiffness(zn1: float, zn2: float, x1: float, x2: float, beta: float,
                             alpha_n: float, hfp: float = 1.25, c_r: float = 1.0,
                             c_m: float = 0.8, youngs_modulus: float = E_STEEL
                             ) -> tuple[float, float, float, float]:
    """ISO 6336-1 method B single stiffness.

    ``q' = C1 + C2/zn1 + C3/zn2 + C4 x1 + C5 x1/zn1 + C6 x2 + C7 x2/zn2 + C8 x1^2 + C9 x2^2``
    [mm um/N] with the virtual tooth numbers ``zn = z / cos^3 beta`` (``zn2 = inf`` for an
    internal gear: pass ``np.inf``), ``c'_th = 1/q'`` and
    ``c' = c'_th C_M C_R C_B cos(beta) E/E_st`` with
    ``C_B = [1 + 0.5 (1.2 - h_fP/m_n)] [1 - 0.02 (20 deg - alpha_n)]``.

    Args:
        zn1, zn2: virtual tooth numbers (``zn2 = np.inf`` for an internal gear).
        x1, x2: profile shift coefficients.
        beta: reference helix angle [rad].
        alpha_n: normal pressure angle [rad].
        hfp: dedendum of the basic rack over the module, h_fP/m_n.
        c_r: gear blank factor C_R (1 for solid disc gears).
        c_m: correction factor C_M (0.8 in ISO 6336-1).
        youngs_modulus: equivalent E = 2 E1 E2 / (E1 + E2) [Pa]; c' scales with E / 206 GPa.

    Returns:
        (q', c'_th, c', C_B) with q' in mm um/N and stiffnesses in N/(mm um).
    """
    C = ISO_C
    inv2 = 0.0 if np.isinf(zn2) else 1.0 / zn2
    q = (C[0] + C[1] / zn1 + C[2] * inv2 + C[3] * x1 + C[4] * x1 / zn1 + C[5] * x2
         + C[6] * x2 * inv2 + C[7] * x1**2 + C[8] * x2**2)
    c_th = 1.0 / q
    c_b = (1.0 + 0.5 * (1.2 - hfp)) * (1.0 - 0.02 * (20.0 - np.degrees(alpha_n)))
    c_single = c_th * c_m * c_r * c_b * np.cos(beta) * youngs_modulus / E_STEEL
    return float(q), float(c_th), float(c_single), float(c_b)


def iso6336_mesh_stiffness(z1: int, z2: int, beta: float, alpha_n: float, eps_alpha: float,
                           face_width: float, x1: float = 0.0, x2: float = 0.0,
                           hfp: float = 1.25, c_r: float = 1.0,
                           youngs_modulus: float = E_STEEL) -> IsoStiffness:
    """Mesh stiffness by ISO 6336-1 method B.

    ``c_gamma_alpha = c' (0.75 eps_alpha + 0.25)``, ``k_m = c_gamma_alpha b`` (in SI,
    1 N/(mm um) = 1e9 N/m^2). ``z2 < 0`` marks an internal gear (``zn2 = inf``).
    Not included: the reduction of c' below a specific load of 100 N/mm.
    """
    cb3 = np.cos(beta) ** 3
    zn1 = z1 / cb3
    zn2 = np.inf if z2 < 0 else z2 / cb3
    q, c_th, c_single, c_b = iso6336_single_stiffness(zn1, zn2, x1, x2, beta, alpha_n, hfp,
                                                      c_r, 0.8, youngs_modulus)
    cga = c_single * (0.75 * eps_alpha + 0.25)
    return IsoStiffness(q, c_th, c_single, cga, 0.85 * cga, c_single * 1e9 * face_width,
                        cga * 1e9 * face_width, 0.8, c_r, c_b)


def mesh_cycle_levels(k_single: float, eps_alpha: float) -> tuple[float, float, float]:
    """Stiffness over one mesh cycle as two levels.

    With ``n`` tooth pairs in contact the mesh stiffness is ``k' (0.75 n + 0.25)``: the ISO
    mean ``c' (0.75 eps_alpha + 0.25)`` is exactly the cycle average of this law, since
    ``floor(eps_alpha) + 1`` pairs carry the load over the fraction ``frac(eps_alpha)`` of the
    cycle and ``floor(eps_alpha)`` pairs over the rest.

    Returns:
        (k_low, k_high, f_high): stiffnesses [N/m] with ``floor(eps)`` and ``floor(eps) + 1``
        pairs, and the fraction of the cycle with the higher one.
    """
    n = float(np.floor(eps_alpha))
    f = float(eps_alpha - n)
    return k_single * (0.75 * n + 0.25), k_single * (0.75 * (n + 1.0) + 0.25), f


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
