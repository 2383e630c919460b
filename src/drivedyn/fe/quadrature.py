"""Quadrature rules of faces: contact points and their areas for
:class:`~drivedyn.elements.flexible.FlexibleWasherContact` (``points``, ``weights``)."""

from __future__ import annotations

import math

import numpy as np

from drivedyn.errors import ModelError


def annulus_quadrature(r_int: float, r_ext: float, z: float, n_r: int, n_theta: int,
                       cells: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Points (cells n_r n_theta, 3) [m] and areas (cells n_r n_theta,) [m^2] of a product
    rule on the annulus ``r_int <= r <= r_ext`` in the plane ``z``: Gauss-Legendre with
    ``n_r`` points in each of ``cells`` equal radial intervals, with the weight ``r`` (exact
    for an integrand polynomial of degree ``2 n_r - 2`` in r on each interval: give a
    mesh's cells across, whose fields are piecewise polynomials with kinks between cells)
    times ``n_theta`` equal angles at ``2 pi m / n_theta`` (the trapezoidal rule of a periodic
    integrand: exact for its harmonics below ``n_theta``, and converging geometrically for a
    smooth one). The angles are those of the vertices of
    :func:`~drivedyn.fe.mesh.annular_washer` when ``n_theta`` divides its cells around: its
    faces are a polygonal annulus inside the circular one, and a point on a vertex's radius
    lies on the mesh at its true radius. The areas sum to ``pi (r_ext^2 - r_int^2)``. Order:
    radius-major (point ``j n_theta + m`` at radius ``j`` from the inside, angle ``m``)."""
    if not 0.0 <= r_int < r_ext:
        raise ModelError(f"annulus_quadrature: expected 0 <= r_int < r_ext, got r_int = "
                         f"{r_int!r}, r_ext = {r_ext!r} m")
    if n_r < 1 or n_theta < 3 or cells < 1:
        raise ModelError(f"annulus_quadrature: expected n_r >= 1, n_theta >= 3 and cells >= 1, "
                         f"got n_r = {n_r!r}, n_theta = {n_theta!r}, cells = {cells!r}")
    g, w = np.polynomial.legendre.leggauss(n_r)
    half = 0.5 * (r_ext - r_int) / cells
    mid = r_int + half * (2 * np.arange(cells) + 1)
    r = (mid[:, None] + half * g[None, :]).ravel()
    w = np.tile(w, cells)
    th = 2.0 * math.pi * np.arange(n_theta) / n_theta
    R, T = np.meshgrid(r, th, indexing="ij")
    pts = np.stack([R.ravel() * np.cos(T.ravel()), R.ravel() * np.sin(T.ravel()),
                    np.full(R.size, float(z))], axis=1)
    areas = np.repeat(half * w * r * (2.0 * math.pi / n_theta), n_theta)
    return pts, areas
