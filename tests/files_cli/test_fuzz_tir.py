"""Fuzzing the tyre property files (``.tir``) through the reader and the command line.

* Valid files -- MF 5.2 (FITTYP 6, 21, 52), 6.1 or 6.2, TYRESIDE left, right or absent, every
  optional section (units, operating conditions, carcass stiffnesses, scaling, rolling,
  overturning, turn slip, shape tables, vendor sections) and every optional key present or
  absent, numbers in any of the spellings the format allows -- are read, give finite forces,
  moments and relaxation lengths over a grid of operating points (road friction 0 included),
  and a wheel rolling on them from a model file runs (exit 0) or stops with a reason (exit 1).
* Malformed files -- one mutation of a valid file (a value that is not a number, NaN or
  infinite, a missing key or section the formula needs, an impossible value, an unsupported
  FITTYP or TYRESIDE, a key given twice, a line that is not ``KEY = value``, a non-SI unit, a
  coefficient so large that the formula overflows) -- are refused by the reader with a
  :class:`ModelError` naming the file, the section and the key (and its line when the file has
  it), and by ``drivedyn run`` and ``drivedyn vehicle`` with exit 2 and the same message.

The default profile (CI) is short and derandomized; ``pytest -m fuzz_long`` runs the long one.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from drivedyn.errors import ModelError
from drivedyn.tyres import read_tir
from drivedyn.tyres.tir import SECTION_OF
from fuzz_common import Outcome, assert_clean, assert_refused, cli, long, short, to_toml

# -- the content of a valid file ------------------------------------------------------------

#: [MODEL] keys other than FITTYP and TYRESIDE (all optional)
MODEL = {"PROPERTY_FILE_FORMAT": "'PAC2002'", "USE_MODE": "4", "VXLOW": "1.0",
         "LONGVL": "16.7"}
DIMENSION = {"UNLOADED_RADIUS": "0.344", "WIDTH": "0.235", "ASPECT_RATIO": "0.60",
             "RIM_RADIUS": "0.2032", "RIM_WIDTH": "0.178"}
OPERATING = {"INFLPRES": "2.2e5", "NOMPRES": "2.0e5"}
VERTICAL = {"FNOMIN": "4000.0", "VERTICAL_STIFFNESS": "2.1e5", "VERTICAL_DAMPING": "500.0",
            "BREFF": "8.4", "DREFF": "0.27", "FREFF": "0.07"}
STRUCTURAL = {"LONGITUDINAL_STIFFNESS": "3.0e5", "LATERAL_STIFFNESS": "1.5e5"}
SCALING = {k: "1" for k in ("LFZO LCX LMUX LEX LKX LHX LVX LGAX LCY LMUY LEY LKY LHY LVY LGAY "
                            "LTR LRES LGAZ LXAL LYKA LVYKA LS LSGKP LSGAL LMY LKYC LKZC").split()}
SCALING["LMUV"] = "0"
LONGITUDINAL = {
    "PCX1": "1.6411", "PDX1": "1.1739", "PDX2": "-0.16395", "PDX3": "0", "PEX1": "0.46403",
    "PEX2": "0.25022", "PEX3": "0.067842", "PEX4": "-3.7604e-5", "PKX1": "22.303",
    "PKX2": "0.48896", "PKX3": "0.21253", "PHX1": "0.0012297", "PHX2": "0.0004318",
    "PVX1": "-8.8098e-6", "PVX2": "1.862e-5", "PPX1": "-0.3485", "PPX2": "0.37824",
    "PPX3": "-0.09603", "PPX4": "0.06518", "RBX1": "13.276", "RBX2": "-13.778",
    "RBX3": "0", "RCX1": "1.2568", "REX1": "0.65225", "REX2": "-0.24948", "RHX1": "0.0050722",
    "PTX1": "2.3657", "PTX2": "1.4112", "PTX3": "0.56626"}
LATERAL = {
    "PCY1": "1.3507", "PDY1": "1.0489", "PDY2": "-0.18033", "PDY3": "-2.8821",
    "PEY1": "-0.0074722", "PEY2": "-0.0063208", "PEY3": "-9.9935", "PEY4": "-760.14",
    "PEY5": "0", "PKY1": "-21.92", "PKY2": "2.0012", "PKY3": "-0.024778", "PKY4": "2",
    "PKY5": "0", "PKY6": "-0.92405", "PKY7": "-0.24091", "PHY1": "0.0026747",
    "PHY2": "8.9094e-5", "PHY3": "0.031415", "PVY1": "0.037318", "PVY2": "-0.010049",
    "PVY3": "-0.32931", "PVY4": "-0.69553", "PPY1": "-0.6255", "PPY2": "-0.06523",
    "PPY3": "-0.16666", "PPY4": "0.2811", "PPY5": "0", "RBY1": "7.1433", "RBY2": "9.1916",
    "RBY3": "-0.027856", "RBY4": "0", "RCY1": "1.0719", "REY1": "-0.27572", "REY2": "0.32802",
    "RHY1": "5.7448e-6", "RHY2": "-3.1368e-5", "RVY1": "-0.027825", "RVY2": "0.053604",
    "RVY3": "-0.27568", "RVY4": "12.12", "RVY5": "1.9", "RVY6": "-10.704", "PTY1": "2.1439",
    "PTY2": "1.9829"}
ALIGNING = {
    "QBZ1": "10.0", "QBZ2": "-1.2", "QBZ3": "0", "QBZ4": "0.1", "QBZ5": "-0.3", "QBZ6": "0",
    "QBZ9": "10.0", "QBZ10": "0", "QCZ1": "1.2", "QDZ1": "0.09", "QDZ2": "-0.0065",
    "QDZ3": "0.4", "QDZ4": "0", "QDZ6": "0.002", "QDZ7": "-0.001", "QDZ8": "-0.2",
    "QDZ9": "0.02", "QDZ10": "0", "QDZ11": "0", "QEZ1": "-1.0", "QEZ2": "0.1", "QEZ3": "0",
    "QEZ4": "0.2", "QEZ5": "-1.0", "QHZ1": "0.002", "QHZ2": "0.002", "QHZ3": "0.2",
    "QHZ4": "0.1", "PPZ1": "-0.238", "PPZ2": "0", "SSZ1": "0.01", "SSZ2": "0.02",
    "SSZ3": "0.3", "SSZ4": "-0.1"}
ROLLING = {"QSY1": "0.01", "QSY2": "0", "QSY3": "0.0004", "QSY4": "4e-5", "QSY5": "0",
           "QSY6": "0", "QSY7": "0.85", "QSY8": "-0.4"}
OVERTURNING = {"QSX1": "0", "QSX2": "0.8", "QSX3": "0.06"}
TURNSLIP = {"PDXP1": "0.4", "PDXP2": "0", "PDXP3": "0", "PKYP1": "1", "PDYP1": "0.4"}
UNITS = {"LENGTH": ["'meter'", "'metre'", "'m'"], "FORCE": ["'newton'", "'N'"],
         "ANGLE": ["'radians'", "'rad'"], "MASS": ["'kg'", "'kilogram'"],
         "TIME": ["'second'", "'s'"], "PRESSURE": ["'pascal'", "'Pa'"]}

#: (section, {key: value text}, keys the formula cannot do without, section required?)
SECTIONS: list[tuple[str, dict[str, str], tuple[str, ...], bool]] = [
    ("MODEL", MODEL, (), True),
    ("DIMENSION", DIMENSION, ("UNLOADED_RADIUS",), True),
    ("OPERATING_CONDITIONS", OPERATING, (), False),
    ("VERTICAL", VERTICAL, ("FNOMIN", "VERTICAL_STIFFNESS"), True),
    ("STRUCTURAL", STRUCTURAL, (), False),
    ("SCALING_COEFFICIENTS", SCALING, (), False),
    ("LONGITUDINAL_COEFFICIENTS", LONGITUDINAL, ("PCX1", "PDX1", "PKX1"), True),
    ("LATERAL_COEFFICIENTS", LATERAL, ("PCY1", "PDY1", "PKY1", "PKY2"), True),
    ("ALIGNING_COEFFICIENTS", ALIGNING, ("QBZ1", "QCZ1", "QDZ1"), True),
    ("ROLLING_COEFFICIENTS", ROLLING, (), False),
    ("OVERTURNING_COEFFICIENTS", OVERTURNING, (), False),
    ("TURNSLIP_COEFFICIENTS", TURNSLIP, (), False),
]
FITTYPS = {6: "5.2", 21: "5.2", 52: "5.2", 61: "6.1", 62: "6.2"}
#: keys that must be > 0 (the reader's POSITIVE, as the files spell them)
POSITIVE = ("UNLOADED_RADIUS", "FNOMIN", "VERTICAL_STIFFNESS", "PCX1", "PDX1", "PCY1", "PDY1",
            "LONGVL", "LFZO")
TABLES = {
    "SHAPE": ["{radial width}", " 1.0    0.0", " 1.0    0.4", " 0.9    0.9"],
    "LOADED_RADIUS": ["{rho   fz}", " 0.00   0.0", " 0.02   4200.0"],
    "MDI_HEADER": ["FILE_TYPE = 'tir'", "FILE_VERSION = 3.0", "FILE_FORMAT = 'ASCII'"],
    "VENDOR_DATA": ["free text the reader skips: a = b = c", "{not a table}", "x"],
}


@dataclass
class TirCase:
    """A property file as sections of ``KEY = value`` lines, rendered by :meth:`text`.

    Attributes:
        fittyp, side: FITTYP and TYRESIDE (None: absent).
        sections: ``[(SECTION, {KEY: value text})]`` in file order (MODEL holds FITTYP).
        tables: names of the skipped sections (tables, vendor data) written at the end.
        style: how lines are spelt: ``lower`` keys in lower case, ``fortran`` exponents
            with ``D``, ``comments`` a ``$`` comment on every line and ``!`` comment lines,
            ``crlf`` line ends.
    """

    fittyp: int
    side: str | None
    sections: list[tuple[str, dict[str, str]]]
    tables: list[str] = field(default_factory=list)
    style: frozenset[str] = frozenset()

    @property
    def version(self) -> str:
        return FITTYPS[self.fittyp]

    def section(self, name: str) -> dict[str, str] | None:
        for sec, keys in self.sections:
            if sec == name:
                return keys
        return None

    def has(self, key: str) -> bool:
        return any(key in keys for _, keys in self.sections)

    def lines(self) -> tuple[list[str], dict[str, int]]:
        """The file's lines and the line number of each key."""
        out = ["$ fuzzed property file"]
        where: dict[str, int] = {}
        for sec, keys in self.sections:
            if "comments" in self.style:
                out.append("!" + "-" * 40 + sec.lower())
            out.append(f"[{sec}]")
            for k, v in keys.items():
                if "fortran" in self.style and re.fullmatch(r"-?[0-9.]+e-?[0-9]+", v):
                    v = v.replace("e", "D")
                key = k.lower() if "lower" in self.style else k
                line = f"{key:<24s} = {v}"
                if "comments" in self.style:
                    line += "   $ a comment, with 'quotes' = and [brackets]"
                out.append(line)
                where[k] = len(out)
        for t in self.tables:
            out.append(f"[{t}]")
            out += TABLES[t]
        return out, where

    def text(self) -> str:
        lines, _ = self.lines()
        return ("\r\n" if "crlf" in self.style else "\n").join(lines) + "\n"

    def write(self, path: Path) -> Path:
        path.write_bytes(self.text().encode())
        return path


