"""The rear-wheel-drive vehicle's scenarios: ``static`` (the static solution on a flat road)
and ``split-mu-launch`` (a throttle ramp from rest, the left rear wheel on low friction),
their summaries and checks, and the comparison of rear differentials.

Signs: a rear wheel's *drive torque* is the reaction torque of its outboard universal joint
on the wheel about the wheel's spin axis (to the left: forward rolling positive); the tyre
force ``fx`` is positive forward. Launch quantities are means over ``run.window``.

Checks:

* ``static``: the tyre loads sum to ``m g`` (1e-6 relative) and the rear axle's share of
  them equals the one the centre of gravity gives (0.5 %);
* ``open``: the rear wheel torques are equal within 1 %;
* ``torsen-b``: the rear torque ratio (high / low) lies within the differential's analytic
  TDR range (+2 %), and the wheel with more grip gets more torque;
* ``locked``: the wheel with more grip gets more torque;
* every launch: the driveline's power balance over the window (engine = rear wheels +
  driveline dissipation + rate of driveline kinetic energy, 0.5 %) and the model's energy
  audit (1 %).

The driveline power balance is written relative to the rear carrier: the engine's power is
its torque times the shaft's speed relative to its mount on the frame (the engine torque
element's ``power``), a rear wheel's power the outboard joint's torque on the wheel times
the wheel's angular velocity relative to its upright, and the driveline's kinetic energy
``sum(w.h/2 - w_c.h)`` over its bodies (engine and propeller shafts, slip yoke, pinion
shaft, the differential's bodies, half-shafts and plungers) with ``w_c`` the carrier's
angular velocity. The bearings carry the driveline along with the vehicle; the work they do
in that (translation, the frame's pitch and roll) is left out, and it is what
the balance's error measures besides the integration's.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from drivedyn.analysis import vehicle_runs
from drivedyn.library.vehicles.vehicle_rwd import Layout, VehicleRWDFile, build_spec
from drivedyn.library.vehicles.vehicle_rwd.configurations import CONFIGS, config_name
from drivedyn.library.vehicles.vehicle_rwd.schema import WHEELS
from drivedyn.library.vehicles.vehicle_rwd.static_start import static_start

G = 9.81
SCENARIOS = ("static", "split-mu-launch", "power-on-cornering")
#: recording interval [s] of a launch
OUTPUT_DT = 5e-3


@dataclass
class WheelWindow:
    """Window means of one wheel: drive torque [N m] (0 for a front wheel), tyre forces
    [N], spin [rad/s], slip, road friction factor."""

    torque: float
    fx: float
    fz: float
    spin: float
    kappa: float
    mu_road: float


@dataclass
class StaticSummary:
    """The static solution: total mass [kg], centre of gravity (3,) [m], tyre loads [N],
    the rear share of the loads and the one the centre of gravity gives, solve time [s],
    the wheel centres' positions (3,) [m] in the static solution (x forward, y left, z up;
    the origin the model file's)."""

    mass: float
    cg: list[float]
    loads: dict[str, float]
    rear_share: float
    rear_share_cg: float
    unknowns: int
    wall: float
    note: str = ""
    wheel_centres: dict[str, list[float]] = field(default_factory=dict)


@dataclass
class LaunchSummary:
    """What a launch shows over its window (see the module docstring): the wheels' window
    means, the speed [m/s] at the window's end, the rear torque ratio, the yaw rate's mean
    [rad/s] and the lateral drift [m] at the window's end (:func:`body_motion`), the
    analytic TDR range, solver counts, the balances and the per-sample history."""

    rear: str
    wheels: dict[str, WheelWindow]
    speed: float
    axle_ratio: dict[str, float]
    left_share: float
    tdr: tuple[float, float] | None
    wall: float = 0.0
    steps: int = 0
    rejected: int = 0
    unknowns: int = 0
    newton: int = 0
    yaw_rate: float = 0.0
    drift: float = 0.0
    power_balance: float = float("nan")
    energy_error: float = float("nan")
    history: dict[str, list[float]] = field(default_factory=dict)

    @property
    def name(self) -> str:
        return config_name({"rear": self.rear})


def configure(p: VehicleRWDFile, config: str) -> VehicleRWDFile:
    """``p`` with the rear differential of ``config`` (a :data:`CONFIGS` key)."""
    if config not in CONFIGS:
        raise KeyError(f"no configuration {config!r} (known: {', '.join(CONFIGS)})")
    d = p.differentials.model_copy(update={"rear": CONFIGS[config]})
    return p.model_copy(update={"differentials": d})


