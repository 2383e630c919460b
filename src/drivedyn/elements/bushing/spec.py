"""The bushing's parameters: :class:`Bushing` and the records of its curves and Maxwell
branches, checked and converted to the arrays of the six axes (x, y, z of translation, then
of rotation) that the kernel takes."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields
from typing import Any, ClassVar

import numpy as np

from drivedyn.elements.framework.building import what_of
from drivedyn.elements.framework.checks import check_number, unit_of
from drivedyn.elements.framework.curves import check_table, curve_value, pack_curves
from drivedyn.elements.framework.registry import TwoMarkerSpec
from drivedyn.errors import ModelError

AXES = ("x", "y", "z")


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
                keys = ", ".join(f.name for f in fields(cls))
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

    #: the bushing's shape: radius and length as fractions of the mechanism's size
    VISUAL_SIZE: ClassVar[tuple[float, float]] = (0.006, 0.012)

    def visuals(self) -> tuple:
        """A small rubber cylinder on the bushing frame (marker A; its axis the frame's z),
        sized to the mechanism (:attr:`VISUAL_SIZE`)."""
        from drivedyn.elements.framework.visuals import cylinder

        r, length = self.VISUAL_SIZE
        return (cylinder(self.marker_a, r, length, role="bushing", label=self.name,
                         relative=True),)

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
