"""Engine validation cases of rigid bodies and joints (registered with
:func:`drivedyn.validation.base.register_case`): torque-free body, heavy top, pendulum,
slider-crank, screw. The integrator's own cases (order of convergence, energy account) are
in :mod:`drivedyn.validation.integrator`.

Every case builds small mechanisms, simulates them and compares what comes out with an exact
(closed-form or quadrature) reference, reporting one :class:`CaseResult` per checked quantity.
``quick=True`` runs a shorter / coarser variant (used by the test suite); tolerances are
derived from the step size actually used, so both variants are checked honestly.

The exact references are plain functions of :mod:`drivedyn.validation.exact`
(``euler_free_body_exact``, ``top_nutation_reference``, ``pendulum_angle_exact``, ...) so that
the tests can check them independently of the simulator; the mechanisms are in
:mod:`drivedyn.validation.rigid_models`.

Notes on integrator settings:

* ``rho_inf = 1`` (no numerical damping, the trapezoidal rule) is used where energy
  conservation itself is checked. With index-3 constraints that carry large reactions (heavy
  top, large-amplitude pendulum) the undamped scheme shows the classical growing ``(-1)^n``
  oscillation of the multipliers after a few seconds, so the long constrained runs use
  ``rho_inf = 0.9`` (still second order, negligible damping of the physical motion).
"""

from __future__ import annotations

import time

import numpy as np

from drivedyn.solver import (
    FixedStep,
    GeneralizedAlpha,
    element_outputs,
    simulate,
    solve_static,
)
from drivedyn.validation.base import CaseResult, compare, register_case
from drivedyn.validation.common import (
    G,
    crossings,
    failed_check,
    finish_case,
    peak,
    save_figure,
)
from drivedyn.validation.exact import (
    euler_free_body_exact,
    pendulum_angle_exact,
    pendulum_period_exact,
    slider_crank_position,
    slider_crank_statics,
    top_nutation_reference,
    top_steady_precession_rate,
)
from drivedyn.validation.rigid_models import (
    PEND_D,
    PEND_IO,
    PEND_M,
    SC_L,
    SC_R,
    SCREW_M,
    SCREW_PITCH,
    TF_J,
    TF_W0,
    TOP_I1,
    TOP_I3,
    TOP_L,
    TOP_M,
    _pendulum_angle,
    _top_angles,
    pendulum_model,
    screw_model,
    slider_crank_model,
    top_model,
    torque_free_model,
)


