"""Every element parameter has an SI unit, and every message about its value says it.

Over all element types of the ``[[elements]]`` registry (``element_types()``) and the parameter
records they nest (``NormalLaw``, ``FrictionLaw``, ``RoadPatch``, ``Material``): each float
parameter declares its unit (``"1"`` if dimensionless), the plausibility message of a huge
value names the key and the SI unit, and the range messages of ``validate()`` name the unit.
Also the unit parser for the odd dimensions these units need (N/m^1.5, Pa s, N m/rad).
"""

from __future__ import annotations

import dataclasses
import math
import re
import textwrap
import typing
from collections.abc import Callable, Iterator
from fractions import Fraction
from functools import partial
from pathlib import Path
from typing import Any

import pytest

from drivedyn import units as U  # noqa: N812
from drivedyn.config import ModelFileError, load_model, read_library_file
from drivedyn.config.elements_section import element_types, parameter_record, parameter_value
from drivedyn.elements.framework.checks import declared_unit
from drivedyn.elements.framework.registry import REGISTRY
from drivedyn.errors import ModelError
from element_cases import TANGENT_CASES

# the one registered family whose entries are not [[elements]]: bodies have their own section
NOT_ELEMENTS = {"rigid_body"}


def _is_float(hint: Any) -> bool:
    """A float parameter (``float``, ``float | None``)."""
    return hint is float or float in typing.get_args(hint)


def _float_params(cls: type) -> list[str]:
    hints = typing.get_type_hints(cls)
    return [f.name for f in dataclasses.fields(cls) if f.init and _is_float(hints[f.name])]


def _checked_params(cls: type) -> list[str]:
    """The float parameters and the other parameters with a declared unit (a force
    vector): all the values the unit checks apply to."""
    declared = getattr(cls, "units", None) or {}
    return [*_float_params(cls), *(k for k in declared if k not in _float_params(cls))]


def _records(cls: type) -> list[tuple[str, type, bool]]:
    """(field, record class, a sequence of them) of the parameter records ``cls`` takes."""
    out = []
    for f in dataclasses.fields(cls):
        rec, many = parameter_record(cls, f.name)
        if rec is not None:
            out.append((f.name, rec, many))
    return out


def _nested_dataclasses(cls: type) -> set[type]:
    """Every dataclass named in the field types of ``cls`` (found independently of
    ``parameter_record``, so that a record it would miss is seen here)."""
    found: set[type] = set()

    def walk(hint: Any) -> None:
        if isinstance(hint, type) and dataclasses.is_dataclass(hint):
            found.add(hint)
        for arg in typing.get_args(hint):
            walk(arg)

    for hint in typing.get_type_hints(cls).values():
        walk(hint)
    return found


def _label(owner: Any, key: str) -> str:
    """The SI unit a message must show for parameter ``key`` of ``owner`` (class or
    instance): dim_name of each declared dimension; "" for a dimensionless one."""
    dims = U.declared_dims(declared_unit(owner, key))
    if dims == (U.DIMENSIONLESS,):
        return ""
    return " or ".join(U.dim_name(d) for d in dims)


ELEMENTS = element_types()
RECORDS = sorted({rec for cls in ELEMENTS.values() for _, rec, _ in _records(cls)},
                 key=lambda c: c.__name__)


def test_every_family_is_reachable_from_model_files() -> None:
    """The iteration below covers every registered family: each one except the bodies has an
    element type. Fails if a family is registered without an element spec class (mutation:
    drop the ``family`` class attribute of ``SqueezeFilm``)."""
    families = {cls.family for cls in ELEMENTS.values()}
    assert set(REGISTRY) - NOT_ELEMENTS <= families, set(REGISTRY) - NOT_ELEMENTS - families


