"""Tests of drivedyn.rotations (SO(3) exp/log, right tangent operator, helpers)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.spatial.transform import Rotation

from drivedyn.rotations import (
    compose,
    exp_so3,
    exp_so3_into,
    frame_from_axis,
    log_so3,
    orthonormalize,
    rotation_from_euler_zxz,
    skew,
    tangent,
    tangent_into,
    tangent_inv,
    unskew,
)

PI = math.pi
EPS = np.finfo(float).eps
I3 = np.eye(3)

# angles [rad] that exercise the Taylor branch, the switch at 1e-4, the generic branch
# and the near-pi branch of the logarithm
SPECIAL_ANGLES = [
    0.0,
    1e-12,
    1e-9,
    1e-8,
    1e-5,
    9.999e-5,
    1e-4,
    1.0001e-4,
    3e-4,
    1e-3,
    1e-2,
    0.1,
    1.0,
    2.0,
    2.3,  # cos = -0.666 (generic branch of log)
    2.4,  # cos = -0.737 (near-pi branch of log)
    3.0,
    PI - 1e-3,
    PI - 1e-6,
    PI - 1e-9,
]

SETTINGS = settings(max_examples=60, deadline=None)


def random_axes(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(n, 3))
    a /= np.linalg.norm(a, axis=1)[:, None]
    # include the coordinate axes and a diagonal
    fixed = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [1.0, 1.0, 1.0]])
    fixed /= np.linalg.norm(fixed, axis=1)[:, None]
    return np.vstack([fixed, a])


AXES = random_axes(6)

unit_vectors = (
    st.tuples(*(st.floats(-1.0, 1.0) for _ in range(3)))
    .map(np.array)
    .filter(lambda v: np.linalg.norm(v) > 1e-3)
    .map(lambda v: v / np.linalg.norm(v))
)
vectors = st.tuples(*(st.floats(-10.0, 10.0) for _ in range(3))).map(np.array)


def rotvec(axis: np.ndarray, angle: float) -> np.ndarray:
    return np.asarray(axis, dtype=float) * angle


def series_coeffs(t: float) -> tuple[float, float, float, float]:
    """a = sin t/t, b = (1-cos t)/t^2, c = (t-sin t)/t^3, d (tangent_inv) by long series.

    Accurate to round-off for t <= 0.1.
    """
    t2 = t * t
    a = b = c = 0.0
    term_a, term_b, term_c = 1.0, 0.5, 1.0 / 6.0
    for k in range(12):
        a += term_a
        b += term_b
        c += term_c
        term_a *= -t2 / ((2 * k + 2) * (2 * k + 3))
        term_b *= -t2 / ((2 * k + 3) * (2 * k + 4))
        term_c *= -t2 / ((2 * k + 4) * (2 * k + 5))
    # d = sum_{n>=1} |B_2n| t^(2n-2) / (2n)!
    bern = [1 / 6, 1 / 30, 1 / 42, 1 / 30, 5 / 66, 691 / 2730, 7 / 6]
    d = 0.0
    for n, bn in enumerate(bern, start=1):
        d += bn * t2 ** (n - 1) / math.factorial(2 * n)
    return a, b, c, d


def assert_rotation(R: np.ndarray, tol: float = 1e-14) -> None:
    assert R.shape == (3, 3)
    assert_allclose(R.T @ R, I3, atol=tol, rtol=0)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=tol)


# ---------------------------------------------------------------------------------------------
# skew / unskew
# ---------------------------------------------------------------------------------------------


@SETTINGS
@given(vectors, vectors)
def test_skew_is_cross_product(v: np.ndarray, w: np.ndarray) -> None:
    S = skew(v)
    assert_allclose(S, -S.T, atol=0)
    assert_allclose(S @ w, np.cross(v, w), atol=1e-12)
    assert_allclose(unskew(S), v, atol=0)


def test_unskew_takes_skew_part() -> None:
    rng = np.random.default_rng(1)
    A = rng.normal(size=(3, 3))
    v = unskew(A)
    assert_allclose(skew(v), 0.5 * (A - A.T), atol=1e-15)
    assert_allclose(unskew(A + A.T), np.zeros(3), atol=1e-15)


# ---------------------------------------------------------------------------------------------
# exp
# ---------------------------------------------------------------------------------------------


def test_exp_zero_is_identity() -> None:
    assert_allclose(exp_so3(np.zeros(3)), I3, atol=0)


@pytest.mark.parametrize("angle", [*SPECIAL_ANGLES, PI, 4.0, 2 * PI - 1e-3, 10.0, 100.0])
def test_exp_orthonormal_and_matches_scipy(angle: float) -> None:
    for axis in AXES:
        phi = rotvec(axis, angle)
        R = exp_so3(phi)
        assert_rotation(R)
        assert_allclose(R, Rotation.from_rotvec(phi).as_matrix(), atol=2e-15 * max(1, angle))
        # the axis is invariant, the inverse is the transpose
        assert_allclose(R @ phi, phi, atol=1e-15 * max(1.0, angle))
        assert_allclose(exp_so3(-phi), R.T, atol=2e-15)


@SETTINGS
@given(vectors)
def test_exp_orthonormal_random(phi: np.ndarray) -> None:
    assert_rotation(exp_so3(phi))


@SETTINGS
@given(vectors)
def test_exp_into_is_exp(phi: np.ndarray) -> None:
    """The allocation-free form (element loops) gives exp_so3's matrix to round-off (it
    forms S S as phi phi^T - |phi|^2 I instead of a matrix product): entries within 3 ulp of
    1 (measured: 2 ulp at most over 20 000 random vectors of 1e-9 to 17 rad)."""
    out = np.full((3, 3), np.nan)
    exp_so3_into(phi, out)
    assert_allclose(out, exp_so3(phi), atol=7e-16, rtol=0)


def test_exp_rotates_as_expected() -> None:
    R = exp_so3(np.array([0.0, 0.0, PI / 2]))
    assert_allclose(R @ np.array([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0], atol=1e-15)


@pytest.mark.parametrize("t", [1e-12, 1e-8, 1e-6, 9.9e-5, 1.01e-4, 1e-3, 1e-2, 0.1])
def test_exp_accuracy_small_angles(t: float) -> None:
    """No cancellation near 0: compare to the (exactly summed) series."""
    for axis in AXES:
        phi = rotvec(axis, t)
        a, b, _, _ = series_coeffs(t)
        R = exp_so3(phi)
        S = skew(phi)
        # skew part a*phi to relative round-off
        assert_allclose(unskew(R), a * phi, rtol=1e-15, atol=0)
        # the whole matrix to round-off of its O(1) entries
        assert_allclose(R, I3 + a * S + b * (S @ S), rtol=0, atol=2 * EPS)


# ---------------------------------------------------------------------------------------------
# log
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("angle", SPECIAL_ANGLES)
def test_log_inverts_exp_special_angles(angle: float) -> None:
    for axis in AXES:
        phi = rotvec(axis, angle)
        got = log_so3(exp_so3(phi))
        # relative accuracy for small angles, absolute (round-off) accuracy near pi
        assert_allclose(got, phi, rtol=0, atol=4 * EPS * max(angle, 1e-300) + 2e-15 * (angle > 1))


@SETTINGS
@given(unit_vectors, st.floats(0.0, PI, exclude_max=True))
def test_log_inverts_exp_random(axis: np.ndarray, angle: float) -> None:
    phi = axis * angle
    got = log_so3(exp_so3(phi))
    assert_allclose(got, phi, rtol=0, atol=1e-14 * max(angle, 1e-300) + 1e-15)


@SETTINGS
@given(unit_vectors, st.floats(1e-12, 1e-3))
def test_log_inverts_exp_near_pi(axis: np.ndarray, delta: float) -> None:
    phi = axis * (PI - delta)
    assert_allclose(log_so3(exp_so3(phi)), phi, rtol=0, atol=2e-15)


def test_log_at_pi_exactly() -> None:
    """At pi the sign of the axis is ambiguous: check exp(log(R)) == R and the angle."""
    axes = [*AXES, np.array([1.0, -1.0, 0.0]) / math.sqrt(2.0)]
    for axis in axes:
        R = exp_so3(axis * PI)
        phi = log_so3(R)
        assert np.linalg.norm(phi) == pytest.approx(PI, abs=1e-14)
        # the axis is +-axis
        assert abs(abs(np.dot(phi / PI, axis)) - 1.0) < 1e-14
        assert_allclose(exp_so3(phi), R, atol=2e-15)
    # exact half-turn matrices
    for R in (np.diag([1.0, -1.0, -1.0]), np.diag([-1.0, 1.0, -1.0]), np.diag([-1.0, -1.0, 1.0])):
        phi = log_so3(R)
        assert np.linalg.norm(phi) == pytest.approx(PI, abs=1e-15)
        assert_allclose(exp_so3(phi), R, atol=1e-15)


def test_log_of_identity_and_angle_range() -> None:
    assert_allclose(log_so3(I3), np.zeros(3), atol=0)
    # a rotation by 3pi/2 about z is a rotation by pi/2 about -z
    got = log_so3(exp_so3(np.array([0.0, 0.0, 1.5 * PI])))
    assert_allclose(got, [0.0, 0.0, -0.5 * PI], atol=1e-15)


@SETTINGS
@given(
    st.tuples(*(st.floats(-1.0, 1.0) for _ in range(4))).filter(
        lambda q: sum(x * x for x in q) > 1e-2
    )
)
def test_exp_log_roundtrip_random_rotation(q: tuple[float, float, float, float]) -> None:
    R = Rotation.from_quat(np.array(q)).as_matrix()
    phi = log_so3(R)
    assert np.linalg.norm(phi) <= PI + 1e-15
    assert_allclose(exp_so3(phi), R, atol=4e-15)
    # agree with scipy (unique for angle < pi)
    ref = Rotation.from_matrix(R).as_rotvec()
    if np.linalg.norm(ref) < PI - 1e-6:
        assert_allclose(phi, ref, atol=1e-13)


# ---------------------------------------------------------------------------------------------
# tangent operator
# ---------------------------------------------------------------------------------------------


def tangent_fd(phi: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """Central difference of the defining relation log(exp(phi)^T exp(phi + h e_i)) / h."""
    R = exp_so3(phi)
    T = np.empty((3, 3))
    for i in range(3):
        e = np.zeros(3)
        e[i] = h
        plus = log_so3(R.T @ exp_so3(phi + e))
        minus = log_so3(R.T @ exp_so3(phi - e))
        T[:, i] = (plus - minus) / (2.0 * h)
    return T


@pytest.mark.parametrize("angle", [*SPECIAL_ANGLES, PI, 3.5, 5.0, 2 * PI - 0.1, 8.0])
def test_tangent_matches_finite_differences(angle: float) -> None:
    for axis in AXES[:6]:
        phi = rotvec(axis, angle)
        assert_allclose(tangent(phi), tangent_fd(phi), atol=2e-9, rtol=0)


@SETTINGS
@given(vectors.filter(lambda v: np.linalg.norm(v) < 9.0))
def test_tangent_matches_finite_differences_random(phi: np.ndarray) -> None:
    assert_allclose(tangent(phi), tangent_fd(phi), atol=2e-9, rtol=0)


@SETTINGS
@given(vectors.filter(lambda v: np.linalg.norm(v) < 9.0))
def test_tangent_into_equals_tangent(phi: np.ndarray) -> None:
    """The solver's allocation-free form (expanded S^2) against the matrix form."""
    Tn = np.full((2, 3, 3), np.nan)
    tangent_into(phi[0], phi[1], phi[2], Tn, 1)
    assert_allclose(Tn[1], tangent(phi), atol=1e-15, rtol=0)
    assert np.isnan(Tn[0]).all()


