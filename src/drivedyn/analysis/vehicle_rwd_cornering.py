"""The RWD vehicle's ``power-on-cornering`` scenario: a steady circle at constant speed
and steer, then a throttle ramp; its summaries and checks.

The vehicle (:mod:`drivedyn.library.vehicles.vehicle_rwd.cornering`) starts straight at the
scenario's speed from the parked vehicle's static equilibrium
(:func:`~drivedyn.analysis.vehicle_rwd.static_start`); the pinion angle rises smoothly to
its value and is held; a PI speed controller holds the speed with the engine torque until
the throttle ramp, then its output is held and the ramp adds to it. The summaries are means
over two windows of ``[scenarios.power_on_cornering]``: ``steady_window`` (the steady
circle) and ``power_window`` (power on).

Quantities (left turn positive, vehicle axes): the yaw rate ``r`` [rad/s] of the frame's
node at the speed sensor (on the centre line near the centre of gravity), the speed ``V``
[m/s] of that node (horizontal), the path radius ``R = V / r`` [m], the lateral
acceleration ``a_y = V r`` [m/s^2] and, to check it, the tyres' horizontal forces across
the path (normal to the velocity) over the mass. Wheel quantities as in the launch
(:mod:`drivedyn.analysis.vehicle_rwd`), with the lateral force ``fy`` [N] and slip angle
``alpha`` [rad]; the rear torque split is the inner rear wheel's share of the rear axle's
drive torque (the inner wheel is on the side the vehicle turns to).

Checks:

* the controller holds the speed: over the steady window the sensor's speed stays within
  :data:`SPEED_TOLERANCE` of the reference (relative);
* steady circle: ``V r`` equals the tyres' force across the path over the mass within
  :data:`AY_TOLERANCE` (relative);
* ``open``: the rear wheel torques equal within 1 % over the power window;
* ``locked``: the rear wheels turn together (spins equal within 1e-3, relative) over the
  power window (the inner wheel, which has the shorter path, then drives and the outer one
  is dragged: the torque goes to the inner wheel);
* ``clutch``, ``torsen-b``: the slower rear wheel gets more torque over the power window
  (the differential's friction opposes the wheels' relative motion);
* ``torsen-b``: the rear torque ratio within the differential's analytic TDR range (+2 %).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from drivedyn.library.vehicles.vehicle_rwd import Layout, VehicleRWDFile
from drivedyn.library.vehicles.vehicle_rwd.configurations import config_name
from drivedyn.library.vehicles.vehicle_rwd.cornering import Cornering, build_cornering
from drivedyn.library.vehicles.vehicle_rwd.scenario_schema import PowerOnCornering
from drivedyn.library.vehicles.vehicle_rwd.schema import WHEELS

SCENARIO = "power-on-cornering"
#: largest speed deviation from the reference over the steady window (relative)
SPEED_TOLERANCE = 5e-3
#: V r against the tyres' force across the path over the mass (relative)
AY_TOLERANCE = 0.02
#: recording interval [s]
OUTPUT_DT = 5e-3
#: the outputs :func:`window_means` and :func:`summarize` read (for ``run(variables=...)``)
WINDOW_VARIABLES = ["frame.*.velocity", "frame.*.angular_velocity", "wheel_*.rotation",
                    "wheel_*.angular_velocity", "tyre_*.*", "halfshaft_*_outer.torque_*",
                    "speed_control.*"]


@dataclass
class CornerWheel:
    """Window means of one wheel: drive torque [N m] (0 for a front wheel), tyre forces
    [N], spin [rad/s], longitudinal slip, slip angle [rad]."""

    torque: float
    fx: float
    fy: float
    fz: float
    spin: float
    kappa: float
    alpha: float


@dataclass
class CorneringWindow:
    """Means over one window (see the module docstring): sensor speed and its largest
    deviation from the reference [m/s], horizontal speed [m/s], yaw rate [rad/s], lateral
    acceleration ``V r`` and from the tyres [m/s^2], path radius [m], the wheels, the rear
    torque ratio (high / low) and the inner rear wheel's share."""

    window: tuple[float, float]
    speed: float
    speed_deviation: float
    reference_speed: float
    ground_speed: float
    yaw_rate: float
    lateral_acceleration: float
    lateral_acceleration_tyres: float
    radius: float
    wheels: dict[str, CornerWheel]
    axle_ratio: dict[str, float]
    inner_share: float


