"""Step-size control of :func:`~drivedyn.solver.simulate.simulate`: the next step, and what
an accepted or a rejected step does to it.

Compiled functions over two small arrays, so that the Python loop of ``simulate`` and the
compiled loop of :mod:`~drivedyn.solver.step_loop` run the same code (a change made here
goes into both, and the two stay equal bit for bit: ``tests/test_step_loop.py``).

``ctl`` (float64, NCTL): the settings of a run::

    adaptive (0/1), h_min [s], h_max [s], rtol, atol [m or rad], max_rejections, eps_t [s],
    t_end [s], |beta - 1/6| (the error estimate's coefficient), atol_rot [rad] (-1: atol),
    number of nodes (their rotation dofs take atol_rot)

``cs`` (float64, NCS): the controller's memory::

    h [s] (next step size), h_limit [s] (cap after a Newton failure), substep_until [s]
    (fixed steps: sub-steps after a failure until then), consecutive rejections, index of
    the next output time, the exponent of the error's growth with the step size (3 until a
    rejection shows more), the last accepted step's size [s] and error estimate, the
    envelope of the recent estimates and the step size [s] it is scaled to
"""

from __future__ import annotations

import numpy as np
from numba import njit

from drivedyn.solver.newton_kernel import error_norm
from drivedyn.solver.settings import AdaptiveStep

# After a Newton failure at h the adaptive step stays below LIMIT_AFTER_FAILURE h, a cap that
# grows by LIMIT_RELAX per accepted step: the error estimate alone would double h back to the
# size that just failed (contact or flank changes) and fail again.
LIMIT_AFTER_FAILURE = 0.5
LIMIT_RELAX = 1.05
# fixed steps: a run stops after this many consecutive rejections
MAX_REJECTIONS_FIXED = 12
# The error estimate of a second-order scheme grows as h^3 with the step size, and the
# controller sizes its steps by that law (ERROR_EXPONENT). Where a lightly damped mode sits
# near the step size's resolution (a flexible frame's cross member in the RWD vehicle) the
# estimate grows much faster: 0.3 at 250 us, 1.7 at 333 us (h^6). By the h^3 law the
# controller grows the step after every accepted one and meets a rejection each time. A
# rejection after a step grew therefore measures the exponent between the two sizes, and the
# controller uses it (at most ERROR_EXPONENT_MAX) until it relaxes back to 3 by
# EXPONENT_RELAX per accepted step (about 50 steps from 6 to the size where h^3 would
# grow the step again).
ERROR_EXPONENT = 3.0
ERROR_EXPONENT_MAX = 12.0
EXPONENT_RELAX = 0.97
# The estimate of a vibration's error rises and falls with its phase (the change of its
# accelerations over two steps goes as |cos(omega t)|): a step grown at a trough is rejected
# at the next crest. The controller grows the step from the envelope of the recent
# estimates, each scaled to the current size by h^p, which falls by ENVELOPE_DECAY per
# accepted step (to half in 7 steps) and is set by every rejection. It covers estimates
# whose crests come within about 7 steps (the RWD vehicle's frame: every 1 ms, 4-5 steps;
# at a thirtieth of the file's tolerances 388 of 3163 attempts were rejected without the
# envelope, 5 with it, and the run took half the wall); crests further apart still meet a
# rejection each (tests/internals/test_step_control.py).
ENVELOPE_DECAY = 0.9
# A new step size costs a factorisation of the iteration matrix: the step grows only when
# the estimate asks for at least GROWTH_MIN times the current size.
GROWTH_MIN = 1.25

(CT_ADAPTIVE, CT_HMIN, CT_HMAX, CT_RTOL, CT_ATOL, CT_MAXREJ, CT_EPS_T, CT_TEND, CT_ERRC,
 CT_ATOL_ROT, CT_NNODE) = range(11)
NCTL = 11
(CS_H, CS_LIMIT, CS_SUBSTEP, CS_REJ, CS_IOUT, CS_EXP, CS_HACC, CS_EACC, CS_EENV,
 CS_HENV) = range(10)
NCS = 10


