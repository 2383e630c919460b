"""Validation cases of meshed solid parts: finite elements, Craig-Bampton reduction, the
floating-frame body and the flexible washer contact."""

from __future__ import annotations

import math

import numpy as np

from drivedyn.elements.contact import FrictionLaw, NormalLaw
from drivedyn.elements.drivers import JointDriver
from drivedyn.elements.flexible import FlexibleWasherContact
from drivedyn.elements.joints import Cylindrical, Fixed, Hinge
from drivedyn.elements.loads import Force
from drivedyn.fe import (
    Interface,
    SolidMaterial,
    SolidModel,
    annular_washer,
    annulus_quadrature,
    box,
    craig_bampton,
    face_load_patterns,
    frequency_check,
    von_mises,
)
from drivedyn.model.compile import compile_model
from drivedyn.model.flexible import add_flexible_body
from drivedyn.model.spec import Spec
from drivedyn.solver import FixedStep, GeneralizedAlpha, Newton, simulate
from drivedyn.validation.base import CaseResult, compare, register_case
from drivedyn.validation.common import at_least, at_most, failed_check

STEEL = SolidMaterial(210e9, 0.3, 7850.0)


def clamp(solid: SolidModel, nodes: np.ndarray) -> np.ndarray:
    """All dofs of ``nodes``."""
    return (3 * nodes[:, None] + np.arange(3)).ravel()