def _needs_pty(fittyp: int, sections: list[tuple[str, dict[str, str]]]) -> bool:
    """The lateral relaxation length comes from PTY1-2 (MF 5.2, or MF 6.x without the
    carcass's lateral stiffness)."""
    stiff = any("LATERAL_STIFFNESS" in keys for sec, keys in sections if sec == "STRUCTURAL")
    return fittyp < 60 or not stiff


@st.composite
def _subset(draw: Any, keys: dict[str, str], required: tuple[str, ...]) -> dict[str, str]:
    """``keys`` with every optional key present or absent: all, none, or a random subset."""
    mode = draw(st.sampled_from(["all", "none", "some"]))
    optional = [k for k in keys if k not in required]
    if mode == "all":
        chosen = set(optional)
    elif mode == "none":
        chosen = set()
    else:
        chosen = draw(st.sets(st.sampled_from(optional))) if optional else set()
    return {k: v for k, v in keys.items() if k in required or k in chosen}


SCALES = (0.5, 0.8, 1.0, 1.25, 2.0)


def _scaled(value: str, factor: float) -> str:
    return value if factor == 1.0 else f"{float(value) * factor:.6g}"


@st.composite
def valid_tir(draw: Any) -> TirCase:
    """A property file the reader must accept."""
    fittyp = draw(st.sampled_from(sorted(FITTYPS)))
    side = draw(st.sampled_from([None, "LEFT", "RIGHT"]))
    sections: list[tuple[str, dict[str, str]]] = []
    if draw(st.booleans()):
        sections.append(("UNITS", {k: draw(st.sampled_from(v)) for k, v in UNITS.items()
                                   if draw(st.booleans())}))
    for name, keys, required, needed in SECTIONS:
        if not needed and not draw(st.booleans()):
            continue
        content = draw(_subset(keys, required))
        if name == "MODEL":
            content = {"FITTYP": str(fittyp), **content}
            if side is not None:
                content["TYRESIDE"] = f"'{draw(st.sampled_from([side, side.lower()]))}'"
        sections.append((name, content))
    # the lateral relaxation length's coefficients where the formula needs them
    if _needs_pty(fittyp, sections):
        lat = dict(next(keys for sec, keys in sections if sec == "LATERAL_COEFFICIENTS"))
        lat.update(PTY1=LATERAL["PTY1"], PTY2=LATERAL["PTY2"])
        sections = [(s, lat if s == "LATERAL_COEFFICIENTS" else k) for s, k in sections]
    # coefficients off their base values by up to a factor 2 (a different, plausible tyre)
    if draw(st.booleans()):
        sections = [(s, {k: _scaled(v, draw(st.sampled_from(SCALES)))
                         if k in SECTION_OF and k != "FITTYP" else v
                         for k, v in keys.items()}) for s, keys in sections]
    order = draw(st.permutations(range(len(sections))))
    sections = [sections[i] for i in order]
    tables = draw(st.lists(st.sampled_from(sorted(TABLES)), unique=True, max_size=4))
    style = frozenset(draw(st.sets(st.sampled_from(["lower", "fortran", "comments",
                                                    "crlf"]))))
    return TirCase(fittyp, side, sections, tables, style)