@pytest.mark.parametrize("angle", [0.0, 1e-9, *SPECIAL_ANGLES, PI, 5.0])
def test_tangent_into_special_angles(angle: float) -> None:
    for axis in AXES[:6]:
        phi = rotvec(axis, angle)
        Tn = np.empty((1, 3, 3))
        tangent_into(phi[0], phi[1], phi[2], Tn, 0)
        assert_allclose(Tn[0], tangent(phi), atol=1e-15, rtol=0)


def test_tangent_is_right_jacobian_second_order() -> None:
    """exp(phi + d) = exp(phi) exp(T d) + O(|d|^2): the residual shrinks quadratically."""
    rng = np.random.default_rng(3)
    for _ in range(10):
        phi = rng.normal(size=3) * 1.5
        d = rng.normal(size=3)
        errs = []
        for h in (1e-2, 1e-3):
            lhs = exp_so3(phi + h * d)
            rhs = exp_so3(phi) @ exp_so3(tangent(phi) @ (h * d))
            errs.append(np.abs(lhs - rhs).max())
        assert errs[1] < errs[0] / 50.0
        # and it is a right (not left) perturbation
        lhs = exp_so3(phi + 1e-3 * d)
        left = exp_so3(tangent(phi) @ (1e-3 * d)) @ exp_so3(phi)
        if np.linalg.norm(np.cross(phi, d)) > 0.1:
            assert np.abs(lhs - left).max() > 10 * errs[1]


