"""The ``[[elements]]`` section of model files: any registered element type by its class
name, each parameter checked against the element spec's dataclass field (its type) and the
unit the element class declares in ``units`` (parameter -> SI unit string)."""

from __future__ import annotations

import dataclasses
import functools
import typing
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
    kwargs: dict[str, Any] = {}
    for k in _ordered(cls, params):
        v = params[k]
        if k == "function" or k.endswith("_function"):
            kwargs[k] = function(v, where)
        else:
            kwargs[k] = parameter_value(cls, fields[k].type, k, v, f"{where}.{k}", kwargs)
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


def _ordered(cls: type, params: dict[str, Any]) -> list[str]:
    """The keys of ``params`` with those other parameters' units refer to first (the
    exponent of a contact law before its stiffness in N/m^exponent)."""
    from drivedyn.elements.framework.checks import unit_references

    first = unit_references(cls)
    return sorted(params, key=lambda k: k not in first)


def parameter_value(cls: type, ftype: Any, key: str, value: Any, where: str,
                    done: dict[str, Any] | None = None) -> Any:
    """``value`` of parameter ``key`` of element class ``cls`` checked against its field type
    (``int``, ``float``, ``bool``, ``str``, a nested parameter record such as ``NormalLaw``, a
    list of records) and converted to SI with the unit the class declares in ``units`` (a
    unit string of another dimension, or on a dimensionless parameter, is refused; a value
    too large for the unit is refused with the unit in the message). ``done``: the entry's
    parameters converted so far (a unit such as ``"N/m^{exponent}"`` takes its exponent from
    there, else from the class default)."""
    import drivedyn.units as U  # noqa: N812
    from drivedyn.elements.framework.checks import declared_unit

    tname = ftype if isinstance(ftype, str) else getattr(ftype, "__name__", str(ftype))
    kinds = {t.strip() for t in tname.split("|")}
    optional = "None" in kinds
    if value is None and optional:
        return None
    unit = declared_unit(cls, key, done)
    try:
        dims = None if unit is None else U.declared_dims(unit)
    except U.UnitError as exc:  # an exponent the unit cannot take (its own check says why)
        raise ModelError(f"{where}: {exc}") from None
    if dims is not None and dims != (U.DIMENSIONLESS,):
        # a quantity (or a vector of them) in the declared unit
        try:
            if isinstance(value, list):
                out = [U.to_si(v, *dims) for v in value]
                for x in out:
                    U.check_plausible(x, *dims)
                return out
            x = U.to_si(value, *dims)
            U.check_plausible(x, *dims)
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
    if "float" in kinds:  # dimensionless (declared "1"): a plain number
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
    # a nested parameter record (NormalLaw, FrictionLaw) or a list of them (road patches):
    # their own keys, units and types
    record, many = parameter_record(cls, key)
    if record is not None and many and isinstance(value, list):
        return [_record_value(record, v, f"{where}[{i}]") if isinstance(v, dict) else v
                for i, v in enumerate(value)]
    if record is not None and not many and isinstance(value, dict):
        return _record_value(record, value, where)
    return value  # anything else goes to the element, which checks it


def _record_value(record: type, value: dict[str, Any], where: str) -> dict[str, Any]:
    """A table given for a parameter record: its keys checked, each value converted."""
    rfields = {f.name: f for f in dataclasses.fields(record) if f.init}
    unknown = sorted(set(value) - set(rfields))
    if unknown:
        raise ModelError(f"{where}: unknown key(s) {', '.join(unknown)} for "
                         f"{record.__name__}{did_you_mean(unknown[0], rfields)} (keys: "
                         f"{', '.join(rfields)})")
    out: dict[str, Any] = {}
    for k in _ordered(record, value):
        out[k] = parameter_value(record, rfields[k].type, k, value[k], f"{where}.{k}", out)
    return {k: out[k] for k in value}  # the file's order


def parameter_record(cls: type, key: str) -> tuple[type | None, bool]:
    """The parameter record class (a dataclass declaring its ``units``: ``NormalLaw``,
    ``RoadPatch``) that parameter ``key`` of ``cls`` takes, and whether it takes a sequence
    of them (``tuple[RoadPatch, ...]``); (None, False) for other parameters."""
    hint = _hints(cls).get(key)
    many = typing.get_origin(hint) in (tuple, list)
    args = typing.get_args(hint) if many else (hint,)
    for arg in args:
        for t in typing.get_args(arg) or (arg,):  # the members of a union
            if isinstance(t, type) and dataclasses.is_dataclass(t) \
                    and getattr(t, "units", None) is not None:
                return t, many
    return None, False


@functools.cache
def _hints(cls: type) -> dict[str, Any]:
    """Resolved type hints of a spec or record class (cached: they never change)."""
    return typing.get_type_hints(cls)