def control_arrays(step, beta: float, t_end: float,
                   nnode: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """``(ctl, cs)`` for a :class:`~drivedyn.solver.settings.FixedStep` or
    :class:`~drivedyn.solver.settings.AdaptiveStep` ``step``, the integrator's ``beta``, the
    final time ``t_end`` [s] and the model's number of nodes ``nnode`` (their rotation
    coordinates take ``step.atol_rot``)."""
    adaptive = isinstance(step, AdaptiveStep)
    if adaptive:
        h, h_min, h_max = step.h0, step.h_min, step.h_max
        rtol, atol, max_rej = step.rtol, step.atol, step.max_rejections
        atol_rot = step.atol_rot if step.atol_rot is not None else -1.0
    else:
        atol_rot = -1.0
        h = h_max = step.h
        h_min = step.h_min if step.h_min is not None else step.h / 1024
        rtol, atol, max_rej = 0.0, 0.0, MAX_REJECTIONS_FIXED
    eps_t = 1e-9 * (h_min if h_min > 0 else 1e-12)
    ctl = np.array([1.0 if adaptive else 0.0, h_min, h_max, rtol, atol, float(max_rej), eps_t,
                    t_end, abs(beta - 1.0 / 6.0), atol_rot, float(nnode)])
    cs = np.array([h, np.inf, -np.inf, 0.0, 0.0, ERROR_EXPONENT, 0.0, 0.0, 0.0, 0.0])
    return ctl, cs


def signatures(nd: int) -> list[tuple]:
    """``(function, signature)`` of this module's compiled functions as the Python loop of
    ``simulate`` calls them for a model of ``nd`` dofs (for the first-evaluation precompile,
    :mod:`~drivedyn.solver.precompile`)."""
    f = np.zeros(1)
    q = np.zeros(nd)
    calls = [(next_step, (f, f, 0.0, f)), (step_error, (f, q, q, q, q, 0.0, 0.0)),
             (accept_step, (f, f, 0.0, 0.0, 0.0, 1, f)),
             (reject_step, (f, f, 0.0, 0.0, 0.0, True))]
    return [(fn, tuple(fn.typeof_pyval(a) for a in args)) for fn, args in calls]


@njit(cache=True)
def next_step(cs, ctl, t, touts):
    """Size [s] of the next step from time ``t`` [s]; 0 when the run has reached ``t_end``.
    Steps land on the output times ``touts`` (sorted).

    Adaptive steps divide the rest of the output interval evenly: the fewest steps of at most
    the controller's size (to 1e-6 of it, below) that reach the next output time, all of one
    size. Once the size
    is capped by ``h_max``, every interval is then stepped at one constant size; a short or
    stretched last step before each output time (as fixed steps still have) changes the
    step size twice per interval, and each change costs a factorisation of the iteration
    matrix (``newton_kernel.H_REUSE``). Measured (benchmarks/README.md): the Type C vehicle
    profile with 1.44 ms output intervals at a 0.2 ms cap takes 6 072 factorisations with
    even steps, 14 168 with a short or stretched last step. Fixed steps keep their size and
    shorten or stretch (by up to 25 %, not right after a rejection) the one that reaches the output
    time."""
    adaptive = ctl[CT_ADAPTIVE] != 0.0
    h_max = ctl[CT_HMAX]
    eps_t = ctl[CT_EPS_T]
    t_end = ctl[CT_TEND]
    while t < t_end - eps_t:
        iout = int(cs[CS_IOUT])
        t_next = touts[iout] if iout < touts.shape[0] else t_end
        h_try = min(cs[CS_H], h_max)
        if not adaptive and t >= cs[CS_SUBSTEP]:
            h_try = h_max
        if adaptive:
            # the fewest steps of at most h_try to t_next, all of one size. The 1e-6: t
            # carries the round-off of its sum of steps (1e-12 of a 1 ms interval at t = 2 s
            # after a few steps); without it an interval of exactly n steps takes n + 1 now
            # and then, and the step-size changes make a TORSEN zero-torque hold's Newton
            # chatter (4.3 times a loaded hold's work, tests/models/test_torsen_vehicle.py)
            n = np.ceil((t_next - t) / h_try - 1e-6)
            h_try = (t_next - t) / max(n, 1.0)
        else:
            stretch = cs[CS_REJ] == 0.0 and t + h_try >= t_next - 0.25 * h_try
            if t + h_try > t_next or stretch:
                h_try = t_next - t
        if h_try <= eps_t:
            cs[CS_IOUT] += 1.0
            continue
        return h_try
    return 0.0


@njit(cache=True)
def step_error(ctl, a1, a0, a_prev, hdq, h, h_prev):
    """Weighted local error estimate of a converged step of size ``h`` [s] and the dof where
    it is largest; (0, -1) for fixed steps (no estimate).

    ``a1``, ``a0``, ``a_prev``: pseudo-accelerations after the step, before it and one step
    earlier (``h_prev`` [s] before; ``h_prev`` <= 0: none, the first step). The estimate is
    ``|beta - 1/6| h^2 |a1 - a_prev|``, the change of the pseudo-accelerations over the last
    two steps: the pseudo-accelerations of the generalized-alpha scheme carry a numerical
    mode that alternates in sign from step to step (its factor tends to -rho_inf at high
    frequency; excited by every change of step size and by the constraints), which the
    change over one step, ``a1 - a0``, takes for error. On a smooth motion the two-step
    change is twice the one-step one: the estimate then covers the error of the last two
    steps, and gives about the accuracy per tolerance of the one-step estimate, whose
    alternating part inflated it as much (scaled to one step, by ``h / (h + h_prev)``, the
    steps came out 30 % longer and a bouncing ball's restitution twice as far from the exact
    one). Measured on Andrews' squeezer: 10-26 % of the steps rejected at rtol 1e-5 to 1e-3
    (atol 1e-9) with the one-step change, 1-12 % with this one."""
    if ctl[CT_ADAPTIVE] == 0.0:
        return 0.0, -1
    c = ctl[CT_ERRC] * h * h
    if h_prev > 0.0:
        return error_norm(a1, a_prev, hdq, c, ctl[CT_ATOL], ctl[CT_RTOL], ctl[CT_ATOL_ROT],
                          int(ctl[CT_NNODE]))
    return error_norm(a1, a0, hdq, c, ctl[CT_ATOL], ctl[CT_RTOL], ctl[CT_ATOL_ROT],
                      int(ctl[CT_NNODE]))


@njit(cache=True)
def accept_step(cs, ctl, t, h_try, err, iterations, touts):
    """Bookkeeping of an accepted step of size ``h_try`` [s] ending at ``t`` [s] with error
    estimate ``err`` after ``iterations`` Newton iterations: the next step size. Returns
    ``(t, landed)``: ``t`` snapped onto the output time it reached (``landed``)."""
    eps_t = ctl[CT_EPS_T]
    cs[CS_REJ] = 0.0
    landed = False
    iout = int(cs[CS_IOUT])
    if iout < touts.shape[0] and abs(t - touts[iout]) <= 1e-9 * h_try + eps_t:
        t = touts[iout]
        landed = True
        cs[CS_IOUT] += 1.0
    if ctl[CT_ADAPTIVE] != 0.0:
        h = cs[CS_H]
        h_min = ctl[CT_HMIN]
        p = cs[CS_EXP]
        if cs[CS_HENV] > 0.0:
            env = ENVELOPE_DECAY * cs[CS_EENV] * (h_try / cs[CS_HENV]) ** p
        else:
            env = 0.0
        e_ctl = max(err, env)
        cs[CS_EENV] = e_ctl
        cs[CS_HENV] = h_try
        fac = 0.9 * e_ctl ** (-1.0 / p) if e_ctl > 0 else 2.0
        fac = min(2.0, max(0.2, fac))
        if iterations > 6:
            fac = min(fac, 1.0)
        if fac < GROWTH_MIN:
            fac = 1.0
        if h_try >= 0.99 * h:  # not a step shortened to land on an output time
            h = min(ctl[CT_HMAX], max(h_min, h_try * fac))
        elif fac > 1.0:
            # a shortened step may let the size grow, never shrink it (a short step before
            # an output time has a small error because it is short)
            h = max(h, min(ctl[CT_HMAX], h_try * fac))
        cs[CS_LIMIT] *= LIMIT_RELAX
        cs[CS_H] = min(h, max(cs[CS_LIMIT], h_min))
        cs[CS_EXP] = ERROR_EXPONENT + EXPONENT_RELAX * (p - ERROR_EXPONENT)
        cs[CS_HACC] = h_try
        cs[CS_EACC] = err
    return t, landed


@njit(cache=True)
def reject_step(cs, ctl, t, h_try, err, error_rejection):
    """Bookkeeping of a rejected step of size ``h_try`` [s] from ``t`` [s] (``error_rejection``:
    by the error estimate ``err``, otherwise by Newton): the next step size. Returns True
    when the run must stop (step below ``h_min`` or too many rejections in a row)."""
    cs[CS_REJ] += 1.0
    h_min = ctl[CT_HMIN]
    adaptive = ctl[CT_ADAPTIVE] != 0.0
    if adaptive and error_rejection:
        h_acc = cs[CS_HACC]
        e_acc = cs[CS_EACC]
        if h_try > 1.01 * h_acc and h_acc > 0.0 and 0.0 < e_acc < err:
            # the step grew from h_acc and the error more than h^p said: learn the exponent
            p = np.log(err / e_acc) / np.log(h_try / h_acc)
            cs[CS_EXP] = min(ERROR_EXPONENT_MAX, max(cs[CS_EXP], p))
        p = cs[CS_EXP]
        cs[CS_EENV] = err
        cs[CS_HENV] = h_try
        h = max(h_min, h_try * min(0.9, max(0.2, 0.9 * err ** (-1.0 / p))))
    else:
        h = h_try * 0.25
        if adaptive:
            cs[CS_LIMIT] = LIMIT_AFTER_FAILURE * h_try
        else:
            cs[CS_SUBSTEP] = t + ctl[CT_HMAX]
    cs[CS_H] = h
    return h < h_min * (1 - 1e-12) or cs[CS_REJ] > ctl[CT_MAXREJ]
