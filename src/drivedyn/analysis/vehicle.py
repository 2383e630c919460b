"""Vehicle configuration of a differential (seed 003, Fig. 10-13): torque split per level.

The engine torque acts on the housing and steps through ``vehicle.torque_levels`` (each held
for ``vehicle.hold`` after a smooth ramp of ``vehicle.ramp``); both output speeds are
prescribed (Type C: front = sun, rear = coupling; Type B: left and right side gears; second
minus first = ``vehicle.speed_diff`` of the level), optionally again in backwards motion
(:func:`drivedyn.library.differentials.scenarios.vehicle_profile`).

Signs: the speed drivers' torques (``front_speed.torque``, ``rear_speed.torque``, ...) are
the torques they apply on the outputs; the *output torques* reported here are the torques the
outputs deliver to the axles, their negatives, so that in equilibrium
``first + second = housing`` (engine torque about +z, positive = drive in forward motion).

Each level is analysed over the last 60 % of its hold (the transient of the ramp has died
out): window means of the three torques, the relative balance error
``|T_h - (T_1 + T_2)| / |T_h|``, the locking mode and the torque distribution ratio (TDR,
the favoured axle's torque over the other's: in drive -- power from the housing to the axles
-- the slower axle is favoured, in coast the faster one), and the quasi-static TDR of the
differential's analytic model at the same speeds and housing torque.

Cost: the shipped profile (12 loaded levels and 3 zero-torque holds) is timed in the README
and in ``benchmarks/README.md``: 0.38 of real time on two cores (the example's short
profile, with its quicker tip-ins: 0.66). At exactly zero torque the
gears float in their clearances (the planets' centrifugal force opens the sun meshes by
nanometres) and the internal gear floats axially between its washers; the steps stay at the
0.2 ms cap and a zero-torque hold costs no more than a loaded one per simulated second
(0.29 s against 0.30 s; without Newton's deferred refresh 0.62 against 0.49-0.57 s). It
costs 10-15 minutes per simulated second if the gear element lends its mesh stiffness to the
iteration matrix for gaps up to 10 nm instead of 1 pm (``TANGENT_BAND``; Newton then
converges only linearly), 4.4-5.2 s without the model files' 20 nm flank onset
(``GearPair.flank_onset``: a flank closing within a step with its full stiffness makes
Newton diverge), and 2-3 s with Newton's residual floor at 1e-4 instead of 1e-2 of the
largest force sum (``newton_kernel.FLOOR_REL``: the floating gear is then iterated below the
round-off of its position).
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from drivedyn.library import differentials
from drivedyn.library.differentials.scenarios import (
    WINDOW_FRACTION,
    level_windows,
    vehicle_settings,
    vehicle_spec,
)

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
    params: Any = None


def mode_of(diff, torque: float, w_first: float, w_second: float, w_housing: float
            ) -> tuple[int | None, str | None]:
    """(mode number, favoured output name) of a housing torque and output speeds [rad/s];
    (None, None) without torque or without speed difference.

    The helical thrusts, hence the friction faces they load, follow the sign of the torque,
    and the friction follows the speeds relative to the housing: a mode is "drive" when the
    housing torque has the forward-drive sign (``torque > 0``), and the favoured output is the
    one that turns against the torque relative to the housing (``(w - w_housing) torque <
    0``). In forward motion this is the usual rule (drive favours the slower output, coast the
    faster one); in backwards motion the same torque favours the other side."""
    if abs(torque) <= ZERO_TORQUE or w_first == w_second:
        return None, None
    drive = torque > 0
    first, second = diff.outputs
    w_rel = w_first - w_housing if w_first != w_housing else -(w_second - w_housing)
    favoured = (first if w_rel * torque < 0 else second).name
    for m in diff.modes:
        if m.side == favoured and m.drive == drive:
            return m.number, favoured
    raise AssertionError("unreachable")  # pragma: no cover


def _window_mean(res, name: str, k: np.ndarray, comp: int | None = None) -> float:
    v = res.values(name)[k]
    return float((v[:, comp] if comp is not None else v).mean())


def _power_loss(diff, res, k: np.ndarray) -> float:
    """Window mean of input minus output power [W] (engine on the housing, drivers)."""
    p = res.values("engine_torque.torque_z")[k] * res.values("housing.angular_velocity")[k, 2]
    for o in diff.outputs:
        p = p + res.values(f"{o.name}_speed.torque")[k] * \
            res.values(f"{o.body}.angular_velocity")[k, 2]
    return float(p.mean())


def level_stats(p: Any, res, index: int, window: tuple[float, float],
                friction_scale: float = 1.0, backward: bool = False) -> dict | None:
    """Statistics of level ``index`` (of ``vehicle.torque_levels``; ``backward``: its repeat
    in backwards motion) over ``window`` [s], or None if the results do not cover it
    (``friction_scale`` as in the run, for the analytic model).

    Keys (output names of the differential, e.g. ``front``/``rear``): ``level``,
    ``direction`` (``"forward"``/``"backward"``), ``t0``, ``t1`` (window), ``nominal``
    (N m), ``housing`` and one per output (torques delivered to the axles, N m),
    ``w_housing`` and ``w_{output}`` (rad/s), ``balance_error`` (relative, None without
    torque), ``mode``, ``mode_name``, ``favoured``, ``tdr`` and ``tdr_analytic`` (None without
    a mode), ``analytic_{output}`` (N m), ``tdr_error`` (relative, simulated vs analytic),
    ``power_loss`` (input minus output power, W) and ``dissipated`` (mean dissipated power of
    all elements, W; equal to the loss when the window is steady).
    """
    diff = differentials.of(p)
    first, second = diff.outputs
    t = res.values("time")
    if t.size == 0 or t[-1] < window[1] - 1e-9:
        return None
    k = (t >= window[0] - 1e-12) & (t <= window[1] + 1e-12)
    if k.sum() < 2:
        return None
    th = _window_mean(res, "engine_torque.torque_z", k)
    t1 = -_window_mean(res, f"{first.name}_speed.torque", k)
    t2 = -_window_mean(res, f"{second.name}_speed.torque", k)
    wh = _window_mean(res, "housing.angular_velocity", k, 2)
    w1 = _window_mean(res, f"{first.body}.angular_velocity", k, 2)
    w2 = _window_mean(res, f"{second.body}.angular_velocity", k, 2)
    mode, fav = mode_of(diff, th, w1, w2, wh)
    names = [n for n in res.names() if n.endswith(".dissipated_power")]
    out: dict[str, Any] = {
        "level": index, "direction": "backward" if backward else "forward",
        "t0": float(window[0]), "t1": float(window[1]),
        "nominal": float(p.vehicle.torque_levels[index]),
        "housing": th, first.name: t1, second.name: t2, "w_housing": wh,
        f"w_{first.name}": w1, f"w_{second.name}": w2,
        "balance_error": abs(th - (t1 + t2)) / abs(th) if abs(th) > ZERO_TORQUE else None,
        "mode": mode, "mode_name": diff.mode(mode).name if mode else None, "favoured": fav,
        "tdr": None, "tdr_analytic": None, f"analytic_{first.name}": None,
        f"analytic_{second.name}": None, "tdr_error": None,
        "power_loss": _power_loss(diff, res, k),
        "dissipated": float(sum(res.values(n)[k].mean() for n in names)),
    }
    if mode is None:
        return out
    tdr = t2 / t1 if fav == second.name else t1 / t2
    out["tdr"] = tdr
    try:
        a1, a2 = diff.analytic_vehicle(p, (wh, w1, w2), th, friction_scale)
    except RuntimeError as exc:  # no quasi-static equilibrium: report the simulation only
        out["analytic_message"] = str(exc)
        return out
    tdr_a = a2 / a1 if fav == second.name else a1 / a2
    out.update({"tdr_analytic": tdr_a, f"analytic_{first.name}": a1,
                f"analytic_{second.name}": a2, "tdr_error": tdr / tdr_a - 1.0})
    return out


def analyse(p: Any, res, friction_scale: float = 1.0) -> list[dict]:
    """:func:`level_stats` of every level the results cover."""
    out = []
    for _, t0, t1, i, back in level_windows(p):
        s = level_stats(p, res, i, (t0, t1), friction_scale, back)
        if s is not None:
            out.append(s)
    return out


def reversals(levels: list[dict], res, diff=None) -> list[dict]:
    """Axial motion across each sign reversal of the housing torque between consecutive
    loaded levels (zero-torque levels in between are skipped): change of the window-mean
    axial position [m] of the differential's axial bodies (Type C: ``d_sun``, ``d_ring``,
    ``d_coupling``; default ``diff``: the Type C) from the level before to the level after
    (``from_level``, ``to_level``, ``from_torque``, ``to_torque``)."""
    diff = diff or differentials.get("torsen_c")
    t = res.values("time")
    out = []
    loaded = [lv for lv in levels if abs(lv["housing"]) > ZERO_TORQUE]
    for a, b in itertools.pairwise(loaded):
        if a["housing"] * b["housing"] >= 0:
            continue
        ka = (t >= a["t0"] - 1e-12) & (t <= a["t1"] + 1e-12)
        kb = (t >= b["t0"] - 1e-12) & (t <= b["t1"] + 1e-12)
        rec = {"from_level": a["level"], "to_level": b["level"],
               "from_torque": a["housing"], "to_torque": b["housing"]}
        for body, _ in diff.axial_bodies:
            z = res.values(f"{body}.position")[:, 2]
            rec[f"d_{body}"] = float(z[kb].mean() - z[ka].mean())
        out.append(rec)
    return out


def default_output_dt(p: Any) -> float:
    """``solver.output_dt``, reduced to give :data:`WINDOW_SAMPLES` samples per window."""
    return min(p.solver.output_dt, WINDOW_FRACTION * p.vehicle.hold / WINDOW_SAMPLES)


def run_vehicle(p: Any, friction_scale: float = 1.0, progress=None,
                output_dt: float | None = None) -> VehicleRun:
    """Simulate the vehicle profile of ``p`` with the solver settings of ``p.solver`` and
    analyse its held levels.

    Args:
        p: parameters (``[vehicle]`` profile, ``[solver]`` settings with the step capped at
            ``vehicle.h_max`` and ``vehicle.atol_rot``, if given, for the rotations).
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
    sp, _, t_end = vehicle_spec(differentials.of(p), p, friction_scale)
    model = compile_model(sp)
    res = simulate(model, t_end, **vehicle_settings(p),
                   output_dt=output_dt or default_output_dt(p), progress=progress)
    return VehicleRun(results=res, wall_s=time.perf_counter() - t0, success=bool(res.success),
                      message="" if res.success else str(res.message),
                      levels=analyse(p, res, friction_scale), params=p)
