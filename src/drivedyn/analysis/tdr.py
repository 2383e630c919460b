"""Torque distribution ratio on the simulated test bench (seed 003 protocol), for any
differential of :mod:`drivedyn.library.differentials`.

One bench run per loaded side covers two modes (drive, then coast, smooth transition): for
the Type C ``side = "rear"`` gives modes 1 and 2, ``"front"`` modes 3 and 4 (the
differential's ``side_modes``). The TDR of a mode is the applied torque over the resistant
torque (the speed-control driver's torque), each averaged over the mode's steady window
(``bench.window_drive``, ``bench.window_coast``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from drivedyn.library import differentials
from drivedyn.library.differentials.scenarios import bench_spec
from drivedyn.results.metrics import run_metrics
from drivedyn.results.provenance import record_provenance


def side_modes(p) -> dict[str, tuple[int, int]]:
    """side -> (drive mode, coast mode) of the differential of ``p``, in bench order."""
    return differentials.of(p).side_modes


@dataclass
class BenchRun:
    """One simulated bench run (two modes).

    Attributes:
        side: ``"rear"`` or ``"front"`` (output carrying the applied torque).
        tdr: mode number -> TDR.
        applied, resistant: mode -> window-mean torques [N m].
        ripple: mode -> peak-to-peak of the instantaneous ratio in the window / TDR.
        results: the :class:`~drivedyn.results.results.Results` of the run.
        wall_s: wall time of the run [s] (compilation included).
        success: the run reached its end.
        message: solver message when it did not.
    """

    side: str
    tdr: dict[int, float] = field(default_factory=dict)
    applied: dict[int, float] = field(default_factory=dict)
    resistant: dict[int, float] = field(default_factory=dict)
    ripple: dict[int, float] = field(default_factory=dict)
    results: object = None
    wall_s: float = 0.0
    success: bool = True
    message: str = ""
    size: dict = field(default_factory=dict)


def model_size(model, seed_coordinates: int = 0) -> dict:
    """Sizes of a compiled model: ``unknowns`` (coordinates + multipliers), ``coordinates``
    (6 per node, elastic coordinates of flexible parts included), ``multipliers``, and per
    flexible part its finite-element dofs and elastic coordinates (``parts``: name ->
    (fe_dofs, nq)); ``beam_elements``: the number of beam elements; ``seed_coordinates``: the
    size of the papers' flexible bench model of the differential (given: 0 if none)."""
    parts = {}
    checks = []
    beams = sum(len(g.names) for g in model.groups if g.family == "beam")
    for g in model.groups:
        for name, part in zip(g.names, g.extra.get("parts", ()), strict=False):
            parts[name] = (3 * part.n, part.nq)
            checks.append(part.check_text())
    return {"unknowns": model.neq, "coordinates": model.nd, "multipliers": model.nm,
            "parts": parts, "fe_dofs": sum(v[0] for v in parts.values()),
            "elastic_coordinates": sum(v[1] for v in parts.values()), "checks": checks,
            "beam_elements": beams, "seed_coordinates": seed_coordinates}


def size_text(size: dict) -> str:
    """One line describing :func:`model_size` (printed by ``drivedyn tdr``)."""
    txt = (f"model: {size['unknowns']} unknowns ({size['coordinates']} coordinates, "
           f"{size['multipliers']} multipliers)")
    if size.get("beam_elements"):
        txt += f"; {size['beam_elements']} beam elements"
    if size["parts"]:
        txt += (f"; {len(size['parts'])} flexible parts ({', '.join(size['parts'])}): "
                f"{size['fe_dofs']} finite-element dofs reduced to "
                f"{size['elastic_coordinates']} elastic coordinates")
        if size.get("seed_coordinates"):
            txt += (f" (the seeds' flexible model of this differential: "
                    f"{size['seed_coordinates']} coordinates)")
        txt += "".join("\n  " + c for c in size["checks"])
    return txt


