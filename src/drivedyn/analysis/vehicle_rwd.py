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
* ``locked``: the wheel with more grip gets more torque.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from drivedyn.library.vehicles.vehicle_rwd import Layout, VehicleRWDFile, build_spec
from drivedyn.library.vehicles.vehicle_rwd.configurations import CONFIGS, config_name
from drivedyn.library.vehicles.vehicle_rwd.schema import WHEELS

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
    the rear share of the loads and the one the centre of gravity gives, solve time [s]."""

    mass: float
    cg: list[float]
    loads: dict[str, float]
    rear_share: float
    rear_share_cg: float
    unknowns: int
    wall: float
    note: str = ""


@dataclass
class LaunchSummary:
    """What a launch shows over its window (see the module docstring)."""

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

    q = p.model_copy(update={"engine": p.engine.model_copy(update={"throttle": 0.0})})
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
                         unknowns=int(model.neq), wall=wall, note=note)


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
    record_provenance(res.dataset,
                      model_file=json.dumps(p.model_dump(mode="json", warnings=False),
                                            indent=1, default=str),
                      source=source or p.model.name, overrides=overrides,
                      library_model=p.model.library, configuration=config_name(p))
    res.neq = model.neq  # type: ignore[attr-defined]
    return res, lay


def _minimal_rotation(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The rotation turning unit vector ``a`` onto unit vector ``b`` about their normal."""
    c = float(a @ b)
    k = np.cross(a, b)
    s = float(np.linalg.norm(k))
    if s < 1e-15:
        return np.eye(3)
    k /= s
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + s * K + (1.0 - c) * K @ K


def static_start(p: VehicleRWDFile, torsen: dict, base_dir: str | Path, model: Any,
                 lay: Layout) -> Any:
    """The initial state of ``model`` moved to the static equilibrium of the parked vehicle
    (:func:`static`'s solution), so that a run does not begin with the frame springing back
    from its unloaded shape (it sags by 10 mm under the body).

    Every body and node the two models share takes its static position and orientation,
    except the differential's (``rear_*``: they move rigidly with the rear carrier, since a
    TORSEN is solved as the open differential) and the half-shafts and plungers (turned
    about their inner joint so that the shaft reaches its wheel's static centre; the plunger
    slides). Velocities stay the model's own (the vehicle's speed, the wheels' spins)."""
    from drivedyn.model.compile import compile_model
    from drivedyn.solver.statics import solve_static

    q = p.model_copy(update={"engine": p.engine.model_copy(update={"throttle": 0.0})})
    if q.differentials.rear == "torsen-b":
        q = configure(q, "open")
    spec_s, _ = build_spec(q, torsen, base_dir, parked=True)
    ms = compile_model(spec_s)
    ss = solve_static(ms, max_iter=100)
    s0 = ms.initial_state()
    st = model.initial_state()
    x0 = st.x.copy()
    R0 = st.R.copy()
    jc = ms.node_index["carrier"]
    Qc = ss.R[jc] @ s0.R[jc].T

    def carried(point: np.ndarray) -> np.ndarray:
        return ss.x[jc] + Qc @ (point - s0.x[jc])

    def axis(node: int, marker: str, col: int) -> np.ndarray:
        return st.R[node] @ model.marker_frames[marker][2][:, col]

    rigid = ("rear_", "carrier", "propshaft")  # on the carrier, spins kept
    for name, i in model.node_index.items():
        if name.startswith(rigid):
            st.x[i] = carried(x0[i])
            st.R[i] = Qc @ R0[i]
        elif not name.startswith(("halfshaft_", "plunger_", "wheel_", "frame.body.")) \
                and name in ms.node_index:
            j = ms.node_index[name]  # the static displacement (the models may differ a little)
            st.x[i] = x0[i] + ss.x[j] - s0.x[j]
            st.R[i] = ss.R[j] @ s0.R[j].T @ R0[i]
    for name, i in model.node_index.items():  # the body's carriers: rigid with their node
        if name.startswith("frame.body.") and f"{name}.mount" in model.marker_frames:
            n = model.marker_frames[f"{name}.mount"][0]
            Qn = st.R[n] @ R0[n].T
            st.x[i] = st.x[n] + Qn @ (x0[i] - x0[n])
            st.R[i] = Qn @ R0[i]
    for w in WHEELS:  # the wheels turn with their uprights (their spins kept)
        wh = model.node_index[lay.wheels[w]]
        up = model.marker_frames[f"{lay.wheels[w]}_bearing_hub"][0]
        st.R[wh] = st.R[up] @ R0[up].T @ R0[wh]
        st.x[wh] = ss.x[ms.node_index[lay.wheels[w]]]
    for w in lay.drives:
        hs, pl, wh = (model.node_index[n] for n in (f"halfshaft_{w}", f"plunger_{w}",
                                                    lay.wheels[w]))
        p_in = x0[hs] + R0[hs] @ model.marker_frames[f"halfshaft_{w}_in"][1]
        p_in_new = carried(p_in)
        outer_new = st.x[wh] + (x0[pl] - x0[wh])
        a_old = Qc @ (x0[pl] - p_in) / np.linalg.norm(x0[pl] - p_in)
        a_new = (outer_new - p_in_new) / np.linalg.norm(outer_new - p_in_new)
        # with the carrier (the inner joint's cross stays square), then onto the wheel
        Q = _minimal_rotation(a_old, a_new) @ Qc
        st.x[hs] = p_in_new + Q @ (x0[hs] - p_in)
        st.R[hs] = Q @ R0[hs]
        st.x[pl] = outer_new
        st.R[pl] = Q @ R0[pl]
        # the wheel's spin angle that keeps the outer joint's cross square
        u = axis(pl, f"plunger_{w}_out", 0)
        k = st.R[wh][:, 2]
        v = axis(wh, f"halfshaft_{w}_wheel", 1)
        th = np.arctan2(-(u @ v), u @ np.cross(k, v))
        c, s_ = np.cos(th), np.sin(th)
        K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
        st.R[wh] = (np.eye(3) + s_ * K + (1.0 - c) * K @ K) @ st.R[wh]
    return st


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
    tl, tr = wheels["rl"].torque, wheels["rr"].torque
    v = res.values(f"{lay.wheels['fl']}.velocity")[:, 0]
    st = res.stats
    return LaunchSummary(
        rear=lay.rear_type, wheels=wheels, speed=float(v[np.flatnonzero(sel)[-1]]),
        axle_ratio={"rear": _ratio(tl, tr)}, left_share=tl / (tl + tr) if tl + tr else np.nan,
        tdr=lay.tdr, wall=st.wall_s, steps=st.steps, rejected=st.rejected,
        unknowns=int(getattr(res, "neq", 0)), history=hist)


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
    return out


def compare(p: VehicleRWDFile, torsen: dict, configs: list[str], base_dir: str | Path = ".",
            t_end: float | None = None, progress=None) -> list[tuple[LaunchSummary, Any]]:
    """The same launch with each configuration: [(summary, results)]."""
    out = []
    for c in configs:
        q = configure(p, c)
        t0 = time.perf_counter()
        res, lay = run(q, torsen, base_dir, t_end=t_end, progress=progress)
        s = summarize(res, lay, q.run.window)
        s.wall = time.perf_counter() - t0
        out.append((s, res))
    return out


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
    "run",
    "static",
    "static_checks",
    "summarize",
    "table",
]