@pytest.mark.parametrize("cls", [*ELEMENTS.values(), *RECORDS], ids=lambda c: c.__name__)
def test_every_float_parameter_declares_an_si_unit(cls: type) -> None:
    """Each float parameter of each element type and nested record has a declared unit that
    parses, is SI (factor 1) and is a unit of the dimension it names; no declaration is left
    for a parameter that does not exist. Fails if a unit is removed from a ``units``
    declaration (mutation: delete ``"mu": "1"`` from ``FrictionLaw.units``, or
    ``"transition": "m"`` from ``TyreContact.units``), or if a declared unit is not SI
    (mutation: ``"radius": "mm"`` in ``PlaneContact.units``)."""
    declared = dict(getattr(cls, "units", None) or {})
    params = {f.name for f in dataclasses.fields(cls) if f.init}
    assert set(declared) <= params, f"{cls.__name__}: units for no parameter: " \
                                    f"{set(declared) - params}"
    for key in _float_params(cls):
        assert key in declared, f"{cls.__name__}.{key}: a float parameter without a unit"
        text = declared_unit(cls, key)
        for alt in text.split(" or "):
            factor, _ = U.parse_unit(alt)
            assert factor == 1.0, f"{cls.__name__}.{key}: {alt!r} is not SI"


@pytest.mark.parametrize("cls", list(ELEMENTS.values()), ids=lambda c: c.__name__)
def test_nested_records_declare_units(cls: type) -> None:
    """Every dataclass an element type takes as a parameter that has float fields is a
    parameter record (declares ``units``), so model files convert and check its values.
    Fails if a record loses its declaration (mutation: delete ``units`` of ``RoadPatch``)."""
    for rec in _nested_dataclasses(cls):
        if _float_params(rec):
            assert getattr(rec, "units", None) is not None, \
                f"{cls.__name__} takes {rec.__name__} without declared units"


def _huge_cases() -> Iterator[Any]:
    """(element class, parameter, value as written, where, key, unit owner) for each float
    parameter of each element type and of each record it nests."""
    for name, cls in ELEMENTS.items():
        fields = {f.name: f for f in dataclasses.fields(cls)}
        for key in _checked_params(cls):
            huge = 1e30 if key in _float_params(cls) else [0.0, 0.0, 1e30]  # a vector
            yield pytest.param(cls, key, huge, f"elements[3] (e).{key}", key, cls,
                               id=f"{name}.{key}")
        for fname, rec, many in _records(cls):
            for key in _checked_params(rec):
                table = {key: 1e30}
                value = [table] if many else table
                where = f"elements[3] (e).{fname}" + ("[0]" if many else "") + f".{key}"
                yield pytest.param(cls, fields[fname].name, value, where, key, rec,
                                   id=f"{name}.{fname}.{key}")


@pytest.mark.parametrize(("cls", "param", "value", "where", "key", "owner"),
                         list(_huge_cases()))
def test_huge_value_message_names_key_and_si_unit(cls: type, param: str, value: Any,
                                                  where: str, key: str, owner: type) -> None:
    """A value of 1e30 is refused as implausible, the message naming the key path and giving
    the value and the limit in the parameter's SI unit (nothing, no "1", for a dimensionless
    one). Fails if the messages print the dimensionless unit "1" or drop the unit (mutation:
    ``check_plausible`` prints ``dim_name(dim)`` for every dimension, or parameter_value checks
    undeclared-style floats as dimensionless while the unit is declared)."""
    fields = {f.name: f for f in dataclasses.fields(cls)}
    with pytest.raises(ModelError) as exc:
        parameter_value(cls, fields[param].type, param, value, "elements[3] (e)." + param)
    msg = str(exc.value)
    assert msg.startswith(f"{where}: 1e+30 "), msg
    assert "implausibly large" in msg, msg
    label = _label(owner, key)
    if label:
        assert f"1e+30 {label} is implausibly large" in msg, msg
        assert f"{label})" in msg, msg
    else:
        assert "dimensionless" in msg and "1e+30 1 " not in msg and " 1)" not in msg, msg


def _instances() -> dict[type, list[Any]]:
    """Valid specs of each element type: from the element test cases (tests/element_cases),
    else the type built from its required marker names (a base class such as ``Joint``)."""
    out: dict[type, list[Any]] = {}
    for fns in TANGENT_CASES.values():
        for fn in fns:
            for e in fn().elements:
                out.setdefault(type(e), []).append(e)
    for cls in ELEMENTS.values():
        if cls not in out:
            required = [f.name for f in dataclasses.fields(cls) if f.init
                        and f.default is dataclasses.MISSING
                        and f.default_factory is dataclasses.MISSING]
            out[cls] = [cls(**{k: k for k in required})]
    return out


@pytest.fixture(scope="module")
def instances() -> dict[type, list[Any]]:
    return _instances()


_RANGE = re.compile(r"\.(\w+): (?:must|expected|\|beta\| must)")
BAD_VALUES = (-3.0, 0.0, math.nan)


