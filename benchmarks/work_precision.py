"""Work-precision tables: error at the end of a run against the wall time of ``simulate``,
fixed steps and adaptive steps, for four models:

* ``squeezer``: Andrews' squeezing mechanism (``drivedyn.validation.squeezer``, three closed
  loops, t = 0.03 s); error of the crank angle against the seven-angle scipy reference.
* ``typec``: the TORSEN Type C on its test bench (rear side, the tests' short protocol:
  drive window 0.25-0.45 s, coast window 0.9 s to ``--t-bench``), the file's solver
  settings otherwise; error of the two window TDRs against a run at fixed steps of
  ``--h-ref``.
* ``vehicle``: the 4WD vehicle with its three TORSENs launched from rest, ``--t-vehicle``
  seconds; error: the window means of the four wheel torques over the second half of the
  run and the speed at its end, largest relative difference from a fixed-step reference.
* ``rwd``: the RWD vehicle (open rear) on its split-mu launch, the same measure with the
  two rear wheel torques.

A vehicle's final state is no accuracy measure: the gears' rattle in their backlash and the
tyres' slip make the pointwise state differ by 1e-4 between any two settings, while the
figures an engineer reads (window means, the speed) converge.

Usage::

    python benchmarks/work_precision.py                 # all four
    python benchmarks/work_precision.py --only squeezer
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np

import drivedyn as dd
from drivedyn.validation import squeezer as S  # noqa: N812


def _row(kind: str, setting: str, res, wall: float, err: float) -> str:
    st = res.stats
    tot = st.steps + st.rejected
    return (f"{kind:9s} {setting:>10s} {wall:9.3f} {st.steps:7d} {st.rejected:6d} "
            f"{st.rejected / max(tot, 1):6.1%} {err:10.2e}")


def _table(title: str, run: Callable, error: Callable, fixed: list[float],
           rtols: list[float]) -> None:
    print(f"\n{title}")
    print(f"{'steps':9s} {'h / rtol':>10s} {'wall [s]':>9s} {'steps':>7s} {'rej.':>6s} "
          f"{'rej. %':>6s} {'error':>10s}")
    run(dd.FixedStep(fixed[0] if fixed else 1e-5))  # warm-up: compiled kernels loaded
    for h in fixed:
        t0 = time.perf_counter()
        res = run(dd.FixedStep(h))
        print(_row("fixed", f"{h:.1e}", res, time.perf_counter() - t0, error(res)), flush=True)
    for rtol in rtols:
        t0 = time.perf_counter()
        res = run(rtol)
        print(_row("adaptive", f"{rtol:.0e}", res, time.perf_counter() - t0, error(res)),
              flush=True)


def squeezer() -> None:
    model = S.squeezer_model()
    qref, _ = S.reference_solution()

    def error(res) -> float:
        return float(abs(S.squeezer_angles(res)[0][-1] - qref[0]))

    def paired(step):  # adaptive: rtol with atol = 1e-2 m x rtol
        if not isinstance(step, dd.FixedStep):
            step = dd.AdaptiveStep(h0=1e-6, h_max=1e-3, rtol=step, atol=1e-2 * step)
        return dd.simulate(model, S.T_END, step=step, output_dt=5e-4)

    def atol_fixed(step):  # adaptive: rtol with atol = 1e-9
        if not isinstance(step, dd.FixedStep):
            step = dd.AdaptiveStep(h0=1e-6, h_max=1e-3, rtol=step, atol=1e-9)
        return dd.simulate(model, S.T_END, step=step, output_dt=5e-4)

    fixed = [4e-5, 2e-5, 1e-5, 5e-6, 2.5e-6]
    _table("Andrews' squeezer, t = 0.03 s, error of beta [rad]; adaptive: atol = 1e-2 m x "
           "rtol, h_max 1 ms", paired, error, fixed,
           [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8])
    _table("the same, adaptive with atol fixed at 1e-9 (the relative part dominates down to "
           "rtol 1e-6)", atol_fixed, error, [], [1e-3, 1e-4, 1e-5, 1e-6, 1e-7])


def _state_error(ref) -> Callable:
    names = [n for n in ref.dataset.data_vars if str(n).endswith((".position", ".rotation"))]
    final = {n: ref.final(n) for n in names}

    def error(res) -> float:
        if not res.success:
            return float("nan")
        return float(max(np.abs(res.final(n) - final[n]).max() for n in names))
    return error


def _solver_run(model, t_end: float, kw: dict, output_dt: float,
                factor: bool = False) -> Callable:
    """``run(step)``: a fixed step, or for a number an adaptive step with that rtol and the
    settings' atol (``factor``: the settings' rtol, atol and atol_rot times the number)."""
    def run(step):
        opts = dict(kw)
        if isinstance(step, dd.FixedStep):
            opts["step"] = step
        else:
            st = kw["step"]
            if factor:
                arot = None if st.atol_rot is None else step * st.atol_rot
                opts["step"] = dd.AdaptiveStep(st.h0, st.h_min, st.h_max, step * st.rtol,
                                               step * st.atol, atol_rot=arot)
            else:
                opts["step"] = dd.AdaptiveStep(st.h0, st.h_min, st.h_max, step, st.atol,
                                               atol_rot=st.atol_rot)
        return dd.simulate(model, t_end, output_dt=output_dt, **opts)
    return run


def typec(t_end: float, h_ref: float) -> None:
    """The rear bench side (modes 1, 2) on the SHORT protocol of the tests; error: the largest
    relative difference of the two window TDRs from a run at fixed steps of ``h_ref``."""
    from drivedyn.analysis.tdr import window_tdr
    from drivedyn.config import read_library_file
    from drivedyn.library.differentials import of
    from drivedyn.library.differentials.scenarios import bench_spec
    from drivedyn.model.compile import compile_model

    short = {"gears.stiffness_variation": False, "bench.ramp": 0.1,
             "bench.transition": [0.5, 0.8], "bench.t_end": t_end,
             "bench.window_drive": [0.25, 0.45], "bench.window_coast": [0.9, t_end]}
    p, _, _ = read_library_file("torsen-c", short)
    diff = of(p)
    model = compile_model(bench_spec(diff, p, diff.sides[0])[0])
    kw = p.solver.settings()
    st = kw["step"]

    def run(step):
        opts = dict(kw)
        if isinstance(step, dd.FixedStep):
            opts["step"] = step
        else:  # ``step``: factor on the file's rtol, atol and atol_rot
            opts["step"] = dd.AdaptiveStep(st.h0, st.h_min, st.h_max, step * st.rtol,
                                           step * st.atol, atol_rot=step * st.atol_rot)
        return dd.simulate(model, t_end, output_dt=p.solver.output_dt, **opts)

    def tdrs(res) -> np.ndarray:
        return np.array([window_tdr(res, w)[0]
                         for w in (p.bench.window_drive, p.bench.window_coast)])

    ref = tdrs(run(dd.FixedStep(h_ref)))

    def error(res) -> float:
        return float(np.abs(tdrs(res) / ref - 1.0).max()) if res.success else float("nan")

    _table(f"TORSEN Type C bench (rear, modes 1-2), t = {t_end:g} s, TDR error against fixed "
           f"{h_ref:.0e} s; adaptive: the file's tolerances (rtol {st.rtol:g}, atol "
           f"{st.atol:g}, atol_rot {st.atol_rot}) times the factor in the second column",
           run, error, [1e-4, 5e-5, 2.5e-5], [10.0, 3.0, 1.0, 0.3, 0.1])


def _window_error(summary: Callable, ref) -> Callable:
    """Error of a vehicle run: the largest relative difference of its window figures
    (``summary(res)``: wheel torques [N m], vehicle speed [m/s]) from the reference's."""
    r = summary(ref)

    def error(res) -> float:
        if not res.success:
            return float("nan")
        return float(np.abs(summary(res) / r - 1.0).max())
    return error


