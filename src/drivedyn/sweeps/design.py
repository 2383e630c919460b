"""The points of a sweep: varied keys (ranges or lists), sampled keys (distributions) and the
finite-difference stencil of a sensitivity study, turned into a list of points, each a set of
model-file overrides (the dotted keys of ``drivedyn run --set``).

Syntax of the command line (``drivedyn sweep``), also accepted by :func:`drivedyn.sweep`:

- ``KEY=START:STOP:N`` N evenly spaced values from START to STOP (both included);
- ``KEY=V1,V2,...`` the listed values (numbers, or words such as ``open,torsen-b``);
- an optional unit after the values, ``"bench.torque=50:250:5 N m"``: each value is passed
  to the model file as ``"<value> <unit>"`` and checked against the key's dimension;
- ``KEY=normal(MEAN,SD)`` or ``KEY=uniform(LOW,HIGH)`` (``--sample``), optionally with a unit;
- ``KEY`` or ``KEY=NOMINAL`` under ``--sensitivity``: the nominal value is the model file's
  (or the one given), perturbed by +-``rel_step`` of it.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from drivedyn.units import NUMBER

_KEY = re.compile(r"^[A-Za-z_][\w\-]*(\.[\w\-]+)*$")


class SweepInputError(ValueError):
    """A malformed sweep description (option, key, range, distribution): the message names
    the option and the key and says what was expected."""


def _number(text: str, what: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise SweepInputError(f"{what}: {text!r} is not a number") from None
    if not math.isfinite(x):
        raise SweepInputError(f"{what}: {text!r} is not a finite number")
    return x


def _key(key: str, option: str, text: str) -> str:
    key = key.strip()
    if not key:
        raise SweepInputError(f"{option} {text!r}: expected KEY=..., the key is empty")
    if not _KEY.match(key):
        raise SweepInputError(f"{option} {text!r}: {key!r} is not a dotted model-file key "
                              "(e.g. pockets.mu or bodies.rod.mass)")
    return key


def _split_unit(rhs: str) -> tuple[str, str]:
    """``"50:250:5 N m"`` -> (``"50:250:5"``, ``"N m"``)."""
    rhs = rhs.strip()
    values, _, unit = rhs.partition(" ")
    return values.strip(), unit.strip()


def _check_unit(unit: str, what: str) -> None:
    if not unit:
        return
    from drivedyn.units import UnitError, parse_unit

    try:
        parse_unit(unit)
    except UnitError as exc:
        raise SweepInputError(f"{what}: {exc}") from None


@dataclass(frozen=True)
class Vary:
    """A varied key and its values.

    Attributes:
        key: dotted model-file key (``pockets.mu``, ``bodies.rod.mass``).
        values: the values (floats, or strings for a list of words).
        unit: unit of the numeric values ("" for SI numbers or words).
    """

    key: str
    values: tuple
    unit: str = ""

    def model_value(self, v: Any) -> Any:
        """The value as written into the model file (``"<v> <unit>"`` with a unit)."""
        return format_value(v, self.unit)


@dataclass(frozen=True)
class Sample:
    """A sampled key: ``normal(mean, sd)`` or ``uniform(low, high)`` in ``unit``."""

    key: str
    distribution: str
    a: float
    b: float
    unit: str = ""

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        if self.distribution == "normal":
            return rng.normal(self.a, self.b, n)
        return rng.uniform(self.a, self.b, n)

    def describe(self) -> str:
        u = f" {self.unit}" if self.unit else ""
        return f"{self.distribution}({self.a:g},{self.b:g}){u}"


def format_value(v: Any, unit: str) -> Any:
    """A point's value for the model file: a Python float (its repr round-trips, so the
    same value given by ``--set KEY=<repr>`` is bit-identical), ``"<v> <unit>"``, or a word."""
    if isinstance(v, str):
        return v
    x = float(v)
    return f"{x!r} {unit}" if unit else x


def parse_vary(text: str, option: str = "--vary") -> Vary:
    """``KEY=START:STOP:N [UNIT]`` or ``KEY=V1,V2,... [UNIT]`` -> :class:`Vary`."""
    key, sep, rhs = text.partition("=")
    key = _key(key, option, text)
    if not sep or not rhs.strip():
        raise SweepInputError(f"{option} {text!r}: expected {key}=START:STOP:N or "
                              f"{key}=V1,V2,...")
    values_txt, unit = _split_unit(rhs)
    what = f"{option} {key}"
    if ":" in values_txt:
        parts = values_txt.split(":")
        if len(parts) != 3:
            raise SweepInputError(f"{what}={values_txt!r}: expected START:STOP:N (three "
                                  "fields separated by ':')")
        start = _number(parts[0], f"{what} START")
        stop = _number(parts[1], f"{what} STOP")
        try:
            n = int(parts[2])
        except ValueError:
            raise SweepInputError(f"{what}: N = {parts[2]!r} is not a whole number") from None
        if n < 1:
            raise SweepInputError(f"{what}: N = {n}: expected at least 1 point")
        if n > 1 and start == stop:
            raise SweepInputError(f"{what}: START = STOP = {start:g} with N = {n} gives "
                                  f"{n} identical points")
        if n == 1 and start != stop:
            raise SweepInputError(f"{what}: N = 1 with START != STOP: give one value "
                                  f"({key}={start:g}) or N >= 2")
        values: tuple = tuple(float(x) for x in np.linspace(start, stop, n))
    else:
        items = [s.strip() for s in values_txt.split(",")]
        if any(not s for s in items):
            raise SweepInputError(f"{what}={values_txt!r}: an empty value in the list")
        if all(re.fullmatch(NUMBER, s) for s in items):
            values = tuple(_number(s, what) for s in items)
        else:
            if unit:
                raise SweepInputError(f"{what}: words ({values_txt}) cannot take a unit")
            values = tuple(items)
        if len(set(values)) != len(values):
            raise SweepInputError(f"{what}={values_txt!r}: a value is repeated")
    _check_unit(unit, what)
    return Vary(key, values, unit)


_DIST = re.compile(r"^(normal|uniform)\(\s*([^,()]+?)\s*,\s*([^,()]+?)\s*\)\s*(.*)$")


def parse_sample(text: str, option: str = "--sample") -> Sample:
    """``KEY=normal(MEAN,SD) [UNIT]`` or ``KEY=uniform(LOW,HIGH) [UNIT]`` -> :class:`Sample`."""
    key, sep, rhs = text.partition("=")
    key = _key(key, option, text)
    m = _DIST.match(rhs.strip()) if sep else None
    if m is None:
        raise SweepInputError(f"{option} {text!r}: expected {key}=normal(MEAN,SD) or "
                              f"{key}=uniform(LOW,HIGH), optionally followed by a unit")
    dist, a_txt, b_txt, unit = m.groups()
    what = f"{option} {key}"
    a, b = _number(a_txt, what), _number(b_txt, what)
    if dist == "normal" and not b > 0:
        raise SweepInputError(f"{what}: normal(MEAN,SD) needs SD > 0, got {b:g}")
    if dist == "uniform" and not b > a:
        raise SweepInputError(f"{what}: uniform(LOW,HIGH) needs LOW < HIGH, got {a:g}, {b:g}")
    _check_unit(unit.strip(), what)
    return Sample(key, dist, a, b, unit.strip())


def parse_sensitivity(text: str, option: str = "--vary") -> tuple[str, float | None, str]:
    """``KEY`` or ``KEY=NOMINAL [UNIT]`` -> (key, nominal or None, unit)."""
    key, sep, rhs = text.partition("=")
    key = _key(key, option, text)
    if not sep:
        return key, None, ""
    values_txt, unit = _split_unit(rhs)
    if ":" in values_txt or "," in values_txt:
        raise SweepInputError(f"{option} {text!r}: with --sensitivity give {key} (the model "
                              f"file's value is the nominal point) or {key}=NOMINAL")
    _check_unit(unit, f"{option} {key}")
    return key, _number(values_txt, f"{option} {key}"), unit


@dataclass(frozen=True)
class Point:
    """One point of a sweep.

    Attributes:
        index: its position in the result arrays (one integer per dimension).
        overrides: dotted key -> value written into the model file.
    """

    index: tuple[int, ...]
    overrides: dict = field(hash=False)


@dataclass
class Design:
    """The points of a sweep and the coordinates of its result arrays.

    Attributes:
        kind: ``"grid"`` (varied keys, optionally times samples), ``"monte_carlo"`` (samples
            only) or ``"sensitivity"``.
        dims: dimension names (varied keys, ``"sample"``; sensitivity: ``"parameter"``,
            ``"offset"``).
        coords: dimension (or extra coordinate) name -> (dims, values, attrs).
        points: every point, in submission order.
        attrs: description kept in the results file (distributions, seed, steps).
    """

    kind: str
    dims: tuple[str, ...]
    shape: tuple[int, ...]
    coords: dict[str, tuple]
    points: list[Point]
    attrs: dict


def grid(varies: list[Vary], samples: list[Sample] | None = None, n_samples: int = 0,
         seed: int = 0) -> Design:
    """Full factorial design over ``varies`` (one dimension per key, in the given order),
    times ``n_samples`` Monte Carlo draws of ``samples`` (dimension ``sample``; the same draws
    at every grid point: common random numbers, so differences between grid points are not
    blurred by sampling noise). Draws use ``numpy.random.default_rng(seed)`` key by key in
    the given order."""
    samples = samples or []
    keys = [v.key for v in varies] + [s.key for s in samples]
    dup = {k for k in keys if keys.count(k) > 1}
    if dup:
        raise SweepInputError(f"key {sorted(dup)[0]!r} is varied or sampled twice")
    if samples and n_samples < 1:
        raise SweepInputError(f"--samples {n_samples}: expected at least 1 sample")
    if not varies and not samples:
        raise SweepInputError("nothing to sweep: give --vary KEY=START:STOP:N or --sample")
    dims = tuple(v.key for v in varies) + (("sample",) if samples else ())
    shape = tuple(len(v.values) for v in varies) + ((n_samples,) if samples else ())
    coords: dict[str, tuple] = {}
    for v in varies:
        coords[v.key] = ((v.key,), np.asarray(v.values),
                         {"units": v.unit or "SI", "varied": "range or list"})
    draws: dict[str, np.ndarray] = {}
    if samples:
        rng = np.random.default_rng(seed)
        coords["sample"] = (("sample",), np.arange(n_samples), {})
        for s in samples:
            draws[s.key] = s.draw(rng, n_samples)
            coords[s.key] = (("sample",), draws[s.key],
                             {"units": s.unit or "SI", "distribution": s.describe()})
    points = []
    for idx in itertools.product(*(range(n) for n in shape)):
        ov = {v.key: v.model_value(v.values[i]) for v, i in zip(varies, idx, strict=False)}
        if samples:
            k = idx[-1]
            for s in samples:
                ov[s.key] = format_value(draws[s.key][k], s.unit)
        points.append(Point(tuple(idx), ov))
    attrs = {"seed": seed if samples else None,
             "distributions": {s.key: s.describe() for s in samples}}
    kind = "grid" if varies else "monte_carlo"
    return Design(kind, dims, shape, coords, points, attrs)


def sensitivity(params: list[tuple[str, float, str]], rel_step: float) -> Design:
    """Central finite-difference stencil around the nominal point: for each (key, nominal,
    unit), the key at nominal*(1 -+ rel_step) with the others at their nominal values, plus
    the nominal point itself. Dimensions ``parameter`` (the keys) and ``offset`` (-1, 0, +1);
    the nominal point sits at offset 0 of every parameter (computed once)."""
    if not params:
        raise SweepInputError("--sensitivity: name the keys with --vary KEY (or KEY=NOMINAL)")
    if not 0 < rel_step < 0.5:
        raise SweepInputError(f"--rel-step {rel_step:g}: expected 0 < step < 0.5")
    keys = [k for k, _, _ in params]
    dup = {k for k in keys if keys.count(k) > 1}
    if dup:
        raise SweepInputError(f"--sensitivity: key {sorted(dup)[0]!r} is given twice")
    for key, nominal, _ in params:
        if nominal == 0:
            raise SweepInputError(f"--sensitivity {key}: its nominal value is 0, a relative "
                                  f"step is undefined; give {key}=NOMINAL with a non-zero "
                                  "nominal")
    nominal_ov = {k: format_value(x, u) for k, x, u in params}
    steps = [abs(x) * rel_step for _, x, _ in params]
    points = [Point((-1, 1), dict(nominal_ov))]  # the nominal point: offset 0 of every row
    for i, (key, x, unit) in enumerate(params):
        for j, sign in ((0, -1), (2, 1)):
            ov = dict(nominal_ov)
            ov[key] = format_value(x + sign * steps[i], unit)
            points.append(Point((i, j), ov))
    coords = {
        "parameter": (("parameter",), np.asarray(keys), {}),
        "offset": (("offset",), np.array([-1, 0, 1]), {"description": "step of the "
                   "parameter: -1 nominal*(1-rel_step), 0 nominal, +1 nominal*(1+rel_step)"}),
        "nominal": (("parameter",), np.array([x for _, x, _ in params]),
                    {"units": ", ".join(u or "SI" for _, _, u in params)}),
        "step": (("parameter",), np.array(steps), {"description": "absolute step"}),
    }
    return Design("sensitivity", ("parameter", "offset"), (len(params), 3), coords, points,
                  {"rel_step": rel_step})