# -- checks of a valid file -----------------------------------------------------------------

FZ = (0.05, 0.5, 1.0, 2.5)  # [FNOMIN]
KAPPA = (-1.0, -0.2, 0.0, 0.03, 0.5)
ALPHA = (-0.6, 0.0, 0.1)
GAMMA = (-0.1, 0.0, 0.08)
VX = (-5.0, 0.0, 0.3, 20.0)
MU = (0.0, 0.002, 1.0)


def _check_valid(path: Path, case: TirCase) -> None:
    tyre = read_tir(path)
    assert tyre.version == case.version
    fz = np.array(FZ)[:, None, None, None, None, None] * tyre.nominal_load
    out = tyre.evaluate(fz, np.array(KAPPA)[:, None, None, None, None],
                        np.array(ALPHA)[:, None, None, None], np.array(GAMMA)[:, None, None],
                        np.array(VX)[:, None], mu=np.array(MU))
    for name, values in out.items():
        assert np.all(np.isfinite(values)), f"{name} not finite:\n{case.text()}"
    assert np.all(out["sigma_kappa"] > 0) and np.all(out["sigma_alpha"] > 0)
    for rho in (0.0, 0.01, 0.05):
        assert math.isfinite(tyre.effective_radius(rho))


WHEEL = {
    "model": {"name": "wheel-on-tir", "gravity": [0.0, 0.0, -9.81]},
    "bodies": [{"name": "wheel", "mass": "400 kg", "inertia": [20.0, 30.0, 20.0],
                "position": [0.0, 0.0, 0.335], "velocity": [5.0, 0.0, 0.0],
                "angular_velocity": [0.0, 16.0, 0.0]}],
    "markers": [{"name": "hub", "body": "wheel", "axis": [0.0, 1.0, 0.0]}],
    "elements": [{"type": "TyreContact", "name": "tyre", "marker": "hub", "tyre": "",
                  "mu": 1.0}],
    "solver": {"t_end": "4 ms", "step": {"mode": "fixed", "h": "1 ms"}},
    "output": {"dt": "1 ms"},
}