@register_case("torque_free_body")
def torque_free_body(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Torque-free asymmetric body (J = 1, 2, 3 kg m^2), rho_inf = 1: angular momentum and
    kinetic energy are invariants; the body angular velocity follows Euler-Poinsot.

    Catches a wrong or missing gyroscopic term Omega x J Omega. Fails on (quick, seen): the
    bodies' residual without Omega x J Omega: |H - H0| / |H0| 0.32 and the angular velocity
    error 1.9 of |Omega0| in both runs (tolerances 1.1e-4 and 1.2e-3); T passes (0)."""
    t0 = time.perf_counter()
    case = "torque_free_body"
    h = 1e-2 if quick else 5e-3
    t_end = 10.0 if quick else 20.0
    wn = float(np.linalg.norm(TF_W0))
    # generalized-alpha (rho_inf = 1) on the Lie group conserves neither |H| nor T exactly;
    # their errors are bounded and O((|w| h)^2) (second order, no secular drift), so
    # (|w| h)^2 (1.1e-4 quick, 2.8e-5 full) is the scale of the method's own error.
    tol_inv = (wn * h) ** 2
    # the phase error of the motion grows linearly in time: (|w| h)^2 |w| t_end
    tol_w = (wn * h) ** 2 * wn * t_end
    out: list[CaseResult] = []
    figs: list[str] = []
    for pinned in (False, True):
        label = "pinned at the centre of mass, gravity" if pinned else "free body"
        src = "exact invariants of the torque-free motion"
        model = torque_free_model(pinned)
        res = simulate(model, t_end, step=FixedStep(h),
                          integrator=GeneralizedAlpha(rho_inf=1.0), output_dt=10 * h)
        q_h = f"max |H - H0| / |H0|, {label}"
        q_t = f"max |T - T0| / T0, {label}"
        q_w = f"max |Omega - Omega_exact| / |Omega0|, {label}"
        src_w = "Euler-Poinsot solution with Jacobi elliptic functions (Landau-Lifshitz 37)"
        if not res.success:
            out += [failed_check(case, q, "1", tol, s, res)
                    for q, tol, s in ((q_h, tol_inv, src), (q_t, tol_inv, src),
                                      (q_w, tol_w, src_w))]
            continue
        t = res.time
        H = res["body.angular_momentum"].values
        H0 = TF_J * TF_W0
        dH = float(np.max(np.linalg.norm(H - H0, axis=1)) / np.linalg.norm(H0))
        T = res["energy.kinetic"].values
        T0 = 0.5 * float(np.sum(TF_J * TF_W0 ** 2))
        dT = float(np.max(np.abs(T - T0)) / T0)
        R = res["body.rotation"].values
        Om = np.einsum("tji,tj->ti", R, res["body.angular_velocity"].values)
        Om_ex = euler_free_body_exact(TF_J, TF_W0, t)
        dW = float(np.max(np.linalg.norm(Om - Om_ex, axis=1)) / wn)
        out += [compare(case, q_h, 0.0, dH, "1", tol_inv, src),
                compare(case, q_t, 0.0, dT, "1", tol_inv, src),
                compare(case, q_w, 0.0, dW, "1", tol_w, src_w)]
        if pinned:
            def draw(fig, t=t, Om=Om, Om_ex=Om_ex, H=H, H0=H0):
                ax1, ax2 = fig.subplots(2, 1, sharex=True)
                for i, c in enumerate("xyz"):
                    ax1.plot(t, Om[:, i], label=f"Omega_{c} simulated")
                    ax1.plot(t, Om_ex[:, i], "k--", lw=0.8)
                ax1.set_ylabel("body angular velocity [rad/s]")
                ax1.legend(fontsize=7, title="dashed: exact", title_fontsize=7)
                ax2.plot(t, np.linalg.norm(H - H0, axis=1) / np.linalg.norm(H0))
                ax2.set_ylabel("|H - H0| / |H0|")
                ax2.set_xlabel("time [s]")
                fig.suptitle("torque-free body (pinned at its centre of mass)")
            figs += save_figure(figure_dir, "torque_free_body", draw)
    return finish_case(out, t0, figs)


@register_case("heavy_top")
def heavy_top(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Heavy symmetric top on a spherical joint: (a) steady precession, (b) nutation from
    rest in precession (Goldstein's cusp motion).

    Catches a wrong inertia about the fixed point, gravity lever or precession start.
    Fails on (quick, seen): the initial precession rate 1 % high: steady nutation amplitude
    4.4e-3 rad (tolerance 6.3e-4 rad, as built 1.5e-4 rad; 0.1 % high passes, 5.7e-4 rad);
    the parallel-axis term m l^2 left out of the references' I1 (about the fixed point):
    precession rate off by 0.18, maximum nutation angle by 0.45, nutation period not
    measurable."""
    t0 = time.perf_counter()
    case = "heavy_top"
    rho = 0.9  # see the module docstring (rho_inf = 1 is unstable for this constrained top)
    h = 1e-3 if quick else 5e-4
    theta0 = np.radians(30.0)
    w3 = 40.0  # spin [rad/s]
    out: list[CaseResult] = []
    figs: list[str] = []

    # (a) steady precession
    Om = top_steady_precession_rate(TOP_I1, TOP_I3, TOP_M, G, TOP_L, theta0, w3)
    t_end = 1.0 if quick else 2.0  # about one / two precession periods (2 pi / 6.26 s)
    res = simulate(top_model(theta0, w3, Om), t_end, step=FixedStep(h),
                      integrator=GeneralizedAlpha(rho), output_dt=h)
    src = "steady precession m g l = Omega (I3 w3 - I1 Omega cos theta) (Goldstein 5.7)"
    # The fastest motion is the nutation, frequency a = I3 w3 / I1 = 25 rad/s. For a
    # second-order scheme every error below is C (a h)^2 (relative for rates, periods and
    # angles, in rad for the spurious nutation amplitude): (a h)^2 = 6.3e-4 (quick),
    # 1.6e-4 (full). Halving h divides each error by 4.0 (checked for h = 2, 1, 0.5 and
    # 0.25 ms), with C = 0.1 ... 0.7, so the tolerance is C = 1: (a h)^2.
    a_nut = TOP_I3 * w3 / TOP_I1
    tol_rate = (a_nut * h) ** 2
    # spurious nutation in steady precession, from the start-up of the scheme (O(h^2));
    # a 0.1 % error of the initial precession rate would already give 2 dOmega sin(theta) / a
    # = 2.5e-4 rad, a 1 % error 2.5e-3 rad.
    tol_amp = (a_nut * h) ** 2
    if res.success:
        theta, phi, _ = _top_angles(res)
        t = res.time
        rate = float(np.polyfit(t, phi, 1)[0])
        amp = float(theta.max() - theta.min())
        out += [compare(case, "steady precession: mean precession rate", Om, rate, "rad/s",
                        tol_rate, src),
                compare(case, "steady precession: nutation amplitude max-min theta", 0.0, amp,
                        "rad", tol_amp, src)]

        def draw_a(fig, t=t, theta=theta, phi=phi):
            ax1, ax2 = fig.subplots(2, 1, sharex=True)
            ax1.plot(t, np.degrees(theta - theta0))
            ax1.set_ylabel("theta - theta0 [deg]")
            ax2.plot(t, phi - Om * t)
            ax2.set_ylabel("phi - Omega t [rad]")
            ax2.set_xlabel("time [s]")
            fig.suptitle(f"heavy top, steady precession (Omega = {Om:.5f} rad/s)")
        figs += save_figure(figure_dir, "heavy_top_steady", draw_a)
    else:
        out += [failed_check(case, "steady precession: mean precession rate", "rad/s", tol_rate,
                        src, res),
                failed_check(case, "steady precession: nutation amplitude max-min theta", "rad",
                        tol_amp, src, res)]

    # (b) nutation, released with zero precession rate
    ref = top_nutation_reference(TOP_I1, TOP_I3, TOP_M, G, TOP_L, theta0, w3, 0.0)
    n_per = 4 if quick else 8
    t_end = (n_per + 0.5) * ref["T_nut"]
    res = simulate(top_model(theta0, w3, 0.0), t_end, step=FixedStep(h),
                      integrator=GeneralizedAlpha(rho), output_dt=h)
    src = "quadrature of Goldstein's u = cos(theta) cubic (Goldstein 5.7)"
    tol = (a_nut * h) ** 2  # see above (relative errors)
    names = ("nutation period", "precession angle per nutation period",
             "minimum nutation angle", "maximum nutation angle")
    units = ("s", "rad", "rad", "rad")
    tols = (tol, tol, tol, tol)
    if res.success:
        theta, phi, udot = _top_angles(res)
        t = res.time
        # cusps (u maximum, theta minimum): udot crosses zero downwards
        tc = crossings(t, udot, direction=-1)
        tc = tc[tc > 0.5 * ref["T_nut"]]  # skip the release instant
        T_sim = float((tc[-1] - tc[0]) / (len(tc) - 1))
        phic = np.interp(tc, t, phi)
        dphi_sim = float((phic[-1] - phic[0]) / (len(tc) - 1))
        th_min = float(-peak(t, -theta))
        th_max = float(peak(t, theta))
        sims = (T_sim, dphi_sim, th_min, th_max)
        refs = (ref["T_nut"], ref["dphi"], ref["theta_min"], ref["theta_max"])
        out += [compare(case, f"nutation: {q}", rv, sv, u, tol, src)
                for q, u, tol, rv, sv in zip(names, units, tols, refs, sims, strict=True)]

        def draw_b(fig, t=t, theta=theta, phi=phi):
            ax1, ax2 = fig.subplots(2, 1, sharex=True)
            ax1.plot(t, np.degrees(theta), label="simulated")
            for v in (ref["theta_min"], ref["theta_max"]):
                ax1.axhline(np.degrees(v), color="k", ls="--", lw=0.8)
            ax1.set_ylabel("nutation theta [deg]")
            ax1.legend(fontsize=8, title="dashed: exact turning angles", title_fontsize=8)
            ax2.plot(t, phi)
            ax2.set_ylabel("precession phi [rad]")
            ax2.set_xlabel("time [s]")
            fig.suptitle("heavy top released with zero precession rate")
        figs += save_figure(figure_dir, "heavy_top_nutation", draw_b)
    else:
        out += [failed_check(case, f"nutation: {q}", u, tol, src, res)
                for q, u, tol in zip(names, units, tols, strict=True)]
    return finish_case(out, t0, figs)


@register_case("pendulum")
def pendulum(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Physical pendulum on a hinge: small- and large-amplitude periods.

    Catches a wrong period (integrator phase error, inertia about the pivot, the elliptic
    integral's argument). Fails on (quick, seen): the exact period with K(k) instead of
    K(k^2) (scipy's ``ellipk`` takes m = k^2): 120 deg off by 0.117, 2 deg by 4.3e-3
    (tolerance 3.9e-5); the 2 deg check against linear theory still passes."""
    t0 = time.perf_counter()
    case = "pendulum"
    h = 2e-3 if quick else 1e-3
    rho = 0.9
    w0 = np.sqrt(PEND_M * G * PEND_D / PEND_IO)
    T_lin = 2.0 * np.pi / w0
    # relative period error of generalized alpha: O((w0 h)^2); (w0 h)^2 = 3.9e-5 (quick),
    # 9.7e-6 (full); measured: 0.1 (2 deg) and 0.35 (120 deg) of it. For 120 deg the motion
    # is slower near the turning points but its highest frequency content is still ~w0.
    tol_num = (w0 * h) ** 2
    out: list[CaseResult] = []
    histories = []
    for deg in (2.0, 120.0):
        th0 = np.radians(deg)
        T_ex = pendulum_period_exact(PEND_IO, PEND_M, G, PEND_D, th0)
        n_half = 4 if quick else 6  # half periods measured
        t_end = (0.5 * n_half + 0.5) * T_ex
        res = simulate(pendulum_model(th0), t_end, step=FixedStep(h),
                          integrator=GeneralizedAlpha(rho), output_dt=h)
        checks = []
        if deg < 10.0:
            # linear theory: the exact period exceeds 2 pi sqrt(I/mgd) by theta0^2 / 16
            # (7.6e-5 at 2 deg) -- the tolerance is that bound plus the numerical error.
            checks.append((f"period, {deg:g} deg vs linear theory 2 pi sqrt(I_o/(m g d))",
                           T_lin, th0 ** 2 / 16 * 1.01 + tol_num,
                           "small-amplitude pendulum 2 pi sqrt(I_o/(m g d))"))
        checks.append((f"period, {deg:g} deg vs exact 4 sqrt(I_o/(m g d)) K(k^2)", T_ex,
                       tol_num, "complete elliptic integral, k = sin(theta0/2)"))
        if not res.success:
            out += [failed_check(case, q, "s", tol, s, res) for q, _, tol, s in checks]
            continue
        th = _pendulum_angle(res)
        tc = crossings(res.time, th)
        T_sim = float(2.0 * (tc[-1] - tc[0]) / (len(tc) - 1))
        out += [compare(case, q, ref, T_sim, "s", tol, s) for q, ref, tol, s in checks]
        histories.append((deg, res.time, th))

    def draw(fig):
        axs = fig.subplots(len(histories), 1, squeeze=False)[:, 0]
        for ax, (deg, t, th) in zip(axs, histories, strict=True):
            ax.plot(t, np.degrees(th), label="simulated")
            ax.plot(t, np.degrees(pendulum_angle_exact(PEND_IO, PEND_M, G, PEND_D,
                                                       np.radians(deg), t)),
                    "k--", lw=0.8, label="exact")
            ax.set_ylabel(f"theta [deg] ({deg:g} deg)")
            ax.legend(fontsize=8)
        axs[-1].set_xlabel("time [s]")
        fig.suptitle("physical pendulum")
    figs = save_figure(figure_dir, "pendulum", draw) if histories else []
    return finish_case(out, t0, figs)


@register_case("slider_crank")
def slider_crank(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Slider-crank: kinematics at constant crank speed and static reactions.

    Catches a wrong reaction (driver torque, guide normal force) or a piston off its
    constraint path. Fails on (quick, seen): the reference torque without the 1 / cos(phi)
    factor: driver torque off by 1.4e-2, 4.5e-2, 5.3e-2 at 30, 120, 250 deg (tolerance
    1e-7); the compared piston position with its square root expanded to second order,
    r cos(theta) + l - r^2 sin^2(theta) / (2 l): 4.9e-4 m (tolerance 1e-9 m). A constraint
    tolerance of 1e-6 instead of 1e-10 is not caught: Newton still lands the piston within
    1.3e-15 m."""
    t0 = time.perf_counter()
    case = "slider_crank"
    out: list[CaseResult] = []
    figs: list[str] = []
    # (a) kinematics over one revolution at 1 rev/s
    h = 2e-3 if quick else 5e-4
    w = 2.0 * np.pi
    res = simulate(slider_crank_model(0.0, ("speed", w)), 1.0, step=FixedStep(h),
                      integrator=GeneralizedAlpha(0.9), output_dt=h)
    q = "piston position over a revolution: max |x - x(theta)|"
    src = "x = r cos(theta) + sqrt(l^2 - r^2 sin^2 theta)"
    # the position is fixed by the constraints alone (crank angle prescribed); Newton stops
    # at constraint violations below phi_tol = 1e-10 [m or rad] per row, so a few 1e-10 m
    # of position error are allowed: 1e-9 m (1e-8 of the crank radius).
    tol = 1e-9
    if res.success:
        t = res.time
        x = res["slider.position"].values[:, 0]
        th = res["crank_drive.angle"].values
        err_x = float(np.max(np.abs(x - slider_crank_position(SC_R, SC_L, w * t))))
        err_th = float(np.max(np.abs(th - w * t)))
        out += [compare(case, q, 0.0, err_x, "m", tol, src),
                compare(case, "crank angle vs prescribed w t: max error", 0.0, err_th, "rad",
                        1e-9, "speed driver, theta = w t")]

        def draw(fig, t=t, x=x):
            ax1, ax2 = fig.subplots(2, 1, sharex=True)
            ax1.plot(np.degrees(w * t), x, label="simulated")
            ax1.plot(np.degrees(w * t), slider_crank_position(SC_R, SC_L, w * t), "k--",
                     lw=0.8, label="exact")
            ax1.set_ylabel("piston x [m]")
            ax1.legend(fontsize=8)
            ax2.plot(np.degrees(w * t), x - slider_crank_position(SC_R, SC_L, w * t))
            ax2.set_ylabel("error [m]")
            ax2.set_xlabel("crank angle [deg]")
            fig.suptitle("slider-crank kinematics, r = 0.1 m, l = 0.3 m")
        figs += save_figure(figure_dir, "slider_crank", draw)
    else:
        out += [failed_check(case, q, "m", tol, src, res)]

    # (b) statics: the crank held at several angles by an angle driver, piston force P
    P = 100.0
    angles = (30.0, 120.0, 250.0) if quick else (20.0, 60.0, 100.0, 150.0, 200.0, 250.0,
                                                  300.0, 340.0)
    src = "virtual work: T = P r sin(theta + phi) / cos(phi), N = P tan(phi)"
    # statics is exact up to the Newton tolerances (residual 1e-8 relative, constraints
    # 1e-10): 1e-7 relative on the torque (and absolute 1e-7 N on the normal force, which
    # vanishes at dead centres).
    for deg in angles:
        thr = np.radians(deg)
        T_ref, N_ref = slider_crank_statics(SC_R, SC_L, P, thr)
        model = slider_crank_model(thr, ("angle", 0.0), piston_force=P)
        outputs = element_outputs(model, solve_static(model))
        T_drv = outputs["crank_drive"]["torque"]
        N_sim = outputs["guide_joint"]["force_y"]
        # the driver holds the crank: its torque on the crank balances the gas torque
        out.append(compare(case, f"statics {deg:g} deg: driver torque (= -T)", -T_ref, T_drv,
                           "N m", 1e-7, src))
        out.append(compare(case, f"statics {deg:g} deg: guide normal force on the slider (y)",
                           N_ref, N_sim, "N", 1e-7, src))
    return finish_case(out, t0, figs)


@register_case("screw")
def screw(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Nut on a screw joint turned by a speed driver through several revolutions.

    Catches a wrong thread sign or lead and a wrong driver torque. Fails on (quick, seen):
    the screw row with -pitch / (2 pi) (a left-hand thread): travel -0.03 m against 0.03 m,
    largest error 0.06 m (tolerance 1e-9 m), driver torque -0.0312 N m against 0.0312 N m;
    the accumulated angle passes."""
    t0 = time.perf_counter()
    case = "screw"
    h = 2e-3 if quick else 5e-4
    revs = 3 if quick else 10
    speed = 2.0 * np.pi * 2.0  # 2 rev/s
    t_end = revs / 2.0
    res = simulate(screw_model(speed), t_end, step=FixedStep(h),
                      integrator=GeneralizedAlpha(0.9), output_dt=5 * h)
    src = "screw kinematics z = pitch theta / (2 pi)"
    q1 = f"axial travel vs pitch x angle / 2 pi over {revs} revolutions: max error"
    q2 = f"axial travel after {revs} revolutions"
    q3 = "driver torque lifting the nut: m g pitch / (2 pi)"
    # position fixed by the constraints only: constraint tolerance 1e-10 m, allow 1e-9 m
    tol = 1e-9
    if not res.success:
        return finish_case([failed_check(case, q1, "m", tol, src, res)], t0, [])
    t = res.time
    z = res["nut.position"].values[:, 2]
    ang = res["turn.angle"].values
    jang = res["screw.angle"].values
    err = float(np.max(np.abs(z - SCREW_PITCH * ang / (2.0 * np.pi))))
    out = [compare(case, q1, 0.0, err, "m", tol, src),
           compare(case, q2, revs * SCREW_PITCH, z[-1], "m", 1e-8, src + ", angle = w t"),
           compare(case, "accumulated joint angle after the run", speed * t_end,
                   float(jang[-1]), "rad", 1e-9, "speed driver, theta = w t")]
    # At constant speed the only load is the weight: power balance T w = m g v. The torque
    # is a multiplier: its mean over the run is exact up to the Newton tolerance (1e-8
    # relative), tolerance 1e-6. Step to step it carries the (-1)^n oscillation of index-3
    # multipliers, excited by the round-off of the accumulated angle (eps |theta| ~ 1e-14
    # rad after 10 revolutions) amplified by J / (beta h^2): ~5e-7 N m = 2e-5 relative at
    # h = 0.5 ms; tolerance on the largest deviation 1e-4.
    torque = res["turn.torque"].values[1:]
    T_ref = SCREW_M * G * SCREW_PITCH / (2.0 * np.pi)
    out.append(compare(case, q3 + ", mean over the run", T_ref, float(np.mean(torque)),
                       "N m", 1e-6, "power balance of a frictionless screw"))
    out.append(compare(case, q3 + ", largest deviation", T_ref,
                       float(torque[np.argmax(np.abs(torque - T_ref))]), "N m", 1e-4,
                       "power balance of a frictionless screw"))

    def draw(fig):
        ax1, ax2 = fig.subplots(2, 1, sharex=True)
        ax1.plot(t, z, label="simulated")
        ax1.plot(t, SCREW_PITCH * speed * t / (2 * np.pi), "k--", lw=0.8, label="exact")
        ax1.set_ylabel("axial travel [m]")
        ax1.legend(fontsize=8)
        ax2.plot(t, z - SCREW_PITCH * ang / (2 * np.pi))
        ax2.set_ylabel("error [m]")
        ax2.set_xlabel("time [s]")
        fig.suptitle(f"screw joint, pitch {SCREW_PITCH * 1e3:g} mm")
    return finish_case(out, t0, save_figure(figure_dir, "screw", draw))
