"""Tabulated curves (``elements/framework/curves.py``): PCHIP interpolation, linear
extrapolation, derivative and integral, table checks."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.interpolate import PchipInterpolator

from drivedyn.elements.framework.curves import (
    check_table,
    curve_integral,
    curve_value,
    pack_curves,
)

# a progressive bushing curve (N against m) and an irregular monotone table
TABLES = [([-0.01, -0.004, 0.0, 0.004, 0.01], [-3000.0, -800.0, 0.0, 800.0, 3000.0]),
          ([0.0, 0.1, 0.15, 0.4, 1.0, 1.1], [0.0, 0.0, 2.0, 2.1, 8.0, 30.0]),
          ([1.0, 2.0], [5.0, 7.0])]


def test_curves_match_scipy_pchip_inside_and_go_on_straight_outside() -> None:
    """Inside each table the curve and its derivative are SciPy's PchipInterpolator (the
    same Fritsch-Carlson slopes, same end rule); outside, the tangent line at the end point.

    Deliberate mutations that fail it: the slopes replaced by the secants of the left
    interval (values differ from SciPy's); cubic extrapolation of the end segment (outside
    values are not on the end tangent); a sign slip in the Hermite derivative basis."""
    X, Y, D, start = pack_curves(TABLES)
    for k, (x, y) in enumerate(TABLES):
        ref = PchipInterpolator(x, y, extrapolate=False)
        for q in np.linspace(x[0], x[-1], 301):
            f, df = curve_value(X, Y, D, start, k, q)
            assert f == pytest.approx(float(ref(q)), rel=1e-12, abs=1e-9 * max(map(abs, y)))
            assert df == pytest.approx(float(ref(q, 1)), rel=1e-9, abs=1e-9)
        d0, d1 = float(ref(x[0], 1)), float(ref(x[-1], 1))
        for q, x0, y0, s in ((x[0] - 0.3, x[0], y[0], d0), (x[-1] + 0.7, x[-1], y[-1], d1)):
            f, df = curve_value(X, Y, D, start, k, q)
            assert f == pytest.approx(y0 + s * (q - x0), rel=1e-12, abs=1e-12)
            assert df == pytest.approx(s, rel=1e-12, abs=1e-12)


def test_derivative_and_integral_of_a_curve() -> None:
    """The derivative is the central difference of the value, and the integral SciPy's quad
    of the value, across the points and the extensions.

    Deliberate mutations that fail it: one Gauss point instead of two (cubic segments not
    integrated exactly); the integral's segment search off by one point."""
    X, Y, D, start = pack_curves(TABLES)
    for k, (x, _) in enumerate(TABLES):
        span = x[-1] - x[0]
        for q in np.linspace(x[0] - 0.2 * span, x[-1] + 0.2 * span, 57):
            e = 1e-7 * span
            fd = (curve_value(X, Y, D, start, k, q + e)[0]
                  - curve_value(X, Y, D, start, k, q - e)[0]) / (2 * e)
            assert curve_value(X, Y, D, start, k, q)[1] == pytest.approx(fd, rel=1e-5,
                                                                         abs=1e-6)
        a, b = x[0] - 0.3 * span, x[-1] + 0.2 * span
        ref = quad(lambda q, k=k: curve_value(X, Y, D, start, k, q)[0], a, b,
                   points=list(x), limit=200, epsabs=1e-12)[0]
        assert curve_integral(X, Y, D, start, k, a, b) == pytest.approx(ref, rel=1e-10)
        assert curve_integral(X, Y, D, start, k, b, a) == pytest.approx(-ref, rel=1e-10)


def test_a_monotone_table_gives_a_monotone_curve() -> None:
    """No overshoot: a monotone table gives a non-decreasing curve with derivative >= 0 (a
    positive tangent stiffness everywhere), flat where the table is flat.

    Deliberate mutation that fails it: plain cubic-spline (or Catmull-Rom) slopes, which
    overshoot after the flat part of table 1."""
    X, Y, D, start = pack_curves(TABLES)
    q = np.linspace(-0.5, 1.5, 4001)
    f = np.array([curve_value(X, Y, D, start, 1, v)[0] for v in q])
    df = np.array([curve_value(X, Y, D, start, 1, v)[1] for v in q])
    assert np.all(np.diff(f) >= -1e-12) and np.all(df >= 0.0)
    assert np.all(f[(q >= 0.0) & (q <= 0.1)] == 0.0)


@pytest.mark.parametrize("x, y, message", [
    ([0.0], [1.0], "at least 2 points"),
    ([0.0, 1.0, 1.0], [0.0, 1.0, 2.0], "increase strictly"),
    ([0.0, 1.0, 2.0], [0.0, 2.0, 1.0], "must not decrease"),
    ([0.0, np.nan], [0.0, 1.0], "finite"),
    ([0.0, 1.0], [0.0, 1.0, 2.0], "2 abscissae for 3 values"),
])
def test_bad_tables_are_refused_naming_the_table(x, y, message) -> None:
    """Each malformed table is refused with a message naming it and the fault.

    Deliberate mutation that fails it: dropping one of the checks in ``check_table``."""
    with pytest.raises(ValueError, match=message) as exc:
        check_table(x, y, "spring.force_curve")
    assert str(exc.value).startswith("spring.force_curve: ")
    assert "np." not in str(exc.value)  # values as plain numbers, not numpy reprs
    check_table([0.0, 1.0], [2.0, 1.0], "damper", monotone=False)  # allowed when asked
