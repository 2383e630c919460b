"""TORSEN Type C, vehicle configuration (seed 003, Fig. 10-11): a short profile through the
four locking modes.

Profile: +100, -100 N m with the rear slower (modes 1, 4), then +100, -100 N m with the rear
faster (modes 3, 2): three torque reversals, one of them with the speed difference changing
sign during the ramp. Holds are shortened to 0.08 s, ramps to 0.04 s; each level is averaged
over the last 60 % of its hold (from 0.032 s after the ramp: the ramps' transients die out in
~10 ms; the run starts with a ramp from zero torque). A hold at zero torque is tested on its own
profile (``test_through_zero_torque``).
"""

from __future__ import annotations

import logging
import math
import re
import time

import numpy as np
import pytest

from drivedyn.analysis.vehicle import (
    analyse,
    level_windows,
    mode_of,
    reversals,
    run_vehicle,
)
from drivedyn.config import read_library_file
from drivedyn.library.differentials import get
from drivedyn.library.differentials.torsen_c import analytic as analytic_tdr
from drivedyn.plots import vehicle_figures

OVERRIDES = [
    "vehicle.torque_levels=[100.0, -100.0, 100.0, -100.0]",
    "vehicle.speed_diff=[-2.0, -2.0, 2.0, 2.0]",
    "vehicle.hold=0.08",
    "vehicle.ramp=0.04",
]
EXPECTED_MODES = [1, 4, 3, 2]


@pytest.fixture(scope="module")
def params():
    return read_library_file("torsen-c", OVERRIDES)[0]


@pytest.fixture(scope="module")
def run(params):
    t0 = time.perf_counter()
    r = run_vehicle(params)
    print(f"vehicle run: {time.perf_counter() - t0:.1f} s wall, {r.results.stats}")
    return r


def test_mode_of_follows_the_modes_table() -> None:
    tc = get("torsen-c")
    for sign in (1.0, -1.0):  # forward, then backward motion (all speeds negated)
        def mode(torque, diff, sign=sign):
            wf, wr = sign * (30.0 - diff / 2), sign * (30.0 + diff / 2)
            return mode_of(tc, torque, wf, wr, 0.5 * (wf + wr))

        rear, front = ("rear", "front") if sign > 0 else ("front", "rear")
        num = {"rear": (1, 2), "front": (3, 4)}
        assert mode(50.0, -2.0) == (num[rear][0], rear)  # drive, rear slower
        assert mode(-50.0, 2.0) == (num[rear][1], rear)  # coast, rear faster
        assert mode(50.0, 2.0) == (num[front][0], front)  # drive, front slower
        assert mode(-50.0, -2.0) == (num[front][1], front)  # coast, front faster
        assert mode(0.0, 2.0) == (None, None)


def test_vehicle_numerical_settings_replace_the_solver_ones() -> None:
    """``vehicle.h_max``, ``atol_rot`` and ``rho_inf`` reach the vehicle run's ``simulate``
    arguments; left out, the file's ``[solver]`` values do."""
    from drivedyn.library.differentials.scenarios import vehicle_settings

    p = read_library_file("torsen-c", ["vehicle.rho_inf=0.55", "vehicle.atol_rot=2e-5",
                                       "vehicle.h_max=0.15 ms"])[0]
    s = vehicle_settings(p)
    assert s["integrator"].rho_inf == 0.55
    assert s["step"].atol_rot == 2e-5
    assert s["step"].h_max == pytest.approx(1.5e-4, rel=1e-12)
    q = read_library_file("torsen-c")[0].model_copy(deep=True)
    q.vehicle.rho_inf = None
    q.vehicle.atol_rot = None
    q.solver.rho_inf = 0.7  # not the file's vehicle value: the run must take this one
    s = vehicle_settings(q)
    assert s["integrator"].rho_inf == 0.7
    assert s["step"].atol_rot == q.solver.step.atol_rot
    with pytest.raises(Exception, match="rho_inf"):
        read_library_file("torsen-c", ["vehicle.rho_inf=1.5"])


def test_level_windows_match_the_profile(params) -> None:
    """Each analysis window lies where the engine torque and the speed difference hold
    their level (checked on the time functions the model is built from)."""
    from drivedyn.library.differentials.scenarios import vehicle_profile

    torque, _, diff, t_end = vehicle_profile(params)
    w = level_windows(params)
    assert len(w) == len(params.vehicle.torque_levels)
    for (hold_start, a, b, _, _), level, d in zip(w, params.vehicle.torque_levels,
                                            params.vehicle.speed_diff, strict=True):
        assert hold_start < a < b
        for t in np.linspace(hold_start, b, 7):
            assert torque(t) == pytest.approx(level, abs=1e-12)
            assert diff(t) == pytest.approx(d, abs=1e-12)
    assert w[-1][2] == pytest.approx(t_end)


def test_runs_through_all_reversals(run) -> None:
    assert run.success, run.message
    assert [lv["level"] for lv in run.levels] == [0, 1, 2, 3]
    assert [lv["mode"] for lv in run.levels] == EXPECTED_MODES
    for lv in run.levels:
        assert lv["housing"] == pytest.approx(lv["nominal"], rel=1e-9)