def _run_wheel(tmp_path: Path, tir: Path, mu: float = 1.0) -> tuple[Outcome, Path]:
    """``drivedyn run`` on a wheel moving at 5 m/s and spinning a little faster (driving
    slip, about 9 % with the base radius), pressed 9 mm into the road, on the tyre file
    ``tir``."""
    model = {**WHEEL, "elements": [{**WHEEL["elements"][0], "tyre": str(tir), "mu": mu}]}
    path = tmp_path / "wheel.toml"
    path.write_text(to_toml(model))
    return cli(["run", str(path), "--out", str(tmp_path / "wheel.nc")]), path


def _valid_case(tmp_path: Path, case: TirCase, mu: float, cli_run: bool) -> None:
    path = case.write(tmp_path / "fuzz.tir")
    _check_valid(path, case)
    if cli_run:
        out, _ = _run_wheel(tmp_path, path, mu)
        assert_clean(out)
        assert out.exit_code != 2, out.show()


@short(25)
@given(case=valid_tir())
def test_valid_tir_files_are_read(tmp_path: Path, case: TirCase) -> None:
    """Through the reader: fails if it refuses a valid file (a FITTYP, a TYRESIDE, an
    optional key or section it should not need, a spelling of numbers or comments) or if the
    formula divides by zero or overflows on it (a 6.x file without PTY1-2 and its carcass
    stiffness given, a road friction of 0)."""
    _valid_case(tmp_path, case, 1.0, cli_run=False)


