"""Reader of tyre property files (``.tir``, the TNO/Adams MF-Tyre format).

A file is a sequence of ``[SECTION]`` headers and ``KEY = value`` lines; ``$`` starts a comment
(outside quotes), lines starting with ``!`` are comments, values are numbers (a Fortran ``D``
exponent is accepted) or quoted strings. Sections that hold tables (``[SHAPE]``,
``[LOADED_RADIUS]`` ...) or that this reader does not use are skipped; the sections of the
Magic Formula are read strictly: a line that is not ``KEY = value``, a value that is not a
number, a key given twice or a key the formula needs but the file lacks is an error naming the
file, the section and the key. Keys the file omits take MF-Tyre's defaults (scaling factors 1,
coefficients 0, :data:`~drivedyn.tyres.magic_formula.DEFAULTS`).

Values are then checked against what the formula can evaluate: lengths, loads, stiffnesses,
the peak and shape factors > 0, scaling factors >= 0, the divisors PKY2 and PTY2 not 0 (PTY1-2
required where the lateral relaxation length comes from them), and the whole formula finite
over a grid of operating points (:data:`GRID`): a coefficient that overflows it
(``PKX3 = 1e30``) is named with the operating point where it does. ``[MODEL] TYRESIDE`` must
be ``LEFT``, ``RIGHT`` or ``SYMMETRIC`` (:func:`file_side`); ``read_tir(path, side=...)``
mirrors a file measured on the other side of the vehicle.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from drivedyn.errors import ModelError
from drivedyn.tyres.magic_formula import DEFAULTS, GROUPS, INDEX, NOUT, OUT_NAMES, evaluate, pack

#: section of each key the formula reads
SECTION_OF: dict[str, str] = {
    "FITTYP": "MODEL", "LONGVL": "MODEL", "VXLOW": "MODEL",
    "FNOMIN": "VERTICAL", "VERTICAL_STIFFNESS": "VERTICAL", "VERTICAL_DAMPING": "VERTICAL",
    "BREFF": "VERTICAL", "DREFF": "VERTICAL", "FREFF": "VERTICAL",
    "UNLOADED_RADIUS": "DIMENSION", "WIDTH": "DIMENSION",
    "NOMPRES": "OPERATING_CONDITIONS", "INFLPRES": "OPERATING_CONDITIONS",
    "LONGITUDINAL_STIFFNESS": "STRUCTURAL", "LATERAL_STIFFNESS": "STRUCTURAL",
    **{k: "SCALING_COEFFICIENTS" for k in GROUPS["scaling"]},
    **{k: "LONGITUDINAL_COEFFICIENTS" for k in GROUPS["longitudinal"]},
    **{k: "LATERAL_COEFFICIENTS" for k in GROUPS["lateral"]},
    **{k: "ALIGNING_COEFFICIENTS" for k in GROUPS["aligning"]},
    **{k: "ROLLING_COEFFICIENTS" for k in GROUPS["rolling"]},
}
#: keys without which the formula has no meaning
REQUIRED = ("FITTYP", "UNLOADED_RADIUS", "FNOMIN", "VERTICAL_STIFFNESS", "PCX1", "PDX1",
            "PKX1", "PCY1", "PDY1", "PKY1", "PKY2", "QBZ1", "QCZ1", "QDZ1")
#: keys that must be > 0
POSITIVE = ("UNLOADED_RADIUS", "FNOMIN", "VERTICAL_STIFFNESS", "PCX1", "PDX1", "PCY1", "PDY1",
            "LONGVL", "LFZO")
#: keys the formula divides by (a file may not set them to 0)
NONZERO = ("PKY2",)
#: FITTYP values and the version they stand for
VERSIONS = {6: "5.2", 21: "5.2", 52: "5.2", 61: "6.1", 62: "6.2"}
#: values of [MODEL] TYRESIDE (the side of the vehicle the file's tyre was measured on)
SIDES = ("LEFT", "RIGHT", "SYMMETRIC")
#: usual magnitude of the dimensional keys (the coefficients' is 1), to find the key that
#: makes the formula overflow
SCALE = {"LONGVL": 20.0, "VXLOW": 1.0, "FNOMIN": 4e3,
         "UNLOADED_RADIUS": 0.3, "WIDTH": 0.2, "VERTICAL_STIFFNESS": 2e5,
         "VERTICAL_DAMPING": 500.0, "NOMPRES": 2e5, "INFLPRES": 2e5,
         "LONGITUDINAL_STIFFNESS": 3e5, "LATERAL_STIFFNESS": 1.5e5}
#: operating points the formula must be finite at (``coefficients`` refuses a file that is
#: not): vertical load [FNOMIN], longitudinal slip [-], slip angle [rad], camber [rad], forward
#: speed [m/s], road friction factor [-]
GRID: dict[str, tuple[float, ...]] = {
    "fz": (0.05, 0.5, 1.0, 2.5, 4.0),
    "kappa": (-1.0, -0.2, 0.0, 0.03, 0.5, 1.0),
    "alpha": (-0.6, 0.0, 0.1, 0.6),
    "gamma": (-0.1, 0.0, 0.08, 0.1),
    "vx": (-30.0, -5.0, 0.0, 0.3, 20.0),
    "mu": (0.0, 0.002, 1.0),
}
#: sections read strictly (the others may hold tables or vendor data)
STRICT = {"UNITS", "MODEL", "DIMENSION", "OPERATING_CONDITIONS", "VERTICAL", "STRUCTURAL",
          "SCALING_COEFFICIENTS", "LONGITUDINAL_COEFFICIENTS", "LATERAL_COEFFICIENTS",
          "ALIGNING_COEFFICIENTS", "ROLLING_COEFFICIENTS", "OVERTURNING_COEFFICIENTS",
          "TURNSLIP_COEFFICIENTS"}

_SECTION = re.compile(r"^\[\s*([A-Za-z0-9_]+)\s*\]\s*$")
_ASSIGN = re.compile(r"^([A-Za-z][A-Za-z0-9_]*)\s*=\s*(.*?)\s*$")


@dataclass
class TirFile:
    """The parsed content of a property file.

    Attributes:
        path: file read.
        sections: ``{SECTION: {KEY: value}}`` (numbers as float, strings without quotes).
        lines: ``{(SECTION, KEY): line number}`` for messages.
    """

    path: str
    sections: dict[str, dict[str, float | str]] = field(default_factory=dict)
    lines: dict[tuple[str, str], int] = field(default_factory=dict)

    def where(self, section: str, key: str) -> str:
        """``"tyre file file.tir [SECTION] KEY (line N)"`` for messages (every message of
        the reader starts with ``tyre file``: a caller prefixes the key that named the file,
        ``wheels.`` + ``tyre file ...``)."""
        n = self.lines.get((section, key))
        return f"tyre file {self.path} [{section}] {key}" + (f" (line {n})" if n else "")


def _strip_comment(line: str) -> str:
    out, quote = [], False
    for ch in line:
        if ch == "'" or ch == '"':
            quote = not quote
        elif ch == "$" and not quote:
            break
        out.append(ch)
    return "".join(out).strip()


def _value(text: str) -> float | str:
    t = text.strip()
    if len(t) >= 2 and t[0] in "'\"" and t[-1] == t[0]:
        return t[1:-1]
    return float(t.replace("D", "E").replace("d", "e"))


def parse_tir(path: str | Path) -> TirFile:
    """Parse a ``.tir`` file (no evaluation of its content); :class:`ModelError` naming the
    line for syntax errors."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise ModelError(f"tyre file {str(p)!r}: cannot be read ({exc.strerror})") from None
    tf = TirFile(str(p))
    section = ""
    for n, raw in enumerate(text.splitlines(), start=1):
        if raw.lstrip().startswith("!"):
            continue
        line = _strip_comment(raw)
        if not line:
            continue
        m = _SECTION.match(line)
        if m:
            section = m.group(1).upper()
            tf.sections.setdefault(section, {})
            continue
        if section not in STRICT:
            continue  # tables and vendor sections
        m = _ASSIGN.match(line)
        if not m:
            raise ModelError(f"tyre file {tf.path} [{section}] line {n}: expected "
                             f"'KEY = value', got {raw.strip()!r}")
        key = m.group(1).upper()
        if key in tf.sections[section]:
            raise ModelError(f"{tf.where(section, key)}: given twice (again at line {n})")
        try:
            val = _value(m.group(2))
        except ValueError:
            raise ModelError(f"tyre file {tf.path} [{section}] {key} (line {n}): expected a "
                             f"number, got {m.group(2)!r}") from None
        if isinstance(val, float) and not math.isfinite(val):
            raise ModelError(f"tyre file {tf.path} [{section}] {key} (line {n}): expected a "
                             f"finite number, got {m.group(2)!r}")
        tf.sections[section][key] = val
        tf.lines[(section, key)] = n
    return tf