def vehicle(t_end: float, h_ref: float) -> None:
    """The 4WD vehicle with its three TORSENs, launched from rest; error: the window means of
    the four wheel torques and the vehicle speed at the end, second half of the run."""
    import drivedyn.analysis.vehicle_4wd as V  # noqa: N812
    from drivedyn.config import read_library_file
    from drivedyn.library.vehicles.vehicle_4wd import build_spec
    from drivedyn.model.compile import compile_model

    p, _, _ = read_library_file("vehicle-4wd")
    p = V.configure(p, "torsen")
    tc, _, _ = read_library_file("torsen-c")
    tb, _, _ = read_library_file("torsen-b")
    spec, lay = build_spec(p, {"torsen-c": tc, "torsen-b": tb})
    model = compile_model(spec)
    kw = p.solver.settings(h_max=p.run.h_max)
    run = _solver_run(model, t_end, kw, 1e-3, factor=True)
    window = (0.5 * t_end, t_end)

    def figures(res) -> np.ndarray:
        s = V.summarize(res, lay, window)
        return np.array([s.wheels[w].torque for w in V.WHEELS] + [s.speed])

    error = _window_error(figures, run(dd.FixedStep(h_ref)))
    _table(f"4WD vehicle (TORSEN), t = {t_end:g} s, error: wheel torques over {window} s and "
           f"final speed against fixed {h_ref:.0e} s; adaptive: the file's tolerances (rtol "
           f"{kw['step'].rtol:g}, atol {kw['step'].atol:g}) times the factor in the second "
           "column", run, error, [2e-4, 1e-4, 5e-5], [3.0, 1.0, 0.3, 0.1, 0.03])


