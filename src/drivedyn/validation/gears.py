"""Validation of the gear pair element: single pairs (ratio, helical thrust, ISO 6336
stiffness) and the planetary set (Willis equation)."""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from drivedyn.elements import GearPair, Hinge, JointDriver, Torque
from drivedyn.model import GROUND, Spec, compile_model
from drivedyn.solver import FixedStep, GeneralizedAlpha, element_outputs, simulate, solve_static
from drivedyn.timefunctions import SmoothStep
from drivedyn.validation.base import CaseResult, compare, register_case
from drivedyn.validation.common import (
    crossings,
    failed_check,
    finish_case,
)

GEAR_Z = (0.0, 0.0, 1.0)


def gear_pair_model(za: int = 20, zb: int = 40, mn: float = 3e-3, beta: float = 0.0,
                    internal: str | None = None, inertia: tuple[float, float] = (2e-3, 8e-3),
                    **kw: Any) -> tuple[Spec, Any]:
    """Wheel A at the origin, wheel B at the working centre distance along x, both on hinges
    to the ground about global z; ``kw`` goes to :class:`~drivedyn.GearPair`. Returns the
    spec (to be completed) and the :class:`CylindricalPair` geometry."""
    from drivedyn.elements.gears import CylindricalPair

    geo = CylindricalPair.build(za, -zb if internal == "b" else zb, mn, np.radians(20.0), beta)
    a = geo.centre_distance
    spec = Spec()
    spec.add_rigid_body("A", 1.0, (1e-3, 1e-3, inertia[0]))
    spec.add_rigid_body("B", 2.0, (inertia[1],) * 3, position=(a, 0.0, 0.0))
    spec.add_marker("gA", GROUND, axis=GEAR_Z)
    spec.add_marker("mA", "A", axis=GEAR_Z)
    spec.add_marker("gB", GROUND, position=(a, 0.0, 0.0), axis=GEAR_Z)
    spec.add_marker("mB", "B", axis=GEAR_Z)
    spec.add(Hinge("hA", "gA", "mA"))
    spec.add(Hinge("hB", "gB", "mB"))
    spec.add(GearPair("g", "mA", "mB", za, zb, mn, 0.02, helix_angle=beta, internal=internal,
                         **kw))
    return spec, geo


