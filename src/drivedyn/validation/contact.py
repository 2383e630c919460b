"""Validation of the contact family: bouncing ball (seed slides), restitution laws against the
impact ODE, friction, thrust washer, squeeze film."""

from __future__ import annotations

import time

import numpy as np

from drivedyn.elements import (
    Cylindrical,
    Force,
    FrictionLaw,
    JointDriver,
    NormalLaw,
    PlaneContact,
    SqueezeFilm,
    ThrustWasherContact,
    UnilateralContact,
)
from drivedyn.model import GROUND, Spec, compile_model
from drivedyn.solver import FixedStep, GeneralizedAlpha, simulate
from drivedyn.validation.base import CaseResult, compare, register_case
from drivedyn.validation.common import (
    G,
    failed_check,
    finish_case,
    rot_y,
    save_figure,
)


def impact_restitution_ode(chi: float, n: float, K: float, m: float, v0: float,
                           g: float = 0.0) -> float:
    """Restitution (rebound over approach speed at delta = 0) of a mass ``m`` hitting a rigid
    wall at ``v0`` [m/s] with the force ``K delta^n (1 + chi deltadot / v0)`` (never pulling)
    and a constant acceleration ``g`` towards the wall during the contact: scipy DOP853 with
    tolerances 1e-12. With ``g = 0`` it equals the exact relation ``phi(chi) = phi(-e chi)``."""
    from scipy.integrate import solve_ivp

    def f(t, y):
        d, v = y
        F = K * d**n * (1.0 + chi * v / v0) if d > 0.0 else 0.0
        return [v, g - max(F, 0.0) / m]

    def out(t, y):
        return y[0]

    out.terminal = True
    out.direction = -1
    tc = 10.0 * (m * v0**2 / K) ** (1.0 / (n + 1.0)) / v0
    sol = solve_ivp(f, [0.0, 50.0 * tc], [1e-300, v0], events=out, rtol=1e-12, atol=1e-30,
                    method="DOP853", first_step=tc * 1e-6)
    return -float(sol.y_events[0][0][1]) / v0


