"""Helpers shared by the contact elements (kernels and group building); see
:mod:`drivedyn.elements.contact` for the formulation."""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.contact.friction import (
    FrictionLaw,
    friction_phi,
    friction_scalar,
    friction_table,
)
from drivedyn.elements.contact.impact_laws import (
    NSTATE,
    ST_COUNT,
    ST_FLAG,
    ST_REBOUND,
    ST_VS,
    NormalLaw,
    impact_speed,
    law_table,
    normal_force,
)
from drivedyn.elements.framework.building import make_group, node_dofs
from drivedyn.elements.framework.contract import LOCAL_SIZE_12, local_arrays_at
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.primitives import prim_axial
from drivedyn.elements.framework.work_arrays import carve
from drivedyn.errors import ModelError

# --- kernels ------------------------------------------------------------------------------------
#
# A force-type contact kernel receives its parameters as ``(*geometry, law, friction, na)``
# (:func:`contact_group`): ``law`` (nel, 5) has the rows ``(K, n, chi, c, v_min)`` of the
# normal laws, ``friction`` (nel, 5) the rows ``(kind, mu, mu_static, v_stribeck, eps_v)`` of
# the friction laws, read through the helpers below; ``na`` is the first hidden aux column.


@njit(cache=True, inline="always")
def contact_normal(law, e, delta, rate, es, o):
    """Normal force of element ``e`` at penetration ``delta`` and rate ``rate`` (state block
    at ``es[o]``): ``(F, dF/ddelta, dF/drate, V, P_dis, v_s)`` (see
    :func:`~drivedyn.elements.contact.impact_laws.normal_force`)."""
    K, n, chi, c, vmin = law[e, 0], law[e, 1], law[e, 2], law[e, 3], law[e, 4]
    vs = impact_speed(es, o, vmin)
    F, Fd, Fr, V, Pn = normal_force(delta, rate, K, n, chi, c, vs)
    return F, Fd, Fr, V, Pn, vs


@njit(cache=True, inline="always")
def has_friction(fric, e):
    """True if element ``e`` has a friction law (mu or mu_static > 0)."""
    return fric[e, 1] + fric[e, 2] > 0.0


@njit(cache=True, inline="always")
def friction_coefficient(fric, e, s):
    """Signed ``mu_R(s)`` and ``dmu_R/ds`` of element ``e`` at the sliding velocity ``s``."""
    return friction_scalar(s, int(fric[e, 0]), fric[e, 1], fric[e, 2], fric[e, 3], fric[e, 4])


@njit(cache=True, inline="always")
def friction_ratio(fric, e, v):
    """``mu_R(v)/v`` and its derivative of element ``e`` at the sliding speed ``v >= 0``."""
    return friction_phi(v, int(fric[e, 0]), fric[e, 1], fric[e, 2], fric[e, 3], fric[e, 4])


@njit(cache=True, inline="always")
def axis_distance(xA, RA, xB, RB, pA, pB, axis, g, H, vl, Hv, full, ws, wv):
    """Distance of marker B from marker A along A's axis ``axis`` (node frame), gradient
    ``g``, (if ``full``) ``H = dg/dq`` and ``Hv = H^T v``; returns the distance and its rate
    ``g . v`` (local velocities ``vl``)."""
    phi = prim_axial(xA, RA, xB, RB, pA, pB, axis, g, H, full, ws, wv)
    rate = 0.0
    for a in range(12):
        rate += g[a] * vl[a]
    if full:
        transpose_times(H, vl, Hv)
    return phi, rate


@njit(cache=True, inline="always")
def omega_projection(RA, RB, abar, G, D, full, M3):
    """Relative spin about an axis of A: ``(omega_B - omega_A) . (R_A abar) = G . v``.

    ``G`` (12,) is ``[0, -abar, 0, R_B^T R_A abar]`` on the local dofs ``[x_A, theta_A, x_B,
    theta_B]`` (body-frame angular velocities); if ``full``, ``D = dG/dq`` (12, 12), non-zero
    in rows 9..11: ``-R_B^T R_A abar~`` (columns theta_A) and ``u~`` with
    ``u = R_B^T R_A abar`` (columns theta_B). ``M3`` is a (3, 3) work array.
    """
    for i in range(3):
        for j in range(3):
            M3[i, j] = RB[0, i] * RA[0, j] + RB[1, i] * RA[1, j] + RB[2, i] * RA[2, j]
    u0 = M3[0, 0] * abar[0] + M3[0, 1] * abar[1] + M3[0, 2] * abar[2]
    u1 = M3[1, 0] * abar[0] + M3[1, 1] * abar[1] + M3[1, 2] * abar[2]
    u2 = M3[2, 0] * abar[0] + M3[2, 1] * abar[1] + M3[2, 2] * abar[2]
    for i in range(12):
        G[i] = 0.0
    G[3] = -abar[0]
    G[4] = -abar[1]
    G[5] = -abar[2]
    G[9] = u0
    G[10] = u1
    G[11] = u2
    if full:
        D[:, :] = 0.0
        for i in range(3):
            m0 = M3[i, 0]
            m1 = M3[i, 1]
            m2 = M3[i, 2]
            # -(M abar~) row i = -(M[i,:] x abar)
            D[9 + i, 3] = -(m1 * abar[2] - m2 * abar[1])
            D[9 + i, 4] = -(m2 * abar[0] - m0 * abar[2])
            D[9 + i, 5] = -(m0 * abar[1] - m1 * abar[0])
        D[9, 10] = -u2
        D[9, 11] = u1
        D[10, 9] = u2
        D[10, 11] = -u0
        D[11, 9] = -u1
        D[11, 10] = u0


