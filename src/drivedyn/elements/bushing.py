"""Rubber bushings between two markers (family ``bushing``): six axes of elastic, damping and
rate-dependent (Maxwell) forces in the bushing frame.

Deflections (measured from the model's initial configuration, where the bushing is unloaded
apart from its preload):

* translation ``d = R_A^T (p_B - p_A) - d0`` [m]: the displacement of marker B's origin
  relative to marker A's origin, in marker A's frame (the *bushing frame*);
* rotation ``theta = log(R_A^T R_B')`` [rad]: the rotation vector of B relative to A, with
  ``R_B' = R_B R_rel0^T`` marker B's frame corrected by its initial orientation relative to A
  (so marker B's own axes do not matter). The logarithm is objective: it does not depend on
  how the pair is oriented in space.

Per axis ``j`` (x, y, z of translation, then of rotation) the law is a Kelvin-Voigt part in
parallel with Maxwell branches::

    f_j = g_j(x_j) + c_j xdot_j + sum_b k_b (x_j - u_b),    c_b u_b' = k_b (x_j - u_b)

with ``g_j`` linear (``k_j x + preload_j``) or a tabulated curve (monotone cubic Hermite,
:mod:`drivedyn.elements.framework.curves`, extrapolated linearly; its value at zero
deflection is a preload, and ``preload_j`` adds to it). Under ``x = X sin(w t)`` the complex
stiffness of an axis is ``K*(w) = k + i w c + sum_b k_b (i w tau_b)/(1 + i w tau_b)``,
``tau_b = c_b/k_b``.

Generalised forces: with ``x = (d, theta)`` and ``xdot = B(q) v`` (``B`` the derivative of
the six deflections with respect to the node coordinates), the residual is ``B^T f``. The
deflections are invariant under any rigid motion of the whole pair, so the forces and
moments on A and B balance exactly, moments about any point included: the force on A is
``+R_A f_d`` acting at marker B's origin (on the line of action of the force ``-R_A f_d`` on
B), and the moments conjugate to ``theta`` are ``T(theta)^-T f_theta`` in B's frame
(``T`` the SO(3) tangent operator; equal to the law's moments for small rotations).

Maxwell branches: the branch spring's deflection ``s_b = x - u_b`` is an internal state
committed at each accepted step, together with the deflections and the time. Between the
committed state (``t_n, x_n, s_n``) and the evaluation (``t, x``) the deflection is taken
linear in time and the branch equation ``s_b' = xdot - s_b / tau_b`` is integrated exactly::

    s_b = phi (x - x_n) + E s_n,    E = exp(-h/tau_b),  phi = (1 - E) tau_b / h,  h = t - t_n

(exact for a piecewise-linear deflection, second order for a smooth one, stable for any
``h/tau_b``); the tangent takes its derivative ``k_b phi``. A static equilibrium at the
committed time (``h = 0``) sees the branches at their committed deflections (they act as
springs of stiffness ``k_b`` on top of the static law).

Energies: potential ``int_0^x g_j + sum_b k_b s_b^2 / 2``, dissipated power
``c_j xdot_j^2 + sum_b k_b^2 s_b^2 / c_b``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.beams.se3 import tangent_inv_coeffs
from drivedyn.elements.framework.building import make_group, node_dofs, two_markers, what_of
from drivedyn.elements.framework.checks import check_number, unit_of
from drivedyn.elements.framework.contract import local_arrays_at, local_size
from drivedyn.elements.framework.curves import (
    check_table,
    curve_integral,
    curve_value,
    pack_curves,
)
from drivedyn.elements.framework.group import COMMIT_TIME, Group
from drivedyn.elements.framework.primitives import cross, mm, mtm, mtv, mv, set_skew
from drivedyn.elements.framework.registry import Family, TwoMarkerSpec, register
from drivedyn.elements.framework.work_arrays import carve
from drivedyn.errors import ModelError
from drivedyn.rotations import log_so3

AXES = ("x", "y", "z")

OUTPUTS = (
    ("force_x", "N", "bushing force along the bushing frame's x axis (the law's value: the "
     "force on body B is -force_x along x, on body A +force_x)"),
    ("force_y", "N", "bushing force along y (as force_x)"),
    ("force_z", "N", "bushing force along z (as force_x)"),
    ("moment_x", "N m", "bushing moment about the bushing frame's x axis (the law's value, "
     "resisting the rotation rotation_x)"),
    ("moment_y", "N m", "bushing moment about y (as moment_x)"),
    ("moment_z", "N m", "bushing moment about z (as moment_x)"),
    ("deflection_x", "m", "displacement of marker B relative to marker A along the bushing "
     "frame's x axis, from the initial configuration"),
    ("deflection_y", "m", "displacement of B relative to A along y"),
    ("deflection_z", "m", "displacement of B relative to A along z"),
    ("rotation_x", "rad", "rotation vector of B relative to A (log of the relative rotation), "
     "x component in the bushing frame"),
    ("rotation_y", "rad", "rotation of B relative to A, y component"),
    ("rotation_z", "rad", "rotation of B relative to A, z component"),
    ("dissipated_power", "W", "power dissipated by the dampers and the Maxwell branches"),
)
NPUB = len(OUTPUTS)  # hidden columns after these: the branch deflections s_b (committed)
COL_DEFL = 6  # first deflection column (committed as x_n)
NLAW = 6  # axes

# work arrays (views of the group's buffer, see _work)
NMAT = 14
NVEC = 12
_L = local_size(12, 0)
WORK_SIZE = _L + 2 * 72 + 9 * NMAT + 3 * NVEC + 5 * 6 + 12


# --- records of the parameter tables ---------------------------------------------------------


@dataclass(frozen=True)
class BushingCurve:
    """Force against deflection along one translational axis of a :class:`Bushing`: a table
    read as a monotone cubic (PCHIP) curve, continued linearly beyond its ends.

    Attributes:
        axis: ``"x"``, ``"y"`` or ``"z"`` of the bushing frame.
        deflection: (n,) strictly increasing deflections [m], n >= 2.
        force: (n,) forces [N], not decreasing (the value at zero deflection is a preload).
    """

    axis: str
    deflection: tuple[float, ...]
    force: tuple[float, ...]
    units: ClassVar[dict[str, str]] = {"deflection": "m", "force": "N"}
    table: ClassVar[tuple[str, str]] = ("deflection", "force")


@dataclass(frozen=True)
class BushingRotationalCurve:
    """Moment against rotation about one axis of a :class:`Bushing` (as
    :class:`BushingCurve`).

    Attributes:
        axis: ``"x"``, ``"y"`` or ``"z"`` of the bushing frame.
        angle: (n,) strictly increasing rotations [rad], n >= 2.
        moment: (n,) moments [N m], not decreasing.
    """

    axis: str
    angle: tuple[float, ...]
    moment: tuple[float, ...]
    units: ClassVar[dict[str, str]] = {"angle": "rad", "moment": "N m"}
    table: ClassVar[tuple[str, str]] = ("angle", "moment")


@dataclass(frozen=True)
class MaxwellBranch:
    """A spring ``stiffness`` [N/m] in series with a damper ``damping`` [N s/m] along one
    translational axis of a :class:`Bushing` (relaxation time ``damping / stiffness``).

    Attributes:
        axis: ``"x"``, ``"y"`` or ``"z"`` of the bushing frame.
        stiffness: k_b [N/m] > 0.
        damping: c_b [N s/m] > 0.
    """

    axis: str
    stiffness: float
    damping: float
    units: ClassVar[dict[str, str]] = {"stiffness": "N/m", "damping": "N s/m"}


@dataclass(frozen=True)
class RotationalMaxwellBranch:
    """A Maxwell branch about one rotational axis of a :class:`Bushing`.

    Attributes:
        axis: ``"x"``, ``"y"`` or ``"z"`` of the bushing frame.
        stiffness: k_b [N m/rad] > 0.
        damping: c_b [N m s/rad] > 0.
    """

    axis: str
    stiffness: float
    damping: float
    units: ClassVar[dict[str, str]] = {"stiffness": "N m/rad", "damping": "N m s/rad"}


def _records(values: Any, cls: type, where: str) -> tuple[Any, ...]:
    """``values`` (records or tables with the record's keys) as a tuple of ``cls``."""
    if isinstance(values, (str, bytes, dict)) or not isinstance(values, Sequence):
        raise ModelError(f"{where}: expected a list of {cls.__name__} (or tables), got "
                         f"{values!r}")
    out = []
    for i, v in enumerate(values):
        if isinstance(v, dict):
            try:
                v = cls(**v)
            except TypeError:
                keys = ", ".join(f for f in cls.__dataclass_fields__)
                raise ModelError(f"{where}[{i}]: expected the keys {keys}, got "
                                 f"{sorted(v)}") from None
        elif not isinstance(v, cls):
            raise ModelError(f"{where}[{i}]: expected a {cls.__name__} or a table, got {v!r}")
        out.append(v)
    return tuple(out)


def _axis(rec: Any, where: str) -> int:
    if rec.axis not in AXES:
        raise ModelError(f"{where}.axis: expected 'x', 'y' or 'z', got {rec.axis!r}")
    return AXES.index(rec.axis)


# --- the spec -----------------------------------------------------------------------------------


@dataclass(frozen=True)
class Bushing(TwoMarkerSpec):
    """A rubber bushing: six axes (three translations, three rotations) between two markers,
    in the frame of marker A (see the module docstring for the deflections and the law).

    Each axis is linear (stiffness, damping, preload) or follows a tabulated curve, plus
    optional Maxwell branches (a spring in series with a damper) that make its dynamic
    stiffness and loss angle depend on the frequency, as in real rubber.

    Attributes:
        name: unique element name.
        marker_a: marker whose frame is the bushing frame.
        marker_b: marker on the other body (its origin is the bushing's centre on that body;
            its axes do not matter: rotations are measured from the initial orientation).
        stiffness: (3,) k [N/m] >= 0 along x, y, z (0 on an axis with a curve).
        damping: (3,) c [N s/m] >= 0.
        rotational_stiffness: (3,) k [N m/rad] >= 0 about x, y, z.
        rotational_damping: (3,) c [N m s/rad] >= 0.
        preload: (3,) force [N] at zero deflection (added to a curve's own value).
        rotational_preload: (3,) moment [N m] at zero rotation.
        curves: :class:`BushingCurve` records (or tables ``{axis, deflection, force}``), at
            most one per axis; they replace the linear stiffness of their axes.
        rotational_curves: :class:`BushingRotationalCurve` records (``{axis, angle,
            moment}``).
        branches: :class:`MaxwellBranch` records (``{axis, stiffness, damping}``), any
            number per axis.
        rotational_branches: :class:`RotationalMaxwellBranch` records.
    """

    stiffness: tuple[float, float, float] = (0.0, 0.0, 0.0)
    damping: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rotational_stiffness: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rotational_damping: tuple[float, float, float] = (0.0, 0.0, 0.0)
    preload: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rotational_preload: tuple[float, float, float] = (0.0, 0.0, 0.0)
    curves: tuple[BushingCurve, ...] = ()
    rotational_curves: tuple[BushingRotationalCurve, ...] = ()
    branches: tuple[MaxwellBranch, ...] = ()
    rotational_branches: tuple[RotationalMaxwellBranch, ...] = ()
    family: ClassVar[str] = "bushing"
    units: ClassVar[dict[str, str]] = {
        "stiffness": "N/m",
        "damping": "N s/m",
        "rotational_stiffness": "N m/rad",
        "rotational_damping": "N m s/rad",
        "preload": "N",
        "rotational_preload": "N m",
    }

    def _vector(self, label: str, low: float | None) -> np.ndarray:
        """Parameter ``label`` as a (3,) array, each component checked (``>= low``)."""
        what = what_of(self)
        value = getattr(self, label)
        unit = unit_of(self, label)
        if isinstance(value, (str, bytes)) or not isinstance(value, (Sequence, np.ndarray)) \
                or len(value) != 3:
            raise ModelError(f"{what}.{label}: expected 3 numbers [{unit}] (x, y, z), got "
                             f"{value!r}")
        return np.array([check_number(what, f"{label}[{i}]", v, low, unit=unit)
                         for i, v in enumerate(value)])

    def laws(self) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                            list[tuple[int, np.ndarray, np.ndarray]],
                            list[tuple[int, float, float]]]:
        """The six axes' parameters as the kernel uses them (x, y, z, rx, ry, rz), checked:
        stiffness (6,), damping (6,), preload (6,), the curves ``(axis, x, y)`` and the
        branches ``(axis, k_b, c_b)``; :class:`ModelError` naming the parameter and the
        value otherwise."""
        what = what_of(self)
        k = np.r_[self._vector("stiffness", 0.0), self._vector("rotational_stiffness", 0.0)]
        c = np.r_[self._vector("damping", 0.0), self._vector("rotational_damping", 0.0)]
        pre = np.r_[self._vector("preload", None), self._vector("rotational_preload", None)]
        curves: list[tuple[int, np.ndarray, np.ndarray]] = []
        for label, cls, off in (("curves", BushingCurve, 0),
                                ("rotational_curves", BushingRotationalCurve, 3)):
            for i, rec in enumerate(_records(getattr(self, label), cls, f"{what}.{label}")):
                where = f"{what}.{label}[{i}]"
                j = off + _axis(rec, where)
                xl, yl = cls.table
                for lab in (xl, yl):
                    vals = getattr(rec, lab)
                    unit = unit_of(rec, lab)
                    if isinstance(vals, (str, bytes)) \
                            or not isinstance(vals, (Sequence, np.ndarray)):
                        raise ModelError(f"{where}.{lab}: expected a list of numbers [{unit}], "
                                         f"got {vals!r}")
                    for n, val in enumerate(vals):
                        check_number(where, f"{lab}[{n}]", val, unit=unit)
                try:
                    xa, ya = check_table(getattr(rec, xl), getattr(rec, yl), where)
                except (TypeError, ValueError) as exc:
                    msg = str(exc)
                    raise ModelError(msg if msg.startswith(where) else f"{where}: {msg}") \
                        from None
                if any(cj == j for cj, _, _ in curves):
                    raise ModelError(f"{where}.axis: a second curve for axis {rec.axis!r}")
                if k[j] != 0.0:
                    kl = "stiffness" if off == 0 else "rotational_stiffness"
                    raise ModelError(f"{what}.{kl}[{j - off}]: must be 0 on axis {rec.axis!r}, "
                                     f"which has a curve ({label}[{i}]), got "
                                     f"{getattr(self, kl)[j - off]!r}")
                curves.append((j, xa, ya))
        branches: list[tuple[int, float, float]] = []
        for label, cls, off in (("branches", MaxwellBranch, 0),
                                ("rotational_branches", RotationalMaxwellBranch, 3)):
            for i, rec in enumerate(_records(getattr(self, label), cls, f"{what}.{label}")):
                where = f"{what}.{label}[{i}]"
                j = off + _axis(rec, where)
                kb = check_number(where, "stiffness", rec.stiffness, 0.0, True,
                                  unit_of(rec, "stiffness"))
                cb = check_number(where, "damping", rec.damping, 0.0, True,
                                  unit_of(rec, "damping"))
                branches.append((j, kb, cb))
        return k, c, pre, curves, branches

    def validate(self) -> None:
        self.laws()

    def dynamic_stiffness(self, axis: str, omega: float, rotational: bool = False) -> complex:
        """The complex stiffness ``K*(omega)`` [N/m or N m/rad] of one axis about zero
        deflection: ``k + i omega c + sum_b k_b (i omega tau_b)/(1 + i omega tau_b)``, ``k``
        the static law's slope at zero (the curve's, if the axis has one)."""
        k, c, _, curves, branches = self.laws()
        j = AXES.index(axis) + (3 if rotational else 0)
        ks = k[j]
        for cj, xa, ya in curves:
            if cj == j:
                X, Y, D, start = pack_curves([(xa, ya)])
                ks = float(curve_value(X, Y, D, start, 0, 0.0)[1])
        out = complex(ks, omega * c[j])
        for bj, kb, cb in branches:
            if bj == j:
                iwt = 1j * omega * cb / kb
                out += kb * iwt / (1.0 + iwt)
        return out


