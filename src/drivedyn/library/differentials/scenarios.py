"""The shared scenarios of every differential: the test bench and the vehicle configuration.

**Bench** (seed 003, Fig. 7a): housing held (``hold_housing`` driver on
``housing_bearing``), torque on one output (``applied_torque``), the other output's speed
prescribed (``speed_control``) so that the outputs differ by ``speed_diff``; the load follows
``s(t)``: 0 -> +1 (drive) over ``bench.ramp``, then +1 -> -1 (coast) over
``bench.transition`` (smooth C^1 steps). Sign convention (forward = +z): in drive the axle
torques resist forward motion, so the applied torque is ``-torque s(t)``; the loaded output
turns with its torque (it is the input of the gear train seen from the housing), which makes
the mode "bias to the loaded side". The TDR of a mode is the applied over the resistant
torque (the speed-control driver's), window means.

**Vehicle configuration** (seed 003, Fig. 7b, 10, 13): engine torque on the housing
(``engine_torque``), both output speeds prescribed (drivers ``{output}_speed``, mean speed
``vehicle.speed``, second minus first = the level's ``speed_diff``); optionally the same
torque levels again in backwards motion after a reversal of both output speeds
(``vehicle.backward``): the helical thrusts, hence the loaded friction faces, follow the
torque's sign, and the favoured output follows the speeds relative to the housing, so the
backward half shows the four modes with the favoured sides exchanged.
"""

from __future__ import annotations

from typing import Any

from drivedyn.elements import JointDriver, Torque
from drivedyn.library.differentials.base import Differential
from drivedyn.model.spec import ModelError, Spec
from drivedyn.timefunctions import Constant, SmoothStep, Sum, TimeFunction


def bench_profile(p: Any) -> TimeFunction:
    """s(t): 0 -> +1 (drive) over ``bench.ramp``, +1 -> -1 (coast) over
    ``bench.transition``, smooth (C^1) steps."""
    bn = p.bench
    t1, t2 = bn.transition
    return Sum([SmoothStep(0.0, bn.ramp, 0.0, 1.0), SmoothStep(t1, t2, 0.0, -2.0)])


def bench_spec(diff: Differential, p: Any, side: str, torque: float | None = None,
               speed_diff: float | None = None, friction_scale: float = 1.0
               ) -> tuple[Spec, Any]:
    """Test bench of ``diff`` with the torque on output ``side`` (see the module doc).

    Args:
        diff: the differential type.
        p: its validated parameters.
        side: loaded output (``diff.sides``).
        torque: applied torque magnitude [N m] (default ``bench.torque``).
        speed_diff: output speed difference [rad/s] (default ``bench.speed_diff``).
        friction_scale: factor on every friction coefficient.
    Returns:
        (spec, geometry).
    """
    if side not in diff.sides:
        raise ModelError(f"{diff.name}: bench side must be one of "
                         f"{', '.join(repr(s) for s in diff.sides)}, got {side!r}")
    T0 = p.bench.torque if torque is None else torque
    dw = p.bench.speed_diff if speed_diff is None else speed_diff
    if not T0 > 0:
        raise ModelError(f"bench torque must be > 0 N m, got {T0!r}")
    if not dw > 0:
        raise ModelError(f"bench speed difference must be > 0 rad/s, got {dw!r}")
    sp, geo = diff.build(p, (0.0, 0.0, 0.0), friction_scale)
    speeds = dict(zip((o.name for o in diff.outputs), diff.housing_fixed_speeds(p, dw),
                      strict=True))
    s = bench_profile(p)
    loaded, other = diff.output(side), diff.other(side)
    sp.add(JointDriver("hold_housing", "housing_bearing", 0.0, quantity="angle"))
    sp.add(Torque("applied_torque", loaded.marker, vector=(0, 0, -T0), function=s))
    # the loaded output turns with -s (it drives the train); the other one the other way
    sp.add(JointDriver("speed_control", other.bearing, s * speeds[other.name],
                       quantity="speed"))
    return sp, geo


def level_times(p: Any) -> list[tuple[float, float, int, bool]]:
    """(hold start, hold end, index into ``vehicle.torque_levels``, backward?) [s] of every
    held level of the vehicle profile, in time order (see :func:`vehicle_profile`)."""
    v = p.vehicle
    n = len(v.torque_levels)
    out = []
    for i in range(n):
        t0 = (i + 1) * v.ramp + i * v.hold
        out.append((t0, t0 + v.hold, i, False))
    if v.backward:
        t_rev = n * (v.ramp + v.hold) + v.reversal
        for i in range(n):
            t0 = t_rev + (i + 1) * v.ramp + i * v.hold
            out.append((t0, t0 + v.hold, i, True))
    return out