@njit(cache=True, inline="always")
def transpose_times(H, vl, out):
    """out[b] = sum_a H[a, b] vl[a]: the derivative of ``g . v`` when ``H = dg/dq``."""
    for b in range(12):
        s = 0.0
        for a in range(12):
            s += H[a, b] * vl[a]
        out[b] = s


@njit(cache=True, inline="always")
def add_normal(F, Fd, Fr, sgn, g, H, Hv, rq, K, C, dFq, dFv, full):
    """Normal force ``F(delta, deltadot)`` with ``delta = sgn phi + const``, ``grad phi = g``,
    ``d g/dq = H``, ``Hv = H^T v``: ``rq += F sgn g``; fills ``dFq = dF/dq``,
    ``dFv = dF/dv``; ``K += sgn (F H + g dFq^T)``, ``C += sgn g dFv^T``."""
    for a in range(12):
        rq[a] += sgn * F * g[a]
    if full:
        for b in range(12):
            dFq[b] = sgn * (Fd * g[b] + Fr * Hv[b])
            dFv[b] = sgn * Fr * g[b]
        for a in range(12):
            ga = sgn * g[a]
            for b in range(12):
                K[a, b] += sgn * F * H[a, b] + ga * dFq[b]
                C[a, b] += ga * dFv[b]


@njit(cache=True, inline="always")
def add_velocity_force(f, dfds, dfdF, J, dJ, Jv, dFq, dFv, rq, K, C, full):
    """A force ``f(s, F)`` on a sliding rate ``s = J(q) . v`` (``Jv = dJ^T v``) with the
    normal force derivatives ``dFq, dFv``: ``rq += f J``,
    ``K += f dJ + J (dfds Jv + dfdF dFq)^T``, ``C += J (dfds J + dfdF dFv)^T``."""
    for a in range(12):
        rq[a] += f * J[a]
    if full:
        for a in range(12):
            ja = J[a]
            for b in range(12):
                K[a, b] += f * dJ[a, b] + ja * (dfds * Jv[b] + dfdF * dFq[b])
                C[a, b] += ja * (dfds * J[b] + dfdF * dFv[b])


# --- specs and groups ----------------------------------------------------------------------


def coerce_laws(spec: Any, what: str, law_field: str = "law") -> None:
    """Turn mappings given for the normal law and the friction law (model files: TOML tables)
    into :class:`NormalLaw` / :class:`FrictionLaw` on a frozen spec (in ``__post_init__``)."""
    for fname, cls in ((law_field, NormalLaw), ("friction", FrictionLaw)):
        val = getattr(spec, fname)
        if isinstance(val, dict):
            try:
                object.__setattr__(spec, fname, cls(**val))
            except TypeError as exc:
                raise ModelError(f"{what}.{fname}: {exc}") from None


def check_laws(spec: Any, what: str) -> None:
    if not isinstance(spec.law, NormalLaw):
        raise ModelError(f"{what}.law: expected a NormalLaw, got {type(spec.law).__name__}")
    spec.law.validate(what)
    if spec.friction is not None:
        if not isinstance(spec.friction, FrictionLaw):
            raise ModelError(f"{what}.friction: expected a FrictionLaw or None, got "
                             f"{type(spec.friction).__name__}")
        spec.friction.validate(what)


def washer_friction_radius(r_int: float, r_ext: float) -> float:
    """Friction radius of an annulus under uniform pressure [m]:
    ``2 pi mu (F/S)(r_ext^3 - r_int^3)/3 = mu F r_m``."""
    return 2.0 * (r_ext**3 - r_int**3) / (3.0 * (r_ext**2 - r_int**2))


def marker_motion(ctx: Any, node: int, p: np.ndarray) -> tuple[np.ndarray, np.ndarray,
                                                               np.ndarray, np.ndarray]:
    """Initial position [m], velocity [m/s], rotation and angular velocity [rad/s] (global)
    of the point at offset ``p`` (node frame) on ``node`` (``ctx.nn`` = ground), from the
    spec's initial velocities."""
    R = ctx.R0[node]
    xp = ctx.x0[node] + R @ p
    vn = np.zeros(3)
    w = np.zeros(3)
    if node < ctx.nn:
        name = next(k for k, i in ctx.node_index.items() if i == node)
        spec = ctx.spec
        if name in spec.bodies:
            b = spec.bodies[name]
            w = np.asarray(b.angular_velocity, float)
            vn = b.velocity + np.cross(w, b.rotation @ b.com)
        else:
            nd = spec.nodes[name]
            w = np.asarray(nd.angular_velocity, float)
            vn = np.asarray(nd.velocity, float)
    return xp, vn + np.cross(w, R @ p), R, w


