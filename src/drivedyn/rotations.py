"""Rotations on SO(3): exponential, logarithm, tangent operator, composition.

Conventions (used everywhere in drivedyn):

* A rotation is a 3x3 orthonormal matrix ``R`` mapping body-frame components to global
  components, ``x_global = R @ x_body``.
* Rotation vectors ``phi`` (3,) [rad] are the Cartesian rotation vector: ``R = exp(skew(phi))``.
* Perturbations are *right* (body-frame, material) increments: ``R' = R @ exp(skew(dtheta))``.
  Angular velocities of nodes are body-frame vectors ``Omega`` with ``Rdot = R skew(Omega)``.
* ``tangent(phi)`` is the right-trivialised tangent operator (right Jacobian) ``T``:
  ``exp(phi + d) = exp(phi) exp(T(phi) d) + O(|d|^2)``; ``tangent_inv`` is its inverse.

All functions are ``numba.njit`` compiled so that element kernels can call them; they are
equally usable from Python with numpy arrays (float64).
Near ``|phi| = 0`` the trigonometric coefficients switch to Taylor series; near ``|phi| = pi``
the logarithm extracts the axis from the symmetric part of ``R`` instead of the (vanishing)
skew part, so both limits are accurate to machine precision.
"""

from __future__ import annotations

import numpy as np
from numba import njit

SMALL_ANGLE = 1e-4  # below this angle [rad] Taylor series are exact to double precision


@njit(cache=True, inline="always")
def skew_into(v: np.ndarray, S: np.ndarray) -> None:
    """Write the skew-symmetric matrix of ``v`` (3,) into ``S`` (3, 3): ``S @ w ==
    cross(v, w)`` (no allocation: element kernels' work arrays)."""
    S[0, 0] = 0.0
    S[1, 1] = 0.0
    S[2, 2] = 0.0
    S[0, 1] = -v[2]
    S[0, 2] = v[1]
    S[1, 0] = v[2]
    S[1, 2] = -v[0]
    S[2, 0] = -v[1]
    S[2, 1] = v[0]


@njit(cache=True)
def skew(v: np.ndarray) -> np.ndarray:
    """Skew-symmetric matrix ``S`` of ``v`` (3,) so that ``S @ w == cross(v, w)``."""
    S = np.empty((3, 3))
    skew_into(v, S)
    return S


@njit(cache=True)
def unskew(S: np.ndarray) -> np.ndarray:
    """Axial vector (3,) of the skew-symmetric part of ``S`` (3, 3)."""
    v = np.empty(3)
    v[0] = 0.5 * (S[2, 1] - S[1, 2])
    v[1] = 0.5 * (S[0, 2] - S[2, 0])
    v[2] = 0.5 * (S[1, 0] - S[0, 1])
    return v


@njit(cache=True)
def angle_coeffs(t: float) -> tuple[float, float, float]:
    """Return a = sin t / t, b = (1 - cos t)/t^2, c = (t - sin t)/t^3 for angle t >= 0."""
    if t < SMALL_ANGLE:
        t2 = t * t
        a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0
        b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0
        c = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0
    else:
        s = np.sin(t)
        a = s / t
        # half-angle form 1 - cos t = 2 sin^2(t/2) avoids cancellation for small t
        sh = np.sin(0.5 * t) / t
        b = 2.0 * sh * sh
        c = (t - s) / (t * t * t)
    return a, b, c


@njit(cache=True)
def exp_so3(phi: np.ndarray) -> np.ndarray:
    """Rotation matrix (3, 3) of the rotation vector ``phi`` (3,) [rad] (Rodrigues)."""
    t = np.sqrt(phi[0] ** 2 + phi[1] ** 2 + phi[2] ** 2)
    a, b, _ = angle_coeffs(t)
    S = skew(phi)
    return np.eye(3) + a * S + b * (S @ S)


@njit(cache=True)
def exp_so3_into(phi: np.ndarray, out: np.ndarray) -> None:
    """:func:`exp_so3` written into ``out`` (3, 3): no allocation (element loops)."""
    t = np.sqrt(phi[0] ** 2 + phi[1] ** 2 + phi[2] ** 2)
    a, b, _ = angle_coeffs(t)
    # S = phi~, S S = phi phi^T - |phi|^2 I
    t2 = phi[0] ** 2 + phi[1] ** 2 + phi[2] ** 2
    for i in range(3):
        for j in range(3):
            out[i, j] = b * (phi[i] * phi[j] - (t2 if i == j else 0.0))
        out[i, i] += 1.0
    out[0, 1] -= a * phi[2]
    out[0, 2] += a * phi[1]
    out[1, 0] += a * phi[2]
    out[1, 2] -= a * phi[0]
    out[2, 0] -= a * phi[1]
    out[2, 1] += a * phi[0]


