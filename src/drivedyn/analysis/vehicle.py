"""Vehicle configuration of the TORSEN Type C (seed 003, Fig. 10-11): torque split per level.

The engine torque acts on the housing and steps through ``vehicle.torque_levels`` (each held
for ``vehicle.hold`` after a smooth ramp of ``vehicle.ramp``); both output speeds are
prescribed (front = sun, rear = coupling, rear - front = ``vehicle.speed_diff`` of the level).

Signs: the speed drivers' torques (``front_speed.torque``, ``rear_speed.torque``) are the
torques they apply on the sun and the coupling; the *output torques* reported here are the
torques the outputs deliver to the axles, their negatives, so that in equilibrium
``front + rear = housing`` (engine torque about +z, positive = drive).

Each level is analysed over the last 60 % of its hold (the transient of the ramp has died
out): window means of the three torques, the relative balance error
``|T_h - (T_f + T_r)| / |T_h|``, the locking mode and the torque distribution ratio (TDR,
the favoured axle's torque over the other's: in drive the slower axle is favoured, in coast
the faster one), and the quasi-static TDR of :func:`drivedyn.analysis.analytic_tdr.solve` at
the same speeds and housing torque.

Cost: the shipped profile (12 loaded levels) is timed in the README. Avoid long holds at
exactly zero torque: the meshes then hover within nanometres of contact, where the gear
element lends its stiffness to the iteration matrix (``TANGENT_BAND`` in
:mod:`drivedyn.elements.gears`) but not to the residual; the axially free sun then converges
only linearly in Newton (rate ``K / (K + M / (beta' h^2))``) and the step stays near
1e-5 s (measured: 10-15 min of wall time per simulated second at zero torque).
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from drivedyn.library.torsen_c import MODES, vehicle_spec
from drivedyn.library.torsen_c_schema import TorsenCFile

#: fraction of each hold (its end) over which a level is averaged
WINDOW_FRACTION = 0.6
#: default sampling: at least this many output samples per analysis window
WINDOW_SAMPLES = 50
#: housing torques below this [N m] count as zero (no locking mode)
ZERO_TORQUE = 1e-9


@dataclass
class VehicleRun:
    """One simulated vehicle profile.

    Attributes:
        results: the :class:`~drivedyn.results.results.Results` of the run (partial when the
            run failed).
        wall_s: wall time [s], compilation included.
        success: the run reached the end of the profile.
        message: solver message when it did not.
        levels: one dict per held level whose window the run covered (see :func:`level_stats`).
        params: the parameters of the run.
    """

    results: Any = None
    wall_s: float = 0.0
    success: bool = True
    message: str = ""
    levels: list[dict] = field(default_factory=list)
    params: TorsenCFile | None = None


def level_windows(p: TorsenCFile) -> list[tuple[float, float, float]]:
    """(hold start, window start, window end) [s] of each level of the profile
    (as :func:`drivedyn.library.torsen_c.vehicle_profile`: level i is held from
    ``(i + 1) ramp + i hold`` for ``hold``)."""
    v = p.vehicle
    out = []
    for i in range(len(v.torque_levels)):
        t0 = (i + 1) * v.ramp + i * v.hold
        t1 = t0 + v.hold
        out.append((t0, t1 - WINDOW_FRACTION * v.hold, t1))
    return out


def mode_of(torque: float, speed_diff: float) -> tuple[int | None, str | None]:
    """(mode number 1-4 as in :data:`~drivedyn.library.torsen_c.MODES`, favoured output
    ``"rear"``/``"front"``) for a housing torque and a rear-minus-front speed difference;
    (None, None) without torque or without speed difference."""
    if abs(torque) <= ZERO_TORQUE or speed_diff == 0:
        return None, None
    drive = torque > 0
    rear_slower = speed_diff < 0
    favoured = "rear" if drive == rear_slower else "front"
    for num, _, side, is_drive in MODES:
        if side == favoured and is_drive == drive:
            return num, favoured
    raise AssertionError("unreachable")  # pragma: no cover


def _window_mean(res, name: str, k: np.ndarray, comp: int | None = None) -> float:
    v = res[name].values[k]
    return float((v[:, comp] if comp is not None else v).mean())


def _power_loss(res, k: np.ndarray) -> float:
    """Window mean of input minus output power [W] (engine on the housing, drivers)."""
    p = (res["engine_torque.torque_z"].values[k] * res["housing.angular_velocity"].values[k, 2]
         + res["front_speed.torque"].values[k] * res["sun.angular_velocity"].values[k, 2]
         + res["rear_speed.torque"].values[k] * res["coupling.angular_velocity"].values[k, 2])
    return float(p.mean())


def level_stats(p: TorsenCFile, res, index: int, window: tuple[float, float],
                friction_scale: float = 1.0) -> dict | None:
    """Statistics of level ``index`` over ``window`` [s], or None if the results do not
    cover it (``friction_scale`` as in the run, for the analytic model).

    Keys: ``level``, ``t0``, ``t1`` (window), ``nominal`` (N m), ``housing``, ``front``,
    ``rear`` (output torques to the axles, N m), ``w_housing``, ``w_front``, ``w_rear``
    (rad/s), ``balance_error`` (relative, None without torque), ``mode``, ``mode_name``,
    ``favoured``, ``tdr`` and ``tdr_analytic`` (None without a mode), ``analytic_front``,
    ``analytic_rear`` (N m), ``tdr_error`` (relative, simulated vs analytic), ``power_loss``
    (input minus output power, W) and ``dissipated`` (mean dissipated power of all elements,
    W; equal to the loss when the window is steady).
    """
    t = res["time"].values
    if t.size == 0 or t[-1] < window[1] - 1e-9:
        return None
    k = (t >= window[0] - 1e-12) & (t <= window[1] + 1e-12)
    if k.sum() < 2:
        return None
    th = _window_mean(res, "engine_torque.torque_z", k)
    tf = -_window_mean(res, "front_speed.torque", k)
    tr = -_window_mean(res, "rear_speed.torque", k)
    wh = _window_mean(res, "housing.angular_velocity", k, 2)
    wf = _window_mean(res, "sun.angular_velocity", k, 2)
    wr = _window_mean(res, "coupling.angular_velocity", k, 2)
    mode, fav = mode_of(th, wr - wf)
    names = [str(n) for n in res.dataset.data_vars if str(n).endswith(".dissipated_power")]
    out: dict[str, Any] = {
        "level": index, "t0": float(window[0]), "t1": float(window[1]),
        "nominal": float(p.vehicle.torque_levels[index]),
        "housing": th, "front": tf, "rear": tr, "w_housing": wh, "w_front": wf, "w_rear": wr,
        "balance_error": abs(th - (tf + tr)) / abs(th) if abs(th) > ZERO_TORQUE else None,
        "mode": mode, "mode_name": MODES[mode - 1][1] if mode else None, "favoured": fav,
        "tdr": None, "tdr_analytic": None, "analytic_front": None, "analytic_rear": None,
        "tdr_error": None, "power_loss": _power_loss(res, k),
        "dissipated": float(sum(res[n].values[k].mean() for n in names)),
    }
    if mode is None:
        return out
    from drivedyn.analysis.analytic_tdr import solve

    try:
        q = solve(p, (wh, wf, wr), known="housing", torque=th, friction_scale=friction_scale)
    except RuntimeError as exc:  # no quasi-static equilibrium: report the simulation only
        out["analytic_message"] = str(exc)
        q = None
    tdr = tr / tf if fav == "rear" else tf / tr
    out["tdr"] = tdr
    if q is None:
        return out
    af, ar = -float(q.torque_sun), -float(q.torque_coupling)
    tdr_a = ar / af if fav == "rear" else af / ar
    out.update(tdr=tdr, tdr_analytic=tdr_a, analytic_front=af, analytic_rear=ar,
               tdr_error=tdr / tdr_a - 1.0)
    return out


def analyse(p: TorsenCFile, res, friction_scale: float = 1.0) -> list[dict]:
    """:func:`level_stats` of every level the results cover."""
    out = []
    for i, (_, t0, t1) in enumerate(level_windows(p)):
        s = level_stats(p, res, i, (t0, t1), friction_scale)
        if s is not None:
            out.append(s)
    return out


def reversals(levels: list[dict], res) -> list[dict]:
    """Axial motion across each sign reversal of the housing torque between consecutive
    loaded levels (zero-torque levels in between are skipped): change of the window-mean
    axial position [m] of sun, ring and coupling (``d_sun``, ``d_ring``, ``d_coupling``)
    from the level before to the level after (``from_level``, ``to_level``,
    ``from_torque``, ``to_torque``)."""
    t = res["time"].values
    out = []
    loaded = [lv for lv in levels if abs(lv["housing"]) > ZERO_TORQUE]
    for a, b in itertools.pairwise(loaded):
        if a["housing"] * b["housing"] >= 0:
            continue
        ka = (t >= a["t0"] - 1e-12) & (t <= a["t1"] + 1e-12)
        kb = (t >= b["t0"] - 1e-12) & (t <= b["t1"] + 1e-12)
        rec = {"from_level": a["level"], "to_level": b["level"],
               "from_torque": a["housing"], "to_torque": b["housing"]}
        for body in ("sun", "ring", "coupling"):
            z = res[f"{body}.position"].values[:, 2]
            rec[f"d_{body}"] = float(z[kb].mean() - z[ka].mean())
        out.append(rec)
    return out


def default_output_dt(p: TorsenCFile) -> float:
    """``solver.output_dt``, reduced to give :data:`WINDOW_SAMPLES` samples per window."""
    return min(p.solver.output_dt, WINDOW_FRACTION * p.vehicle.hold / WINDOW_SAMPLES)


def run_vehicle(p: TorsenCFile, friction_scale: float = 1.0, progress=None,
                output_dt: float | None = None) -> VehicleRun:
    """Simulate the vehicle profile of ``p`` with the solver settings of ``p.solver`` and
    analyse its held levels.

    Args:
        p: parameters (``[vehicle]`` profile, ``[solver]`` settings with the step capped at
            ``vehicle.h_max``).
        friction_scale: factor on every friction coefficient.
        progress: ``progress(t, h, steps)`` callback.
        output_dt: sampling interval [s]; default ``solver.output_dt``, or finer so that each
            analysis window holds :data:`WINDOW_SAMPLES` samples (the output torques carry
            mesh and pocket vibrations of a few tenths of a N m: window means need samples).
    Returns:
        :class:`VehicleRun`; if the solver stops early, the partial results and the levels
        completed before the stop.
    """
    from drivedyn.model.compile import compile_model
    from drivedyn.solver.simulate import simulate

    t0 = time.perf_counter()
    sp, _, t_end = vehicle_spec(p, friction_scale)
    model = compile_model(sp)
    res = simulate(model, t_end, **p.solver.settings(h_max=p.vehicle.h_max),
                   output_dt=output_dt or default_output_dt(p), progress=progress)
    return VehicleRun(results=res, wall_s=time.perf_counter() - t0, success=bool(res.success),
                      message="" if res.success else str(res.message),
                      levels=analyse(p, res, friction_scale), params=p)
