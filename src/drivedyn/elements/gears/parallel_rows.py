"""A parallel gear pair in a residual-only evaluation: primitives, rates and generalised
force in scalar arithmetic (numba).

The gear loop (:mod:`~drivedyn.elements.gears.kernel`) serves the matrix pass and the
residual alike through :func:`~drivedyn.elements.gears.kinematics.projections` and loops
over the full mesh Jacobian ``Sj`` (NS x NP). Two things cost in a residual-only pass:

* ``projections`` writes each gradient entry into the loop's work arrays as soon as it is
  formed; those arrays are views of one buffer, so after every store the compiler must
  assume that the node rotations and marker axes it reads next have changed, and loads them
  again. :func:`parallel_projections` reads the rotations, positions and lever vectors once
  into scalar variables and forms the gradients from those.
* a parallel pair's ``Sj`` has 7 non-zero entries of 25 (``parallel_coords``), yet the
  loops zero it and run over all of them. :func:`parallel_rates` and
  :func:`parallel_chain` read only the non-zero ones.

The arithmetic is that of the general path, operation for operation and in the same order
(a term that is an exact zero there is left out here): the residual, its scales and the
outputs are the same to the last bit (``tests/elements/test_gears.py``:
``test_residual_only_parallel_pairs_equal_the_matrix_pass``). Measured at a state of the
gear-row race (199 spur pairs, one residual-only evaluation, best of three): 35.4 -> 28.3
us; the race's run 1.86-1.98 -> 1.64-1.73 s.
"""

from __future__ import annotations

from numba import njit

from drivedyn.elements.framework.primitives import mtv_scalar, mv_scalar


@njit(cache=True)
def _axis_a(RA, RB, RmA, i, d0, d1, d2, w0, w1, w2, pB, levB, g):
    """``p = d . u`` (returned) and its gradient ``g`` (12,) for marker A's axis ``i``
    (``u = R_A RmA[:, i]``, returned too): ``[-u, RmA_i x R_A^T w, u, pB x R_B^T u]``, the
    last block zero without a lever on B."""
    m0 = RmA[0, i]
    m1 = RmA[1, i]
    m2 = RmA[2, i]
    u0, u1, u2 = mv_scalar(RA, m0, m1, m2)
    g[0] = -u0
    g[1] = -u1
    g[2] = -u2
    g[3] = m1 * w2 - m2 * w1
    g[4] = m2 * w0 - m0 * w2
    g[5] = m0 * w1 - m1 * w0
    g[6] = u0
    g[7] = u1
    g[8] = u2
    if levB:
        t0, t1, t2 = mtv_scalar(RB, u0, u1, u2)
        g[9] = pB[1] * t2 - pB[2] * t1
        g[10] = pB[2] * t0 - pB[0] * t2
        g[11] = pB[0] * t1 - pB[1] * t0
    else:
        g[9] = 0.0
        g[10] = 0.0
        g[11] = 0.0
    return d0 * u0 + d1 * u1 + d2 * u2, u0, u1, u2


@njit(cache=True)
def _axis_b(RA, RB, RmB, j, d0, d1, d2, w0, w1, w2, pA, levA, g):
    """``d . v`` (returned) and its gradient ``g`` (12,) for marker B's axis ``j`` (``v = R_B
    RmB[:, j]``): ``[-v, R_A^T v x pA, v, RmB_j x R_B^T w_B]``, the second block zero without
    a lever on A."""
    m0 = RmB[0, j]
    m1 = RmB[1, j]
    m2 = RmB[2, j]
    v0, v1, v2 = mv_scalar(RB, m0, m1, m2)
    g[0] = -v0
    g[1] = -v1
    g[2] = -v2
    g[6] = v0
    g[7] = v1
    g[8] = v2
    g[9] = m1 * w2 - m2 * w1
    g[10] = m2 * w0 - m0 * w2
    g[11] = m0 * w1 - m1 * w0
    if levA:
        t0, t1, t2 = mtv_scalar(RA, v0, v1, v2)
        g[3] = t1 * pA[2] - t2 * pA[1]
        g[4] = t2 * pA[0] - t0 * pA[2]
        g[5] = t0 * pA[1] - t1 * pA[0]
    else:
        g[3] = 0.0
        g[4] = 0.0
        g[5] = 0.0
    return d0 * v0 + d1 * v1 + d2 * v2