@short(3)
@given(case=valid_tir(), mu=st.sampled_from(MU))
def test_valid_tir_files_run(tmp_path: Path, case: TirCase, mu: float) -> None:
    """A wheel rolling on a valid file from a model file (``drivedyn run``, 4 ms): fails if
    the run crashes (e.g. the tyre kernel dividing by zero on a road without friction) or
    refuses the file."""
    _valid_case(tmp_path, case, mu, cli_run=True)


# -- malformed files: one mutation of a valid file ------------------------------------------

@dataclass
class Mutation:
    """A change that makes the file malformed, and what the message must name."""

    label: str
    kind: str  # the label without the key
    section: str  # the section and key named in the message
    key: str
    line: bool  # the message gives the key's line
    apply: Any  # TirCase -> new text


def _replace_value(case: TirCase, key: str, value: str) -> str:
    lines, where = case.lines()
    n = where[key] - 1
    lines[n] = re.sub(r"=\s*\S.*$", f"= {value}", lines[n]) if value else \
        lines[n].split("=")[0] + "="
    return "\n".join(lines) + "\n"


def _drop(case: TirCase, key: str) -> str:
    lines, where = case.lines()
    del lines[where[key] - 1]
    return "\n".join(lines) + "\n"


def _drop_section(case: TirCase, name: str) -> str:
    kept = TirCase(case.fittyp, case.side, [(s, k) for s, k in case.sections if s != name],
                   case.tables, case.style)
    return kept.text()


