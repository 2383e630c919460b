"""The four-wheel-drive vehicle on split-mu: run, window means, torque splits, balances,
and the comparison of differential types (seed 003, Figure 15).

Signs: a wheel's *drive torque* is the torque its half-shaft applies to it about the wheel's
axis (+y, forward rolling positive), the negative of the half-shaft spring's reported torque;
the tyre force ``fx`` is positive forward. All window quantities are means over
``run.window`` of the recorded samples (record densely: ``output_dt`` 1 ms by default here).

Checks (:func:`checks`, the issue's acceptance criteria):

* ``open``: the four drive torques are equal within 2 % (an open differential splits evenly
  whatever the speeds); the lowest-friction wheel spins (its slip grows).
* ``locked``: the two wheels of each axle turn together (window-mean spins within
  :data:`LOCKED_SPIN`: measured 3.6e-4 front, 1e-4 rear on the split-mu rolling start, the
  half-shafts' and tyres' compliance; the clutch-pack axle slips 4.2e-3, the open one 76 %),
  and the wheel with more grip on each axle takes more torque.
* ``torsen``: each axle's torque ratio (high / low) lies in the band of that differential's
  analytic TDRs (lowest -2 % to highest +2 %: on split-mu one wheel slips and the TORSEN
  biases at its TDR; an open or a locked axle falls outside) and the wheel with more grip
  gets more torque; the central Type C's rear / front split lies inside its locking band
  (``[1 / TDR_3, TDR_1]`` in drive) while its outputs turn together and at one end of it
  while they slip (:data:`CENTRAL_STICK`).
* every configuration: torque balance of each differential (housing input vs outputs) and
  power balance of the driveline (engine power = wheel powers + driveline dissipation + rate
  of driveline kinetic energy) within 0.5 % over the window; the model's energy audit.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from drivedyn.analysis import vehicle_runs
from drivedyn.library.vehicles.vehicle_4wd import Layout, Vehicle4WDFile, build_spec
from drivedyn.library.vehicles.vehicle_4wd.configurations import CONFIGS, config_name
from drivedyn.library.vehicles.vehicle_4wd.schema import WHEELS
from drivedyn.results.provenance import record_provenance


@dataclass
class WheelWindow:
    """Window means of one wheel: drive torque [N m], tyre forces [N], spin [rad/s], slip,
    road friction factor and the tyre's friction limit ``mu_x Fz`` [N]."""

    torque: float
    fx: float
    fz: float
    spin: float
    kappa: float
    mu_road: float
    limit: float


@dataclass
class Summary:
    """What a split-mu run shows over its window.

    Attributes:
        types: position -> differential type.
        wheels: wheel -> :class:`WheelWindow`.
        speed: vehicle speed [m/s] at the window's end; acceleration [m/s^2] over it.
        engine: mean engine torque [N m].
        front_share: front axle's share of the four drive torques.
        left_share: axle -> left wheel's share of that axle's torque.
        axle_ratio: axle -> higher / lower wheel torque magnitude of that axle (drive or
            coast).
        central_ratio: rear / front axle torque.
        central_slip: the central differential's rear minus front output speed over their
            mean magnitude (window means about its axis; 0: it sticks).
        central_modes: the central TORSEN's analytic bench TDRs of modes 1-4 (None for the
            other types).
        traction: sum of the four tyre forces [N].
        torque_balance: position -> |input - outputs| / |input| of that differential.
        power_balance: |P_engine - P_wheels - D_driveline - dK/dt| / P_engine.
        energy_error: |balance error| / work in of the whole model at the window's end.
        wall: wall time [s]; steps, rejected, newton: solver counts.
        tdr: position -> (lowest, highest) analytic TDR of a TORSEN, else None.
    """

    types: dict[str, str]
    wheels: dict[str, WheelWindow]
    speed: float
    acceleration: float
    engine: float
    front_share: float
    left_share: dict[str, float]
    axle_ratio: dict[str, float]
    central_ratio: float
    central_slip: float
    traction: float
    torque_balance: dict[str, float]
    power_balance: float
    energy_error: float
    wall: float = 0.0
    steps: int = 0
    rejected: int = 0
    newton: int = 0
    tdr: dict[str, Any] = field(default_factory=dict)
    central_modes: list[float] | None = None

    @property
    def name(self) -> str:
        return config_name(self.types)