# --- the kernel -------------------------------------------------------------------------------


@njit(cache=True)
def _log_into(Rr, out):
    """``out`` (3,) <- the rotation vector of ``Rr`` (3, 3) without allocating (as
    :func:`drivedyn.rotations.log_so3`, whose near-pi branch it calls beyond 134 deg)."""
    tr = Rr[0, 0] + Rr[1, 1] + Rr[2, 2]
    c = min(1.0, max(-1.0, 0.5 * (tr - 1.0)))
    w0 = 0.5 * (Rr[2, 1] - Rr[1, 2])
    w1 = 0.5 * (Rr[0, 2] - Rr[2, 0])
    w2 = 0.5 * (Rr[1, 0] - Rr[0, 1])
    if c > -0.7:
        s = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        t = math.atan2(s, c)
        if t < 1e-4:
            t2 = t * t
            f = 1.0 / (1.0 - t2 / 6.0 + t2 * t2 / 120.0)
        else:
            f = t / s
        out[0] = f * w0
        out[1] = f * w1
        out[2] = f * w2
    else:
        th = log_so3(Rr)
        out[0] = th[0]
        out[1] = th[1]
        out[2] = th[2]


@njit(cache=True, inline="always")
def _mmt(A, B, out):
    """out = A B^T (3x3)."""
    for i in range(3):
        for j in range(3):
            out[i, j] = A[i, 0] * B[j, 0] + A[i, 1] * B[j, 1] + A[i, 2] * B[j, 2]


