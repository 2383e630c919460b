"""Magic Formula tyres: hand-computed points of Pacejka's equations, peaks, combined slip,
relaxation lengths, the simple sets and the errors of malformed property files."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drivedyn.errors import ModelError
from drivedyn.tyres import SURFACES, read_tir, shipped, shipped_files, simple_tyre
from drivedyn.tyres.tir import parse_tir

TIR = shipped("pac2002_235_60R16")


def _coeffs(path) -> dict[str, float]:
    """The file's numbers by key (independent of the reader's coefficient array)."""
    out: dict[str, float] = {}
    for sec in parse_tir(path).sections.values():
        for k, v in sec.items():
            if isinstance(v, float):
                out[k] = v
    return out


def _mf(B, C, D, E, x):
    return D * math.sin(C * math.atan(B * x - E * (B * x - math.atan(B * x))))


def _hand_52(c, fz, kappa, alpha, gamma):
    """MF 5.2 (Pacejka 2012 4.E9-4.E78 with MF 5.2 camber terms), written out once more."""
    g = c.get
    r0, fz0 = c["UNLOADED_RADIUS"], c["FNOMIN"]
    dfz = (fz - fz0) / fz0
    ta = math.tan(alpha)
    # longitudinal
    kx = kappa + g("PHX1", 0) + g("PHX2", 0) * dfz
    mux = (c["PDX1"] + g("PDX2", 0) * dfz) * (1 - g("PDX3", 0) * gamma ** 2)
    Dx = mux * fz
    Ex = (g("PEX1", 0) + g("PEX2", 0) * dfz + g("PEX3", 0) * dfz ** 2) * (
        1 - g("PEX4", 0) * np.sign(kx))
    Kx = fz * (c["PKX1"] + g("PKX2", 0) * dfz) * math.exp(g("PKX3", 0) * dfz)
    Bx = Kx / (c["PCX1"] * Dx + 1e-6)
    Fx0 = _mf(Bx, c["PCX1"], Dx, Ex, kx) + fz * (g("PVX1", 0) + g("PVX2", 0) * dfz)

    def lateral(gam):
        Ky = c["PKY1"] * fz0 * math.sin(2 * math.atan(fz / (c["PKY2"] * fz0))) * (
            1 - g("PKY3", 0) * abs(gam))
        Shy = g("PHY1", 0) + g("PHY2", 0) * dfz + g("PHY3", 0) * gam
        ay = ta + Shy
        muy = (c["PDY1"] + g("PDY2", 0) * dfz) * (1 - g("PDY3", 0) * gam ** 2)
        Ey = min((g("PEY1", 0) + g("PEY2", 0) * dfz)
                 * (1 - (g("PEY3", 0) + g("PEY4", 0) * gam) * np.sign(ay)), 1.0)
        By = Ky / (c["PCY1"] * muy * fz + 1e-6)
        Svy = fz * (g("PVY1", 0) + g("PVY2", 0) * dfz + (g("PVY3", 0) + g("PVY4", 0) * dfz)
                    * gam)
        return _mf(By, c["PCY1"], muy * fz, Ey, ay) + Svy, muy, By, Ky, Shy, Svy

    Fy0, muy, By, Ky, Shy, Svy = lateral(gamma)
    # combined
    def w(B, C, E, x):
        return math.cos(C * math.atan(B * x - E * (B * x - math.atan(B * x))))
    Bxa = c["RBX1"] * math.cos(math.atan(c["RBX2"] * kappa))
    Exa = c["REX1"] + c["REX2"] * dfz
    Fx = Fx0 * w(Bxa, c["RCX1"], Exa, ta + c["RHX1"]) / w(Bxa, c["RCX1"], Exa, c["RHX1"])
    Byk = c["RBY1"] * math.cos(math.atan(c["RBY2"] * (ta - c["RBY3"])))
    Eyk = c["REY1"] + c["REY2"] * dfz
    Shyk = c["RHY1"] + c["RHY2"] * dfz
    Gyk = w(Byk, c["RCY1"], Eyk, kappa + Shyk) / w(Byk, c["RCY1"], Eyk, Shyk)
    Dvyk = muy * fz * (c["RVY1"] + c["RVY2"] * dfz + c["RVY3"] * gamma) * math.cos(
        math.atan(c["RVY4"] * ta))
    Fy = Gyk * Fy0 + Dvyk * math.sin(c["RVY5"] * math.atan(c["RVY6"] * kappa))
    # aligning
    ca = math.cos(alpha)
    at = ta + g("QHZ1", 0) + g("QHZ2", 0) * dfz + (g("QHZ3", 0) + g("QHZ4", 0) * dfz) * gamma
    Bt = (c["QBZ1"] + g("QBZ2", 0) * dfz + g("QBZ3", 0) * dfz ** 2) * (
        1 + g("QBZ4", 0) * gamma + g("QBZ5", 0) * abs(gamma))
    Ct = c["QCZ1"]
    Dt = fz * (r0 / fz0) * (c["QDZ1"] + g("QDZ2", 0) * dfz) * (
        1 + g("QDZ3", 0) * gamma + g("QDZ4", 0) * gamma ** 2)
    Et = min((g("QEZ1", 0) + g("QEZ2", 0) * dfz + g("QEZ3", 0) * dfz ** 2) * (
        1 + (g("QEZ4", 0) + g("QEZ5", 0) * gamma) * 2 / math.pi * math.atan(Bt * Ct * at)), 1)
    ar = ta + Shy + Svy / (Ky + 1e-6)
    Br = g("QBZ9", 0) + g("QBZ10", 0) * By * c["PCY1"]
    Dr = fz * r0 * ((g("QDZ6", 0) + g("QDZ7", 0) * dfz)
                    + (g("QDZ8", 0) + g("QDZ9", 0) * dfz) * gamma) * ca
    rk = Kx / (Ky + 1e-6)
    at_eq = math.copysign(math.hypot(at, rk * kappa), at)
    ar_eq = math.copysign(math.hypot(ar, rk * kappa), ar)
    t = Dt * w(Bt, Ct, Et, at_eq) * ca
    Fyp = Gyk * lateral(0.0)[0]
    s = r0 * (g("SSZ1", 0) + g("SSZ2", 0) * Fy / fz0 + (g("SSZ3", 0) + g("SSZ4", 0) * dfz)
              * gamma)
    Mz = -t * Fyp + Dr * math.cos(math.atan(Br * ar_eq)) + s * Fx
    return Fx, Fy, Mz


POINTS = [  # (fz [N], kappa, alpha [rad], gamma [rad])
    (4000.0, 0.05, 0.0, 0.0), (2500.0, -0.12, 0.0, 0.0), (6000.0, 0.0, 0.06, 0.0),
    (3000.0, 0.0, -0.2, 0.0), (4500.0, 0.08, 0.04, 0.0), (3500.0, -0.3, 0.1, 0.02),
    (5200.0, 0.4, -0.15, -0.03),
]


@pytest.mark.parametrize("point", POINTS)
def test_mf52_matches_hand_computed_points(point):
    tyre = read_tir(TIR)
    c = _coeffs(TIR)
    fx, fy, mz = tyre.forces(*point)
    ex, ey, ez = _hand_52(c, *point)
    assert fx == pytest.approx(ex, rel=1e-9, abs=1e-9)
    assert fy == pytest.approx(ey, rel=1e-9, abs=1e-9)
    assert mz == pytest.approx(ez, rel=1e-9, abs=1e-9)


def test_pure_slip_peak_position_and_value():
    """The pure longitudinal peak is D + S_V at the slip where the MF argument is pi/(2C)."""
    tyre = read_tir(TIR)
    c = _coeffs(TIR)
    fz = 4000.0
    kap = np.linspace(0.0, 0.5, 50001)
    fx = tyre.forces(fz, kap, 0.0)[0]
    i = int(np.argmax(fx))
    C, D = c["PCX1"], c["PDX1"] * fz
    E = c["PEX1"] * (1 - c["PEX4"])
    B = c["PKX1"] * fz / (C * D + 1e-6)
    # B x - E (B x - atan B x) = tan(pi / 2C) solved by bisection
    lo, hi = 0.0, 1.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if B * mid - E * (B * mid - math.atan(B * mid)) < math.tan(math.pi / (2 * C)):
            lo = mid
        else:
            hi = mid
    k_peak = lo - c["PHX1"]
    assert kap[i] == pytest.approx(k_peak, abs=1e-5)
    assert fx[i] == pytest.approx(D + fz * c["PVX1"], rel=1e-9)


def test_combined_slip_reduces_both_forces():
    """Adding the other slip lowers each force, over a grid of slips (not at the smallest,
    where the combined-slip shifts RHX1, RVY* may raise them slightly)."""
    tyre = read_tir(TIR)
    kap = np.array([0.05, 0.1, 0.2, 0.4])[:, None]
    alp = np.array([0.05, 0.1, 0.2])[None, :]
    fx, fy, _ = tyre.forces(4000.0, kap, alp)
    fx_pure = tyre.forces(4000.0, kap, 0.0)[0]
    fy_pure = tyre.forces(4000.0, 0.0, alp)[1]
    assert np.all(fx < fx_pure) and np.all(fx > 0)
    assert np.all(-fy < -fy_pure) and np.all(fy < 0)
    # strongly where the other slip dominates (measured 0.314 and 0.252)
    assert fx[0, 2] < 0.33 * fx_pure[0, 0] and -fy[3, 0] < 0.27 * -fy_pure[0, 0]


def test_slip_stiffness_is_the_slope_at_zero_slip():
    tyre = read_tir(TIR)
    r = tyre.evaluate(4000.0, 0.0, 0.0)
    h = 1e-6
    shx = tyre.value("PHX1")
    dfx = (tyre.forces(4000.0, -shx + h, 0.0)[0] - tyre.forces(4000.0, -shx - h, 0.0)[0]) / (2 * h)
    assert dfx == pytest.approx(r["kxk"], rel=1e-6)
    assert r["kxk"] == pytest.approx(22.303 * 4000.0, rel=1e-12)


def test_relaxation_lengths_mf52():
    tyre = read_tir(TIR)
    c = _coeffs(TIR)
    fz = 3000.0
    dfz = (fz - 4000.0) / 4000.0
    sk, sa = tyre.relaxation_lengths(fz)
    assert sk == pytest.approx(fz * (c["PTX1"] + c["PTX2"] * dfz) * math.exp(-c["PTX3"] * dfz)
                               * c["UNLOADED_RADIUS"] / 4000.0, rel=1e-12)
    assert sa == pytest.approx(c["PTY1"] * math.sin(2 * math.atan(fz / (c["PTY2"] * 4000.0)))
                               * c["UNLOADED_RADIUS"], rel=1e-12)


def test_road_friction_scales_the_peak():
    tyre = read_tir(TIR)
    kap = np.linspace(0.0, 0.6, 6001)
    peak1 = tyre.forces(4000.0, kap, 0.0)[0].max()
    peak03 = tyre.forces(4000.0, kap, 0.0, mu=0.3)[0].max()
    # D scales with LMUX; the small vertical shift S_Vx scales with it too in MF 5.2
    assert peak03 == pytest.approx(0.3 * peak1, rel=2e-4)
    assert tyre.scaled(LMUX=0.3).forces(4000.0, kap, 0.0)[0].max() == pytest.approx(peak03)


def _write_61(tmp_path, extra: str = "") -> str:
    text = TIR.read_text().replace("FITTYP                   = 6 ", "FITTYP = 61 ")
    text += ("\n[OPERATING_CONDITIONS]\nINFLPRES = 2.2e5\nNOMPRES = 2.0e5\n"
             "[STRUCTURAL]\nLONGITUDINAL_STIFFNESS = 3.0e5\nLATERAL_STIFFNESS = 1.5e5\n" + extra)
    p = tmp_path / "mf61.tir"
    p.write_text(text)
    return str(p)


def test_mf61_pressure_camber_and_relaxation(tmp_path):
    """MF 6.1 at zero camber and nominal pressure equals MF 5.2 except the digressive
    friction factor (1 at LMU = 1) and the sine of camber; pressure enters through PPX/PPY;
    relaxation lengths follow the carcass stiffnesses."""
    t52 = read_tir(TIR)
    p61 = _write_61(tmp_path, "[LONGITUDINAL_COEFFICIENTS]\n")
    t61 = read_tir(p61)
    assert t61.version == "6.1"
    fx52, fy52, _ = t52.forces(3500.0, 0.07, 0.03)
    fx61, fy61, _ = t61.forces(3500.0, 0.07, 0.03, pressure=2.0e5)
    assert fx61 == pytest.approx(fx52, rel=1e-12)
    assert fy61 == pytest.approx(fy52, rel=1e-12)
    r = t61.evaluate(3500.0, 0.0, 0.0)
    assert r["sigma_kappa"] == pytest.approx(r["kxk"] / 3.0e5, rel=1e-12)
    assert r["sigma_alpha"] == pytest.approx(-r["kya"] / 1.5e5, rel=1e-12)
    # pressure dependence of the slip stiffness (4.E15): (1 + PPX1 dpi + PPX2 dpi^2)
    text = open(p61).read().replace("PKX3                     = 0.21253",
                                    "PKX3 = 0.21253\nPPX1 = -0.3\nPPX2 = 0.1")
    p2 = tmp_path / "mf61p.tir"
    p2.write_text(text)
    t = read_tir(p2)
    k_nom = t.evaluate(3500.0, 0.0, 0.0, pressure=2.0e5)["kxk"]
    k_hi = t.evaluate(3500.0, 0.0, 0.0, pressure=2.4e5)["kxk"]
    assert k_hi / k_nom == pytest.approx(1 - 0.3 * 0.2 + 0.1 * 0.04, rel=1e-12)
    # camber enters as sin(gamma) in 6.x
    g = 0.05
    mux61 = t61.evaluate(3500.0, 0.0, 0.0, gamma=g, pressure=2.0e5)["mu_y"]
    c = _coeffs(TIR)
    dfz = (3500.0 - 4000.0) / 4000.0
    assert mux61 == pytest.approx((c["PDY1"] + c["PDY2"] * dfz)
                                  * (1 - c["PDY3"] * math.sin(g) ** 2), rel=1e-12)


def test_rolling_resistance_opposes_motion():
    tyre = read_tir(TIR)
    assert tyre.evaluate(4000.0, 0.0, 0.0, vx=10.0)["my"] == pytest.approx(
        -0.01 * 4000.0 * 0.344, rel=1e-12)
    assert tyre.evaluate(4000.0, 0.0, 0.0, vx=-10.0)["my"] > 0
    assert tyre.evaluate(0.0, 0.3, 0.1)["fx"] == 0.0  # no load, no force


@pytest.mark.parametrize("surface", sorted(SURFACES))
def test_simple_sets(surface):
    B, C, D, E = SURFACES[surface]
    t = simple_tyre(surface)
    fz = 3000.0
    for kappa in (0.02, 0.1, 0.5):
        fx = t.forces(fz, kappa, 0.0)[0]
        assert fx == pytest.approx(_mf(B, C, D * fz, E, kappa), rel=1e-12)
    fy = t.forces(fz, 0.0, 0.1)[1]
    assert fy == pytest.approx(-_mf(B, C, D * fz, E, math.tan(0.1)), rel=1e-12)
    # combined: the force lies on the slip vector and its size is the curve at |slip|
    fx, fy, mz = t.forces(fz, 0.1, 0.1)
    s = math.hypot(0.1, math.tan(0.1))
    assert math.hypot(fx, fy) == pytest.approx(_mf(B, C, D * fz, E, s), rel=1e-12)
    assert mz == 0.0
    assert t.forces(fz, 0.5, 0.0, mu=0.5)[0] == pytest.approx(
        _mf(B, C, 0.5 * D * fz, E, 0.5), rel=1e-12)


def test_shipped_files_listed():
    assert "pac2002_235_60R16" in shipped_files()
    with pytest.raises(ModelError, match="no such shipped file"):
        shipped("nope")


BAD = [
    ("FITTYP                   = 6 ", "FITTYP = 3 ", r"\[MODEL\] FITTYP.*expected one of"),
    ("PCX1                     = 1.6411", "PCX1 = abc", r"\[LONGITUDINAL_COEFFICIENTS\] PCX1 "
     r"\(line \d+\): expected a number"),
    ("PKX1                     = 22.303           $ [A] slip stiffness Kfx/Fz at Fznom\n", "",
     r"\[LONGITUDINAL_COEFFICIENTS\] PKX1: missing"),
    ("UNLOADED_RADIUS          = 0.344", "UNLOADED_RADIUS = -0.3",
     r"\[DIMENSION\] UNLOADED_RADIUS \(line \d+\): must be > 0"),
    ("PDY1                     = 1.0489", "PDY1 1.0489", r"\[LATERAL_COEFFICIENTS\] line \d+: "
     r"expected 'KEY = value'"),
    ("QCZ1                     = 1.2", "QCZ1 = 1.2\nQCZ1 = 1.3", r"QCZ1.*given twice"),
    ("PCY1                     = 1.3507", "PCY1 = 'x'", r"\[LATERAL_COEFFICIENTS\] PCY1.*"
     "expected a number"),
    ("LENGTH                   = 'meter'", "LENGTH = 'mm'", r"\[UNITS\] LENGTH \(line \d+\): "
     "expected SI"),
]


@pytest.mark.parametrize("old,new,message", BAD)
def test_malformed_files_name_section_and_key(tmp_path, old, new, message):
    text = TIR.read_text()
    assert old in text
    p = tmp_path / "bad.tir"
    p.write_text(text.replace(old, new))
    with pytest.raises(ModelError, match=message):
        read_tir(p)


def test_missing_section_and_file(tmp_path):
    text = TIR.read_text()
    start = text.index("[ALIGNING_COEFFICIENTS]")
    end = text.index("$-------------------------------------------------------------------rolling")
    p = tmp_path / "noalign.tir"
    p.write_text(text[:start] + text[end:])
    with pytest.raises(ModelError, match=r"\[ALIGNING_COEFFICIENTS\] QBZ1: missing.*no "
                                         r"\[ALIGNING_COEFFICIENTS\] section"):
        read_tir(p)
    with pytest.raises(ModelError, match="cannot be read"):
        read_tir(tmp_path / "absent.tir")


def test_tyre_mf_validation_case():
    from drivedyn.validation import base

    results = base.CASES["tyre_mf"](quick=True, figure_dir=None)
    assert results and all(r.passed for r in results), [r for r in results if not r.passed]


def test_relaxation_lengths_alone_equal_the_full_evaluation(tmp_path):
    """The element's shortcut (relaxation lengths without the forces) gives what the full
    formula reports, for MF 5.2, MF 6.1 with carcass stiffnesses and the simple set."""
    from drivedyn.tyres.magic_formula import relaxation_lengths

    for tyre in (read_tir(TIR), read_tir(_write_61(tmp_path)), simple_tyre("snow")):
        for fz, gamma in ((2500.0, 0.0), (5200.0, 0.03)):
            r = tyre.evaluate(fz, 0.07, 0.05, gamma, pressure=2.1e5)
            sk, sa = relaxation_lengths(tyre.params, fz, gamma, 2.1e5)
            assert (sk, sa) == (r["sigma_kappa"], r["sigma_alpha"])


# --- sides: a file measured on one side, used on the other ---------------------------------
def test_a_tyre_on_the_other_side_is_the_mirror_image_of_its_file() -> None:
    """``read_tir(path, side="right")`` of a file measured on the left is the mirror image of
    the left tyre in the wheel's x-z plane: at (kappa, -alpha, -gamma) it gives the left
    tyre's Fx, My, slip stiffnesses, relaxation lengths and friction, and minus its Fy and
    Mz, over a grid of loads, slips and cambers; the ply-steer force at zero slip changes
    side. The side the file was measured on is read as it is.

    Deliberate mutations that fail it: mirroring alpha but not gamma (the camber terms);
    negating Mz but not Fy; mirroring the file's own side."""
    from drivedyn.tyres.magic_formula import INDEX

    path = shipped("pac2002_235_60R16")  # TYRESIDE = 'LEFT'
    left, right, plain = read_tir(path, side="left"), read_tir(path, side="right"), \
        read_tir(path)
    assert left.params[INDEX["MIRROR"]] == 0.0 and np.array_equal(left.params, plain.params)
    assert right.params[INDEX["MIRROR"]] == 1.0 and "mirrored" in right.name
    same = ("fx", "my", "kxk", "kya", "sigma_kappa", "sigma_alpha", "mu_x", "mu_y")
    for fz in (2000.0, 4000.0, 7000.0):
        for kappa in (-0.1, 0.0, 0.05):
            for alpha in (-0.08, 0.0, 0.03):
                for gamma in (-0.05, 0.0, 0.04):
                    a = left.evaluate(fz, kappa, alpha, gamma, 10.0)
                    b = right.evaluate(fz, kappa, -alpha, -gamma, 10.0)
                    for k in same:
                        assert b[k] == pytest.approx(a[k], rel=1e-12, abs=1e-9), k
                    for k in ("fy", "mz"):
                        assert b[k] == pytest.approx(-a[k], rel=1e-12, abs=1e-9), k
    fy0 = left.evaluate(4000.0, 0.0, 0.0, 0.0, 10.0)["fy"]
    assert abs(fy0) > 1.0  # the file's ply-steer/conicity force
    assert right.evaluate(4000.0, 0.0, 0.0, 0.0, 10.0)["fy"] == pytest.approx(-fy0)