def _range_messages(spec: Any) -> Iterator[tuple[Any, str]]:
    """(owner, message) of the messages validating ``spec`` with one parameter (its own or
    a nested record's) set to -3, 0 or NaN gives, the owner being the spec or the record
    whose parameter was changed."""
    cls = type(spec)
    for key in _checked_params(cls):
        for bad in BAD_VALUES:
            msg = _validate(partial(dataclasses.replace, spec, **{key: bad}))
            if msg:
                yield spec, msg
    for fname, rec, many in _records(cls):
        current = getattr(spec, fname)
        items = list(current) if many else [current]
        for i, item in enumerate(items):
            if not isinstance(item, rec):
                continue
            for key in _checked_params(rec):
                for bad in BAD_VALUES:
                    msg = _validate(partial(_with_record, spec, fname, many, items, i,
                                            key, bad))
                    if msg:
                        yield item, msg


def _with_record(spec: Any, fname: str, many: bool, items: list[Any], i: int, key: str,
                 bad: float) -> Any:
    """``spec`` with parameter ``key`` of its record ``items[i]`` (field ``fname``) set to
    ``bad`` (a record may refuse it when built: ``Material``)."""
    new = dataclasses.replace(items[i], **{key: bad})
    value = tuple([*items[:i], new, *items[i + 1:]]) if many else new
    return dataclasses.replace(spec, **{fname: value})


def _validate(build: Callable[[], Any]) -> str:
    """The message of building and validating a spec ("" if it passes)."""
    try:
        build().validate()
    except ModelError as exc:
        return str(exc)
    return ""


@pytest.mark.parametrize("cls", list(ELEMENTS.values()), ids=lambda c: c.__name__)
def test_range_messages_name_the_si_unit(cls: type, instances: dict[type, list[Any]]) -> None:
    """``validate()`` of a valid spec with one float parameter (its own or a nested
    record's) made negative, zero or NaN: every message that refuses a parameter
    (``"<what>.<key>: must be ..."``) names that parameter's SI unit; at least one range check
    is met per element type with dimensional parameters. Fails if a check's message loses the
    unit (mutation: ``check_param`` passes ``unit=""`` to ``check_number``, or ``Joint``
    validates ``k`` with a bare ``check_number``)."""
    checked = 0
    dimensional = False
    for spec in instances[cls]:
        for owner, msg in _range_messages(spec):
            named = _RANGE.search(msg)
            if named is None:  # a message about the whole element or a relation
                continue
            param = named.group(1)
            if param not in _checked_params(type(owner)):
                continue  # another parameter refused on the way (a relation, an int)
            label = _label(owner, param)
            if label:
                dimensional = True
                assert label in msg, msg
                checked += 1
            else:
                assert "[1]" not in msg and not re.search(r"must be \S+ \S+ 1, got", msg), msg
    has_dimensional = any(
        _label(cls, k) for k in _checked_params(cls)) or any(
        _label(rec, k) for _, rec, _ in _records(cls) for k in _checked_params(rec))
    assert checked or not has_dimensional, f"{cls.__name__}: no range check met"
    assert dimensional == bool(checked)


# -- the parser and the messages ----------------------------------------------------------------


@pytest.mark.parametrize(("text", "factor", "dim", "name"), [
    ("N/m^1.5", 1.0, (Fraction(-1, 2), 1, -2, 0), "N/m^1.5"),
    ("N/mm^1.5", 1e-3**-1.5, (Fraction(-1, 2), 1, -2, 0), "N/m^1.5"),
    ("N s/m", 1.0, U.DAMPING, "N s/m"),
    ("N m/rad", 1.0, U.TORSIONAL_STIFFNESS, "N m/rad"),
    ("N m s/rad", 1.0, U.TORSIONAL_DAMPING, "N m s/rad"),
    ("Pa s", 1.0, U.VISCOSITY, "Pa s"),
    ("N s/m^2", 1.0, U.VISCOSITY, "Pa s"),
    ("N s/m^1.5", 1.0, (Fraction(-1, 2), 1, -1, 0), "N s/m^1.5"),
    ("N/m^1.37", 1.0, (Fraction(-37, 100), 1, -2, 0), "N/m^1.37"),
    ("N/m^1", 1.0, U.STIFFNESS, "N/m"),
    ("1/s", 1.0, (0, 0, -1, 0), "1/s"),
    ("Hz", 1.0, (0, 0, -1, 0), "1/s"),
    ("1", 1.0, U.DIMENSIONLESS, "1"),
    ("kg*m^2", 1.0, U.INERTIA, "kg m^2"),
    ("m^0.5", 1.0, (Fraction(1, 2), 0, 0, 0), "m^0.5"),
])
def test_parse_unit_of_odd_dimensions(text: str, factor: float, dim: U.Dim, name: str) -> None:
    """Decimal exponents, a ``1`` numerator and the derived units of contacts and films
    parse to the exact dimension, and ``dim_name`` writes them back readably in a form the
    parser reads again. Fails if exponents are read as integers only (mutation: the exponent
    pattern ``-?\\d+``) or if dim_name writes fractional powers as ``m^-0.5 kg s^-2``."""
    f, d = U.parse_unit(text)
    assert f == pytest.approx(factor, rel=1e-15)
    assert d == dim
    assert U.dim_name(d) == name
    assert U.parse_unit(U.dim_name(d)) == (1.0, d)