def configure(p: Vehicle4WDFile, config: str) -> Vehicle4WDFile:
    """``p`` with every position set to the types of ``config`` (a :data:`CONFIGS` key)."""
    if config not in CONFIGS:
        raise KeyError(f"no configuration {config!r} (known: {', '.join(CONFIGS)})")
    c, f, r = CONFIGS[config]
    d = p.differentials.model_copy(update={"central": c, "front": f, "rear": r})
    return p.model_copy(update={"differentials": d})


#: relative speed of the central's outputs below which it sticks (measured 1.1e-4 on the
#: split-mu launch: the regularised friction's creep and the shafts' compliance; the
#: frictionless central slips by several per cent)
CENTRAL_STICK = 1e-3

#: recording interval [s] of :func:`run` (the window means need at least 3 samples)
OUTPUT_DT = 1e-3


def run(p: Vehicle4WDFile, torsen: dict, base_dir: str | Path = ".", t_end: float | None = None,
        output_dt: float = OUTPUT_DT, progress=None, source: str = "",
        overrides: list[str] | tuple = ()):
    """Build, compile and simulate the vehicle: (results, layout). The results record the
    parameters of the run, its ``source`` file, ``overrides`` and configuration
    (:func:`~drivedyn.results.provenance.record_provenance`), so that reports and plots find
    the vehicle's dashboard."""
    import json

    from drivedyn.model.compile import compile_model
    from drivedyn.solver import simulate

    spec, lay = build_spec(p, torsen, base_dir)
    model = compile_model(spec)
    t_end = p.run.t_end if t_end is None else t_end
    res = simulate(model, t_end, output_dt=output_dt, progress=progress,
                   **p.solver.settings(h_max=p.run.h_max))
    record_provenance(res,
                      model_file=json.dumps(p.model_dump(mode="json", warnings=False),
                                            indent=1, default=str),
                      source=source or p.model.name, overrides=overrides,
                      library_model=p.model.library, configuration=config_name(p))
    return res, lay


def _mean(res, name: str, sel, col: int | None = None) -> float:
    v = res.values(name)
    v = v[:, col] if col is not None else v
    return float(np.mean(v[sel]))