def test_symmetric_files_and_bad_sides(tmp_path) -> None:
    """A ``SYMMETRIC`` file and a file without ``TYRESIDE`` are used as they are on both
    sides; a side other than left/right is refused naming it, by the reader and by the tyre
    element (``side`` key).

    Deliberate mutations that fail it: mirroring a file without TYRESIDE (taken as LEFT);
    accepting ``side = "centre"``."""
    from drivedyn.elements.tyre import TyreContact
    from drivedyn.tyres.magic_formula import INDEX

    text = shipped("pac2002_235_60R16").read_text()
    sym = tmp_path / "sym.tir"
    sym.write_text(text.replace("'LEFT'", "'SYMMETRIC'"))
    none = tmp_path / "none.tir"
    none.write_text("\n".join(line for line in text.splitlines()
                              if not line.strip().startswith("TYRESIDE")))
    for f in (sym, none):
        assert read_tir(f, side="right").params[INDEX["MIRROR"]] == 0.0
    with pytest.raises(ModelError, match="side: expected 'left' or 'right', got 'centre'"):
        read_tir(sym, side="centre")
    with pytest.raises(ModelError, match="side: expected 'left' or 'right', got 'centre'"):
        TyreContact("t", "m", "pac2002_235_60R16", side="centre").validate()
    right = TyreContact("t", "m", "pac2002_235_60R16", side="right").resolved()[0]
    assert right.params[INDEX["MIRROR"]] == 1.0