@pytest.mark.parametrize(
    "t", [1e-12, 1e-8, 1e-6, 1e-5, 9.999e-5, 1e-4, 1.0001e-4, 3e-4, 1e-3, 1e-2, 0.1]
)
def test_tangent_accuracy_small_angles(t: float) -> None:
    """T = I - b S + c S^2 and T^-1 = I + S/2 + d S^2 to round-off near 0 (no cancellation)."""
    for axis in AXES:
        phi = rotvec(axis, t)
        _, b, c, d = series_coeffs(t)
        S = skew(phi)
        S2 = S @ S
        T = tangent(phi)
        Ti = tangent_inv(phi)
        assert_allclose(unskew(T), -b * phi, rtol=2e-15, atol=0)
        assert_allclose(unskew(Ti), 0.5 * phi, rtol=EPS, atol=0)
        assert_allclose(T, I3 - b * S + c * S2, rtol=0, atol=2 * EPS)
        assert_allclose(Ti, I3 + 0.5 * S + d * S2, rtol=0, atol=2 * EPS)


def test_tangent_high_precision_reference() -> None:
    """Compare T and T^-1 to 50-digit references over the whole range of angles."""
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 40
    angles = [1e-7, 5e-5, 9.99e-5, 1.001e-4, 2e-4, 5e-4, 2e-3, 0.03, 0.5, 1.5, 2.5, 3.1, 4.5]
    for angle in angles:
        for axis in AXES[:5]:
            phi = rotvec(axis, angle)
            p = [mp.mpf(float(x)) for x in phi]
            t = mp.sqrt(p[0] ** 2 + p[1] ** 2 + p[2] ** 2)
            S = mp.matrix([[0, -p[2], p[1]], [p[2], 0, -p[0]], [-p[1], p[0], 0]])
            b = (1 - mp.cos(t)) / t**2
            c = (t - mp.sin(t)) / t**3
            d = 1 / t**2 - (1 + mp.cos(t)) / (2 * t * mp.sin(t))
            T_ref = mp.eye(3) - b * S + c * S * S
            Ti_ref = mp.eye(3) + S / 2 + d * S * S
            T_ref = np.array(T_ref.tolist(), dtype=float)
            Ti_ref = np.array(Ti_ref.tolist(), dtype=float)
            assert_allclose(tangent(phi), T_ref, rtol=0, atol=3 * EPS)
            assert_allclose(tangent_inv(phi), Ti_ref, rtol=0, atol=4 * EPS * max(1.0, angle))