@register_case("bouncing_ball")
def bouncing_ball(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """The seeds' bouncing ball (seed 000: Lankarani-Nikravesh law, e = 0.8, n = 1.5,
    K = 1e10 N/m^1.5, h0 = 1 m, m = 0.85 kg, g = 10 m/s^2): every bounce against an ODE
    reference that includes gravity during the contact, apexes, energy balance.

    Catches a wrong impact speed v_s of the hysteresis term, a wrong restitution, lost
    contact energy. Fails on (quick, seen): v_s taken as the last rate before the contact
    without its free-flight extrapolation (the -2 a0 p0 term): approach speed of the first
    impact off by 1.8e-6 (tolerance 1e-10); the restitution, apex and energy checks pass
    (the ODE reference is evaluated at that approach speed)."""
    from drivedyn.library.bouncing_ball import plot_height, run_bounce

    t0 = time.perf_counter()
    case = "bouncing_ball"
    run = run_bounce(t_end=1.5 if quick else 3.0)
    src_ode = ("impact ODE m deltaddot = m g - K delta^n (1 + chi deltadot/v_s), scipy "
               "DOP853 1e-12")
    if not run.success or not run.restitution:
        return finish_case([failed_check(case, "bounces", "1", 1e-5, src_ode, run)], t0, [])
    K, n, m, g = 1e10, 1.5, 0.85, 10.0
    out = [compare(case, "approach speed of the first impact", np.sqrt(2 * g * 1.0),
                   run.impact_speeds[0], "m/s", 1e-10, "free fall from h0: sqrt(2 g h0)")]
    # tolerance: the time integration at contact onset and separation (force kinks) is
    # measured at ~1e-6 with the benchmark's step control (rtol 1e-6, atol 1e-12)
    for i, (v, e) in enumerate(zip(run.impact_speeds, run.restitution, strict=True)):
        out.append(compare(case, f"restitution of bounce {i + 1} (approach {v:.4f} m/s)",
                           impact_restitution_ode(run.chi, n, K, m, v, g), e, "1", 1e-5,
                           src_ode))
    out.append(compare(case, "restitution predicted by the exact relation (no gravity)",
                       run.e_predicted, run.restitution[0], "1", 3e-4,
                       "chi - ln(1 + chi) = -e chi - ln(1 - e chi); gravity during the "
                       "contact lowers e by ~1e-4"))
    for i, h in enumerate(run.apex_heights):
        out.append(compare(case, f"apex height after bounce {i + 1}",
                           run.rebound_speeds[i] ** 2 / (2 * g), h, "m", 1e-5,
                           "free flight: v_rebound^2 / (2 g)"))
    res = run.results
    lost = (res["energy.kinetic"].values[0] + res["energy.potential"].values[0]
            - res["energy.kinetic"].values[-1] - res["energy.potential"].values[-1])
    out.append(compare(case, "energy lost (kinetic + potential) vs dissipated by the contact",
                       run.dissipated, lost, "J", 1e-3, "energy balance"))

    def draw(fig):
        plot_height(run, fig)

    out[0].source += f"; {run.steps} steps, {run.wall_s:.2f} s"
    return finish_case(out, t0, save_figure(figure_dir, "bouncing_ball", draw))


@register_case("restitution_laws")
def restitution_laws(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Achieved restitution of every continuous-impact law for e = 0.2, 0.5, 0.8, 0.95:
    simulated collision without gravity vs the exact relation at the law's chi.

    Catches a wrong hysteresis damping term K delta^n chi deltadot / v_s. Fails on (quick,
    seen): chi 2 % too large in the contact force: every law and target off by 3.1e-3 to
    1.1e-2 (tolerance 2e-5)."""
    from drivedyn.elements.contact.impact_laws import IMPACT_LAWS, restitution_from_chi
    from drivedyn.library.bouncing_ball import restitution_table

    t0 = time.perf_counter()
    case = "restitution_laws"
    targets = (0.5, 0.8) if quick else (0.2, 0.5, 0.8, 0.95)
    rows = restitution_table(targets=targets)
    src = "exact relation chi - ln(1 + chi) = -e chi - ln(1 - e chi) at the law's chi"
    # the collision runs resolve each impact with ~250 steps: 2e-6 measured, tolerance 2e-5
    out = [compare(case, f"{r['law']}, e = {r['e_target']:g} (chi = {r['chi']:.4g})",
                   r["e_predicted"], r["e_simulated"], "1", 2e-5, src) for r in rows]

    def draw(fig):
        ax = fig.subplots()
        es = np.linspace(0.05, 0.99, 200)
        from drivedyn.elements.contact.impact_laws import damping_factor

        for law in IMPACT_LAWS:
            ax.plot(es, [restitution_from_chi(damping_factor(law, e)) for e in es], lw=1,
                    label=f"{law} (exact relation)")
            pts = [(r["e_target"], r["e_simulated"]) for r in rows if r["law"] == law]
            ax.plot(*zip(*pts, strict=True), "ko", ms=3)
        ax.plot([0, 1], [0, 1], "k:", lw=0.8)
        ax.set_xlabel("restitution given to the law")
        ax.set_ylabel("restitution achieved")
        ax.legend(fontsize=7)
        fig.suptitle("continuous-impact laws: achieved restitution (dots: simulated)")
    return finish_case(out, t0, save_figure(figure_dir, "restitution_laws", draw))


@register_case("contact_friction")
def contact_friction(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """A block on an incline (contact point at the centre of mass): regularised Coulomb
    friction (creep speed below tan(theta) = mu, Coulomb acceleration above) and the
    augmented-Lagrangian stick/slip contact (true sticking, Coulomb acceleration).

    Catches a wrong regularised friction law or friction force. Fails on (quick, seen): the
    coulomb law's branch below eps_v linear, mu_R = mu v / eps_v, instead of
    mu (2 - v/eps_v) v/eps_v: creep speed 6.0e-4 m/s against 3.68e-4 m/s (0.63, tolerance
    1e-5); the sliding and augmented-Lagrangian checks pass (they do not use that branch).
    The augmented-Lagrangian stick test |sigma_t| <= 0.5 mu N instead of mu N: largest
    displacement on tan(theta) = 0.3 2.8e-4 m (tolerance 1e-9 m)."""
    t0 = time.perf_counter()
    case = "contact_friction"
    m, mu, K = 2.0, 0.5, 1e6
    src_a = "sliding block: a = g (sin(theta) - mu cos(theta))"

    def block(theta, friction=None, mu_al=None):
        R = rot_y(theta)
        spec = Spec(gravity=(0.0, 0.0, -G))
        spec.add_marker("slope", GROUND, rotation=R)
        pen = 0.0 if mu_al is not None else m * G * np.cos(theta) / K
        spec.add_rigid_body("block", m, (0.01, 0.01, 0.01), position=-pen * R[:, 2])
        spec.add_marker("foot", "block")
        if mu_al is not None:
            spec.add(UnilateralContact("contact", "slope", "foot", mu=mu_al))
        else:
            law = NormalLaw(K, 1.0, law="penalty", damping=2.0 * np.sqrt(K * m))
            spec.add(PlaneContact("contact", "slope", "foot", law=law, friction=friction))
        res = simulate(compile_model(spec), 0.6, integrator=GeneralizedAlpha(0.9),
                          step=FixedStep(1e-3), output_dt=1e-3)
        t_axis = R[:, 0]
        return res, res["block.position"].values @ t_axis, res["block.velocity"].values @ t_axis

    out: list[CaseResult] = []
    hist = []
    eps = 1e-3
    for label, kw in (("regularised Coulomb", {"friction": FrictionLaw(mu, eps_v=eps)}),
                      ("augmented Lagrangian", {"mu_al": mu})):
        th_slide = np.arctan(0.7)
        res, s, v = block(th_slide, **kw)
        q = f"{label}: acceleration on a slope tan(theta) = 0.7 > mu = {mu}"
        if not res.success:
            out.append(failed_check(case, q, "m/s^2", 1e-6, src_a, res))
            continue
        sel = res.time > 0.1
        a = float(np.polyfit(res.time[sel], v[sel], 1)[0])
        out.append(compare(case, q, G * (np.sin(th_slide) - mu * np.cos(th_slide)), a,
                           "m/s^2", 1e-6, src_a))
        th_stick = np.arctan(0.3)
        res, s, v = block(th_stick, **kw)
        late = res.time > 0.3
        if label == "augmented Lagrangian":
            out.append(compare(case, f"{label}: largest displacement on tan(theta) = 0.3 < mu",
                               0.0, float(np.max(np.abs(s - s[0]))), "m", 1e-9,
                               "sticking: no motion (Newton tolerance)"))
        else:
            v_c = eps * (1 - np.sqrt(1 - 0.3 / mu))
            out.append(compare(case, f"{label}: creep speed on tan(theta) = 0.3 < mu",
                               v_c, float(np.mean(v[late])), "m/s", 1e-5,
                               "mu_R(v_c) = tan(theta): v_c = eps_v (1 - sqrt(1 - tan/mu))"))
        hist.append((label, res.time, s - s[0]))

    def draw(fig):
        ax = fig.subplots()
        for label, t, s in hist:
            ax.semilogy(t[1:], np.abs(s[1:]) + 1e-12, label=f"{label}, tan(theta) = 0.3")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("|displacement along the slope| + 1e-12 [m]")
        ax.legend(fontsize=8)
        fig.suptitle("block held by friction: regularised creep vs augmented-Lagrangian stick")
    return finish_case(out, t0, save_figure(figure_dir, "contact_friction", draw) if hist else [])


@register_case("thrust_washer")
def thrust_washer(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """A gear driven at constant speed and pressed on a thrust washer: driver torque vs the
    friction torque of the seeds M = 2 pi mu_R (F/S)(r_ext^3 - r_int^3)/3.

    Catches a wrong friction radius or friction speed. Fails on (quick, seen): the friction
    radius (r_int + r_ext)/2 instead of 2 (r_ext^3 - r_int^3) / (3 (r_ext^2 - r_int^2)):
    driver torque off by 3.6e-2 and 6.4e-2 (tolerance 1e-6)."""
    t0 = time.perf_counter()
    case = "thrust_washer"
    ri, re, K, mg = 0.02, 0.04, 1e9, 0.5
    out: list[CaseResult] = []
    src = "M = 2 pi mu_R (F/S) (r_ext^3 - r_int^3) / 3 (seeds), mu_R at v = r_m omega"
    for F, omega, mu, eps in ((200.0, 10.0, 0.12, 1e-3), (100.0, 0.5, 0.1, 0.05)):
        spec = Spec()
        spec.add_marker("axis", GROUND)
        spec.add_marker("washer", GROUND)
        spec.add_rigid_body("gear", mg, (2e-4, 2e-4, 4e-4), position=(0, 0, -F / K),
                            angular_velocity=(0, 0, omega))
        spec.add_marker("face", "gear")
        spec.add(Cylindrical("guide", "axis", "face"))
        spec.add(JointDriver("motor", "guide", omega, quantity="speed"))
        spec.add(Force("thrust", "face", vector=(0, 0, -F)))
        law = NormalLaw(K, 1.0, law="penalty", damping=2.0 * np.sqrt(K * mg))
        friction = FrictionLaw(mu, eps_v=eps)
        spec.add(ThrustWasherContact("contact", "washer", "face", law=law, r_int=ri,
                                        r_ext=re, friction=friction))
        res = simulate(compile_model(spec), 0.2, integrator=GeneralizedAlpha(0.8),
                          step=FixedStep(1e-4), output_dt=1e-3)
        q = f"driver torque, F = {F:g} N, omega = {omega:g} rad/s, mu = {mu:g}"
        if not res.success:
            out.append(failed_check(case, q, "N m", 1e-6, src, res))
            continue
        rm = 2 * (re**3 - ri**3) / (3 * (re**2 - ri**2))
        mu_r = float(friction.coefficient(rm * omega))
        M = 2 * np.pi * mu_r * (F / (np.pi * (re**2 - ri**2))) * (re**3 - ri**3) / 3
        out.append(compare(case, q + f" (mu_R = {mu_r:.4g})", M,
                           float(np.mean(res["motor.torque"].values[res.time > 0.1])),
                           "N m", 1e-6, src))
    return finish_case(out, t0, [])


@register_case("squeeze_film")
def squeeze_film(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Two annular faces squeezing the oil film under a constant load: film thickness vs the
    closed form 1/h^2 = 1/h0^2 + 4 F t / (3 pi mu C).

    Catches a wrong film force coefficient or lost film dissipation. Fails on (quick, seen):
    the element's bracket C without its logarithmic term, r_ext^4 - r_int^4 (the disk
    formula): film thickness at 0.25 s 2.69e-5 m against 8.81e-6 m, largest relative error
    7.7 (tolerance 2e-5), load work against film dissipation off by 210 (tolerance 1e-4)."""
    from drivedyn.elements.contact.squeeze_film import annulus_factor

    t0 = time.perf_counter()
    case = "squeeze_film"
    F, h0, mu, ri, ro = 100.0, 20e-6, 0.01, 0.015, 0.03
    C = annulus_factor(ri, ro)
    spec = Spec()
    spec.add_marker("housing_face", GROUND)
    spec.add_rigid_body("plate", 0.01, (1e-6, 1e-6, 2e-6), position=(0, 0, h0),
                        velocity=(0, 0, -F * h0**3 / (1.5 * np.pi * mu * C)))
    spec.add_marker("plate_face", "plate")
    spec.add(SqueezeFilm("film", "housing_face", "plate_face", viscosity=mu, r_int=ri,
                            r_ext=ro, roughness=1e-7))
    spec.add(Force("load", "plate_face", vector=(0, 0, -F)))
    t_end = 0.25 if quick else 0.5
    res = simulate(compile_model(spec), t_end, integrator=GeneralizedAlpha(0.8),
                      step=FixedStep(1e-3), output_dt=1e-2)
    src = "Reynolds squeeze film of an annulus: 1/h^2 = 1/h0^2 + 4 F t / (3 pi mu C)"
    q = f"film thickness at t = {t_end:g} s"
    if not res.success:
        return finish_case([failed_check(case, q, "m", 2e-5, src, res)], t0, [])
    t = res.time
    h = res["film.film_thickness"].values
    h_ref = 1.0 / np.sqrt(1 / h0**2 + 4 * F * t / (3 * np.pi * mu * C))
    # second-order integration of a smooth motion with h = 1 ms: ~1e-6 relative measured
    out = [compare(case, q, h_ref[-1], h[-1], "m", 2e-5, src),
           compare(case, "largest relative error of h(t) over the run", 0.0,
                   float(np.max(np.abs(h / h_ref - 1))), "1", 2e-5, src),
           compare(case, "work of the load vs energy dissipated by the film",
                   float(res["energy.work_in"].values[-1]),
                   float(res["film.dissipated_energy"].values[-1]), "J", 1e-4,
                   "energy balance")]

    def draw(fig):
        ax = fig.subplots()
        ax.plot(t, h * 1e6, label="drivedyn")
        ax.plot(t, h_ref * 1e6, "k--", lw=0.8, label="closed form")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("film thickness [um]")
        ax.legend()
        fig.suptitle(f"squeeze film, annulus {ri * 1e3:g}-{ro * 1e3:g} mm, F = {F:g} N")
    return finish_case(out, t0, save_figure(figure_dir, "squeeze_film", draw))


# ---------------------------------------------------------------------------------------------
# gear pairs (element drivedyn.elements.gears.GearPair)
# ---------------------------------------------------------------------------------------------
