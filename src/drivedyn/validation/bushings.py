"""Bushing validation case (registered with :func:`drivedyn.validation.base.register_case`):

* ``bushing_dynamic_stiffness``: a bushing axis with a Kelvin-Voigt part and two Maxwell
  branches, deflected sinusoidally by a driver (one marker on the ground, the other on a
  driven plate) at three frequencies. The first harmonics of the steady-state force and
  deflection (discrete Fourier sums over whole periods) give the complex stiffness, whose
  modulus and loss angle are compared with the closed form of the branch network
  ``K*(w) = k0 + i w c0 + sum_b k_b (i w tau_b)/(1 + i w tau_b)``, and the energy the
  element dissipates over one period with ``pi X^2 Im K*``. Both a translational axis (a
  screw joint of pitch 2 pi m/rev driven in angle: the plate slides 1 m per rad) and a
  rotational one (a hinge driven in angle). A slow sweep of a tabulated axis then checks the
  static curve against its table, inside it and on its linear extension.

The deflection is prescribed at every step by a piecewise-linear table of ``X sin(w t)``
sampled at the step times, so the driver holds the exact sinusoid at the steps.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from drivedyn.elements.bushing import (
    Bushing,
    BushingCurve,
    MaxwellBranch,
    RotationalMaxwellBranch,
)
from drivedyn.elements.drivers import JointDriver
from drivedyn.elements.joints import Hinge, Screw
from drivedyn.model import Model, Spec, compile_model
from drivedyn.solver import FixedStep, GeneralizedAlpha, simulate
from drivedyn.timefunctions import Table
from drivedyn.validation.base import CaseResult, compare, register_case
from drivedyn.validation.common import failed_check, finish_case, save_figure

#: translational axis z: k0 [N/m], c0 [N s/m], branches (k_b [N/m], tau_b [s])
TRANSLATION = (1.0e6, 150.0, ((4.0e5, 1.0e-3), (6.0e5, 1.0e-2)))
#: rotational axis x: k0 [N m/rad], c0 [N m s/rad], branches (k_b [N m/rad], tau_b [s])
ROTATION = (800.0, 0.1, ((300.0, 2.0e-3), (500.0, 1.5e-2)))
FREQUENCIES = (1.0, 10.0, 50.0)  # [Hz]
STEPS_PER_PERIOD = 200
AMPLITUDE = {"translation": 1.0e-3, "rotation": 1.0e-2}  # [m], [rad]
#: static curve (axis y): deflection [m], force [N]
STATIC_TABLE = ((-0.004, -0.002, 0.0, 0.001, 0.003), (-9000.0, -3500.0, 200.0, 1800.0, 8000.0))


def branch_bushing(kind: str, marker_a: str = "seat", marker_b: str = "sleeve") -> Bushing:
    """The bushing of the case: the network of :data:`TRANSLATION` on z or of
    :data:`ROTATION` on x."""
    if kind == "translation":
        k0, c0, br = TRANSLATION
        return Bushing("bushing", marker_a, marker_b, stiffness=(0.0, 0.0, k0),
                       damping=(0.0, 0.0, c0),
                       branches=tuple(MaxwellBranch("z", k, k * tau) for k, tau in br))
    k0, c0, br = ROTATION
    return Bushing("bushing", marker_a, marker_b, rotational_stiffness=(k0, 0.0, 0.0),
                   rotational_damping=(c0, 0.0, 0.0),
                   rotational_branches=tuple(RotationalMaxwellBranch("x", k, k * tau)
                                             for k, tau in br))


def rig(bushing: Bushing, joint: str, axis: tuple[float, float, float], motion: Any) -> Model:
    """A plate on the ground through ``bushing`` (markers ``seat`` on the ground, ``sleeve``
    on the plate, both at the origin with the global axes), its motion along or about the
    global ``axis`` prescribed by the time function ``motion`` (starting at 0): a slide [m]
    through a screw of pitch 2 pi m/rev (``joint="screw"``: also a rotation of ``motion`` rad
    about the axis, which the bushing's axes under test do not see) or a rotation [rad]
    through a hinge (``joint="hinge"``)."""
    spec = Spec()
    spec.add_rigid_body("plate", 0.5, [1e-3, 1e-3, 1e-3])
    spec.add_marker("seat", "ground")
    spec.add_marker("sleeve", "plate")
    spec.add_marker("guide_ground", "ground", axis=axis)
    spec.add_marker("guide_plate", "plate", axis=axis)
    if joint == "screw":
        spec.add(Screw("guide", "guide_ground", "guide_plate", pitch=2.0 * np.pi))
    else:
        spec.add(Hinge("guide", "guide_ground", "guide_plate"))
    spec.add(JointDriver("drive", "guide", motion, quantity="angle"))
    spec.add(bushing)
    return compile_model(spec)


@dataclass
class Harmonic:
    """Steady-state response of one axis at one frequency.

    Attributes:
        k_sim: simulated complex stiffness (first harmonics of force over deflection).
        k_ref: closed form ``K*(omega)``.
        energy_sim: energy dissipated by the element over the last period [J].
        energy_ref: ``pi X^2 Im K*`` [J].
        res: the run's results.
    """

    k_sim: complex
    k_ref: complex
    energy_sim: float
    energy_ref: float
    res: Any


def first_harmonic(t: np.ndarray, y: np.ndarray, omega: float) -> complex:
    """Complex amplitude ``Y`` of ``y(t) ~ Re(Y exp(i omega t))`` from samples covering whole
    periods uniformly (the last sample, one period after the first, is left out)."""
    return complex(2.0 * np.mean(y[:-1] * np.exp(-1j * omega * t[:-1])))


def harmonic_response(kind: str, freq: float, periods_fit: int = 2,
                      steps: int = STEPS_PER_PERIOD, rho_inf: float = 0.8) -> Harmonic:
    """Run the rig at ``freq`` [Hz] long enough for the branches' start transient to decay
    below 1e-6 (14 of the longest relaxation times), then fit ``periods_fit`` periods."""
    X = AMPLITUDE[kind]
    omega = 2.0 * np.pi * freq
    period = 1.0 / freq
    h = period / steps
    tau_max = max(tau for _, tau in (TRANSLATION if kind == "translation" else ROTATION)[2])
    n_settle = int(np.ceil(14.0 * tau_max / period))
    n_per = n_settle + periods_fit
    n = n_per * steps
    times = h * np.arange(n + 1)
    bushing = branch_bushing(kind)
    motion = Table(times, X * np.sin(omega * times))
    model = (rig(bushing, "screw", (0.0, 0.0, 1.0), motion) if kind == "translation"
             else rig(bushing, "hinge", (1.0, 0.0, 0.0), motion))
    res = simulate(model, times[-1], step=FixedStep(h), integrator=GeneralizedAlpha(rho_inf),
                   output_dt=h)
    ax = "z" if kind == "translation" else "x"
    k_ref = bushing.dynamic_stiffness(ax, omega, rotational=kind == "rotation")
    if not res.success:
        return Harmonic(complex(np.nan), k_ref, np.nan, np.pi * X * X * k_ref.imag, res)
    name = f"force_{ax}" if kind == "translation" else f"moment_{ax}"
    defl = f"deflection_{ax}" if kind == "translation" else f"rotation_{ax}"
    t = np.asarray(res.time)
    i0 = n_settle * steps
    sel = slice(i0, n + 1)
    tt = t[sel]
    F = first_harmonic(tt, res[f"bushing.{name}"].values[sel], omega)
    Xh = first_harmonic(tt, res[f"bushing.{defl}"].values[sel], omega)
    D = res["bushing.dissipated_energy"].values
    e_cycle = float(D[n] - D[n - steps])
    return Harmonic(F / Xh, k_ref, e_cycle, np.pi * X * X * k_ref.imag, res)


def pchip_reference(xs: np.ndarray, fs: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The static curve of a table by SciPy (an implementation independent of the
    element's): PCHIP inside the table, the end tangents outside."""
    from scipy.interpolate import PchipInterpolator

    p = PchipInterpolator(xs, fs)
    dp = p.derivative()
    lo = fs[0] + dp(xs[0]) * (x - xs[0])
    hi = fs[-1] + dp(xs[-1]) * (x - xs[-1])
    return np.where(x < xs[0], lo, np.where(x > xs[-1], hi, p(np.clip(x, xs[0], xs[-1]))))


def static_sweep(quick: bool = False) -> tuple[np.ndarray, np.ndarray, Any]:
    """A slow sweep (1 s) of a tabulated translational axis without damping, from 0 down to
    -6 mm and up to +5 mm, beyond both ends of :data:`STATIC_TABLE`: the deflections [m],
    the forces [N] and the results."""
    xs, fs = STATIC_TABLE
    bushing = Bushing("bushing", "seat", "sleeve", curves=(BushingCurve("y", xs, fs),))
    n = 110 if quick else 220
    h = 1.0 / n
    # kink on a step (30 % of n); on the way up each step adds 1/(0.7 n) of 11 mm, so the
    # deflection lands on every point of the table (multiples of 1 mm from -6 mm)
    motion = Table((0.0, 0.3, 1.0), (0.0, -0.006, 0.005))
    res = simulate(rig(bushing, "screw", (0.0, 1.0, 0.0), motion), 1.0, step=FixedStep(h),
                   output_dt=h)
    if not res.success:
        return np.zeros(0), np.zeros(0), res
    return res["bushing.deflection_y"].values, res["bushing.force_y"].values, res


@register_case("bushing_dynamic_stiffness")
def bushing_dynamic_stiffness(quick: bool = False,
                              figure_dir: str | None = None) -> list[CaseResult]:
    """|K*|, loss angle and energy per cycle of a translational and a rotational bushing axis
    (Kelvin-Voigt part and two Maxwell branches) at 1, 10 and 50 Hz against the closed
    form of the network; the static curve of a tabulated axis against its table. Seen to
    fail: the element built with its branches' dampers (relaxation times) 10 % high, the
    reference keeping the file's: loss angle 9.6 % off at 1 Hz, |K*| 2.2 % at 10 Hz,
    energy per cycle 9.7 % at 1 Hz (tolerance 1 %)."""
    t0 = time.perf_counter()
    case = "bushing_dynamic_stiffness"
    src = "closed form K* = k0 + i w c0 + sum k_b i w tau_b/(1 + i w tau_b)"
    # 1 %: the requirement; measured errors are below 1e-3 (the second-order
    # Newmark velocity of the damper and the exact branch update at 200 steps per period)
    tol = 0.01
    out: list[CaseResult] = []
    runs: dict[str, list[tuple[float, Harmonic]]] = {}
    for kind in ("translation", "rotation"):
        unit = "N/m" if kind == "translation" else "N m/rad"
        runs[kind] = []
        for f in FREQUENCIES:
            hr = harmonic_response(kind, f)
            label = f"{kind} axis, {f:g} Hz"
            if not np.isfinite(hr.k_sim):
                for q, u in (("|K*|", unit), ("loss angle", "deg"), ("energy per cycle", "J")):
                    out.append(failed_check(case, f"{q}, {label}", u, tol, src, hr.res))
                continue
            runs[kind].append((f, hr))
            out.append(compare(case, f"|K*|, {label}", abs(hr.k_ref), abs(hr.k_sim), unit,
                               tol, src))
            out.append(compare(case, f"loss angle, {label}", np.degrees(np.angle(hr.k_ref)),
                               np.degrees(np.angle(hr.k_sim)), "deg", tol,
                               src + "; delta = atan(Im K*/Re K*)"))
            out.append(compare(case, f"energy dissipated per cycle, {label}", hr.energy_ref,
                               hr.energy_sim, "J", tol, "pi X^2 Im K*"))
    xs, fs = STATIC_TABLE
    x, F, res = static_sweep(quick)
    q_pts = "static curve at the table's points: max |F - table| / max |table|"
    q_all = ("static curve over the sweep -6 .. 5 mm (table -4 .. 3 mm): max |F - ref| / "
             "max |table|")
    src_all = ("SciPy PchipInterpolator of the table inside it, its end tangents beyond "
               "(linear extrapolation)")
    if not x.size:
        out.append(failed_check(case, q_pts, "1", 1e-9, "the table", res))
        out.append(failed_check(case, q_all, "1", 1e-9, src_all, res))
    else:
        ref = pchip_reference(np.asarray(xs), np.asarray(fs), x)
        scale = float(np.max(np.abs(fs)))
        # the sweep passes every table point at a step (see static_sweep)
        hits = [int(np.argmin(np.abs(x - xi))) for xi in xs]
        err_pts = max(abs(F[i] - fi) for i, fi in zip(hits, fs, strict=True)) / scale
        out.append(compare(case, q_pts, 0.0, err_pts, "1", 1e-9, "the table"))
        out.append(compare(case, q_all, 0.0, float(np.max(np.abs(F - ref))) / scale, "1",
                           1e-9, src_all))

    def draw(fig):
        axs = fig.subplots(1, 3)
        grid = np.logspace(np.log10(0.5), np.log10(100.0), 200)
        for kind, ls in (("translation", "o"), ("rotation", "s")):
            b = branch_bushing(kind)
            ax, rot = ("z", False) if kind == "translation" else ("x", True)
            kr = np.array([b.dynamic_stiffness(ax, 2.0 * np.pi * f, rot) for f in grid])
            k1 = abs(b.dynamic_stiffness(ax, 2.0 * np.pi * FREQUENCIES[0], rot))
            axs[0].plot(grid, abs(kr) / k1, "k--", lw=0.8)
            axs[1].plot(grid, np.degrees(np.angle(kr)), "k--", lw=0.8)
            fr = np.array([f for f, _ in runs[kind]])
            ks = np.array([hr.k_sim for _, hr in runs[kind]])
            if fr.size:
                axs[0].plot(fr, abs(ks) / k1, ls, label=f"{kind} (simulated)")
                axs[1].plot(fr, np.degrees(np.angle(ks)), ls, label=kind)
        axs[0].set_xscale("log")
        axs[1].set_xscale("log")
        axs[0].set_xlabel("frequency [Hz]")
        axs[1].set_xlabel("frequency [Hz]")
        axs[0].set_ylabel("|K*| / |K*(1 Hz)|")
        axs[1].set_ylabel("loss angle [deg]")
        axs[0].legend(fontsize=7)
        if x.size:
            axs[2].plot(np.asarray(xs) * 1e3, fs, "ko", label="table")
            axs[2].plot(x * 1e3, F, "-", label="simulated sweep")
            axs[2].set_xlabel("deflection [mm]")
            axs[2].set_ylabel("force [N]")
            axs[2].legend(fontsize=7)
        fig.suptitle("bushing: dynamic stiffness (closed form dashed) and static curve")
    return finish_case(out, t0, save_figure(figure_dir, case, draw))
