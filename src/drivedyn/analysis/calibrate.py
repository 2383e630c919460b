"""Calibration of friction coefficients to measured torque distribution ratios, for any
differential of :mod:`drivedyn.library.differentials`.

Least squares on ``log(TDR_model / TDR_measured)`` over the free parameters, each bounded
to its physical range (the model file's ``[calibration] bounds``, with their source in
``bounds_source``). A fit that ends on a bound (within 1 % of the range,
:data:`BOUND_MARGIN`) is a failed calibration (:class:`FitAtBoundError`): the measurements ask
for a coefficient outside its physical range, so the model lacks a mechanism or the range
is wrong, and the fitted numbers mean nothing. A free parameter is one dotted key of the
model file (e.g. ``washers.sun_housing.mu``) or a group of keys that share one fitted value
(e.g. the washer and pocket coefficients of the Type C: *one shared coefficient*). The
analytic quasi-static model of the differential does the fitting; the bench simulation then
confirms it. If the simulated TDRs differ from the analytic ones by more than ``sim_tol``,
the targets are corrected by that ratio and the analytic fit is repeated (a fixed-point on
the small model difference), so the shipped coefficients reproduce the measurements *in
simulation*.

A fit with as many free numbers as measurements reproduces them by construction and predicts
nothing; :mod:`drivedyn.analysis.calibration_study` gives the honest predictive error
(leave-out by distinct measurement), the cost profile of each fitted number and the spread
under the measurement uncertainty.

:func:`update_toml_text` writes the model file with the fitted values and a
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
#: dotted key -> (low, high) physical range of a friction coefficient
Bounds = dict[str, tuple[float, float]]

#: a fitted number closer to a bound than this fraction of its range ends "on the bound"
BOUND_MARGIN = 0.01


class FitAtBoundError(RuntimeError):
    """A fitted number ended on a bound of its physical range: a failed calibration.

    Attributes:
        keys: per offending group: (label, value, low, high).
    """

    def __init__(self, hits: list[tuple[str, float, float, float]], source: str = ""):
        self.keys = hits
        lines = []
        for label, v, lo, hi in hits:
            side, want = ("upper", "more") if hi - v < v - lo else ("lower", "less")
            lines.append(
                f"{label} = {v:.4f} ends on the {side} bound of its range [{lo:g}, {hi:g}]: the "
                f"measurements ask for {want} friction than the physical range allows, so the "
                "model lacks a loss mechanism (or the range is wrong)")
        msg = "; ".join(lines) + ". A fit on a bound is a failed calibration: nothing written"
        if source:
            msg += f" (bounds: {source})"
        super().__init__(msg)


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
        at_bound: free groups (labels ``"a, b"``) that ended within :data:`BOUND_MARGIN` of
            a bound.
        bounds: per free group its (low, high) range.
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
    bounds: list[tuple[float, float]] = field(default_factory=list)


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


def expand_groups(groups: list[Group], x: np.ndarray) -> dict[str, float]:
    """Dotted key -> value of each free group's number ``x`` (tied keys share theirs)."""
    return {k: float(v) for g, v in zip(groups, x, strict=True) for k in g}


def analytic_tdrs(p: Any, modes: list[int]) -> dict[int, float]:
    """mode -> TDR of the differential's analytic quasi-static model on the bench."""
    diff = differentials.of(p)
    return {m: float(diff.analytic_bench(p, m)) for m in modes}


def start_values(p: Any, groups: list[Group]) -> np.ndarray:
    """Start of a fit: each group's mean of its keys' values in ``p``."""
    return np.array([np.mean([get_value(p, k) for k in g]) for g in groups], float)


def group_bounds(p: Any, groups: list[Group],
                 bounds: tuple[float, float] | None = None) -> list[tuple[float, float]]:
    """(low, high) of each free group: ``bounds`` for all if given, else the model file's
    ``[calibration] bounds`` (a tied group takes the intersection of its keys' ranges).
    KeyError names a key without a range."""
    if bounds is not None:
        return [tuple(bounds)] * len(groups)
    table = file_bounds(p)
    out: list[tuple[float, float]] = []
    for g in groups:
        missing = [k for k in g if k not in table]
        if missing:
            raise KeyError(f"{missing[0]}: no physical range in the file's [calibration] bounds "
                           f"(declared: {', '.join(table) or 'none'}); add it there with its "
                           "source, or give --bounds LOW HIGH")
        lo, hi = max(table[k][0] for k in g), min(table[k][1] for k in g)
        if not lo < hi:
            raise ValueError(f"{', '.join(g)}: the tied keys' ranges do not overlap")
        out.append((lo, hi))
    return out


def file_bounds(p: Any) -> Bounds:
    """The model file's ``[calibration] bounds``: dotted key -> (low, high)."""
    cal = getattr(p, "calibration", None)
    return {k: (float(v[0]), float(v[1])) for k, v in (cal.bounds if cal else {}).items()}


def bound_hits(groups: list[Group], x: np.ndarray,
               bounds: list[tuple[float, float]]) -> list[tuple[str, float, float, float]]:
    """(label, value, low, high) of each group within :data:`BOUND_MARGIN` of a bound."""
    return [(", ".join(g), float(v), lo, hi)
            for g, v, (lo, hi) in zip(groups, x, bounds, strict=True)
            if min(v - lo, hi - v) <= BOUND_MARGIN * (hi - lo)]


