"""Tabulated curves of elements: a force against a deflection or a velocity, given as a table
of points, read as a smooth monotone curve (bushings, coil springs, dampers, bump stops).

Interpolation: the piecewise cubic Hermite curve through the points with Fritsch-Carlson
slopes (PCHIP, Fritsch & Carlson, SIAM J. Numer. Anal. 17 (1980) 238-246): continuous with a
continuous first derivative, and monotone between the points when the table is (no
overshoot, so a monotone force-deflection table gives a monotone force and a positive
tangent stiffness). Outside the table the curve goes on as the straight line of its end slope
(linear extrapolation), so a deflection beyond the measured range keeps a finite stiffness.

A family packs the curves of all its elements into flat arrays with :func:`pack_curves`
(build time, numpy) and its kernel reads curve ``k`` with :func:`curve_value` (compiled):
the value and its derivative, which the element's tangent needs.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numba import njit


def pchip_slopes(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Fritsch-Carlson slopes (n,) at the points of a table with strictly increasing ``x``
    (n >= 2): the weighted harmonic mean of the neighbouring secants where they have the
    same sign, 0 at a local extremum, the three-point end formula (clipped to keep the
    shape) at the ends; two points give the straight line."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    n = x.size
    h = np.diff(x)
    delta = np.diff(y) / h
    d = np.zeros(n)
    if n == 2:
        d[:] = delta[0]
        return d
    for i in range(1, n - 1):
        a, b = delta[i - 1], delta[i]
        if a * b > 0.0:
            w1 = 2.0 * h[i] + h[i - 1]
            w2 = h[i] + 2.0 * h[i - 1]
            d[i] = (w1 + w2) / (w1 / a + w2 / b)
    d[0] = _end_slope(h[0], h[1], delta[0], delta[1])
    d[-1] = _end_slope(h[-1], h[-2], delta[-1], delta[-2])
    return d


def _end_slope(h0: float, h1: float, m0: float, m1: float) -> float:
    """Shape-preserving three-point end slope (as SciPy's PchipInterpolator)."""
    d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    if np.sign(d) != np.sign(m0):
        return 0.0
    if np.sign(m0) != np.sign(m1) and abs(d) > abs(3.0 * m0):
        return 3.0 * m0
    return float(d)


def check_table(x: Sequence[float], y: Sequence[float], what: str,
                monotone: bool = True, xname: str = "abscissae"
                ) -> tuple[np.ndarray, np.ndarray]:
    """The table as arrays; ``ValueError`` naming ``what`` for fewer than two points,
    non-finite values, ``x`` (``xname`` in the messages) not strictly increasing or
    (``monotone``) ``y`` decreasing anywhere."""
    xa = np.asarray(x, dtype=float).ravel()
    ya = np.asarray(y, dtype=float).ravel()
    if xa.size != ya.size:
        raise ValueError(f"{what}: {xa.size} abscissae for {ya.size} values")
    if xa.size < 2:
        raise ValueError(f"{what}: a table needs at least 2 points, got {xa.size}")
    if not (np.all(np.isfinite(xa)) and np.all(np.isfinite(ya))):
        raise ValueError(f"{what}: values must be finite")
    if np.any(np.diff(xa) <= 0.0):
        i = int(np.argmax(np.diff(xa) <= 0.0))
        raise ValueError(f"{what}: {xname} must increase strictly, got {float(xa[i])!r} "
                         f"then {float(xa[i + 1])!r}")
    if monotone and np.any(np.diff(ya) < 0.0):
        i = int(np.argmax(np.diff(ya) < 0.0))
        # plain floats: numpy scalars print as np.float64(...)
        a, b, c, d = (float(v) for v in (ya[i], xa[i], ya[i + 1], xa[i + 1]))
        raise ValueError(f"{what}: values must not decrease (a monotone curve), got "
                         f"{a!r} at {b!r} then {c!r} at {d!r}")
    return xa, ya


def pack_curves(tables: Sequence[tuple[Sequence[float], Sequence[float]]]
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Flat arrays of several curves for a kernel: abscissae, values and slopes of all the
    points one curve after the other, and ``start`` (ncurves + 1,) int64, curve ``k``'s
    points being ``start[k]:start[k + 1]``. No curve: one empty entry (kernels index
    nothing)."""
    xs, ys, ds, start = [], [], [], [0]
    for x, y in tables:
        xa, ya = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        xs.append(xa)
        ys.append(ya)
        ds.append(pchip_slopes(xa, ya))
        start.append(start[-1] + xa.size)
    if not xs:
        return np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(1, dtype=np.int64)
    return (np.concatenate(xs), np.concatenate(ys), np.concatenate(ds),
            np.asarray(start, dtype=np.int64))


@njit(cache=True)
def curve_value(X, Y, D, start, k, q):
    """Value and derivative (f, df/dq) of packed curve ``k`` (:func:`pack_curves`) at
    ``q``: the cubic Hermite segment holding ``q``, the end tangent line outside."""
    i0 = start[k]
    i1 = start[k + 1] - 1
    if q <= X[i0]:
        return Y[i0] + D[i0] * (q - X[i0]), D[i0]
    if q >= X[i1]:
        return Y[i1] + D[i1] * (q - X[i1]), D[i1]
    lo = i0
    hi = i1
    while hi - lo > 1:  # X[lo] <= q < X[hi]
        mid = (lo + hi) // 2
        if X[mid] <= q:
            lo = mid
        else:
            hi = mid
    h = X[hi] - X[lo]
    t = (q - X[lo]) / h
    t2 = t * t
    t3 = t2 * t
    h00 = 2.0 * t3 - 3.0 * t2 + 1.0
    h10 = t3 - 2.0 * t2 + t
    h01 = -2.0 * t3 + 3.0 * t2
    h11 = t3 - t2
    f = h00 * Y[lo] + h10 * h * D[lo] + h01 * Y[hi] + h11 * h * D[hi]
    dh00 = 6.0 * t2 - 6.0 * t
    dh10 = 3.0 * t2 - 4.0 * t + 1.0
    dh01 = -6.0 * t2 + 6.0 * t
    dh11 = 3.0 * t2 - 2.0 * t
    df = (dh00 * Y[lo] + dh01 * Y[hi]) / h + dh10 * D[lo] + dh11 * D[hi]
    return f, df


@njit(cache=True)
def curve_integral(X, Y, D, start, k, q0, q1):
    """Integral of packed curve ``k`` from ``q0`` to ``q1`` (the potential energy of a
    spring whose force is the curve), by Gauss-Legendre on each Hermite segment (exact for
    the cubics) and exactly on the linear extensions."""
    if q1 < q0:
        return -curve_integral(X, Y, D, start, k, q1, q0)
    i0 = start[k]
    i1 = start[k + 1] - 1
    # the breakpoints of the curve between q0 and q1
    total = 0.0
    a = q0
    while a < q1:
        if a < X[i0]:
            b = min(q1, X[i0])
        elif a >= X[i1]:
            b = q1
        else:
            j = i0
            while j < i1 and X[j + 1] <= a:
                j += 1
            b = min(q1, X[j + 1])
        # two-point Gauss-Legendre is exact up to cubics: the segment is one piece
        m = 0.5 * (a + b)
        r = 0.5 * (b - a) / np.sqrt(3.0)
        fa, _ = curve_value(X, Y, D, start, k, m - r)
        fb, _ = curve_value(X, Y, D, start, k, m + r)
        total += 0.5 * (b - a) * (fa + fb)
        a = b
    return total