def summarize(res, lay: Layout, window: tuple[float, float]) -> Summary:
    """Window means, splits and balances of a run (see the module docstring)."""
    t = res.time
    sel = (t >= window[0] - 1e-12) & (t <= window[1] + 1e-12)
    if sel.sum() < 3:
        raise ValueError(f"window {window} s holds {int(sel.sum())} samples; record more "
                         "densely or widen it")
    i0, i1 = np.flatnonzero(sel)[[0, -1]]
    wheels = {}
    for w in WHEELS:
        tq = -_mean(res, f"{lay.halfshafts[w]}.torque", sel)
        fx = _mean(res, f"{lay.tyres[w]}.fx", sel)
        fz = _mean(res, f"{lay.tyres[w]}.fz", sel)
        spin = _mean(res, f"{lay.wheels[w]}.angular_velocity", sel, 1)
        kap = _mean(res, f"{lay.tyres[w]}.kappa", sel)
        mu = _mean(res, f"{lay.tyres[w]}.road_mu", sel)
        lim = _mean(res, f"{lay.tyres[w]}.friction_limit", sel)
        wheels[w] = WheelWindow(tq, fx, fz, spin, kap, mu, lim)
    T = {w: wheels[w].torque for w in WHEELS}
    front = T["fl"] + T["fr"]
    rear = T["rl"] + T["rr"]
    v = res.values("body.velocity")[:, 0]
    dt = t[i1] - t[i0]
    # torque balance of each differential (Euler: input - outputs = rate of the angular
    # momentum of its bodies about its axis, relative to the car body)
    tb = {}
    prop = {a: -_mean(res, f"{lay.propshafts[a]}.torque", sel) for a in ("front", "rear")}
    # engine torque about the central housing's axis (its sign kept: coast is negative)
    axis = res.values(f"{lay.housings['central']}.rotation")[:, :, 2]
    tq = np.stack([res.values(f"{lay.engine}.torque_{c}") for c in "xyz"], axis=1)
    eng = float(np.mean(np.einsum("ij,ij->i", tq, axis)[sel]))
    # the central's outputs (front, rear) about its axis
    w_out = [float(np.mean(np.einsum("ij,ij->i", res.values(f"{b}.angular_velocity"),
                                     axis)[sel]))
             for b in lay.outputs.get("central", ())]
    slip = _div(w_out[1] - w_out[0], 0.5 * (abs(w_out[0]) + abs(w_out[1]))) \
        if len(w_out) == 2 else math.nan
    inputs = {"central": eng,
              "front": _mean(res, f"{lay.bevels['front']}.torque_b", sel),
              "rear": _mean(res, f"{lay.bevels['rear']}.torque_b", sel)}
    outputs = {"central": prop["front"] + prop["rear"], "front": front, "rear": rear}
    for pos in ("central", "front", "rear"):
        dh = (_axial_momentum(res, lay, pos, i1) - _axial_momentum(res, lay, pos, i0)) / dt
        tb[pos] = _div(abs(inputs[pos] - outputs[pos] - dh), abs(inputs[pos]))
    # power balance of the driveline over the window
    w_eng = _integral(res, f"{lay.engine}.power", i0, i1) + \
        _integral(res, f"{lay.engine}_reaction.power", i0, i1)
    w_wheels = 0.0
    wb = res.values("body.angular_velocity")[:, 1]
    for w in WHEELS:
        p_w = -res.values(f"{lay.halfshafts[w]}.torque") * (
            res.values(f"{lay.wheels[w]}.angular_velocity")[:, 1] - wb)
        w_wheels += float(np.trapezoid(p_w[i0:i1 + 1], t[i0:i1 + 1]))
    d_dl = 0.0
    for n in res.names():
        if n.endswith(".dissipated_energy") and not n.startswith(("tyre_", "energy.")):
            d = res.values(n)
            d_dl += float(d[i1] - d[i0])
    dk = _driveline_kinetic(res, lay, i1) - _driveline_kinetic(res, lay, i0)
    pb = _div(abs(w_eng - w_wheels - d_dl - dk), abs(w_eng))
    wi = res.values("energy.work_in")[i1]
    ee = abs(res.values("energy.balance_error")[i1]) / max(abs(wi), 1e-12)
    return Summary(
        types=dict(lay.types), wheels=wheels, speed=float(v[i1]),
        acceleration=float((v[i1] - v[i0]) / dt), engine=eng,
        front_share=_div(front, front + rear),
        left_share={"front": _div(T["fl"], front), "rear": _div(T["rl"], rear)},
        axle_ratio={"front": _ratio(T["fl"], T["fr"]), "rear": _ratio(T["rl"], T["rr"])},
        central_ratio=_div(rear, front), central_slip=slip,
        traction=sum(wh.fx for wh in wheels.values()),
        torque_balance=tb, power_balance=pb, energy_error=ee,
        wall=res.stats.wall_s, steps=res.stats.steps, rejected=res.stats.rejected,
        newton=res.stats.newton_iterations, tdr=dict(lay.tdr),
        central_modes=lay.modes.get("central"))


def _ratio(a: float, b: float) -> float:
    """Larger over smaller magnitude of two torques (drive or coast)."""
    return _div(max(abs(a), abs(b)), min(abs(a), abs(b)))


def _div(a: float, b: float) -> float:
    """``a / b`` with IEEE semantics: +-inf for a non-zero ``a`` over 0, NaN for 0 / 0 (a
    run without engine torque, a wheel on a road without friction: the ratio is undefined
    and the check that reads it fails, instead of the analysis)."""
    if b != 0.0:
        return a / b
    return math.copysign(math.inf, a) if a != 0.0 else math.nan