def fit_log_tdr(p: Any, groups: list[Group], targets: dict[int, float],
                bounds: list[tuple[float, float]], x0: np.ndarray) -> tuple[np.ndarray, float]:
    """Bounded least squares of ``ln(TDR_m / target_m)`` (every measurement with the same
    relative uncertainty); returns the fitted numbers and the cost (half the sum of
    squares)."""
    modes = sorted(targets)
    want = np.array([targets[m] for m in modes])

    def resid(x):
        got = analytic_tdrs(with_values(p, expand_groups(groups, x)), modes)
        return np.log(np.array([got[m] for m in modes]) / want)

    lo = np.array([b[0] for b in bounds])
    hi = np.array([b[1] for b in bounds])
    x0 = np.clip(x0, lo + 1e-9, hi - 1e-9)
    sol = least_squares(resid, x0, bounds=(lo, hi), xtol=1e-12, ftol=1e-12, gtol=1e-12)
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


def _refuse(groups: list[Group], x: np.ndarray, box: list[tuple[float, float]], p: Any,
            refuse: bool) -> None:
    hits = bound_hits(groups, x, box)
    if hits and refuse:
        cal = getattr(p, "calibration", None)
        raise FitAtBoundError(hits, cal.bounds_source if cal else "")


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
              bounds: tuple[float, float] | None = None, confirm: bool = True,
              sim_tol: float = 0.005, max_corrections: int = 2, progress=None,
              refuse_at_bound: bool = True) -> Calibration:
    """Fit the free coefficients so that the TDR of the target modes match.

    Args:
        p: starting parameters (a differential's model file).
        free: free parameters: dotted keys of friction coefficients, or tuples of keys that
            share one value (see :func:`groups_of`).
        targets: mode (1-4) -> measured TDR.
        bounds: one range for every free coefficient; None: the file's ``[calibration]
            bounds`` (:func:`group_bounds`).
        confirm: simulate the bench with the fitted values (and correct, see module doc).
        sim_tol: largest accepted relative difference simulation / analytic before a
            correction.
        max_corrections: number of target corrections from the simulation.
        progress: ``progress(message)`` callback for long steps.
        refuse_at_bound: raise :class:`FitAtBoundError` when a fitted number ends on a bound
            (before any simulation); False records it in ``at_bound`` instead.
    """
    groups = groups_of(free)
    check_free(p, groups, targets)
    box = group_bounds(p, groups, bounds)
    x0 = start_values(p, groups)
    goal = dict(targets)
    x, cost = fit_log_tdr(p, groups, goal, box, x0)
    _refuse(groups, x, box, p, refuse_at_bound)
    q = with_values(p, expand_groups(groups, x))
    modes = [m.number for m in differentials.of(p).modes]
    ana = analytic_tdrs(q, modes)
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
            x, cost = fit_log_tdr(p, groups, goal, box, x)
            _refuse(groups, x, box, p, refuse_at_bound)
            q = with_values(p, expand_groups(groups, x))
            ana = analytic_tdrs(q, modes)
            its += 1
    at_bound = [h[0] for h in bound_hits(groups, x, box)]
    return Calibration(q, expand_groups(groups, x), groups, dict(targets), ana, sim, its, cost,
                       at_bound, off, box)


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
                      study: dict[str, Any] | None = None) -> dict[str, Any]:
    """The ``[calibration]`` table recording a fit: the inputs of the file's table (bounds,
    uncertainty and their sources) kept, then what was fitted and, from ``study`` (keys
    ``distinct``, ``cross_validation``, ``profile``, ``spread`` as returned by
    :mod:`drivedyn.analysis.calibration_study`), what the fit can claim."""
    inputs = getattr(cal.params, "calibration", None)
    res: dict[str, float] = {}
    for m in sorted(cal.targets):
        res[f"mode{m}_analytic"] = round(cal.analytic[m], 4)
        if cal.simulated:
            res[f"mode{m}_simulated"] = round(cal.simulated[m], 4)
    table: dict[str, Any] = {}
    if inputs is not None and inputs.bounds:
        table["bounds"] = {k: list(v) for k, v in inputs.bounds.items()}
        table["bounds_source"] = inputs.bounds_source
    if inputs is not None:
        table["uncertainty"] = inputs.uncertainty
        if inputs.uncertainty_source:
            table["uncertainty_source"] = inputs.uncertainty_source
    table.update({
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
    })
    if study:
        table["left_out_together"] = [list(d) for d in study["distinct"]]
        errs = {m: e for lo in study["cross_validation"] for m, e in lo.error_pct.items()}
        table["cross_validation"] = {f"mode{m}": round(e, 2) for m, e in sorted(errs.items())}
        table["profile"] = {k: [round(x, 4) for x in v["interval"]]
                            for k, v in study["profile"].items()}
        sp = study["spread"]
        table["spread"] = {**{k: [round(x, 4) for x in v] for k, v in sp["values"].items()},
                           **{f"mode{m}": [round(x, 4) for x in v]
                              for m, v in sorted(sp["tdr"].items())}}
    return table


def relative_errors(values: dict[int, float], targets: dict[int, float]) -> dict[int, float]:
    """mode -> 100 (value / target - 1) [%]."""
    return {m: 100 * (values[m] / targets[m] - 1) for m in targets if m in values
            and math.isfinite(values[m])}