def _insert_after(case: TirCase, key: str, text: str) -> str:
    lines, where = case.lines()
    lines.insert(where[key], text)
    return "\n".join(lines) + "\n"


def _section_of(case: TirCase, key: str) -> str:
    return next(s for s, keys in case.sections if key in keys)


NOT_NUMBERS = ["abc", "1.2.3", "", "nan", "inf", "-inf", "1e400", "--1", "0x10", "1,5"]


def mutations(case: TirCase) -> list[Mutation]:
    """Every mutation applicable to ``case``."""
    muts: list[Mutation] = []

    def add(label: str, section: str, key: str, line: bool, apply: Any,
            kind: str | None = None) -> None:
        muts.append(Mutation(label, kind or label, section, key, line, apply))

    def set_to(key: str, value: str) -> Any:
        return lambda c: _replace_value(c, key, value)

    for s, k in [(s, k) for s, ks in case.sections for k in ks if s != "UNITS"]:
        if k in ("TYRESIDE", "PROPERTY_FILE_FORMAT"):
            continue
        for bad in NOT_NUMBERS:
            add(f"{k} = {bad!r}", s, k, True, set_to(k, bad), f"= {bad!r}")
        if k in SECTION_OF:
            add(f"{k} a string", s, k, True, set_to(k, "'text'"), "a string")
            for huge in ("1e30", "-1e30", "1e200"):
                add(f"{k} = {huge}", s, k, True, set_to(k, huge), f"= {huge}")
        add(f"{k} given twice", s, k, True,
            lambda c, k=k: _insert_after(c, k, f"{k} = 1.0"), "twice")
    for k in POSITIVE:
        if case.has(k):
            for bad in ("0", "-1", "-1e-9"):
                add(f"{k} = {bad}", _section_of(case, k), k, True, set_to(k, bad),
                    f"positive {bad}")
    for name, _, required, _needed in SECTIONS:
        for k in required:
            add(f"no {k}", name, k, False, lambda c, k=k: _drop(c, k))
        if required:
            add(f"no [{name}]", name, required[0], False,
                lambda c, n=name: _drop_section(c, n))
    if _needs_pty(case.fittyp, case.sections):
        for k in ("PTY1", "PTY2"):
            add(f"no {k}", "LATERAL_COEFFICIENTS", k, False, lambda c, k=k: _drop(c, k))
        add("PTY2 = 0", "LATERAL_COEFFICIENTS", "PTY2", True, set_to("PTY2", "0"))
    add("no FITTYP", "MODEL", "FITTYP", False, lambda c: _drop(c, "FITTYP"))
    for bad in ("0", "3", "5", "60", "6.5", "63", "-61", "'MF61'"):
        add(f"FITTYP = {bad}", "MODEL", "FITTYP", True, set_to("FITTYP", bad))
    add("PKY2 = 0", "LATERAL_COEFFICIENTS", "PKY2", True, set_to("PKY2", "0"))
    for k in SCALING:
        if case.has(k) and k != "LFZO":
            add(f"{k} < 0", "SCALING_COEFFICIENTS", k, True, set_to(k, "-0.5"), "scaling < 0")
    if case.has("VERTICAL_DAMPING"):
        add("VERTICAL_DAMPING < 0", "VERTICAL", "VERTICAL_DAMPING", True,
            set_to("VERTICAL_DAMPING", "-100"))
    if case.side is not None:
        for bad in ("'UP'", "'L'", "''", "3"):
            add(f"TYRESIDE = {bad}", "MODEL", "TYRESIDE", True, set_to("TYRESIDE", bad))
    units = case.section("UNITS") or {}
    for k, bad in (("LENGTH", "'mm'"), ("FORCE", "'kN'"), ("ANGLE", "'deg'"),
                   ("PRESSURE", "'bar'"), ("TIME", "'ms'")):
        if k in units:
            add(f"{k} in {bad}", "UNITS", k, True, set_to(k, bad))
    # a line that is not KEY = value in a section the reader reads
    for text in ("PDY1 1.0489", "= 3", "[MODEL", "\x00\x01 junk"):
        add(f"line {text!r}", "LONGITUDINAL_COEFFICIENTS", "line", False,
            lambda c, t=text: _insert_after(c, "PCX1", t))
    return muts


