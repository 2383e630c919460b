"""Validation of the RWD vehicle of seeds 001/002 (registered with
:func:`drivedyn.validation.base.register_case`):

* ``rwd_static_loads``: the parked vehicle's static solution (flexible ladder frame, double
  wishbones on bushings, tyres on a flat road). The four tyre loads sum to ``m g`` (1e-6
  relative: the static solve's residual is far below it; a mass that the builder counts but
  does not hang on the vehicle, or a weight cancelled in the static solution, shows at the
  1e-3 level) and the rear axle's share of them equals the one the centre of gravity gives,
  ``(x_f - x_cg) / (x_f - x_r)`` (0.5 %: the suspensions' small fore-aft reactions move it
  by about 1e-4).
* ``rwd_split_mu``: the seeds' launch on split-mu (left rear wheel on ice, mu 0.1, from
  walking pace with a throttle ramp; the shipped file's 3 s run, means over 1.5-3 s) with
  an open and (full run) a TORSEN Type B rear differential. The open differential's rear
  wheel torques are equal within 1 %; the TORSEN's rear torque ratio equals the Type B's
  analytic TDR of the drive modes (:func:`drivedyn.library.differentials.torsen_b.analytic.
  bench_tdr`, mode 1) within 1 % and the wheel on dry road gets more torque; for each run
  the driveline's power balance (engine = rear wheels + driveline dissipation + rate of the
  driveline's kinetic energy, :func:`drivedyn.analysis.vehicle_rwd.power_balance`) within
  0.5 % and the model's energy audit (balance error / work in at the window's end) within
  1 %.
"""

from __future__ import annotations

import time

from drivedyn.validation.base import CaseResult, compare, register_case
from drivedyn.validation.common import G, at_least, at_most, finish_case


def _vehicle(configs: list[str] | None = None, sets: list[str] | None = None):
    """The shipped vehicle file (with ``sets``), the TORSEN files it names and its folder."""
    import drivedyn.analysis.vehicle_rwd as V  # noqa: N812 - short name for the analysis
    from drivedyn.config import read_library_file
    from drivedyn.config.loader import read_vehicle_differentials, resolve_path

    p, _, source = read_library_file("vehicle-rwd", sets or [])
    base = resolve_path("vehicle-rwd").parent
    torsen: dict = {}
    for c in configs or [None]:
        q = V.configure(p, c) if c else p
        torsen.update(read_vehicle_differentials(q, source, base))
    return p, torsen, base


@register_case("rwd_static_loads")
def rwd_static_loads(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """See the module docstring. Mutations that fail it: cancelling the differential's gears'
    weight when parked (``lift=True`` in the static solution): the sum is off by 1e-3; the
    centre of gravity taken as the sprung body's own (x 0.056 m in Chrono's reference
    instead of the whole vehicle's 0.034 m): the reference share moves by 0.66 %."""
    import drivedyn.analysis.vehicle_rwd as V  # noqa: N812

    t0 = time.perf_counter()
    case = "rwd_static_loads"
    p, torsen, base = _vehicle()
    s = V.static(V.configure(p, "open"), torsen, base)
    total = sum(s.loads.values())
    out = [compare(case, "sum of the four tyre loads", s.mass * G, total, "N", 1e-6,
                   "statics: the road carries the weight m g"),
           compare(case, "rear axle's share of the tyre loads", s.rear_share_cg,
                   s.rear_share, "1", 5e-3,
                   "moments about the front axle: (x_f - x_cg) / (x_f - x_r)")]
    return finish_case(out, t0, [])


@register_case("rwd_split_mu")
def rwd_split_mu(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """See the module docstring (quick: the open differential only). Mutations that fail
    it: the vehicle's TORSEN built with its pockets' friction halved while the reference
    keeps the file's (the ratio drops by about 10 %); a bevel
    differential whose spiders are pinned (a locked differential: the torques differ by a
    factor 1.7); the engine shaft left out of the driveline's kinetic energy in the power
    balance (it holds most of it), or the TORSEN's friction and film losses left out of the
    driveline's dissipation (1.4 % of the engine's work over the window)."""
    import drivedyn.analysis.vehicle_rwd as V  # noqa: N812
    from drivedyn.library.differentials.torsen_b import analytic as ab

    t0 = time.perf_counter()
    case = "rwd_split_mu"
    configs = ["open"] if quick else ["open", "torsen-b"]
    p, torsen, base = _vehicle(configs)
    runs = {s.name: (s, res) for s, res in V.compare(p, torsen, configs, base)}
    out: list[CaseResult] = []
    so = runs["open"][0]
    tl, tr = so.wheels["rl"].torque, so.wheels["rr"].torque
    out.append(at_most(case, "open: |T_rl - T_rr| / mean rear wheel torque",
                       abs(tl - tr) / (0.5 * abs(tl + tr)), 0.01, "1",
                       "an open differential splits evenly (its spiders turn freely)"))
    if "torsen-b" in runs:
        st = runs["torsen-b"][0]
        out.append(compare(case, "TORSEN B rear torque ratio vs its analytic TDR (drive)",
                           ab.bench_tdr(torsen["torsen-b"], 1), st.axle_ratio["rear"], "1",
                           0.01, "the differential biases at its TDR once the ice wheel "
                           "spins (seeds 001/002); torsen_b analytic model"))
        out.append(at_least(case, "TORSEN B: dry wheel torque / ice wheel torque",
                            st.wheels["rr"].torque / st.wheels["rl"].torque, 1.0, "1",
                            "seeds 001/002: the wheel with more grip gets more torque"))
    for name, (s, _) in runs.items():
        out.append(at_most(case, f"{name}: driveline power balance", s.power_balance, 5e-3,
                           "1", "engine = rear wheels + driveline dissipation + "
                           "d(K_driveline)/dt, relative to the carrier"))
        out.append(at_most(case, f"{name}: energy audit (balance error / work in)",
                           s.energy_error, 1e-2, "1", "the model's energy account"))
    figures: list[str] = []
    if figure_dir:
        from drivedyn.validation.common import save_figure

        def draw(fig):
            ax = fig.add_subplot(1, 1, 1)
            for name, (s, _) in runs.items():
                h = s.history
                for w, ls in (("rl", "--"), ("rr", "-")):
                    ax.plot(h["time"], h[f"torque_{w}"], ls, label=f"{name} {w}")
            ax.axvspan(*p.run.window, color="0.9")
            ax.set_xlabel("time [s]")
            ax.set_ylabel("rear wheel drive torque [N m]")
            ax.set_title("RWD split-mu launch (left rear on mu 0.1)")
            ax.legend()

        figures = save_figure(figure_dir, case, draw)
    return finish_case(out, t0, figures)