@njit(cache=True, inline="always")
def _put(K, r0, c0, M, s):
    """K[r0:r0+3, c0:c0+3] += s M."""
    for i in range(3):
        for j in range(3):
            K[r0 + i, c0 + j] += s * M[i, j]


@njit(cache=True, inline="always")
def _put_t(K, r0, c0, M, s):
    """K[r0:r0+3, c0:c0+3] += s M^T."""
    for i in range(3):
        for j in range(3):
            K[r0 + i, c0 + j] += s * M[j, i]


@njit(cache=True, inline="always")
def _d_tinv(th, t2, cc, ee, y, sgn, out):
    """``out`` (3, 3) <- d(T_s(theta) y)/d theta for ``T_s = I + sgn theta~/2 + cc theta~^2``
    (``sgn = 1``: the inverse tangent ``T^-1``; ``-1``: its transpose), ``cc = c(t)``,
    ``ee = c'(t)/t`` (:func:`~drivedyn.elements.beams.se3.tangent_inv_coeffs`)."""
    ty = th[0] * y[0] + th[1] * y[1] + th[2] * y[2]
    for i in range(3):
        gi = th[i] * ty - t2 * y[i]  # (theta x (theta x y))_i
        for j in range(3):
            v = cc * (th[i] * y[j] - 2.0 * y[i] * th[j]) + ee * gi * th[j]
            if i == j:
                v += cc * ty
            out[i, j] = v
    # -sgn y~ / 2
    h = -0.5 * sgn
    out[0, 1] -= h * y[2]
    out[0, 2] += h * y[1]
    out[1, 0] += h * y[2]
    out[1, 2] -= h * y[0]
    out[2, 0] -= h * y[1]
    out[2, 1] += h * y[0]