@pytest.mark.parametrize("angle", [*SPECIAL_ANGLES, PI, 4.0, 5.5, 2 * PI - 0.5])
def test_tangent_inv_is_inverse(angle: float) -> None:
    for axis in AXES:
        phi = rotvec(axis, angle)
        T = tangent(phi)
        Ti = tangent_inv(phi)
        tol = 4 * EPS * np.linalg.cond(T)
        assert_allclose(Ti @ T, I3, atol=tol, rtol=0)
        assert_allclose(T @ Ti, I3, atol=tol, rtol=0)


@SETTINGS
@given(unit_vectors, st.floats(0.0, 6.0))
def test_tangent_inv_is_inverse_random(axis: np.ndarray, angle: float) -> None:
    phi = axis * angle
    T = tangent(phi)
    assert_allclose(tangent_inv(phi) @ T, I3, atol=8 * EPS * np.linalg.cond(T), rtol=0)


def test_tangent_properties() -> None:
    """T(phi) phi = phi and T(-phi) = T(phi)^T (left Jacobian)."""
    rng = np.random.default_rng(5)
    for _ in range(20):
        phi = rng.normal(size=3) * 2.0
        T = tangent(phi)
        assert_allclose(T @ phi, phi, atol=1e-14)
        assert_allclose(tangent(-phi), T.T, atol=1e-15)
        # d/dt exp(phi(t)) = exp(phi) skew(T phi_dot): angular velocity in body frame
        phidot = rng.normal(size=3)
        h = 1e-6
        Rdot = (exp_so3(phi + h * phidot) - exp_so3(phi - h * phidot)) / (2 * h)
        assert_allclose(Rdot, exp_so3(phi) @ skew(T @ phidot), atol=1e-8)


