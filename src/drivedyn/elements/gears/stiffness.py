"""Mesh stiffness: ISO 6336-1 method B (build time) and its variation over the mesh cycle
(in the kernel).

* :func:`iso6336_single_stiffness`, :func:`iso6336_mesh_stiffness`: ISO 6336-1 method B
  (theoretical single stiffness from the C1..C9 series, ``C_M``, ``C_R``, ``C_B``, the helix
  factor and the mean mesh stiffness ``c_gamma_alpha = c' (0.75 eps_alpha + 0.25)``); SI, and
  the standard's own units (N/(mm um)) where it defines them, named ``*_iso``.
* :func:`mesh_cycle_levels`: the stiffness over the mesh cycle (pairs in contact).
* :func:`mesh_stiffness`: the smoothed two-level law ``k_m(phi_A)`` the kernel evaluates.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

E_STEEL = 206e9  # [Pa] Young's modulus of the steel/steel reference of ISO 6336-1
ISO_C = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)


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


@njit(cache=True)
def _smoothstep(y, w):
    """Quintic ramp from 0 (y <= -w/2) to 1 (y >= w/2): value, d/dy, d2/dy2."""
    t = y / w + 0.5
    if t <= 0.0:
        return 0.0, 0.0, 0.0
    if t >= 1.0:
        return 1.0, 0.0, 0.0
    return (t * t * t * (10.0 + t * (-15.0 + 6.0 * t)), 30.0 * t * t * (1.0 - t) ** 2 / w,
            60.0 * t * (1.0 - t) * (1.0 - 2.0 * t) / (w * w))


@njit(cache=True, inline="always")
def mesh_stiffness(dphi, kst):
    """k_m over the mesh cycle (smoothed two-level law): value, d/dphi_A, d2/dphi_A2."""
    k_lo = kst[0]
    k_hi = kst[1]
    if k_hi == k_lo:
        return k_lo, 0.0, 0.0
    f = kst[2]
    w = kst[3]
    dp = kst[4] / (2.0 * np.pi)
    ph = dp * dphi + kst[5]
    ph -= np.floor(ph)
    h0, h1, h2 = _smoothstep(ph, w)
    a0, a1, a2 = _smoothstep(ph - f, w)
    b0, b1, b2 = _smoothstep(ph - 1.0, w)
    dk = k_hi - k_lo
    return (k_lo + dk * (h0 - a0 + b0), dk * (h1 - a1 + b1) * dp,
            dk * (h2 - a2 + b2) * dp * dp)
