"""Display units of plotted quantities: SI prefixes chosen by magnitude, angles in degrees
or turns, angular speeds in rpm or rad/s.

Every function returns ``(scale, display unit)``: the plotted values are ``scale * values``
(values in the SI unit of the results file). The rules, as ``docs/plots.md`` states them:

* :func:`si_scale`: the prefix (n, µ, m, k, M, G) goes on the first symbol of the unit
  (``"mN m"``, not ``"N mm"``) and is the largest that keeps the largest magnitude at or above
  1 (``1e-5 m`` -> ``µm``, ``3e-3 N m`` -> ``mN m``, ``2e3 N`` -> ``kN``, ``4e7 Pa`` ->
  ``MPa``). ``kg``, ``rad``, ``deg``, ``rpm`` and dimensionless quantities keep their unit.
* :func:`angle_scale`: angles [rad] in degrees up to :data:`TURNS_IN_DEG` turns, in turns
  (``rev``) beyond.
* :func:`speed_scale`: angular speeds [rad/s] of rotating parts in rpm, others in rad/s.
"""

from __future__ import annotations

import math
import re

import numpy as np

from drivedyn.units import UNITS

#: SI prefixes offered, largest first (factor, symbol)
PREFIXES: tuple[tuple[float, str], ...] = (
    (1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n"))
#: first symbols that take no prefix (already prefixed, or not SI-prefixed by custom)
UNPREFIXED = frozenset({"kg", "rad", "deg", "rev", "rpm", "1", "-", "%", "min", "h"})
#: angles up to this many turns are shown in degrees, larger ones in turns
TURNS_IN_DEG = 10.0
RPM = UNITS["rpm"][0]  # rad/s per rpm
_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
_TOKEN = re.compile(r"^([A-Za-zµ%]+)(?:\^(-?\d+))?$")


def peak(values: object) -> float:
    """Largest finite magnitude of ``values`` (0 for empty, all-NaN or all-zero data)."""
    a = np.abs(np.asarray(values, dtype=float))
    a = a[np.isfinite(a)]
    return float(a.max()) if a.size else 0.0


def pretty_unit(unit: str) -> str:
    """A unit as figures show it: exponents as superscripts (``"kg m^2/s"`` ->
    ``"kg m²/s"``), ``"1"`` (dimensionless) as ``"-"``."""
    unit = unit.strip()
    if unit in ("", "1"):
        return "-"
    return re.sub(r"\^(-?\d+)", lambda m: m.group(1).translate(_SUPERSCRIPT), unit)


def _first_symbol(unit: str) -> tuple[str, int, str] | None:
    """(first symbol, its exponent, the rest of the unit string) of the numerator, or None
    when the unit has no numerator symbol (``"1/s"``)."""
    m = re.match(r"\s*([^\s/*]+)(.*)$", unit, re.S)
    if m is None:
        return None
    tok = _TOKEN.match(m.group(1))
    if tok is None:
        return None
    return tok.group(1), int(tok.group(2) or 1), m.group(2)


def si_scale(values: object, unit: str) -> tuple[float, str]:
    """(scale, display unit) for ``values`` [``unit``, SI]: the SI prefix on the first symbol
    that brings the largest magnitude into [1, 1000) (see the module doc; with an exponent
    ``e`` on that symbol, into [1, 1000**e)). Empty, all-NaN and all-zero data: scale 1 and
    the bare unit."""
    first = _first_symbol(unit)
    if first is None or first[0] in UNPREFIXED or first[1] <= 0:
        return 1.0, pretty_unit(unit)
    sym, exp, rest = first
    top = peak(values)
    if top == 0.0 or not math.isfinite(top):
        return 1.0, pretty_unit(unit)
    factor, prefix = PREFIXES[-1]
    for f, p in PREFIXES:
        if top / f**exp >= 1.0 - 1e-12:
            factor, prefix = f, p
            break
    return 1.0 / factor**exp, pretty_unit(f"{prefix}{sym}{'' if exp == 1 else f'^{exp}'}{rest}")


def angle_scale(values: object) -> tuple[float, str]:
    """(scale, unit) of angles [rad]: degrees up to :data:`TURNS_IN_DEG` turns, turns
    (``"rev"``) beyond."""
    if peak(values) <= TURNS_IN_DEG * 2 * math.pi:
        return 180.0 / math.pi, "deg"
    return 1.0 / (2 * math.pi), "rev"


def rotating(omega: object, t: object) -> bool:
    """Is this angular speed [rad/s] (samples at times ``t`` [s]) that of a rotating part
    rather than an oscillating one: it keeps one sign while above 1 rad/s, or its net
    rotation over the run reaches one turn."""
    w = np.asarray(omega, dtype=float)
    tt = np.asarray(t, dtype=float)
    ok = np.isfinite(w)
    if not ok.any() or peak(w) < 1.0:
        return False
    fast = w[ok & (np.abs(w) >= 1.0)]
    if fast.min() * fast.max() > 0:
        return True
    return len(tt) > 1 and abs(float(np.trapezoid(np.where(ok, w, 0.0), tt))) >= 2 * math.pi


def speed_scale(omega: object, as_rpm: bool) -> tuple[float, str]:
    """(scale, unit) of angular speeds [rad/s]: ``"rpm"`` for rotating parts, else
    ``"rad/s"``."""
    return (1.0 / RPM, "rpm") if as_rpm else (1.0, "rad/s")


def display_scale(values: object, unit: str, prefer: str | None = None) -> tuple[float, str]:
    """(scale, display unit) of ``values`` [``unit``] by the rules above: ``"rad"`` through
    :func:`angle_scale`, ``"rad/s"`` in rpm when ``prefer == "rpm"``, everything else through
    :func:`si_scale`. ``prefer`` may also name any unit of :mod:`drivedyn.units` of the same
    dimension (``"deg"``, ``"mm"``) or ``"%"`` for a dimensionless quantity."""
    unit = unit.strip()
    if prefer == "%" and unit in ("", "1"):
        return 100.0, "%"
    if prefer is not None and prefer != "%":
        from drivedyn.units import parse_unit

        f_pref, d_pref = parse_unit(prefer)
        f_unit, d_unit = parse_unit(unit)
        if d_pref != d_unit:
            raise ValueError(f"display unit {prefer!r} does not fit quantities in {unit!r}")
        return f_unit / f_pref, pretty_unit(prefer)
    if unit == "rad":
        return angle_scale(values)
    return si_scale(values, unit)