@njit(cache=True, inline="always")
def _tinv_apply(th, t2, cc, y, sgn, out):
    """``out`` (3,) <- ``(I + sgn theta~/2 + cc theta~^2) y``."""
    ty = th[0] * y[0] + th[1] * y[1] + th[2] * y[2]
    c0 = th[1] * y[2] - th[2] * y[1]
    c1 = th[2] * y[0] - th[0] * y[2]
    c2 = th[0] * y[1] - th[1] * y[0]
    out[0] = y[0] + 0.5 * sgn * c0 + cc * (th[0] * ty - t2 * y[0])
    out[1] = y[1] + 0.5 * sgn * c1 + cc * (th[1] * ty - t2 * y[1])
    out[2] = y[2] + 0.5 * sgn * c2 + cc * (th[2] * ty - t2 * y[2])


@njit(cache=True, inline="always")
def _axis_laws(e, xv, xd, kx, cx, pre, cid, CX, CY, CD, cstart, f, kt, cv):
    """Static law and damper of each axis of element ``e``: forces ``f``, tangents ``kt``
    (d f / d x) and ``cv`` (d f / d xdot) (6,); returns (potential energy, dissipated
    power)."""
    pot = 0.0
    dis = 0.0
    for j in range(NLAW):
        q = xv[j]
        k = cid[e, j]
        if k >= 0:
            fs, ks = curve_value(CX, CY, CD, cstart, k, q)
            pot += curve_integral(CX, CY, CD, cstart, k, 0.0, q)
        else:
            ks = kx[e, j]
            fs = ks * q
            pot += 0.5 * ks * q * q
        fd = cx[e, j] * xd[j]
        f[j] = fs + pre[e, j] + fd
        kt[j] = ks
        cv[j] = cx[e, j]
        pot += pre[e, j] * q
        dis += fd * xd[j]
    return pot, dis