@st.composite
def malformed_tir(draw: Any) -> tuple[TirCase, Mutation]:
    case = draw(valid_tir())
    return case, draw(st.sampled_from(mutations(case)))


def _expect_refused(text: str, path: Path, mut: Mutation, case: TirCase) -> str:
    """The reader's message for a malformed file (a huge coefficient may also be accepted:
    then the formula must stay finite). Returns the message, "" if accepted."""
    path.write_bytes(text.encode("utf-8", errors="surrogateescape"))
    try:
        tyre = read_tir(path)
    except ModelError as exc:
        msg = str(exc)
    else:
        assert "e30" in mut.label or "e200" in mut.label, \
            f"{mut.label}: accepted\n{text}"
        _check_valid(path, case)
        assert tyre is not None
        return ""
    assert str(path) in msg, f"{mut.label}: the message does not name the file: {msg}"
    if mut.key == "line":
        assert re.search(r"line \d+", msg), f"{mut.label}: no line in {msg}"
    else:
        assert f"[{mut.section}] {mut.key}" in msg, f"{mut.label}: {msg}"
        if mut.line:
            assert re.search(rf"\[{mut.section}\] {mut.key} \(line \d+\)", msg), \
                f"{mut.label}: no line in {msg}"
    return msg


def _malformed_case(tmp_path: Path, case: TirCase, mut: Mutation, via_cli: bool) -> None:
    path = tmp_path / "bad.tir"
    msg = _expect_refused(mut.apply(case), path, mut, case)
    if not msg or not via_cli:
        return
    out, model = _run_wheel(tmp_path, path)
    assert_refused(out, str(model), str(path))
    assert not list(tmp_path.glob("*.nc"))


@short(25)
@given(pair=malformed_tir())
def test_malformed_tir_files_are_refused(tmp_path: Path, pair: tuple[TirCase, Mutation]
                                         ) -> None:
    """Fails if a malformed file is accepted (e.g. the reader stops checking PTY2 or
    TYRESIDE), crashes the reader or the command line, or is refused without naming the file,
    the section and the key (and its line)."""
    case, mut = pair
    _malformed_case(tmp_path, case, mut, via_cli=True)


def _full_case(fittyp: int, side: str, carcass: bool) -> TirCase:
    """Every section and key (without [STRUCTURAL] unless ``carcass``), every unit."""
    sections = [("UNITS", {k: v[0] for k, v in UNITS.items()})]
    for name, keys, _, _ in SECTIONS:
        if name == "STRUCTURAL" and not carcass:
            continue
        content = dict(keys)
        if name == "MODEL":
            content = {"FITTYP": str(fittyp), **content, "TYRESIDE": f"'{side}'"}
        sections.append((name, content))
    return TirCase(fittyp, side, sections, sorted(TABLES))


