"""Tabulated point-to-point springs, dampers and bump stops (families
``nonlinear_spring_damper``, ``bump_stop``).

Both act along the line of their two markers, like
:class:`~drivedyn.elements.springs.SpringDamper`, with the same sign convention: a scalar
tension ``s`` [N] (positive pulls the markers together, negative pushes them apart) on the
length ``L = |x_B + R_B p_B - x_A - R_A p_A|`` [m] and its rate ``Ldot`` [m/s] (positive:
the markers move apart).

* :class:`NonlinearSpringDamper`: a coil spring and a damper. Tension
  ``s = f_s(L - L0) + f_d(Ldot) + F0`` with the deflection ``x = L - L0`` (positive:
  extension; a compressed coil spring has ``x < 0`` and ``f_s < 0``), ``f_s`` the spring
  curve (a table of ``(x [m], tension [N])`` or ``k x``), and the damper
  ``f_d = F_reb(Ldot)`` in rebound (``Ldot >= 0``) and ``f_d = -F_comp(-Ldot)`` in
  compression, both tables of ``(speed [m/s] >= 0, force [N] >= 0)`` starting at (0, 0).
  Potential ``V = int_0^x f_s + F0 L`` [J], dissipated power ``f_d Ldot >= 0`` [W].
* :class:`BumpStop`: one-sided. Deflection beyond contact ``delta = L_c - L`` (compression
  stop) or ``L - L_c`` (extension stop), ``L_c`` the contact length (the initial length minus
  or plus the free travel ``gap``). For ``delta > 0`` the contact force is
  ``F = max(0, S(delta) F_k(delta) + c S(delta) deltadot)`` [N], ``F_k`` the stiffness table
  of ``(delta [m], force [N])`` from (0, 0), ``S`` the smooth onset ramp
  ``3 t^2 - 2 t^3`` of ``t = delta / transition`` (1 beyond, and without ramp when
  ``transition = 0``); 0 otherwise. It pushes the markers apart (compression stop:
  ``s = -F``) or pulls them together (extension stop: ``s = F``) and never the other way.
  Potential ``int_0^delta S F_k`` [J], dissipated power ``(F - S F_k) deltadot >= 0`` [W].

Every table is read by :mod:`drivedyn.elements.framework.curves` (PCHIP, linear
extrapolation beyond the last point). The residual is ``s g`` (``g = dL/dq``), the stiffness
``s H + g (s_L g + s_Ldot H^T v)^T`` and the damping ``s_Ldot g g^T``, with ``s_L`` and
``s_Ldot`` the partial derivatives of the tension.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
import drivedyn.units as U  # noqa: N812
from drivedyn.elements.framework.building import make_group, node_dofs, two_markers, what_of
from drivedyn.elements.framework.checks import check_param, check_param_optional
from drivedyn.elements.framework.contract import LOCAL_SIZE_12, local_arrays_at
from drivedyn.elements.framework.curves import (
    check_table,
    curve_integral,
    curve_value,
    pack_curves,
)
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.primitives import prim_distance, scalar_force
from drivedyn.elements.framework.registry import Family, TwoMarkerSpec, register
from drivedyn.elements.framework.work_arrays import carve
from drivedyn.errors import ModelError

#: a table as the specs hold it: ``((x0, y0), (x1, y1), ...)`` in SI units
CurveTable = tuple[tuple[float, float], ...]

#: markers closer than this in the initial configuration [m] have no line of action
MIN_LENGTH = 1e-9


# --- kernels -----------------------------------------------------------------------------------

#: entries of the work buffer of both families (their last parameter, ``work``)
WORK_SIZE = LOCAL_SIZE_12 + sc.GRAD_HESS_SIZE_12 + 24 + sc.WORKSPACE_SIZE


@njit(cache=True, inline="always")
def _work(buf):
    """Local arrays, gradient and Hessian, two 12-vectors and the primitives' workspace, as
    views of ``buf`` (:data:`WORK_SIZE`)."""
    o = LOCAL_SIZE_12 + sc.GRAD_HESS_SIZE_12
    return (local_arrays_at(buf, 0, 12, 0), sc.grad_hess_at(buf, LOCAL_SIZE_12, 12),
            carve(buf, o, 12), carve(buf, o + 12, 12), sc.workspace_at(buf, o + 24))

@njit(cache=True, inline="always")
def _length_and_rate(x, R, nA, nB, pA, pB, C, e, g, H, vl, full, ws, wv):
    """Length of the markers' line (filling ``g``, and ``H`` if ``full``) and its rate."""
    L = prim_distance(x[nA], R[nA], x[nB], R[nB], pA, pB, g, H, full, ws, wv)
    sc.velocities(C, e, 12, vl)
    Ld = 0.0
    for a in range(12):
        Ld += g[a] * vl[a]
    return L, Ld