# ---------------------------------------------------------------------------------------------
# compose, orthonormalize, frames, Euler angles
# ---------------------------------------------------------------------------------------------


@SETTINGS
@given(vectors, vectors)
def test_compose_matches_matrix_product(a: np.ndarray, b: np.ndarray) -> None:
    c = compose(a, b)
    assert np.linalg.norm(c) <= PI + 1e-14
    assert_allclose(exp_so3(c), exp_so3(a) @ exp_so3(b), atol=1e-13)


def test_compose_special_cases() -> None:
    rng = np.random.default_rng(7)
    for _ in range(10):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        a = axis * 0.7
        assert_allclose(compose(a, -a), np.zeros(3), atol=1e-15)
        assert_allclose(compose(a, np.zeros(3)), a, atol=1e-15)
        assert_allclose(compose(np.zeros(3), a), a, atol=1e-15)
        # same axis: angles add
        assert_allclose(compose(a, axis * 1.1), axis * 1.8, atol=1e-14)


def test_orthonormalize() -> None:
    rng = np.random.default_rng(11)
    for _ in range(10):
        R = exp_so3(rng.normal(size=3))
        assert_allclose(orthonormalize(R), R, atol=1e-15)
        for eps in (1e-4, 1e-6):
            Rp = R + eps * rng.normal(size=(3, 3))
            err0 = np.abs(Rp.T @ Rp - I3).max()
            Q = orthonormalize(Rp)
            err1 = np.abs(Q.T @ Q - I3).max()
            assert err1 < max(50 * err0**2, 1e-15)
            assert np.linalg.det(Q) > 0


@pytest.mark.parametrize(
    "axis",
    [
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -2.0],
        [1.0, 0.0, 0.0],
        [0.0, 3.0, 0.0],
        [1.0, 1.0, 1.0],
        [1.0, 1.0, 0.0],
        [0.3, -0.2, 5.0],
        [1e-8, 0.0, 1.0],
    ],
)
def test_frame_from_axis(axis: list[float]) -> None:
    a = np.asarray(axis)
    F = frame_from_axis(a)
    assert_rotation(F)
    assert_allclose(F[:, 2], a / np.linalg.norm(a), atol=1e-15)
    assert_allclose(frame_from_axis(a), F, atol=0)  # deterministic
    assert_allclose(frame_from_axis(3.0 * a), F, atol=1e-15)  # scale invariant


@SETTINGS
@given(vectors.filter(lambda v: np.linalg.norm(v) > 1e-6))
def test_frame_from_axis_random(a: np.ndarray) -> None:
    F = frame_from_axis(a)
    assert_rotation(F)
    assert_allclose(F[:, 2], a / np.linalg.norm(a), atol=1e-15)