def _angular_momentum_z(res, params) -> np.ndarray:
    """Total angular momentum of the differential about the axis [kg m^2/s]: spins about
    the centres of mass plus the planets' orbits."""
    b = params.bodies
    mass = {name: getattr(b, name).mass for name in ("housing", "case", "sun", "ring",
                                                      "coupling")}
    mass.update({f"planet{k + 1}": b.planet.mass for k in range(params.gears.planets)})
    h = 0.0
    for name, m in mass.items():
        x = res[f"{name}.position"].values
        v = res[f"{name}.velocity"].values
        h = h + res[f"{name}.angular_momentum"].values[:, 2] + m * (x[:, 0] * v[:, 1]
                                                                     - x[:, 1] * v[:, 0])
    return h


def test_torque_balance_in_held_windows(run, params) -> None:
    """About the axis, T_h - (T_f + T_r) = dH/dt (H: total angular momentum; the bearings
    carry no axial moment). Over a held window the speeds are steady: the mean inertia
    torque dH/T_window is checked to use less than half of the 1e-3 tolerance (it is
    ~2e-4 T_h in the first window, the tail of the start at full torque, and below 1e-4
    after that), and the window means of the output torques must balance the housing
    torque to 1e-3 (the instantaneous imbalance is the mesh and pocket vibration, a few
    tenths of a N m, that averages out)."""
    res = run.results
    t = res["time"].values
    h = _angular_momentum_z(res, params)
    for lv in run.levels:
        k = np.flatnonzero((t >= lv["t0"] - 1e-12) & (t <= lv["t1"] + 1e-12))
        inertial = abs(h[k[-1]] - h[k[0]]) / (t[k[-1]] - t[k[0]]) / abs(lv["housing"])
        assert inertial < 0.5e-3, f"level {lv['level']}: speeds not steady ({inertial:.2e})"
        assert lv["balance_error"] < 1e-3, (
            f"level {lv['level']}: |T_h - (T_f + T_r)| / |T_h| = {lv['balance_error']:.2e} "
            f"(T_h {lv['housing']:.3f}, front {lv['front']:.3f}, rear {lv['rear']:.3f} N m; "
            f"mean inertia torque {inertial:.1e} T_h)")


def test_reversals_move_sun_and_coupling_against_the_ring(run) -> None:
    """Seed 003, Fig. 11: at each reversal sun and coupling travel together, the internal
    gear the other way; drive pushes the sun to the front (-z), coast to the rear."""
    rev = reversals(run.levels, run.results)
    assert len(rev) == 3
    for r in rev:
        msg = (f"levels {r['from_level']}->{r['to_level']}: d_sun {r['d_sun'] * 1e6:.1f}, "
               f"d_coupling {r['d_coupling'] * 1e6:.1f}, d_ring {r['d_ring'] * 1e6:.1f} um")
        assert math.copysign(1, r["d_sun"]) == math.copysign(1, r["d_coupling"]), msg
        assert math.copysign(1, r["d_ring"]) == -math.copysign(1, r["d_sun"]), msg
        assert r["d_sun"] * r["from_torque"] > 0, msg  # drive -> coast: sun to the rear
        for body in ("sun", "coupling", "ring"):
            assert abs(r[f"d_{body}"]) > 50e-6, msg  # at least the washer play


def test_tdr_matches_the_quasi_static_model(run, params) -> None:
    for lv in run.levels:
        err = lv["tdr"] / lv["tdr_analytic"] - 1.0
        assert abs(err) < 0.02, (
            f"level {lv['level']} (mode {lv['mode']}): simulated TDR {lv['tdr']:.4f}, "
            f"analytic {lv['tdr_analytic']:.4f}, discrepancy {err * 100:+.2f} %")
    # the analytic value at the level's speeds is the bench mode's TDR at the same torque
    # split direction (both come from the same equilibrium): sanity of the comparison
    q = analytic_tdr.all_modes(params)
    for lv in run.levels:
        assert lv["tdr_analytic"] == pytest.approx(q[lv["mode"] - 1], rel=0.05)


def test_partial_results_keep_the_completed_levels(run, params, tmp_path) -> None:
    """A run that stops early (here: its results cut at 0.25 s) still yields the levels
    whose windows it covered, and its figures."""
    from drivedyn.results.results import Results

    ds = run.results.dataset
    cut = Results(ds.sel(time=ds["time"] <= 0.25).copy(), False, "cut", run.results.stats)
    levels = analyse(params, cut)
    assert [lv["level"] for lv in levels] == [0, 1]
    assert levels[1]["tdr"] == pytest.approx(run.levels[1]["tdr"], rel=1e-12)
    assert len(vehicle_figures(cut, tmp_path)) == 4


def test_figures_are_written(run, tmp_path) -> None:
    paths = vehicle_figures(run, tmp_path)
    assert len(paths) == 4
    for p in paths:
        assert p.exists() and p.stat().st_size > 10_000, p
    # the results alone are enough too
    again = vehicle_figures(run.results, tmp_path / "from_results")
    assert [p.name for p in again] == [p.name for p in paths]