@njit(cache=True, inline="always")
def _branches(e, xv, es, s0, t, baxis, bk, bc, nbr, f, kt, aux):
    """Maxwell branches of element ``e`` from the committed state ``es[s0:]`` (time, six
    deflections, branch deflections): forces added to ``f``, tangents to ``kt``, the new
    branch deflections into ``aux[e, NPUB + b]``; returns (potential energy, dissipated
    power)."""
    pot = 0.0
    dis = 0.0
    nb = nbr[e]
    if nb == 0:
        return pot, dis
    tn = es[s0]
    h = t - tn if math.isfinite(tn) else 0.0
    if h < 0.0:
        h = 0.0
    for b in range(nb):
        j = baxis[e, b]
        kb = bk[e, b]
        cb = bc[e, b]
        r = h * kb / cb
        E = math.exp(-r)
        phi = -math.expm1(-r) / r if r > 1e-12 else 1.0 - 0.5 * r
        s = phi * (xv[j] - es[s0 + 1 + j]) + E * es[s0 + 1 + NLAW + b]
        fb = kb * s
        f[j] += fb
        kt[j] += kb * phi
        aux[e, NPUB + b] = s
        pot += 0.5 * fb * s
        dis += fb * fb / cb
    return pot, dis


@njit(cache=True)
def _bushings(P, C, W, full):
    (pA, pB, RmA, RmB, d0, kx, cx, pre, cid, CX, CY, CD, cstart, baxis, bk, bc, nbr) = P
    L, B, Jv, S, V, rows, vl = W
    rq, _, _, Cd, K, _ = L
    f, kt, cv, xv, xd = rows[0], rows[1], rows[2], rows[3], rows[4]
    RAg, Mab, U, Rrel, Ti, T1, T2, Q, Z, N, Sk, D3, T3, T4 = (
        S[0], S[1], S[2], S[3], S[4], S[5], S[6], S[7], S[8], S[9], S[10], S[11], S[12], S[13])
    th, PA, PB, ra, sv, ua, fa, Fb, mu, om, v1, v2 = (
        V[0], V[1], V[2], V[3], V[4], V[5], V[6], V[7], V[8], V[9], V[10], V[11])
    x, R, _, _, _, es, _, t = sc.state(C)
    aux = C[sc.AUX]
    for e in range(sc.count(C)):
        nA, nB = sc.pair(C, e)
        Ra = R[nA]
        Rb = R[nB]
        A = RmA[e]
        Bm = RmB[e]
        pb = pB[e]
        # frames: marker A (global), node B in node A's frame, U = A Rrel, Rrel = R_A^T R_B'
        mm(Ra, A, RAg)
        mtm(Ra, Rb, Mab)
        mm(Mab, Bm, U)
        mtm(A, U, Rrel)
        _log_into(Rrel, th)
        t2 = th[0] * th[0] + th[1] * th[1] + th[2] * th[2]
        cc, ee = tangent_inv_coeffs(t2)
        set_skew(th, Sk)
        for i in range(3):
            for j in range(3):
                s2 = Sk[i, 0] * Sk[0, j] + Sk[i, 1] * Sk[1, j] + Sk[i, 2] * Sk[2, j]
                Ti[i, j] = (1.0 if i == j else 0.0) + 0.5 * Sk[i, j] + cc * s2
        # marker origins, the arm of marker B from node A (node A frame), deflections
        mv(Ra, pA[e], v1)
        mv(Rb, pb, v2)
        for i in range(3):
            PA[i] = x[nA, i] + v1[i]
            PB[i] = x[nB, i] + v2[i]
            v1[i] = PB[i] - x[nA, i]
            v2[i] = PB[i] - PA[i]
        mtv(Ra, v1, ra)
        mtv(RAg, v2, fa)  # (fa as scratch: R_A^T (p_B - p_A))
        for i in range(3):
            xv[i] = fa[i] - d0[e, i]
            xv[3 + i] = th[i]
        # B = d x / d q (6, 12): rows d (translation), theta (rotation)
        B[:, :] = 0.0
        set_skew(ra, Sk)
        mtm(A, Sk, T1)  # A^T ra~
        set_skew(pb, Sk)
        mm(Mab, Sk, T2)  # Mab pb~
        mtm(A, T2, T3)  # A^T Mab pb~
        for i in range(3):
            for j in range(3):
                B[i, j] = -RAg[j, i]
                B[i, 3 + j] = T1[i, j]
                B[i, 6 + j] = RAg[j, i]
                B[i, 9 + j] = -T3[i, j]
        _mmt(Ti, U, T1)  # Ti U^T
        _mmt(Ti, Bm, T2)  # Ti Bm^T
        for i in range(3):
            for j in range(3):
                B[3 + i, 3 + j] = -T1[i, j]
                B[3 + i, 9 + j] = T2[i, j]
        sc.velocities(C, e, 12, vl)
        for i in range(6):
            sv_ = 0.0
            for a in range(12):
                sv_ += B[i, a] * vl[a]
            xd[i] = sv_
        # laws
        pot, dis = _axis_laws(e, xv, xd, kx, cx, pre, cid, CX, CY, CD, cstart, f, kt, cv)
        p2, d2 = _branches(e, xv, es, sc.state_offset(C, e), t, baxis, bk, bc, nbr, f, kt, aux)
        pot += p2
        dis += d2
        for a in range(12):
            r_ = 0.0
            for i in range(6):
                r_ += B[i, a] * f[i]
            rq[a] = r_
        if full:
            _matrices(B, Jv, K, Cd, f, kt, cv, vl, Ra, A, Bm, Mab, U, Rrel, Ti, th, t2, cc, ee,
                      ra, pb, T1, T2, T3, T4, Q, Z, N, Sk, D3, sv, ua, fa, Fb, mu, om, v1, v2)
        sc.scatter(C, L, e, 2, full)
        sc.energy(C, e, 0.0, pot, 0.0, dis)
        for j in range(6):
            aux[e, j] = f[j]
            aux[e, COL_DEFL + j] = xv[j]
        aux[e, 12] = dis