def window_tdr(results, window: tuple[float, float]) -> tuple[float, float, float, float]:
    """(TDR, applied mean, resistant mean, relative ripple) over ``window`` [s] of a bench
    run's results."""
    t = results.values("time")
    k = (t >= window[0] - 1e-12) & (t <= window[1] + 1e-12)
    if k.sum() < 2:
        raise ValueError(f"window {window} holds fewer than two output samples")
    ta = results.values("applied_torque.torque_z")[k]
    tr = results.values("speed_control.torque")[k]
    tdr = abs(ta.mean() / tr.mean())
    ratio = np.abs(ta / np.where(tr == 0, np.nan, tr))
    return float(tdr), float(ta.mean()), float(tr.mean()), float(np.ptp(ratio) / tdr)


def bench_parameters(p, side: str, torque: float | None = None,
                     speed_diff: float | None = None) -> dict:
    """The model-file content (JSON-ready, SI) of one bench side of parameters ``p``: the
    scenario set to the bench with the torque on ``side``, the bench torque [N m] and speed
    difference [rad/s] as run. ``drivedyn run`` of it simulates the same bench run."""
    data = p.model_dump(mode="json", warnings=False)
    data["scenario"] = {"kind": "bench", "modes": side}
    if torque is not None:
        data["bench"]["torque"] = float(torque)
    if speed_diff is not None:
        data["bench"]["speed_diff"] = float(speed_diff)
    return data


def run_bench(p, side: str, torque: float | None = None,
              speed_diff: float | None = None, friction_scale: float = 1.0,
              progress=None, output_dt: float | None = None, source: str = "",
              overrides: list[str] | dict | tuple = ()) -> BenchRun:
    """Simulate one bench side and extract the TDR of its two modes. The results record the
    run's parameters (:func:`bench_parameters`) and configuration, so a report or plot of
    them finds the differential's bench dashboard.

    Args:
        p: parameters of a differential (its model file).
        side: the loaded output (Type C: ``"rear"`` for modes 1, 2, ``"front"`` for 3, 4).
        torque: applied torque [N m] (default ``bench.torque``).
        speed_diff: output speed difference [rad/s] (default ``bench.speed_diff``).
        friction_scale: factor on every friction coefficient.
        progress: ``progress(t, h, steps)`` callback.
        output_dt: sampling interval [s] (default ``solver.output_dt``).
        source: model file or shipped name of ``p`` (recorded with the results).
        overrides: the ``--set`` overrides that made ``p`` (recorded with the results).
    """
    import json

    from drivedyn.model.compile import compile_model
    from drivedyn.solver.simulate import simulate

    t0 = time.perf_counter()
    diff = differentials.of(p)
    sp, _ = bench_spec(diff, p, side, torque, speed_diff, friction_scale)
    model = compile_model(sp)
    res = simulate(model, p.bench.t_end, **p.solver.settings(),
                   output_dt=output_dt or p.solver.output_dt, progress=progress)
    config = differentials.configuration(p, side)
    if friction_scale != 1.0:
        config += f", friction x{friction_scale:g}"
    record_provenance(res,
                      model_file=json.dumps(bench_parameters(p, side, torque, speed_diff),
                                            indent=1, default=str),
                      source=source or p.model.name, overrides=overrides,
                      library_model=p.model.library, configuration=config)
    run = BenchRun(side, results=res, wall_s=time.perf_counter() - t0,
                   success=bool(res.success), message="" if res.success else str(res.message),
                   size=model_size(model, diff.seed_coordinates))
    windows = (p.bench.window_drive, p.bench.window_coast)
    for mode, win in zip(diff.side_modes[side], windows, strict=True):
        if not res.success and res.values("time")[-1] < win[1]:
            continue
        run.tdr[mode], run.applied[mode], run.resistant[mode], run.ripple[mode] = \
            window_tdr(res, win)
    return run


def parallel_sides(requested: bool = True) -> bool:
    """Whether :func:`evaluate` runs two bench sides at the same time, the second in a forked
    process: when ``requested``, with two or more CPUs, on Linux, from a process that is
    neither a daemon (a Dask or pool worker) nor multi-threaded (forking a threaded process
    is unsafe)."""
    import multiprocessing as mp
    import os
    import sys
    import threading

    return (requested and (os.cpu_count() or 1) >= 2 and sys.platform.startswith("linux")
            and "fork" in mp.get_all_start_methods() and not mp.current_process().daemon
            and threading.active_count() == 1)