#: fraction of each hold (its end) over which a level is averaged (the ramp's transient has
#: died out)
WINDOW_FRACTION = 0.6


def level_windows(p: Any) -> list[tuple[float, float, float, int, bool]]:
    """(hold start, window start, window end, level index, backward?) [s] of each held level
    of the profile, in time order (:func:`level_times`); the window is the last
    :data:`WINDOW_FRACTION` of the hold."""
    out = []
    for t0, t1, i, back in level_times(p):
        out.append((t0, t1 - WINDOW_FRACTION * (t1 - t0), t1, i, back))
    return out


def vehicle_profile(p: Any) -> tuple[TimeFunction, TimeFunction, TimeFunction, float]:
    """(housing torque T(t) [N m], mean output speed w(t) [rad/s], second-minus-first speed
    difference d(t) [rad/s], t_end [s]).

    From T = 0 at t = 0, smooth steps over ``vehicle.ramp`` to each level, held for
    ``vehicle.hold`` (level i over [(i + 1) ramp + i hold, (i + 1)(ramp + hold)]). With
    ``vehicle.backward``: then w and d reverse over ``vehicle.reversal`` with the last torque
    held, and the levels run again with the same torques and d negated (backwards motion)."""
    v = p.vehicle
    if len(v.torque_levels) != len(v.speed_diff) or len(v.torque_levels) < 1:
        raise ModelError("vehicle.torque_levels and vehicle.speed_diff must have the same "
                         f"length >= 1, got {len(v.torque_levels)} and {len(v.speed_diff)}")
    try:
        return _vehicle_profile(v)
    except ValueError as exc:  # a ramp that ends where it starts in floating point
        raise ModelError(f"vehicle.ramp = {v.ramp!r} s, vehicle.hold = {v.hold!r} s, "
                         f"vehicle.reversal = {v.reversal!r} s: the profile's steps cannot be "
                         f"timed ({exc})") from None


def _vehicle_profile(v: Any) -> tuple[TimeFunction, TimeFunction, TimeFunction, float]:
    tq: list[Any] = []
    dd: list[Any] = [Constant(v.speed_diff[0])]
    ww: list[Any] = [Constant(v.speed)]
    t = 0.0
    last_t, last_d = 0.0, v.speed_diff[0]
    halves = (1.0, -1.0) if v.backward else (1.0,)
    for h, sign in enumerate(halves):
        if h:  # speed reversal, last torque held
            ww.append(SmoothStep(t, t + v.reversal, 0.0, -2.0 * v.speed))
            dd.append(SmoothStep(t, t + v.reversal, 0.0, -2.0 * last_d))
            last_d = -last_d
            t += v.reversal
        for i, level in enumerate(v.torque_levels):
            diff = sign * v.speed_diff[i]
            tq.append(SmoothStep(t, t + v.ramp, 0.0, level - last_t))
            if diff != last_d:
                dd.append(SmoothStep(t, t + v.ramp, 0.0, diff - last_d))
            last_t, last_d = level, diff
            t += v.ramp + v.hold
    mean = ww[0] if len(ww) == 1 else Sum(ww)
    return Sum(tq), mean, Sum(dd), t


def vehicle_settings(p: Any) -> dict:
    """``simulate``'s ``integrator``, ``step`` and ``newton`` arguments for the vehicle run
    of ``p``: the file's ``[solver]`` with the step capped at ``vehicle.h_max``,
    ``vehicle.atol_rot`` [rad], if given, for the nodes' rotations and ``vehicle.rho_inf``,
    if given, for the integrator's."""
    return p.solver.settings(h_max=p.vehicle.h_max, atol_rot=p.vehicle.atol_rot,
                             rho_inf=p.vehicle.rho_inf)


def vehicle_spec(diff: Differential, p: Any, friction_scale: float = 1.0
                 ) -> tuple[Spec, Any, float]:
    """Vehicle configuration of ``diff`` (module doc). Returns (spec, geometry, t_end)."""
    T, w, d, t_end = vehicle_profile(p)
    w0, d0 = p.vehicle.speed, p.vehicle.speed_diff[0]
    w1, w2 = w0 - d0 / 2, w0 + d0 / 2
    sp, geo = diff.build(p, (diff.housing_speed(p, w1, w2), w1, w2), friction_scale)
    first, second = diff.outputs
    sp.add(Torque("engine_torque", "b_housing", vector=(0, 0, 1.0), function=T))
    sp.add(JointDriver(f"{first.name}_speed", first.bearing, Sum([w, d * -0.5]),
                       quantity="speed"))
    sp.add(JointDriver(f"{second.name}_speed", second.bearing, Sum([w, d * 0.5]),
                       quantity="speed"))
    return sp, geo, t_end