#: accepted spellings of the SI units in ``[UNITS]`` (the formula reads SI numbers)
SI_UNITS = {"LENGTH": ("meter", "metre", "m"), "FORCE": ("newton", "n"),
            "ANGLE": ("radians", "radian", "rad"), "MASS": ("kg", "kilogram"),
            "TIME": ("second", "sec", "s"), "PRESSURE": ("pascal", "pa")}


def coefficients(tf: TirFile) -> tuple[np.ndarray, int]:
    """The coefficient array ``P`` and FITTYP of a parsed file; refuses a missing required
    key, an unsupported FITTYP, units other than SI and impossible values, naming section
    and key."""
    for key, unit in tf.sections.get("UNITS", {}).items():
        ok = SI_UNITS.get(key)
        if ok is not None and str(unit).strip().lower() not in ok:
            raise ModelError(f"{tf.where('UNITS', key)}: expected SI ({ok[0]}), got "
                             f"{unit!r}; convert the file to SI units")
    values: dict[str, float] = {}
    for key, section in SECTION_OF.items():
        sec = tf.sections.get(section, {})
        if key not in sec:
            continue
        v = sec[key]
        if isinstance(v, str):
            raise ModelError(f"{tf.where(section, key)}: expected a number, got {v!r}")
        values[key] = v
    for key in REQUIRED:
        if key not in values:
            section = SECTION_OF[key]
            have = "" if section in tf.sections else f" (the file has no [{section}] section)"
            raise ModelError(f"tyre file {tf.path} [{section}] {key}: missing; the Magic "
                             f"Formula needs it{have}")
    fittyp = int(values["FITTYP"])
    if fittyp not in VERSIONS or fittyp != values["FITTYP"]:
        raise ModelError(f"{tf.where('MODEL', 'FITTYP')}: expected one of "
                         f"{', '.join(map(str, VERSIONS))} (MF 5.2, 6.1, 6.2), got "
                         f"{values['FITTYP']!r}")
    side = tf.sections.get("MODEL", {}).get("TYRESIDE")
    if side is not None and (not isinstance(side, str) or side.strip().upper() not in SIDES):
        raise ModelError(f"{tf.where('MODEL', 'TYRESIDE')}: expected "
                         f"{', '.join(repr(x) for x in SIDES)}, got {side!r}")
    _check_relaxation_keys(tf, values, fittyp)
    P = pack(values)
    for key in POSITIVE:
        if P[INDEX[key]] <= 0.0:
            raise ModelError(f"{tf.where(SECTION_OF[key], key)}: must be > 0, got "
                             f"{float(P[INDEX[key]])!r}")
    if P[INDEX["VERTICAL_DAMPING"]] < 0.0:
        raise ModelError(f"{tf.where('VERTICAL', 'VERTICAL_DAMPING')}: must be >= 0, got "
                         f"{float(P[INDEX['VERTICAL_DAMPING']])!r}")
    for key in GROUPS["scaling"]:
        if P[INDEX[key]] < 0.0:
            raise ModelError(f"{tf.where('SCALING_COEFFICIENTS', key)}: must be >= 0 (a "
                             f"scaling factor), got {float(P[INDEX[key]])!r}")
    for key in NONZERO:
        if P[INDEX[key]] == 0.0:
            raise ModelError(f"{tf.where(SECTION_OF[key], key)}: must not be 0 (the formula "
                             "divides by it)")
    _check_grid(tf, values, P)
    return P, fittyp