def _bench_runs(p, sides: list[tuple[str, tuple[int, int]]], torque: float,
                speed_diff: float, friction_scale: float, on_run, meanwhile=None,
                parallel: bool = True, provenance: dict | None = None):
    """``(side, BenchRun)`` of every side in ``sides``, in order. Two sides run at the same
    time when :func:`parallel_sides` allows: the kernels are compiled (or loaded) here first
    for the first side's model (:func:`~drivedyn.solver.simulate.load_kernels`), then a
    forked process, which inherits them, runs the second side while this one runs the
    first: the Type C bench's four modes take the longer side's time (1.7 s) instead of
    both (2.9 s). ``meanwhile()`` (optional) is called in this process while the second
    side runs in its own, before the first side's run here: on the Type C bench the first
    (rear) side is the shorter one (4953 steps against 6875), so work done there costs no
    wall time (with one process: after the first side). ``provenance``: ``source`` and
    ``overrides`` keywords of :func:`run_bench`."""
    prov = provenance or {}
    for side, pair in sides:
        if on_run is not None:
            on_run(side, pair)
    if len(sides) == 2 and parallel_sides(parallel):
        import multiprocessing as mp

        from threadpoolctl import threadpool_limits

        from drivedyn.model.compile import compile_model
        from drivedyn.solver.simulate import load_kernels

        sp, _ = bench_spec(differentials.of(p), p, sides[0][0], torque, speed_diff,
                           friction_scale)
        load_kernels(compile_model(sp), **p.solver.settings())
        # the runs' results come back as arrays (Results.from_contents): unpickling the
        # second side's in the pool's result thread imports nothing, so it cannot race this
        # thread importing xarray for the first side's dataset (two threads importing
        # xarray at once make Python's import lock refuse one: "deadlock detected")
        # one BLAS thread in each process (the forked one inherits it): OpenBLAS's threads
        # wait spinning, and two processes of two threads on two cores took 59-481 s per
        # side of the flexible-washer bench against 12-20 s one after the other
        with threadpool_limits(limits=1, user_api="blas"), \
                mp.get_context("fork").Pool(1) as pool:
            second = pool.apply_async(run_bench, (p, sides[1][0], torque, speed_diff,
                                                  friction_scale), prov)
            if meanwhile is not None:
                meanwhile()
            first = run_bench(p, sides[0][0], torque, speed_diff, friction_scale, **prov)
            if on_run is not None:
                on_run(first)
            yield sides[0][0], first
            run = second.get()
        if on_run is not None:
            on_run(run)
        yield sides[1][0], run
        return
    for i, (side, _pair) in enumerate(sides):
        run = run_bench(p, side, torque, speed_diff, friction_scale, **prov)
        if on_run is not None:
            on_run(run)
        if i == 0 and meanwhile is not None:
            meanwhile()
        yield side, run


def mode_name(p, mode: int) -> str:
    """``"drive, bias rear"`` etc. (``p``: parameters or a Differential)."""
    diff = p if isinstance(p, differentials.Differential) else differentials.of(p)
    return diff.mode(mode).name


def experimental(p) -> dict[int, float]:
    """Measured TDR of each mode from the model file's ``[experiment]`` table."""
    out = {}
    for key, val in p.experiment.tdr.items():
        out[int(key.removeprefix("mode"))] = float(val)
    return out


def seeds_simulation(p) -> dict[int, float]:
    """The seeds' simulated TDR of each mode (``[experiment] seeds``)."""
    return {int(k.removeprefix("mode")): float(v) for k, v in p.experiment.seeds.items()}


@dataclass
class TdrEvaluation:
    """The TDRs of a differential on the bench, as ``drivedyn tdr`` reports them.

    Attributes:
        rows: one dict per mode: ``mode``, ``name``, ``tdr`` (simulated, or analytic with
            ``analytic_only``; NaN if its run failed), ``analytic``, ``experimental``
            (None without a measurement), ``error_pct`` and ``sim_vs_analytic_pct``.
        runs: one dict per bench run: ``side``, ``wall_s``, ``size``, ``steps``,
            ``newton_iterations``, ``success``.
        metrics: ``dissipated_energy`` [J] summed over the runs, ``peak_pressure`` [Pa] the
            largest over the runs and ``peak_pressure_at``, ``steps``,
            ``newton_iterations``, ``rejected_steps`` summed (NaN/0 with ``analytic_only``).
        failed: empty, or what failed (the rows of the modes after it stay NaN).
        torque: applied torque [N m]; speed_diff: output speed difference [rad/s].
    """

    rows: list[dict]
    runs: list[dict]
    metrics: dict
    failed: str
    torque: float
    speed_diff: float


