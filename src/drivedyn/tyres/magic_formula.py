"""Pacejka's Magic Formula 5.2 and 6.1/6.2, steady state, as one compiled function.

Equations of Pacejka, *Tire and Vehicle Dynamics*, 3rd ed. (2012), section 4.3.2 (4.E1-4.E78,
MF 6.1) and Pacejka & Besselink / Adams PAC2002 (MF 5.2), with turn slip left out (all zeta
factors 1). Units SI: forces [N], moments [N m], slips [-], angles [rad], speeds [m/s],
pressure [Pa]. Axes and signs: TYDEX/ISO-W of the property file (x forward along the wheel
heading, z up, y to the left; ``alpha = atan(V_cy/|V_cx|)`` so that a positive slip angle gives
a negative side force with the files' negative ``PKY1``; ``kappa = -V_sx/|V_cx|`` positive when
driving).

The coefficients live in one float array ``P`` (:data:`KEYS` order, :func:`pack`); the same
function serves the Python API (:class:`drivedyn.tyres.Tyre`) and the tyre element's kernel, so
the two cannot disagree. ``P[KIND]`` selects the Magic Formula (0) or the simple B, C, D, E
formula (1, :mod:`drivedyn.tyres.simple`).

Differences between versions (``FITTYP``: 6, 21, 52 = MF 5.2; 61, 62 = MF 6.1/6.2):
camber enters as ``gamma * LGAx`` in 5.2 and as ``sin(gamma)`` in 6.x; 6.x adds the inflation
pressure terms (``PPX*``, ``PPY*``, ``PPZ*``, ``QSY7-8``), the camber stiffness form of the
lateral shift (``PKY6-7``), the digressive friction factor ``LMU' = 10 LMU/(1 + 9 LMU)`` in the
vertical shifts, and relaxation lengths from the carcass stiffnesses (``[STRUCTURAL]``) when
given.

Sides: a property file describes the tyre mounted on the side of the vehicle it was measured
on (``[MODEL] TYRESIDE``). On the other side the same tyre is its mirror image in the wheel's
x-z plane: with ``P[MIRROR] = 1`` the formula is evaluated at ``(-alpha, -gamma)`` and ``Fy``
and ``Mz`` change sign (``Fx``, ``My``, the slip stiffnesses and the relaxation lengths do not),
so that every asymmetry of the file (ply-steer and conicity shifts, camber terms) moves to
the other side as it does on a real vehicle.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: coefficient names by group; ``P`` holds them in this order, then KIND and the simple set.
GROUPS: dict[str, tuple[str, ...]] = {
    "model": ("FITTYP LONGVL VXLOW FNOMIN UNLOADED_RADIUS WIDTH VERTICAL_STIFFNESS "
              "VERTICAL_DAMPING BREFF DREFF FREFF NOMPRES INFLPRES LONGITUDINAL_STIFFNESS "
              "LATERAL_STIFFNESS").split(),
    "scaling": ("LFZO LCX LMUX LEX LKX LHX LVX LGAX LCY LMUY LEY LKY LHY LVY LGAY LTR LRES "
                "LGAZ LXAL LYKA LVYKA LS LSGKP LSGAL LMY LKYC LKZC LMUV").split(),
    "longitudinal": ("PCX1 PDX1 PDX2 PDX3 PEX1 PEX2 PEX3 PEX4 PKX1 PKX2 PKX3 PHX1 PHX2 PVX1 "
                     "PVX2 PPX1 PPX2 PPX3 PPX4 RBX1 RBX2 RBX3 RCX1 REX1 REX2 RHX1 PTX1 PTX2 "
                     "PTX3").split(),
    "lateral": ("PCY1 PDY1 PDY2 PDY3 PEY1 PEY2 PEY3 PEY4 PEY5 PKY1 PKY2 PKY3 PKY4 PKY5 PKY6 "
                "PKY7 PHY1 PHY2 PHY3 PVY1 PVY2 PVY3 PVY4 PPY1 PPY2 PPY3 PPY4 PPY5 RBY1 RBY2 "
                "RBY3 RBY4 RCY1 REY1 REY2 RHY1 RHY2 RVY1 RVY2 RVY3 RVY4 RVY5 RVY6 PTY1 "
                "PTY2").split(),
    "aligning": ("QBZ1 QBZ2 QBZ3 QBZ4 QBZ5 QBZ6 QBZ9 QBZ10 QCZ1 QDZ1 QDZ2 QDZ3 QDZ4 QDZ6 QDZ7 "
                 "QDZ8 QDZ9 QDZ10 QDZ11 QEZ1 QEZ2 QEZ3 QEZ4 QEZ5 QHZ1 QHZ2 QHZ3 QHZ4 PPZ1 PPZ2 "
                 "SSZ1 SSZ2 SSZ3 SSZ4").split(),
    "rolling": "QSY1 QSY2 QSY3 QSY4 QSY5 QSY6 QSY7 QSY8".split(),
    "simple": "KIND SIMPLE_B SIMPLE_C SIMPLE_D SIMPLE_E SIMPLE_SIGMA SIMPLE_RR".split(),
    # 1: the tyre is used on the other side of the vehicle than its file was measured on
    "side": ("MIRROR",),
}
KEYS: tuple[str, ...] = tuple(k for g in GROUPS.values() for k in g)
INDEX: dict[str, int] = {k: i for i, k in enumerate(KEYS)}
NPAR = len(KEYS)
KIND = INDEX["KIND"]
KIND_MF = 0.0
KIND_SIMPLE = 1.0
# positions the short helpers read directly (compile-time constants for numba)
_FITTYP, _FNOMIN, _R0 = INDEX["FITTYP"], INDEX["FNOMIN"], INDEX["UNLOADED_RADIUS"]
_NOMPRES, _INFLPRES = INDEX["NOMPRES"], INDEX["INFLPRES"]
_CX, _CY = INDEX["LONGITUDINAL_STIFFNESS"], INDEX["LATERAL_STIFFNESS"]
_LFZO, _LKX, _LMUY = INDEX["LFZO"], INDEX["LKX"], INDEX["LMUY"]
_LSGKP, _LSGAL = INDEX["LSGKP"], INDEX["LSGAL"]
_PKX1, _PPX1, _PKY3 = INDEX["PKX1"], INDEX["PPX1"], INDEX["PKY3"]
_PTX1, _PTY1, _SIGMA = INDEX["PTX1"], INDEX["PTY1"], INDEX["SIMPLE_SIGMA"]
_MIRROR = INDEX["MIRROR"]

#: values of keys a file may omit (the others default to 0, as in MF-Tyre and Adams)
DEFAULTS: dict[str, float] = {
    **{k: 1.0 for k in GROUPS["scaling"]},
    "LMUV": 0.0,
    "PKY4": 2.0,
    "VXLOW": 1.0,
    "LONGVL": 16.7,
    "WIDTH": 0.2,
}

#: outputs of :func:`evaluate` (indices into ``out``)
OUT_NAMES = ("fx", "fy", "mz", "my", "kxk", "kya", "sigma_kappa", "sigma_alpha", "mu_x",
             "mu_y")
NOUT = len(OUT_NAMES)
EPS = 1e-6  # Pacejka's epsilon against division by zero (4.E18, 4.E26)
A_MU = 10.0  # digressive friction factor of MF 6.1 (4.E8)


def pack(values: dict[str, float]) -> np.ndarray:
    """The coefficient array ``P`` (NPAR,) from ``{KEY: value}`` plus :data:`DEFAULTS`."""
    P = np.zeros(NPAR)
    for k, v in DEFAULTS.items():
        P[INDEX[k]] = v
    for k, v in values.items():
        P[INDEX[k]] = float(v)
    return P


@njit(cache=True, inline="always")
def _sgn(x):
    return (x > 0.0) - (x < 0.0)


@njit(cache=True, inline="always")
def _mf(B, C, D, E, x):
    """``D sin(C atan(B x - E (B x - atan(B x))))``."""
    bx = B * x
    return D * math.sin(C * math.atan(bx - E * (bx - math.atan(bx))))


@njit(cache=True, inline="always")
def _weight(B, C, E, x):
    """``cos(C atan(B x - E (B x - atan(B x))))`` (combined-slip weighting, 4.E55)."""
    bx = B * x
    return math.cos(C * math.atan(bx - E * (bx - math.atan(bx))))


@njit(cache=True)
def _lateral(P, v6, fz, dfz, dpi, ta, gamma, lmuy_s, lmuy_p, shift):
    """Pure lateral slip (4.E19-4.E30): (Fy0, mu_y, By, Cy, Kya, SHy, SVy, gamma_y)."""
    (lfzo, lcx, lmux, lex, lkx, lhx, lvx, lgax, lcy, lmuy, ley, lky, lhy, lvy, lgay, ltr,
     lres, lgaz, lxal, lyka, lvyka, ls, lsgkp, lsgal, lmy, lkyc, lkzc, lmuv) = P[15:43]
    (pcy1, pdy1, pdy2, pdy3, pey1, pey2, pey3, pey4, pey5, pky1, pky2, pky3, pky4, pky5, pky6,
     pky7, phy1, phy2, phy3, pvy1, pvy2, pvy3, pvy4, ppy1, ppy2, ppy3, ppy4, ppy5, rby1, rby2,
     rby3, rby4, rcy1, rey1, rey2, rhy1, rhy2, rvy1, rvy2, rvy3, rvy4, rvy5, rvy6, pty1,
     pty2) = P[72:117]
    fz0 = P[3] * lfzo
    if v6:
        gy = math.sin(gamma)
        kya = (pky1 * fz0 * (1.0 + ppy1 * dpi) * (1.0 - pky3 * abs(gy))
               * math.sin(pky4 * math.atan(fz / ((pky2 + pky5 * gy * gy)
                                                 * (1.0 + ppy2 * dpi) * fz0))) * lky)
        kyg0 = fz * (pky6 + pky7 * dfz) * (1.0 + ppy5 * dpi) * lkyc
        svyg = fz * (pvy3 + pvy4 * dfz) * gy * lkyc * lmuy_p
        shy = (phy1 + phy2 * dfz) * lhy + (kyg0 * gy - svyg) / (kya + EPS)
        svy = fz * (pvy1 + pvy2 * dfz) * lvy * lmuy_p + svyg
    else:
        gy = gamma * lgay
        kya = pky1 * fz0 * math.sin(2.0 * math.atan(fz / (pky2 * fz0))) * (
            1.0 - pky3 * abs(gy)) * lky
        shy = (phy1 + phy2 * dfz) * lhy + phy3 * gy
        svy = fz * ((pvy1 + pvy2 * dfz) * lvy + (pvy3 + pvy4 * dfz) * gy) * lmuy_s
    shy *= shift
    svy *= shift
    ay = ta + shy
    cy = pcy1 * lcy
    muy = (pdy1 + pdy2 * dfz) * (1.0 + ppy3 * dpi + ppy4 * dpi * dpi) * (
        1.0 - pdy3 * gy * gy) * lmuy_s
    dy = muy * fz
    if v6:
        ey = (pey1 + pey2 * dfz) * (1.0 + pey5 * gy * gy - (pey3 + pey4 * gy) * _sgn(ay)) * ley
    else:
        ey = (pey1 + pey2 * dfz) * (1.0 - (pey3 + pey4 * gy) * _sgn(ay)) * ley
    ey = min(ey, 1.0)
    by = kya / (cy * dy + EPS)
    fy0 = _mf(by, cy, dy, ey, ay) + svy
    return fy0, muy, by, cy, kya, shy, svy, gy


@njit(cache=True, inline="always")
def _relaxation(P, v6, fz, dfz, gy, kxk, kya):
    """Relaxation lengths (sigma_kappa, sigma_alpha) [m], at least 0.1 mm: MF 5.2 from
    PTX1-3 and PTY1-2; MF 6.x the slip stiffness over the carcass stiffness when
    ``[STRUCTURAL]`` gives it."""
    r0, fz0, cxs, cys = P[_R0], P[_FNOMIN] * P[_LFZO], P[_CX], P[_CY]
    if v6 and cxs > 0.0:
        sig_k = kxk / cxs
    else:
        ptx1, ptx2, ptx3 = P[_PTX1:_PTX1 + 3]
        sig_k = fz * (ptx1 + ptx2 * dfz) * math.exp(-ptx3 * dfz) * (r0 / fz0) * P[_LSGKP]
    if v6 and cys > 0.0:
        sig_a = kya / cys
    else:
        pty1, pty2 = P[_PTY1:_PTY1 + 2]
        # PTY2 = 0 (a file without PTY1-2; the reader refuses it) leaves the floor below
        peak = math.sin(2.0 * math.atan(fz / (pty2 * fz0))) if pty2 != 0.0 else 0.0
        sig_a = pty1 * peak * (1.0 - P[_PKY3] * abs(gy)) * r0 * P[_LFZO] * P[_LSGAL]
    return max(sig_k, 1e-4), max(abs(sig_a), 1e-4)


@njit(cache=True)
def relaxation_lengths(P, fz, gamma, pressure):
    """(sigma_kappa, sigma_alpha) [m] at load ``fz`` [N] > 0, camber ``gamma`` [rad] and
    inflation ``pressure`` [Pa] (<= 0: INFLPRES): what :func:`evaluate` reports, without the
    forces (the tyre element needs them before it knows the slips)."""
    if P[KIND] == KIND_SIMPLE:
        return P[_SIGMA], P[_SIGMA]
    if P[_MIRROR] != 0.0:
        gamma = -gamma
    v6 = P[_FITTYP] >= 60.0
    fz0 = P[_FNOMIN] * P[_LFZO]
    dfz = (fz - fz0) / fz0
    dpi = 0.0
    p = pressure if pressure > 0.0 else P[_INFLPRES]
    if v6 and P[_NOMPRES] > 0.0 and p > 0.0:
        dpi = (p - P[_NOMPRES]) / P[_NOMPRES]
    pkx1, pkx2, pkx3 = P[_PKX1:_PKX1 + 3]
    ppx1, ppx2 = P[_PPX1:_PPX1 + 2]
    kxk = fz * (pkx1 + pkx2 * dfz) * math.exp(pkx3 * dfz) * (
        1.0 + ppx1 * dpi + ppx2 * dpi * dpi) * P[_LKX]
    lat = _lateral(P, v6, fz, dfz, dpi, 0.0, gamma, P[_LMUY], P[_LMUY], 1.0)
    return _relaxation(P, v6, fz, dfz, lat[7], kxk, lat[4])


@njit(cache=True)
def _simple(P, fz, kappa, alpha, vx, mu_scale, out):
    """The simple formula (kind 1): one B, C, D, E curve on the combined slip
    ``s = sqrt(kappa^2 + tan(alpha)^2)``, force along the slip vector, D scaled by the road's
    friction; no aligning moment; rolling resistance ``-f_r Fz R0 sgn(Vx)``."""
    b, c, d, e, sig, rr = P[KIND + 1:KIND + 7]
    ta = math.tan(alpha)
    s = math.sqrt(kappa * kappa + ta * ta)
    dd = d * mu_scale * fz
    if s > 1e-12:
        f_over_s = _mf(b, c, dd, e, s) / s
    else:
        f_over_s = b * c * dd  # the slope at zero slip
    out[0] = f_over_s * kappa
    out[1] = -f_over_s * ta
    out[2] = 0.0
    out[3] = -rr * fz * P[4] * _sgn(vx)
    out[4] = b * c * dd
    out[5] = -b * c * dd
    out[6] = sig
    out[7] = sig
    out[8] = d * mu_scale
    out[9] = d * mu_scale


@njit(cache=True)
def evaluate(P, fz, kappa, alpha, gamma, vx, pressure, mu_scale, shift, out):
    """Steady-state tyre forces into ``out`` (NOUT,): Fx, Fy [N], Mz, My [N m] at the contact
    point (ISO-W), the slip stiffnesses Kxk = dFx0/dkappa [N] and Kya = dFy0/dalpha [N/rad],
    the relaxation lengths sigma_kappa, sigma_alpha [m] and the friction coefficients mu_x,
    mu_y [-].

    Args: ``fz`` vertical load [N] (<= 0: no force), ``kappa`` longitudinal slip [-],
    ``alpha`` slip angle [rad], ``gamma`` camber [rad], ``vx`` longitudinal speed of the wheel
    centre [m/s] (signs of Mz and My, speed terms), ``pressure`` inflation [Pa] (<= 0: the
    file's INFLPRES), ``mu_scale`` road friction factor on LMUX and LMUY (1 = the tyre's test
    surface), ``shift`` factor on the horizontal and vertical shifts of Fx and Fy and on
    the aligning moment's trail and residual moment (1; the tyre element fades them out below
    VXLOW so that a tyre at rest carries no force at zero slip, and no aligning moment whose
    sign jumps with that of ``vx``: Mz's ``sgn(V_x)`` would otherwise flip the moment as a
    wheel at rest creeps forward or back, a residual Newton cannot converge on).
    """
    for i in range(NOUT):
        out[i] = 0.0
    if fz <= 0.0:
        return
    if P[KIND] == KIND_SIMPLE:
        _simple(P, fz, kappa, alpha, vx, mu_scale, out)
        return
    mirror = P[_MIRROR] != 0.0
    if mirror:  # the file's tyre seen in a mirror (module doc): evaluated at -alpha, -gamma
        alpha = -alpha
        gamma = -gamma
    (fittyp, longvl, vxlow, fnomin, r0, width, cz, kz, breff, dreff, freff, nompres,
     inflpres, cxs, cys) = P[0:15]
    (lfzo, lcx, lmux, lex, lkx, lhx, lvx, lgax, lcy, lmuy, ley, lky, lhy, lvy, lgay, ltr,
     lres, lgaz, lxal, lyka, lvyka, ls, lsgkp, lsgal, lmy, lkyc, lkzc, lmuv) = P[15:43]
    (pcx1, pdx1, pdx2, pdx3, pex1, pex2, pex3, pex4, pkx1, pkx2, pkx3, phx1, phx2, pvx1, pvx2,
     ppx1, ppx2, ppx3, ppx4, rbx1, rbx2, rbx3, rcx1, rex1, rex2, rhx1, ptx1, ptx2,
     ptx3) = P[43:72]
    (pcy1, pdy1, pdy2, pdy3, pey1, pey2, pey3, pey4, pey5, pky1, pky2, pky3, pky4, pky5, pky6,
     pky7, phy1, phy2, phy3, pvy1, pvy2, pvy3, pvy4, ppy1, ppy2, ppy3, ppy4, ppy5, rby1, rby2,
     rby3, rby4, rcy1, rey1, rey2, rhy1, rhy2, rvy1, rvy2, rvy3, rvy4, rvy5, rvy6, pty1,
     pty2) = P[72:117]
    (qbz1, qbz2, qbz3, qbz4, qbz5, qbz6, qbz9, qbz10, qcz1, qdz1, qdz2, qdz3, qdz4, qdz6, qdz7,
     qdz8, qdz9, qdz10, qdz11, qez1, qez2, qez3, qez4, qez5, qhz1, qhz2, qhz3, qhz4, ppz1, ppz2,
     ssz1, ssz2, ssz3, ssz4) = P[117:151]
    (qsy1, qsy2, qsy3, qsy4, qsy5, qsy6, qsy7, qsy8) = P[151:159]
    v6 = fittyp >= 60.0
    fz0 = fnomin * lfzo
    dfz = (fz - fz0) / fz0
    dpi = 0.0
    p = pressure if pressure > 0.0 else inflpres
    if v6 and nompres > 0.0 and p > 0.0:
        dpi = (p - nompres) / nompres
    ta = math.tan(alpha)  # alpha* (4.E3)
    ca = 1.0 / math.sqrt(1.0 + ta * ta)  # cos(alpha)
    sv = _sgn(vx)
    # friction scaling with the road and the slip speed (4.E7, 4.E8)
    vs = abs(vx) * math.sqrt(kappa * kappa + ta * ta)
    lmux_s = lmux * mu_scale / (1.0 + lmuv * vs / longvl)
    lmuy_s = lmuy * mu_scale / (1.0 + lmuv * vs / longvl)
    if v6:
        lmux_p = A_MU * lmux_s / (1.0 + (A_MU - 1.0) * lmux_s)
        lmuy_p = A_MU * lmuy_s / (1.0 + (A_MU - 1.0) * lmuy_s)
    else:
        lmux_p = lmux_s
        lmuy_p = lmuy_s
    # --- pure longitudinal slip (4.E9-4.E18)
    gx = math.sin(gamma) if v6 else gamma * lgax
    shx = (phx1 + phx2 * dfz) * lhx * shift
    kx = kappa + shx
    cx = pcx1 * lcx
    mux = (pdx1 + pdx2 * dfz) * (1.0 + ppx3 * dpi + ppx4 * dpi * dpi) * (
        1.0 - pdx3 * gx * gx) * lmux_s
    dx = mux * fz
    ex = min((pex1 + pex2 * dfz + pex3 * dfz * dfz) * (1.0 - pex4 * _sgn(kx)) * lex, 1.0)
    kxk = fz * (pkx1 + pkx2 * dfz) * math.exp(pkx3 * dfz) * (
        1.0 + ppx1 * dpi + ppx2 * dpi * dpi) * lkx
    bx = kxk / (cx * dx + EPS)
    svx = fz * (pvx1 + pvx2 * dfz) * lvx * lmux_p * shift
    fx0 = _mf(bx, cx, dx, ex, kx) + svx
    # --- pure lateral slip (4.E19-4.E30)
    fy0, muy, by, cy, kya, shy, svy, gy = _lateral(P, v6, fz, dfz, dpi, ta, gamma, lmuy_s,
                                                   lmuy_p, shift)
    # --- combined slip, longitudinal force (4.E50-4.E57)
    gc = math.sin(gamma) if v6 else gamma
    if v6:
        bxa = (rbx1 + rbx3 * gc * gc) * math.cos(math.atan(rbx2 * kappa)) * lxal
    else:
        bxa = rbx1 * math.cos(math.atan(rbx2 * kappa)) * lxal
    exa = min(rex1 + rex2 * dfz, 1.0)
    gxa = _weight(bxa, rcx1, exa, ta + rhx1) / _weight(bxa, rcx1, exa, rhx1)
    fx = gxa * fx0
    # --- combined slip, lateral force (4.E58-4.E67)
    dvyk = muy * fz * (rvy1 + rvy2 * dfz + rvy3 * gc) * math.cos(math.atan(rvy4 * ta))
    svyk = dvyk * math.sin(rvy5 * math.atan(rvy6 * kappa)) * lvyka * shift
    shyk = rhy1 + rhy2 * dfz
    if v6:
        byk = (rby1 + rby4 * gc * gc) * math.cos(math.atan(rby2 * (ta - rby3))) * lyka
    else:
        byk = rby1 * math.cos(math.atan(rby2 * (ta - rby3))) * lyka
    eyk = min(rey1 + rey2 * dfz, 1.0)
    gyk = _weight(byk, rcy1, eyk, kappa + shyk) / _weight(byk, rcy1, eyk, shyk)
    fy = gyk * fy0 + svyk
    # --- aligning moment, pure slip quantities (4.E31-4.E49)
    gz = math.sin(gamma) if v6 else gamma * lgaz
    sht = qhz1 + qhz2 * dfz + (qhz3 + qhz4 * dfz) * gz
    at = ta + sht
    if v6:
        bt = (qbz1 + qbz2 * dfz + qbz3 * dfz * dfz) * (1.0 + qbz5 * abs(gz) + qbz6 * gz * gz)
    else:
        bt = (qbz1 + qbz2 * dfz + qbz3 * dfz * dfz) * (1.0 + qbz4 * gz + qbz5 * abs(gz))
    # B_t and B_r grow as 1/LMUY*: floored at EPS so that a road without friction (or
    # LMUY = 0) gives Mz = 0 (no side force, no residual moment) instead of 0/0
    lmuy_t = max(lmuy_s, EPS)
    bt *= lky / lmuy_t
    ct = qcz1
    # the trail and the residual moment change sign with the direction of rolling; ``shift``
    # fades both with the shifts (continuous through standstill, below)
    dt0 = fz * (r0 / fz0) * (qdz1 + qdz2 * dfz) * (1.0 - ppz1 * dpi) * ltr * sv * shift
    if v6:
        dt = dt0 * (1.0 + qdz3 * abs(gz) + qdz4 * gz * gz)
    else:
        dt = dt0 * (1.0 + qdz3 * gz + qdz4 * gz * gz)
    et = min((qez1 + qez2 * dfz + qez3 * dfz * dfz)
             * (1.0 + (qez4 + qez5 * gz) * (2.0 / math.pi) * math.atan(bt * ct * at)), 1.0)
    kya_p = kya + EPS
    shf = shy + svy / kya_p
    ar = ta + shf
    br = qbz9 * lky / lmuy_t + qbz10 * by * cy
    if v6:
        dr = fz * r0 * ((qdz6 + qdz7 * dfz) * lres
                        + ((qdz8 + qdz9 * dfz) * (1.0 + ppz2 * dpi)
                           + (qdz10 + qdz11 * dfz) * abs(gz)) * gz * lkzc) * lmuy_s * sv * ca
    else:
        dr = fz * r0 * ((qdz6 + qdz7 * dfz) * lres + (qdz8 + qdz9 * dfz) * gz) * lmuy_s * sv * ca
    dr *= shift
    # combined-slip aligning moment (4.E71-4.E78): equivalent slip angles, Fy' at zero camber
    rk = kxk / kya_p
    at_eq = math.sqrt(at * at + rk * rk * kappa * kappa) * (1.0 if at >= 0.0 else -1.0)
    ar_eq = math.sqrt(ar * ar + rk * rk * kappa * kappa) * (1.0 if ar >= 0.0 else -1.0)
    if gamma != 0.0:
        fy0_g0 = _lateral(P, v6, fz, dfz, dpi, ta, 0.0, lmuy_s, lmuy_p, shift)[0]
    else:
        fy0_g0 = fy0
    fyp = gyk * fy0_g0
    t = dt * _weight(bt, ct, et, at_eq) * ca
    mzr = dr * math.cos(math.atan(br * ar_eq))
    s = r0 * (ssz1 + ssz2 * (fy / fz0) + (ssz3 + ssz4 * dfz) * gz) * ls
    mz = -t * fyp + mzr + s * fx
    # --- rolling resistance (4.E70)
    vr = vx / longvl
    base = qsy1 + qsy2 * fx / fz0 + qsy3 * abs(vr) + qsy4 * vr ** 4
    if v6:
        base += (qsy5 + qsy6 * fz / fz0) * gamma * gamma
        fac = (fz / fz0) ** qsy7
        if nompres > 0.0 and p > 0.0:
            fac *= (p / nompres) ** qsy8
        my = -r0 * fz0 * lmy * base * fac * sv
    else:
        my = -r0 * fz * lmy * base * sv
    sig_k, sig_a = _relaxation(P, v6, fz, dfz, gy, kxk, kya)
    if mirror:  # ... and its lateral force and aligning moment mirrored back
        fy = -fy
        mz = -mz
    out[0] = fx
    out[1] = fy
    out[2] = mz
    out[3] = my
    out[4] = kxk
    out[5] = kya
    out[6] = sig_k
    out[7] = sig_a
    out[8] = mux
    out[9] = muy


@njit(cache=True)
def effective_radius(P, rho):
    """Effective rolling radius R_e [m] at the radial deflection ``rho`` [m] (>= 0): MF 6.1's
    ``R0 - (Fz0/Cz)(D atan(B rho_d) + F rho_d)``, ``rho_d = Cz rho / Fz0``, with the file's
    BREFF, DREFF, FREFF; without them ``R0 - rho/3`` (radial tyres, Pacejka 2012 sec. 7.2)."""
    r0 = P[4]
    if P[KIND] == KIND_SIMPLE or (P[8] == 0.0 and P[9] == 0.0 and P[10] == 0.0):
        return r0 - rho / 3.0
    fz0 = P[3] * P[15]
    cz = P[6]
    rd = cz * rho / fz0
    return r0 - (fz0 / cz) * (P[9] * math.atan(P[8] * rd) + P[10] * rd)