def vehicle_rwd(t_end: float, h_ref: float) -> None:
    """The RWD vehicle (flexible ladder frame, suspensions on bushings, engine map, open rear
    differential), split-mu launch from its static start; error: the window means of the
    two rear wheel torques and the vehicle speed, second half of the run."""
    import drivedyn.analysis.vehicle_rwd as V  # noqa: N812
    from drivedyn.config import read_library_file
    from drivedyn.config.loader import read_vehicle_differentials, resolve_path
    from drivedyn.library.vehicles.vehicle_rwd import build_spec
    from drivedyn.model.compile import compile_model

    base = resolve_path("vehicle-rwd").parent
    p, _, source = read_library_file("vehicle-rwd")
    p = V.configure(p, "open")
    torsen = read_vehicle_differentials(p, source, base)
    spec, lay = build_spec(p, torsen, base)
    model = compile_model(spec)
    state = V.static_start(p, torsen, base, model, lay)
    kw = dict(p.solver.settings(h_max=p.run.h_max), state=state)
    run = _solver_run(model, t_end, kw, 1e-3, factor=True)
    window = (0.5 * t_end, t_end)

    def figures(res) -> np.ndarray:
        s = V.summarize(res, lay, window)
        return np.array([s.wheels["rl"].torque, s.wheels["rr"].torque, s.speed])

    error = _window_error(figures, run(dd.FixedStep(h_ref)))
    _table(f"RWD vehicle (open rear), t = {t_end:g} s, error: rear wheel torques and speed "
           f"over {window} s against fixed {h_ref:.0e} s; adaptive: the file's tolerances (rtol "
           f"{kw['step'].rtol:g}, atol {kw['step'].atol:g}) times the factor in the second "
           "column", run, error, [2e-4, 1e-4, 5e-5], [3.0, 1.0, 0.3, 0.1, 0.03])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", choices=("squeezer", "typec", "vehicle", "rwd"))
    ap.add_argument("--t-bench", type=float, default=1.1)
    ap.add_argument("--t-vehicle", type=float, default=0.6)
    ap.add_argument("--h-ref", type=float, default=1e-5)
    a = ap.parse_args()
    if a.only in (None, "squeezer"):
        squeezer()
    if a.only in (None, "typec"):
        typec(a.t_bench, a.h_ref)
    if a.only in (None, "vehicle"):
        vehicle(a.t_vehicle, a.h_ref)
    if a.only in (None, "rwd"):
        vehicle_rwd(a.t_vehicle, a.h_ref)


if __name__ == "__main__":
    main()
