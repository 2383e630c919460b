"""Python-side time functions: :class:`TimeFunction` and its kinds (:class:`Constant`,
:class:`Ramp`, :class:`SmoothStep`, :class:`Table`, :class:`Held`, :class:`Sum`), and the
parser
:func:`as_time_function` of numbers and plain-data mappings.

Each leaf evaluates itself with the interpreted (``.py_func``) per-kind routine of
:mod:`drivedyn.timefunctions.kernels`, the same code the compiled kernels run.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from drivedyn.timefunctions.kernels import (
    _constant_eval,
    _held_eval,
    _ramp_eval,
    _smooth_step_eval,
    _table_eval,
)

_constant_py = _constant_eval.py_func
_held_py = _held_eval.py_func
_ramp_py = _ramp_eval.py_func
_smooth_step_py = _smooth_step_eval.py_func
_table_py = _table_eval.py_func


def _finite_float(name: str, x: Any) -> float:
    if isinstance(x, bool) or not isinstance(x, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {type(x).__name__}")
    v = float(x)
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite, got {v}")
    return v


def _is_scalar_number(x: Any) -> bool:
    return isinstance(x, numbers.Real) and not isinstance(x, bool)


class TimeFunction:
    """Base class of time functions ``f(t)``, ``t`` [s].

    Supports ``f + g`` / ``f + 2.0`` / ``sum([...])`` (giving a :class:`Sum`), ``-f``,
    ``f - g`` and scaling by a real number ``k * f`` (scales every term; a leaf stays the
    same kind). Methods accept a float ``t`` (returning a float) or an array of times
    (returning an array of the same shape).
    """

    # let numpy scalars defer to our reflected operators (np.float64(2) * f)
    __array_ufunc__ = None

    # -- to be provided by leaves -------------------------------------------------------------
    def evaluate(self, t: float) -> tuple[float, float, float, float]:
        """Return ``(value, d/dt [1/s], d2/dt2 [1/s^2], int_0^t f [s])`` at ``t`` [s]."""
        raise NotImplementedError

    def terms(self) -> list[TimeFunction]:
        """Leaf terms (non-:class:`Sum`) whose sum is this function."""
        return [self]

    def scaled(self, factor: float) -> TimeFunction:
        """This function multiplied by ``factor``."""
        raise NotImplementedError

    def breakpoints(self) -> tuple[float, ...]:
        """Sorted times [s] where the function or a derivative is not smooth."""
        return ()

    def to_dict(self) -> dict[str, Any]:
        """Plain-data description accepted by :func:`as_time_function`."""
        raise NotImplementedError

    # -- evaluation ---------------------------------------------------------------------------
    def _component(self, t: float | np.ndarray, j: int) -> float | np.ndarray:
        if np.ndim(t) == 0:
            return self.evaluate(float(t))[j]
        ta = np.asarray(t, dtype=float)
        flat = np.array([self.evaluate(float(x))[j] for x in ta.ravel()], dtype=float)
        return flat.reshape(ta.shape)

    def __call__(self, t: float | np.ndarray) -> float | np.ndarray:
        """Value at time ``t`` [s]."""
        return self._component(t, 0)

    def derivative(self, t: float | np.ndarray) -> float | np.ndarray:
        """First time derivative at ``t`` [s] (value unit per s; right limit at breakpoints)."""
        return self._component(t, 1)

    def second_derivative(self, t: float | np.ndarray) -> float | np.ndarray:
        """Second time derivative at ``t`` [s] (value unit per s^2; kinks ignored)."""
        return self._component(t, 2)

    def integral(self, t: float | np.ndarray) -> float | np.ndarray:
        """Exact integral ``int_0^t f(tau) dtau`` (value unit times s)."""
        return self._component(t, 3)

    # -- algebra ------------------------------------------------------------------------------
    def __add__(self, other: Any) -> Sum:
        if isinstance(other, TimeFunction):
            return Sum((*self.terms(), *other.terms()))
        if _is_scalar_number(other):
            if other == 0:
                return Sum(tuple(self.terms()))
            return Sum((*self.terms(), Constant(other)))
        return NotImplemented

    def __radd__(self, other: Any) -> Sum:
        if isinstance(other, TimeFunction):
            return Sum((*other.terms(), *self.terms()))
        if _is_scalar_number(other):
            if other == 0:
                return Sum(tuple(self.terms()))
            return Sum((Constant(other), *self.terms()))
        return NotImplemented

    def __mul__(self, other: Any) -> TimeFunction:
        if _is_scalar_number(other):
            return self.scaled(float(other))
        return NotImplemented

    __rmul__ = __mul__

    def __neg__(self) -> TimeFunction:
        return self.scaled(-1.0)

    def __sub__(self, other: Any) -> Sum:
        if isinstance(other, TimeFunction) or _is_scalar_number(other):
            return self + (-1.0) * other
        return NotImplemented

    def __rsub__(self, other: Any) -> Sum:
        if _is_scalar_number(other):
            return (-self) + other
        return NotImplemented


@dataclass(frozen=True)
class Constant(TimeFunction):
    """Constant ``f(t) = value``."""

    value: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "value", _finite_float("Constant: value", self.value))

    def evaluate(self, t: float) -> tuple[float, float, float, float]:
        return _constant_py(float(t), self.value)

    def scaled(self, factor: float) -> Constant:
        return Constant(self.value * factor)

    def to_dict(self) -> dict[str, Any]:
        return {"type": "constant", "value": self.value}


@dataclass(frozen=True)
class Held(TimeFunction):
    """An input held between the calls of a resumable run: ``f(t) = scale u``, with ``u`` the
    value last written to the input ``name`` (``start`` until then), constant over each
    call (zero-order hold). Its integral stays continuous where ``u`` changes, so a speed
    driver following it turns on without a jump of angle.

    The value lives in the packed arrays of the compiled model
    (:data:`~drivedyn.timefunctions.kernels.KIND_HELD`); a
    :class:`~drivedyn.solver.simulation.Simulation` writes it between calls
    (``set_input``). Evaluated here, the input stays at ``start``.

    Attributes:
        name: input name (every term of this name takes the value written).
        start: value of ``u`` before any is written (unit of what it drives).
        scale: factor on ``u`` (from ``k * f``).
    """

    name: str
    start: float = 0.0
    scale: float = 1.0

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"Held: name must be a non-empty string, got {self.name!r}")
        object.__setattr__(self, "start", _finite_float("Held: start", self.start))
        object.__setattr__(self, "scale", _finite_float("Held: scale", self.scale))

    def evaluate(self, t: float) -> tuple[float, float, float, float]:
        return _held_py(float(t), self.scale * self.start, 0.0, 0.0)

    def scaled(self, factor: float) -> Held:
        return Held(self.name, self.start, self.scale * factor)

    def to_dict(self) -> dict[str, Any]:
        return {"type": "held", "name": self.name, "start": self.start, "scale": self.scale}


def _check_interval(cls: str, t0: float, t1: float) -> None:
    if not t1 > t0:
        raise ValueError(f"{cls}: t1 (={t1}) must be greater than t0 (={t0})")


@dataclass(frozen=True)
class Ramp(TimeFunction):
    """Linear ramp: ``v0`` for ``t <= t0`` [s], linear to ``v1`` at ``t1`` [s], ``v1`` after.

    Requires ``t1 > t0``. The derivative is ``(v1 - v0)/(t1 - t0)`` on ``[t0, t1)``, else 0;
    the second derivative is 0.
    """

    t0: float
    t1: float
    v0: float
    v1: float

    def __post_init__(self) -> None:
        name = type(self).__name__
        for f in ("t0", "t1", "v0", "v1"):
            object.__setattr__(self, f, _finite_float(f"{name}: {f}", getattr(self, f)))
        _check_interval(name, self.t0, self.t1)

    def evaluate(self, t: float) -> tuple[float, float, float, float]:
        return _ramp_py(float(t), self.t0, self.t1, self.v0, self.v1)

    def scaled(self, factor: float) -> Ramp:
        return type(self)(self.t0, self.t1, self.v0 * factor, self.v1 * factor)

    def breakpoints(self) -> tuple[float, ...]:
        return (self.t0, self.t1)

    def to_dict(self) -> dict[str, Any]:
        return {"type": "ramp", "t0": self.t0, "t1": self.t1, "v0": self.v0, "v1": self.v1}


@dataclass(frozen=True)
class SmoothStep(TimeFunction):
    """C1 cubic step: ``v0`` for ``t <= t0`` [s], ``v1`` for ``t >= t1`` [s], in between
    ``v0 + (v1 - v0)(3 s^2 - 2 s^3)`` with ``s = (t - t0)/(t1 - t0)``.

    Requires ``t1 > t0``. The second derivative is the cubic's on ``[t0, t1)``, else 0.
    """

    t0: float
    t1: float
    v0: float
    v1: float

    def __post_init__(self) -> None:
        name = type(self).__name__
        for f in ("t0", "t1", "v0", "v1"):
            object.__setattr__(self, f, _finite_float(f"{name}: {f}", getattr(self, f)))
        _check_interval(name, self.t0, self.t1)

    def evaluate(self, t: float) -> tuple[float, float, float, float]:
        return _smooth_step_py(float(t), self.t0, self.t1, self.v0, self.v1)

    def scaled(self, factor: float) -> SmoothStep:
        return type(self)(self.t0, self.t1, self.v0 * factor, self.v1 * factor)

    def breakpoints(self) -> tuple[float, ...]:
        return (self.t0, self.t1)

    def to_dict(self) -> dict[str, Any]:
        return {
            "type": "smooth_step",
            "t0": self.t0,
            "t1": self.t1,
            "v0": self.v0,
            "v1": self.v1,
        }


@dataclass(frozen=True)
class Table(TimeFunction):
    """Piecewise-linear interpolation of ``values`` over ``times`` [s].

    Constant extrapolation (first / last value) outside ``[times[0], times[-1]]``.
    ``times`` must be strictly increasing, with at least 2 points, the same length as
    ``values``, all finite. The second derivative is 0 (kinks ignored). Stored as tuples of
    floats so the object is hashable.
    """

    times: Sequence[float]
    values: Sequence[float]
    _x: np.ndarray = field(init=False, repr=False, compare=False)
    _y: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        x = self._as_1d("times", self.times)
        y = self._as_1d("values", self.values)
        if x.shape[0] != y.shape[0]:
            raise ValueError(
                f"Table: times and values must have the same length "
                f"(got {x.shape[0]} times and {y.shape[0]} values)"
            )
        if x.shape[0] < 2:
            raise ValueError(f"Table: times needs at least 2 points, got {x.shape[0]}")
        dx = np.diff(x)
        if np.any(dx <= 0.0):
            i = int(np.argmax(dx <= 0.0)) + 1
            raise ValueError(
                f"Table: times must be strictly increasing, but times[{i}] = {x[i]} "
                f"<= times[{i - 1}] = {x[i - 1]}"
            )
        x.flags.writeable = False
        y.flags.writeable = False
        object.__setattr__(self, "times", tuple(float(v) for v in x))
        object.__setattr__(self, "values", tuple(float(v) for v in y))
        object.__setattr__(self, "_x", x)
        object.__setattr__(self, "_y", y)

    @staticmethod
    def _as_1d(name: str, seq: Any) -> np.ndarray:
        if isinstance(seq, str | bytes) or not isinstance(seq, Iterable | np.ndarray):
            raise TypeError(f"Table: {name} must be a sequence of numbers")
        try:
            a = np.array(seq, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"Table: {name} must be a sequence of numbers ({exc})") from None
        if a.ndim != 1:
            raise ValueError(f"Table: {name} must be one-dimensional, got shape {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"Table: {name} must be finite")
        return a

    def evaluate(self, t: float) -> tuple[float, float, float, float]:
        v, d, dd, integral = _table_py(float(t), self._x, self._y)
        return float(v), float(d), float(dd), float(integral)

    def scaled(self, factor: float) -> Table:
        return Table(self.times, tuple(v * factor for v in self.values))

    def breakpoints(self) -> tuple[float, ...]:
        return tuple(self.times)

    def to_dict(self) -> dict[str, Any]:
        return {"type": "table", "times": list(self.times), "values": list(self.values)}


@dataclass(frozen=True)
class Sum(TimeFunction):
    """Sum of time functions. Nested sums are flattened; numbers become :class:`Constant`."""

    terms_: tuple[TimeFunction, ...]

    def __init__(self, terms: Iterable[TimeFunction | float]) -> None:
        flat: list[TimeFunction] = []
        for term in terms:
            flat.extend(as_time_function(term).terms())
        object.__setattr__(self, "terms_", tuple(flat))

    def __repr__(self) -> str:
        return f"Sum({list(self.terms_)!r})"

    def evaluate(self, t: float) -> tuple[float, float, float, float]:
        v = d = dd = integral = 0.0
        for term in self.terms_:
            tv, td, tdd, ti = term.evaluate(t)
            v += tv
            d += td
            dd += tdd
            integral += ti
        return v, d, dd, integral

    def terms(self) -> list[TimeFunction]:
        return list(self.terms_)

    def scaled(self, factor: float) -> Sum:
        return Sum(tuple(term.scaled(factor) for term in self.terms_))

    def breakpoints(self) -> tuple[float, ...]:
        return tuple(sorted({b for term in self.terms_ for b in term.breakpoints()}))

    def to_dict(self) -> dict[str, Any]:
        return {"type": "sum", "terms": [term.to_dict() for term in self.terms_]}


# ---------------------------------------------------------------------------------------------
# Parsing
# ---------------------------------------------------------------------------------------------

_DICT_KEYS: dict[str, tuple[str, ...]] = {
    "constant": ("value",),
    "ramp": ("t0", "t1", "v0", "v1"),
    "smooth_step": ("t0", "t1", "v0", "v1"),
    "table": ("times", "values"),
    "sum": ("terms",),
    "held": ("name",),
}
#: keys a mapping may give besides the required ones
_DICT_OPTIONAL: dict[str, tuple[str, ...]] = {"held": ("start", "scale")}


def as_time_function(x: Any) -> TimeFunction:
    """Convert ``x`` to a :class:`TimeFunction`.

    * a :class:`TimeFunction` is returned unchanged;
    * a real number (not bool) becomes :class:`Constant`;
    * a mapping with key ``"type"`` in ``constant`` (``value``), ``ramp`` / ``smooth_step``
      (``t0, t1, v0, v1``), ``table`` (``times, values``), ``held`` (``name``, optional
      ``start``, ``scale``), ``sum`` (``terms``: list of anything accepted here) is parsed;
      the type is case-insensitive and ``-``/space are read as ``_``. Missing or unknown
      keys raise ValueError.

    Anything else raises TypeError.
    """
    if isinstance(x, TimeFunction):
        return x
    if _is_scalar_number(x):
        return Constant(float(x))
    if isinstance(x, Mapping):
        if "type" not in x:
            raise ValueError(f"time function mapping needs a 'type' key, got keys {sorted(x)}")
        typ = str(x["type"]).strip().lower().replace("-", "_").replace(" ", "_")
        if typ == "smoothstep":
            typ = "smooth_step"
        if typ not in _DICT_KEYS:
            raise ValueError(
                f"unknown time function type {x['type']!r}; expected one of {sorted(_DICT_KEYS)}"
            )
        required = _DICT_KEYS[typ]
        given = set(x) - {"type"}
        missing = [k for k in required if k not in given]
        if missing:
            raise ValueError(f"time function of type {typ!r} is missing key(s) {missing}")
        allowed = (*required, *_DICT_OPTIONAL.get(typ, ()))
        unknown = sorted(given - set(allowed))
        if unknown:
            raise ValueError(
                f"time function of type {typ!r} has unknown key(s) {unknown}; "
                f"expected {list(allowed)}"
            )
        if typ == "constant":
            return Constant(x["value"])
        if typ == "ramp":
            return Ramp(x["t0"], x["t1"], x["v0"], x["v1"])
        if typ == "smooth_step":
            return SmoothStep(x["t0"], x["t1"], x["v0"], x["v1"])
        if typ == "table":
            return Table(x["times"], x["values"])
        if typ == "held":
            return Held(x["name"], x.get("start", 0.0), x.get("scale", 1.0))
        terms = x["terms"]
        if isinstance(terms, str | bytes | Mapping) or not isinstance(terms, Iterable):
            raise ValueError("time function of type 'sum': 'terms' must be a list")
        return Sum([as_time_function(term) for term in terms])
    raise TypeError(
        f"cannot convert {type(x).__name__} to a time function "
        "(expected a number, a TimeFunction or a mapping with a 'type' key)"
    )