def static(p: VehicleRWDFile, torsen: dict, base_dir: str | Path = ".") -> StaticSummary:
    """The static solution of the parked vehicle (no throttle; see
    :func:`~drivedyn.library.vehicles.vehicle_rwd.model.build_spec`, ``parked``)."""
    from drivedyn.model.compile import compile_model
    from drivedyn.solver.statics import solve_static
    from drivedyn.solver.system import element_outputs

    q = p.model_copy(update={"engine": p.engine.model_copy(update={"throttle": 0.0,
                                                                   "idle_throttle": 0.0})})
    note = ""
    if q.differentials.rear == "torsen-b":
        # the TORSEN's floating gears have no stiffness at rest (a singular static matrix)
        q = configure(q, "open")
        note = "solved with the open differential in place of the TORSEN (floating gears)"
    t0 = time.perf_counter()
    spec, lay = build_spec(q, torsen, base_dir, parked=True)
    model = compile_model(spec)
    st = solve_static(model, max_iter=100)
    out = element_outputs(model, st)
    wall = time.perf_counter() - t0
    loads = {w: float(out[lay.tyres[w]]["fz"]) for w in WHEELS}
    total = sum(loads.values())
    xf = 0.5 * (lay.wheel_x["fl"] + lay.wheel_x["fr"])
    xr = 0.5 * (lay.wheel_x["rl"] + lay.wheel_x["rr"])
    return StaticSummary(mass=lay.total_mass, cg=[float(c) for c in lay.cg], loads=loads,
                         rear_share=(loads["rl"] + loads["rr"]) / total,
                         rear_share_cg=float((xf - lay.cg[0]) / (xf - xr)),
                         unknowns=int(model.neq), wall=wall, note=note,
                         wheel_centres={w: [float(c) for c in st.x[model.node_index[b]]]
                                        for w, b in lay.wheels.items()})


def static_checks(s: StaticSummary) -> list[tuple[str, float, float, bool]]:
    """(name, value, limit, passed) of the static solution."""
    total = sum(s.loads.values())
    e_sum = abs(total - s.mass * G) / (s.mass * G)
    e_split = abs(s.rear_share - s.rear_share_cg) / s.rear_share_cg
    return [("static: tyre loads sum to m g (relative error)", e_sum, 1e-6, e_sum <= 1e-6),
            ("static: rear share equals the centre of gravity's (relative error)", e_split,
             5e-3, e_split <= 5e-3)]


def run(p: VehicleRWDFile, torsen: dict, base_dir: str | Path = ".",
        t_end: float | None = None, output_dt: float = OUTPUT_DT, progress=None,
        source: str = "", overrides: list[str] | tuple = ()) -> tuple[Any, Layout]:
    """Build, compile and simulate the launch: (results, layout); the results record the
    parameters, source and configuration."""
    import json

    from drivedyn.model.compile import compile_model
    from drivedyn.results.provenance import record_provenance
    from drivedyn.solver import simulate

    spec, lay = build_spec(p, torsen, base_dir)
    model = compile_model(spec)
    t_end = p.run.t_end if t_end is None else t_end
    state = static_start(p, torsen, base_dir, model, lay)
    res = simulate(model, t_end, state=state, output_dt=output_dt, progress=progress,
                   **p.solver.settings(h_max=p.run.h_max))
    record_provenance(res,
                      model_file=json.dumps(p.model_dump(mode="json", warnings=False),
                                            indent=1, default=str),
                      source=source or p.model.name, overrides=overrides,
                      library_model=p.model.library, configuration=config_name(p))
    res.neq = model.neq  # type: ignore[attr-defined]
    return res, lay


def drive_torque(res: Any, lay: Layout, w: str) -> np.ndarray:
    """Drive torque [N m] of rear wheel ``w`` per sample (see the module docstring)."""
    tq = np.stack([res.values(f"{lay.drives[w]}.torque_{c}") for c in "xyz"], axis=1)
    axis = res.values(f"{lay.wheels[w]}.rotation")[:, :, 2]
    return np.einsum("ij,ij->i", tq, axis)