@register_case("gear_pair")
def gear_pair(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Gear pair element: helical force components and deflection (statics), ISO 6336-1
    method B worked example, mesh natural frequency, kinematic ratio over 120 revolutions,
    worm efficiency with tooth friction.

    Catches a wrong tooth normal (helix or pressure angle), mesh stiffness, ratio or
    friction. Fails on (quick, seen): the base helix angle beta_b taken as the reference
    helix angle beta: axial force / (F_t tan beta) and normal force / (F_t / (cos alpha_n
    cos beta)) both 1.0077 (tolerance 1e-9); the other checks pass (the mesh frequency's
    reference uses the element's own coefficients). The tooth friction force with its sign
    reversed: worm efficiency 1.446 against 0.761 (tolerance 1e-5). The second component of
    the sliding velocity (row 2 of W) set to zero is not caught (efficiency error 3e-8)."""
    from drivedyn.elements.gears import CylindricalPair, iso6336_mesh_stiffness, mesh_info

    t0 = time.perf_counter()
    case = "gear_pair"
    out: list[CaseResult] = []
    an = np.radians(20.0)

    # statics: A held, 100 N m on B; exact to the Newton tolerance (1e-8 relative measured
    # 1e-12), tolerance 1e-9
    beta = np.radians(20.0)
    spec, geo = gear_pair_model(beta=beta, helix_angle_b=-beta, stiffness=3e8)
    spec.add(JointDriver("hold", "hA", 0.0, quantity="angle"))
    spec.add(Torque("T", "mB", vector=(0.0, 0.0, 100.0)))
    m = compile_model(spec)
    o = element_outputs(m, solve_static(m))["g"]
    Ft = o["tangential_force"]
    src = "DIN 3990 / ISO 6336 helical mesh forces, 20/40 teeth, m_n 3 mm, beta 20 deg"
    out += [
        compare(case, "tangential force x r_B / torque", 1.0, Ft * abs(geo.r2) / 100.0, "1",
                1e-9, "moment balance of wheel B"),
        compare(case, "axial force / (F_t tan beta)", 1.0, -o["axial_force"] / (Ft * np.tan(beta)),
                "1", 1e-9, src),
        compare(case, "radial force / (F_t tan alpha_n / cos beta)", 1.0,
                o["radial_force"] / (Ft * np.tan(an) / np.cos(beta)), "1", 1e-9, src),
        compare(case, "normal force / (F_t / (cos alpha_n cos beta))", 1.0,
                o["normal_force"] * np.cos(an) * np.cos(beta) / Ft, "1", 1e-9, src),
        compare(case, "static mesh deflection [F_n / k_m]", o["normal_force"] / 3e8,
                o["deflection"], "m", 1e-9, "spring law along the tooth normal"),
    ]

    # ISO 6336-1 method B, z = 20/40, m_n = 3 mm, alpha_n = 20 deg, beta = 0, x = 0, b = 20 mm
    geo0 = CylindricalPair.build(20, 40, 3e-3, an)
    q = 0.04723 + 0.15551 / 20 + 0.25791 / 40
    c_ref = 1.0 / q * 0.8 * 1.0 * 0.975 * (0.75 * geo0.eps_alpha + 0.25)
    iso = iso6336_mesh_stiffness(20, 40, 0.0, an, geo0.eps_alpha, 0.02)
    out.append(compare(case, "ISO 6336 c_gamma_alpha, 20/40, m 3, alpha 20, beta 0 (18.739)",
                       c_ref, iso.c_gamma_alpha_iso, "N/(mm um)", 1e-12,
                       "ISO 6336-1 method B by hand: q' = 0.061453, C_M 0.8, C_B 0.975, "
                       f"eps_alpha {geo0.eps_alpha:.5f}"))
    spec, geo = gear_pair_model(beta=beta, helix_angle_b=-beta)
    out.append(compare(case, "element default stiffness = ISO 6336 k_m (helical)",
                       iso6336_mesh_stiffness(20, 40, beta, an, geo.eps_alpha, 0.02).k_mesh,
                       mesh_info(compile_model(spec), "g")["stiffness"], "N/m", 1e-12,
                       "ISO 6336-1 method B"))

    # natural frequency: free wheels, zero backlash, rho_inf = 1 (trapezoidal rule)
    spec, geo = gear_pair_model(beta=beta, helix_angle_b=-beta, stiffness=1e8)
    body = spec.bodies["A"]
    spec.bodies["A"] = type(body)(**{**body.__dict__, "angular_velocity": np.array([0, 0, 1.0])})
    m = compile_model(spec)
    info = mesh_info(m, "g")
    w = float(np.sqrt(1e8 * (info["coef_a"] ** 2 / 2e-3 + info["coef_b"] ** 2 / 8e-3)))
    n_per = 200
    h = 2 * np.pi / w / n_per
    periods = 20 if quick else 40
    res = simulate(m, periods * 2 * np.pi / w, step=FixedStep(h),
                      integrator=GeneralizedAlpha(1.0), output_dt=h)
    q1 = "mesh natural frequency sqrt(k (c_A^2/J_A + c_B^2/J_B)), 200 steps per period"
    src = "two inertias coupled by the mesh, c = r_b cos(beta_b)"
    if not res.success:
        out.append(failed_check(case, q1, "rad/s", 2e-4, src, res))
    else:
        F = res["g.normal_force"].values
        tc = crossings(res.time, F - F.mean(), 1)
        w_sim = 2 * np.pi * (len(tc) - 1) / (tc[-1] - tc[0])
        # the trapezoidal rule shortens the frequency by (w h)^2 / 12 = 8.2e-5 here
        out.append(compare(case, q1, w, w_sim, "rad/s", 2e-4, src))
        out.append(compare(case, "mesh natural frequency, trapezoidal dispersion removed "
                           "(2/h) atan(w h/2)", 2 / h * np.arctan(0.5 * w * h), w_sim, "rad/s",
                           1e-5, src))

    # kinematic ratio over 120 revolutions, external helical pair, loaded
    za, zb = 17, 43
    spec, geo = gear_pair_model(za, zb, beta=np.radians(15.0), helix_angle_b=-np.radians(15.0),
                                stiffness=2e8, damping_ratio=0.05)
    revs = 30 if quick else 120
    spec.add(JointDriver("drive", "hA", SmoothStep(0.0, 0.05, 0.0, 2 * np.pi * 100),
                            quantity="speed"))
    spec.add(Torque("load", "mB", vector=(0.0, 0.0, -5.0)))
    res = simulate(compile_model(spec), 0.025 + revs / 100.0 + 0.005,
                      step=FixedStep(2e-4), integrator=GeneralizedAlpha(0.9),
                      output_dt=5e-3)
    q2 = f"speed ratio -z_B/z_A x angle B / angle A after {revs} revolutions"
    if not res.success:
        out.append(failed_check(case, q2, "1", 1e-6, "gear kinematics", res))
    else:
        ratio = res["hB.angle"].values[-1] / res["hA.angle"].values[-1]
        # the mesh deflection (5 N m load) changes angle B by u / c_B ~ 1e-7 rad
        out.append(compare(case, q2, 1.0, -ratio * zb / za, "1", 1e-6,
                           "z_A/z_B, 17/43 helical, 100 rev/s"))

    # worm efficiency with tooth friction (mu 0.05, lead angle 10 deg, 2 starts / 40 teeth)
    mu, gam = 0.05, np.radians(10.0)
    bA, bB = np.pi / 2 - gam, gam
    rA, rB = 2 * 3e-3 / (2 * np.cos(bA)), 40 * 3e-3 / (2 * np.cos(bB))
    c, s = np.cos(-(bA + bB)), np.sin(-(bA + bB))
    FB = np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])
    spec = Spec()
    spec.add_rigid_body("worm", 0.5, (1e-4, 1e-4, 1e-4))
    spec.add_rigid_body("wheel", 2.0, (5e-3, 5e-3, 5e-3), position=(rA + rB, 0, 0))
    spec.add_marker("g1", "ground", axis=GEAR_Z)
    spec.add_marker("m1", "worm", axis=GEAR_Z)
    spec.add_marker("g2", "ground", position=(rA + rB, 0, 0), rotation=FB)
    spec.add_marker("m2", "wheel", rotation=FB)
    spec.add(Hinge("h1", "g1", "m1"))
    spec.add(Hinge("h2", "g2", "m2"))
    spec.add(GearPair("w", "m1", "m2", 2, 40, 3e-3, 0.02, helix_angle=bA, helix_angle_b=bB,
                         kind="crossed", stiffness=1e8, damping=500.0, friction=mu))
    spec.add(JointDriver("drive", "h1", SmoothStep(0, 0.02, 0, 100.0), quantity="speed"))
    spec.add(Torque("load", "m2", vector=20.0 * FB[:, 2]))
    res = simulate(compile_model(spec), 0.1, step=FixedStep(2e-5),
                      integrator=GeneralizedAlpha(0.9), output_dt=1e-3)
    q3 = "worm efficiency, mu 0.05, lead angle 10 deg"
    src = "tan(gamma) / tan(gamma + phi'), tan(phi') = mu / cos(alpha_n) (worm driving)"
    phi = np.arctan(mu / np.cos(an))
    if not res.success:
        out.append(failed_check(case, q3, "1", 1e-5, src, res))
    else:
        wB = float(res["wheel.angular_velocity"].values[-1] @ FB[:, 2])
        eta = 20.0 * abs(wB) / float(res["drive.power"].values[-1])
        out.append(compare(case, q3, np.tan(gam) / np.tan(gam + phi), eta, "1", 1e-5, src))
    return finish_case(out, t0, [])


@register_case("planetary_set")
def planetary_set(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Helical planetary set (sun 24, three planets 18, ring 60): Willis equation with sun and
    ring driven, static torque split with carrier and ring held.

    Catches a wrong sign of the internal (ring) mesh. Fails on (quick, seen): the ring
    wheel's mesh coefficient with the external sign: carrier speed -28.33 rad/s against
    5 rad/s (tolerance 1e-7); the planet speed ratio (9.7e-8, as built 1e-12), the torque
    split and the load sharing pass."""
    t0 = time.perf_counter()
    case = "planetary_set"
    zs, zp, zr, mn, beta = 24, 18, 60, 2e-3, np.radians(15.0)

    def build() -> Spec:
        rs, rp = zs * mn / (2 * np.cos(beta)), zp * mn / (2 * np.cos(beta))
        spec = Spec()
        spec.add_rigid_body("sun", 1.0, (1e-3, 1e-3, 1.5e-3))
        spec.add_rigid_body("ring", 3.0, (2e-2, 2e-2, 3e-2))
        spec.add_rigid_body("carrier", 2.0, (5e-3, 5e-3, 8e-3))
        for name in ("sun", "ring", "carrier"):
            spec.add_marker(f"g_{name}", "ground", axis=GEAR_Z)
            spec.add_marker(f"m_{name}", name, axis=GEAR_Z)
            spec.add(Hinge(f"h_{name}", f"g_{name}", f"m_{name}"))
        for k in range(3):
            ang = 2 * np.pi * k / 3
            pos = (rs + rp) * np.array([np.cos(ang), np.sin(ang), 0.0])
            spec.add_rigid_body(f"planet{k}", 0.3, (1e-4, 1e-4, 1.5e-4), position=pos)
            spec.add_marker(f"c{k}", "carrier", position=pos, axis=GEAR_Z)
            spec.add_marker(f"p{k}", f"planet{k}", axis=GEAR_Z)
            spec.add(Hinge(f"hp{k}", f"c{k}", f"p{k}"))
            spec.add(GearPair(f"sp{k}", "m_sun", f"p{k}", zs, zp, mn, 0.015,
                                 helix_angle=beta, damping_ratio=0.05))
            spec.add(GearPair(f"pr{k}", f"p{k}", "m_ring", zp, zr, mn, 0.015,
                                 helix_angle=-beta, internal="b", damping_ratio=0.05))
        return spec

    out: list[CaseResult] = []
    spec = build()
    ws, wr = 30.0, -5.0
    spec.add(JointDriver("d_s", "h_sun", SmoothStep(0, 0.05, 0, ws), quantity="speed"))
    spec.add(JointDriver("d_r", "h_ring", SmoothStep(0, 0.05, 0, wr), quantity="speed"))
    res = simulate(compile_model(spec), 0.15 if quick else 0.3, step=FixedStep(1e-4),
                      integrator=GeneralizedAlpha(0.9), output_dt=1e-3)
    q = "carrier speed, sun 30 rad/s, ring -5 rad/s"
    src = "Willis: w_c = (z_S w_s + z_R w_r) / (z_S + z_R)"
    if not res.success:
        out.append(failed_check(case, q, "rad/s", 1e-7, src, res))
    else:
        wc = float(res["carrier.angular_velocity"].values[-1, 2])
        out.append(compare(case, q, (zs * ws + zr * wr) / (zs + zr), wc, "rad/s", 1e-7, src))
        wp = float(res["planet0.angular_velocity"].values[-1, 2])
        out.append(compare(case, "planet speed relative to the carrier / (w_s - w_c)", -zs / zp,
                           (wp - wc) / (ws - wc), "1", 1e-7, "Willis: -z_S / z_P"))
    spec = build()
    spec.add(JointDriver("hold_c", "h_carrier", 0.0, quantity="angle"))
    spec.add(JointDriver("hold_r", "h_ring", 0.0, quantity="angle"))
    spec.add(Torque("Ts", "m_sun", vector=(0, 0, 30.0)))
    m = compile_model(spec)
    o = element_outputs(m, solve_static(m))
    t_ring = abs(sum(o[f"pr{k}"]["torque_b"] for k in range(3)))
    out.append(compare(case, "static torque split T_ring / T_sun (no friction)", zr / zs,
                       t_ring / 30.0, "1", 1e-9, "moment balance of the planets: z_R / z_S"))
    loads = [o[f"sp{k}"]["normal_force"] for k in range(3)]
    out.append(compare(case, "load sharing: spread of the three sun-planet forces / mean", 0.0,
                       float(np.ptp(loads) / np.mean(loads)), "1", 1e-9, "symmetry"))
    return finish_case(out, t0, [])


# the TORSEN cases live in their own module; importing it registers them