@njit(cache=True, inline="always")
def parallel_projections(xA, RA, xB, RB, pA, pB, RmA, RmB, p, gp, wk):
    """The residual-only primitives of a parallel pair: ``p[0:3] = d . a_i`` (marker A's
    axes) and ``p[3:5] = d . b_j`` (marker B's x and y axes), ``d = x_mB - x_mA`` [m], with
    their gradients ``gp[0:5]`` (12 each, node order ``[x_A, theta_A, x_B, theta_B]``);
    marker A's global axes go to ``wk[2:5]`` (the outputs' frame). ``xA, xB`` (3,) [m],
    ``RA, RB`` (3, 3) the nodes; ``pA, pB`` (3,) [m] and ``RmA, RmB`` (3, 3) the markers in
    their node frames. The same values as ``projections(..., nb=True, full=False)``."""
    levA = pA[0] != 0.0 or pA[1] != 0.0 or pA[2] != 0.0
    levB = pB[0] != 0.0 or pB[1] != 0.0 or pB[2] != 0.0
    if levA:
        a0, a1, a2 = mv_scalar(RA, pA[0], pA[1], pA[2])
    else:
        a0 = a1 = a2 = 0.0
    if levB:
        b0, b1, b2 = mv_scalar(RB, pB[0], pB[1], pB[2])
    else:
        b0 = b1 = b2 = 0.0
    # w = x_B + R_B pB - x_A = d + R_A pA;  w_B = d - R_B pB
    w0 = xB[0] + b0 - xA[0]
    w1 = xB[1] + b1 - xA[1]
    w2 = xB[2] + b2 - xA[2]
    d0 = w0 - a0
    d1 = w1 - a1
    d2 = w2 - a2
    e0 = d0 - b0
    e1 = d1 - b1
    e2 = d2 - b2
    c0, c1, c2 = mtv_scalar(RA, w0, w1, w2)
    f0, f1, f2 = mtv_scalar(RB, e0, e1, e2)
    q0, u0, u1, u2 = _axis_a(RA, RB, RmA, 0, d0, d1, d2, c0, c1, c2, pB, levB, gp[0])
    q1, v0, v1, v2 = _axis_a(RA, RB, RmA, 1, d0, d1, d2, c0, c1, c2, pB, levB, gp[1])
    q2, z0, z1, z2 = _axis_a(RA, RB, RmA, 2, d0, d1, d2, c0, c1, c2, pB, levB, gp[2])
    q3 = _axis_b(RA, RB, RmB, 0, d0, d1, d2, f0, f1, f2, pA, levA, gp[3])
    q4 = _axis_b(RA, RB, RmB, 1, d0, d1, d2, f0, f1, f2, pA, levA, gp[4])
    p[0] = q0
    p[1] = q1
    p[2] = q2
    p[3] = q3
    p[4] = q4
    wk[2, 0] = u0
    wk[2, 1] = u1
    wk[2, 2] = u2
    wk[3, 0] = v0
    wk[3, 1] = v1
    wk[3, 2] = v2
    wk[4, 0] = z0
    wk[4, 1] = z1
    wk[4, 2] = z2


@njit(cache=True, inline="always")
def parallel_chain(Sj, Qs, gp, Qp, rq):
    """The generalised force of a parallel pair, ``rq = gp^T Sj^T Qs`` (12,), from the mesh
    law's ``Qs`` (NS,), the Jacobian ``Sj`` of the mesh coordinates and the gradients ``gp``
    of :func:`parallel_projections`; ``Qp = Sj^T Qs`` (5,) is kept. Only ``Sj``'s non-zero
    entries of a parallel pair enter (``parallel_coords``: rows 0 and 3 on ``p[0:2]``, row
    1 on ``p[3:5]``, row 2 on ``p[2]``); the sums run in the order of the loops they
    replace, so the values are the same."""
    s0 = Qs[0]
    s1 = Qs[1]
    s3 = Qs[3]
    q0 = Sj[0, 0] * s0 + Sj[3, 0] * s3
    q1 = Sj[0, 1] * s0 + Sj[3, 1] * s3
    q2 = Sj[2, 2] * Qs[2]
    q3 = Sj[1, 3] * s1
    q4 = Sj[1, 4] * s1
    Qp[0] = q0
    Qp[1] = q1
    Qp[2] = q2
    Qp[3] = q3
    Qp[4] = q4
    for a in range(12):
        rq[a] = gp[0, a] * q0 + gp[1, a] * q1 + gp[2, a] * q2 + gp[3, a] * q3 + gp[4, a] * q4


@njit(cache=True, inline="always")
def parallel_rates(Sj, gp, vl, pd, sd):
    """The rates of a parallel pair: ``pd = gp vl`` (5,) of the primitives and ``sd = Sj pd``
    (NS,) of the mesh coordinates, from the element's velocities ``vl`` (12,); only ``Sj``'s
    non-zero entries enter (as in :func:`parallel_chain`)."""
    for i in range(5):
        acc = 0.0
        for a in range(12):
            acc += gp[i, a] * vl[a]
        pd[i] = acc
    d0 = pd[0]
    d1 = pd[1]
    sd[0] = Sj[0, 0] * d0 + Sj[0, 1] * d1
    sd[1] = Sj[1, 3] * pd[3] + Sj[1, 4] * pd[4]
    sd[2] = Sj[2, 2] * pd[2]
    sd[3] = Sj[3, 0] * d0 + Sj[3, 1] * d1
    sd[4] = 0.0