@pytest.mark.parametrize(("text", "match"), [
    ("N/m/s", "at most one '/'"),
    ("N/m^x", "unknown unit"),
    ("N/m^1.5.2", "unknown unit"),
    ("2 N", "unknown unit '2'"),
    ("mm^-400", "out of range"),
])
def test_parse_unit_errors(text: str, match: str) -> None:
    """Malformed units are refused with a UnitError, never another exception. Fails if the
    overflow of a huge exponent escapes (mutation: drop the OverflowError catch)."""
    with pytest.raises(U.UnitError, match=match):
        U.parse_unit(text)


def test_declared_alternatives_convert_either_dimension() -> None:
    """A parameter declared ``"N/m or N m/rad"`` takes a unit of either dimension and refuses
    others, naming both. Fails if ``to_si`` checks the first dimension only (mutation:
    ``if dim != expected``)."""
    dims = U.declared_dims("N/m or N m/rad")
    assert dims == (U.STIFFNESS, U.TORSIONAL_STIFFNESS)
    assert U.to_si("2 kN/m", *dims) == 2000.0
    assert U.to_si("3 N m/rad", *dims) == 3.0
    with pytest.raises(U.UnitError, match="'1 N' is in N, expected N/m or N m/rad"):
        U.to_si("1 N", *dims)


def test_plausibility_messages() -> None:
    """The value and the limit in the SI unit; a dimensionless value without a "1"; a
    non-finite one with its unit in brackets. Fails if the dimensionless unit prints as "1"
    (mutation: ``label = dim_name(dim)`` in ``check_plausible``)."""
    hertz = U.parse_unit("N/m^1.5")[1]
    with pytest.raises(U.UnitError) as exc:
        U.check_plausible(1e18, hertz)
    assert str(exc.value) == ("1e+18 N/m^1.5 is implausibly large (|value| <= 1e+15 "
                              "N/m^1.5): a unit mistake?")
    with pytest.raises(U.UnitError) as exc:
        U.check_plausible(1e18, U.DIMENSIONLESS)
    assert str(exc.value) == ("1e+18 is implausibly large for a dimensionless parameter "
                              "(|value| <= 1e+15): a typing mistake?")
    with pytest.raises(U.UnitError, match=r"must be finite \[N s/m\], got nan"):
        U.check_plausible(math.nan, U.DAMPING)
    with pytest.raises(U.UnitError, match=r"^must be finite, got inf$"):
        U.check_plausible(math.inf, U.DIMENSIONLESS)


# -- through a model file ---------------------------------------------------------------------

MODEL = """
[model]
name = "drop"

[[bodies]]
name = "ball"
mass = "1 kg"
inertia = [1e-4, 1e-4, 1e-4]
position = [0, 0, "10 mm"]

[[markers]]
name = "floor"
body = "ground"

[[markers]]
name = "centre"
body = "ball"

[[elements]]
type = "Prismatic"
name = "slide"
marker_a = "floor"
marker_b = "centre"

[[elements]]
type = "PlaneContact"
name = "impact"
marker_a = "floor"
marker_b = "centre"
law = { stiffness = 1e10, exponent = 1.5, restitution = 0.8 }

[solver]
t_end = "10 ms"
"""