def summarize(res: Any, lay: Layout, window: tuple[float, float]) -> LaunchSummary:
    """Window means of a launch."""
    t = res.time
    sel = (t >= window[0] - 1e-12) & (t <= window[1] + 1e-12)
    if sel.sum() < 3:
        raise ValueError(f"window {window} s holds {int(sel.sum())} samples; record more "
                         "densely or widen it")
    wheels = {}
    hist: dict[str, list[float]] = {"time": t.tolist()}
    for w in WHEELS:
        tq = drive_torque(res, lay, w) if w in lay.drives else np.zeros_like(t)
        axis = res.values(f"{lay.wheels[w]}.rotation")[:, :, 2]
        spin = np.einsum("ij,ij->i", res.values(f"{lay.wheels[w]}.angular_velocity"), axis)
        wheels[w] = WheelWindow(
            torque=float(np.mean(tq[sel])),
            fx=float(np.mean(res.values(f"{lay.tyres[w]}.fx")[sel])),
            fz=float(np.mean(res.values(f"{lay.tyres[w]}.fz")[sel])),
            spin=float(np.mean(spin[sel])),
            kappa=float(np.mean(res.values(f"{lay.tyres[w]}.kappa")[sel])),
            mu_road=float(np.mean(res.values(f"{lay.tyres[w]}.road_mu")[sel])))
        if w in lay.drives:
            hist[f"torque_{w}"] = tq.tolist()
        hist[f"spin_{w}"] = spin.tolist()
        hist[f"kappa_{w}"] = res.values(f"{lay.tyres[w]}.kappa").tolist()
    tl, tr = wheels["rl"].torque, wheels["rr"].torque
    body = body_motion(res)
    for k, v_ in body.items():
        hist[k] = v_.tolist()
    v = res.values(f"{lay.wheels['fl']}.velocity")[:, 0]
    st = res.stats
    i0, i1 = np.flatnonzero(sel)[[0, -1]]
    pb, _ = power_balance(res, lay, int(i0), int(i1))
    wi = res.values("energy.work_in")[i1]
    ee = abs(res.values("energy.balance_error")[i1]) / max(abs(wi), 1e-12)
    return LaunchSummary(
        rear=lay.rear_type, wheels=wheels, speed=float(v[np.flatnonzero(sel)[-1]]),
        axle_ratio={"rear": _ratio(tl, tr)}, left_share=tl / (tl + tr) if tl + tr else np.nan,
        tdr=lay.tdr, wall=st.wall_s, steps=st.steps, rejected=st.rejected,
        unknowns=int(getattr(res, "neq", 0)), newton=st.newton_iterations,
        power_balance=pb, energy_error=float(ee),
        yaw_rate=float(np.mean(body["yaw_rate"][sel])), drift=float(body["drift"][i1]),
        history=hist)


def body_motion(res: Any) -> dict[str, np.ndarray]:
    """Per sample: the vehicle's forward ``speed`` [m/s], ``yaw_rate`` [rad/s] (about z,
    positive to the left) and lateral ``drift`` [m] (y displacement from the start, positive
    to the left), each the mean over the body's carriers (``frame.body.*``, one at each body
    mount on each rail: the sprung mass, not a frame node's vibration)."""
    names = sorted({n.rsplit(".", 1)[0] for n in res.names()
                    if n.startswith("frame.body.") and n.endswith(".velocity")})
    v = np.mean([res.values(f"{n}.velocity")[:, 0] for n in names], axis=0)
    r = np.mean([res.values(f"{n}.angular_velocity")[:, 2] for n in names], axis=0)
    y = np.mean([res.values(f"{n}.position")[:, 1] for n in names], axis=0)
    return {"speed": v, "yaw_rate": r, "drift": y - y[0]}


#: name prefixes of the driveline's bodies and elements (see the module docstring)
DRIVELINE = ("engine", "prop", "pinion", "rear_", "halfshaft_", "plunger_")


def _integral(res: Any, p: np.ndarray, i0: int, i1: int) -> float:
    return float(np.trapezoid(p[i0:i1 + 1], res.time[i0:i1 + 1]))