@register_case("fe_cantilever")
def fe_cantilever(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """A 1 m x 0.1 m x 0.1 m steel block clamped at x = 0 with a shear load P at x = 1
    (27-node hexahedra) vs Timoshenko beam theory; and uniform tension vs sigma = F/A. Seen
    to fail: the assembled stiffness 2 % high gives the tip 2.9 % off (tolerance 2 %,
    baseline 0.9 %) and the tension stress 2 % off (tolerance 1e-6)."""
    L, a, P = 1.0, 0.1, 1000.0
    solid = SolidModel(box(L, a, a, 20, 2, 2), STEEL)
    tip = solid.select("x", L)
    area = solid.face_areas(tip)
    f = np.zeros(3 * solid.n)
    f[3 * tip + 2] = -P * area / area.sum()
    u = solid.static(clamp(solid, solid.select("x", 0.0)), f)
    E, nu = STEEL.youngs_modulus, STEEL.poisson_ratio
    I, A = a**4 / 12, a * a
    k = 10 * (1 + nu) / (12 + 11 * nu)  # Cowper, rectangle
    ref = P * L**3 / (3 * E * I) + P * L / (k * E / (2 * (1 + nu)) * A)
    sim = -float(np.sum(u[3 * tip + 2] * area) / area.sum())
    out = [compare("fe_cantilever", "tip deflection under a 1 kN shear load", ref, sim, "m",
                   0.02, "Timoshenko beam: P L^3/(3 E I) + P L/(k G A), Cowper k")]
    # uniform tension with symmetry supports: exact constant stress
    root = solid.select("x", 0.0)
    fixed = np.concatenate([3 * root, 3 * root[np.abs(solid.nodes[root, 1]) < 1e-9] + 1,
                            3 * root[np.abs(solid.nodes[root, 2]) < 1e-9] + 2])
    sigma = 1e6
    f = np.zeros(3 * solid.n)
    f[3 * tip] = sigma * area
    s = solid.stress_modes(solid.static(fixed, f)[:, None])[:, :, 0]
    worst = float(np.max(np.abs(von_mises(s) - sigma)))
    out.append(compare("fe_cantilever", "uniform tension: largest nodal von Mises error",
                       sigma, sigma + worst, "Pa", 1e-6, "sigma = F/A exactly"))
    return out


def annular_plate_deflection(q: float, a: float, b: float, t: float, E: float,
                             nu: float) -> float:
    """Deflection [m] of the free inner edge (r = b) of an annular plate clamped at its outer
    edge r = a under uniform pressure q: the closed-form Kirchhoff solution behind Roark's
    Table 11.2 (case outer edge fixed, inner edge free), constants solved exactly.

    w = q r^4/(64 D) + C1 + C2 r^2 + C3 ln r + C4 r^2 ln r with w(a) = w'(a) = 0 and
    M_r(b) = Q_r(b) = 0."""
    D = E * t**3 / (12 * (1 - nu**2))

    def rows(r):
        # w, w', M_r/(-D) = w'' + nu w'/r, Q_r/(-D) = d/dr(w'' + w'/r) per basis function
        lr = math.log(r)
        w = [1.0, r * r, lr, r * r * lr]
        dw = [0.0, 2 * r, 1 / r, 2 * r * lr + r]
        d2 = [0.0, 2.0, -1 / r**2, 2 * lr + 3]
        d3 = [0.0, 0.0, 2 / r**3, 2 / r]
        m = [d2[i] + nu * dw[i] / r for i in range(4)]
        qq = [d3[i] + d2[i] / r - dw[i] / r**2 for i in range(4)]
        p = q / (64 * D)
        part = (p * r**4, 4 * p * r**3, 12 * p * r * r + nu * 4 * p * r * r,
                24 * p * r + 12 * p * r - 4 * p * r)
        return w, dw, m, qq, part

    wa, dwa, _, _, pa = rows(a)
    _, _, mb, qb, pb = rows(b)
    Amat = np.array([wa, dwa, mb, qb])
    rhs = -np.array([pa[0], pa[1], pb[2], pb[3]])
    C = np.linalg.solve(Amat, rhs)
    wb, _, _, _, pbb = rows(b)
    return float(np.dot(C, wb) + pbb[0])


@register_case("fe_annular_plate")
def fe_annular_plate(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Annular steel plate (b = 50 mm, a = 100 mm, t = 3 mm) clamped at r = a, uniform
    pressure 0.1 MPa on its face: inner-edge deflection vs Roark. Seen to fail: the
    assembled stiffness 5 % high gives 6.9 % (tolerance 3 %, baseline 1.3 %)."""
    b, a, t, q = 0.05, 0.1, 0.003, 1e5
    nt = 36 if quick else 48
    solid = SolidModel(annular_washer(b, a, t, 6 if quick else 8, nt, 1), STEEL)
    # the mid-side nodes of the faceted rim sit at a cos(pi/nt): the clamp holds them too
    rim = a * math.cos(math.pi / nt) * (1 - 1e-9)
    top = solid.select("z", t)
    area = solid.face_areas(top)
    f = np.zeros(3 * solid.n)
    f[3 * top + 2] = -q * area
    u = solid.static(clamp(solid, solid.select(r_min=rim)), f)
    inner = solid.select(r_max=b * (1 + 1e-9))
    sim = -float(np.mean(u[3 * inner + 2]))
    ref = -annular_plate_deflection(-q, a, b, t, STEEL.youngs_modulus, STEEL.poisson_ratio)
    return [compare("fe_annular_plate", "deflection of the free inner edge, 0.1 MPa", ref, sim,
                    "m", 0.03, "Roark Table 11.2, outer edge fixed, inner edge free "
                    "(closed-form Kirchhoff plate)")]


@register_case("fe_modes")
def fe_modes(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Free-free steel bar 1 m x 20 mm x 20 mm (slender: shear and rotary inertia change the
    third bending frequency by about 0.7 %): bending eigenfrequencies vs Euler-Bernoulli;
    Craig-Bampton (interface x = 0) vs the full model. Seen to fail: the assembled mass 5 %
    high lowers the bending frequencies by 2.5-3.0 % (tolerance 2 %); a reduction with 6
    fixed-interface modes instead of 16 puts its fifth free-free frequency 106 % high
    (tolerance 0.5 %; 8 modes pass at 0.29 %)."""
    L, a = 1.0, 0.02
    solid = SolidModel(box(L, a, a, 30, 1, 1), STEEL)
    itf = [Interface("end", solid.select("x", 0.0), np.zeros(3))]
    part = craig_bampton(solid, itf, 16, "bar", cache=False)
    full, red = frequency_check(part, solid, itf, 8, free=True)
    E, rho = STEEL.youngs_modulus, STEEL.density
    EI_mA = E * a**4 / 12 / (rho * a * a)
    bend = [(bl**2) * math.sqrt(EI_mA) / (2 * math.pi * L**2)
            for bl in (4.730041, 7.853205, 10.995608)]
    out = []
    for k, fr in enumerate(bend):
        sim = full[np.argmin(np.abs(full - fr))]
        out.append(compare("fe_modes", f"free-free bending mode {k + 1}", fr, sim, "Hz", 0.02,
                           "Euler-Bernoulli free-free beam (beta L = 4.730, 7.853, 10.996)"))
    for k in range(5):
        out.append(compare("fe_modes", f"Craig-Bampton (16 modes) vs full, mode {k + 1}",
                           full[k], red[k], "Hz", 0.005, "full finite-element model"))
    return out


def spinning_part(spin: float, kick: float):
    """A bar (0.5 x 0.05 x 0.05 m, 6 fixed-interface modes) mounted by its end on a free
    node spinning at ``spin`` rad/s, its first mode excited with amplitude ``kick``."""
    solid = SolidModel(box(0.5, 0.05, 0.05, 6, 1, 1), STEEL)
    part = craig_bampton(solid, [Interface("root", solid.select("x", 0.0), np.zeros(3))], 6,
                         "bar")
    sp = Spec()
    sp.add_node("hub", angular_velocity=(0.0, 0.0, spin))
    sp.add_marker("mount", "hub")
    q0 = np.zeros(part.nq)
    q0[0] = kick
    add_flexible_body(sp, "bar", part, "mount", q0=q0)
    return sp, part


def hub_part(part, Q: np.ndarray, spin: float, kick: float, gravity) -> Spec:
    """``part`` mounted by its interface 0 on a hub node in a hinge to the ground, its
    first elastic coordinate started at ``kick``: the hub frame is ``Q`` (3, 3) and spins
    at ``spin`` [rad/s] about its z axis, which is the hinge axis; ``gravity`` (3,)
    [m/s^2], global."""
    sp = Spec(gravity=gravity)
    sp.add_node("hub", rotation=Q, angular_velocity=Q @ np.array([0.0, 0.0, spin]))
    sp.add_marker("ground_axis", "ground", rotation=Q)
    sp.add_marker("hub_axis", "hub")
    sp.add(Hinge("bearing", "ground_axis", "hub_axis"))
    q0 = np.zeros(part.nq)
    q0[0] = kick
    add_flexible_body(sp, "bar", part, "hub_axis", q0=q0)
    return sp


@register_case("ffrf_energy")
def ffrf_energy(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Floating frame of reference: energy conservation of a free spinning, vibrating part
    and frame invariance of a loaded one.

    Energy: undamped free bar (0.5 x 0.05 x 0.05 m, 6 fixed-interface modes) spinning at
    50 rad/s and vibrating (first mode 168 Hz, started from a deflection: vibration energy
    0.558 J against 1025 J of spin) over 0.05 s with ``rho_inf = 1``: the energy drift
    relative to the *vibration* energy at h = 1e-5 s <= 3 %, and its order from 2e-5 to
    1e-5 s >= 1.8. Measured: drift 6.8 % and 1.56 % (order 2.1; the scheme does not
    conserve energy exactly on the nonlinear floating-frame equations). Fails on a run
    that does not reach its end (the floating frame's equations without a force scale did
    not take a step, and a drift over the total energy passed on nothing: seen) and on
    numerical dissipation (rho_inf = 0.9: 3.6 % at 1e-5 s, seen). The order check is for a
    loss that does not fall with the step: a stiffness-proportional damping of 1e-9 s in
    the part gives drift 3.8 % and order 1.18, both failing (seen; 1e-8 s: 26 %, order
    -0.02; 1e-10 s passes both, 1.78 % and 1.98).

    Frame invariance: the same bar on a hub in a hinge, spinning at 50 rad/s about the
    hinge axis in gravity (9.81 m/s^2 across the axis: a bending load that turns with the
    part at the spin frequency), first mode started at q0 = 1e-3, 0.05 s at h = 1e-4 s
    (``rho_inf = 0.9``: a joint), run twice: as built, and with the hub frame, the hinge
    axis, the spin and gravity all turned by one large rotation (119 deg about (1.2, -0.8,
    1.5)). The elastic coordinates live in the part frame, so their histories must agree:
    largest difference / largest ``|q|`` <= 1e-9. The runs solve to a Newton tolerance of
    1e-12 (the default 1e-8 leaves differences of 1.5e-7); 1e-9 is 2000 times their
    round-off and 4e-8 of what gravity alone (9.81 m/s^2 against 625 m/s^2 of centrifugal
    acceleration at mid-length) does when it is taken in the wrong frame. This fails on
    anything the formulation takes in the wrong frame: the part's inertia loads
    ``alpha = R^T (xdd - g)``, the angular velocity, the joint's rows. Measured 5.5e-13.

    Fails on (seen; the kernel mutations in a scratch copy of the source): the kernel's
    ``alpha = R (xdd - g)`` instead of ``R^T (xdd - g)``: 3.9e-2 (and the free energy run
    stops early); gravity subtracted in the part frame, ``alpha = R^T xdd - g``: 8.9e-3,
    which the energy checks pass (no gravity there); gravity left unturned in the turned
    run: 3.9e-2.
    """
    sp, part = spinning_part(50.0, 1e-3)
    model = compile_model(sp)
    t_end = 0.05  # quick too: over 0.02 s the drift's order is not yet settled (1.77)
    drifts = []
    for h in (2e-5, 1e-5):
        res = simulate(model, t_end, step=FixedStep(h), integrator=GeneralizedAlpha(1.0),
                       output_dt=1e-3)
        if not res.success:
            return [failed_check("ffrf_energy", f"energy drift over {t_end} s, {h:g} s steps",
                                 "1", 0.03, "conservation (no damping, rho_inf = 1)", res)]
        E = res.dataset["energy.kinetic"].values + res.dataset["energy.potential"].values
        e_vib = float(res.dataset["bar.elastic_energy"].values[0])  # at rest in the frame
        drifts.append(float(np.max(np.abs(E - E[0]))) / e_vib)
    out = [at_most("ffrf_energy", f"energy drift over {t_end} s at 1e-5 s steps, relative "
                   "to the vibration energy", drifts[1], 0.03, "1",
                   "conservation (no damping, rho_inf = 1)"),
           at_least("ffrf_energy", "order of the drift (2e-5 -> 1e-5 s)",
                    math.log2(drifts[0] / drifts[1]), 1.8, "1",
                    "second-order scheme: the drift is a discretisation error")]
    # frame invariance of a part loaded by gravity and spinning in a hinge
    from drivedyn.rotations import exp_so3

    g = np.array([0.0, -9.81, 0.0])
    qs = []
    for Q in (np.eye(3), exp_so3(np.array([1.2, -0.8, 1.5]))):
        res = simulate(compile_model(hub_part(part, Q, 50.0, 1e-3, Q @ g)), t_end,
                       step=FixedStep(1e-4), integrator=GeneralizedAlpha(0.9),
                       newton=Newton(tol=1e-12), output_dt=5e-4, variables=["bar.q"])
        if not res.success:
            return [*out, failed_check("ffrf_energy", "elastic coordinates, turned vs as "
                                       "built", "1", 1e-9, "frame invariance", res)]
        qs.append(res.dataset["bar.q"].values)
    out.append(compare("ffrf_energy", "elastic coordinates of a spinning part in gravity, "
                       "all turned vs as built: largest difference / largest |q|", 0.0,
                       float(np.abs(qs[1] - qs[0]).max() / np.abs(qs[0]).max()), "1", 1e-9,
                       "frame invariance: q lives in the part frame"))
    return out


def washer_bench(load: float, mu: float, spin: float, k_contact: float, n_modes: int = 6,
                 quadrature: tuple[int, int] | None = None, tilt: float = 0.0):
    """A steel washer (r 20..35 mm, 2 mm) mounted by its back face on a carrier fixed to the
    ground, pressed by a spinning rigid face with the axial force ``load`` [N], at every face
    node or at the points of ``annulus_quadrature(..., *quadrature)``; the face tilted by
    ``tilt`` [rad] about the gear's x axis (the pressure then varies around the washer, and
    turns with the gear)."""
    ri, re, t = 0.020, 0.035, 0.002
    solid = SolidModel(annular_washer(ri, re, t, 2, 36, 1), STEEL)
    part = craig_bampton(solid, [Interface("back", solid.select("z", 0.0), np.zeros(3))],
                         n_modes, "washer", loads=face_load_patterns(solid, solid.select("z", t)))
    sp = Spec()
    sp.add_rigid_body("carrier", 0.5, (1e-3, 1e-3, 2e-3))
    sp.add_rigid_body("gear", 0.3, (3e-4, 3e-4, 5e-4), position=(0, 0, t + 0.01),
                      angular_velocity=(0, 0, spin))
    sp.add_marker("ground_c", "ground", axis=(0, 0, 1))
    sp.add_marker("carrier_c", "carrier", axis=(0, 0, 1))
    sp.add(Fixed("carrier_fix", "ground_c", "carrier_c"))
    sp.add_marker("ground_g", "ground", position=(0, 0, t + 0.01), axis=(0, 0, 1))
    sp.add_marker("gear_g", "gear", axis=(0, 0, 1))
    sp.add(Cylindrical("gear_bearing", "ground_g", "gear_g"))
    sp.add(JointDriver("gear_spin", "gear_bearing", spin, quantity="speed"))
    sp.add(Force("load", "gear_g", vector=(0, 0, -load)))
    sp.add_marker("face", "gear", position=(0, 0, -0.01),
                  axis=(0.0, math.sin(tilt), -math.cos(tilt)))
    fb = add_flexible_body(sp, "washer", part, "carrier_c")
    if quadrature is None:
        where = {"face": solid.select("z", t)}
    else:
        pts, areas = annulus_quadrature(ri, re, t, *quadrature, cells=2)
        where = {"points": pts, "weights": areas}
    sp.add(FlexibleWasherContact(
        "contact", "carrier_c", "face", body=fb.name, **where,
        law=NormalLaw(k_contact, 1.0, law="penalty", damping=2e4),
        friction=FrictionLaw(mu, eps_v=1e-4)))
    return sp, (ri, re, solid, part)


@register_case("washer_pressure")
def washer_pressure(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Rigid spinning face on a flexible washer under 2 kN: integrated pressure vs load and
    friction torque vs mu F r_m (uniform pressure: contact compliance >> washer's), and the
    washer's largest von Mises stress against the full finite-element solution under the
    run's nodal pressures *and* their friction tractions. A run that stops early is a failed
    check, not a reading of its partial results.

    The same bench with the contact at the points of a face quadrature (2 Gauss radii in
    each of the 2 cells across, 12 angles: 48 points against 360 face nodes): its friction
    torque against mu F r_m within 1e-4, where the nodes' sum is 0.25 % low (the 36-gon mesh's
    mid-side nodes sit inside the circle).

    Seen to fail: the washer reduced with the normal pressure patterns only
    (``face_load_patterns(..., friction=False)``: the friction tractions then do not deform
    it) gives a von Mises stress 1.5 % low (tolerance 0.1 %); with the friction patterns the
    difference is 2e-4. The quadrature with one radius per cell misses mu F r_m by 0.6 %
    (with one radius for the width, 2.4 %)."""
    load, mu, spin = 2000.0, 0.1, 10.0
    sp, (ri, re, solid, _) = washer_bench(load, mu, spin, 1e9)
    res = simulate(compile_model(sp), 0.03, step=FixedStep(1e-4), output_dt=1e-3)
    if not res.success:
        return [failed_check("washer_pressure", "integrated face pressure under a 2 kN load",
                             "N", 0.01, "equilibrium", res)]
    ds = res.dataset
    F = float(ds["contact.normal_force"].values[-1])
    M = float(ds["contact.friction_torque"].values[-1])
    rm = 2 * (re**3 - ri**3) / (3 * (re**2 - ri**2))
    # the washer's stresses at the end vs the full finite-element solution under the nodal
    # pressures of the run and their friction (the face spins at +spin about z and drags the
    # washer along e_theta; sliding speeds are 1e4 times eps_v, so the friction is mu p);
    # the static modes make the reduced part exact for them
    face = solid.select("z", 0.002)
    p = ds["contact.contact_pressure"].values[-1]
    a = solid.face_areas(face)
    X = solid.nodes[face]
    r = np.hypot(X[:, 0], X[:, 1])
    f = np.zeros(3 * solid.n)
    f[3 * face + 2] = -p * a
    f[3 * face] = -np.sign(spin) * mu * p * a * X[:, 1] / r
    f[3 * face + 1] = np.sign(spin) * mu * p * a * X[:, 0] / r
    u = solid.static(clamp(solid, solid.select("z", 0.0)), f)
    vm_full = float(von_mises(solid.stress_modes(u[:, None])[:, :, 0]).max())
    vm_run = float(ds["washer.max_von_mises"].values[-1])
    spq, _ = washer_bench(load, mu, spin, 1e9, quadrature=(2, 12))
    rq = simulate(compile_model(spq), 0.03, step=FixedStep(1e-4), output_dt=1e-3)
    if not rq.success:
        return [failed_check("washer_pressure", "friction torque at a face quadrature", "N m",
                             1e-4, "equilibrium", rq)]
    Fq = float(rq.dataset["contact.normal_force"].values[-1])
    Mq = float(rq.dataset["contact.friction_torque"].values[-1])
    return [
        compare("washer_pressure", "friction torque at a face quadrature (48 points), "
                "per unit of mu F r_m", 1.0, abs(Mq) / (mu * Fq * rm), "1", 1e-4,
                "M = mu F r_m; the rule integrates the annulus"),
        compare("washer_pressure", "integrated face pressure under a 2 kN load", load, F, "N",
                1e-3, "equilibrium of the pressed face"),
        compare("washer_pressure", "friction torque, mu = 0.1 (magnitude)", mu * load * rm,
                abs(M), "N m", 0.01, "M = mu F r_m, r_m = 2 (re^3 - ri^3)/(3 (re^2 - ri^2))"),
        compare("washer_pressure", "largest von Mises stress of the washer", vm_full, vm_run,
                "Pa", 1e-3, "full FE model under the run's nodal pressures and friction "
                "tractions (quasi-static)"),
    ]
