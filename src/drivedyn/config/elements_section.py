"""The ``[[elements]]`` section of model files: any registered element type by its class
name, each parameter checked against the element spec's dataclass field (its type) and the
unit the element class declares in ``units`` (parameter -> SI unit string)."""

from __future__ import annotations

import dataclasses
from typing import Any

from drivedyn.errors import ModelError, did_you_mean


def element_types() -> dict[str, type]:
    """Class name -> element spec class of every registered element family."""
    import drivedyn.elements as E  # noqa: N812

    out: dict[str, type] = {}
    stack = list(E.ElementSpec.__subclasses__())
    while stack:
        cls = stack.pop()
        stack += cls.__subclasses__()
        if dataclasses.is_dataclass(cls) and getattr(cls, "family", "") \
                and not cls.__name__.startswith("_"):
            out[cls.__name__] = cls
    return dict(sorted(out.items()))


def generic_element(e: Any, where: str, function: Any) -> Any:
    """An element spec from an ``[[elements]]`` entry: every parameter checked against the
    spec's dataclass field (type) and its declared unit (``units`` of the element class:
    parameter -> SI unit), so a stiffness in kg or a tooth count of 2.5 is refused here with
    its key; then the element's own ``validate()`` (a negative stiffness), its message naming
    the entry (``where``: ``"elements[2] (spring)"``) and the key."""
    types = element_types()
    cls = types.get(e.type)
    if cls is None:
        raise ModelError(f"{where}.type: unknown element type {e.type!r}"
                         f"{did_you_mean(e.type, types)} (known: {', '.join(types)})")
    params = dict(e.model_extra or {})
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    unknown = [k for k in params if k not in fields]
    if unknown:
        also = f"; also unknown: {', '.join(unknown[1:])}" if unknown[1:] else ""
        raise ModelError(f"{where}.{unknown[0]}: unknown key{did_you_mean(unknown[0], fields)} "
                         f"({e.type} parameters: "
                         f"{', '.join(k for k in fields if k != 'name')}{also})")
    missing = [k for k, f in fields.items() if k != "name" and k not in params
               and f.default is dataclasses.MISSING
               and f.default_factory is dataclasses.MISSING]
    if missing:
        raise ModelError(f"{where}.{missing[0]}: required key is missing ({e.type} needs "
                         f"{', '.join(missing)})")
    kwargs = {}
    for k, v in params.items():
        if k == "function" or k.endswith("_function"):
            kwargs[k] = function(v, where)
        else:
            kwargs[k] = parameter_value(cls, fields[k].type, k, v, f"{where}.{k}")
    try:
        spec = cls(name=e.name, **kwargs)
    except TypeError as exc:
        raise ModelError(f"{where}: {exc}") from None
    try:
        spec.validate()
    except (ValueError, TypeError) as exc:  # ModelError, or a value numpy cannot read
        # "SpringDamper 's'.stiffness: must be >= 0" -> "elements[1] (s).stiffness: ..."
        msg, what = str(exc), f"{type(spec).__name__} {spec.name!r}"
        raise ModelError(where + msg[len(what):] if msg.startswith(what)
                         else f"{where}: {msg}") from None
    return spec


def element_parameters(type_name: str) -> list[str] | None:
    """The keys an ``[[elements]]`` entry of element type ``type_name`` (a class name) takes,
    or None for an unknown type."""
    cls = element_types().get(type_name)
    if cls is None:
        return None
    return ["type", *(f.name for f in dataclasses.fields(cls) if f.init)]


def parameter_value(cls: type, ftype: Any, key: str, value: Any, where: str) -> Any:
    """``value`` of parameter ``key`` of element class ``cls`` checked against its field type
    (``int``, ``float``, ``bool``, ``str``, a nested parameter record such as ``NormalLaw``)
    and converted to SI with the unit the class declares in ``units`` (a unit string of
    another dimension, or on a parameter without a unit, is refused)."""
    import drivedyn.units as U  # noqa: N812

    tname = ftype if isinstance(ftype, str) else getattr(ftype, "__name__", str(ftype))
    kinds = {t.strip() for t in tname.split("|")}
    optional = "None" in kinds
    if value is None and optional:
        return None
    declared = dict(getattr(cls, "units", {}) or {})
    if key in declared:  # a quantity (or a vector of them) in the declared unit
        dim = U.parse_unit(declared[key])[1]
        try:
            if isinstance(value, list):
                out = [U.to_si(v, dim) for v in value]
                for x in out:
                    U.check_plausible(x, dim)
                return out
            x = U.to_si(value, dim)
            U.check_plausible(x, dim)
        except U.UnitError as exc:
            raise ModelError(f"{where}: {exc}") from None
        return x
    if kinds & {"int"} and not kinds & {"float"}:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ModelError(f"{where}: expected an integer, got {value!r}")
        return value
    if "bool" in kinds:
        if not isinstance(value, bool):
            raise ModelError(f"{where}: expected true or false, got {value!r}")
        return value
    if "float" in kinds:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ModelError(f"{where}: expected a plain number (this parameter takes no "
                             f"unit), got {value!r}")
        try:
            U.check_plausible(float(value), U.DIMENSIONLESS)
        except U.UnitError as exc:
            raise ModelError(f"{where}: {exc}") from None
        return float(value)
    if kinds == {"str"} or kinds == {"str", "None"}:
        if not isinstance(value, str):
            raise ModelError(f"{where}: expected a string, got {value!r}")
        return value
    # a nested parameter record (NormalLaw, FrictionLaw): its own keys, units and types
    record = _record_class(kinds)
    if record is not None and isinstance(value, dict):
        rfields = {f.name: f for f in dataclasses.fields(record) if f.init}
        unknown = sorted(set(value) - set(rfields))
        if unknown:
            raise ModelError(f"{where}: unknown key(s) {', '.join(unknown)} for "
                             f"{record.__name__}{did_you_mean(unknown[0], rfields)} (keys: "
                             f"{', '.join(rfields)})")
        return {k: parameter_value(record, rfields[k].type, k, v, f"{where}.{k}")
                for k, v in value.items()}
    return value  # anything else goes to the element, which checks it


def _record_class(kinds: set[str]) -> type | None:
    import drivedyn.elements as E  # noqa: N812

    for k in kinds:
        cls = getattr(E, k, None)
        if isinstance(cls, type) and dataclasses.is_dataclass(cls):
            return cls
    return None
