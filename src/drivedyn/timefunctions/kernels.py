"""Compiled evaluation of packed time functions (numba kernels).

The per-kind scalar routines return ``(value, d/dt, d2/dt2, int_0^t)`` of one term; the
Python classes of :mod:`drivedyn.timefunctions.functions` run them interpreted
(``.py_func``), so both paths agree to round-off. :func:`eval_term`, :func:`eval_function`
and :func:`eval_time_functions` read the flat arrays of
:class:`~drivedyn.timefunctions.packing.PackedTimeFunctions`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

KIND_CONSTANT = 0  #: par = [value, 0, 0, 0]
KIND_RAMP = 1  #: par = [t0, t1, v0, v1]
KIND_SMOOTH_STEP = 2  #: par = [t0, t1, v0, v1]
KIND_TABLE = 3  #: par = [offset, npoints, 0, 0]; tab[offset:offset+n] times, then n values
#: par = [value, t_held, integral at t_held, scale]: an input held since ``t_held`` [s], its
#: value written in place between runs (:func:`hold_value`); ``scale`` is the term's factor
#: on what is written
KIND_HELD = 4


# ---------------------------------------------------------------------------------------------
# Per-kind scalar routines. Each returns (value, d/dt, d2/dt2, int_0^t). They are
# self-contained (no calls to other jitted functions) so that their ``py_func`` runs as plain
# Python without triggering compilation.
# ---------------------------------------------------------------------------------------------


@njit(cache=True)
def _constant_eval(t: float, value: float) -> tuple[float, float, float, float]:
    """Constant ``value``: returns (value, 0, 0, value * t)."""
    return value, 0.0, 0.0, value * t


@njit(cache=True)
def _held_eval(t: float, value: float, t_held: float,
               integral_held: float) -> tuple[float, float, float, float]:
    """Input held at ``value`` since ``t_held`` [s], integral ``integral_held`` then: returns
    (value, 0, 0, integral_held + value (t - t_held))."""
    return value, 0.0, 0.0, integral_held + value * (t - t_held)


@njit(cache=True)
def _ramp_eval(
    t: float, t0: float, t1: float, v0: float, v1: float
) -> tuple[float, float, float, float]:
    """Linear ramp from (t0, v0) to (t1, v1), constant outside; requires t1 > t0."""
    slope = (v1 - v0) / (t1 - t0)
    if t < t0:
        v = v0
        d = 0.0
    elif t < t1:
        v = v0 + slope * (t - t0)
        d = slope
    else:
        v = v1
        d = 0.0
    # integral over [a, b] = [min(0, t), max(0, t)] split at the breakpoints
    if t >= 0.0:
        a = 0.0
        b = t
        sign = 1.0
    else:
        a = t
        b = 0.0
        sign = -1.0
    total = 0.0
    if a < t0:
        total += v0 * (min(b, t0) - a)
    if b > t1:
        total += v1 * (b - max(a, t1))
    lo = max(a, t0)
    hi = min(b, t1)
    if hi > lo:
        flo = v0 + slope * (lo - t0)
        fhi = v0 + slope * (hi - t0)
        total += 0.5 * (flo + fhi) * (hi - lo)
    return v, d, 0.0, sign * total


@njit(cache=True)
def _smooth_step_eval(
    t: float, t0: float, t1: float, v0: float, v1: float
) -> tuple[float, float, float, float]:
    """Cubic smooth step ``v0 + (v1 - v0)(3 s^2 - 2 s^3)``, s = (t - t0)/(t1 - t0)."""
    h = t1 - t0
    dv = v1 - v0
    if t < t0:
        v = v0
        d = 0.0
        dd = 0.0
    elif t < t1:
        s = (t - t0) / h
        v = v0 + dv * s * s * (3.0 - 2.0 * s)
        d = dv / h * 6.0 * s * (1.0 - s)
        dd = dv / (h * h) * (6.0 - 12.0 * s)
    else:
        v = v1
        d = 0.0
        dd = 0.0
    if t >= 0.0:
        a = 0.0
        b = t
        sign = 1.0
    else:
        a = t
        b = 0.0
        sign = -1.0
    total = 0.0
    if a < t0:
        total += v0 * (min(b, t0) - a)
    if b > t1:
        total += v1 * (b - max(a, t1))
    lo = max(a, t0)
    hi = min(b, t1)
    if hi > lo:
        # antiderivative from t0 inside the blend: v0 (tau - t0) + dv h (s^3 - s^4 / 2)
        slo = (lo - t0) / h
        shi = (hi - t0) / h
        total += v0 * (hi - lo) + dv * h * (
            shi * shi * shi * (1.0 - 0.5 * shi) - slo * slo * slo * (1.0 - 0.5 * slo)
        )
    return v, d, dd, sign * total


@njit(cache=True)
def _table_eval(t: float, x: np.ndarray, y: np.ndarray) -> tuple[float, float, float, float]:
    """Piecewise-linear table through (x[i], y[i]); x strictly increasing, len >= 2."""
    n = x.shape[0]
    if t < x[0]:
        v = y[0]
        d = 0.0
    elif t >= x[n - 1]:
        v = y[n - 1]
        d = 0.0
    else:
        lo = 0
        hi = n - 1
        while hi - lo > 1:  # invariant x[lo] <= t < x[hi]
            mid = (lo + hi) // 2
            if x[mid] <= t:
                lo = mid
            else:
                hi = mid
        d = (y[hi] - y[lo]) / (x[hi] - x[lo])
        v = y[lo] + d * (t - x[lo])
    if t >= 0.0:
        a = 0.0
        b = t
        sign = 1.0
    else:
        a = t
        b = 0.0
        sign = -1.0
    total = 0.0
    if a < x[0]:
        total += y[0] * (min(b, x[0]) - a)
    if b > x[n - 1]:
        total += y[n - 1] * (b - max(a, x[n - 1]))
    for j in range(n - 1):
        if x[j] >= b:
            break
        lo_ = max(a, x[j])
        hi_ = min(b, x[j + 1])
        if hi_ > lo_:
            s = (y[j + 1] - y[j]) / (x[j + 1] - x[j])
            flo = y[j] + s * (lo_ - x[j])
            fhi = y[j] + s * (hi_ - x[j])
            total += 0.5 * (flo + fhi) * (hi_ - lo_)
    return v, d, 0.0, sign * total


@njit(cache=True)
def eval_term(
    t: float, k: int, kind: np.ndarray, par: np.ndarray, tab: np.ndarray
) -> tuple[float, float, float, float]:
    """Evaluate packed term ``k`` at time ``t`` [s].

    Returns ``(value, d/dt, d2/dt2, int_0^t)``; see :class:`PackedTimeFunctions` for the
    array layout.
    """
    kd = kind[k]
    if kd == KIND_CONSTANT:
        return _constant_eval(t, par[k, 0])
    elif kd == KIND_RAMP:
        return _ramp_eval(t, par[k, 0], par[k, 1], par[k, 2], par[k, 3])
    elif kd == KIND_SMOOTH_STEP:
        return _smooth_step_eval(t, par[k, 0], par[k, 1], par[k, 2], par[k, 3])
    elif kd == KIND_HELD:
        return _held_eval(t, par[k, 0], par[k, 1], par[k, 2])
    elif kd == KIND_TABLE:
        off = int(par[k, 0])
        n = int(par[k, 1])
        return _table_eval(t, tab[off : off + n], tab[off + n : off + 2 * n])
    raise ValueError("unknown time function kind")


@njit(cache=True)
def eval_function(
    t: float, i: int, kind: np.ndarray, par: np.ndarray, fstart: np.ndarray, tab: np.ndarray
) -> tuple[float, float, float, float]:
    """Evaluate packed function ``i`` (sum of its terms) at time ``t`` [s].

    Returns ``(value, d/dt, d2/dt2, int_0^t)``.
    """
    v = 0.0
    d = 0.0
    dd = 0.0
    integral = 0.0
    for k in range(fstart[i], fstart[i + 1]):
        tv, td, tdd, ti = eval_term(t, k, kind, par, tab)
        v += tv
        d += td
        dd += tdd
        integral += ti
    return v, d, dd, integral


@njit(cache=True)
def eval_time_functions(
    t: float,
    kind: np.ndarray,
    par: np.ndarray,
    fstart: np.ndarray,
    tab: np.ndarray,
    out: np.ndarray,
) -> None:
    """Fill ``out`` (nf, 4) with ``[value, d/dt, d2/dt2, int_0^t]`` of every packed function.

    ``t`` [s]; ``kind``, ``par``, ``fstart``, ``tab`` as in :class:`PackedTimeFunctions`.
    Does not allocate.
    """
    nf = fstart.shape[0] - 1
    for i in range(nf):
        v, d, dd, integral = eval_function(t, i, kind, par, fstart, tab)
        out[i, 0] = v
        out[i, 1] = d
        out[i, 2] = dd
        out[i, 3] = integral


def hold_value(par: np.ndarray, k: int, t: float, value: float) -> None:
    """Hold the input of packed term ``k`` (a :data:`KIND_HELD` term) at ``value`` from time
    ``t`` [s] on, in place in ``par`` (nterms, 4): its integral stays continuous at ``t``
    (the angle a speed driver prescribes does not jump). ``value`` is scaled by the term's
    factor ``par[k, 3]``."""
    par[k, 2] += par[k, 0] * (t - par[k, 1])
    par[k, 1] = t
    par[k, 0] = par[k, 3] * value
