"""Messages of model files: :class:`ModelFileError` and the one-line-per-problem text of a
pydantic validation error (key path with list items by name, value, expectation, and a
"did you mean" hint for a misspelt key)."""

from __future__ import annotations

import typing
from typing import Any

from pydantic import BaseModel, ValidationError

from drivedyn.errors import did_you_mean


class ModelFileError(ValueError):
    """A model file that cannot be read or validated; the message lists every problem with
    its key path, the bad value and what was expected."""


def _path(data: Any, loc: tuple) -> str:
    out = ""
    node = data
    for part in loc:
        if isinstance(part, int):
            name = node[part].get("name") if isinstance(node, list) and part < len(node) \
                and isinstance(node[part], dict) else None
            out += f"[{part}]" + (f" ({name})" if name else "")
        else:
            out += ("." if out else "") + str(part)
        try:
            node = node[part]
        except (KeyError, IndexError, TypeError):
            node = None
    return out


def _allowed_keys(schema: type[BaseModel] | None, loc: tuple) -> list[str]:
    """The keys the schema section at ``loc[:-1]`` accepts (for "did you mean")."""
    models: list[Any] = [schema] if schema is not None else []
    for part in loc[:-1]:
        if isinstance(part, int):
            continue
        nxt: list[Any] = []
        for m in models:
            f = m.model_fields.get(part) if isinstance(m, type) and issubclass(m, BaseModel) \
                else None
            if f is not None:
                nxt += _models_in(f.annotation)
        models = nxt or models
    keys: list[str] = []
    for m in models:
        if isinstance(m, type) and issubclass(m, BaseModel):
            keys += list(m.model_fields)
    return keys


def _models_in(annotation: Any) -> list[Any]:
    """Pydantic model classes inside an annotation (unions, lists, dicts, Annotated)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    out: list[Any] = []
    for arg in typing.get_args(annotation):
        out += _models_in(arg)
    return out


#: location parts pydantic adds for the members of a union
_UNION_TAGS = ("float", "str", "none", "int", "bool", "Rotation", "FixedStepFile",
               "AdaptiveStepFile")


def _union_tag(part: str) -> bool:
    return part in _UNION_TAGS or part.startswith(("tuple[", "list[", "dict[",
                                                   "function-", "nullable["))


def format_validation_error(source: str, data: dict, exc: ValidationError,
                            schema: type[BaseModel] | None = None,
                            element_labels: list[str] | None = None) -> str:
    """One line per problem: ``key.path: what was expected (got value)``; unknown keys get
    the closest known key of their section. ``element_labels``: how to name each
    ``elements`` entry (entries translated from a deprecated section by that section)."""
    lines = [f"{source}: {exc.error_count()} problem(s)"]
    for err in exc.errors():
        loc = tuple(p for p in err["loc"] if p not in ("function-after", "function-before"))
        # discriminated unions (solver.step) add their tag ("fixed", "adaptive") to the path
        loc = tuple(p for i, p in enumerate(loc)
                    if not (i and loc[i - 1] == "step" and p in ("fixed", "adaptive")))
        # union members appear as extra location parts ("float", "tuple[...]"); keep the
        # user's keys only (a key may start like one: "strategy")
        loc = tuple(p for p in loc if isinstance(p, int) or not _union_tag(str(p)))
        msg = err["msg"]
        for prefix in ("Value error, ", "Assertion failed, "):
            if msg.startswith(prefix):
                msg = msg[len(prefix):]
        if err["type"] == "extra_forbidden":
            msg = "unknown key" + (did_you_mean(str(loc[-1]), _allowed_keys(schema, loc))
                                   or " (misspelt?)")
        elif err["type"] == "missing":
            msg = "required key is missing"
        path = _path(data, loc) or "(top level)"
        if element_labels and len(loc) > 1 and loc[0] == "elements" \
                and isinstance(loc[1], int) and loc[1] < len(element_labels):
            path = element_labels[loc[1]] + path[len(_path(data, loc[:2])):]
        got = "" if err["type"] == "missing" else f" (got {err.get('input')!r})"
        lines.append(f"  {path}: {msg}{got}")
    return "\n".join(lines)


# -- building ----------------------------------------------------------------------------