@njit(cache=True)
def nonlinear_spring_kernel(
    pA, pB, free, pre, lin, cid, X, Y, D, start, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    W = _work(sc.work_buffer(work, WORK_SIZE))  # views of the group's buffer
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    L, (g, H), vl, Hv, (ws, wv) = W
    full = sc.full_pass(want, mode)
    rq, _, _, Cd, K, _ = L
    for e in range(sc.count(C)):
        nA, nB = sc.pair(C, e)
        length, rate = _length_and_rate(x, R, nA, nB, pA[e], pB[e], C, e, g, H, vl, full, ws,
                                        wv)
        dx = length - free[e]
        if cid[e, 0] >= 0:
            fs, ks = curve_value(X, Y, D, start, cid[e, 0], dx)
            V = curve_integral(X, Y, D, start, cid[e, 0], 0.0, dx)
        else:
            fs = lin[e] * dx
            ks = lin[e]
            V = 0.5 * lin[e] * dx * dx
        # rebound (Ldot >= 0) pulls, compression pushes: both tables hold magnitudes
        fd = 0.0
        cd = 0.0
        if rate >= 0.0:
            if cid[e, 1] >= 0:
                fd, cd = curve_value(X, Y, D, start, cid[e, 1], rate)
        elif cid[e, 2] >= 0:
            fc, cd = curve_value(X, Y, D, start, cid[e, 2], -rate)
            fd = -fc
        s = fs + pre[e] + fd
        scalar_force(s, ks, cd, g, H, vl, Hv, rq, K, Cd, full)
        sc.scatter(C, L, e, 2, full)
        sc.energy(C, e, 0.0, V + pre[e] * length, 0.0, fd * rate)
        sc.report(C, e, (s, length, rate, dx, fs + pre[e], fd, fd * rate))


@njit(cache=True, inline="always")
def _ramp(d, eps):
    """Onset ramp ``S = 3 t^2 - 2 t^3`` of ``t = d / eps`` (1 for ``d >= eps`` or
    ``eps = 0``) and ``dS/dd``: zero value and slope at ``d = 0``, slope 0 again at ``eps``."""
    if eps <= 0.0 or d >= eps:
        return 1.0, 0.0
    t = d / eps
    return t * t * (3.0 - 2.0 * t), 6.0 * t * (1.0 - t) / eps


# Gauss-Legendre, 4 points on [-1, 1]: exact up to degree 7, the ramp (cubic) times a
# Hermite segment (cubic)
_GL_X = (-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526)
_GL_W = (0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538)


@njit(cache=True)
def stop_potential(X, Y, D, start, k, d, eps):
    """Potential [J] of a bump stop at deflection ``d`` [m]: ``int_0^d S F_k``, curve ``k``
    the stiffness table (from 0), ``S`` the ramp of length ``eps`` (:func:`_ramp`); exact
    (Gauss-Legendre on each piece of the curve inside the ramp, the curve's integral
    beyond)."""
    if d <= 0.0:
        return 0.0
    if eps <= 0.0:
        return curve_integral(X, Y, D, start, k, 0.0, d)
    b = min(d, eps)
    i1 = start[k + 1] - 1
    j = start[k]
    total = 0.0
    a = 0.0
    while a < b:
        while j < i1 and X[j + 1] <= a:
            j += 1
        c = b if j >= i1 else min(b, X[j + 1])
        m = 0.5 * (a + c)
        h = 0.5 * (c - a)
        for i in range(4):
            q = m + h * _GL_X[i]
            f, _ = curve_value(X, Y, D, start, k, q)
            S, _ = _ramp(q, eps)
            total += h * _GL_W[i] * S * f
        a = c
    if d > eps:
        total += curve_integral(X, Y, D, start, k, eps, d)
    return total


@njit(cache=True)
def bump_stop_kernel(
    pA, pB, contact, side, cid, damp, eps, X, Y, D, start, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    W = _work(sc.work_buffer(work, WORK_SIZE))  # views of the group's buffer
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    L, (g, H), vl, Hv, (ws, wv) = W
    full = sc.full_pass(want, mode)
    rq, _, _, Cd, K, _ = L
    for e in range(sc.count(C)):
        nA, nB = sc.pair(C, e)
        length, rate = _length_and_rate(x, R, nA, nB, pA[e], pB[e], C, e, g, H, vl, full, ws,
                                        wv)
        sg = side[e]  # +1: compression stop, -1: extension stop
        d = sg * (contact[e] - length)
        dd = -sg * rate
        F = 0.0
        Fk = 0.0
        Fq = 0.0  # dF/d delta
        Fv = 0.0  # dF/d deltadot
        V = 0.0
        if d > 0.0:
            fk, dfk = curve_value(X, Y, D, start, cid[e], d)
            S, dS = _ramp(d, eps[e])
            Fk = S * fk
            cs = damp[e] * S
            F = Fk + cs * dd
            V = stop_potential(X, Y, D, start, cid[e], d, eps[e])
            if F > 0.0:
                Fq = dS * fk + S * dfk + damp[e] * dS * dd
                Fv = cs
            else:  # the damper would pull through a fast rebound: no force at all
                F = 0.0
        # s = -sg F; d delta/dL = -sg, d deltadot/dLdot = -sg, so ds/dL = Fq, ds/dLdot = Fv
        scalar_force(-sg * F, Fq, Fv, g, H, vl, Hv, rq, K, Cd, full)
        sc.scatter(C, L, e, 2, full)
        P_dis = (F - Fk) * dd
        sc.energy(C, e, 0.0, V, 0.0, P_dis)
        sc.report(C, e, (F, length, rate, d, Fk, F - Fk, P_dis))


# --- tables in specs -----------------------------------------------------------------------------


def _pairs(value: Any, dims: tuple[U.Dim, U.Dim]) -> CurveTable:
    """``value`` (a sequence of pairs or an (n, 2) array) as a table of (x, y) pairs in SI:
    each entry a number (SI) or a ``"<number> <unit>"`` string of its column's dimension;
    ``ValueError`` (a
    :class:`~drivedyn.units.UnitError` for units) otherwise."""
    if isinstance(value, np.ndarray):  # Python numbers, as model files give them
        value = value.tolist()
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence):
        raise ValueError("not a list")
    out = []
    for row in value:
        if isinstance(row, np.ndarray):
            row = row.tolist()
        if isinstance(row, (str, bytes)) or not isinstance(row, Sequence) or len(row) != 2:
            raise ValueError(f"each point is a pair [x, y], got {row!r}")
        xy = (U.to_si(row[0], dims[0]), U.to_si(row[1], dims[1]))
        for v, dim in zip(xy, dims, strict=True):
            U.check_plausible(v, dim)
        out.append(xy)
    return tuple(out)


def coerce_tables(spec: Any, tables: dict[str, tuple[U.Dim, U.Dim]]) -> None:
    """Tables given as lists (model files) or with unit strings stored as tuples of SI pairs
    on a frozen spec; a table that does not read is left as given for ``validate``."""
    for key, dims in tables.items():
        value = getattr(spec, key)
        if value is None:
            continue
        try:
            object.__setattr__(spec, key, _pairs(value, dims))
        except (ValueError, TypeError):
            pass


def table_arrays(spec: Any, key: str, dims: tuple[U.Dim, U.Dim], columns: str,
                 origin: str | None = None, monotone: bool = True,
                 xname: str = "abscissae") -> tuple[np.ndarray, np.ndarray]:
    """The abscissae and values of table parameter ``key`` of ``spec``, checked
    (:func:`~drivedyn.elements.framework.curves.check_table`: at least two points, abscissae
    increasing, values non-decreasing if ``monotone``); :class:`ModelError` naming the
    element, the key and the value otherwise. ``columns``: what a point is, for the message;
    ``xname``: what the abscissae are, for the message; ``origin``: the unit of the
    abscissae of a table of magnitudes, which must start at (0, 0) (no negative abscissa, no
    force at zero), None for any table."""
    what = f"{what_of(spec)}.{key}"
    value = getattr(spec, key)
    try:
        pairs = _pairs(value, dims)
    except U.UnitError as exc:
        raise ModelError(f"{what}: {exc} (in {value!r})") from None
    except (ValueError, TypeError):
        raise ModelError(f"{what}: expected a table of {columns} pairs, e.g. "
                         f"[[0.0, 0.0], [0.05, 1500.0]], got {value!r}") from None
    x = [p[0] for p in pairs]
    y = [p[1] for p in pairs]
    if origin is not None and any(v < 0.0 for v in x):
        bad = next(v for v in x if v < 0.0)
        raise ModelError(f"{what}: abscissae must be >= 0 {origin} (the table holds "
                         f"magnitudes), got {bad!r}")
    try:
        xa, ya = check_table(x, y, what, monotone=monotone, xname=xname)
    except ValueError as exc:
        raise ModelError(str(exc)) from None
    if origin is not None and (xa[0] != 0.0 or ya[0] != 0.0):
        raise ModelError(f"{what}: the table must start at (0, 0) (no force at zero), got "
                         f"({float(xa[0])!r}, {float(ya[0])!r}) first")
    return xa, ya


def _length_dims() -> tuple[U.Dim, U.Dim]:
    return (U.LENGTH, U.FORCE)


def _speed_dims() -> tuple[U.Dim, U.Dim]:
    return (U.VELOCITY, U.FORCE)


# --- specs --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class NonlinearSpringDamper(TwoMarkerSpec):
    """Coil spring and damper between the origins of two markers, from tabulated curves.

    Tension ``s = f_s(L - L0) + f_d(Ldot) + F0`` [N], positive pulling the markers together
    (the convention of :class:`~drivedyn.elements.springs.SpringDamper`): the deflection
    ``x = L - L0`` is positive in extension, so a compression spring's table has negative
    deflections and negative (pushing) tensions.

    Attributes:
        name: unique element name.
        marker_a, marker_b: attachment markers, apart in the initial configuration.
        spring_curve: table ``((x [m], tension [N]), ...)`` of the spring, non-decreasing
            (PCHIP between points, straight beyond the ends); or None.
        stiffness: linear alternative k [N/m] >= 0 (``f_s = k x``); None: no spring unless
            ``spring_curve`` is given (not both).
        free_length: L0 [m] > 0; None = the initial distance.
        damper_curve_rebound: table ``((speed [m/s], force [N]), ...)`` from (0, 0),
            non-decreasing, for ``Ldot >= 0`` (the damper pulls with that force); None: no
            damping in rebound.
        damper_curve_compression: the same for ``Ldot < 0`` at speed ``-Ldot`` (the damper
            pushes); None: no damping in compression.
        preload: F0 [N], tension added at every length (negative: compression).
    """

    spring_curve: CurveTable | None = None
    stiffness: float | None = None
    free_length: float | None = None
    damper_curve_rebound: CurveTable | None = None
    damper_curve_compression: CurveTable | None = None
    preload: float = 0.0
    family: ClassVar[str] = "nonlinear_spring_damper"
    units: ClassVar[dict[str, str]] = {
        "stiffness": "N/m",
        "free_length": "m",
        "preload": "N",
    }

    def __post_init__(self) -> None:
        coerce_tables(self, {"spring_curve": _length_dims(),
                              "damper_curve_rebound": _speed_dims(),
                              "damper_curve_compression": _speed_dims()})

    def tables(self) -> tuple[tuple[np.ndarray, np.ndarray] | None, ...]:
        """The checked tables (abscissae, values) of the spring, the rebound and the
        compression damper (None where not given)."""
        spring = None if self.spring_curve is None else table_arrays(
            self, "spring_curve", _length_dims(), "[deflection m, tension N]")
        dampers = []
        for key in ("damper_curve_rebound", "damper_curve_compression"):
            if getattr(self, key) is None:
                dampers.append(None)
                continue
            dampers.append(table_arrays(self, key, _speed_dims(), "[speed m/s, force N]",
                                        origin="m/s"))
        return (spring, *dampers)

    def validate(self) -> None:
        check_param_optional(self, "stiffness", 0.0)
        check_param_optional(self, "free_length", 0.0, strict=True)
        check_param(self, "preload")
        if self.spring_curve is not None and self.stiffness is not None:
            raise ModelError(f"{what_of(self)}: give spring_curve or stiffness, not both")
        self.tables()

    def visuals(self) -> tuple:
        """A coil between the markers when the element has a spring (sized by the viewer
        from their initial distance), else a damper's tube."""
        from drivedyn.elements.framework.visuals import coil, link

        if self.spring_curve is not None or self.stiffness is not None:
            return (coil(self.marker_a, self.marker_b, label=self.name),)
        return (link(self.marker_a, self.marker_b, 0.0, role="damper", label=self.name),)


@dataclass(frozen=True)
class BumpStop(TwoMarkerSpec):
    """One-sided bump stop between the origins of two markers, from a tabulated curve.

    Contact when the markers have come ``gap`` closer than in the initial configuration
    (``side = "compression"``: contact length ``L_c = L_init - gap``) or gone ``gap``
    further apart (``side = "extension"``, a rebound stop: ``L_c = L_init + gap``); the
    force pushes them apart (compression) or pulls them together (extension), never the
    other way, and is exactly zero before contact.

    Attributes:
        name: unique element name.
        marker_a, marker_b: attachment markers, apart in the initial configuration.
        stiffness_curve: table ``((delta [m], force [N]), ...)`` of the force against the
            deflection beyond contact, from (0, 0), non-decreasing.
        gap: free travel [m] from the initial length to contact; negative: the stop is in
            contact, compressed by ``-gap``, in the initial configuration.
        damping: c [N s/m] >= 0 in contact, ramped in with the stiffness (needs
            ``transition > 0``).
        transition: length [m] >= 0 of the smooth onset ramp ``3 t^2 - 2 t^3``
            (``t = delta / transition``) multiplying the curve and the damping: the force
            then has a continuous slope at contact onset. 0: the force is the curve from
            contact on (its slope jumps at onset from 0 to the curve's first slope).
        side: ``"compression"`` or ``"extension"``.
    """

    stiffness_curve: CurveTable
    gap: float
    damping: float = 0.0
    transition: float = 0.0
    side: str = "compression"
    family: ClassVar[str] = "bump_stop"
    units: ClassVar[dict[str, str]] = {
        "gap": "m",
        "damping": "N s/m",
        "transition": "m",
    }

    def __post_init__(self) -> None:
        coerce_tables(self, {"stiffness_curve": _length_dims()})

    def table(self) -> tuple[np.ndarray, np.ndarray]:
        """The checked stiffness table (deflections, forces)."""
        return table_arrays(self, "stiffness_curve", _length_dims(),
                            "[deflection m, force N]", origin="m")

    def validate(self) -> None:
        what = what_of(self)
        check_param(self, "gap")
        check_param(self, "damping", 0.0)
        check_param(self, "transition", 0.0)
        if self.side not in ("compression", "extension"):
            raise ModelError(f"{what}.side: must be 'compression' or 'extension', got "
                             f"{self.side!r}")
        if self.damping > 0.0 and self.transition <= 0.0:
            raise ModelError(f"{what}.transition: must be > 0 m with damping (the damping "
                             f"force must vanish smoothly at contact onset), got "
                             f"{self.transition!r}")
        self.table()

    def visuals(self) -> tuple:
        """The stop's rubber: a stub on the line of the markers, from marker A (a
        compression stop) or marker B (an extension stop), a fifth of their initial
        distance long."""
        from drivedyn.elements.framework.visuals import link

        a, b = ((self.marker_a, self.marker_b) if self.side == "compression"
                else (self.marker_b, self.marker_a))
        return (link(a, b, 0.0, role="stop", label=self.name, fraction=0.2),)


# --- families -----------------------------------------------------------------------------------


def initial_lengths(specs: Sequence[Any], ctx: Any, pA: np.ndarray, pB: np.ndarray,
                    lnodes: np.ndarray) -> np.ndarray:
    """Initial distances [m] of the markers of each element; :class:`ModelError` for markers
    at one point (no line of action)."""
    out = np.zeros(len(specs))
    for e, s in enumerate(specs):
        nA, nB = lnodes[e]
        d = (ctx.x0[nB] + ctx.R0[nB] @ pB[e]) - (ctx.x0[nA] + ctx.R0[nA] @ pA[e])
        out[e] = float(np.linalg.norm(d))
        if out[e] < MIN_LENGTH:
            raise ModelError(
                f"{what_of(s)}: markers {s.marker_a!r} and {s.marker_b!r} are at the same "
                f"point in the initial configuration (distance {out[e]:.3g} m); the element "
                f"acts along the line between its markers, place them apart")
    return out


_LINE_OUTPUTS = (("length", "m", "distance of the markers"),
                 ("length_rate", "m/s", "rate of the distance (> 0: the markers separate)"))


class NonlinearSpringFamily(Family):
    """Registry entry of :class:`NonlinearSpringDamper`."""

    name = "nonlinear_spring_damper"

    def build(self, specs, ctx) -> Group:
        pA, pB, _, _, lnodes = two_markers(specs, ctx, "a spring-damper")
        L0 = initial_lengths(specs, ctx, pA, pB, lnodes)
        nel = len(specs)
        cid = np.full((nel, 3), -1, np.int64)
        tables = []
        for e, s in enumerate(specs):
            for j, xy in enumerate(s.tables()):
                if xy is not None:
                    cid[e, j] = len(tables)
                    tables.append(xy)
        free = np.array([L0[e] if s.free_length is None else s.free_length
                         for e, s in enumerate(specs)], float)
        params = (pA, pB, free,
                  np.array([s.preload for s in specs], float),
                  np.array([s.stiffness or 0.0 for s in specs], float),
                  cid, *pack_curves(tables), np.zeros(WORK_SIZE))
        outputs = (("force", "N", "tension (positive pulls the markers together)"),
                   *_LINE_OUTPUTS,
                   ("deflection", "m", "length minus free length (> 0: extension)"),
                   ("spring_force", "N", "tension of the spring, preload included"),
                   ("damper_force", "N", "tension of the damper (> 0 in rebound)"),
                   ("dissipated_power", "W", "power dissipated by the damper"))
        return make_group(self.name, specs, nonlinear_spring_kernel, params, lnodes,
                          node_dofs(ctx, lnodes), outputs, dissipative=True)


class BumpStopFamily(Family):
    """Registry entry of :class:`BumpStop`."""

    name = "bump_stop"

    def build(self, specs, ctx) -> Group:
        pA, pB, _, _, lnodes = two_markers(specs, ctx, "a bump stop")
        L0 = initial_lengths(specs, ctx, pA, pB, lnodes)
        side = np.array([1.0 if s.side == "compression" else -1.0 for s in specs])
        contact = L0 - side * np.array([s.gap for s in specs], float)
        for e, s in enumerate(specs):
            if contact[e] <= 0.0:
                sign = "-" if side[e] > 0.0 else "+"
                raise ModelError(f"{what_of(s)}.gap: the contact length (initial distance "
                                 f"{L0[e]:.6g} m {sign} gap) must be > 0 m, got gap "
                                 f"{s.gap!r}")
        outputs = (("force", "N", "contact force (>= 0; pushes the markers apart, or pulls "
                    "them together for an extension stop)"),
                   *_LINE_OUTPUTS,
                   ("deflection", "m", "deflection beyond contact (< 0: free travel left)"),
                   ("spring_force", "N", "force of the stiffness curve (with the onset ramp)"),
                   ("damper_force", "N", "force of the damping (contact force minus spring "
                    "force)"),
                   ("dissipated_power", "W", "power dissipated by the damping"))
        params = (pA, pB, contact, side, np.arange(len(specs), dtype=np.int64),
                  np.array([s.damping for s in specs], float),
                  np.array([s.transition for s in specs], float),
                  *pack_curves([s.table() for s in specs]), np.zeros(WORK_SIZE))
        return make_group(self.name, specs, bump_stop_kernel, params, lnodes,
                          node_dofs(ctx, lnodes), outputs, dissipative=True)


register(NonlinearSpringFamily())
register(BumpStopFamily())
