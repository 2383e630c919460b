r"""Quasi-static torque distribution ratio of the TORSEN Type B, derived by hand.

This model shares only the *parameters* with the simulator (the model file); every force is
written out below from the equilibrium of each part at constant speeds, so that it checks the
multibody simulation (the bench TDRs agree within 1 %).

Frame and signs: axis z, forward rotation +z, speeds relative to the housing
``w_l' = w_l - w_h``, ``w_r' = w_r - w_h``; Willis: ``w_r' = -w_l'``. Pair 0 is studied
(element gear ``a`` at the angle ``-spread/2`` meshing the left side gear, ``b`` at
``+spread/2`` meshing the right one); the ``n`` pairs share the load equally. Element spins
relative to the housing: ``w_a' = -w_l' z_s / z_e``, ``w_b' = -w_a'``; ``sigma_a``,
``sigma_b`` their signs.

**A mesh** between gear 1 (centre c1, pitch radius r1, helix beta1) and gear 2 (c2, r2,
beta2 = -beta1), unit vector ``u`` from c1 to c2, ``t = z x u``, scalar ``W`` (the tangential
force on gear 2 along t): force on gear 2 ``W t + |W| tan(alpha_t) u`` (the separating force),
on gear 1 the opposite; torques about their own axes ``-r2 W`` on gear 2 and ``-r1 W`` on
gear 1; axial forces ``tan(beta1) W`` on gear 1 and ``tan(beta2) W`` on gear 2 (both equal to
``-tan(beta) T / r`` with ``T`` the mesh torque on the gear). Meshes: left side gear (1) - a
(2), ``W_a``; right side gear (1) - b (2), ``W_b``; a (1) - b (2) at both ends, ``W_ab`` in
total (the split between the two ends only tilts the gears, which their guides hold).

**Tooth friction** (``gears.tooth_friction`` ``mu_t``; law, normal force and mean arm
derived in :mod:`drivedyn.library.differentials.tooth_friction`): each mesh puts a couple
``C = mu_t F_N s_eff`` on its two wheels, turning each towards the other's angular velocity
relative to the housing (which carries the element gears' centres), with the normal flank
force ``F_N = |W| / (cos(alpha_n) cos(beta))``. Per pair, with ``kappa = s_eff /
(cos alpha_n cos beta)`` of the side pair ``z_s/z_e`` and of the end pair ``z_e/z_e``::

    C_a = mu_t |W_a| kappa_se,  C_b = mu_t |W_b| kappa_se,  C_ab = mu_t |W_ab| kappa_ee
    s_la = sgn(w_l' - w_a'),    s_rb = sgn(w_r' - w_b'),    s_ab = sgn(w_a' - w_b')

(the two end meshes carry ``W_ab`` between them on the same flanks, so their couples add to
``C_ab``). The couples are ``-C_a s_la`` on the left side gear and ``+C_a s_la`` on a,
``-C_b s_rb`` on the right side gear and ``+C_b s_rb`` on b, ``-C_ab s_ab`` on a and
``+C_ab s_ab`` on b; they change no force, hence no thrust.

**Element gear in its pocket**: contact at the direction ``e`` (angle psi) from its centre,
normal force ``-N e``, tip friction ``-sigma mu_p N (z x e)`` and torque
``-sigma mu_p N r_tip``; end-face friction torque ``-sigma mu_p |A| r_end`` with its axial
load ``A``; centrifugal force ``m w_h^2 R`` outwards (vehicle)::

    a:  W_a t_a + |W_a| ta_s e_a - W_ab t_ab - |W_ab| ta_e u_ab + pocket_a + cen_a = 0
        -r_e W_a - r_e W_ab - sigma_a mu_p (N_a r_tip + |A_a| r_end) + C_a s_la - C_ab s_ab = 0
        A_a = tan(beta_a) W_a + tan(beta_ea) W_ab
    b:  W_b t_b + |W_b| ta_s e_b + W_ab t_ab + |W_ab| ta_e u_ab + pocket_b + cen_b = 0
        -r_e W_b - r_e W_ab - sigma_b mu_p (N_b r_tip + |A_b| r_end) + C_b s_rb + C_ab s_ab = 0
        A_b = tan(beta_b) W_b - tan(beta_ea) W_ab

(``beta_ea``: helix of a's ends, the partner's ends have the opposite hand.)

**Side gears** (axial thrusts ``A_l = n tan(beta_l) W_a``, ``A_r = n tan(beta_r) W_b``;
washers: ``N_l`` on the housing behind the left gear pushes it along +z, ``N_r`` behind the
right gear along -z, ``N_m`` between them pushes them apart)::

    left:   A_l + N_l - N_m = 0         right:  A_r + N_m - N_r = 0
    N_m = max(0, A_l, -A_r),  N_l = N_m - A_l,  N_r = A_r + N_m

(the stronger of two converging thrusts passes through the middle washer to the other gear's
housing washer; diverging thrusts each go to their own housing washer). Moments about z
(washer friction ``mu_w N r_m`` against the relative spin of the two faces)::

    T_l - n r_s W_a - n C_a s_la - mu_w N_l r_ml sgn(w_l') - mu_w N_m r_mm sgn(w_l - w_r) = 0
    T_r - n r_s W_b - n C_b s_rb - mu_w N_r r_mr sgn(w_r') + mu_w N_m r_mm sgn(w_l - w_r) = 0
    (vehicle)  T_h + T_l + T_r = 0

With one external torque given these are 8 equations (9 with the housing) in ``W_a, W_b,
W_ab, N_a, psi_a, N_b, psi_b`` and the unknown output torque(s), solved by Newton's method
(``scipy.optimize.fsolve``) from the frictionless solution.

Independent check, a power balance in the housing frame: at constant speeds the external
power ``T_l w_l' + T_r w_r'`` equals the friction power of the washers, tips, end faces and
teeth (tested in ``tests/models/test_torsen_b.py`` and
``tests/models/test_tooth_friction_analytic.py``), which gives the textbook form
``TDR = (1 + k)/(1 - k)`` with ``k`` the friction work per unit of transmitted work.

Tooth friction alone (no pocket, end-face or washer friction): with ``q = sgn(w_a')
sgn(W_a)`` (+1 when the right side gear drives the train relative to the housing, -1 when
the left one does) and ``h = pi (1 - eps_alpha + eps_1^2 + eps_2^2) / cos(beta_b)`` of each pair
(``kappa / r_i = h / z_i``), the element moments give ``W_ab`` and ``W_b`` from ``W_a`` and::

    T_r / T_l = (1 + q mu_t h_se/z_s)(1 + q mu_t h_se/z_e)(1 + q mu_t h_ee/z_e)
                / ((1 - q mu_t h_se/z_s)(1 - q mu_t h_se/z_e)(1 - q mu_t h_ee/z_e))

whose first order, ``ln(T_r / T_l) = q mu_t (2 H_V,se + H_V,ee)``, is the product of the
three meshes' Ohlendorf efficiencies ``1 - mu_t H_V`` along the train.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from drivedyn.library.differentials.tooth_friction import couple_arm
from drivedyn.library.differentials.torsen_b.model import MODES, check_parameters
from drivedyn.library.differentials.torsen_b.schema import TorsenBFile


@dataclass(frozen=True)
class QuasiStatic:
    """Solution of the quasi-static equilibrium [N, N m, rad].

    Attributes:
        torque_left, torque_right, torque_housing: external torques on the members.
        mesh_a, mesh_b, mesh_ab: tangential mesh forces of one pair (W_a, W_b, W_ab).
        pocket_force: (N_a, N_b); pocket_angle: (psi_a, psi_b).
        end_force: axial loads on the element gears' end faces (|A_a|, |A_b|).
        washer_force: normal force of each washer (name -> N).
        friction_power: friction power of each source in the housing frame [W] (washers by
            name, ``"tips"``, ``"end_faces"``, ``"teeth"``; summed over the pairs).
        residual: largest equation residual after the solve (scaled by the applied torque).
    """

    torque_left: float
    torque_right: float
    torque_housing: float
    mesh_a: float
    mesh_b: float
    mesh_ab: float
    pocket_force: tuple[float, float]
    pocket_angle: tuple[float, float]
    end_force: tuple[float, float]
    washer_force: dict[str, float]
    friction_power: dict[str, float]
    residual: float


def _sgn(x: float) -> float:
    return 1.0 if x > 0 else (-1.0 if x < 0 else 0.0)


def _unit(angle: float) -> np.ndarray:
    return np.array([math.cos(angle), math.sin(angle)])


def _perp(v: np.ndarray) -> np.ndarray:
    """z x v."""
    return np.array([-v[1], v[0]])


def solve(p: TorsenBFile, speeds: tuple[float, float, float], known: str, torque: float,
          friction_scale: float = 1.0) -> QuasiStatic:
    """Quasi-static equilibrium at constant speeds.

    Args:
        p: parameters (the model file).
        speeds: (w_housing, w_left, w_right) [rad/s], consistent with Willis' equation.
        known: which external torque is given: ``"left"`` or ``"right"`` (bench, housing held;
            the other output's torque is solved for) or ``"housing"`` (vehicle: both output
            torques solved for).
        torque: the given torque [N m] about +z.
        friction_scale: factor on every friction coefficient.
    """
    if known not in ("left", "right", "housing"):
        raise ValueError(f"known must be 'left', 'right' or 'housing', got {known!r}")
    geo = check_parameters(p)
    g = p.gears
    n = g.pairs
    rs, re = geo.r_side, geo.r_element
    ta_s = math.tan(g.pressure_angle) / math.cos(g.helix_angle)
    ta_e = ta_s  # the ends: same module, pressure and helix angle (magnitude)
    tb_l = math.tan(g.helix_angle)
    tb_r, tb_a, tb_b = -tb_l, -tb_l, tb_l
    tb_ea = -tb_l
    wh, wl, wr = speeds
    wlr, wrr = wl - wh, wr - wh
    sig_a = _sgn(-wlr * g.teeth_side / g.teeth_element)
    sig_b = -sig_a
    s_l, s_r, s_lr = _sgn(wlr), _sgn(wrr), _sgn(wl - wr)
    war = -wlr * g.teeth_side / g.teeth_element  # element spins relative to the housing
    wbr = -wrr * g.teeth_side / g.teeth_element
    s_la, s_rb, s_ab = _sgn(wlr - war), _sgn(wrr - wbr), _sgn(war - wbr)
    f = friction_scale
    mu_w, mu_p = p.washers.mu * f, p.pockets.mu * f
    mut = g.tooth_friction * f
    if mut > 0:
        k_se = couple_arm(g.teeth_side, g.teeth_element, g.module, g.pressure_angle,
                          g.helix_angle)
        k_ee = couple_arm(g.teeth_element, g.teeth_element, g.module, g.pressure_angle,
                          g.helix_angle)
    else:
        k_se = k_ee = 0.0
    rm = geo.washer_radius
    r_tip, r_end = geo.r_tip_element, rm["end"]
    tha, thb = geo.element_angles(n)[0]
    e_a, e_b = _unit(tha), _unit(thb)
    t_a, t_b = _perp(e_a), _perp(e_b)
    u_ab = (e_b - e_a) / np.linalg.norm(e_b - e_a)
    t_ab = _perp(u_ab)
    cen = p.bodies.element.mass * wh**2 * geo.centre
    T0 = abs(torque) if torque != 0 else 1.0
    F0 = T0 / (n * rs)

    def washers(Wa: float, Wb: float) -> dict[str, float]:
        A_l, A_r = n * tb_l * Wa, n * tb_r * Wb
        Nm = max(0.0, A_l, -A_r)
        return {"left": Nm - A_l, "middle": Nm, "right": A_r + Nm}

    def unpack(x):
        Wa, Wb, Wab, Na, psa, Nb, psb = x[:7] * np.array([F0, F0, F0, F0, 1.0, F0, 1.0])
        rest = x[7:] * T0
        if known == "left":
            Tl, Tr = torque, rest[0]
        elif known == "right":
            Tr, Tl = torque, rest[0]
        else:
            Tl, Tr = rest
        return Wa, Wb, Wab, Na, psa, Nb, psb, Tl, Tr

    def element(W: float, e, t, sign_ab: float, Wab: float, N: float, psi: float, sig: float,
                tb: float, tbe: float, s_side: float):
        ep = _unit(psi)
        F = (W * t + abs(W) * ta_s * e + sign_ab * (Wab * t_ab + abs(Wab) * ta_e * u_ab)
             - N * ep - sig * mu_p * N * _perp(ep) + cen * e)
        A = tb * W + tbe * Wab
        # tooth friction: side mesh +C s_side; end mesh -C_ab s_ab on a, +C_ab s_ab on b
        C = mut * (abs(W) * k_se * s_side + sign_ab * abs(Wab) * k_ee * s_ab)
        M = -re * W - re * Wab - sig * mu_p * (N * r_tip + abs(A) * r_end) + C
        return F, M, A

    def equations(x):
        Wa, Wb, Wab, Na, psa, Nb, psb, Tl, Tr = unpack(x)
        Fa, Ma, _ = element(Wa, e_a, t_a, -1.0, Wab, Na, psa, sig_a, tb_a, tb_ea, s_la)
        Fb, Mb, _ = element(Wb, e_b, t_b, 1.0, Wab, Nb, psb, sig_b, tb_b, -tb_ea, s_rb)
        W = washers(Wa, Wb)
        eq = [*(Fa / F0), Ma / (re * F0), *(Fb / F0), Mb / (re * F0),
              (Tl - n * rs * Wa - n * mut * abs(Wa) * k_se * s_la
               - mu_w * W["left"] * rm["left"] * s_l
               - mu_w * W["middle"] * rm["middle"] * s_lr) / T0,
              (Tr - n * rs * Wb - n * mut * abs(Wb) * k_se * s_rb
               - mu_w * W["right"] * rm["right"] * s_r
               + mu_w * W["middle"] * rm["middle"] * s_lr) / T0]
        if known == "housing":
            eq.append((torque + Tl + Tr) / T0)
        return eq

    # frictionless start: T_l = T_r, W_a = W_b = -W_ab
    if known == "housing":
        Tl0 = -torque / 2
    else:
        Tl0 = torque
    W0 = Tl0 / (n * rs)
    Fa0, _, _ = element(W0, e_a, t_a, -1.0, -W0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    Fb0, _, _ = element(W0, e_b, t_b, 1.0, -W0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    x0 = [W0 / F0, W0 / F0, -W0 / F0, np.linalg.norm(Fa0) / F0, math.atan2(Fa0[1], Fa0[0]),
          np.linalg.norm(Fb0) / F0, math.atan2(Fb0[1], Fb0[0])]
    x0 += [Tl0 / T0, Tl0 / T0] if known == "housing" else [Tl0 / T0]
    from scipy.optimize import fsolve  # here: 0.4 s of import off every command's start

    x, _info, ier, msg = fsolve(equations, np.array(x0, float), full_output=True, xtol=1e-13)
    res = float(np.max(np.abs(equations(x))))
    if ier != 1 and res > 1e-9:
        raise RuntimeError(f"analytic TDR (Type B): equilibrium not found ({msg.strip()}; "
                           f"residual {res:.2e})")
    Wa, Wb, Wab, Na, psa, Nb, psb, Tl, Tr = unpack(x)
    _, _, Aa = element(Wa, e_a, t_a, -1.0, Wab, Na, psa, sig_a, tb_a, tb_ea, s_la)
    _, _, Ab = element(Wb, e_b, t_b, 1.0, Wab, Nb, psb, sig_b, tb_b, -tb_ea, s_rb)
    W = washers(Wa, Wb)
    wer = abs(wlr * g.teeth_side / g.teeth_element)
    power = {"left": mu_w * W["left"] * rm["left"] * abs(wlr),
             "middle": mu_w * W["middle"] * rm["middle"] * abs(wl - wr),
             "right": mu_w * W["right"] * rm["right"] * abs(wrr),
             "tips": n * mu_p * (Na + Nb) * r_tip * wer,
             "end_faces": n * mu_p * (abs(Aa) + abs(Ab)) * r_end * wer,
             "teeth": n * mut * (abs(Wa) * k_se * abs(wlr - war) + abs(Wb) * k_se * abs(wrr - wbr)
                                 + abs(Wab) * k_ee * abs(war - wbr))}
    return QuasiStatic(Tl, Tr, -(Tl + Tr), Wa, Wb, Wab, (Na, Nb), (psa, psb),
                       (abs(Aa), abs(Ab)), W, power, res)


def bench_speeds(mode: int, speed_diff: float) -> tuple[tuple[float, float, float], float]:
    """Speeds (housing, left, right) and sign of the applied torque in a bench mode (as
    :func:`drivedyn.library.differentials.scenarios.bench_spec`): the loaded output turns with
    its torque, which is negative (resisting forward motion) in drive."""
    _, _, side, drive = MODES[mode - 1]
    s = 1.0 if drive else -1.0
    w = speed_diff / 2
    if side == "right":
        return (0.0, s * w, -s * w), -s
    return (0.0, -s * w, s * w), -s


def bench_tdr(p: TorsenBFile, mode: int, torque: float | None = None,
              speed_diff: float | None = None, friction_scale: float = 1.0) -> float:
    """Analytic TDR of one bench mode (1-4): applied torque / resistant torque (the favoured
    side's torque over the other's)."""
    side = MODES[mode - 1][2]
    T0 = p.bench.torque if torque is None else torque
    dw = p.bench.speed_diff if speed_diff is None else speed_diff
    speeds, sgn = bench_speeds(mode, dw)
    q = solve(p, speeds, side, sgn * T0, friction_scale)
    if side == "right":
        return abs(q.torque_right / q.torque_left)
    return abs(q.torque_left / q.torque_right)


def vehicle_torques(p: TorsenBFile, speeds: tuple[float, float, float], torque: float,
                    friction_scale: float = 1.0) -> tuple[float, float]:
    """Output torques (left, right) delivered to the axles [N m] with the housing torque
    ``torque`` and the speeds (housing, left, right) [rad/s]."""
    q = solve(p, speeds, "housing", torque, friction_scale)
    return -float(q.torque_left), -float(q.torque_right)


def all_modes(p: TorsenBFile, **kw) -> list[float]:
    """Analytic TDR of modes 1-4."""
    return [bench_tdr(p, m, **kw) for m in (1, 2, 3, 4)]
