"""Building an FMI 2.0 co-simulation FMU of a drivedyn model with pythonfmu
(``FmuBuilder.build_FMU``): a small generated script declares the FMU's class (a subclass of
:class:`~drivedyn.fmu.slave.DrivedynSlave`, named after the FMU file), and the FMU carries
the model file's text and the ``--set`` overrides in its resources
(:mod:`drivedyn.fmu.resources`). The FMU imports drivedyn where it runs: the script says so
in the error it raises at instantiation when drivedyn cannot be imported.
"""

from __future__ import annotations

import json
import re
import sys
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from drivedyn.errors import ModelError
from drivedyn.fmu.kinds import FMU_KINDS, REFERENCES, cosim
from drivedyn.fmu.resources import META_FILE, MODEL_FILE


class FmuError(ModelError):
    """A model that has no FMU interface, or an FMU that cannot be built."""


_SCRIPT = '''"""FMI 2.0 co-simulation FMU of the drivedyn model {name!r}, built by `drivedyn fmu`.

It runs drivedyn, which must be installed in the Python that loads it:
    pip install "drivedyn[fmu]"
"""

# pythonfmu's loader releases a reference to this module's namespace that it does not hold
# each time it instantiates the FMU, after running this file in that namespace: two more at
# each run keep the namespace alive (freed, the next instantiation in the process crashed)
globals().setdefault("_namespace_refs", []).extend([globals()] * 2)

try:
    from drivedyn.fmu.slave import DrivedynSlave
except ImportError as exc:
    import sys as _sys

    raise ImportError(
        "this FMU ({name}) runs drivedyn, which the Python that loads it cannot import "
        f"({{exc}}); install drivedyn in that Python ({{_sys.executable}}, Python "
        f"{{_sys.version_info[0]}}.{{_sys.version_info[1]}}): pip install 'drivedyn[fmu]'"
    ) from exc


class {identifier}(DrivedynSlave):
    """{title}"""
'''


def model_identifier(out: str | Path) -> str:
    """The FMU's model identifier (its class and binary name) from its file name: the stem
    with every character that is not a letter, digit or underscore made ``_``."""
    ident = re.sub(r"\W", "_", Path(out).stem, flags=re.ASCII)
    return ident if ident[:1].isalpha() else f"fmu_{ident}"


def fmu_kind(model: str | Path, overrides: Mapping[str, Any]) -> tuple[str, Any]:
    """(kind, co-simulation interface) of a model file or shipped model name, validated.

    Raises:
        FmuError: a model without an FMU interface (a plain model file, a vehicle).
        ModelFileError, ModelError: a model file or overrides that do not validate.
    """
    from drivedyn.config.loader import _read_data, library_of

    data, source = _read_data(model, dict(overrides))
    lib = library_of(data)
    if lib not in FMU_KINDS:
        what = "a plain bodies-and-elements model" if lib is None else f"model.library = {lib!r}"
        raise FmuError(f"{source}: {what} has no FMU interface (models with one: "
                       f"{', '.join(k.replace('_', '-') for k in FMU_KINDS)})")
    return FMU_KINDS[lib], cosim(FMU_KINDS[lib], model, overrides)


def _carry_references(folder: Path, model: str | Path, kind: str, params: Any,
                      overrides: dict) -> dict:
    """Copy the files the model file names by a path relative to its folder
    (:data:`~drivedyn.fmu.kinds.REFERENCES`) into ``folder``; returns the overrides with
    those keys naming the copies (read relative to the FMU's resources)."""
    import shutil

    from drivedyn.config.loader import resolve_path

    base = resolve_path(model).parent
    out = dict(overrides)
    for key in REFERENCES.get(kind, ()):
        value: Any = params
        for part in key.split("."):
            value = getattr(value, part)
        path = base / str(value)
        if not Path(str(value)).is_absolute() and path.is_file():
            shutil.copyfile(path, folder / path.name)
            out[key] = path.name
    return out


def _write_resources(folder: Path, model: str | Path, kind: str, overrides: dict,
                     source: str) -> Path:
    """Write the model file's text and the FMU record into ``folder``; returns it."""
    from drivedyn.config.loader import resolve_path
    from drivedyn.solver.simulation import _version

    text = resolve_path(model).read_bytes().decode("utf-8")
    (folder / MODEL_FILE).write_text(text, encoding="utf-8")
    meta = {"kind": kind, "model": Path(str(model)).stem, "source": source,
            "overrides": overrides, "drivedyn_version": _version()}
    (folder / META_FILE).write_text(json.dumps(meta, indent=1, default=str), encoding="utf-8")
    return folder


def parse_overrides(sets: Sequence[str] | Mapping[str, Any]) -> dict[str, Any]:
    """``["key=value", ...]`` (``--set``) or a mapping -> {dotted key: value}."""
    from drivedyn.config.overrides import parse_override

    if isinstance(sets, Mapping):
        return dict(sets)
    return dict(parse_override(s) for s in sets)


def build_fmu(model: str | Path, out: str | Path,
              overrides: Sequence[str] | Mapping[str, Any] = ()) -> Path:
    """Build the FMU of ``model`` (a model file or a shipped name such as ``torsen-b``) with
    ``overrides`` applied, into ``out`` (``NAME.fmu``); returns its path.

    Raises:
        FmuError: pythonfmu missing, or a model without an FMU interface.
        ModelFileError, ModelError: a model file or overrides that do not validate.
    """
    try:
        from pythonfmu import FmuBuilder
    except ImportError:
        raise FmuError("building an FMU needs pythonfmu: pip install 'drivedyn[fmu]'") from None
    sets = parse_overrides(overrides)
    kind, interface = fmu_kind(model, sets)
    out = Path(out)
    ident = model_identifier(out)
    module = f"drivedyn_fmu_{ident}"
    with tempfile.TemporaryDirectory(prefix="drivedyn_fmu_") as tmp:
        folder = Path(tmp)
        script = folder / f"{module}.py"
        script.write_text(_SCRIPT.format(name=interface.params.model.name, identifier=ident,
                                         title=interface.title), encoding="utf-8")
        res = folder / "resources"
        res.mkdir()
        sets = _carry_references(res, model, kind, interface.params, sets)
        _write_resources(res, model, kind, sets, interface.source)
        try:
            return Path(FmuBuilder.build_FMU(script, dest=out,
                                             project_files=sorted(res.iterdir())))
        finally:  # the builder imports the script as a module and puts its folder on the path
            sys.modules.pop(module, None)
            while str(folder) in sys.path:
                sys.path.remove(str(folder))