def _check_relaxation_keys(tf: TirFile, values: dict[str, float], fittyp: int) -> None:
    """PTY1 and PTY2 (PTY2 not 0) where the lateral relaxation length comes from them: MF
    5.2, and MF 6.x without the carcass's ``[STRUCTURAL] LATERAL_STIFFNESS``."""
    if fittyp >= 60 and values.get("LATERAL_STIFFNESS", 0.0) > 0.0:
        return
    why = ("the lateral relaxation length needs it" if fittyp < 60 else
           "the lateral relaxation length needs it without [STRUCTURAL] LATERAL_STIFFNESS")
    for key in ("PTY1", "PTY2"):
        if key not in values:
            raise ModelError(f"tyre file {tf.path} [LATERAL_COEFFICIENTS] {key}: missing; "
                             f"{why}")
    if values["PTY2"] == 0.0:
        raise ModelError(f"{tf.where('LATERAL_COEFFICIENTS', 'PTY2')}: must not be 0 ({why}, "
                         "and divides by it)")


def _first_failure(P: np.ndarray, points: list[tuple[float, ...]] | None = None
                   ) -> tuple[tuple[float, ...], str] | None:
    """The first operating point of ``points`` (default the whole :data:`GRID`) where the
    formula raises or gives a non-finite output, with what went wrong; None if none."""
    fz0 = P[INDEX["FNOMIN"]] * P[INDEX["LFZO"]]
    if points is None:
        points = [(f * fz0, *rest) for f in GRID["fz"] for rest in itertools.product(
            GRID["kappa"], GRID["alpha"], GRID["gamma"], GRID["vx"], GRID["mu"])]
    out = np.zeros((len(points), NOUT))
    for n, (fz, kappa, alpha, gamma, vx, mu) in enumerate(points):
        try:
            evaluate(P, fz, kappa, alpha, gamma, vx, 0.0, mu, 1.0, out[n])
        except (ArithmeticError, ValueError) as exc:  # numba's float division by zero
            return points[n], f"raises {type(exc).__name__} ({exc})"
    finite = np.isfinite(out)
    if finite.all():
        return None
    n, i = (int(j[0]) for j in np.nonzero(~finite))
    return points[n], f"gives {OUT_NAMES[i]} = {float(out[n, i])!r}"


