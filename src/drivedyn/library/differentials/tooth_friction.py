r"""Tooth friction of a parallel-axis helical mesh for the quasi-static (analytic) models,
derived by hand from the friction law of the gear element (not from its code).

**Law** (the gear element's, :mod:`drivedyn.elements.gears`): Coulomb friction ``mu`` on the
profile sliding of the loaded teeth, summed over the contacts of a mesh cycle and taken at
its cycle mean. A contact at the distance ``s`` from the pitch point along the line of action
slides at ``s |w_1 - w_2|`` (``w_1``, ``w_2``: the wheels' angular velocities about the common
axis direction, relative to the carrier that holds their centres); with the normal flank
force ``F_N`` shared equally by the contacts, the friction is a couple
``mu F_N s_eff`` on the two wheels, each one's couple turning it towards the other's angular
velocity::

    T_1 = -mu F_N s_eff sgn(w_1 - w_2),     T_2 = +mu F_N s_eff sgn(w_1 - w_2)

(no net force, so nothing else in the equilibrium changes: the couple changes the torque
ratio of the mesh, not its forces). Its power is ``mu F_N s_eff |w_1 - w_2|``. The law is
Coulomb's for sliding speeds ``s_eff |w_1 - w_2|`` above the element's regularisation speed
(``GearPair.friction_velocity``, 1 mm/s; 7-10 mm/s at the TORSEN benches' 20 rpm).

**Normal flank force**: the tooth normal lies in the normal plane at the normal pressure
angle; the torque of ``F_N`` about wheel i is ``F_N r_bi cos(beta_b)`` (its line of action is
tangent to the base cylinder, inclined by the base helix angle), equal to the tangential
force at the pitch circle times ``r_i``, so::

    F_N = |F_t| / (cos(alpha_t) cos(beta_b)) = |F_t| / (cos(alpha_n) cos(beta))

(``cos alpha_t cos beta_b = cos alpha_n cos beta``), whatever the centre distance.

**Mean arm** (Ohlendorf; ISO/TR 14179-2 gear loss factor ``H_V``): the path of contact runs
from ``-eps_2 p_bt`` (wheel 2's tip) to ``+eps_1 p_bt`` (wheel 1's tip), ``p_bt = pi m_t
cos(alpha_t)`` the transverse base pitch, ``eps_i`` the addendum contact ratios (without
profile shift ``eps_i p_bt = sqrt(r_ai^2 - r_bi^2) - r_bi tan(alpha_t)``; an internal wheel,
tips inside its pitch circle, ``r_bi tan(alpha_t) - sqrt(r_ai^2 - r_bi^2)``). Over one mesh
cycle (phase ``u`` in [0, 1), base pitches) with ``1 <= eps_alpha = eps_1 + eps_2 < 2`` and
``eps_1, eps_2 < 1``: for ``u < eps_alpha - 1`` two contacts at ``u - eps_2`` (< 0) and
``u - eps_2 + 1`` (> 0) share the load, mean arm ``((eps_2 - u) + (u - eps_2 + 1))/2 = 1/2``;
for ``u >= eps_alpha - 1`` one contact at ``u - eps_2``, from ``eps_1 - 1`` to ``1 - eps_2``
through the pitch point. The cycle mean::

    s_eff / p_bt = (eps_alpha - 1)/2 + ((1 - eps_1)^2 + (1 - eps_2)^2)/2
                 = (1 - eps_alpha + eps_1^2 + eps_2^2) / 2

Then ``mu F_N s_eff |w_1 - w_2|`` over the rolling power ``|F_t| r_1 |w_1|`` is Ohlendorf's
``mu H_V``, ``H_V = pi (1/z_1 +- 1/z_2) (1 - eps_alpha + eps_1^2 + eps_2^2) / cos(beta_b)``
(+ external, - internal; ``r_1 w_1 = r_2 w_2`` in magnitudes).
"""

from __future__ import annotations

import math


def contact_ratios(z1: int, z2: int, mn: float, alpha_n: float, beta: float
                   ) -> tuple[float, float, float]:
    """``(eps_1, eps_2, p_bt)``: addendum contact ratios of a pair without profile shift
    (addendum ``mn``) and the transverse base pitch [m]. ``z2 < 0``: internal wheel 2.

    Args:
        z1: tooth number of wheel 1 (external).
        z2: tooth number of wheel 2 (negative: internal).
        mn: normal module [m].
        alpha_n: normal pressure angle [rad].
        beta: helix angle [rad] (magnitude used).
    """
    cb = math.cos(beta)
    at = math.atan(math.tan(alpha_n) / cb)
    mt = mn / cb
    p_bt = math.pi * mt * math.cos(at)

    def eps(z: int) -> float:
        r = abs(z) * mt / 2
        rb = r * math.cos(at)
        ra = r + mn if z > 0 else r - mn  # an internal wheel's tips lie inside r
        g = math.sqrt(ra * ra - rb * rb) - rb * math.tan(at)
        return (g if z > 0 else -g) / p_bt

    return eps(z1), eps(z2), p_bt


def sliding_arm(z1: int, z2: int, mn: float, alpha_n: float, beta: float) -> float:
    """Ohlendorf's mean friction arm ``s_eff = p_bt (1 - eps_alpha + eps_1^2 + eps_2^2)/2``
    [m] (module docstring); ``z2 < 0``: internal wheel 2. Raises ``ValueError`` outside the
    formula's range (``1 <= eps_alpha < 2``, ``eps_1, eps_2 < 1``)."""
    e1, e2, p_bt = contact_ratios(z1, z2, mn, alpha_n, beta)
    if not (1.0 <= e1 + e2 < 2.0 and 0.0 < e1 < 1.0 and 0.0 < e2 < 1.0):
        raise ValueError(f"mean friction arm of the mesh z = {z1}/{z2}: contact ratios "
                         f"eps_1 = {e1:.4g}, eps_2 = {e2:.4g} outside 1 <= eps_alpha < 2, "
                         "eps_i < 1 (Ohlendorf's closed form)")
    return p_bt * (1.0 - (e1 + e2) + e1 * e1 + e2 * e2) / 2.0


def couple_arm(z1: int, z2: int, mn: float, alpha_n: float, beta: float) -> float:
    """``kappa = s_eff / (cos(alpha_n) cos(beta))`` [m]: the friction couple per unit
    friction coefficient and unit tangential (pitch-circle) force, ``mu F_N s_eff = mu |F_t|
    kappa`` (module docstring)."""
    return sliding_arm(z1, z2, mn, alpha_n, beta) / (math.cos(alpha_n) * math.cos(beta))
