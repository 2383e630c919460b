"""Checks of element parameters (specs and laws): one message format for every family.

Messages name the element and the field, ``"<what>.<label>: must be > 0, got -1.0"``, so that
a model file's author finds the value to fix.
"""

from __future__ import annotations

import math
from typing import Any

from drivedyn.errors import ModelError


def check_number(what: str, label: str, value: Any, low: float | None = None,
                 strict: bool = False) -> float:
    """``float(value)``, finite and, if ``low`` is given, ``>= low`` (``> low`` if
    ``strict``); otherwise :class:`ModelError` naming ``what.label``."""
    try:
        val = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"{what}.{label}: expected a number, got {value!r}") from None
    if not math.isfinite(val) or (low is not None and (val < low or (strict and val == low))):
        cond = "finite" if low is None else f"{'>' if strict else '>='} {low:g}"
        raise ModelError(f"{what}.{label}: must be {cond}, got {value!r}")
    return val


def check_optional(what: str, label: str, value: Any, low: float | None = None,
                   strict: bool = False) -> float | None:
    """:func:`check_number` for a value that may be None (automatic, absent)."""
    return None if value is None else check_number(what, label, value, low, strict)
