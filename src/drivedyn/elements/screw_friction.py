"""Coulomb friction with stick along a screw joint's helix: a helical spline's teeth.

A helical spline (or screw) of pitch radius ``r`` [m] and lead ``2 pi c`` [m/rev] lets marker B
move relative to marker A only along the helix: relative rotation ``theta`` [rad] about a3
and slide ``u = d . a3`` [m] with ``u = c theta + c0`` (:class:`~drivedyn.elements.joints.Screw`).
In the plane of the tangential displacement ``r theta`` and the slide ``u`` the helix runs
along ``(r, c) / L`` with ``L = sqrt(r^2 + c^2)``; the teeth's normal force is the joint's
screw-row force ``sigma`` [N] (along a3) resolved on the flank normal ``(-c, r) / L``:
``N = |sigma| L / r``. The slide along the helix is ``s = (r^2 theta + c u) / L`` [m]
(``L theta`` on the helix; its gradient is orthogonal to the screw row's, so friction along
``s`` does not load the row that measures N).

Friction is elastoplastic (a stick spring ``k_t`` [N/m] in series with a Coulomb slider,
integrated by return mapping, as in plasticity): with ``z`` the committed slip of the last
accepted step, the trial force ``F* = k_t (s - z)`` is kept while ``|F*| <= mu N`` (stick:
the teeth hold a load that reverses or rests, which a regularised law lets creep away),
otherwise ``F = mu N sign(F*)`` and the slip moves to ``s - F / k_t`` (slip). The force
``F`` [N] acts along the helix, ``F ds/dq`` in the residual (positive: resisting an increase
of ``s``); its tangent is exact in both states, including ``dF/dsigma`` in slip, which
couples the friction to the joint's multiplier.
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def helix_slide(r, c, th, u, gth, Hth, g, H, full, gs, Hs):
    """The slide along the helix ``s = (r^2 theta + c u) / L`` [m] from the relative angle
    ``th`` [rad] with gradient ``gth`` (12,) and derivatives ``Hth`` (12, 12) and the slide
    ``u`` [m] with ``g``, ``H``; writes its gradient into ``gs`` and, if ``full``, its
    derivatives into ``Hs``. ``r`` [m] pitch radius, ``c`` [m/rad] lead over 2 pi."""
    L = math.sqrt(r * r + c * c)
    a = r * r / L
    b = c / L
    for i in range(12):
        gs[i] = a * gth[i] + b * g[i]
    if full:
        for i in range(12):
            for j in range(12):
                Hs[i, j] = a * Hth[i, j] + b * H[i, j]
    return a * th + b * u


@njit(cache=True)
def coulomb_return(mu, r, c, k_t, s, z, sigma):
    """Return mapping of the stick spring ``k_t`` [N/m] and Coulomb limit ``mu N`` with
    ``N = |sigma| L / r`` [N]: ``(F, dF/ds, dF/dsigma, z_new)`` for the slide ``s`` [m],
    the committed slip ``z`` [m] and the screw-row force ``sigma`` [N]."""
    L = math.sqrt(r * r + c * c)
    limit = mu * abs(sigma) * L / r
    trial = k_t * (s - z)
    if abs(trial) <= limit:
        return trial, k_t, 0.0, z
    sgn = 1.0 if trial > 0.0 else -1.0
    f = sgn * limit
    dsig = 0.0
    if sigma > 0.0:
        dsig = sgn * mu * L / r
    elif sigma < 0.0:
        dsig = -sgn * mu * L / r
    return f, 0.0, dsig, s - f / k_t