def test_frame_from_axis_rejects_zero() -> None:
    with pytest.raises(ValueError, match="axis"):
        frame_from_axis(np.zeros(3))


@SETTINGS
@given(st.floats(-7.0, 7.0), st.floats(-7.0, 7.0), st.floats(-7.0, 7.0))
def test_euler_zxz(psi: float, theta: float, phi: float) -> None:
    R = rotation_from_euler_zxz(psi, theta, phi)
    assert_rotation(R)
    ref = Rotation.from_euler("ZXZ", [psi, theta, phi]).as_matrix()  # intrinsic z-x'-z''
    assert_allclose(R, ref, atol=1e-14)
    ez = np.array([0.0, 0.0, 1.0])
    ex = np.array([1.0, 0.0, 0.0])
    expected = exp_so3(psi * ez) @ exp_so3(theta * ex) @ exp_so3(phi * ez)
    assert_allclose(R, expected, atol=1e-14)


def _sin_cos_decimal(t: float) -> tuple:
    """sin(t)/t and (1 - cos t)/t^2 of a float ``t`` (0 < t < 1) in 40-digit decimal
    arithmetic (their Taylor series summed until the terms vanish)."""
    from decimal import Decimal, localcontext

    with localcontext() as ctx:
        ctx.prec = 40
        x = Decimal(t)
        x2 = x * x
        a, b = Decimal(0), Decimal(0)
        ta, tb = Decimal(1), Decimal(1) / 2
        k = 0
        while abs(ta) > Decimal(10) ** -45:
            a += ta
            b += tb
            ta *= -x2 / ((2 * k + 2) * (2 * k + 3))
            tb *= -x2 / ((2 * k + 3) * (2 * k + 4))
            k += 1
        return float(a), float(b)


def test_node_rotation_update_is_exact_to_round_off_across_the_series_switch():
    """``lie_update`` takes Rodrigues' coefficients of a node's rotation increment from
    their Taylor series below 0.1 rad (``SERIES_T2``) and from ``sin`` above: the rotation
    it writes must be ``R0 exp(phi)`` of the exact coefficients (40-digit decimal series)
    within 2 ulp (the product with R0 adds its own) on both sides of the switch, and the
    increment orthogonal to round-off. Fails with a series coefficient off (``_A4`` =
    1/36288, ``_B3`` = -1/4032: seen)."""
    from drivedyn.solver.system import SERIES_T2, lie_update

    rng = np.random.default_rng(7)
    eps = np.finfo(float).eps
    worst = 0.0
    for t in np.concatenate([np.geomspace(1e-6, 0.3, 60), np.sqrt(SERIES_T2) * (1 + np.array(
            [-1e-12, 1e-12]))]):
        axis = rng.standard_normal(3)
        phi = t * axis / np.linalg.norm(axis)
        t_ = float(np.sqrt(phi @ phi))
        R0 = exp_so3(rng.standard_normal(3))
        x, R = np.zeros((1, 3)), np.zeros((1, 3, 3))
        lie_update(np.zeros((1, 3)), R0[None], np.r_[0.0, 0.0, 0.0, phi], 1, x, R,
                   np.zeros((1, 3, 3)), False)
        a, b = _sin_cos_decimal(t_)
        S = np.array([[0, -phi[2], phi[1]], [phi[2], 0, -phi[0]], [-phi[1], phi[0], 0]])
        E = np.eye(3) + a * S + b * (S @ S)
        ref = R0 @ E
        worst = max(worst, float(np.abs(R[0] - ref).max()) / eps)
        # the increment alone (R0 = I) is orthogonal to round-off
        lie_update(np.zeros((1, 3)), np.eye(3)[None], np.r_[0.0, 0.0, 0.0, phi], 1, x, R,
                   np.zeros((1, 3, 3)), False)
        assert np.abs(R[0].T @ R[0] - np.eye(3)).max() < 4 * eps
    assert worst < 2.0, worst