def power_balance(res: Any, lay: Layout, i0: int, i1: int) -> tuple[float, float]:
    """The driveline's power balance between samples ``i0`` and ``i1`` (see the module
    docstring): (|W_engine - W_wheels - D_driveline - dK_driveline| / |W_engine|, W_engine
    [J])."""
    names = res.names()
    w_eng = _integral(res, res.values(f"{lay.engine}.power"), i0, i1)
    w_wheels = 0.0
    for w, joint in lay.drives.items():
        m = np.stack([res.values(f"{joint}.torque_{c}") for c in "xyz"], axis=1)
        w_rel = (res.values(f"{lay.wheels[w]}.angular_velocity")
                 - res.values(f"{lay.uprights[w]}.angular_velocity"))
        w_wheels += _integral(res, np.einsum("ij,ij->i", m, w_rel), i0, i1)
    d_dl = sum(float(res.values(n)[i1] - res.values(n)[i0]) for n in names
               if n.endswith(".dissipated_energy") and n.startswith(DRIVELINE))
    bodies = [n[:-len(".angular_momentum")] for n in names
              if n.endswith(".angular_momentum") and n.startswith(DRIVELINE)]
    w_c = res.values("carrier.angular_velocity")

    def kinetic(i: int) -> float:
        k = 0.0
        for b in bodies:
            w, h = res.values(f"{b}.angular_velocity")[i], res.values(f"{b}.angular_momentum")[i]
            k += 0.5 * float(w @ h) - float(w_c[i] @ h)
        return k

    err = w_eng - w_wheels - d_dl - (kinetic(i1) - kinetic(i0))
    return (abs(err) / abs(w_eng) if w_eng else float("nan")), w_eng


def _ratio(a: float, b: float) -> float:
    lo = min(abs(a), abs(b))
    return max(abs(a), abs(b)) / lo if lo > 0 else float("inf")


def checks(s: LaunchSummary, tol: float = 0.02) -> list[tuple[str, float, float, bool]]:
    """(name, value, limit, passed) of a launch."""
    out: list[tuple[str, float, float, bool]] = []
    left, right = s.wheels["rl"], s.wheels["rr"]
    if s.name == "open":
        dev = abs(left.torque - right.torque) / (0.5 * abs(left.torque + right.torque))
        out.append(("open: rear wheel torques equal (relative difference)", dev, 0.01,
                    dev <= 0.01))
    if abs(left.mu_road - right.mu_road) > 1e-12 and s.name in ("locked", "torsen-b",
                                                                 "clutch"):
        hi, lo = (left, right) if left.mu_road > right.mu_road else (right, left)
        out.append((f"{s.name}: higher-friction rear wheel gets more torque",
                    abs(hi.torque) / max(abs(lo.torque), 1e-300), 1.0,
                    abs(hi.torque) > abs(lo.torque)))
    if s.name == "torsen-b" and s.tdr:
        lim = s.tdr[1] * (1 + tol)
        r = s.axle_ratio["rear"]
        out.append(("torsen-b: rear torque ratio within the analytic TDR", r, lim, r <= lim))
    out.append((f"{s.name}: driveline power balance", s.power_balance, 5e-3,
                s.power_balance <= 5e-3))
    out.append((f"{s.name}: energy audit (balance error / work in)", s.energy_error, 1e-2,
                s.energy_error <= 1e-2))
    return out


def compare(p: VehicleRWDFile, torsen: dict, configs: list[str], base_dir: str | Path = ".",
            t_end: float | None = None, progress=None) -> list[tuple[LaunchSummary, Any]]:
    """The same vehicle with each configuration: [(summary, results)]
    (:func:`drivedyn.analysis.vehicle_runs.compare`)."""
    return vehicle_runs.compare(sys.modules[__name__], p, torsen, configs, base_dir,
                                t_end=t_end, progress=progress)


def table(summaries: list[LaunchSummary]) -> str:
    """Markdown table of the rear wheel torques and ratios."""
    lines = ["| configuration | T_rl [N m] | T_rr [N m] | ratio | kappa_rl | kappa_rr | "
             "speed [m/s] | steps | wall [s] |", "|" + "---|" * 9]
    for s in summaries:
        W = s.wheels
        lines.append(f"| {s.name} | {W['rl'].torque:.1f} | {W['rr'].torque:.1f} | "
                     f"{s.axle_ratio['rear']:.3f} | {W['rl'].kappa:.3f} | {W['rr'].kappa:.3f}"
                     f" | {s.speed:.3f} | {s.steps} | {s.wall:.1f} |")
    return "\n".join(lines)


__all__ = [
    "CONFIGS",
    "SCENARIOS",
    "LaunchSummary",
    "StaticSummary",
    "checks",
    "compare",
    "config_name",
    "configure",
    "drive_torque",
    "power_balance",
    "run",
    "static",
    "static_checks",
    "summarize",
    "table",
]
