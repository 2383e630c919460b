"""The floating-frame body's closed-form tangent against complex steps of its forces.

Complex steps (``h = 1e-30``) of :func:`ffrf_forces` give its derivatives exact to
round-off, so the closed form must match them to round-off, column by column, at random
states and invariants (nothing of a real part's structure is assumed: the identity holds for
any inputs)."""

from __future__ import annotations

import numpy as np
import pytest

from drivedyn.elements.flexible.kernel import ffrf_forces
from drivedyn.elements.flexible.tangent import ffrf_tangent
from drivedyn.rotations import exp_so3

H = 1e-30


def _inputs(nq: int, seed: int) -> dict:
    rng = np.random.default_rng(seed)
    n = rng.standard_normal
    return {"mass": 1.0 + rng.random(), "S0": n(3), "Phib": n((3, nq)), "G0": n((3, 3)),
            "A": n((3, 3, nq)), "Q": n((3, 3, nq, nq)), "Qa": n((3, nq, nq)),
            "Mqq": n((nq, nq)), "Kr": n((nq, nq)), "Dr": n((nq, nq)), "g": n(3),
            "R": exp_so3(n(3)), "xdd": n(3), "Om": 3 * n(3), "Omd": n(3), "q": n(nq),
            "qd": n(nq), "qdd": n(nq)}


def _forces(p: dict, nq: int, R, Om, q, qd, dtype=float):
    """(rx, rth, rq) and the work arrays of one evaluation in ``dtype``."""
    z = np.zeros
    Qq, G, Hd, Hdd, B = z((3, 3, nq), dtype), z((3, 3), dtype), z((3, 3), dtype), \
        z((3, 3), dtype), z((3, 3), dtype)
    rx, rth, rq = z(3, dtype), z(3, dtype), z(nq, dtype)
    ffrf_forces(p["mass"], p["S0"], p["Phib"], p["G0"], p["A"], p["Q"], p["Qa"], p["Mqq"],
                p["Kr"], p["Dr"], nq, p["g"], R.astype(dtype), p["xdd"].astype(dtype),
                Om.astype(dtype), p["Omd"].astype(dtype), q.astype(dtype), qd.astype(dtype),
                p["qdd"].astype(dtype), dtype(0), Qq, G, Hd, Hdd, B, rx, rth, rq)
    return np.concatenate([rx, rth, rq]), (Qq, G, Hd, B)


@pytest.mark.parametrize(("nq", "seed"), [(1, 1), (4, 2), (7, 3), (10, 4)])
def test_closed_form_tangent_is_the_complex_step_derivative(nq, seed):
    """Every column of the stiffness (rotation, elastic coordinates) and gyroscopic
    (angular velocity, elastic velocities) matrices within 1e-13 of the largest entry.
    Fails with a term of a derivative left out, e.g. the rotation's ``R (e_j x f)`` or the
    elastic coordinates' ``B dP`` (seen: errors of order 1)."""
    p = _inputs(nq, seed)
    R, Om, q, qd = p["R"], p["Om"], p["q"], p["qd"]
    _, (Qq, G, Hd, B) = _forces(p, nq, R, Om, q, qd)
    m = 6 + nq
    Kx, Cx = np.zeros((m, m)), np.zeros((m, m))
    ffrf_tangent(p["mass"], p["S0"], p["Phib"], p["A"], p["Q"], p["Qa"], p["Kr"], p["Dr"], nq,
                 p["g"], R, p["xdd"], Om, q, qd, p["qdd"], Qq, G, Hd, B, Kx, Cx,
                 np.zeros((8, 3)), np.zeros((7, 3, 3)))
    Kc, Cc = np.zeros((m, m)), np.zeros((m, m))
    c = np.complex128
    for j in range(3):
        skew = np.cross(np.eye(3)[j], np.eye(3))      # rows e_j x e_k: the transpose of e_j~
        Rj = R.astype(c) @ (np.eye(3) + 1j * H * skew.T)   # R exp(i h e_j~)
        Kc[:, 3 + j] = _forces(p, nq, Rj, Om, q, qd, c)[0].imag / H
        Oj = Om.astype(c) + 1j * H * np.eye(3)[j]
        Cc[:, 3 + j] = _forces(p, nq, R, Oj, q, qd, c)[0].imag / H
    for j in range(nq):
        e = 1j * H * np.eye(nq)[j]
        Kc[:, 6 + j] = _forces(p, nq, R, Om, q + e, qd, c)[0].imag / H
        Cc[:, 6 + j] = _forces(p, nq, R, Om, q, qd + e, c)[0].imag / H
    scale = max(np.abs(Kc).max(), np.abs(Cc).max())
    assert np.abs(Kx - Kc).max() < 1e-13 * scale
    assert np.abs(Cx - Cc).max() < 1e-13 * scale
