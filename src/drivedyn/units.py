"""Quantities with units in model files: ``"3 mm"``, ``"1500 rpm"``, ``"2.5 kg m^2"``.

A model file may give any physical value either as a plain number (SI) or as a string
``"<number> <unit>"``; it is converted to SI and its dimension is checked against what the
field expects. Units are products of symbols with optional exponents (``^2``, ``^-1``, or
decimal ones such as ``^1.5`` for the stiffness of a Hertz contact, N/m^1.5), separated by
spaces or ``*``, with at most one ``/`` (everything after it is in the denominator):
``"N m s/rad"``, ``"kg*m^2"``, ``"m/s^2"``, ``"1/s"`` (``1`` stands for no unit).

Dimensions are exponent vectors over (m, kg, s, rad), exact rationals (ints where whole).
Angles count as a dimension so that a speed in rpm cannot be given where a length is expected.

An element parameter may declare alternative units, ``"N/m or N m/rad"``
(:func:`declared_dims`): one number used in either dimension (the scaling of constraint rows
that constrain positions and rotations alike).
"""

from __future__ import annotations

import math
import re
from fractions import Fraction

Exponent = int | Fraction  # an exact exponent: 1, -2, Fraction(3, 2)
Dim = tuple[Exponent, Exponent, Exponent, Exponent]  # exponents of m, kg, s, rad

DIMENSIONLESS: Dim = (0, 0, 0, 0)
LENGTH: Dim = (1, 0, 0, 0)
MASS: Dim = (0, 1, 0, 0)
TIME: Dim = (0, 0, 1, 0)
ANGLE: Dim = (0, 0, 0, 1)
INERTIA: Dim = (2, 1, 0, 0)
VELOCITY: Dim = (1, 0, -1, 0)
ACCELERATION: Dim = (1, 0, -2, 0)
ANGULAR_VELOCITY: Dim = (0, 0, -1, 1)
FORCE: Dim = (1, 1, -2, 0)
TORQUE: Dim = (2, 1, -2, 0)
STIFFNESS: Dim = (0, 1, -2, 0)  # N/m
DAMPING: Dim = (0, 1, -1, 0)  # N s/m
TORSIONAL_STIFFNESS: Dim = (2, 1, -2, -1)  # N m/rad
TORSIONAL_DAMPING: Dim = (2, 1, -1, -1)  # N m s/rad
PRESSURE: Dim = (-1, 1, -2, 0)  # Pa (moduli, stresses)
DENSITY: Dim = (-3, 1, 0, 0)  # kg/m^3
MASS_PER_LENGTH: Dim = (-1, 1, 0, 0)  # kg/m
MASS_LENGTH: Dim = (1, 1, 0, 0)  # kg m (rotary inertia per length)
BENDING_STIFFNESS: Dim = (3, 1, -2, 0)  # N m^2 (EI, GJ)
VOLUME: Dim = (3, 0, 0, 0)  # m^3 (section moduli)
VISCOSITY: Dim = (-1, 1, -1, 0)  # Pa s (dynamic viscosity of oil films)
POWER: Dim = (2, 1, -3, 0)  # W
PITCH: Dim = (1, 0, 0, -1)  # m/rad... a screw pitch is given per revolution, see below

_NAMES = {
    DIMENSIONLESS: "1", LENGTH: "m", MASS: "kg", TIME: "s", ANGLE: "rad", INERTIA: "kg m^2",
    VELOCITY: "m/s", ACCELERATION: "m/s^2", ANGULAR_VELOCITY: "rad/s", FORCE: "N",
    TORQUE: "N m", STIFFNESS: "N/m", DAMPING: "N s/m", TORSIONAL_STIFFNESS: "N m/rad",
    TORSIONAL_DAMPING: "N m s/rad", PRESSURE: "Pa", DENSITY: "kg/m^3",
    MASS_PER_LENGTH: "kg/m", MASS_LENGTH: "kg m", BENDING_STIFFNESS: "N m^2", VOLUME: "m^3",
    VISCOSITY: "Pa s", POWER: "W",
}

