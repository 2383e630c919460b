"""Calibration of friction coefficients to measured torque distribution ratios, for any
differential of :mod:`drivedyn.library.differentials`.

Least squares on ``log(TDR_model / TDR_measured)`` over the free parameters, bounded to a
plausible range. A free parameter is one dotted key of the model file (e.g.
``washers.sun_housing.mu``) or a group of keys that share one fitted value (e.g. all the
washer coefficients of the Type C: *one shared coefficient*). The analytic quasi-static model
of the differential does the fitting; the bench simulation then confirms it. If the simulated
TDRs differ from the analytic ones by more than ``sim_tol``, the targets are corrected by that
ratio and the analytic fit is repeated (a fixed-point on the small model difference), so the
shipped coefficients reproduce the measurements *in simulation*.

A fit with as many free numbers as measurements reproduces them by construction and predicts
nothing; :func:`cross_validate` gives the honest predictive error: it refits leaving out each
mode in turn and reports the error of the left-out mode's prediction.

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

from drivedyn.library import differentials

Group = tuple[str, ...]


@dataclass
class Calibration:
    """Outcome of :func:`calibrate`.

    Attributes:
        params: the calibrated parameter set.
        values: dotted key -> fitted value (tied keys share theirs).
        groups: the free parameters, each a tuple of tied keys.
        targets: mode -> measured TDR.
        analytic: mode -> analytic TDR with the fitted values.
        simulated: mode -> simulated TDR (empty without confirmation).
        iterations: analytic fits done (1 + corrections from the simulation).
        cost: final least-squares cost (half the sum of squared log errors).
        at_bound: free keys that ended on a bound.
        offsets: mode -> simulated / analytic TDR of the final parameters (1 without
            confirmation).
    """

    params: Any
    values: dict[str, float]
    groups: list[Group]
    targets: dict[int, float]
    analytic: dict[int, float]
    simulated: dict[int, float] = field(default_factory=dict)
    iterations: int = 1
    cost: float = 0.0
    at_bound: list[str] = field(default_factory=list)
    offsets: dict[int, float] = field(default_factory=dict)


def get_value(p: Any, key: str) -> Any:
    """The value of a dotted key of the parameter set."""
    obj: Any = p
    for part in key.split("."):
        if not hasattr(obj, part):
            raise KeyError(f"{key}: no such parameter ({part!r} unknown)")
        obj = getattr(obj, part)
    return obj


def with_values(p: Any, values: dict[str, float]) -> Any:
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
    return type(p).model_validate(data)


def groups_of(free: list[str | Group]) -> list[Group]:
    """Free parameters as groups of tied keys (a key alone, a tuple, or ``"a,b,c"``)."""
    out: list[Group] = []
    for f in free:
        g = tuple(k.strip() for k in f.split(",")) if isinstance(f, str) else tuple(f)
        if not g or any(not k for k in g):
            raise ValueError(f"free parameter {f!r}: expected dotted keys")
        out.append(g)
    return out


def _expand(groups: list[Group], x: np.ndarray) -> dict[str, float]:
    return {k: float(v) for g, v in zip(groups, x, strict=True) for k in g}


def _analytic(p: Any, modes: list[int]) -> dict[int, float]:
    diff = differentials.of(p)
    return {m: diff.analytic_bench(p, m) for m in modes}


def _fit(p: Any, groups: list[Group], targets: dict[int, float], bounds: tuple[float, float],
         x0: np.ndarray) -> tuple[np.ndarray, float]:
    modes = sorted(targets)
    want = np.array([targets[m] for m in modes])

    def resid(x):
        got = _analytic(with_values(p, _expand(groups, x)), modes)
        return np.log(np.array([got[m] for m in modes]) / want)

    lo, hi = bounds
    x0 = np.clip(x0, lo + 1e-9, hi - 1e-9)
    sol = least_squares(resid, x0, bounds=(np.full(len(groups), lo), np.full(len(groups), hi)),
                        xtol=1e-12, ftol=1e-12, gtol=1e-12)
    return sol.x, float(sol.cost)


def _simulate(q: Any, progress=None) -> dict[int, float]:
    from drivedyn.analysis.tdr import run_bench

    sim: dict[int, float] = {}
    for side in differentials.of(q).sides:
        if progress:
            progress(f"confirming by simulation: bench with the torque on the {side} output")
        run = run_bench(q, side)
        if not run.success:
            raise RuntimeError(f"bench simulation ({side}) failed: {run.message}")
        sim.update(run.tdr)
    return sim


def check_free(p: Any, groups: list[Group], targets: dict[int, float]) -> None:
    """Refuse free keys that are not friction coefficients of ``p`` and modes that do not
    exist (ValueError/KeyError naming them)."""
    if not groups:
        raise ValueError("nothing to fit: give at least one free coefficient")
    seen: set[str] = set()
    for g in groups:
        for key in g:
            v = get_value(p, key)
            if not isinstance(v, float) or not key.endswith("mu"):
                raise ValueError(f"{key}: only friction coefficients (keys ending in 'mu') "
                                 "can be fitted")
            if key in seen:
                raise ValueError(f"{key}: appears in two free parameters")
            seen.add(key)
    modes = [m.number for m in differentials.of(p).modes]
    bad = [m for m in targets if m not in modes]
    if bad:
        raise ValueError(f"targets: modes must be in {modes}, got {bad}")


def calibrate(p: Any, free: list[str | Group], targets: dict[int, float],
              bounds: tuple[float, float] = (0.02, 0.2), confirm: bool = True,
              sim_tol: float = 0.005, max_corrections: int = 2, progress=None) -> Calibration:
    """Fit the free coefficients so that the TDR of the target modes match.

    Args:
        p: starting parameters (a differential's model file).
        free: free parameters: dotted keys of friction coefficients, or tuples of keys that
            share one value (see :func:`groups_of`).
        targets: mode (1-4) -> measured TDR.
        bounds: plausible range of every free coefficient.
        confirm: simulate the bench with the fitted values (and correct, see module doc).
        sim_tol: largest accepted relative difference simulation / analytic before a
            correction.
        max_corrections: number of target corrections from the simulation.
        progress: ``progress(message)`` callback for long steps.
    """
    groups = groups_of(free)
    check_free(p, groups, targets)
    x0 = np.array([np.mean([get_value(p, k) for k in g]) for g in groups], float)
    goal = dict(targets)
    x, cost = _fit(p, groups, goal, bounds, x0)
    q = with_values(p, _expand(groups, x))
    modes = [m.number for m in differentials.of(p).modes]
    ana = _analytic(q, modes)
    sim: dict[int, float] = {}
    its = 1
    off = {m: 1.0 for m in modes}
    if confirm:
        for corr in range(max_corrections + 1):
            sim = _simulate(q, progress)
            off = {m: sim[m] / ana[m] for m in modes}
            if all(abs(off[m] - 1) <= sim_tol for m in targets) or corr == max_corrections:
                break
            # correct the analytic targets by the model difference, refit
            goal = {m: targets[m] / off[m] for m in targets}
            x, cost = _fit(p, groups, goal, bounds, x)
            q = with_values(p, _expand(groups, x))
            ana = _analytic(q, modes)
            its += 1
    lo, hi = bounds
    at_bound = [", ".join(g) for g, v in zip(groups, x, strict=True)
                if min(v - lo, hi - v) < 1e-6]
    return Calibration(q, _expand(groups, x), groups, dict(targets), ana, sim, its, cost,
                       at_bound, off)


def cross_validate(p: Any, free: list[str | Group], targets: dict[int, float],
                   bounds: tuple[float, float] = (0.02, 0.2),
                   offsets: dict[int, float] | None = None, confirm: bool = False,
                   progress=None) -> dict[int, dict[str, float]]:
    """Leave-one-out: for each target mode, fit the free parameters to the *other* modes and
    predict the left-out one.

    Args:
        p, free, targets, bounds: as :func:`calibrate`.
        offsets: mode -> simulated / analytic TDR (from a confirmed :func:`calibrate`); the
            fits aim at ``target / offset`` and the predictions are ``analytic * offset``, so
            that they stand for the simulation. None: the analytic model alone.
        confirm: simulate the bench of each left-out fit instead (costs two bench runs per
            mode).
    Returns:
        mode -> {``predicted``, ``target``, ``error_pct``, and per free group its fitted
        value (key: the group's first key)}.
    """
    groups = groups_of(free)
    check_free(p, groups, targets)
    off = offsets or {}
    out: dict[int, dict[str, float]] = {}
    x0 = np.array([np.mean([get_value(p, k) for k in g]) for g in groups], float)
    for m in sorted(targets):
        rest = {k: targets[k] / off.get(k, 1.0) for k in targets if k != m}
        if progress:
            progress(f"leave-one-out: fitting without mode {m}")
        x, _ = _fit(p, groups, rest, bounds, x0)
        q = with_values(p, _expand(groups, x))
        if confirm:
            pred = _simulate(q, progress)[m]
        else:
            pred = differentials.of(q).analytic_bench(q, m) * off.get(m, 1.0)
        rec = {"predicted": float(pred), "target": float(targets[m]),
               "error_pct": 100.0 * (pred / targets[m] - 1.0)}
        rec.update({g[0]: float(v) for g, v in zip(groups, x, strict=True)})
        out[m] = rec
    return out


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


def calibration_table(cal: Calibration, source: str, command: str,
                      cv: dict[int, dict[str, float]] | None = None) -> dict[str, Any]:
    """The ``[calibration]`` table recording a fit (and its leave-one-out errors ``cv``, see
    :func:`cross_validate`)."""
    res: dict[str, float] = {}
    for m in sorted(cal.targets):
        res[f"mode{m}_analytic"] = round(cal.analytic[m], 4)
        if cal.simulated:
            res[f"mode{m}_simulated"] = round(cal.simulated[m], 4)
    return {
        "fitted": list(cal.values),
        "tied": [list(g) for g in cal.groups if len(g) > 1],
        "targets": {f"mode{m}": v for m, v in sorted(cal.targets.items())},
        "source": source,
        "command": command,
        "method": (f"bounded least squares on log TDR of {len(cal.groups)} free number(s) "
                   f"for {len(cal.targets)} measurement(s) with the analytic quasi-static model, "
                   + ("confirmed by bench simulation; " if cal.simulated else "")
                   + f"{cal.iterations} analytic fit(s)"),
        "result": res,
        "cross_validation": {f"mode{m}": round(r["error_pct"], 2)
                             for m, r in sorted((cv or {}).items())},
    }


def relative_errors(values: dict[int, float], targets: dict[int, float]) -> dict[int, float]:
    """mode -> 100 (value / target - 1) [%]."""
    return {m: 100 * (values[m] / targets[m] - 1) for m in targets if m in values
            and math.isfinite(values[m])}