@njit(cache=True)
def _matrices(B, Jv, K, Cd, f, kt, cv, vl, Ra, A, Bm, Mab, U, Rrel, Ti, th, t2, cc, ee, ra, pb,
              T1, T2, T3, T4, Q, Z, N, Sk, D3, sv, ua, fa, Fb, mu, om, v1, v2):
    """Stiffness ``K`` and damping ``Cd`` (12, 12) of one bushing:
    ``K = G(f) + B^T diag(kt) B + B^T diag(cv) dxdot/dq``, ``Cd = B^T diag(cv) B``, with
    ``G(f) = d(B^T f)/dq`` at fixed ``f`` (the geometric part); node rotations perturbed on
    the right. Matrices in node frames: ``Mab = Ra^T Rb``, ``U = Mab Bm``, ``Rrel = A^T U``;
    ``ra`` is marker B's origin from node A (node A frame)."""
    wA = vl[3:6]
    wB = vl[9:12]
    # --- dxdot/dq, translation rows: xdot_d = A^T (Ra^T u + ra x Omega_A),
    # u = xdot_B - xdot_A - Rb (pb x Omega_B)
    cross(pb, wB, sv)
    mv(Mab, sv, v1)
    for i in range(3):
        v2[i] = vl[6 + i] - vl[i]
    mtv(Ra, v2, ua)
    for i in range(3):
        ua[i] -= v1[i]
    Jv[:, :] = 0.0
    set_skew(wA, Sk)
    _mmt(Sk, Ra, T1)  # Omega_A~ Ra^T
    mtm(A, T1, T2)
    for i in range(3):
        for j in range(3):
            Jv[i, j] = T2[i, j]
            Jv[i, 6 + j] = -T2[i, j]
    set_skew(ra, T3)
    mm(Sk, T3, T1)  # Omega_A~ ra~
    set_skew(ua, T3)
    for i in range(3):
        for j in range(3):
            T1[i, j] = T3[i, j] - T1[i, j]
    mtm(A, T1, T2)
    for i in range(3):
        for j in range(3):
            Jv[i, 3 + j] = T2[i, j]
    set_skew(sv, T3)
    mm(Mab, T3, T1)  # Mab s~
    set_skew(pb, T3)
    mm(Mab, T3, T2)  # Mab pb~
    mm(Sk, T2, T3)
    for i in range(3):
        for j in range(3):
            T1[i, j] += T3[i, j]
    mtm(A, T1, T2)
    for i in range(3):
        for j in range(3):
            Jv[i, 9 + j] = T2[i, j]
    # rotation rows: thetadot = Ti omega, omega = Bm^T Omega_B - Rrel^T A^T Omega_A;
    # d thetadot = (DTi[omega] Ti - Ti (Rrel^T A^T Omega_A)~) dxi,
    # dxi = -U^T dphi_A + Bm^T dphi_B
    mtv(A, wA, v1)
    mtv(Rrel, v1, v2)
    mtv(Bm, wB, om)
    for i in range(3):
        om[i] -= v2[i]
    _d_tinv(th, t2, cc, ee, om, 1.0, D3)
    mm(D3, Ti, N)
    set_skew(v2, Sk)
    mm(Ti, Sk, T1)
    for i in range(3):
        for j in range(3):
            N[i, j] -= T1[i, j]
    _mmt(N, U, T1)
    _mmt(N, Bm, T2)
    for i in range(3):
        for j in range(3):
            Jv[3 + i, 3 + j] = -T1[i, j]
            Jv[3 + i, 9 + j] = T2[i, j]
    # --- material part: B^T diag(kt) B + B^T diag(cv) Jv; damping B^T diag(cv) B
    for a in range(12):
        for b in range(12):
            sk = 0.0
            sc_ = 0.0
            sj = 0.0
            for i in range(6):
                sk += B[i, a] * kt[i] * B[i, b]
                sc_ += B[i, a] * cv[i] * B[i, b]
                sj += B[i, a] * cv[i] * Jv[i, b]
            K[a, b] = sk + sj
            Cd[a, b] = sc_
    # --- geometric part, translation: rq = (-Ra fa, fa~ ra, Ra fa, pb~ Mab^T fa), fa = A f_d
    mv(A, f[0:3], fa)
    mtv(Mab, fa, Fb)
    set_skew(fa, Sk)
    mm(Ra, Sk, T1)  # Ra fa~
    _put(K, 0, 3, T1, 1.0)
    _put(K, 6, 3, T1, -1.0)
    _mmt(Sk, Ra, T1)  # fa~ Ra^T
    _put(K, 3, 0, T1, -1.0)
    _put(K, 3, 6, T1, 1.0)
    set_skew(ra, T3)
    mm(Sk, T3, T1)  # fa~ ra~
    _put(K, 3, 3, T1, 1.0)
    set_skew(pb, T3)
    mm(Mab, T3, T2)
    mm(Sk, T2, T1)  # fa~ Mab pb~
    _put(K, 3, 9, T1, -1.0)
    mtm(Mab, Sk, T2)  # Mab^T fa~
    mm(T3, T2, T1)  # pb~ Mab^T fa~
    _put(K, 9, 3, T1, -1.0)
    set_skew(Fb, T2)
    mm(T3, T2, T1)  # pb~ Fb~
    _put(K, 9, 9, T1, 1.0)
    # rotation: rq = (-U mu, Bm mu), mu = Ti^T m; with Q = Dmu Ti, Z = mu~ - Q:
    # d rq_A = U Z dxi, d rq_B = Bm Q dxi
    _tinv_apply(th, t2, cc, f[3:6], -1.0, mu)
    _d_tinv(th, t2, cc, ee, f[3:6], -1.0, D3)
    mm(D3, Ti, Q)
    set_skew(mu, Z)
    for i in range(3):
        for j in range(3):
            Z[i, j] -= Q[i, j]
    mm(U, Z, T1)  # U Z
    _mmt(T1, U, T2)
    _put(K, 3, 3, T2, -1.0)
    _mmt(T1, Bm, T2)
    _put(K, 3, 9, T2, 1.0)
    mm(Bm, Q, T1)  # Bm Q
    _mmt(T1, U, T2)
    _put(K, 9, 3, T2, -1.0)
    _mmt(T1, Bm, T2)
    _put(K, 9, 9, T2, 1.0)