def evaluate(p, modes: list[int], torque: float | None = None,
             speed_diff: float | None = None, friction_scale: float = 1.0,
             analytic_only: bool = False, on_run=None, parallel: bool = True,
             source: str = "", overrides: list[str] | dict | tuple = ()) -> TdrEvaluation:
    """Simulate the bench runs that cover ``modes`` and give every mode's TDR with its
    analytic and measured values (the computation behind ``drivedyn tdr`` and TDR sweeps).

    Args:
        p: parameters of a differential (its validated model file).
        modes: locking modes 1-4 to evaluate.
        torque: applied torque [N m] (default ``bench.torque``).
        speed_diff: output speed difference [rad/s] (default ``bench.speed_diff``).
        friction_scale: factor on every friction coefficient.
        analytic_only: only the analytic quasi-static TDR (no simulation).
        on_run: ``on_run(side, pair)`` called before each bench run, ``on_run(run)`` after
            (a :class:`BenchRun`); for progress messages.
        parallel: run the two bench sides at the same time where :func:`parallel_sides`
            allows (False: one after the other; the results are the same).
        source, overrides: the model file (or shipped name) and the ``--set`` overrides of
            ``p``, recorded with each bench run's results (:func:`run_bench`).
    """
    diff = differentials.of(p)
    T0 = p.bench.torque if torque is None else torque
    dw = p.bench.speed_diff if speed_diff is None else speed_diff
    exp = experimental(p)
    sim: dict[int, float] = {}
    runs: list[dict] = []
    failed = ""
    metrics = {"dissipated_energy": float("nan"), "peak_pressure": float("nan"),
               "peak_pressure_at": "", "steps": 0, "rejected_steps": 0,
               "newton_iterations": 0}
    ana: dict[int, float] = {}

    analytic_failed: list[str] = []

    def analytic() -> None:
        for m in modes:
            if m not in ana:
                try:
                    ana[m] = diff.analytic_bench(p, m, T0, dw, friction_scale)
                except RuntimeError as exc:  # no sliding equilibrium (e.g. self-locking)
                    ana[m] = float("nan")
                    analytic_failed.append(f"analytic model failed for mode {m}: {exc}")

    if not analytic_only:
        metrics["dissipated_energy"] = 0.0
        sides = [(s, pair) for s, pair in side_modes(p).items() if set(pair) & set(modes)]
        # the analytic values (their first call imports scipy.optimize, 0.4-0.7 s) while
        # the second side runs in its own process: no wall time there
        for side, run in _bench_runs(p, sides, T0, dw, friction_scale, on_run, analytic,
                                     parallel, {"source": source, "overrides": overrides}):
            m = run_metrics(run.results)
            metrics["dissipated_energy"] += m["dissipated_energy"]
            if not metrics["peak_pressure"] >= m["peak_pressure"]:
                metrics["peak_pressure"] = m["peak_pressure"]
                metrics["peak_pressure_at"] = f"{side}: {m['peak_pressure_at']}"
            for k in ("steps", "rejected_steps", "newton_iterations"):
                metrics[k] += m[k]
            runs.append({"side": side, "wall_s": round(run.wall_s, 3), "size": run.size,
                         "steps": int(run.results.stats.steps),
                         "newton_iterations": int(run.results.stats.newton_iterations),
                         "success": run.success})
            sim.update(run.tdr)
            if not run.success:
                failed = f"{side} bench run failed: {run.message}"
                break
    analytic()
    if analytic_failed and not failed:
        failed = "; ".join(analytic_failed)
    rows = []
    for m in modes:
        val = sim.get(m, float("nan")) if not analytic_only else ana[m]
        e = exp.get(m)
        rows.append({
            "mode": m, "name": mode_name(diff, m), "tdr": val, "analytic": ana[m],
            "experimental": e,
            "error_pct": 100 * (val / e - 1) if e and np.isfinite(val) else None,
            "sim_vs_analytic_pct": 100 * (val / ana[m] - 1) if np.isfinite(val) else None,
        })
    return TdrEvaluation(rows, runs, metrics, failed, T0, dw)