# symbol -> (factor to SI, dimension)
UNITS: dict[str, tuple[float, Dim]] = {
    "m": (1.0, LENGTH), "mm": (1e-3, LENGTH), "cm": (1e-2, LENGTH), "km": (1e3, LENGTH),
    "um": (1e-6, LENGTH), "in": (0.0254, LENGTH),
    "kg": (1.0, MASS), "g": (1e-3, MASS), "t": (1e3, MASS),
    "s": (1.0, TIME), "ms": (1e-3, TIME), "min": (60.0, TIME), "h": (3600.0, TIME),
    "rad": (1.0, ANGLE), "deg": (math.pi / 180.0, ANGLE), "rev": (2 * math.pi, ANGLE),
    "rpm": (2 * math.pi / 60.0, ANGULAR_VELOCITY),
    "N": (1.0, FORCE), "kN": (1e3, FORCE), "Nm": (1.0, TORQUE),
    "Pa": (1.0, (-1, 1, -2, 0)), "kPa": (1e3, (-1, 1, -2, 0)), "MPa": (1e6, (-1, 1, -2, 0)),
    "GPa": (1e9, (-1, 1, -2, 0)), "J": (1.0, (2, 1, -2, 0)), "W": (1.0, (2, 1, -3, 0)),
    "Hz": (1.0, (0, 0, -1, 0)),
}

# Largest magnitude accepted for a model input of each dimension [SI]. Far beyond any
# driveline, bench or vehicle (a loaded truck is 4e4 kg, a test track 10 km, a turbine 1e5 rpm)
# yet small enough to catch a unit slip (mm read as m twice, g as kg...) that would otherwise
# run to a meaningless end. Other dimensions: GENERIC_MAX.
PLAUSIBLE_MAX: dict[Dim, float] = {
    LENGTH: 1e5, MASS: 1e6, INERTIA: 1e6, TIME: 1e6, VELOCITY: 1e3, ACCELERATION: 1e6,
    ANGULAR_VELOCITY: 1e5, ANGLE: 1e9, FORCE: 1e9, TORQUE: 1e9,
}
GENERIC_MAX = 1e15
# Smallest magnitude of a quantity that must be > 0: a length (a module, a radius, a
# clearance, a roughness) of a nanometre, below any part or surface of a driveline; a time (a
# ramp, a step, an output interval) of a picosecond, below any step the solver takes; a
# modulus of 1 Pa and a density of 1 kg/m^3, below any material. Smaller values are a unit
# slip, and what is computed from them underflows or overflows (squares of 1e-300 are 0, a ramp
# of 1e-300 s ends where it starts, a washer of modulus 1e-300 Pa sinks 1e300 m, a mesh of
# density 1e-300 kg/m^3 has no modes).
PLAUSIBLE_MIN_POSITIVE: dict[Dim, float] = {LENGTH: 1e-9, TIME: 1e-12, PRESSURE: 1.0,
                                            DENSITY: 1.0}


def unit_label(*dims: Dim) -> str:
    """SI unit(s) of a quantity as messages print them: ``"N/m"``, ``"N/m or N m/rad"`` for
    alternatives; ``""`` for a dimensionless quantity (no ``"1"`` in messages)."""
    if all(d == DIMENSIONLESS for d in dims):
        return ""
    return " or ".join(dim_name(d) for d in dims)


def _bracket(dims: tuple[Dim, ...]) -> str:
    """`` [N/m]`` after a message phrase; nothing for a dimensionless quantity."""
    label = unit_label(*dims)
    return f" [{label}]" if label else ""


def check_plausible(x: float, dim: Dim, *alternatives: Dim) -> None:
    """Raise :class:`UnitError` for a non-finite value or one whose magnitude exceeds
    :data:`PLAUSIBLE_MAX` for its dimension (``GENERIC_MAX`` for others); ``alternatives``:
    further dimensions the same number may stand for (the largest limit applies). The
    message gives the value and the limit in the SI unit."""
    dims = (dim, *alternatives)
    if not math.isfinite(x):
        raise UnitError(f"must be finite{_bracket(dims)}, got {x!r}")
    top = max(PLAUSIBLE_MAX.get(d, GENERIC_MAX) for d in dims)
    if abs(x) > top:
        label = unit_label(*dims)
        if not label:
            raise UnitError(f"{x:g} is implausibly large for a dimensionless parameter "
                            f"(|value| <= {top:g}): a typing mistake?")
        raise UnitError(f"{x:g} {label} is implausibly large (|value| <= {top:g} {label}): "
                        f"a unit mistake?")


NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"  # a decimal number (regex)
_QUANTITY = re.compile(rf"^\s*({NUMBER})\s*(.*?)\s*$")


def split_quantity(text: str) -> tuple[float, str] | None:
    """``"30 deg"`` -> (30.0, ``"deg"``); ``"2"`` -> (2.0, ``""``); None if ``text`` does
    not start with a number. The unit is not parsed."""
    m = _QUANTITY.match(text)
    return (float(m.group(1)), m.group(2)) if m else None


class UnitError(ValueError):
    """A unit that cannot be parsed or has the wrong dimension."""


def _power(sym: str, e: Exponent) -> str:
    """``m``, ``m^2``, ``m^1.5`` (a decimal exponent, as :func:`parse_unit` reads it)."""
    if e == 1:
        return sym
    return f"{sym}^{e}" if isinstance(e, int) else f"{sym}^{float(e)!r}"


