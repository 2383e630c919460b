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

Friction is elastoplastic (a stick spring ``k`` [N/m] in series with a Coulomb slider,
integrated by return mapping, as in plasticity): with ``z`` the committed slip of the last
accepted step, the trial force ``F* = k (s - z)`` is kept while ``|F*| <= mu N`` (stick:
the teeth hold a load that reverses or rests, which a regularised law lets creep away),
otherwise ``F = mu N sign(F*)`` and the slip moves to ``s - F / k`` (slip). The force
``F`` [N] acts along the helix, ``F ds/dq`` in the residual (positive: resisting an increase
of ``s``); its tangent is exact in both states, including ``dF/dsigma``, which couples the
friction to the joint's multiplier.

The stick stiffness rises with the normal force, ``k = k_t N / (N + N_c)`` with the onset
``N_c`` [N] (``N_c = 0``: the constant ``k_t``). A contact's tangential stiffness vanishes
with its normal load (Mindlin: ``k ~ N^(1/3)`` for a point contact; unloaded flanks do not
touch); the rational law is the simplest smooth rise to the teeth's stiffness ``k_t``. It
matters where the normal force nearly vanishes: with a constant ``k_t`` the stick range
``mu N / k_t`` shrinks to nothing there and the flanks switch between stick and slip at
every reversal of a small motion; with the onset the range stays ``mu (N + N_c) / k_t``.
With ``N_c`` a small fraction of the loaded normal force, ``k`` is ``k_t`` where the
spline carries load. The energy account holds the stick spring's ``F^2 / (2 k)`` at the
current ``k``; a change of ``k`` with the load at a held slide changes it without work (at
the Type C's loads ``F^2 / (2 k)`` is about 1e-5 J).
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
def coulomb_return(mu, r, c, k_t, n_c, s, z, sigma):
    """Return mapping of the stick spring and the Coulomb limit ``mu N`` with
    ``N = |sigma| L / r`` [N]: ``(F, dF/ds, dF/dsigma, z_new, k)`` for the slide ``s`` [m],
    the committed slip ``z`` [m] and the screw-row force ``sigma`` [N]; ``k`` [N/m] is the
    stick stiffness ``k_t N / (N + n_c)`` (``n_c`` [N]; 0: ``k_t``)."""
    lr = math.sqrt(r * r + c * c) / r
    n = abs(sigma) * lr
    dn = lr if sigma > 0.0 else (-lr if sigma < 0.0 else 0.0)  # dN/dsigma
    k = k_t
    dk = 0.0  # dk/dN
    if n_c > 0.0:
        k = k_t * n / (n + n_c)
        dk = k_t * n_c / ((n + n_c) * (n + n_c))
    limit = mu * n
    trial = k * (s - z)
    if abs(trial) <= limit:
        return trial, k, dk * dn * (s - z), z, k
    sgn = 1.0 if trial > 0.0 else -1.0
    # the spring left at the limit: z = s - F / k, F / k = sgn mu (N + n_c) / k_t
    return sgn * limit, 0.0, sgn * mu * dn, s - sgn * mu * (n + n_c) / k_t, k
