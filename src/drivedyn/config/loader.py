"""Model files: TOML -> overrides (``--set key=value``) -> validated schema -> Spec -> Model.

``load_model(path)`` returns a compiled :class:`~drivedyn.model.model.Model` whose
``meta["scenario"]`` holds the file's solver and output settings, so that
``simulate(model)`` runs the scenario as the file describes it. Shipped model files live in
``drivedyn/models/`` and can be named without their path (``load_model("pendulum")``).
"""

from __future__ import annotations

import copy
import dataclasses
import json
import tomllib
import warnings
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel, ValidationError

from drivedyn.config import schema as S  # noqa: N812 - short name for the schema
from drivedyn.config.beams_section import add_beams
from drivedyn.config.elements_section import element_parameters, generic_element
from drivedyn.config.legacy_sections import SECTIONS as LEGACY_SECTIONS
from drivedyn.config.legacy_sections import entry_class, translate
from drivedyn.config.messages import ModelFileError, _allowed_keys, format_validation_error
from drivedyn.config.overrides import _list_item, apply_override, parse_override
from drivedyn.config.parts_section import add_parts, add_washer_contacts
from drivedyn.errors import did_you_mean
from drivedyn.model.model import Model
from drivedyn.model.spec import ModelError, Spec
from drivedyn.rotations import exp_so3
from drivedyn.schema_base import AdaptiveStepFile, Rotation


@dataclass(frozen=True)
class Scenario:
    """Solver and output settings of a model file (the arguments of ``simulate``)."""

    t_end: float
    integrator: Any
    step: Any
    newton: Any
    output_dt: float | None
    output_times: list[float] | None
    variables: list[str] | None

    def simulate_kwargs(self) -> dict[str, Any]:
        return {"integrator": self.integrator, "step": self.step, "newton": self.newton,
                "output_dt": self.output_dt, "output_times": self.output_times,
                "variables": self.variables}


def shipped_models() -> dict[str, Path]:
    """Name -> path of the model files shipped in ``drivedyn/models``."""
    folder = resources.files("drivedyn") / "models"
    out = {}
    for entry in folder.iterdir():
        if entry.name.endswith(".toml"):
            out[entry.name[:-5]] = Path(str(entry))
    return dict(sorted(out.items()))


def resolve_path(name: str | Path) -> Path:
    """A path to an existing file, or the shipped model of that name."""
    p = Path(name)
    if p.is_file():
        return p
    if p.is_dir():
        raise ModelFileError(f"{name}: is a folder, expected a model file (.toml)")
    shipped = shipped_models()
    if str(name) in shipped:
        return shipped[str(name)]
    if p.suffix == ".toml" and p.stem in shipped and not p.parent.name:
        return shipped[p.stem]
    raise ModelFileError(f"{name}: no such file, and no shipped model of that name "
                         f"(shipped: {', '.join(shipped) or 'none'})")


# -- overrides ---------------------------------------------------------------------------


def _rotation(r: Any) -> np.ndarray | None:
    if r is None:
        return None
    if isinstance(r, Rotation):
        axis = np.asarray(r.axis, float)
        n = np.linalg.norm(axis)
        if n == 0:
            raise ModelError("rotation axis must be non-zero")
        return exp_so3(axis / n * r.angle)
    return np.asarray(r, float)


def _function(f: Any, functions: dict, where: str) -> Any:
    """A time function given inline (number or table) or by the name of a ``[functions]``
    entry, converted here so that a mistake is reported with its key."""
    from drivedyn.timefunctions import as_time_function

    key = f"{where}.function"
    if isinstance(f, str):
        if f not in functions:
            raise ModelError(f"{key}: unknown function {f!r}{did_you_mean(f, functions)} "
                             f"(defined: {', '.join(functions) or 'none'})")
        key = f"functions.{f}"
        f = functions[f]
    try:
        return as_time_function(f)
    except (TypeError, ValueError) as exc:
        raise ModelError(f"{key}: {exc}") from None


def _named_function(name: str, f: Any) -> Any:
    from drivedyn.timefunctions import as_time_function

    try:
        return as_time_function(f)
    except (TypeError, ValueError) as exc:
        raise ModelError(f"functions.{name}: {exc}") from None