def test_through_zero_torque() -> None:
    """Tip-out and tip-in: 60 N m, a hold at exactly zero torque with the outputs at the same
    speed (no relative motion in the differential: the gears float in their clearances),
    then -60 N m with the rear faster. The run completes (a hold where the gears float can
    cost minutes of wall time per simulated second); in the zero hold both outputs deliver no
    torque (measured 1.2e-3 and 3e-4 N m of residual vibration, 2e-5 of the load), and the
    loaded level after it is mode 2 with the analytic TDR."""
    p = read_library_file("torsen-c", [
        "vehicle.torque_levels=[60.0, 0.0, -60.0]", "vehicle.speed_diff=[-2.0, 0.0, 2.0]",
        "vehicle.hold=0.08", "vehicle.ramp=0.04"])[0]
    run = run_vehicle(p)
    assert run.success, run.message
    first, zero, last = run.levels
    assert zero["mode"] is None and abs(zero["housing"]) < 1e-12
    assert abs(zero["front"]) < 3e-3 and abs(zero["rear"]) < 3e-3
    assert first["mode"] == 1 and last["mode"] == 2
    assert last["tdr"] == pytest.approx(last["tdr_analytic"], rel=2e-2)


def test_a_zero_torque_hold_costs_about_the_newton_work_of_a_loaded_one(caplog) -> None:
    """A zero-torque hold should cost no more per simulated second than a loaded
    hold. The work is counted, not timed (the same on every machine): Newton iterations of every
    attempt, accepted or rejected, plus eight per factorisation (a factorisation of the
    Type C costs about eight iterations: its matrix and LU against a residual and a solve;
    newton_kernel's note on REFACTOR_AFTER) over each hold's window, from the step log. The
    profile is the shipped one's first three levels: 125 N m, 60 N m, then zero torque after
    a 0.25 s ramp. Measured: 15 000 and 14 800 per simulated second in the loaded holds,
    14 350 in the zero hold (0.97 times the lesser; 2.1 iterations and 0.10 factorisations per
    step against 1.9 and 0.13). The loaded holds' work moves with the steps that lead into
    them: with steps grown from the envelope of recent error estimates (solver.step_control)
    they fell to 12 160 and 12 930 and the zero hold stayed at 13 840 (1.14), every hold at
    h_max without a rejection. The bound below, 1.3, lies between that spread and each known
    way to lose it:
    with newton_kernel.FLOOR_REL at 1e-4 the zero hold takes 3.8 times the loaded ones' work;
    with the factorisation refreshed after every correction that did not contract, even when
    the next check converged, 1.66 times (0.42 factorisations per step: the ratio of two tiny
    last corrections is noise at zero load).

    The run keeps the friction set these figures were measured with (W1 0.3, W3-W5 0.18491,
    pockets 0.173023, no tooth friction, planets held axially): this test guards the Newton
    rules above. With the file's physics the unloaded planets float at a cost no Newton rule
    removes: the zero hold takes 3.7 times a loaded hold's work (1134 factorisations and 48
    rejections in the hold against 165 and none). Per mechanism, at the file's coefficient:
    tooth friction alone 1181 and 48, the end faces alone (with their oil film) 1956 and 105,
    neither 145 and 0; both with the film 1.6 times a loaded hold's work
    (``pockets.end_film``). Bringing that down belongs to the vehicle-speed work."""
    p = read_library_file("torsen-c", [
        "vehicle.torque_levels=[125.0, 60.0, 0.0]", "vehicle.speed_diff=[-2.0, -2.0, -2.0]",
        "washers.sun_housing.mu=0.3", "washers.coupling_case.mu=0.18491",
        "washers.ring_housing.mu=0.18491", "washers.ring_case.mu=0.18491",
        "pockets.mu=0.173023", "gears.tooth_friction=0", "pockets.end_faces=false"])[0]
    with caplog.at_level(logging.DEBUG, logger="drivedyn"):
        run = run_vehicle(p)
    assert run.success, run.message
    steps = []  # (t: end of an accepted step, start of a rejected one, iterations, factorisations)
    for rec in caplog.records:
        msg = rec.getMessage()
        m = re.match(r"t = (\S+) s  h = \S+ s  Newton iterations (\d+)  factorizations (\d+)",
                     msg)
        if m:
            steps.append((float(m[1]), int(m[2]), int(m[3])))
        m = re.match(r"t = (\S+) s  h = \S+ s  rejected: .* \(iterations (\d+), ", msg)
        if m:  # its factorisations are counted in the attempt after it
            steps.append((float(m[1]), int(m[2]), 0))
    stats = run.results.stats
    assert len(steps) == stats.steps + stats.rejected
    work = []
    for lv in run.levels:
        inside = [(it, nf) for t, it, nf in steps if lv["t0"] < t <= lv["t1"]]
        duration = lv["t1"] - lv["t0"]
        work.append(sum(it + 8 * nf for it, nf in inside) / duration)
    loaded, zero = work[:2], work[2]
    print("work per simulated second, loaded and zero-torque holds:", work)
    assert run.levels[2]["mode"] is None
    assert zero <= 1.3 * min(loaded), work