@dataclass
class CorneringSummary:
    """A run of the scenario: its configuration, the two windows, the analytic TDR range of
    a TORSEN (else None), cost, and a time history."""

    rear: str
    steady: CorneringWindow
    power: CorneringWindow
    tdr: tuple[float, float] | None
    wall: float = 0.0
    steps: int = 0
    rejected: int = 0
    unknowns: int = 0
    history: dict[str, list[float]] = field(default_factory=dict)

    @property
    def name(self) -> str:
        return config_name({"rear": self.rear})


def run(p: VehicleRWDFile, torsen: dict, base_dir: str | Path = ".",
        c: PowerOnCornering | None = None, output_dt: float = OUTPUT_DT, progress=None,
        source: str = "", overrides: list[str] | tuple = (), steer: Any = None,
        reference: Any = None, variables: list[str] | None = None
        ) -> tuple[Any, Layout, Cornering]:
    """Build, compile and simulate the scenario ``c`` (default the file's): (results,
    layout, cornering). ``steer``: the pinion angle's time function, ``reference``: the
    reference speed's (defaults: the scenario's); ``variables``: the outputs to keep (glob
    patterns, default all; :data:`WINDOW_VARIABLES` keeps what the summaries read)."""
    import json

    from drivedyn.analysis.vehicle_rwd import static_start
    from drivedyn.model.compile import compile_model
    from drivedyn.results.provenance import record_provenance
    from drivedyn.solver import simulate

    c = p.scenarios.power_on_cornering if c is None else c
    spec, lay, cor, q = build_cornering(p, c, torsen, base_dir, reference=reference,
                                        steer=steer)
    model = compile_model(spec)
    state = static_start(q, torsen, base_dir, model, lay)
    res = simulate(model, c.t_end, state=state, output_dt=output_dt, progress=progress,
                   variables=variables, **p.solver.settings(h_max=c.h_max))
    record_provenance(res,
                      model_file=json.dumps(p.model_dump(mode="json", warnings=False),
                                            indent=1, default=str),
                      source=source or p.model.name, overrides=overrides,
                      library_model=p.model.library, configuration=config_name(p))
    res.neq = model.neq  # type: ignore[attr-defined]
    return res, lay, cor


def _heading(axis: np.ndarray) -> np.ndarray:
    """Unit horizontal headings (n, 3) of wheels whose spin axes (to their left) are the
    rows of ``axis``."""
    h = np.stack([axis[:, 1], -axis[:, 0], np.zeros(len(axis))], axis=1)
    return h / np.linalg.norm(h, axis=1)[:, None]


