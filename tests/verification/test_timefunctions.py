"""Tests of drivedyn.timefunctions (Python objects, packing and the numba kernels)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.integrate import quad

from drivedyn.timefunctions import (
    KIND_CONSTANT,
    KIND_RAMP,
    KIND_SMOOTH_STEP,
    KIND_TABLE,
    Constant,
    PackedTimeFunctions,
    Ramp,
    SmoothStep,
    Sum,
    Table,
    TimeFunction,
    TimeFunctionPool,
    as_time_function,
    eval_function,
    eval_term,
    eval_time_functions,
)

SETTINGS = settings(max_examples=50, deadline=None)

# ---------------------------------------------------------------------------------------------
# strategies: values in [-10, 10], interval widths >= 0.1 so finite differences are tame
# ---------------------------------------------------------------------------------------------

values = st.floats(-10.0, 10.0)
times = st.floats(-3.0, 5.0)
widths = st.floats(0.1, 3.0)

constants = st.builds(Constant, values)
ramps = st.builds(lambda t0, w, v0, v1: Ramp(t0, t0 + w, v0, v1), times, widths, values, values)
steps = st.builds(
    lambda t0, w, v0, v1: SmoothStep(t0, t0 + w, v0, v1), times, widths, values, values
)


@st.composite
def tables(draw: st.DrawFn) -> Table:
    n = draw(st.integers(2, 7))
    start = draw(times)
    dts = draw(st.lists(widths, min_size=n - 1, max_size=n - 1))
    ts = start + np.concatenate([[0.0], np.cumsum(dts)])
    vs = draw(st.lists(values, min_size=n, max_size=n))
    return Table(ts, vs)


leaves = st.one_of(constants, ramps, steps, tables())
functions = st.one_of(leaves, st.lists(leaves, min_size=1, max_size=4).map(Sum))
eval_times = st.floats(-8.0, 12.0)

MARGIN = 1e-3  # keep finite-difference stencils away from breakpoints


def away_from_breakpoints(f: TimeFunction, t: float) -> bool:
    return all(abs(t - b) > MARGIN for b in f.breakpoints())


def quad_between(f: TimeFunction, a: float, b: float) -> float:
    """int_a^b f by scipy quad on each smooth piece between breakpoints (a <= b)."""
    edges = [a, *sorted(x for x in f.breakpoints() if a < x < b), b]
    total = 0.0
    for lo, hi in itertools.pairwise(edges):
        if hi - lo < 1e-9:  # quad dislikes (sub)normal-size intervals; trapezoid suffices
            total += 0.5 * (f(lo) + f(hi)) * (hi - lo)
        else:
            total += quad(lambda x: f(x), lo, hi, epsabs=1e-12, epsrel=1e-11)[0]
    return total


def quad_integral(f: TimeFunction, t: float) -> float:
    """int_0^t f (negative for t < 0)."""
    return quad_between(f, 0.0, t) if t >= 0.0 else -quad_between(f, t, 0.0)


EXAMPLES = [
    Constant(2.5),
    Ramp(0.0, 2.0, 1.0, 5.0),
    Ramp(-1.5, -0.5, 3.0, -2.0),
    Ramp(0.5, 0.75, -4.0, 4.0),
    SmoothStep(0.0, 1.0, 0.0, 1.0),
    SmoothStep(-2.0, 3.0, 10.0, -1.0),
    SmoothStep(1.0, 1.2, 2.0, 7.0),
    Table([0.0, 1.0, 3.0], [0.0, 2.0, -1.0]),
    Table([-2.0, -1.0, 0.5, 2.0, 4.0], [1.0, 3.0, 0.0, 0.0, 6.0]),
    Ramp(0.0, 1.0, 0.0, 1.0) + SmoothStep(0.5, 2.5, 0.0, -3.0) + 0.5,
    2.0 * Table([1.0, 2.0], [1.0, 0.0]) - Ramp(0.0, 3.0, 1.0, 2.0),
]
TS = np.linspace(-3.0, 6.0, 37) + 1e-2  # off the breakpoints


# ---------------------------------------------------------------------------------------------
# values at known points
# ---------------------------------------------------------------------------------------------


def test_constant() -> None:
    f = Constant(2.5)
    for t in (-1.0, 0.0, 3.0):
        assert f.evaluate(t) == (2.5, 0.0, 0.0, 2.5 * t)


def test_ramp_values() -> None:
    f = Ramp(1.0, 3.0, 2.0, 6.0)
    assert f(-5.0) == 2.0
    assert f(1.0) == 2.0
    assert f(2.0) == 4.0
    assert f(2.5) == 5.0
    assert f(3.0) == 6.0
    assert f(100.0) == 6.0
    assert f.derivative(0.5) == 0.0
    assert f.derivative(2.0) == 2.0
    assert f.derivative(4.0) == 0.0
    # right-hand limit at the breakpoints
    assert f.derivative(1.0) == 2.0
    assert f.derivative(3.0) == 0.0
    assert f.second_derivative(2.0) == 0.0
    # integrals: 2*1 up to t0, then trapezoid 2*(2+6)/2 = 8, then 6 per second
    assert f.integral(1.0) == pytest.approx(2.0)
    assert f.integral(2.0) == pytest.approx(2.0 + 3.0)
    assert f.integral(3.0) == pytest.approx(10.0)
    assert f.integral(4.0) == pytest.approx(16.0)
    assert f.integral(-1.0) == pytest.approx(-2.0)
    assert f.integral(0.0) == 0.0


def test_ramp_with_negative_start() -> None:
    f = Ramp(-1.0, 1.0, 0.0, 2.0)  # f = 1 + t on [-1, 1]
    for t in (-1.0, -0.5, 0.0, 0.3, 1.0):
        assert f(t) == pytest.approx(1.0 + t)
        assert f.integral(t) == pytest.approx(t + 0.5 * t * t)
    assert f.integral(2.0) == pytest.approx(1.5 + 2.0)
    assert f.integral(-2.0) == pytest.approx(-0.5)  # int_{-2}^{0} = 0 + 0.5
    g = Ramp(-3.0, -2.0, 1.0, 3.0)  # finished before 0
    assert g.integral(5.0) == pytest.approx(15.0)
    assert g.integral(-2.5) == pytest.approx(-(0.5 * (2.0 + 3.0) / 2 + 3.0 * 2.0))


def test_smooth_step_values() -> None:
    f = SmoothStep(1.0, 3.0, 2.0, 6.0)
    assert f(0.0) == 2.0
    assert f(1.0) == 2.0
    assert f(2.0) == pytest.approx(4.0)
    assert f(1.5) == pytest.approx(2.0 + 4.0 * (3 * 0.25**2 - 2 * 0.25**3))
    assert f(3.0) == 6.0
    assert f(9.0) == 6.0
    # C1: derivative vanishes at both ends, maximal 1.5 * (v1 - v0)/(t1 - t0) in the middle
    assert f.derivative(1.0) == 0.0
    assert f.derivative(3.0) == 0.0
    assert f.derivative(1.0 + 1e-9) == pytest.approx(0.0, abs=1e-7)
    assert f.derivative(3.0 - 1e-9) == pytest.approx(0.0, abs=1e-7)
    assert f.derivative(2.0) == pytest.approx(3.0)
    # second derivative: (v1 - v0)/h^2 * (6 - 12 s) inside, 0 outside
    assert f.second_derivative(0.5) == 0.0
    assert f.second_derivative(3.5) == 0.0
    assert f.second_derivative(2.0) == pytest.approx(0.0, abs=1e-14)
    assert f.second_derivative(1.5) == pytest.approx(4.0 / 4.0 * (6.0 - 3.0))
    assert f.second_derivative(1.0) == pytest.approx(6.0)  # right-hand limit
    # integral of the blend is the trapezoid (symmetric cubic)
    assert f.integral(3.0) == pytest.approx(2.0 + 8.0)
    # 2 up to t0, then 2 * 1 + (v1 - v0) h (s^3 - s^4 / 2) at s = 1/2
    assert f.integral(2.0) == pytest.approx(2.0 + 2.0 + 4.0 * 2.0 * (0.125 - 0.03125))
    assert f.integral(5.0) == pytest.approx(10.0 + 12.0)


def test_table_values() -> None:
    f = Table([0.0, 1.0, 3.0], [0.0, 2.0, -2.0])
    assert f(-1.0) == 0.0
    assert f(0.0) == 0.0
    assert f(0.5) == 1.0
    assert f(1.0) == 2.0
    assert f(2.0) == 0.0
    assert f(3.0) == -2.0
    assert f(7.0) == -2.0
    assert f.derivative(-1.0) == 0.0
    assert f.derivative(0.5) == 2.0
    assert f.derivative(2.0) == -2.0
    assert f.derivative(1.0) == -2.0  # right-hand limit
    assert f.derivative(3.0) == 0.0
    assert f.derivative(4.0) == 0.0
    assert f.second_derivative(0.5) == 0.0
    assert f.integral(1.0) == pytest.approx(1.0)
    assert f.integral(2.0) == pytest.approx(2.0)
    assert f.integral(3.0) == pytest.approx(1.0)
    assert f.integral(4.0) == pytest.approx(-1.0)
    g = Table([-2.0, -1.0], [4.0, 1.0])
    assert g.integral(3.0) == pytest.approx(3.0)
    assert g.integral(-1.5) == pytest.approx(-(1.0 + 0.5 * (1.0 + 2.5) / 2))
    assert g.integral(-3.0) == pytest.approx(-(1.0 + 2.5 + 4.0))


def test_vectorised_call() -> None:
    f = Ramp(0.0, 1.0, 0.0, 1.0)
    ts = np.array([[-1.0, 0.25], [0.5, 2.0]])
    assert_allclose(f(ts), [[0.0, 0.25], [0.5, 1.0]])
    assert f(ts).shape == (2, 2)
    assert_allclose(f.derivative([0.5, 2.0]), [1.0, 0.0])
    assert isinstance(f(0.5), float)


# ---------------------------------------------------------------------------------------------
# derivatives and integrals against numerical references
# ---------------------------------------------------------------------------------------------


def check_derivatives(f: TimeFunction, t: float) -> None:
    h = 1e-6
    fd1 = (f(t + h) - f(t - h)) / (2 * h)
    fd2 = (f.derivative(t + h) - f.derivative(t - h)) / (2 * h)
    assert f.derivative(t) == pytest.approx(fd1, abs=1e-6, rel=1e-7)
    assert f.second_derivative(t) == pytest.approx(fd2, abs=1e-5, rel=1e-6)


def check_integral(f: TimeFunction, t: float) -> None:
    ref = quad_integral(f, t)
    scale = 1.0 + abs(t) * max(abs(f(x)) for x in (0.0, t, *f.breakpoints()))
    assert f.integral(t) == pytest.approx(ref, abs=1e-10 * scale, rel=1e-10)


@pytest.mark.parametrize("f", EXAMPLES, ids=repr)
def test_derivatives_finite_differences_examples(f: TimeFunction) -> None:
    for t in TS:
        if away_from_breakpoints(f, t):
            check_derivatives(f, float(t))


@pytest.mark.parametrize("f", EXAMPLES, ids=repr)
def test_integral_quad_examples(f: TimeFunction) -> None:
    for t in (*TS, *f.breakpoints(), 0.0):
        check_integral(f, float(t))


@SETTINGS
@given(functions, eval_times)
def test_derivatives_finite_differences_random(f: TimeFunction, t: float) -> None:
    assume(away_from_breakpoints(f, t))
    check_derivatives(f, t)


@SETTINGS
@given(functions, eval_times)
def test_integral_quad_random(f: TimeFunction, t: float) -> None:
    check_integral(f, t)


@SETTINGS
@given(functions, eval_times, eval_times)
def test_integral_is_additive(f: TimeFunction, a: float, b: float) -> None:
    """int_0^b - int_0^a = int_a^b, and d/dt int_0^t f = f."""
    lo, hi = min(a, b), max(a, b)
    assume(hi - lo > 1e-3)
    ref = quad_between(f, lo, hi)
    assert f.integral(hi) - f.integral(lo) == pytest.approx(ref, abs=1e-9)
    h = 1e-5
    if away_from_breakpoints(f, a):
        fd = (f.integral(a + h) - f.integral(a - h)) / (2 * h)
        assert fd == pytest.approx(f(a), abs=1e-6)


def test_smooth_step_is_c1() -> None:
    f = SmoothStep(-0.5, 0.7, 1.0, -2.0)
    for b in (f.t0, f.t1):
        assert f(b - 1e-12) == pytest.approx(f(b + 1e-12), abs=1e-10)
        assert f.derivative(b - 1e-9) == pytest.approx(f.derivative(b + 1e-9), abs=1e-7)


# ---------------------------------------------------------------------------------------------
# sums and scaling
# ---------------------------------------------------------------------------------------------


def test_sum_operators() -> None:
    r = Ramp(0.0, 1.0, 0.0, 2.0)
    s = SmoothStep(0.5, 1.5, 1.0, -1.0)
    tb = Table([0.0, 2.0], [3.0, 1.0])
    total = r + s + tb
    assert isinstance(total, Sum)
    assert total.terms() == [r, s, tb]  # flattened
    assert isinstance(r + 1.0, Sum)
    assert (r + 1.0).terms() == [r, Constant(1.0)]
    assert (1.0 + r).terms() == [Constant(1.0), r]
    assert sum([r, s, tb]).terms() == [r, s, tb]
    assert (0 + r).terms() == [r]
    assert (r + 0).terms() == [r]
    assert (total + total).terms() == [r, s, tb, r, s, tb]
    assert Sum([Sum([r, s]), 2.0, tb]).terms() == [r, s, Constant(2.0), tb]
    assert r.terms() == [r]
    for t in TS:
        for j in range(4):
            parts = sum(g.evaluate(t)[j] for g in (r, s, tb))
            assert total.evaluate(t)[j] == pytest.approx(parts, abs=1e-12)
        assert (r - s)(t) == pytest.approx(r(t) - s(t), abs=1e-12)
        assert (-tb)(t) == pytest.approx(-tb(t))
        assert (3.0 - r)(t) == pytest.approx(3.0 - r(t))
    with pytest.raises(TypeError):
        _ = r + "a"  # type: ignore[operator]
    with pytest.raises(TypeError):
        _ = r * r  # type: ignore[operator]


def test_empty_sum_is_zero() -> None:
    z = Sum([])
    assert z.evaluate(1.3) == (0.0, 0.0, 0.0, 0.0)
    assert z.terms() == []


@pytest.mark.parametrize("k", [2.0, -0.5, 0.0, 3])
def test_scaling(k: float) -> None:
    r = Ramp(0.0, 1.0, 1.0, 2.0)
    assert k * r == Ramp(0.0, 1.0, k * 1.0, k * 2.0)
    assert r * k == k * r
    assert np.float64(k) * r == k * r  # numpy scalars defer to us
    s = SmoothStep(0.0, 1.0, 1.0, 2.0)
    assert isinstance(k * s, SmoothStep)
    assert isinstance(k * Table([0.0, 1.0], [1.0, 2.0]), Table)
    assert k * Constant(1.5) == Constant(1.5 * k)
    f = r + s + Table([0.0, 1.0, 2.0], [1.0, -1.0, 4.0]) + 2.0
    g = k * f
    assert isinstance(g, Sum)
    assert len(g.terms()) == len(f.terms())
    for t in TS:
        assert_allclose(g.evaluate(t), k * np.array(f.evaluate(t)), atol=1e-12)


@SETTINGS
@given(functions, functions, st.floats(-5.0, 5.0), eval_times)
def test_linearity_random(f: TimeFunction, g: TimeFunction, k: float, t: float) -> None:
    h = k * f + g
    expected = k * np.array(f.evaluate(t)) + np.array(g.evaluate(t))
    assert_allclose(h.evaluate(t), expected, atol=1e-9, rtol=1e-12)


# ---------------------------------------------------------------------------------------------
# validation
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("cls", [Ramp, SmoothStep])
@pytest.mark.parametrize("t0,t1", [(1.0, 1.0), (2.0, 1.0)])
def test_interval_validation(cls: type, t0: float, t1: float) -> None:
    with pytest.raises(ValueError, match=r"t1 .* must be greater than t0"):
        cls(t0, t1, 0.0, 1.0)


@pytest.mark.parametrize("cls", [Ramp, SmoothStep])
def test_non_finite_parameters(cls: type) -> None:
    with pytest.raises(ValueError, match="v1"):
        cls(0.0, 1.0, 0.0, math.nan)
    with pytest.raises(ValueError, match="t1"):
        cls(0.0, math.inf, 0.0, 1.0)
    with pytest.raises(TypeError, match="t0"):
        cls("0", 1.0, 0.0, 1.0)
    with pytest.raises(ValueError, match="value"):
        Constant(math.inf)


def test_table_validation() -> None:
    with pytest.raises(ValueError, match=r"times must be strictly increasing.*times\[2\]"):
        Table([0.0, 1.0, 1.0], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="times must be strictly increasing"):
        Table([0.0, 2.0, 1.0], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="times and values must have the same length"):
        Table([0.0, 1.0, 2.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="at least 2 points"):
        Table([0.0], [1.0])
    with pytest.raises(ValueError, match="values must be finite"):
        Table([0.0, 1.0], [1.0, math.nan])
    with pytest.raises(ValueError, match="times must be finite"):
        Table([0.0, math.inf], [1.0, 2.0])
    with pytest.raises(ValueError, match="times must be one-dimensional"):
        Table([[0.0, 1.0]], [[1.0, 2.0]])
    with pytest.raises(TypeError, match="times"):
        Table(3.0, [1.0])  # type: ignore[arg-type]


def test_table_is_immutable_and_hashable() -> None:
    ts = np.array([0.0, 1.0])
    f = Table(ts, [1.0, 2.0])
    ts[1] = 5.0  # the table keeps its own copy
    assert f.times == (0.0, 1.0)
    assert f == Table([0.0, 1.0], [1.0, 2.0])
    assert hash(f) == hash(Table((0.0, 1.0), (1.0, 2.0)))
    with pytest.raises(AttributeError):
        f.times = (0.0, 2.0)  # type: ignore[misc]


# ---------------------------------------------------------------------------------------------
# parsing
# ---------------------------------------------------------------------------------------------


def test_as_time_function_numbers_and_passthrough() -> None:
    assert as_time_function(3) == Constant(3.0)
    assert as_time_function(2.5) == Constant(2.5)
    assert as_time_function(np.float64(1.5)) == Constant(1.5)
    r = Ramp(0.0, 1.0, 0.0, 1.0)
    assert as_time_function(r) is r
    for bad in ("1.0", None, [1.0, 2.0], True, object()):
        with pytest.raises(TypeError):
            as_time_function(bad)


def test_as_time_function_dicts() -> None:
    assert as_time_function({"type": "constant", "value": 4}) == Constant(4.0)
    assert as_time_function({"type": "ramp", "t0": 0, "t1": 2, "v0": 1, "v1": 3}) == Ramp(
        0.0, 2.0, 1.0, 3.0
    )
    assert as_time_function(
        {"type": "smooth_step", "t0": 0, "t1": 2, "v0": 1, "v1": 3}
    ) == SmoothStep(0.0, 2.0, 1.0, 3.0)
    assert as_time_function(
        {"type": "Smooth-Step", "t0": 0, "t1": 2, "v0": 1, "v1": 3}
    ) == SmoothStep(0.0, 2.0, 1.0, 3.0)
    assert as_time_function({"type": "table", "times": [0, 1], "values": [2, 3]}) == Table(
        [0.0, 1.0], [2.0, 3.0]
    )
    f = as_time_function(
        {
            "type": "sum",
            "terms": [
                1.5,
                {"type": "ramp", "t0": 0, "t1": 1, "v0": 0, "v1": 1},
                {"type": "sum", "terms": [{"type": "constant", "value": 2}]},
            ],
        }
    )
    assert f == Sum([Constant(1.5), Ramp(0.0, 1.0, 0.0, 1.0), Constant(2.0)])
    assert f(0.5) == pytest.approx(4.0)


def test_as_time_function_dict_errors() -> None:
    with pytest.raises(ValueError, match="'type'"):
        as_time_function({"value": 1.0})
    with pytest.raises(ValueError, match="unknown time function type 'sine'"):
        as_time_function({"type": "sine", "amplitude": 1.0})
    with pytest.raises(ValueError, match=r"missing key\(s\) \['v1'\]"):
        as_time_function({"type": "ramp", "t0": 0, "t1": 1, "v0": 0})
    with pytest.raises(ValueError, match=r"unknown key\(s\) \['t2'\]"):
        as_time_function({"type": "ramp", "t0": 0, "t1": 1, "v0": 0, "v1": 1, "t2": 3})
    with pytest.raises(ValueError, match="t1"):
        as_time_function({"type": "ramp", "t0": 1, "t1": 0, "v0": 0, "v1": 1})
    with pytest.raises(ValueError, match="strictly increasing"):
        as_time_function({"type": "table", "times": [1, 0], "values": [0, 1]})
    with pytest.raises(ValueError, match="terms"):
        as_time_function({"type": "sum", "terms": 3})


@pytest.mark.parametrize("f", EXAMPLES, ids=repr)
def test_to_dict_roundtrip(f: TimeFunction) -> None:
    g = as_time_function(f.to_dict())
    assert g.terms() == f.terms()


# ---------------------------------------------------------------------------------------------
# packing and numba kernels
# ---------------------------------------------------------------------------------------------


def test_pool_ids_and_layout() -> None:
    pool = TimeFunctionPool()
    tb = Table([0.0, 1.0, 3.0], [5.0, 6.0, 7.0])
    ids = [
        pool.add(Ramp(0.0, 1.0, 2.0, 3.0)),
        pool.add(4.0),
        pool.add(tb + SmoothStep(1.0, 2.0, 0.0, 1.0)),
        pool.add({"type": "table", "times": [0, 1], "values": [1, 2]}),
        pool.add(Sum([])),
    ]
    assert ids == [0, 1, 2, 3, 4]
    assert len(pool) == 5
    assert pool[1] == Constant(4.0)
    p = pool.pack()
    assert isinstance(p, PackedTimeFunctions)
    assert p.n_functions == 5
    assert p.kind.dtype == np.int64 and p.fstart.dtype == np.int64
    assert p.par.dtype == np.float64 and p.tab.dtype == np.float64
    assert p.kind.tolist() == [KIND_RAMP, KIND_CONSTANT, KIND_TABLE, KIND_SMOOTH_STEP, KIND_TABLE]
    assert p.fstart.tolist() == [0, 1, 2, 4, 5, 5]
    assert p.par.shape == (5, 4)
    assert p.par[0].tolist() == [0.0, 1.0, 2.0, 3.0]
    assert p.par[1].tolist() == [4.0, 0.0, 0.0, 0.0]
    assert p.par[2].tolist() == [0.0, 3.0, 0.0, 0.0]
    assert p.par[3].tolist() == [1.0, 2.0, 0.0, 1.0]
    assert p.par[4].tolist() == [6.0, 2.0, 0.0, 0.0]
    assert p.tab.tolist() == [0.0, 1.0, 3.0, 5.0, 6.0, 7.0, 0.0, 1.0, 1.0, 2.0]


def test_empty_pool() -> None:
    p = TimeFunctionPool().pack()
    assert p.kind.shape == (0,) and p.kind.dtype == np.int64
    assert p.par.shape == (0, 4) and p.par.dtype == np.float64
    assert p.fstart.tolist() == [0] and p.fstart.dtype == np.int64
    assert p.tab.shape == (1,) and p.tab[0] == 0.0
    out = np.zeros((0, 4))
    eval_time_functions(1.0, p.kind, p.par, p.fstart, p.tab, out)
    # a pool without tables still has a non-empty tab
    pool = TimeFunctionPool()
    pool.add(1.0)
    assert pool.pack().tab.shape == (1,)


def test_kernel_fills_out_in_place() -> None:
    pool = TimeFunctionPool()
    for f in EXAMPLES:
        pool.add(f)
    p = pool.pack()
    out = np.full((len(EXAMPLES), 4), np.nan)
    for t in TS:
        eval_time_functions(float(t), p.kind, p.par, p.fstart, p.tab, out)
        expected = np.array([f.evaluate(float(t)) for f in EXAMPLES])
        assert_allclose(out, expected, rtol=1e-14, atol=1e-13)
        for i, f in enumerate(EXAMPLES):
            assert_allclose(
                eval_function(float(t), i, p.kind, p.par, p.fstart, p.tab), f.evaluate(float(t))
            )
    # breakpoints: the same one-sided conventions in both paths
    for i, f in enumerate(EXAMPLES):
        for b in f.breakpoints():
            assert_allclose(p.evaluate(b)[i], f.evaluate(b), rtol=1e-14, atol=1e-13)


def test_eval_term() -> None:
    pool = TimeFunctionPool()
    terms = [Constant(1.0), Ramp(0.0, 1.0, 0.0, 2.0), SmoothStep(0.0, 1.0, 0.0, 2.0)]
    pool.add(Sum(terms) + Table([0.0, 2.0], [1.0, 3.0]))
    p = pool.pack()
    terms.append(Table([0.0, 2.0], [1.0, 3.0]))
    for k, term in enumerate(terms):
        assert_allclose(eval_term(0.4, k, p.kind, p.par, p.tab), term.evaluate(0.4), rtol=1e-15)


def test_kernel_rejects_unknown_kind() -> None:
    with pytest.raises(ValueError):
        eval_term(0.0, 0, np.array([7], dtype=np.int64), np.zeros((1, 4)), np.zeros(1))


@SETTINGS
@given(st.lists(functions, min_size=1, max_size=5), st.lists(eval_times, min_size=1, max_size=5))
def test_packed_matches_python_random(fs: list[TimeFunction], ts: list[float]) -> None:
    pool = TimeFunctionPool()
    for f in fs:
        pool.add(f)
    p = pool.pack()
    out = np.empty((len(fs), 4))
    # include the breakpoints, where the one-sided conventions must agree too
    for t in [*ts, *(b for f in fs for b in f.breakpoints())]:
        eval_time_functions(t, p.kind, p.par, p.fstart, p.tab, out)
        expected = np.array([f.evaluate(t) for f in fs])
        assert_allclose(out, expected, rtol=1e-13, atol=1e-12)


def test_callable_from_user_kernel() -> None:
    """The helpers compose inside other njit kernels (how loads and drivers use them)."""
    from numba import njit

    @njit
    def work(ts: np.ndarray, i: int, kind, par, fstart, tab) -> float:
        total = 0.0
        for t in ts:
            v, d, _, _ = eval_function(t, i, kind, par, fstart, tab)
            total += v * d
        return total

    pool = TimeFunctionPool()
    pool.add(1.0)
    f = Ramp(0.0, 1.0, 0.0, 2.0) + Table([0.0, 2.0], [1.0, 0.0])
    i = pool.add(f)
    p = pool.pack()
    ts = np.linspace(-1.0, 3.0, 17)
    expected = sum(f(t) * f.derivative(t) for t in ts)
    assert work(ts, i, *p) == pytest.approx(expected, rel=1e-14)
    out = np.zeros((2, 4))
    eval_time_functions(0.5, *p, out)  # the NamedTuple unpacks in field order
    assert_allclose(out[1], f.evaluate(0.5))