def _load(tmp_path: Path, text: str) -> Any:
    path = tmp_path / "m.toml"
    path.write_text(textwrap.dedent(text))
    return load_model(path)


def _message(tmp_path: Path, text: str) -> str:
    with pytest.raises(ModelFileError) as exc:
        _load(tmp_path, text)
    return str(exc.value)


def test_impact_stiffness_message_in_n_per_m_to_the_exponent(tmp_path: Path) -> None:
    """The Hertz stiffness of 1e18 is refused in N/m^1.5 (not the dimensionless "1"), the
    unit following the law's exponent (N/m for exponent 1, also when the exponent is written
    after the stiffness); a unit string with the exponent converts. Fails if the stiffness
    loses its declared unit (mutation: delete ``"stiffness"`` from ``NormalLaw.units``) or
    the exponent is read after the stiffness (mutation: ``_ordered`` returns the file's
    order)."""
    msg = _message(tmp_path, MODEL.replace("stiffness = 1e10", "stiffness = 1e18"))
    assert ("elements[1] (impact).law.stiffness: 1e+18 N/m^1.5 is implausibly large "
            "(|value| <= 1e+15 N/m^1.5): a unit mistake?") in msg
    msg = _message(tmp_path, MODEL.replace("stiffness = 1e10, exponent = 1.5",
                                           "stiffness = 1e18, exponent = 1"))
    assert "law.stiffness: 1e+18 N/m is implausibly large (|value| <= 1e+15 N/m)" in msg
    msg = _message(tmp_path, MODEL.replace("stiffness = 1e10", "stiffness = -3"))
    assert "elements[1] (impact).law.stiffness: must be > 0 N/m^1.5, got -3.0" in msg
    model = _load(tmp_path, MODEL.replace("stiffness = 1e10", 'stiffness = "1e5 N/mm^1.5"'))
    assert model.spec.element("impact").law.stiffness == pytest.approx(1e5 * 1e-3**-1.5)
    msg = _message(tmp_path, MODEL.replace("stiffness = 1e10", 'stiffness = "1e5 N/mm"'))
    assert "law.stiffness: '1e5 N/mm' is in N/m, expected N/m^1.5" in msg


def test_dimensionless_and_mixed_parameters_in_model_files(tmp_path: Path) -> None:
    """A dimensionless parameter takes plain numbers only and its messages print no unit; a
    joint's scaling (one number for position and rotation rows) is refused in both units.
    Fails if a dimensionless parameter accepts a unit string (mutation: parameter_value
    converts declared "1" parameters with ``to_si``)."""
    msg = _message(tmp_path, MODEL.replace("restitution = 0.8", 'restitution = "0.8 m"'))
    assert "law.restitution: expected a plain number (this parameter takes no unit)" in msg
    msg = _message(tmp_path, MODEL.replace("restitution = 0.8", "restitution = 1e18"))
    assert "law.restitution: 1e+18 is implausibly large for a dimensionless parameter" in msg
    msg = _message(tmp_path, MODEL.replace('marker_b = "centre"\n\n[[elements]]',
                                           'marker_b = "centre"\nk = -2\n\n[[elements]]'))
    assert "elements[0] (slide).k: must be > 0 N/m or N m/rad, got -2.0" in msg


def test_library_contact_stiffness_in_n_per_m_to_the_exponent() -> None:
    """A differential file's ``contact.stiffness`` is read in the normal law's unit
    N/m^exponent: refused in it when implausible or not positive, converted from a unit
    string. Fails if the library schema checks the stiffness as a bare number again
    (mutation: ``stiffness: Annotated[float, Field(gt=0)]`` without the validator)."""
    with pytest.raises(ModelFileError) as exc:
        read_library_file("torsen-c", {"contact.stiffness": 1e18})
    assert ("contact.stiffness: 1e+18 N/m^1.5 is implausibly large (|value| <= 1e+15 "
            "N/m^1.5): a unit mistake?") in str(exc.value)
    with pytest.raises(ModelFileError) as exc:
        read_library_file("torsen-c", {"contact.stiffness": -1, "contact.exponent": 1})
    assert "contact.stiffness: must be > 0 N/m" in str(exc.value)
    p = read_library_file("torsen-c", {"contact.stiffness": "1e5 N/mm^1.5"})[0]
    assert p.contact.stiffness == pytest.approx(1e5 * 1e-3**-1.5)