@njit(cache=True)
def log_so3(R: np.ndarray) -> np.ndarray:
    """Rotation vector (3,) [rad], with angle in [0, pi], of the rotation matrix ``R`` (3, 3).

    Uses the skew part away from pi and the symmetric part ``(R + I)/2 = n n^T`` (up to
    ``cos`` terms) near pi, so that the axis is accurate in both regimes.
    """
    tr = R[0, 0] + R[1, 1] + R[2, 2]
    c = min(1.0, max(-1.0, 0.5 * (tr - 1.0)))
    w = unskew(R)  # = sin(t) n
    s = np.sqrt(w[0] ** 2 + w[1] ** 2 + w[2] ** 2)
    t = np.arctan2(s, c)
    if t < SMALL_ANGLE:
        a, _, _ = angle_coeffs(t)
        return w / a
    if c > -0.7:
        return w * (t / s)
    # near pi: R = c I + (1 - c) n n^T + s n~ ; pick the largest diagonal of n n^T
    B = (R + R.T) * 0.5
    nn = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            nn[i, j] = (B[i, j] - (c if i == j else 0.0)) / (1.0 - c)
    k = 0
    if nn[1, 1] > nn[k, k]:
        k = 1
    if nn[2, 2] > nn[k, k]:
        k = 2
    n = nn[:, k] / np.sqrt(max(nn[k, k], 1e-300))
    n = n / np.sqrt(n[0] ** 2 + n[1] ** 2 + n[2] ** 2)
    # choose the sign that agrees with the skew part (sin t > 0 for t < pi)
    if n[0] * w[0] + n[1] * w[1] + n[2] * w[2] < 0.0:
        n = -n
    return n * t


@njit(cache=True)
def tangent(phi: np.ndarray) -> np.ndarray:
    """Right tangent operator T(phi) (3, 3): ``exp(phi + d) ~ exp(phi) exp(T d)``."""
    t = np.sqrt(phi[0] ** 2 + phi[1] ** 2 + phi[2] ** 2)
    _, b, c = angle_coeffs(t)
    S = skew(phi)
    return np.eye(3) - b * S + c * (S @ S)


@njit(cache=True)
def tangent_into(p0: float, p1: float, p2: float, Tn: np.ndarray, i: int) -> None:
    """:func:`tangent` of ``phi = (p0, p1, p2)`` [rad] written into ``Tn[i]`` (``Tn``:
    (n, 3, 3)), without temporaries: ``T = I - b S + c S^2`` with ``S^2 = phi phi^T - t^2 I``.

    Equal to :func:`tangent` up to round-off. The solver calls it for every node at every
    matrix evaluation; :func:`tangent` allocates three arrays and calls BLAS for ``S @ S``
    (and its compilation costs seconds, the slice assignment of its result more).
    """
    t2 = p0 * p0 + p1 * p1 + p2 * p2
    _, b, c = angle_coeffs(np.sqrt(t2))
    Tn[i, 0, 0] = 1.0 + c * (p0 * p0 - t2)
    Tn[i, 1, 1] = 1.0 + c * (p1 * p1 - t2)
    Tn[i, 2, 2] = 1.0 + c * (p2 * p2 - t2)
    Tn[i, 0, 1] = b * p2 + c * p0 * p1
    Tn[i, 1, 0] = -b * p2 + c * p0 * p1
    Tn[i, 0, 2] = -b * p1 + c * p0 * p2
    Tn[i, 2, 0] = b * p1 + c * p0 * p2
    Tn[i, 1, 2] = b * p0 + c * p1 * p2
    Tn[i, 2, 1] = -b * p0 + c * p1 * p2


@njit(cache=True)
def tangent_inv(phi: np.ndarray) -> np.ndarray:
    """Inverse of :func:`tangent` (3, 3), valid for |phi| < 2 pi."""
    t = np.sqrt(phi[0] ** 2 + phi[1] ** 2 + phi[2] ** 2)
    S = skew(phi)
    if t < SMALL_ANGLE:
        t2 = t * t
        d = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
    else:
        # (t/2) sin t / (1 - cos t) = (t/2) cot(t/2); half-angle form avoids the
        # cancellation of 1 - cos t for small t
        h = 0.5 * t
        d = (1.0 - h * np.cos(h) / np.sin(h)) / (t * t)
    return np.eye(3) + 0.5 * S + d * (S @ S)


@njit(cache=True)
def compose(phi_a: np.ndarray, phi_b: np.ndarray) -> np.ndarray:
    """Rotation vector of ``exp(phi_a) exp(phi_b)`` (3,), angle in [0, pi]."""
    return log_so3(exp_so3(phi_a) @ exp_so3(phi_b))


@njit(cache=True)
def orthonormalize(R: np.ndarray) -> np.ndarray:
    """Nearest rotation matrix to ``R`` (3, 3) by one polar-decomposition Newton step.

    Used to remove round-off drift of long runs; exact for an already orthonormal matrix.
    """
    Rin = np.linalg.inv(R).T
    return 0.5 * (R + Rin)


def frame_from_axis(axis: np.ndarray) -> np.ndarray:
    """Rotation matrix (3, 3) whose third column is the unit vector along ``axis`` (3,).

    The first column is the global axis least aligned with ``axis``, made orthogonal, so the
    frame is deterministic. Used to build joint frames from a single axis.
    """
    z = np.asarray(axis, dtype=float)
    nz = np.linalg.norm(z)
    if nz == 0.0:
        raise ValueError("axis must be a non-zero vector")
    z = z / nz
    e = np.eye(3)[int(np.argmin(np.abs(z)))]
    x = e - np.dot(e, z) * z
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.column_stack([x, y, z])


def rotation_from_euler_zxz(psi: float, theta: float, phi: float) -> np.ndarray:
    """Rotation matrix (3, 3) of classical z-x-z Euler angles [rad] (precession, nutation, spin)."""

    def rz(a: float) -> np.ndarray:
        c, s = np.cos(a), np.sin(a)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])

    def rx(a: float) -> np.ndarray:
        c, s = np.cos(a), np.sin(a)
        return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])

    return rz(psi) @ rx(theta) @ rz(phi)