def window_means(res: Any, lay: Layout, cor: Cornering, window: tuple[float, float],
                 reference: float) -> CorneringWindow:
    """Means over ``window`` [s] (see the module docstring); ``reference``: the reference
    speed [m/s]."""
    from drivedyn.analysis.vehicle_rwd import drive_torque

    t = res.time
    sel = (t >= window[0] - 1e-12) & (t <= window[1] + 1e-12)
    if sel.sum() < 3:
        raise ValueError(f"window {window} s holds {int(sel.sum())} samples; record more "
                         "densely or widen it")
    u = res.values(f"{cor.controller}.speed")[sel]
    v = res.values(f"{cor.node}.velocity")[sel]
    r = res.values(f"{cor.node}.angular_velocity")[sel][:, 2]
    V = np.hypot(v[:, 0], v[:, 1])
    across = np.stack([-v[:, 1], v[:, 0]], axis=1) / V[:, None]  # z x v / |v|
    f_across = np.zeros(len(V))
    wheels = {}
    for w in WHEELS:
        axis = res.values(f"{lay.wheels[w]}.rotation")[:, :, 2]
        spin = np.einsum("ij,ij->i", res.values(f"{lay.wheels[w]}.angular_velocity"), axis)
        tq = drive_torque(res, lay, w) if w in lay.drives else np.zeros_like(t)
        fx = res.values(f"{lay.tyres[w]}.fx")[sel]
        fy = res.values(f"{lay.tyres[w]}.fy")[sel]
        ex = _heading(axis[sel])
        ey = np.stack([-ex[:, 1], ex[:, 0]], axis=1)
        F = fx[:, None] * ex[:, :2] + fy[:, None] * ey
        f_across += np.einsum("ij,ij->i", F, across)
        wheels[w] = CornerWheel(
            torque=float(np.mean(tq[sel])), fx=float(np.mean(fx)), fy=float(np.mean(fy)),
            fz=float(np.mean(res.values(f"{lay.tyres[w]}.fz")[sel])),
            spin=float(np.mean(spin[sel])),
            kappa=float(np.mean(res.values(f"{lay.tyres[w]}.kappa")[sel])),
            alpha=float(np.mean(res.values(f"{lay.tyres[w]}.alpha")[sel])))
    tl, tr = wheels["rl"].torque, wheels["rr"].torque
    yaw = float(np.mean(r))
    inner = tl if yaw >= 0.0 else tr
    lo, hi = sorted((abs(tl), abs(tr)))
    return CorneringWindow(
        window=(float(window[0]), float(window[1])), speed=float(np.mean(u)),
        speed_deviation=float(np.max(np.abs(u - reference))), reference_speed=reference,
        ground_speed=float(np.mean(V)), yaw_rate=yaw,
        lateral_acceleration=float(np.mean(V * r)),
        lateral_acceleration_tyres=float(np.mean(f_across)) / lay.total_mass,
        radius=float(np.mean(V)) / yaw if yaw != 0.0 else float("inf"),
        wheels=wheels, axle_ratio={"rear": hi / lo if lo > 0 else float("inf")},
        inner_share=inner / (tl + tr) if tl + tr else float("nan"))


def summarize(res: Any, lay: Layout, cor: Cornering, c: PowerOnCornering
              ) -> CorneringSummary:
    """The scenario's two windows, cost and history (every recorded sample: time, sensor
    speed, yaw rate, ``V r``, rear drive torques and loads)."""
    from drivedyn.analysis.vehicle_rwd import drive_torque

    v = res.values(f"{cor.node}.velocity")
    r = res.values(f"{cor.node}.angular_velocity")[:, 2]
    hist = {"time": res.time.tolist(),
            "speed": res.values(f"{cor.controller}.speed").tolist(),
            "yaw_rate": r.tolist(),
            "lateral_acceleration": (np.hypot(v[:, 0], v[:, 1]) * r).tolist()}
    for w in lay.drives:
        hist[f"torque_{w}"] = drive_torque(res, lay, w).tolist()
        hist[f"fz_{w}"] = res.values(f"{lay.tyres[w]}.fz").tolist()
    st = res.stats
    return CorneringSummary(
        rear=lay.rear_type, steady=window_means(res, lay, cor, c.steady_window, c.speed),
        power=window_means(res, lay, cor, c.power_window, c.speed), tdr=lay.tdr,
        wall=st.wall_s, steps=st.steps, rejected=st.rejected,
        unknowns=int(getattr(res, "neq", 0)), history=hist)