def time_histories(res, wheels=WHEELS) -> dict[str, np.ndarray]:
    """Per-sample outputs of a vehicle run: ``torque_<w>`` (drive torques [N m]),
    ``spin_<w>`` [rad/s], ``slip_<w>`` [-], ``speed`` [m/s] and the splits ``front_share``,
    ``left_share_front``, ``left_share_rear`` (NaN while the total torque is below 5 % of its
    largest value, where a share means nothing)."""
    out: dict[str, np.ndarray] = {}
    for w in wheels:
        out[f"torque_{w}"] = -res.values(f"halfshaft_{w}.torque")
        out[f"spin_{w}"] = res.values(f"wheel_{w}.angular_velocity")[:, 1]
        out[f"slip_{w}"] = res.values(f"tyre_{w}.kappa")
    out["speed"] = res.values("body.velocity")[:, 0]
    front = out["torque_fl"] + out["torque_fr"]
    rear = out["torque_rl"] + out["torque_rr"]
    total = front + rear
    ok = np.abs(total) >= 0.05 * np.max(np.abs(total)) if total.size else total

    def share(a, b):
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(ok & (np.abs(b) > 0), a / b, np.nan)

    out["front_share"] = share(front, total)
    out["left_share_front"] = share(out["torque_fl"], front)
    out["left_share_rear"] = share(out["torque_rl"], rear)
    return out


def _integral(res, name: str, i0: int, i1: int) -> float:
    t = res.time
    return float(np.trapezoid(res.values(name)[i0:i1 + 1], t[i0:i1 + 1]))


def _relative_velocity(res, b: str, i: int) -> np.ndarray:
    """Velocity [m/s] of body ``b``'s centre relative to the car body (its rigid motion)."""
    x = res.values(f"{b}.position")[i]
    xb = res.values("body.position")[i]
    vb = res.values("body.velocity")[i] + np.cross(res.values("body.angular_velocity")[i],
                                                   x - xb)
    return res.values(f"{b}.velocity")[i] - vb


def _driveline_kinetic(res, lay: Layout, i: int) -> float:
    """Kinetic energy [J] of the driveline bodies at sample ``i``, relative to the car body
    in translation (the car body's bearings do the work of carrying them along)."""
    k = 0.0
    for b, m in lay.driveline.items():
        v = _relative_velocity(res, b, i)
        w = res.values(f"{b}.angular_velocity")[i]
        h = res.values(f"{b}.angular_momentum")[i]
        k += 0.5 * m * float(v @ v) + 0.5 * float(w @ h)
    return k


def _axial_momentum(res, lay: Layout, pos: str, i: int) -> float:
    """Angular momentum [kg m^2/s] of the bodies of differential ``pos`` about its axis
    through its housing centre, relative to the car body in translation."""
    hb = lay.housings[pos]
    o = res.values(f"{hb}.position")[i]
    a = res.values(f"{hb}.rotation")[i][:, 2]
    total = 0.0
    for b, m in lay.driveline.items():
        if not b.startswith(pos + "_"):
            continue
        r = res.values(f"{b}.position")[i] - o
        total += float(res.values(f"{b}.angular_momentum")[i] @ a) + m * float(
            np.cross(r, _relative_velocity(res, b, i)) @ a)
    return total


#: largest relative spin difference of a locked axle's wheels (window means)
LOCKED_SPIN = 1e-3


def checks(s: Summary, tol: float = 0.02, balance: float = 5e-3) -> list[tuple[str, float,
                                                                                float, bool]]:
    """The acceptance checks of a summary: (name, value, limit, passed)."""
    out: list[tuple[str, float, float, bool]] = []
    W = s.wheels
    kind = s.name
    if kind == "open":
        T = np.array([W[w].torque for w in WHEELS])
        dev = _div(float(np.max(np.abs(T - T.mean()))), float(T.mean()))
        out.append(("open: wheel torques equal (max deviation)", dev, tol, dev <= tol))
        low = min(WHEELS, key=lambda w: W[w].mu_road)
        out.append((f"open: lowest-friction wheel {low} slips (|slip|)", abs(W[low].kappa),
                    0.05, abs(W[low].kappa) > 0.05))
    if kind == "locked":
        for axle, (l_, r_) in (("front", ("fl", "fr")), ("rear", ("rl", "rr"))):
            d = _div(abs(W[l_].spin - W[r_].spin), max(abs(W[l_].spin), abs(W[r_].spin)))
            out.append((f"locked: {axle} wheels turn together (relative spin difference)", d,
                        LOCKED_SPIN, d <= LOCKED_SPIN))
    for axle in ("front", "rear"):
        l_, r_ = (W["fl"], W["fr"]) if axle == "front" else (W["rl"], W["rr"])
        if abs(l_.mu_road - r_.mu_road) > 1e-12 and kind in ("locked", "torsen", "clutch"):
            hi, lo = (l_, r_) if l_.mu_road > r_.mu_road else (r_, l_)
            out.append((f"{kind}: {axle} higher-friction wheel gets more torque",
                        _div(abs(hi.torque), abs(lo.torque)), 1.0,
                        abs(hi.torque) > abs(lo.torque)))
        tdr = s.tdr.get(axle)
        if kind == "torsen" and tdr:
            lo, hi = tdr[0] * (1 - tol), tdr[1] * (1 + tol)
            r = s.axle_ratio[axle]
            # the limit shown is the band's end the ratio is nearer to
            out.append((f"torsen: {axle} torque ratio at the TDR ({lo:.3f}-{hi:.3f})", r,
                        hi if r >= lo else lo, lo <= r <= hi))
    out += central_checks(s, tol)
    for pos, e in s.torque_balance.items():
        out.append((f"{kind}: torque balance of the {pos} differential", e, balance,
                    e <= balance))
    out.append((f"{kind}: driveline power balance", s.power_balance, balance,
                s.power_balance <= balance))
    out.append((f"{kind}: energy audit (balance error / work in)", s.energy_error, 1e-2,
                s.energy_error <= 1e-2))
    return out