def build_spec(mf: S.ModelFile, base_dir: str | Path = ".") -> Spec:
    """A :class:`Spec` from a validated file (bodies, nodes, beams, markers, parts, then the
    ``[[elements]]`` in file order, then the washer contacts); ``base_dir``: folder of the
    model file (mesh files are relative to it)."""
    spec = Spec(gravity=mf.model.gravity)
    for b in mf.bodies:
        spec.add_rigid_body(b.name, b.mass, b.inertia, com=b.com, position=b.position,
                            rotation=_rotation(b.rotation), velocity=b.velocity,
                            angular_velocity=b.angular_velocity)
    for n in mf.nodes:
        spec.add_node(n.name, n.position, _rotation(n.rotation), n.velocity, n.angular_velocity)
    # beams create their nodes, which markers may sit on
    add_beams(spec, mf)
    # markers on the nodes of parts' interfaces ("washer.tip") come after the parts, which
    # need their own mounting markers first
    later = [m for m in mf.markers if m.body not in spec.bodies and m.body not in spec.nodes
             and m.body != "ground" and any(m.body.startswith(p.name + ".")
                                            for p in mf.parts)]
    for m in mf.markers:
        if m not in later:
            spec.add_marker(m.name, m.body, position=m.position,
                            rotation=_rotation(m.rotation), axis=m.axis)
    parts = add_parts(spec, mf, Path(base_dir))
    for m in later:
        spec.add_marker(m.name, m.body, position=m.position, rotation=_rotation(m.rotation),
                        axis=m.axis)
    # every named function is converted (and checked) here, used or not
    funcs = {name: _named_function(name, f) for name, f in mf.functions.items()}
    for element in file_elements(mf, funcs):
        spec.add(element)
    add_washer_contacts(spec, mf, parts)
    return spec


def file_elements(mf: S.ModelFile, funcs: dict[str, Any],
                  problems: list[str] | None = None) -> list[Any]:
    """The element specs of the file's ``[[elements]]`` entries (those translated from the
    deprecated sections first), each parameter checked against its element class; a
    :class:`ModelError` naming the entry and key, or with ``problems`` given, every entry's
    problem appended there (and the entry left out)."""
    out = []
    for i, e in enumerate(mf.elements):
        try:
            out.append(generic_element(e, mf.element_label(i),
                                       lambda v, w: _function(v, funcs, w)))
        except ModelError as exc:
            if problems is None:
                raise
            problems.append(str(exc))
    return out


def scenario_of(mf: S.ModelFile) -> Scenario:
    from drivedyn.solver.settings import AdaptiveStep, FixedStep, GeneralizedAlpha, Newton

    st = mf.solver.step
    if isinstance(st, AdaptiveStepFile):
        step = AdaptiveStep(st.h0, st.h_min, st.h_max, st.rtol, st.atol, atol_rot=st.atol_rot)
    else:
        step = FixedStep(st.h)
    nw = mf.solver.newton
    return Scenario(
        t_end=mf.solver.t_end,
        integrator=GeneralizedAlpha(mf.solver.rho_inf),
        step=step,
        newton=Newton(nw.strategy, nw.tol, nw.phi_tol, nw.max_iter),
        output_dt=mf.output.dt,
        output_times=mf.output.times,
        variables=mf.output.variables,
    )