def test_every_tir_mutation_is_refused(tmp_path: Path) -> None:
    """Each kind of mutation once per section, through the reader, on a 6.1 right-side file
    with every section and key and on a 5.2 left-side file without carcass stiffnesses. Fails
    if any one of them is accepted or badly reported (e.g. the reader's check of non-finite
    numbers or of TYRESIDE is removed)."""
    for case in (_full_case(61, "RIGHT", True), _full_case(52, "LEFT", False)):
        seen: set[tuple[str, str]] = set()
        for mut in mutations(case):
            if (mut.kind, mut.section) in seen:
                continue
            seen.add((mut.kind, mut.section))
            _expect_refused(mut.apply(case), tmp_path / "bad.tir", mut, case)


def test_tir_errors_through_the_vehicle(tmp_path: Path) -> None:
    """``drivedyn vehicle --set wheels.tyre=FILE`` refuses a malformed file before running,
    naming the vehicle file, the tyre file and the key, and runs a valid 6.2 right-side file
    without PTY1-2 (carcass stiffnesses given). Fails if a tyre error escapes as an internal
    error or loses the file or the key."""
    sections = [(n, dict(k)) for n, k, _, _ in SECTIONS]
    sections[0] = ("MODEL", {"FITTYP": "62", "TYRESIDE": "'RIGHT'", **MODEL})
    good = TirCase(62, "RIGHT", sections)
    lat = good.section("LATERAL_COEFFICIENTS")
    assert lat is not None
    del lat["PTY1"], lat["PTY2"]
    path = good.write(tmp_path / "good.tir")
    base = ["vehicle", "--t-end", "0.002", "--set", "run.window=[0, 0.002]"]
    out = cli([*base, "--set", f'wheels.tyre="{path}"'])
    assert_clean(out)
    assert out.exit_code != 2, out.show()
    bad = tmp_path / "bad.tir"
    bad.write_text(_replace_value(good, "FNOMIN", "-4000"))
    out = cli([*base, "--set", f'wheels.tyre="{bad}"'])
    assert_refused(out, "vehicle-4wd", "wheels.tyre", str(bad), "[VERTICAL] FNOMIN (line")


@pytest.mark.fuzz_long
@long(1000)
@given(case=valid_tir())
def test_valid_tir_files_read_long(tmp_path: Path, case: TirCase) -> None:
    """Long profile of :func:`test_valid_tir_files_are_read` (fails on the same mutations,
    e.g. the formula dividing by LMUY* again at road friction 0)."""
    _valid_case(tmp_path, case, 1.0, cli_run=False)


@pytest.mark.fuzz_long
@long(100)
@given(case=valid_tir(), mu=st.sampled_from(MU))
def test_valid_tir_files_run_long(tmp_path: Path, case: TirCase, mu: float) -> None:
    """Long profile of :func:`test_valid_tir_files_run` (fails on the same mutations, e.g.
    the relaxation length dividing by PTY2 = 0 in the tyre kernel)."""
    _valid_case(tmp_path, case, mu, cli_run=True)


@pytest.mark.fuzz_long
@long(40)
@given(case=valid_tir())
def test_valid_tir_files_in_the_vehicle_long(tmp_path: Path, case: TirCase) -> None:
    """Valid files as the vehicle's tyre (``drivedyn vehicle --set wheels.tyre=FILE``, 2 ms):
    runs or fails with a reason."""
    path = case.write(tmp_path / "fuzz.tir")
    out = cli(["vehicle", "--t-end", "0.002", "--set", "run.window=[0, 0.002]", "--set",
               f'wheels.tyre="{path}"'])
    assert_clean(out)
    assert out.exit_code != 2, out.show()


@pytest.mark.fuzz_long
@long(600)
@given(pair=malformed_tir())
def test_malformed_tir_files_long(tmp_path: Path, pair: tuple[TirCase, Mutation]) -> None:
    """Long profile of :func:`test_malformed_tir_files_are_refused` (fails on the same
    mutations, e.g. the reader no longer refusing a negative scaling factor)."""
    case, mut = pair
    _malformed_case(tmp_path, case, mut, via_cli=True)