def central_band(s: Summary) -> tuple[float, float] | None:
    """The central TORSEN Type C's locking band of its rear / front torque split from its
    analytic bench TDRs: ``(1 / TDR_3, TDR_1)`` in drive (mode 1 biases the rear, mode 3 the
    front), ``(1 / TDR_4, TDR_2)`` in coast; None for another central differential."""
    modes = s.central_modes
    if s.types.get("central") != "torsen-c" or not modes:
        return None
    drive = s.engine > 0
    return 1.0 / (modes[2] if drive else modes[3]), modes[0] if drive else modes[1]


def central_checks(s: Summary, tol: float) -> list[tuple[str, float, float, bool]]:
    """The central TORSEN Type C's split: rear / front torque inside its locking band
    (:func:`central_band`, +-``tol``) while it sticks (``|central_slip| <=
    CENTRAL_STICK``), at one end of it (within ``tol``) while it slips."""
    band = central_band(s)
    if band is None:
        return []
    lo_r, hi_r = band
    r, slip = abs(s.central_ratio), s.central_slip
    if abs(slip) <= CENTRAL_STICK:
        lo, hi = lo_r * (1 - tol), hi_r * (1 + tol)
        return [(f"torsen: central sticks (slip {slip:.1e}), rear/front split inside its "
                 f"locking band ({lo:.3f}-{hi:.3f})", r, hi if r >= lo else lo,
                 lo <= r <= hi)]
    end = lo_r if abs(r / lo_r - 1) < abs(r / hi_r - 1) else hi_r
    dev = abs(r / end - 1)
    return [(f"torsen: central slips (slip {slip:.1e}), rear/front split at its TDR "
             f"{end:.3f} (relative deviation)", dev, tol, dev <= tol)]


def compare(p: Vehicle4WDFile, torsen: dict, configs: list[str], base_dir: str | Path = ".",
            t_end: float | None = None, progress=None) -> list[tuple[Summary, Any]]:
    """The same vehicle with each configuration: [(summary, results)]
    (:func:`drivedyn.analysis.vehicle_runs.compare`)."""
    return vehicle_runs.compare(sys.modules[__name__], p, torsen, configs, base_dir,
                                t_end=t_end, progress=progress)


def table(summaries: list[Summary]) -> str:
    """Markdown table of the wheel torques, splits and balances."""
    head = ("| configuration | T_fl | T_fr | T_rl | T_rr | front share | ratio front | ratio "
            "rear | traction [N] | speed [m/s] | wall [s] |")
    lines = [head, "|" + "---|" * 11]
    for s in summaries:
        W = s.wheels
        lines.append(
            f"| {s.name} | {W['fl'].torque:.2f} | {W['fr'].torque:.2f} | {W['rl'].torque:.2f} "
            f"| {W['rr'].torque:.2f} | {s.front_share:.3f} | {s.axle_ratio['front']:.3f} | "
            f"{s.axle_ratio['rear']:.3f} | {s.traction:.1f} | {s.speed:.3f} | {s.wall:.1f} |")
    return "\n".join(lines)