def _read_data(path: str | Path, overrides: list[str] | dict[str, Any] | None
               ) -> tuple[dict, str]:
    p = resolve_path(path)
    source = str(path)
    try:
        text = p.read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ModelFileError(f"{source}: not UTF-8 text (byte 0x{exc.object[exc.start]:02x} at "
                             f"offset {exc.start}); save the model file as UTF-8") from None
    except OSError as exc:
        raise ModelFileError(f"{source}: cannot be read ({exc.strerror or exc})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelFileError(f"{source}: not valid TOML: {exc}") from None
    data = copy.deepcopy(data)
    items = overrides.items() if isinstance(overrides, dict) else \
        [parse_override(o) for o in (overrides or [])]
    for k, v in items:
        apply_override(data, k, v)
    return data, source


def library_of(data: dict) -> str | None:
    """The parametric library model a file describes (``[model] library = ...``), or None
    for a plain bodies-and-elements file."""
    model = data.get("model")
    return model.get("library") if isinstance(model, dict) else None


def read_model_file(path: str | Path, overrides: list[str] | dict[str, Any] | None = None,
                    ) -> tuple[S.ModelFile, dict, str]:
    """Read, override and validate a model file: (schema object, raw data, source name).

    Every ``[[elements]]`` entry is checked against its element class (parameters, units,
    the element's ``validate()``); a :class:`ModelFileError` lists every problem. A file
    with deprecated element sections (``[[joints]]``...) issues one ``DeprecationWarning``
    per section (also in the schema object's ``notes``).
    """
    data, source = _read_data(path, overrides)
    if library_of(data) is not None:
        raise ModelFileError(f"{source}: a parametric {library_of(data)!r} model file; read it "
                             "with read_library_file or load_model")
    mf = _plain_file(data, source)
    # the elements' parameters, checked against their element classes: every problem at once
    from drivedyn.timefunctions import Constant

    problems: list[str] = []
    funcs = {}
    for name, f in mf.functions.items():
        try:
            funcs[name] = _named_function(name, f)
        except ModelError as exc:
            problems.append(str(exc))
            funcs[name] = Constant(0.0)  # reported once, not again where it is used
    file_elements(mf, funcs, problems)
    if problems:
        raise ModelFileError(_problems(source, problems))
    for note in mf.notes:
        warnings.warn(note, DeprecationWarning, stacklevel=3)  # at load_model's caller
    return mf, data, source


def _problems(source: str, problems: list[str]) -> str:
    return "\n".join([f"{source}: {len(problems)} problem(s)", *(f"  {p}" for p in problems)])


def _plain_file(data: dict, source: str) -> S.ModelFile:
    """The validated schema of a plain bodies-and-elements file, its deprecated element
    sections translated into ``[[elements]]`` entries first (see
    :mod:`drivedyn.config.legacy_sections`; their deprecation notes in ``notes``)."""
    tr = translate(data)
    if tr.problems:
        raise ModelFileError(_problems(source, tr.problems))
    try:
        mf = S.ModelFile.model_validate(tr.data)
    except ValidationError as exc:
        raise ModelFileError(format_validation_error(source, tr.data, exc, S.ModelFile,
                                                     tr.labels)) from None
    mf.set_origin(tr.labels, tr.notes(source))
    return mf


def _library_schemas() -> dict[str, type]:
    """Library key -> model-file schema of every library model (imports them all)."""
    return {k: _library_schema(k) for k in _library_keys()}


def _library_keys() -> list[str]:
    """Every library key (``"torsen_c"``, ``"vehicle_rwd"``...), nothing imported."""
    from drivedyn.library import differentials, vehicles

    return [*differentials.TYPES, *vehicles.TYPES]


def _library_schema(lib: Any) -> type[BaseModel] | None:
    """The model-file schema of library key ``lib`` (None: not a library key), importing
    that library model only: a differential's file does not import the vehicles (0.7 s of
    every `drivedyn tdr`, measured)."""
    from drivedyn.library import differentials, vehicles

    if not isinstance(lib, str):
        return None
    if lib in differentials.TYPES:
        return differentials.get(lib).schema
    if lib in vehicles.TYPES:
        return vehicles.get(lib).SCHEMA
    return None


def read_library_file(path: str | Path, overrides: list[str] | dict[str, Any] | None = None,
                      ) -> tuple[Any, dict, str]:
    """Read, override and validate a parametric model file (``[model] library``, e.g. the
    shipped ``torsen-c`` or ``vehicle-4wd``): (parameters, raw data, source name)."""
    data, source = _read_data(path, overrides)
    lib = library_of(data)
    schema = _library_schema(lib)
    if schema is None:
        raise ModelFileError(f"{source}: model.library = {lib!r}: expected one of "
                             f"{', '.join(_library_keys())}")
    try:
        params = schema.model_validate(data)
    except ValidationError as exc:
        raise ModelFileError(format_validation_error(source, data, exc, schema)) from None
    return params, data, source


def _sibling(name: str, base: Path) -> str | Path:
    """A model named by another file: a shipped name, or a path relative to ``base``."""
    p = Path(name)
    if str(name) in shipped_models() or p.is_absolute():
        return name
    return base / p


def read_vehicle_differentials(params: Any, source: str, base: Path) -> dict[str, Any]:
    """The validated and checked TORSEN parameter files a vehicle's positions use
    (``differentials.torsen_c``, ``differentials.torsen_b``), errors naming the vehicle's
    key."""
    from drivedyn.library import differentials

    out: dict[str, Any] = {}
    d = params.differentials
    kinds = {getattr(d, pos, None) for pos in ("central", "front", "rear")}
    for kind in sorted(kinds & {"torsen-c", "torsen-b"}):
        key = kind.replace("-", "_")
        name = getattr(d, key)
        try:
            out[kind], _, _ = read_library_file(_sibling(name, base))
        except ModelFileError as exc:
            raise ModelFileError(f"{source}: differentials.{key} = {name!r}: {exc}") from None
        lib = out[kind].model.library
        if lib != key:
            raise ModelFileError(f"{source}: differentials.{key} = {name!r}: expected a "
                                 f"{key} model file, got model.library = {lib!r}")
        try:
            differentials.get(kind).check(out[kind])
        except ModelError as exc:
            raise ModelFileError(f"{source}: differentials.{key} = {name!r}: {exc}") from None
        if getattr(out[kind].flexible, "shafts", False):
            raise ModelFileError(f"{source}: differentials.{key} = {name!r}: flexible.shafts "
                                 "= true: expected false in a vehicle (the vehicle's own "
                                 "propeller and half shafts connect to the output gears)")
    return out


def _schema_of(data: dict) -> type[BaseModel]:
    lib = library_of(data)
    if not isinstance(lib, str):  # none (a plain file), or not a name: refused when read
        return S.ModelFile
    return _library_schema(lib) or S.ModelFile


def validate_file(path: str | Path, overrides: list[str] | dict[str, Any] | None = None
                  ) -> tuple[Any, str | None]:
    """Read and validate any model file: (schema object, its ``model.library`` or None for a
    plain bodies-and-elements file). Raises :class:`ModelFileError`."""
    data, _ = _read_data(path, overrides)
    lib = library_of(data)
    if lib is None:
        return read_model_file(path, overrides)[0], None
    return read_library_file(path, overrides)[0], lib


def check_override_keys(path: str | Path, overrides: dict[str, Any],
                        option: str = "--set") -> None:
    """Refuse keys that the model file's schema does not know, naming the key and the closest
    known one (values are not judged here: an impossible value of one point of a sweep is that
    point's failure, not a bad command).

    Raises :class:`ModelFileError` naming ``option`` and the key.
    """
    base, source = _read_data(path, None)
    schema = _schema_of(base)
    for key, value in overrides.items():
        data = copy.deepcopy(base)
        try:
            apply_override(data, key, value)
        except ModelFileError as exc:
            raise ModelFileError(f"{option} {key}: {str(exc).split(': ', 1)[-1]}") from None
        if schema is S.ModelFile:
            _check_element_key(data, key, source, option)
            tr = translate(data)
            if tr.problems:
                raise ModelFileError(f"{option} {key}: {tr.problems[0]}")
            data = tr.data
        try:
            schema.model_validate(data)
        except ValidationError as exc:
            for e in exc.errors():
                if e["type"] == "extra_forbidden":
                    loc = tuple(p for p in e["loc"] if not isinstance(p, int))
                    hint = did_you_mean(str(loc[-1]), _allowed_keys(schema, e["loc"]))
                    raise ModelFileError(f"{option} {key}: {source} has no key "
                                         f"{'.'.join(map(str, loc))!r}{hint}") from None


def _check_element_key(data: dict, key: str, source: str, option: str) -> None:
    """Refuse a key of an element entry (``elements.NAME.KEY``, or of a deprecated section:
    ``springs.NAME.KEY``) that its element class does not take."""
    parts = key.split(".")
    section = parts[0]
    if len(parts) < 3 or (section != "elements" and section not in LEGACY_SECTIONS) \
            or not isinstance(data.get(section), list):
        return
    try:
        item = _list_item(data[section], parts[1], section)
    except ModelFileError:
        return
    known = element_parameters(entry_class(section, item) or "")
    if known is not None and parts[2] not in known:
        raise ModelFileError(f"{option} {key}: {source} has no key "
                             f"{section + '.' + parts[2]!r}{did_you_mean(parts[2], known)} "
                             f"({entry_class(section, item)} keys: {', '.join(known)})")


def read_value(path: str | Path, key: str, overrides: dict[str, Any] | None = None) -> Any:
    """The value of a dotted key in a model file (list items by name): the file's own text
    (``"28 deg"`` stays a string) or, for a key the file leaves at its default, the
    validated value (SI).

    Raises :class:`ModelFileError` for a key that names nothing.
    """
    data, source = _read_data(path, overrides)
    node: Any = data
    parts = key.split(".")
    for i, part in enumerate(parts):
        if isinstance(node, list):
            try:
                node = _list_item(node, part, ".".join(parts[: i + 1]))
            except ModelFileError:
                node = None
                break
        elif isinstance(node, dict) and part in node:
            node = node[part]
        else:
            node = None
            break
    if node is not None and not isinstance(node, (dict, list)):
        return node
    if node is None:  # not in the file: the schema's default, if the key exists
        schema = _schema_of(data)
        if schema is S.ModelFile:
            obj: Any = _plain_file(data, source)
        else:
            try:
                obj = schema.model_validate(data)
            except ValidationError as exc:
                raise ModelFileError(format_validation_error(source, data, exc,
                                                             schema)) from None
        for part in parts:
            if not hasattr(obj, part):
                obj = None
                break
            obj = getattr(obj, part)
        if obj is not None and not isinstance(obj, (BaseModel, dict, list, tuple)):
            return obj
    raise ModelFileError(f"{source}: {key!r} does not name a single value of the model file")


def load_model(path: str | Path, overrides: list[str] | dict[str, Any] | None = None) -> Model:
    """Compile the model of a TOML file (path or shipped name), with ``--set``-style
    overrides (``["solver.t_end=2", "bodies.rod.mass=2 kg"]`` or a dict).

    Raises :class:`ModelFileError` for unreadable or invalid files and
    :class:`~drivedyn.model.spec.ModelError` for physically impossible models. The model's
    ``meta["notes"]`` holds one line per deprecated section of the file (also issued as a
    ``DeprecationWarning``).
    """
    from drivedyn.model.compile import compile_model

    data, _ = _read_data(path, overrides)
    if library_of(data) is not None:
        return _load_library_model(path, overrides)
    mf, data, source = read_model_file(path, overrides)
    try:
        model = compile_model(build_spec(mf, resolve_path(path).parent))
    except ModelError as exc:
        raise ModelError(f"{source}: {exc}") from None
    model.meta["scenario"] = scenario_of(mf)
    model.meta["source"] = source
    model.meta["model_file"] = json.dumps(data, indent=1, default=str)
    model.meta["model_name"] = mf.model.name
    # one line each about the file (deprecated sections), printed by `drivedyn run`
    model.meta["notes"] = mf.notes
    return model


def _load_library_model(path: str | Path, overrides) -> Model:
    """A parametric file's scenario (``[scenario] kind`` of a differential, or a vehicle) as
    a compiled model."""
    from drivedyn.library import differentials, vehicles
    from drivedyn.library.differentials import scenarios
    from drivedyn.model.compile import compile_model

    params, data, source = read_library_file(path, overrides)
    lib = params.model.library
    if lib in vehicles.TYPES:
        base = resolve_path(path).parent
        torsen = read_vehicle_differentials(params, source, base)
        try:
            mod = vehicles.get(lib)
            spec, layout = mod.build_spec(params, torsen, base)
            model = compile_model(spec)
            start = getattr(mod, "INITIAL_STATE", None)
            if start is not None:  # e.g. the static equilibrium the run starts from
                model = dataclasses.replace(
                    model, state0=start(params, torsen, base, model, layout))
        except ModelError as exc:
            raise ModelError(f"{source}: {exc}") from None
        model.meta["scenario"] = Scenario(
            t_end=params.run.t_end, **params.solver.settings(h_max=params.run.h_max),
            output_dt=params.solver.output_dt, output_times=None, variables=None)
        model.meta["layout"] = layout
    else:
        diff = differentials.of(params)
        side = params.scenario.modes or diff.sides[0]
        if params.scenario.kind == "bench" and side not in diff.sides:
            raise ModelFileError(f"{source}: scenario.modes = {side!r}: expected the output "
                                 f"the bench loads, one of {', '.join(diff.sides)}")
        try:
            if params.scenario.kind == "bench":
                spec, _ = scenarios.bench_spec(diff, params, side)
                t_end = params.bench.t_end
                settings = params.solver.settings()
            else:
                spec, _, t_end = scenarios.vehicle_spec(diff, params)
                settings = scenarios.vehicle_settings(params)
            model = compile_model(spec)
        except ModelError as exc:
            raise ModelError(f"{source}: {exc}") from None
        model.meta["scenario"] = Scenario(
            t_end=t_end, **settings,
            output_dt=params.solver.output_dt, output_times=None, variables=None)
    model.meta["source"] = source
    model.meta["model_file"] = json.dumps(data, indent=1, default=str)
    model.meta["model_name"] = params.model.name
    model.meta["notes"] = list(getattr(model.meta.get("layout"), "notes", []))
    model.meta["library"] = params
    model.meta["library_model"] = lib
    model.meta["configuration"] = (vehicles.configuration(params) if lib in vehicles.TYPES
                                   else differentials.configuration(params))
    return model