def _fraction_text(num: list[str], den: list[str]) -> str:
    top = " ".join(num) or "1"
    return f"{top}/{' '.join(den)}" if den else top


def dim_name(dim: Dim) -> str:
    """Readable SI unit of a dimension: a named one (``"N m/rad"``, ``"Pa s"``), else newtons
    times powers of m, s and rad for anything with kg^1 (``"N/m^1.5"``, ``"N s/m^1.5"``), else
    powers of the base units (``"1/s"``, ``"m^3/s"``)."""
    if dim in _NAMES:
        return _NAMES[dim]
    syms = ("m", "kg", "s", "rad")
    rest = list(dim)
    num, den = [], []
    if dim[1] == 1:  # a force per or times something: N and the remaining powers
        rest = [a - b for a, b in zip(dim, FORCE, strict=True)]
        num.append("N")
    for sym, e in zip(syms, rest, strict=True):
        if e > 0:
            num.append(_power(sym, e))
        elif e < 0:
            den.append(_power(sym, -e))
    return _fraction_text(num, den)


def _exponent(text: str | None) -> Exponent:
    """An exponent as written (``"2"``, ``"-1"``, ``"1.5"``), exact; 1 if absent."""
    if text is None:
        return 1
    e = Fraction(text)
    return int(e) if e.denominator == 1 else e


_TOKEN = re.compile(r"([A-Za-z]+|1)(?:\^(-?\d+(?:\.\d+)?))?")


def parse_unit(text: str) -> tuple[float, Dim]:
    """Factor to SI and dimension of a unit expression (``"N m/rad"``, ``"kg*m^2"``,
    ``"N/mm^1.5"``, ``"1/s"``)."""
    text = text.strip()
    if not text:
        return 1.0, DIMENSIONLESS
    if text.count("/") > 1:
        raise UnitError(f"unit {text!r}: use at most one '/'")
    num, _, den = text.partition("/")
    factor = 1.0
    dim: list[Exponent] = [0, 0, 0, 0]
    for part, sign in ((num, 1), (den, -1)):
        for tok in re.split(r"[\s*]+", part.strip()):
            if not tok:
                continue
            m = _TOKEN.fullmatch(tok)
            if m is None or (m.group(1) != "1" and m.group(1) not in UNITS):
                sym = m.group(1) if m else tok
                raise UnitError(f"unknown unit {sym!r} in {text!r} (known: "
                                f"{', '.join(sorted(UNITS))})")
            if m.group(1) == "1":  # a plain number: "1/s"
                continue
            f, d = UNITS[m.group(1)]
            e = sign * _exponent(m.group(2))
            try:
                factor *= f ** float(e) if isinstance(e, Fraction) else f**e
            except (OverflowError, ZeroDivisionError):
                raise UnitError(f"unit {text!r}: exponent out of range") from None
            dim = [a + e * b for a, b in zip(dim, d, strict=True)]
    out = tuple(int(x) if Fraction(x).denominator == 1 else Fraction(x) for x in dim)
    return factor, out  # type: ignore[return-value]


def declared_dims(text: str) -> tuple[Dim, ...]:
    """Dimensions of a parameter's declared SI unit: one (``"N/m"``), or the alternatives of
    ``"N/m or N m/rad"``."""
    return tuple(parse_unit(alt)[1] for alt in text.split(" or "))


def to_si(value: object, expected: Dim, *alternatives: Dim) -> float:
    """A number (taken as SI) or a ``"<number> <unit>"`` string, converted to SI; the unit
    must have the dimension ``expected`` (or one of ``alternatives``).

    Raises :class:`UnitError` for an unknown unit or a unit of another dimension.
    """
    dims = (expected, *alternatives)
    label = unit_label(*dims)
    if isinstance(value, bool):
        raise UnitError(f"expected a number{_bracket(dims)}, got {value!r}")
    if isinstance(value, (int, float)):
        return float(value)
    if not isinstance(value, str):
        example = f" or a string like '1.5 {dim_name(expected)}'" if label else ""
        raise UnitError(f"expected a number{_bracket(dims)}{example}, got {value!r}")
    m = _QUANTITY.match(value)
    if m is None:
        raise UnitError(f"expected '<number> <unit>'{_bracket(dims)}, got {value!r}")
    factor, dim = parse_unit(m.group(2))
    if dim not in dims:
        given = f"is in {unit_label(dim)}" if unit_label(dim) else "has no unit"
        raise UnitError(f"{value!r} {given}, expected {label or 'a plain number'}")
    return float(m.group(1)) * factor
