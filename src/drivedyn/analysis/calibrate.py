"""Calibration of friction coefficients to measured torque distribution ratios.

Least squares on ``log(TDR_model / TDR_measured)`` over the chosen free coefficients
(dotted keys of the model file, e.g. ``washers.sun_housing.mu``), bounded to a plausible
range. The analytic quasi-static model (:mod:`drivedyn.analysis.analytic_tdr`) does the
fitting; the bench simulation then confirms it. If the simulated TDRs differ from the
analytic ones by more than ``sim_tol``, the targets are corrected by that ratio and the
analytic fit is repeated (a fixed-point on the small model difference), so the shipped
coefficients reproduce the measurements *in simulation*.

:func:`write_calibrated` writes the model file with the fitted values and a
``[calibration]`` table that states which values were fitted to which data and the command
that reproduces the fit.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from drivedyn.analysis.analytic_tdr import all_modes
from drivedyn.library.torsen_c_schema import TorsenCFile


@dataclass
class Calibration:
    """Outcome of :func:`calibrate`.

    Attributes:
        params: the calibrated parameter set.
        values: free key -> fitted value.
        targets: mode -> measured TDR.
        analytic: mode -> analytic TDR with the fitted values.
        simulated: mode -> simulated TDR (empty without confirmation).
        iterations: analytic fits done (1 + corrections from the simulation).
        cost: final least-squares cost (half the sum of squared log errors).
        at_bound: free keys that ended on a bound.
    """

    params: TorsenCFile
    values: dict[str, float]
    targets: dict[int, float]
    analytic: dict[int, float]
    simulated: dict[int, float] = field(default_factory=dict)
    iterations: int = 1
    cost: float = 0.0
    at_bound: list[str] = field(default_factory=list)


def get_value(p: TorsenCFile, key: str) -> Any:
    """The value of a dotted key of the parameter set."""
    obj: Any = p
    for part in key.split("."):
        if not hasattr(obj, part):
            raise KeyError(f"{key}: no such parameter ({part!r} unknown)")
        obj = getattr(obj, part)
    return obj


def with_values(p: TorsenCFile, values: dict[str, float]) -> TorsenCFile:
    """A copy of ``p`` with dotted keys set (validated again)."""
    data = p.model_dump()
    for key, val in values.items():
        node = data
        parts = key.split(".")
        for part in parts[:-1]:
            node = node[part]
        if parts[-1] not in node:
            raise KeyError(f"{key}: no such parameter")
        node[parts[-1]] = float(val)
    return TorsenCFile.model_validate(data)


def _fit(p: TorsenCFile, free: list[str], targets: dict[int, float], bounds: tuple[float, float],
         x0: np.ndarray) -> tuple[np.ndarray, float]:
    modes = sorted(targets)
    want = np.array([targets[m] for m in modes])

    def resid(x):
        q = with_values(p, dict(zip(free, x, strict=True)))
        got = all_modes(q)
        return np.log(np.array([got[m - 1] for m in modes]) / want)

    lo, hi = bounds
    x0 = np.clip(x0, lo + 1e-9, hi - 1e-9)
    sol = least_squares(resid, x0, bounds=(np.full(len(free), lo), np.full(len(free), hi)),
                        xtol=1e-12, ftol=1e-12, gtol=1e-12)
    return sol.x, float(sol.cost)


def calibrate(p: TorsenCFile, free: list[str], targets: dict[int, float],
              bounds: tuple[float, float] = (0.02, 0.2), confirm: bool = True,
              sim_tol: float = 0.005, max_corrections: int = 2, progress=None) -> Calibration:
    """Fit the ``free`` coefficients so that the TDR of the target modes match.

    Args:
        p: starting parameters.
        free: dotted keys of friction coefficients to fit (e.g. ``washers.ring_case.mu``).
        targets: mode (1-4) -> measured TDR.
        bounds: plausible range of every free coefficient.
        confirm: simulate the bench with the fitted values (and correct, see module doc).
        sim_tol: largest accepted relative difference simulation / analytic before a
            correction.
        max_corrections: number of target corrections from the simulation.
        progress: ``progress(message)`` callback for long steps.
    """
    if not free:
        raise ValueError("nothing to fit: give at least one free coefficient")
    for key in free:
        v = get_value(p, key)
        if not isinstance(v, float) or not key.endswith("mu"):
            raise ValueError(f"{key}: only friction coefficients (keys ending in 'mu') can be "
                             "fitted")
    bad = [m for m in targets if m not in (1, 2, 3, 4)]
    if bad:
        raise ValueError(f"targets: modes must be 1-4, got {bad}")
    x0 = np.array([get_value(p, k) for k in free], float)
    goal = dict(targets)
    x, cost = _fit(p, free, goal, bounds, x0)
    q = with_values(p, dict(zip(free, x, strict=True)))
    ana = dict(zip((1, 2, 3, 4), all_modes(q), strict=True))
    sim: dict[int, float] = {}
    its = 1
    if confirm:
        from drivedyn.analysis.tdr import run_bench

        for corr in range(max_corrections + 1):
            sim = {}
            for side in ("rear", "front"):
                if progress:
                    progress(f"confirming by simulation: {side} bench")
                run = run_bench(q, side)
                if not run.success:
                    raise RuntimeError(f"bench simulation ({side}) failed: {run.message}")
                sim.update(run.tdr)
            off = {m: sim[m] / ana[m] for m in targets}
            if all(abs(o - 1) <= sim_tol for o in off.values()) or corr == max_corrections:
                break
            # correct the analytic targets by the model difference, refit
            goal = {m: targets[m] / off[m] for m in targets}
            x, cost = _fit(p, free, goal, bounds, x)
            q = with_values(p, dict(zip(free, x, strict=True)))
            ana = dict(zip((1, 2, 3, 4), all_modes(q), strict=True))
            its += 1
    lo, hi = bounds
    at_bound = [k for k, v in zip(free, x, strict=True) if min(v - lo, hi - v) < 1e-6]
    return Calibration(q, dict(zip(free, map(float, x), strict=True)), dict(targets), ana, sim,
                       its, cost, at_bound)


# -- writing the model file ----------------------------------------------------------------


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(round(float(v), 6)) if isinstance(v, float) else str(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f'{_key(k)} = {_toml_value(x)}' for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {v!r} to TOML")


def _key(k: str) -> str:
    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else _toml_value(k)


def update_toml_text(text: str, values: dict[str, float], calibration: dict[str, Any]) -> str:
    """The model file ``text`` with ``key = value`` lines of the dotted ``values`` replaced
    (comments kept) and its ``[calibration]`` table replaced by ``calibration``."""
    lines = text.splitlines()
    out: list[str] = []
    table = ""
    done: set[str] = set()
    skip = False
    for line in lines:
        m = re.match(r"^\s*\[([A-Za-z0-9_.\-]+)\]\s*(#.*)?$", line)
        if m:
            table = m.group(1)
            skip = table == "calibration" or table.startswith("calibration.")
            if skip:
                continue
        if skip:
            continue
        km = re.match(r"^(\s*)([A-Za-z0-9_\-]+)(\s*=\s*)([^#]*?)(\s*#.*)?$", line)
        if km and table:
            key = f"{table}.{km.group(2)}"
            if key in values:
                line = (f"{km.group(1)}{km.group(2)}{km.group(3)}"
                        f"{_toml_value(float(values[key]))}{km.group(5) or ''}")
                done.add(key)
        out.append(line)
    missing = set(values) - done
    if missing:
        raise KeyError(f"cannot find {', '.join(sorted(missing))} in the model file text")
    while out and not out[-1].strip():
        out.pop()
    out += ["", "[calibration]                    # written by drivedyn calibrate"]
    for k, v in calibration.items():
        out.append(f"{_key(k)} = {_toml_value(v)}")
    return "\n".join(out) + "\n"


def calibration_table(cal: Calibration, source: str, command: str) -> dict[str, Any]:
    """The ``[calibration]`` table recording a fit."""
    res: dict[str, float] = {}
    for m in sorted(cal.targets):
        res[f"mode{m}_analytic"] = round(cal.analytic[m], 4)
        if cal.simulated:
            res[f"mode{m}_simulated"] = round(cal.simulated[m], 4)
    return {
        "fitted": list(cal.values),
        "targets": {f"mode{m}": v for m, v in sorted(cal.targets.items())},
        "source": source,
        "command": command,
        "method": ("bounded least squares on log TDR with the analytic quasi-static model "
                   f"(drivedyn.analysis.analytic_tdr), confirmed by bench simulation; "
                   f"{cal.iterations} analytic fit(s)"),
        "result": res,
    }


def relative_errors(values: dict[int, float], targets: dict[int, float]) -> dict[int, float]:
    """mode -> 100 (value / target - 1) [%]."""
    return {m: 100 * (values[m] / targets[m] - 1) for m in targets if m in values
            and math.isfinite(values[m])}