def axial_motion(ctx: Any, nA: int, pA: np.ndarray, abar: np.ndarray, nB: int,
                 pB: np.ndarray) -> tuple[float, float]:
    """Initial value and rate of ``(x_mB - x_mA) . (R_A abar)``."""
    xa, va, RA, wa = marker_motion(ctx, nA, pA)
    xb, vb, _, _ = marker_motion(ctx, nB, pB)
    a = RA @ abar
    d = xb - xa
    return float(d @ a), float((vb - va) @ a + d @ np.cross(wa, a))


def commit_range(c0: int, n: int) -> tuple[int, ...]:
    """``Group.commit_cols`` copying ``aux[:, c0:c0+n]`` into each element's state."""
    return tuple(range(c0, c0 + n))


GAP_RATE = ("gap_rate", "m/s", "rate of the gap")
MU_R = ("friction_coefficient", "1", "regularised friction coefficient mu_R")
CONTACT_POWER = ("dissipated_power", "W", "impact damping + friction power")

STATE_OUTPUTS = (
    ("impact_speed", "m/s", "approach speed at first contact of the current or last contact"),
    ("rebound_speed", "m/s", "separation speed of the last finished contact"),
    ("impacts", "1", "number of contacts started"),
    ("in_contact", "1", "1 while in contact, else 0"),
)


@njit(cache=True, inline="always")
def work_offsets(ngh, nvec):
    """Offsets in a contact kernel's work buffer: after ``local_arrays(12, 0)``, ``ngh``
    gradient/Hessian pairs (12), then ``nvec`` vectors (12), then the primitives' workspace
    and a 3 x 3 matrix."""
    v = LOCAL_SIZE_12 + ngh * sc.GRAD_HESS_SIZE_12
    return LOCAL_SIZE_12, v, v + 12 * nvec


@njit(cache=True, inline="always")
def work_size(ngh: int, nvec: int) -> int:
    """Entries of a contact kernel's work buffer (:func:`work_offsets`; the same sum, so
    that ``work_size.py_func`` needs no compiled function: a module or a build that calls a
    compiled function from Python compiles it there, on the first run's critical path, 0.4-0.6
    s of a cold import)."""
    return LOCAL_SIZE_12 + ngh * sc.GRAD_HESS_SIZE_12 + 12 * nvec + sc.WORKSPACE_SIZE + 9


@njit(cache=True, inline="always")
def washer_work(work):
    """The work arrays of a washer-like contact (thrust washer, squeeze film) as views of
    the group's buffer ``work`` (``work_size(2, 5)`` entries): local arrays, two gradient and
    Hessian pairs, three vectors, a pair of vectors, the primitives' workspace, a 3 x 3."""
    buf = sc.work_buffer(work, work_size(2, 5))
    G, V, w = work_offsets(2, 5)
    return (local_arrays_at(buf, 0, 12, 0), sc.grad_hess_at(buf, G, 12),
            sc.grad_hess_at(buf, G + 156, 12), carve(buf, V, 12), carve(buf, V + 12, 12),
            carve(buf, V + 24, 12), (carve(buf, V + 36, 12), carve(buf, V + 48, 12)),
            sc.workspace_at(buf, w), carve(buf, w + sc.WORKSPACE_SIZE, (3, 3)))


def contact_group(family: str, specs: list[Any], ctx: Any, kernel: Any, geom: tuple,
                  states: list[list[float]], outputs: tuple[tuple[str, str, str], ...],
                  lnodes: np.ndarray, work_size: int) -> Group:
    """The :class:`Group` of a force-type contact family: kernel parameters
    ``(*geom, law table, friction table, na, work)`` (the specs' ``law`` and ``friction``;
    ``work``: the kernel's work buffer of ``work_size`` entries), the
    impact state block of each element
    written by the kernel into hidden aux columns ``na .. na + NSTATE`` and committed from
    there; exported outputs ``outputs`` (columns 0..) plus :data:`STATE_OUTPUTS`."""
    eoff = np.array([ctx.alloc_state(st) for st in states], np.int64)
    na = len(outputs)
    cols = tuple(range(na)) + tuple(na + c for c in (ST_VS, ST_REBOUND, ST_COUNT, ST_FLAG))
    return make_group(
        family, specs, kernel, (*geom, law_table([s.law for s in specs]),
                                      friction_table([s.friction for s in specs]), na,
                                      np.zeros(work_size)), lnodes,
        node_dofs(ctx, lnodes), outputs + STATE_OUTPUTS, eoff=eoff, nstate=NSTATE,
        commit_cols=commit_range(na, NSTATE), naux=na + NSTATE, aux_cols=cols, dissipative=True,
    )
