"""The test bench of ``drivedyn tdr`` as inputs of a differential FMU, and the TDRs of the
FMU's outputs over the bench's windows (the FMU-versus-``tdr`` comparison of the tests and of
``benchmarks/fmu_bench.py``).

The bench (:mod:`drivedyn.library.differentials.scenarios`) holds the housing, applies the
torque ``T0 s(t)`` to the loaded output and controls the other one's speed, with ``s(t)``
going 0 -> +1 (drive) -> -1 (coast). Its steady states seen from the FMU's causality: the
housing at rest, the loaded output at ``-s w_loaded`` and the other at ``+s w_other`` (the
speeds with the housing held, ``housing_fixed_speeds``), and on the housing the torque that
holds it, ``T0 s (1 + 1/TDR)``: the outputs then carry ``T0`` (the loaded one) and
``T0 / TDR``, as on the bench. The TDR that sets the housing torque is the analytic one of
the mode; the FMU's own TDR comes out of its run.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from drivedyn.library import differentials
from drivedyn.library.differentials.cosim import INPUT_TORQUE, speed_input
from drivedyn.library.differentials.scenarios import bench_profile


def bench_inputs(p: Any, side: str, dt: float, torque: float | None = None,
                 speed_diff: float | None = None) -> np.ndarray:
    """The bench run of loaded output ``side`` as FMU inputs sampled every ``dt`` [s] from 0
    to ``bench.t_end``: a structured array with fields ``time`` [s], ``input_torque``
    [N m] and the two ``{output}_speed`` [rad/s] (the ``input`` of ``fmpy.simulate_fmu``).

    Args:
        p: validated parameters of a differential.
        side: the loaded output (its drive and coast modes, ``diff.side_modes``).
        dt: sampling interval [s] (the communication step: each sample is held over it).
        torque: the loaded output's torque [N m] (default ``bench.torque``).
        speed_diff: output speed difference [rad/s] (default ``bench.speed_diff``).
    """
    diff = differentials.of(p)
    T0 = p.bench.torque if torque is None else torque
    dw = p.bench.speed_diff if speed_diff is None else speed_diff
    speeds = dict(zip((o.name for o in diff.outputs), diff.housing_fixed_speeds(p, dw),
                      strict=True))
    drive, coast = diff.side_modes[side]
    f_drive = 1.0 + 1.0 / diff.analytic_bench(p, drive, T0, dw, 1.0)
    f_coast = 1.0 + 1.0 / diff.analytic_bench(p, coast, T0, dw, 1.0)
    other = diff.other(side).name
    t = np.linspace(0.0, p.bench.t_end, round(p.bench.t_end / dt) + 1)
    s = np.asarray(bench_profile(p)(t), float)
    names = (INPUT_TORQUE, speed_input(side), speed_input(other))
    out = np.zeros(t.size, dtype=[("time", float)] + [(n, float) for n in names])
    out["time"] = t
    out[INPUT_TORQUE] = T0 * s * np.where(s >= 0.0, f_drive, f_coast)
    out[speed_input(side)] = -s * speeds[side]
    out[speed_input(other)] = s * speeds[other]
    return out


def window_tdrs(p: Any, side: str, time: np.ndarray, torques: dict[str, np.ndarray]
                ) -> dict[int, float]:
    """Mode -> TDR (loaded over other output torque, window means) of a run of
    :func:`bench_inputs`, from its output times [s] and ``{output}_torque`` series [N m]."""
    diff = differentials.of(p)
    loaded = torques[f"{side}_torque"]
    other = torques[f"{diff.other(side).name}_torque"]
    out = {}
    for mode, (a, b) in zip(diff.side_modes[side], (p.bench.window_drive,
                                                    p.bench.window_coast), strict=True):
        k = (time >= a - 1e-12) & (time <= b + 1e-12)
        out[mode] = float(abs(loaded[k].mean() / other[k].mean())) if k.sum() >= 2 \
            else float("nan")
    return out
