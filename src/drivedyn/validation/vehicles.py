"""Validation of the tyres and the 4WD vehicle: the Magic Formula's exact properties and the
relaxation time constant (``tyre_mf``), the split-mu vehicle with each differential type
against the identities and the differentials' own bench figures (``vehicle_4wd_split_mu``)."""

from __future__ import annotations

import math
import time

import numpy as np

from drivedyn.validation.base import CaseResult, compare, register_case
from drivedyn.validation.common import at_least, at_most, failed_check


@register_case("tyre_mf")
def tyre_mf(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Magic Formula of the shipped PAC2002 file: pure-slip peak (D + S_V, exact), slip
    stiffnesses at zero slip (the formula's K_x, K_y against the numerical slope), the simple
    dry set's peak, and the tyre element's first-order relaxation: a slip step on a wheel
    rolling at 10 m/s relaxes with the time constant sigma_kappa / V (1 %; a relaxation run
    that stops early is a failed check). Seen to fail: the tyre element given PTX1 5 % high
    (the reference keeps the file's) relaxes 4.9 % slower."""
    from scipy.optimize import curve_fit

    from drivedyn.elements import Hinge, JointDriver, Prismatic, TyreContact
    from drivedyn.model.compile import compile_model
    from drivedyn.model.spec import Spec
    from drivedyn.solver import simulate
    from drivedyn.solver.settings import FixedStep
    from drivedyn.timefunctions import SmoothStep
    from drivedyn.tyres import SURFACES, read_tir, shipped, simple_tyre
    from drivedyn.validation.common import finish_case, save_figure

    t0 = time.perf_counter()
    case = "tyre_mf"
    tyre = read_tir(shipped("pac2002_235_60R16"))
    out: list[CaseResult] = []
    fz = 4000.0
    kap = np.linspace(0.0, 0.4, 40001)
    fx = tyre.forces(fz, kap, 0.0)[0]
    peak = fz * tyre.value("PDX1") + fz * tyre.value("PVX1")  # dfz = 0 at the nominal load
    out.append(compare(case, "pure longitudinal peak at the nominal load (D_x + S_Vx)", peak,
                       float(fx.max()), "N", 1e-9, "Pacejka 2012 eq. 4.E9-4.E18: sin = 1"))
    r = tyre.evaluate(fz, 0.0, 0.0)
    h = 1e-6
    shx = tyre.value("PHX1")
    slope = (tyre.forces(fz, -shx + h, 0.0)[0] - tyre.forces(fz, -shx - h, 0.0)[0]) / (2 * h)
    out.append(compare(case, "longitudinal slip stiffness K_x = Fz PKX1 (nominal load)",
                       fz * tyre.value("PKX1"), float(slope), "N", 1e-6,
                       "eq. 4.E15 at dfz = 0; central difference of the formula"))
    ky = tyre.value("PKY1") * fz * math.sin(2 * math.atan(1 / tyre.value("PKY2")))
    out.append(compare(case, "cornering stiffness K_y = PKY1 Fz0 sin(2 atan(1/PKY2))", ky,
                       float(r["kya"]), "N/rad", 1e-12, "eq. 4.E25 (MF 5.2) at Fz = Fz0"))
    D = SURFACES["dry"][2]
    simple = simple_tyre("dry")
    sp = simple.forces(3000.0, np.linspace(0, 1, 100001), 0.0)[0]
    out.append(compare(case, "simple dry set: peak = D Fz", D * 3000.0, float(sp.max()), "N",
                       1e-9, "F = D sin(C atan(B x - E (B x - atan B x))), physics.md 5"))
    # relaxation on a rolling rig
    r0, cz = tyre.unloaded_radius, tyre.vertical_stiffness
    height, v, k_step, ts = r0 - 0.02, 10.0, 0.01, 0.05
    re = tyre.effective_radius(0.02)
    spec = Spec()
    spec.add_rigid_body("carrier", 1e7, (1e6, 1e6, 1e6), position=(0, 0, height),
                        velocity=(v, 0, 0))
    spec.add_rigid_body("wheel", 20.0, (0.6, 1.0, 0.6), position=(0, 0, height),
                        velocity=(v, 0, 0), angular_velocity=(0, v / re, 0))
    spec.add_marker("g_x", "ground", position=(0, 0, height), axis=(1, 0, 0))
    spec.add_marker("c_x", "carrier", axis=(1, 0, 0))
    spec.add(Prismatic("slide", "g_x", "c_x"))
    spec.add_marker("c_hub", "carrier", axis=(0, 1, 0))
    spec.add_marker("w_hub", "wheel", axis=(0, 1, 0))
    spec.add(Hinge("axle", "c_hub", "w_hub"))
    spec.add(JointDriver("spin", "axle", function=SmoothStep(
        ts, ts + 1e-4, v / re, v * (1 + k_step) / re)))
    spec.add(TyreContact("tyre", "w_hub", tyre))
    res = simulate(compile_model(spec), 0.5, step=FixedStep(2e-4), output_dt=2e-4)
    if not res.success:
        return [*out, failed_check(case, "relaxation: time constant of a slip step", "s",
                                   0.01, "first-order transient slip", res)]
    t = res.time
    k = res["tyre.kappa_transient"].values
    tau = tyre.relaxation_lengths(cz * 0.02)[0] / v
    sel = t > ts + 2e-4
    (_, tau_fit), _ = curve_fit(lambda tt, a, ta: a * (1 - np.exp(-(tt - ts) / ta)), t[sel],
                                k[sel], p0=(k_step, 0.1))
    out.append(compare(case, "relaxation: time constant of a slip step (sigma_kappa / V)", tau,
                       float(tau_fit), "s", 0.01, "first-order transient slip, Pacejka 2012 "
                       "sec. 7.2; MF 5.2 sigma_kappa from PTX1-3"))

    def draw(fig):
        ax1, ax2 = fig.subplots(1, 2)
        ax1.plot(kap, fx, label="pure slip")
        ax1.plot(kap, tyre.forces(fz, kap, 0.1)[0], label="alpha = 0.1 rad")
        ax1.set_xlabel("longitudinal slip [-]")
        ax1.set_ylabel("Fx [N] at Fz = 4 kN")
        ax1.legend()
        ax2.plot(t, k, label="kappa' (simulated)")
        ax2.plot(t[sel], k_step * (1 - np.exp(-(t[sel] - ts) / tau)), "--",
                 label="first order, tau = sigma/V")
        ax2.set_xlabel("time [s]")
        ax2.set_ylabel("transient slip [-]")
        ax2.legend()

    return finish_case(out, t0, save_figure(figure_dir, "tyre_mf", draw))


@register_case("vehicle_4wd_split_mu")
def vehicle_4wd_split_mu(quick: bool = False, figure_dir: str | None = None
                         ) -> list[CaseResult]:
    """The 4WD vehicle of seed 003 on split-mu (rolling start at 2 m/s, 100 N m on the
    central housing, road friction 0.002 / 0.05 / 0.01 / 0.8 under FL / FR / RL / RR) with
    open, locked, clutch and TORSEN differentials (quick: open and TORSEN): the TORSEN axles
    bias at the Type B bench TDR of the drive modes (0.5 %) and, braking with -100 N m at
    3 m/s (full run), of the coast modes; open differentials split evenly
    (2 %), locked and limited-slip vehicles pull harder than the open one, and the torque
    balance of every differential and the driveline power balance hold (5e-5 and 5e-4; the
    issue's tolerance is 0.5 %, measured 1.2e-5 and 1.2e-4); the central Type C's rear /
    front split lies inside its locking band while its outputs turn together (measured
    1.46 in 0.614-3.57 on this rolling start) or at a band end while they slip. Seen to
    fail: the central's friction lost in the simulation (washers, pockets, teeth at mu 0)
    slips by -43 % at its nominal split 1.40 on the launch from rest, 61 % from the band's
    nearest end."""
    import drivedyn.analysis.vehicle_4wd as V  # noqa: N812
    from drivedyn.config import read_library_file
    from drivedyn.library.differentials.torsen_b import analytic as ab
    from drivedyn.validation.common import finish_case

    t0 = time.perf_counter()
    case = "vehicle_4wd_split_mu"
    p, _, _ = read_library_file("vehicle-4wd", [
        "body.speed=2", "load.ramp=0.1", "run.t_end=0.8", "run.window=[0.5,0.8]"])
    tc, _, _ = read_library_file("torsen-c")
    tb, _, _ = read_library_file("torsen-b")
    configs = ["open", "torsen"] if quick else ["open", "locked", "clutch", "torsen"]
    runs = {s.name: (s, res) for s, res in V.compare(p, {"torsen-c": tc, "torsen-b": tb},
                                                     configs)}
    out: list[CaseResult] = []
    tdr_drive = ab.bench_tdr(tb, 1)
    s = runs["torsen"][0]
    for axle in ("front", "rear"):
        out.append(compare(case, f"TORSEN {axle} axle torque ratio vs Type B bench TDR "
                           "(drive, analytic)", tdr_drive, s.axle_ratio[axle], "1", 5e-3,
                           "the differential biases at its TDR once a wheel slips (seed 003); "
                           "torsen_b analytic model"))
        hi, lo = ("fr", "fl") if axle == "front" else ("rr", "rl")
        out.append(at_least(case, f"TORSEN {axle}: higher-friction wheel torque / other's",
                             abs(s.wheels[hi].torque / s.wheels[lo].torque), 1.0, "1",
                             "seed 003 Fig. 15: the wheel with more grip gets more torque"))
    # the central Type C: inside its locking band while it sticks, at a band end if it slips
    lo, hi = V.central_band(s) or (math.nan, math.nan)
    if abs(s.central_slip) <= V.CENTRAL_STICK:
        out.append(at_least(case, "TORSEN central: rear / front split (sticking) vs 1 / TDR_3",
                            s.central_ratio, lo * 0.98, "1",
                            "inside the locking band while the outputs turn together "
                            f"(relative speed {s.central_slip:.1e}); torsen_c analytic, -2 %"))
        out.append(at_most(case, "TORSEN central: rear / front split (sticking) vs TDR_1",
                           s.central_ratio, hi * 1.02, "1",
                           "inside the locking band; torsen_c analytic, +2 %"))
    else:
        (label, dev, tol, _), = V.central_checks(s, 0.02)
        out.append(at_most(case, label, dev, tol, "1", "a slipping TORSEN sits at its TDR"))
    if not quick:  # engine braking: the coast modes
        pc, _, _ = read_library_file("vehicle-4wd", [
            "body.speed=3", "load.torque=-100", "load.ramp=0.1", "run.t_end=0.8",
            "run.window=[0.5,0.8]"])
        (sc, _), = V.compare(pc, {"torsen-c": tc, "torsen-b": tb}, ["torsen"])
        tdr_coast = ab.bench_tdr(tb, 2)
        for axle in ("front", "rear"):
            out.append(compare(case, f"TORSEN {axle} axle torque ratio in engine braking vs "
                               "Type B bench TDR (coast, analytic)", tdr_coast,
                               sc.axle_ratio[axle], "1", 5e-3,
                               "the coast modes of the differential (seed 003)"))
    so = runs["open"][0]
    T = np.array([so.wheels[w].torque for w in ("fl", "fr", "rl", "rr")])
    out.append(at_most(case, "open: largest deviation of a wheel torque from the mean",
                        float(np.max(np.abs(T - T.mean())) / T.mean()), 0.02, "1",
                        "an open differential splits evenly (bevel spiders turn freely)"))
    for name in configs:
        sc = runs[name][0]
        if name != "open":
            out.append(at_least(case, f"{name}: traction / open traction",
                                 sc.traction / so.traction, 1.3, "1",
                                 "limiting the slip of the ice wheel frees the others' grip"))
        for pos, e in sc.torque_balance.items():
            out.append(at_most(case, f"{name}: torque balance of the {pos} differential", e,
                                5e-5, "1", "Euler: input - outputs = d(H_axis)/dt (the issue "
                                "asks 0.5 %; measured <= 1.2e-5)"))
        out.append(at_most(case, f"{name}: driveline power balance", sc.power_balance, 5e-4,
                            "1", "engine = wheels + dissipation + d(K_driveline)/dt (the issue "
                            "asks 0.5 %; measured <= 1.2e-4)"))
    figures: list[str] = []
    if figure_dir:
        from pathlib import Path

        from drivedyn.plots.vehicle_4wd import comparison_figure, save, wheel_torques_figure

        d = Path(figure_dir)
        figures.append(str(save(wheel_torques_figure(
            [(n, r) for n, (_, r) in runs.items()], p.run.window), d / "vehicle_4wd.png")))
        figures.append(str(save(comparison_figure([sc for sc, _ in runs.values()]),
                                d / "vehicle_4wd_comparison.png")))
    return finish_case(out, t0, figures)