def checks(s: CorneringSummary, tol: float = 0.02) -> list[tuple[str, float, float, bool]]:
    """(name, value, limit, passed) of a run (see the module docstring)."""
    st, pw = s.steady, s.power
    dev = st.speed_deviation / st.reference_speed
    e_ay = abs(st.lateral_acceleration - st.lateral_acceleration_tyres) / abs(
        st.lateral_acceleration_tyres)
    out = [("steady circle: speed within the controller's tolerance (largest relative "
            "deviation)", dev, SPEED_TOLERANCE, dev <= SPEED_TOLERANCE),
           ("steady circle: V r equals the tyres' force across the path over the mass "
            "(relative)", e_ay, AY_TOLERANCE, e_ay <= AY_TOLERANCE)]
    left, right = pw.wheels["rl"], pw.wheels["rr"]
    if s.name == "open":
        d = abs(left.torque - right.torque) / (0.5 * abs(left.torque + right.torque))
        out.append(("open: rear wheel torques equal, power on (relative difference)", d, 0.01,
                    d <= 0.01))
    elif s.name == "locked":
        d = abs(left.spin - right.spin) / (0.5 * abs(left.spin + right.spin))
        out.append(("locked: rear wheels turn together, power on (relative spin difference)",
                    d, 1e-3, d <= 1e-3))
    else:
        slow, fast = (left, right) if left.spin < right.spin else (right, left)
        out.append((f"{s.name}: the slower rear wheel gets more torque, power on",
                    slow.torque / fast.torque if fast.torque else float("inf"), 1.0,
                    slow.torque > fast.torque))
    if s.name == "torsen-b" and s.tdr:
        lim = s.tdr[1] * (1 + tol)
        ratio = pw.axle_ratio["rear"]
        out.append(("torsen-b: rear torque ratio within the analytic TDR, power on", ratio,
                    lim, ratio <= lim))
    return out


def compare(p: VehicleRWDFile, torsen: dict, configs: list[str], base_dir: str | Path = ".",
            progress=None) -> list[tuple[CorneringSummary, Any]]:
    """The scenario with each configuration: [(summary, results)]."""
    from drivedyn.analysis.vehicle_rwd import configure

    out = []
    for name in configs:
        q = configure(p, name)
        t0 = time.perf_counter()
        res, lay, cor = run(q, torsen, base_dir, progress=progress)
        s = summarize(res, lay, cor, q.scenarios.power_on_cornering)
        s.wall = time.perf_counter() - t0
        out.append((s, res))
    return out


def window_dict(w: CorneringWindow) -> dict[str, Any]:
    """A window as the JSON output gives it."""
    return {"window": list(w.window), "speed": w.speed,
            "speed_deviation": w.speed_deviation, "ground_speed": w.ground_speed,
            "yaw_rate": w.yaw_rate, "lateral_acceleration": w.lateral_acceleration,
            "lateral_acceleration_tyres": w.lateral_acceleration_tyres, "radius": w.radius,
            "wheels": {k: vars(x) for k, x in w.wheels.items()}, "axle_ratio": w.axle_ratio,
            "inner_share": w.inner_share}


def table(summaries: list[CorneringSummary]) -> str:
    """Markdown table of both windows of each run."""
    lines = ["| configuration | window | V [m/s] | r [rad/s] | a_y [m/s^2] | R [m] | "
             "T_rl [N m] | T_rr [N m] | inner share | Fz_rl [N] | Fz_rr [N] | kappa_rl | "
             "kappa_rr |", "|" + "---|" * 13]
    for s in summaries:
        for label, w in (("steady", s.steady), ("power", s.power)):
            W = w.wheels
            lines.append(f"| {s.name} | {label} | {w.ground_speed:.3f} | {w.yaw_rate:.4f} | "
                         f"{w.lateral_acceleration:.3f} | {w.radius:.2f} | "
                         f"{W['rl'].torque:.1f} | {W['rr'].torque:.1f} | "
                         f"{w.inner_share:.3f} | {W['rl'].fz:.0f} | {W['rr'].fz:.0f} | "
                         f"{W['rl'].kappa:.4f} | {W['rr'].kappa:.4f} |")
    return "\n".join(lines)
