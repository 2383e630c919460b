"""Joint rows and relative angles in a residual-only evaluation, in scalar arithmetic (numba).

:func:`drivedyn.elements.joints.constraint_kernel` evaluates every row through the
primitives of :mod:`drivedyn.elements.framework.primitives`, which write their gradients
into work arrays, so that the same code serves the iteration matrix (their Hessians). A
residual-only evaluation needs only ``g (k lam + p Phi)`` and ``k Phi`` of each row. Here
the same quantities are computed with the node rotations, the vectors and the local
residual held in scalar variables, which the compiler keeps in registers (the work arrays
are views of one buffer, so every store to a gradient entry forced the rotations to be
loaded again):

* :func:`geometric_rows`: the rows that are pure geometry, ``d . a_i`` (``ROW_AXIAL``) and
  ``a_i . b_j`` (``ROW_DOT``);
* :func:`angle_gradient`: the relative angle about marker A's z axis with its gradient
  (drivers, screws, torsional springs); :func:`angle_only`: the angle alone (a hinge's
  output).

The arithmetic is that of ``prim_axial``, ``prim_dot`` and ``prim_angle``, operation for
operation, and rows are added in the same order: the results are the same to the last bit
(``tests/elements/test_joints.py``: ``test_geometric_rows_equal_the_primitives_bit_for_bit``
and ``test_scalar_angles_are_prim_angles_to_the_last_bit``). Measured on the shaft chain
(one residual-only evaluation at a state of its run): 200 hinges 46 -> 22 us, 200 torsional
springs 17 -> 11 us.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from drivedyn.elements.framework.primitives import mtv_scalar, mv_scalar


# _dot_parts is a plain njit function, which LLVM inlines (the same cost per evaluation);
# inlined at numba's IR level instead, it and the scalar mv / mtv made the first compilation
# of a Type C bench command 1.4 s longer (17.2 -> 18.6 s, benchmarks/cold_start.py).
@njit(cache=True)
def _dot_parts(RB, a0, a1, a2, b0, b1, b2, u0, u1, u2, e0, e1, e2, f0, f1, f2):
    """``prim_dot``'s value and the rotation entries of its gradient: ``a . b`` with
    ``a = R_A e``, ``b = R_B f`` and ``u = R_A^T b`` given (``e, f`` the axes in the node
    frames); returns ``(a . b, e x u, f x R_B^T a)``, the last two as components."""
    z0, z1, z2 = mtv_scalar(RB, a0, a1, a2)
    return (a0 * b0 + a1 * b1 + a2 * b2,
            e1 * u2 - e2 * u1, e2 * u0 - e0 * u2, e0 * u1 - e1 * u0,
            f1 * z2 - f2 * z1, f2 * z0 - f0 * z2, f0 * z1 - f1 * z0)


@njit(cache=True, inline="always")
def geometric_rows(nrow, rtype, ai, bj, kk, pp, lam, dofe, off, xA, RA, xB, RB, pA, pB, RmA,
                   RmB, rq, rl):
    """Rows ``0 .. nrow - 1`` of one joint, all ``ROW_AXIAL`` (0) or ``ROW_DOT`` (1), in
    ``MODE_DYN``: ``rq`` (12,) gets ``sum_i g_i (k_i lam_i + p_i Phi_i)`` (node order
    ``[x_A, theta_A, x_B, theta_B]``), ``rl[i]`` (nm,) gets ``k_i Phi_i``.

    ``rtype, ai, bj, kk, pp`` are the element's rows of the group's row tables (row type,
    A-axis column, B-axis column, scaling [N/m or N m/rad], penalty [same]); ``lam`` the
    multipliers of the model, row i's at ``dofe[12 + i] - off`` (the element's row of the
    group's dof table, the number of node dofs before the multipliers); ``xA, xB``
    (3,) [m] and ``RA, RB`` (3, 3) the node positions and rotations (global); ``pA, pB``
    (3,) [m] the marker origins and ``RmA, RmB`` (3, 3) the marker axes (columns), in the
    node frames. Returns the last row's force ``k lam + p Phi``.
    """
    # w = R_B pB + (x_B - x_A), t = R_A pA: prim_axial's d + R_A pA and R_A pA
    w0, w1, w2 = mv_scalar(RB, pB[0], pB[1], pB[2])
    w0 += xB[0] - xA[0]
    w1 += xB[1] - xA[1]
    w2 += xB[2] - xA[2]
    t0, t1, t2 = mv_scalar(RA, pA[0], pA[1], pA[2])
    u0, u1, u2 = mtv_scalar(RA, w0, w1, w2)
    q0 = q1 = q2 = q3 = q4 = q5 = q6 = q7 = q8 = q9 = q10 = q11 = 0.0
    sig = 0.0
    for i in range(nrow):
        c = ai[i]
        e0 = RmA[0, c]
        e1 = RmA[1, c]
        e2 = RmA[2, c]
        a0, a1, a2 = mv_scalar(RA, e0, e1, e2)
        if rtype[i] == 0:  # d . a
            val = 0.0
            val += (w0 - t0) * a0
            val += (w1 - t1) * a1
            val += (w2 - t2) * a2
            s0, s1, s2 = mtv_scalar(RB, a0, a1, a2)
            sig = kk[i] * lam[dofe[12 + i] - off] + pp[i] * val
            q0 += sig * -a0
            q1 += sig * -a1
            q2 += sig * -a2
            q3 += sig * (e1 * u2 - e2 * u1)
            q4 += sig * (e2 * u0 - e0 * u2)
            q5 += sig * (e0 * u1 - e1 * u0)
            q6 += sig * a0
            q7 += sig * a1
            q8 += sig * a2
            q9 += sig * (pB[1] * s2 - pB[2] * s1)
            q10 += sig * (pB[2] * s0 - pB[0] * s2)
            q11 += sig * (pB[0] * s1 - pB[1] * s0)
        else:  # a . b
            cb = bj[i]
            f0 = RmB[0, cb]
            f1 = RmB[1, cb]
            f2 = RmB[2, cb]
            b0, b1, b2 = mv_scalar(RB, f0, f1, f2)
            v0, v1, v2 = mtv_scalar(RA, b0, b1, b2)
            val, g3, g4, g5, g9, g10, g11 = _dot_parts(RB, a0, a1, a2, b0, b1, b2, v0, v1, v2,
                                                       e0, e1, e2, f0, f1, f2)
            sig = kk[i] * lam[dofe[12 + i] - off] + pp[i] * val
            # the translation entries of a dot row's gradient are zero: adding sig * 0
            # changes no sum but the sign of a zero
            q3 += sig * g3
            q4 += sig * g4
            q5 += sig * g5
            q9 += sig * g9
            q10 += sig * g10
            q11 += sig * g11
        rl[i] = kk[i] * val
    rq[0] = q0
    rq[1] = q1
    rq[2] = q2
    rq[3] = q3
    rq[4] = q4
    rq[5] = q5
    rq[6] = q6
    rq[7] = q7
    rq[8] = q8
    rq[9] = q9
    rq[10] = q10
    rq[11] = q11
    return sig


@njit(cache=True, inline="always")
def angle_gradient(RA, RB, a1, a2, b1, g):
    """``prim_angle``'s angle [rad] in (-pi, pi] and gradient ``g`` (12,) without its
    Hessian, in scalar arithmetic: the same values to the last bit (the two dot products
    ``s = (R_A a2) . (R_B b1)``, ``c = (R_A a1) . (R_B b1)`` and their gradients as
    ``prim_dot`` computes them). ``a1, a2`` (3,) are marker A's first two axes and ``b1``
    (3,) marker B's first axis, in the node frames."""
    # b = R_B b1 and u = R_A^T b, shared by both dot products
    b0, b1_, b2 = mv_scalar(RB, b1[0], b1[1], b1[2])
    u0, u1, u2 = mtv_scalar(RA, b0, b1_, b2)
    x0, x1, x2 = mv_scalar(RA, a2[0], a2[1], a2[2])
    s, s3, s4, s5, s9, s10, s11 = _dot_parts(RB, x0, x1, x2, b0, b1_, b2, u0, u1, u2,
                                             a2[0], a2[1], a2[2], b1[0], b1[1], b1[2])
    x0, x1, x2 = mv_scalar(RA, a1[0], a1[1], a1[2])
    c, c3, c4, c5, c9, c10, c11 = _dot_parts(RB, x0, x1, x2, b0, b1_, b2, u0, u1, u2,
                                             a1[0], a1[1], a1[2], b1[0], b1[1], b1[2])
    r2 = s * s + c * c
    zero = (c * 0.0 - s * 0.0) / r2  # the translation entries, as prim_angle's loop has them
    for i in range(3):
        g[i] = zero
        g[6 + i] = zero
    g[3] = (c * s3 - s * c3) / r2
    g[4] = (c * s4 - s * c4) / r2
    g[5] = (c * s5 - s * c5) / r2
    g[9] = (c * s9 - s * c9) / r2
    g[10] = (c * s10 - s * c10) / r2
    g[11] = (c * s11 - s * c11) / r2
    return np.arctan2(s, c)


@njit(cache=True, inline="always")
def angle_only(RA, RB, a1, a2, b1):
    """:func:`angle_gradient`'s angle [rad] alone, the same value to the last bit."""
    b0, b1_, b2 = mv_scalar(RB, b1[0], b1[1], b1[2])
    x0, x1, x2 = mv_scalar(RA, a2[0], a2[1], a2[2])
    s = x0 * b0 + x1 * b1_ + x2 * b2
    x0, x1, x2 = mv_scalar(RA, a1[0], a1[1], a1[2])
    c = x0 * b0 + x1 * b1_ + x2 * b2
    return np.arctan2(s, c)
