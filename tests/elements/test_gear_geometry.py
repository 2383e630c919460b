"""Involute geometry, contact ratios and ISO 6336-1 method B mesh stiffness (build-time
numpy code of the gear element), against values worked by hand from the formulas."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drivedyn.elements.gears import (
    CylindricalPair,
    effective_sliding_arm,
    inverse_involute,
    involute,
    iso6336_mesh_stiffness,
    iso6336_single_stiffness,
    mesh_cycle_levels,
)
from drivedyn.elements.gears.geometry import top_land

DEG = math.pi / 180.0


@pytest.mark.parametrize("alpha", [1e-4, 0.1, 20 * DEG, 0.7, 1.3])
def test_inverse_involute(alpha):
    assert inverse_involute(involute(alpha)) == pytest.approx(alpha, rel=1e-13)


def test_standard_spur_pair_by_hand():
    """z = 20/40, m = 3 mm, alpha = 20 deg, no shift: radii, centre distance and the
    transverse contact ratio from the addendum and base circles."""
    p = CylindricalPair.build(20, 40, 3e-3, 20 * DEG)
    assert p.r1 == pytest.approx(0.030) and p.r2 == pytest.approx(0.060)
    assert p.aw == pytest.approx(0.090, rel=1e-14) and p.alpha_wt == pytest.approx(20 * DEG)
    rb1, rb2 = 0.030 * math.cos(20 * DEG), 0.060 * math.cos(20 * DEG)
    pb = math.pi * 3e-3 * math.cos(20 * DEG)
    eps = (math.sqrt(0.033**2 - rb1**2) + math.sqrt(0.063**2 - rb2**2)
           - 0.090 * math.sin(20 * DEG)) / pb
    assert p.eps_alpha == pytest.approx(eps, rel=1e-13)
    assert p.eps_alpha == pytest.approx(1.6352, abs=1e-4)
    assert p.eps_1 + p.eps_2 == pytest.approx(p.eps_alpha, rel=1e-14)


def test_profile_shift_and_internal_pair():
    """Working pressure angle from inv alpha_wt = inv alpha_t + 2 tan alpha_n (x1 + x2) /
    (z1 + z2); an internal gear (z2 < 0) has its tips inside the pitch circle and the
    contact ratio [g_a1 - g_a2 + a_w sin alpha_wt] / p_bt."""
    an, beta = 20 * DEG, 15 * DEG
    p = CylindricalPair.build(19, 41, 2e-3, an, beta, x1=0.3, x2=0.1)
    at = math.atan(math.tan(an) / math.cos(beta))
    inv_wt = math.tan(at) - at + 2 * math.tan(an) * 0.4 / 60
    assert involute(p.alpha_wt) == pytest.approx(inv_wt, rel=1e-12)
    assert p.aw == pytest.approx(0.5 * 60 * 2e-3 / math.cos(beta) * math.cos(at)
                                 / math.cos(p.alpha_wt), rel=1e-13)
    q = CylindricalPair.build(20, -60, 3e-3, an, beta)
    assert q.internal and q.aw < 0 and abs(q.ra2) < abs(q.r2)
    g1 = math.sqrt(q.ra1**2 - q.rb1**2)
    g2 = math.sqrt(q.ra2**2 - q.rb2**2)
    assert q.eps_alpha == pytest.approx((g1 - g2 + abs(q.aw) * math.sin(q.alpha_wt)) / q.p_bt,
                                        rel=1e-13)


def test_iso6336_worked_example():
    """ISO 6336-1 method B for z = 20/40, m_n = 3 mm, alpha_n = 20 deg, beta = 0, x = 0,
    b = 20 mm, standard basic rack (h_fP = 1.25 m_n), solid steel gears, worked by hand:

    q' = 0.04723 + 0.15551/20 + 0.25791/40 = 0.06145325 mm um/N, c'_th = 16.2725,
    C_B = [1 + 0.5 (1.2 - 1.25)] [1 - 0.02 (20 - 20)] = 0.975,
    c' = 16.2725 x 0.8 x 1 x 0.975 = 12.6926 N/(mm um),
    c_gamma_alpha = c' (0.75 eps_alpha + 0.25) = 18.739 N/(mm um) (eps_alpha = 1.63519),
    k_m = c_gamma_alpha b 1e6 = 3.7478e8 N/m.
    """
    p = CylindricalPair.build(20, 40, 3e-3, 20 * DEG)
    s = iso6336_mesh_stiffness(20, 40, 0.0, 20 * DEG, p.eps_alpha, 0.020)
    q = 0.04723 + 0.15551 / 20 + 0.25791 / 40
    assert s.q_iso == pytest.approx(q, rel=1e-14)
    assert s.c_b == pytest.approx(0.975, rel=1e-14)
    c1 = 1.0 / q * 0.8 * 0.975
    assert s.c_single_iso == pytest.approx(c1, rel=1e-14)
    assert s.c_single_iso == pytest.approx(12.6926, abs=1e-4)
    cga = c1 * (0.75 * p.eps_alpha + 0.25)
    assert s.c_gamma_alpha_iso == pytest.approx(cga, rel=1e-14)
    assert s.c_gamma_alpha_iso == pytest.approx(18.739, abs=1e-3)
    assert 14.0 <= s.c_gamma_alpha_iso <= 20.0  # typical range for steel gears
    assert s.k_mesh == pytest.approx(cga * 20.0 * 1e6, rel=1e-14)
    assert s.c_gamma_beta_iso == pytest.approx(0.85 * cga, rel=1e-14)


def test_iso6336_helical_shifted_internal_and_material():
    """Virtual tooth numbers z/cos^3 beta, shift terms, the cos(beta) factor, C_B of another
    rack and pressure angle, zn2 = inf for an internal gear, E scaling."""
    beta, an = 12 * DEG, 22.5 * DEG
    zn1, zn2 = 23 / math.cos(beta) ** 3, 57 / math.cos(beta) ** 3
    x1, x2 = 0.25, -0.1
    C = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)
    q = (C[0] + C[1] / zn1 + C[2] / zn2 + C[3] * x1 + C[4] * x1 / zn1 + C[5] * x2
         + C[6] * x2 / zn2 + C[7] * x1**2 + C[8] * x2**2)
    cb = (1 + 0.5 * (1.2 - 1.4)) * (1 - 0.02 * (20 - 22.5))
    qq, _cth, c1, cbb = iso6336_single_stiffness(zn1, zn2, x1, x2, beta, an, hfp=1.4,
                                                c_r=0.9, youngs_modulus=103e9)
    assert qq == pytest.approx(q, rel=1e-14) and cbb == pytest.approx(cb, rel=1e-14)
    assert c1 == pytest.approx(0.8 * 0.9 * cb * math.cos(beta) * 0.5 / q, rel=1e-14)
    s = iso6336_mesh_stiffness(20, -60, 0.0, 20 * DEG, 1.8, 0.01)
    assert s.q_iso == pytest.approx(0.04723 + 0.15551 / 20, rel=1e-14)


def test_mesh_cycle_levels_average_to_the_iso_mean():
    """k' (0.75 n + 0.25) with n pairs in contact averages to c' (0.75 eps + 0.25)."""
    for eps in (1.35, 1.64, 2.2):
        lo, hi, f = mesh_cycle_levels(1.0, eps)
        assert (1 - f) * lo + f * hi == pytest.approx(0.75 * eps + 0.25, rel=1e-14)
    assert mesh_cycle_levels(2.0, 1.5)[:2] == pytest.approx((2.0, 3.5))


@pytest.mark.parametrize(("z1", "z2"), [(20, 40), (13, 17), (25, 77)])
def test_effective_sliding_arm_matches_ohlendorf(z1, z2):
    """Mean load-shared distance from the pitch point = p_bt (1 - eps + eps1^2 + eps2^2)/2
    (Ohlendorf; ISO/TR 14179-2 gear loss factor) for 1 < eps_alpha < 2."""
    p = CylindricalPair.build(z1, z2, 2e-3, 20 * DEG, 10 * DEG)
    assert 1.0 < p.eps_alpha < 2.0 and max(p.eps_1, p.eps_2) < 1.0
    ref = 0.5 * p.p_bt * (1 - p.eps_alpha + p.eps_1**2 + p.eps_2**2)
    assert effective_sliding_arm(p.eps_1, p.eps_2, p.p_bt) == pytest.approx(ref, rel=1e-12)


def test_effective_sliding_arm_single_pair():
    """eps_1 = eps_2 = 1/2 (eps_alpha = 1): one contact sweeps [-p/2, p/2] uniformly, so the
    mean |s| is p/4; long paths (eps_1, eps_2 > 1) stay finite."""
    assert effective_sliding_arm(0.5, 0.5, 1.0) == pytest.approx(0.25, rel=1e-14)
    assert np.isfinite(effective_sliding_arm(1.2, 1.1, 0.01))


def test_undercut_limits_spur_and_helical() -> None:
    """Spur 20 deg: the classical limit 2 / sin^2(20 deg) = 17.1 teeth, practical 14.25
    (Roloff/Matek x_min = (14 - z) / 17); helical: the rack's addendum line must not pass
    below the interference point, (h_a - x) m_n <= r sin^2(alpha_t), r = z m_n / (2 cos b)."""
    from drivedyn.elements.gears import undercut_limits

    a20 = np.radians(20.0)
    z_g, _, _ = undercut_limits(8, a20)
    assert z_g == pytest.approx(2 / np.sin(a20) ** 2, rel=1e-14)
    assert z_g == pytest.approx(17.097, abs=1e-3)
    for z in range(6, 15):
        assert undercut_limits(z, a20)[2] == pytest.approx((14 - z) / 17, abs=0.02)
    mn = 1.5e-3
    for z, beta in ((10, np.radians(30.0)), (12, np.radians(15.0)), (25, np.radians(40.0))):
        _, x_th, _ = undercut_limits(z, a20, beta)
        alpha_t = np.arctan(np.tan(a20) / np.cos(beta))
        r = z * mn / (2 * np.cos(beta))
        assert (1.0 - x_th) * mn == pytest.approx(r * np.sin(alpha_t) ** 2, rel=1e-12)


def test_gear_pair_refuses_undercut() -> None:
    from drivedyn.elements import GearPair
    from drivedyn.errors import ModelError

    kw = dict(module=2e-3, face_width=0.02)
    with pytest.raises(ModelError, match=r"teeth_a.*undercuts.*profile_shift_a >= 0\.36"):
        GearPair("g", "a", "b", 8, 40, **kw).validate()
    GearPair("g", "a", "b", 8, 40, profile_shift_a=0.37, profile_shift_b=-0.37, **kw).validate()
    GearPair("g", "a", "b", 15, 40, **kw).validate()          # slight undercut accepted
    # the Type C planets (z 10, 30 deg helix) are within the practical limit
    GearPair("g", "a", "b", 50, 10, helix_angle=np.radians(30), **kw).validate()
    # the ring of an internal pair is not a rack-cut external wheel: only the pinion counts
    GearPair("g", "a", "b", 10, 70, internal="b", helix_angle=np.radians(30), **kw).validate()
    with pytest.raises(ModelError, match=r"teeth_b.*undercuts"):
        GearPair("g", "a", "b", 40, 9, **kw).validate()
    # bevel: Tredgold's virtual number z / cos(delta) (10 teeth on a 20 deg cone: 10.6)
    with pytest.raises(ModelError, match=r"teeth_a.*undercuts"):
        GearPair("g", "a", "b", 10, 27, kind="bevel", cone_angle_a=np.radians(20.3),
                 cone_angle_b=np.radians(69.7), **kw).validate()


def test_top_land_by_hand() -> None:
    """Top land of a z 20, m 1 mm, 20 deg spur gear worked by hand (ISO 21771): d_a = 22,
    d_b = 18.794, alpha_a = 31.321 deg, s_a = 22 (pi/40 + inv 20 deg - inv alpha_a) =
    0.6949 mm; a helical gear's normal land is the transverse one times cos(beta_a); a
    positive profile shift widens the tooth but its tip (d_a grows) narrows the land."""
    s, beta_a = top_land(20, 1e-3, 20 * DEG)
    db = 20e-3 * math.cos(20 * DEG)
    aa = math.acos(db / 22e-3)
    ref = 22e-3 * (math.pi / 40 + involute(20 * DEG) - involute(aa))
    assert s == pytest.approx(ref, rel=1e-12) and s == pytest.approx(0.6949e-3, rel=1e-3)
    assert beta_a == 0.0
    sn, beta_a = top_land(12, 2e-3, 20 * DEG, 30 * DEG)
    assert beta_a == pytest.approx(math.atan(math.tan(30 * DEG) * 31.7128 / 27.7128), rel=1e-5)
    assert sn == pytest.approx(1.6505e-3 * math.cos(beta_a), rel=1e-3)
    assert top_land(20, 1e-3, 20 * DEG, x=0.5)[0] < s
