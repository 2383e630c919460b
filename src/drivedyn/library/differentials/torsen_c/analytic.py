r"""Quasi-static torque distribution ratio of the TORSEN Type C, derived by hand.

This model shares only the *parameters* with the simulator (the model file); every force
is written out below from the equilibrium of each part at constant speeds, so that it can
check the multibody simulation (simulated and analytic TDR agree within 2 %).

Frame and signs: axis z, forward rotation +z, speeds relative to the housing
``w_s' = w_s - w_h``, ``w_c' = w_c - w_h`` (ring = coupling), planet spin
``w_p' = -w_s' z_s / z_p``. One planet is studied at the angle 0 (unit vectors
``r`` radial, ``t`` tangential); the ``n`` planets share the load equally.

**Meshes** (pitch point on the line of centres; helical gears): the sun mesh pushes the
planet with ``F_s t + |F_s| tan(alpha_t) r`` (separating force, ``tan alpha_t =
tan alpha_n / cos beta``), the ring mesh with ``F_r t - |F_r| tan(alpha_t) r``. Reactions:
sun torque ``-n F_s r_s``, ring torque ``-n F_r r_r``; axial thrusts
``A_s = h tan(beta) n F_s`` on the sun and ``A_r = -h tan(beta) n F_r`` on the ring
(``h = +1`` right-hand sun). On the planet the two mesh thrusts are ``-h tan(beta) F_s``
(sun mesh) and ``+h tan(beta) F_r`` (ring mesh): they cancel only without friction. The net
thrust ``A_p = h tan(beta) (F_r - F_s)`` (with the pocket friction 40-60 % of one mesh's
thrust at the bench) presses the planet's end face on a pocket floor (``pockets.end_faces``,
friction radius ``r_e``), whose friction resists the planet's spin. The thrusts' couple
``r_p tan(beta) (|F_s| + |F_r|)`` about the tangential axis goes to the planet's guide
(held against tilt, no friction: the bore's end reactions are not modelled).

**Planet in its pocket**: contact at the direction ``e = (cos psi, sin psi)`` from the planet
centre, normal force ``-N e``, tip friction ``mu_p N`` opposing the slip of the tip circle
(radius ``r_a``): force ``-sigma mu_p N (z x e)`` and torque ``-sigma mu_p N r_a``,
``sigma = sign(w_p')``; end-face friction torque ``-sigma mu_p |A_p| r_e``.

**Tooth friction** (``gears.tooth_friction`` ``mu_t``; law, normal force and mean arm
derived in :mod:`drivedyn.library.differentials.tooth_friction`): each mesh puts a couple
``C = mu_t F_N s_eff`` on its two wheels, turning each towards the other's angular velocity
relative to the housing (which carries the planet centres), with the normal flank force
``F_N = |F_t| / (cos(alpha_n) cos(beta))``. Per planet::

    C_s = mu_t |F_s| kappa_sp,   C_r = mu_t |F_r| kappa_pr,   kappa = s_eff / (cos alpha_n cos beta)
    s_sp = sgn(w_s' - w_p'),     s_pr = sgn(w_p' - w_r')

(``s_eff`` of the sun-planet pair ``z_s/z_p`` and of the internal pair ``z_p/-z_r``; with
``w_p' = -w_s' z_s/z_p`` and ``w_r' = -w_s' z_s/z_r``, ``s_sp = sgn(w_s')`` and ``s_pr =
-sgn(w_s') = sigma``). The couples on the planet are ``+C_s s_sp`` and ``-C_r s_pr``, on the
sun ``-C_s s_sp``, on the ring ``+C_r s_pr``. With the centrifugal force ``m w_h^2 a``
(vehicle)::

    r:  |F_s| tan(alpha_t) - |F_r| tan(alpha_t) - N cos psi + sigma mu_p N sin psi + m w_h^2 a = 0
    t:  F_s + F_r - N sin psi - sigma mu_p N cos psi = 0
    z:  r_p (F_r - F_s) - sigma mu_p (N r_a + |A_p| r_e) + C_s s_sp - C_r s_pr = 0

**Spline** (screw joint of lead ``L``, flank radius ``r``, helix ``tan(beta) = 2 pi r / L``):
the torque ``T_B`` it applies on the ring comes with the axial force ``T_B tan(beta) / r =
2 pi T_B / L`` on the coupling and the opposite on the ring. With flank friction
``spline.mu`` the flanks stick at their Coulomb limit against the separation the thrust
drives (the limit state of a spline stiffer than the washers, docs/torsen_c.md): their
resultant leans back by the friction angle ``phi = atan(mu)``, axial force
``T_B tan(beta - phi) / r``.

**Axial equilibrium and washers** (unilateral, rigid; washer normals: W1, W2, W4 along +z,
W3, W5 along -z)::

    sun:       A_s + N1 - N2 = 0
    coupling:  k T_B + N2 - N3 = 0          (k = tan(beta - phi) / r, signed with L)
    ring:      A_r - k T_B + N4 - N5 = 0

The ring has one of N4, N5 non-zero (the sign of its net thrust). The sun and coupling
(pushed the same way by the design) either rest on W1 with the coupling on the sun
(``N3 = 0``) or on W3 with the sun on the coupling (``N1 = 0``).

**Moments about z** (washer friction ``mu_i N_i r_mi`` against the relative spin of the two
faces, ``r_mi = 2 (r_e^3 - r_i^3) / (3 (r_e^2 - r_i^2))``)::

    sun:       T_s - n F_s r_s - n C_s s_sp - M1 sgn(w_s') + M2 sgn(w_c - w_s) = 0
    ring:      -n F_r r_r + n C_r s_pr - (M4 + M5) sgn(w_c') + T_B = 0
    coupling:  T_c - M2 sgn(w_c - w_s) - M3 sgn(w_c') - T_B = 0
    (vehicle)  T_h + T_s + T_c = 0

Given the applied torque (and speeds), these are 6 equations (7 with the housing torque) in
``F_s, F_r, N, psi, T_B`` and the unknown output torque(s); they are solved by Newton's
method (``scipy.optimize.fsolve``) from the frictionless solution. The friction signs come
from the prescribed speeds, the washer loads from the axial equilibrium at each iterate.

The couples leave the forces, hence the thrusts and the washer loads, as they are; they
change the mesh forces' ratio through the planet's moment. Tooth friction alone (no pocket
or washer friction), with ``q = sgn(w_s') sgn(F_s)`` (-1 when the ring drives the train
relative to the housing, +1 when the sun does) and ``h = pi (1 - eps_alpha + eps_1^2 +
eps_2^2) / cos(beta_b)`` of each pair (``kappa / r_i = h / z_i``), gives in closed form::

    T_r / T_s = rho (1 + q mu_t h_pr/z_r)(1 - q mu_t h_sp/z_p)
                    / ((1 + q mu_t h_sp/z_s)(1 + q mu_t h_pr/z_p))

whose first order, ``ln(T_r / (rho T_s)) = -q mu_t (H_V,sp + H_V,pr)``, is the product of the
two meshes' Ohlendorf efficiencies ``1 - mu_t H_V`` (checked in
``tests/models/test_tooth_friction_analytic.py``).

For small friction this reduces to the textbook bias ratio ``TBR = 1/eta`` (physics.md 4):
with only pocket friction ``b = mu_p r_a / r_p`` (radial mesh forces and centrifugal force
neglected) the rear/front ratio is ``rho (1 + b)/(1 - b)`` when the ring drives the train
relative to the housing and ``rho (1 - b)/(1 + b)`` when the sun does
(:func:`pocket_only_ratio`, used in the tests as an independent limit).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from drivedyn.library.differentials.tooth_friction import couple_arm
from drivedyn.library.differentials.torsen_c.model import MODES, check_parameters
from drivedyn.library.differentials.torsen_c.schema import TorsenCFile


@dataclass(frozen=True)
class QuasiStatic:
    """Solution of the quasi-static equilibrium [N, N m, rad].

    Attributes:
        torque_sun, torque_coupling, torque_housing: external torques on the members.
        mesh_sun, mesh_ring: tangential mesh forces per planet (signed along t).
        pocket_force, pocket_angle: pocket normal force per planet and its direction psi.
        spline_torque: torque of the spline on the ring.
        washer_force: normal force of each washer (name -> N).
        washer_torque: friction torque magnitude of each washer (name -> N m).
        tooth_couple: tooth-friction couples of one planet's meshes (C_s, C_r) [N m].
        planet_thrust: net axial thrust of the meshes on one planet, ``A_p`` [N] (on its
            end face with ``pockets.end_faces``, else on its frictionless guide).
        residual: largest equation residual after the solve (scaled by the applied torque).
    """

    torque_sun: float
    torque_coupling: float
    torque_housing: float
    mesh_sun: float
    mesh_ring: float
    pocket_force: float
    pocket_angle: float
    spline_torque: float
    washer_force: dict[str, float]
    washer_torque: dict[str, float]
    tooth_couple: tuple[float, float]
    planet_thrust: float
    residual: float


def _sgn(x: float) -> float:
    return 1.0 if x > 0 else (-1.0 if x < 0 else 0.0)


def solve(p: TorsenCFile, speeds: tuple[float, float, float], known: str, torque: float,
          friction_scale: float = 1.0) -> QuasiStatic:
    """Quasi-static equilibrium at constant speeds.

    Args:
        p: parameters (the model file).
        speeds: (w_housing, w_sun, w_coupling) [rad/s], consistent with Willis' equation.
        known: which external torque is given: ``"coupling"`` or ``"sun"`` (test bench,
            housing held; the other output's torque is solved for) or ``"housing"``
            (vehicle: both output torques solved for).
        torque: the given torque [N m] about +z.
        friction_scale: factor on every friction coefficient.
    """
    if known not in ("coupling", "sun", "housing"):
        raise ValueError(f"known must be 'coupling', 'sun' or 'housing', got {known!r}")
    geo = check_parameters(p)
    g = p.gears
    n = g.planets
    rs, rp, rr, ra, a = geo.r_sun, geo.r_planet, geo.r_ring, geo.r_tip_planet, \
        geo.carrier_radius
    tb = abs(math.tan(g.helix_angle)) * geo.hand  # h tan(beta), h = +1 right-hand sun
    ta = math.tan(g.pressure_angle) / math.cos(g.helix_angle)
    wh, ws, wc = speeds
    wsr, wcr = ws - wh, wc - wh
    wpr = -wsr * g.teeth_sun / g.teeth_planet
    sig = _sgn(wpr)
    s_s, s_c, s_cs = _sgn(wsr), _sgn(wcr), _sgn(wc - ws)
    s_sp, s_pr = _sgn(wsr - wpr), _sgn(wpr - wcr)  # relative spins of the meshes' wheels
    f = friction_scale
    mut = g.tooth_friction * f
    if mut > 0:
        k_sp = couple_arm(g.teeth_sun, g.teeth_planet, g.module, g.pressure_angle,
                          g.helix_angle)
        k_pr = couple_arm(g.teeth_planet, -g.teeth_ring, g.module, g.pressure_angle,
                          g.helix_angle)
    else:
        k_sp = k_pr = 0.0
    mu = {name: getattr(p.washers, name).mu * f for name in geo.washer_radius}
    rm = geo.washer_radius
    mup = p.pockets.mu * f
    t_beta, r_end = abs(math.tan(g.helix_angle)), geo.r_end
    cen = p.bodies.planet.mass * wh**2 * a
    k_spl = 0.0 if math.isinf(geo.lead) else 2 * math.pi / geo.lead
    if k_spl != 0.0 and p.spline.mu > 0.0:
        # friction at its limit against the separation the thrust drives: the flanks'
        # resultant leans back by the friction angle phi, axial force T tan(beta - phi) / r
        r_sp = p.spline.radius
        beta_s = math.atan(abs(k_spl) * r_sp)
        k_spl = math.copysign(math.tan(beta_s - math.atan(p.spline.mu * f)) / r_sp, k_spl)
    T0 = abs(torque) if torque != 0 else 1.0

    def washers(Fs: float, Fr: float, TB: float) -> dict[str, float]:
        As = tb * n * Fs
        Ar = -tb * n * Fr
        Fc = k_spl * TB
        X = Ar - Fc
        N4, N5 = max(0.0, -X), max(0.0, X)
        # sun + coupling: both on W1 (coupling pressing on the sun), both on W3 (sun
        # pressing on the coupling), or pushed apart (each on its own washer)
        if Fc <= 0 and As + Fc <= 0:
            N1, N2, N3 = -(As + Fc), -Fc, 0.0
        elif As >= 0 and As + Fc >= 0:
            N1, N2, N3 = 0.0, As, As + Fc
        else:  # As < 0 < Fc
            N1, N2, N3 = -As, 0.0, Fc
        return {"sun_housing": N1, "sun_coupling": N2, "coupling_case": N3,
                "ring_housing": N4, "ring_case": N5}

    def unpack(x):
        Fs, Fr, N, psi, TB = x[:5] * np.array([T0 / rs, T0 / rs, T0 / rs, 1.0, T0])
        rest = x[5:] * T0
        if known == "coupling":
            Tc, Ts = torque, rest[0]
        elif known == "sun":
            Ts, Tc = torque, rest[0]
        else:
            Ts, Tc = rest
        return Fs, Fr, N, psi, TB, Ts, Tc

    def equations(x):
        Fs, Fr, N, psi, TB, Ts, Tc = unpack(x)
        W = washers(Fs, Fr, TB)
        M = {k: mu[k] * W[k] * rm[k] for k in W}
        Cs, Cr = mut * abs(Fs) * k_sp, mut * abs(Fr) * k_pr
        c, s = math.cos(psi), math.sin(psi)
        e = [
            (abs(Fs) * ta - abs(Fr) * ta - N * c + sig * mup * N * s + cen) * rs / T0,
            (Fs + Fr - N * s - sig * mup * N * c) * rs / T0,
            (rp * (Fr - Fs) - sig * mup * (N * ra + t_beta * abs(Fr - Fs) * r_end)
             + Cs * s_sp - Cr * s_pr) * rs / (rp * T0),
            (Ts - n * Fs * rs - n * Cs * s_sp - M["sun_housing"] * s_s
             + M["sun_coupling"] * s_cs) / T0,
            (-n * Fr * rr + n * Cr * s_pr - (M["ring_housing"] + M["ring_case"]) * s_c
             + TB) / T0,
            (Tc - M["sun_coupling"] * s_cs - M["coupling_case"] * s_c - TB) / T0,
        ]
        if known == "housing":
            e.append((torque + Ts + Tc) / T0)
        return e

    # frictionless start: T_c / T_s = rho, sun force from the known torque
    if known == "coupling":
        Ts0 = torque / geo.rho
    elif known == "sun":
        Ts0 = torque
    else:
        Ts0 = -torque / (1 + geo.rho)
    Fs0 = Ts0 / (n * rs)
    x0 = [Fs0 * rs / T0, Fs0 * rs / T0, 2 * abs(Fs0) * rs / T0,
          math.copysign(math.pi / 2, Fs0 if Fs0 != 0 else 1.0), Fs0 * n * rr / T0]
    if known == "housing":
        x0 += [Ts0 / T0, geo.rho * Ts0 / T0]
    elif known == "coupling":
        x0 += [Ts0 / T0]
    else:
        x0 += [geo.rho * Ts0 / T0]
    from scipy.optimize import fsolve  # here: 0.4 s of import off every command's start

    x, _info, ier, msg = fsolve(equations, np.array(x0, float), full_output=True, xtol=1e-13)
    res = float(np.max(np.abs(equations(x))))
    if ier != 1 and res > 1e-9:
        raise RuntimeError(f"analytic TDR: equilibrium not found ({msg.strip()}; residual "
                           f"{res:.2e})")
    Fs, Fr, N, psi, TB, Ts, Tc = unpack(x)
    W = washers(Fs, Fr, TB)
    return QuasiStatic(Ts, Tc, -(Ts + Tc), Fs, Fr, N, psi, TB, W,
                       {k: mu[k] * W[k] * rm[k] for k in W},
                       (mut * abs(Fs) * k_sp, mut * abs(Fr) * k_pr),
                       tb * (Fr - Fs), res)


def bench_speeds(p: TorsenCFile, side: str, drive: bool, speed_diff: float
                 ) -> tuple[tuple[float, float, float], float]:
    """Speeds (housing, sun, coupling) and sign of the applied torque in a bench mode
    (as :func:`drivedyn.library.differentials.scenarios.bench_spec`): the loaded output turns
    with its torque, which is negative (resisting forward motion) in drive."""
    rho = p.gears.teeth_ring / p.gears.teeth_sun
    s = 1.0 if drive else -1.0
    w_ring = speed_diff / (1 + rho)
    w_sun = rho * speed_diff / (1 + rho)
    if side == "rear":
        return (0.0, s * w_sun, -s * w_ring), -s
    return (0.0, -s * w_sun, s * w_ring), -s


def bench_tdr(p: TorsenCFile, mode: int, torque: float | None = None,
              speed_diff: float | None = None, friction_scale: float = 1.0) -> float:
    """Analytic TDR of one bench mode (1-4): applied torque / resistant torque, i.e. the
    favoured axle's torque over the other's (rear/front in modes 1-2, front/rear in 3-4)."""
    _, _, side, drive = MODES[mode - 1]
    T0 = p.bench.torque if torque is None else torque
    dw = p.bench.speed_diff if speed_diff is None else speed_diff
    speeds, sgn = bench_speeds(p, side, drive, dw)
    known = "coupling" if side == "rear" else "sun"
    q = solve(p, speeds, known, sgn * T0, friction_scale)
    if side == "rear":
        return abs(q.torque_coupling / q.torque_sun)
    return abs(q.torque_sun / q.torque_coupling)


def vehicle_torques(p: TorsenCFile, speeds: tuple[float, float, float], torque: float,
                    friction_scale: float = 1.0) -> tuple[float, float]:
    """Output torques (front, rear) delivered to the axles [N m] with the housing torque
    ``torque`` and the speeds (housing, front, rear) [rad/s]."""
    q = solve(p, speeds, "housing", torque, friction_scale)
    return -float(q.torque_sun), -float(q.torque_coupling)


def all_modes(p: TorsenCFile, **kw) -> list[float]:
    """Analytic TDR of modes 1-4."""
    return [bench_tdr(p, m, **kw) for m in (1, 2, 3, 4)]


def pocket_only_ratio(rho: float, mu_p: float, r_tip: float, r_pitch: float,
                      ring_drives: bool) -> float:
    """Textbook estimate of the rear/front torque ratio with pocket friction only:
    ``rho (1 + b)/(1 - b)`` if the ring drives relative to the housing, ``rho (1 - b)/(1 + b)``
    if the sun does, ``b = mu_p r_tip / r_pitch``.

    An approximation of :func:`solve`: it neglects the radial mesh forces, the centrifugal
    force and the tilt of the pocket reaction by the friction angle (it takes the pocket
    normal force as ``F_s + F_r`` instead of about ``(F_s + F_r) / sqrt(1 + mu_p^2)``); the
    exact pocket-only value, ``x = b / sqrt(1 + mu_p^2 - b^2 tan^2 alpha_t)`` in place of
    ``b``, is derived and checked in ``tests/models/test_torsen_c.py``."""
    b = mu_p * r_tip / r_pitch
    k = (1 + b) / (1 - b)
    return rho * k if ring_drives else rho / k