@njit(cache=True, inline="always")
def _work(buf):
    """The work arrays of :func:`_bushings` as views of ``buf`` (:data:`WORK_SIZE`)."""
    o = _L
    B = carve(buf, o, (6, 12))
    Jv = carve(buf, o + 72, (6, 12))
    o += 144
    S = carve(buf, o, (NMAT, 3, 3))
    o += 9 * NMAT
    V = carve(buf, o, (NVEC, 3))
    o += 3 * NVEC
    rows = carve(buf, o, (5, 6))
    return (local_arrays_at(buf, 0, 12, 0), B, Jv, S, V, rows, carve(buf, o + 30, 12))


@njit(cache=True)
def bushing_kernel(
    pA, pB, RmA, RmB, d0, kx, cx, pre, cid, CX, CY, CD, cstart, baxis, bk, bc, nbr, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    buf = sc.work_buffer(work, WORK_SIZE)
    sc.run(_bushings,
           (pA, pB, RmA, RmB, d0, kx, cx, pre, cid, CX, CY, CD, cstart, baxis, bk, bc, nbr),
           (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
            r, rabs, data, eout, aux), _work(buf))


# --- the family -------------------------------------------------------------------------------


class BushingFamily(Family):
    """Registry entry of :class:`Bushing`."""

    name = "bushing"
    spec_types = (Bushing,)

    def build(self, specs, ctx) -> Group:
        pA, pB, RmA, RmB, lnodes = two_markers(specs, ctx, "a bushing")
        nel = len(specs)
        laws = [s.laws() for s in specs]
        nbm = max(len(lw[4]) for lw in laws)
        d0 = np.zeros((nel, 3))
        kx = np.zeros((nel, NLAW))
        cx = np.zeros((nel, NLAW))
        pre = np.zeros((nel, NLAW))
        cid = np.full((nel, NLAW), -1, np.int64)
        baxis = np.zeros((nel, max(nbm, 1)), np.int64)
        bk = np.ones((nel, max(nbm, 1)))
        bc = np.ones((nel, max(nbm, 1)))
        nbr = np.zeros(nel, np.int64)
        eoff = np.zeros(nel, np.int64)
        tables = []
        for e, (k, c, p, curves, branches) in enumerate(laws):
            nA, nB = lnodes[e]
            RA0 = ctx.R0[nA] @ RmA[e]
            RB0 = ctx.R0[nB] @ RmB[e]
            # B's frame corrected to A's at the start: rotations count from there
            RmB[e] = RmB[e] @ (RB0.T @ RA0)
            PA0 = ctx.x0[nA] + ctx.R0[nA] @ pA[e]
            PB0 = ctx.x0[nB] + ctx.R0[nB] @ pB[e]
            d0[e] = RA0.T @ (PB0 - PA0)
            kx[e], cx[e], pre[e] = k, c, p
            for j, xa, ya in curves:
                cid[e, j] = len(tables)
                tables.append((xa, ya))
            nbr[e] = len(branches)
            for b, (j, kb, cb) in enumerate(branches):
                baxis[e, b], bk[e, b], bc[e, b] = j, kb, cb
            if nbm:
                # committed state: time, the six deflections, the branch deflections
                eoff[e] = ctx.alloc_state([0.0] * (1 + NLAW + nbm))  # models start at t = 0
        CX, CY, CD, cstart = pack_curves(tables)
        params = (pA, pB, RmA, RmB, d0, kx, cx, pre, cid, CX, CY, CD, cstart, baxis, bk, bc,
                  nbr, np.zeros(WORK_SIZE))
        commit = (COMMIT_TIME, *range(COL_DEFL, COL_DEFL + NLAW),
                  *range(NPUB, NPUB + nbm)) if nbm else ()
        return make_group(
            self.name, specs, bushing_kernel, params, lnodes, node_dofs(ctx, lnodes), OUTPUTS,
            eoff=eoff, nstate=len(commit), commit_cols=commit, naux=NPUB + nbm,
            dissipative=True,
        )


register(BushingFamily())
