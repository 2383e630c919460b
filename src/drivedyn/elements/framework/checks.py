"""Checks of element parameters (specs and laws): one message format for every family.

Messages name the element and the field and give the bound in the parameter's SI unit,
``"<what>.<label>: must be > 0 N/m, got -1.0"``, so that a model file's author finds the value
to fix and sees the unit it is read in. The unit comes from the class's declaration
(:func:`declared_unit`), so an element states each unit once, in its ``units``.

Declared units (``units`` of a spec or record class: parameter -> SI unit) are SI unit strings
of :mod:`drivedyn.units`; ``"1"`` declares a dimensionless parameter (a friction coefficient, a
ratio), ``"N/m or N m/rad"`` one number used in either dimension, and ``{name}`` in a unit
stands for the value of parameter ``name`` of the same record, for a unit that depends on
another parameter (a contact stiffness in ``"N/m^{exponent}"``).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from decimal import Decimal
from typing import Any

import drivedyn.units as U  # noqa: N812
from drivedyn.elements.framework.building import what_of
from drivedyn.errors import ModelError

_PLACEHOLDER = re.compile(r"\{(\w+)\}")


def unit_references(cls: type) -> set[str]:
    """Parameters of ``cls`` whose values enter the declared unit of another one
    (``exponent`` for ``"N/m^{exponent}"``)."""
    out: set[str] = set()
    for text in (getattr(cls, "units", None) or {}).values():
        out |= set(_PLACEHOLDER.findall(text))
    return out


def declared_unit(owner: Any, label: str, values: Mapping[str, Any] | None = None) \
        -> str | None:
    """The SI unit the spec or record ``owner`` (a class or an instance) declares for
    parameter ``label``; None if it declares none. A ``{name}`` in it is filled with the value
    of parameter ``name``: from ``values`` (a model file's entry) if given there, else from
    ``owner`` (an instance, or the class default). A value that is not a finite number leaves
    the name in place (``"N/m^exponent"``, for messages only)."""
    cls = owner if isinstance(owner, type) else type(owner)
    text = (getattr(cls, "units", None) or {}).get(label)
    if text is None or "{" not in text:
        return text

    def fill(m: re.Match[str]) -> str:
        name = m.group(1)
        val = values[name] if values is not None and name in values else \
            getattr(owner, name, None)
        if isinstance(val, bool) or not isinstance(val, (int, float)) \
                or not math.isfinite(val):
            return name
        # positional decimal digits, as parse_unit reads exponents: 1.5, 2 (not 2.0, 1e+16)
        return format(Decimal(repr(float(val))), "f").removesuffix(".0")

    return _PLACEHOLDER.sub(fill, text)


def unit_of(owner: Any, label: str) -> str:
    """The SI unit of parameter ``label`` of ``owner`` as messages print it (``"N/m^1.5"``,
    ``"N/m or N m/rad"``); ``""`` for a dimensionless or undeclared parameter."""
    text = declared_unit(owner, label)
    if text is None:
        return ""
    try:
        return U.unit_label(*U.declared_dims(text))
    except U.UnitError:  # a placeholder left unfilled: the declaration as written
        return text


def check_number(what: str, label: str, value: Any, low: float | None = None,
                 strict: bool = False, unit: str = "") -> float:
    """``float(value)``, finite and, if ``low`` is given, ``>= low`` (``> low`` if
    ``strict``); otherwise :class:`ModelError` naming ``what.label`` and the bound in
    ``unit`` (the parameter's SI unit, ``""`` if dimensionless)."""
    try:
        val = float(value)
    except (TypeError, ValueError):
        unit_text = f" [{unit}]" if unit else ""
        raise ModelError(f"{what}.{label}: expected a number{unit_text}, got {value!r}") \
            from None
    if not math.isfinite(val) or (low is not None and (val < low or (strict and val == low))):
        if low is None:
            cond = f"finite [{unit}]" if unit else "finite"
        else:
            cond = f"{'>' if strict else '>='} {low:g}" + (f" {unit}" if unit else "")
        raise ModelError(f"{what}.{label}: must be {cond}, got {value!r}")
    return val


def check_optional(what: str, label: str, value: Any, low: float | None = None,
                   strict: bool = False, unit: str = "") -> float | None:
    """:func:`check_number` for a value that may be None (automatic, absent)."""
    return None if value is None else check_number(what, label, value, low, strict, unit)


def check_param(owner: Any, label: str, low: float | None = None, strict: bool = False,
                what: str | None = None) -> float:
    """:func:`check_number` of parameter ``label`` of the spec or record ``owner``, its
    message in the unit ``owner`` declares for it; ``what`` names the element (default:
    ``"Hinge 'h1'"``, the spec's type and name)."""
    return check_number(what_of(owner) if what is None else what, label, getattr(owner, label),
                        low, strict, unit_of(owner, label))


def check_param_optional(owner: Any, label: str, low: float | None = None,
                         strict: bool = False, what: str | None = None) -> float | None:
    """:func:`check_param` for a parameter that may be None (automatic, absent)."""
    if getattr(owner, label) is None:
        return None
    return check_param(owner, label, low, strict, what)


def range_message(owner: Any, label: str, condition: str) -> str:
    """``"must be <condition> <unit>"`` for a hand-written range check of parameter ``label``
    (``condition``: ``"in (0, 1)"``), the unit as :func:`unit_of` gives it."""
    unit = unit_of(owner, label)
    return f"must be {condition}" + (f" {unit}" if unit else "")
