"""What a calibration can claim: its predictive error by distinct measurement, the cost
profile of each fitted number, and the spread under the measurement uncertainty.

All three use the analytic quasi-static model of the differential, with the simulated /
analytic ratio of each mode (``offsets``, from a confirmed
:func:`drivedyn.analysis.calibrate.calibrate`) applied so that the figures stand for the
simulation.

**Distinct measurements** (:func:`distinct_measurements`): two modes whose model TDRs agree,
at every point of the fitted numbers' ranges, to far less than the measurement uncertainty
(the Type B's mirror twins: modes 1 and 3, 2 and 4) are one measurement repeated, as far as
the model can tell. Leaving out one of them keeps its twin in the fit, so the leave-out
error would be a reweighting, not a prediction: :func:`cross_validate` leaves them out
together. A left-out fit with fewer distinct measurements left than fitted numbers cannot
determine them and predicts nothing (reported, not computed).

**Profile** (:func:`profile`): the chi-square ``sum ((ln TDR_model - ln TDR_measured) /
s)^2`` (``s`` the relative uncertainty of a measured TDR) along each fitted number, the
others refitted at each point; the interval where it rises by less than 1 above its minimum
is what the data determine (a flat profile: the data cannot tell the number). The fit
minimises the same sum, so the interval holds the fitted value.

**Spread** (:func:`spread`): every measurement scaled by ``1 +- s`` (all ``2^n`` corners),
refitted: the range of each fitted number and of each predicted TDR.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from drivedyn.analysis.calibrate import (
    Group,
    analytic_tdrs,
    bound_hits,
    expand_groups,
    fit_log_tdr,
    start_values,
    with_values,
)

#: two modes are one measurement when their model TDRs differ by less than this fraction of
#: the relative measurement uncertainty at every sampled point of the ranges
TELL_APART = 0.1


@dataclass
class LeftOut:
    """One leave-out fit: the distinct measurement ``modes`` left out together.

    Attributes:
        modes: the left-out modes (twins together).
        predicted: mode -> predicted TDR (NaN when not identifiable).
        error_pct: mode -> 100 (predicted / measured - 1).
        values: group label -> fitted value without the left-out modes.
        identifiable: enough distinct measurements left to determine the fitted numbers.
        at_bound: group labels that ended on a bound in this fit.
    """

    modes: tuple[int, ...]
    predicted: dict[int, float]
    error_pct: dict[int, float]
    values: dict[str, float] = field(default_factory=dict)
    identifiable: bool = True
    at_bound: list[str] = field(default_factory=list)


def _label(g: Group) -> str:
    return ", ".join(g)


def _points(bounds: list[tuple[float, float]]) -> list[np.ndarray]:
    """Sample points of the box: the quarter and three-quarter values of each range, all
    combinations (at most 8: the first three groups vary, the others at mid-range)."""
    pts = []
    k = min(len(bounds), 3)
    for corner in itertools.product((0.25, 0.75), repeat=k):
        x = [lo + 0.5 * (hi - lo) for lo, hi in bounds]
        for i, f in enumerate(corner):
            lo, hi = bounds[i]
            x[i] = lo + f * (hi - lo)
        pts.append(np.array(x))
    return pts


def distinct_measurements(p: Any, groups: list[Group], targets: dict[int, float],
                          bounds: list[tuple[float, float]],
                          uncertainty: float) -> list[tuple[int, ...]]:
    """The target modes grouped into distinct measurements: modes whose model TDRs agree to
    :data:`TELL_APART` of the relative uncertainty at every sampled point of the ranges
    (:func:`_points`) are one measurement."""
    modes = sorted(targets)
    tol = TELL_APART * uncertainty
    logs = []
    for x in _points(bounds):
        val = analytic_tdrs(with_values(p, expand_groups(groups, x)), modes)
        logs.append({m: math.log(val[m]) for m in modes})
    out: list[tuple[int, ...]] = []
    for m in modes:
        for i, grp in enumerate(out):
            if all(abs(lg[m] - lg[grp[0]]) < tol for lg in logs):
                out[i] = (*grp, m)
                break
        else:
            out.append((m,))
    return out


def cross_validate(p: Any, groups: list[Group], targets: dict[int, float],
                   bounds: list[tuple[float, float]], distinct: list[tuple[int, ...]],
                   offsets: dict[int, float] | None = None,
                   progress=None) -> list[LeftOut]:
    """Leave out each distinct measurement in turn (twins together), fit the others and
    predict the left-out modes.

    Args:
        p: the model (start values of the fit from it).
        groups: the free groups; bounds: their (low, high) ranges.
        targets: mode -> measured TDR; distinct: from :func:`distinct_measurements`.
        offsets: mode -> simulated / analytic TDR; the fits aim at ``target / offset`` and
            the predictions are ``analytic * offset``.
    """
    off = offsets or {}
    out: list[LeftOut] = []
    for left in distinct:
        rest = {k: targets[k] / off.get(k, 1.0) for k in targets if k not in left}
        n_left = sum(1 for d in distinct if d != left)
        if n_left < len(groups):
            nan = {m: math.nan for m in left}
            out.append(LeftOut(left, nan, dict(nan), identifiable=False))
            continue
        if progress:
            progress(f"leave-out: fitting without mode(s) {', '.join(map(str, left))}")
        x, _ = fit_log_tdr(p, groups, rest, bounds, start_values(p, groups))
        q = with_values(p, expand_groups(groups, x))
        pred = {m: v * off.get(m, 1.0) for m, v in analytic_tdrs(q, list(left)).items()}
        out.append(LeftOut(left, pred,
                           {m: 100.0 * (pred[m] / targets[m] - 1.0) for m in left},
                           {_label(g): float(v) for g, v in zip(groups, x, strict=True)},
                           True, [h[0] for h in bound_hits(groups, x, bounds)]))
    return out


def _chi2(p: Any, groups: list[Group], x: np.ndarray, goal: dict[int, float],
          sigma: dict[int, float]) -> float:
    val = analytic_tdrs(with_values(p, expand_groups(groups, x)), sorted(goal))
    return float(sum((math.log(val[m] / goal[m]) / sigma[m]) ** 2 for m in goal))


def profile(p: Any, groups: list[Group], targets: dict[int, float],
            bounds: list[tuple[float, float]], uncertainty: float,
            offsets: dict[int, float] | None = None, points: int = 21) -> dict[str, dict]:
    """Chi-square profile along each fitted number (the others refitted at each point).

    Returns:
        group label -> {``values`` (grid over the range), ``delta_chi2`` (above the
        profile's minimum), ``minimum`` (the value at the minimum, refined between the grid
        points), ``interval`` [low, high] where ``delta_chi2 <= 1`` (its ends found by root
        bracketing to 1e-9; a bound of the range when it stays below 1 up to it)}.
    """
    from scipy.optimize import brentq, minimize_scalar

    off = offsets or {}
    goal = {m: targets[m] / off.get(m, 1.0) for m in targets}
    sigma = {m: uncertainty for m in targets}
    x0 = start_values(p, groups)
    out: dict[str, dict] = {}
    for i, g in enumerate(groups):
        lo, hi = bounds[i]
        others = [h for j, h in enumerate(groups) if j != i]
        obox = [b for j, b in enumerate(bounds) if j != i]

        def chi(v: float, g=g, others=others, obox=obox, i=i) -> float:
            q = with_values(p, {k: float(v) for k in g})
            if not others:
                return _chi2(q, [], np.zeros(0), goal, sigma)
            xo, _ = fit_log_tdr(q, others, goal, obox, np.delete(x0, i))
            return _chi2(q, others, xo, goal, sigma)

        grid = np.linspace(lo, hi, points)
        curve = np.array([chi(v) for v in grid])
        k = int(np.argmin(curve))
        a, b = grid[max(k - 1, 0)], grid[min(k + 1, points - 1)]
        best = minimize_scalar(chi, bounds=(a, b), method="bounded",
                               options={"xatol": 1e-10})
        vmin, cmin = (float(best.x), float(best.fun)) if best.fun < curve[k] else (
            float(grid[k]), float(curve[k]))

        def rise(v: float, chi=chi, cmin=cmin) -> float:
            return chi(v) - cmin - 1.0

        low = lo if rise(lo) <= 0 else brentq(rise, lo, vmin, xtol=1e-9)
        high = hi if rise(hi) <= 0 else brentq(rise, vmin, hi, xtol=1e-9)
        out[_label(g)] = {"values": grid.tolist(), "delta_chi2": (curve - cmin).tolist(),
                          "minimum": vmin, "interval": [float(low), float(high)]}
    return out


def spread(p: Any, groups: list[Group], targets: dict[int, float],
           bounds: list[tuple[float, float]], uncertainty: float,
           offsets: dict[int, float] | None = None) -> dict[str, Any]:
    """Refit with every measurement scaled by ``1 +- uncertainty`` (relative; all corners).

    Returns:
        {``values``: group label -> [min, max] of the fitted number, ``tdr``: mode ->
        [min, max] of the predicted TDR, ``fits``: number of fits, ``at_bound``: fits that
        ended on a bound}.
    """
    off = offsets or {}
    modes = sorted(targets)
    x0 = start_values(p, groups)
    vals, tdrs, on_bound = [], [], 0
    for signs in itertools.product((-1.0, 1.0), repeat=len(modes)):
        goal = {m: targets[m] * (1.0 + s * uncertainty) / off.get(m, 1.0)
                for m, s in zip(modes, signs, strict=True)}
        x, _ = fit_log_tdr(p, groups, goal, bounds, x0)
        on_bound += bool(bound_hits(groups, x, bounds))
        q = with_values(p, expand_groups(groups, x))
        vals.append(x)
        tdrs.append([v * off.get(m, 1.0) for m, v in analytic_tdrs(q, modes).items()])
    va, ta = np.array(vals), np.array(tdrs)
    return {"values": {_label(g): [float(va[:, i].min()), float(va[:, i].max())]
                       for i, g in enumerate(groups)},
            "tdr": {m: [float(ta[:, j].min()), float(ta[:, j].max())]
                    for j, m in enumerate(modes)},
            "fits": len(vals), "at_bound": on_bound}