def _check_grid(tf: TirFile, values: dict[str, float], P: np.ndarray) -> None:
    """Refuse coefficients that make the formula overflow or divide by zero somewhere on
    :data:`GRID`, naming the key that does it: of the keys whose default
    (:data:`~drivedyn.tyres.magic_formula.DEFAULTS`, else 0) makes that point finite, the
    one farthest from its usual magnitude (:data:`SCALE`)."""
    bad = _first_failure(P)
    if bad is None:
        return
    pt, what = bad
    fz, kappa, alpha, gamma, vx, mu = pt
    at = (f"at Fz = {fz:g} N, kappa = {kappa:g}, alpha = {alpha:g} rad, gamma = {gamma:g} "
          f"rad, Vx = {vx:g} m/s, road friction {mu:g}")
    # the most unusual values first: |value| over the key's usual magnitude
    for key in sorted(values, key=lambda k: -abs(values[k]) / SCALE.get(k, 1.0)):
        trial = P.copy()
        trial[INDEX[key]] = DEFAULTS.get(key, 0.0)
        if key != "FITTYP" and _first_failure(trial, [pt]) is None:
            raise ModelError(f"{tf.where(SECTION_OF[key], key)}: the Magic Formula {what} "
                             f"{at} with this value ({values[key]!r}); expected a coefficient "
                             "of usual size")
    raise ModelError(f"tyre file {tf.path}: the Magic Formula {what} {at}; check the "
                     "coefficients")


def file_side(tf: TirFile) -> str | None:
    """The side of the vehicle the file's tyre was measured on: ``"left"``, ``"right"``,
    ``"symmetric"``, or None when the file has no ``[MODEL] TYRESIDE`` (checked by
    :func:`coefficients`)."""
    side = tf.sections.get("MODEL", {}).get("TYRESIDE")
    return side.strip().lower() if isinstance(side, str) else None
