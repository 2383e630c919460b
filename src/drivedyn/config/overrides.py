"""``--set KEY=VALUE`` overrides of a model file's data: parsing and applying them by
dotted key (list items by their ``name``, vector components by index)."""

from __future__ import annotations

import tomllib
from typing import Any

from drivedyn.config.messages import ModelFileError


def parse_override(text: str) -> tuple[str, Any]:
    """``"a.b.c=VALUE"`` -> (``"a.b.c"``, value); VALUE is read as a TOML value
    (``2``, ``"3 mm"``, ``[0, 0, -9.81]``) or, failing that, as a plain string."""
    key, sep, raw = text.partition("=")
    key = key.strip()
    if not sep or not key:
        raise ModelFileError(f"--set {text!r}: expected KEY=VALUE, e.g. solver.t_end=2")
    try:
        value = tomllib.loads(f"v = {raw.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw.strip()
    return key, value


def apply_override(data: dict, key: str, value: Any) -> None:
    """Set ``data[key]`` for a dotted key; list items are addressed by their ``name``
    (``bodies.crank.mass``) or index (``bodies.0.mass``), vector components by index
    (``elements.push.vector.0``)."""
    parts = key.split(".")
    node: Any = data
    for i, part in enumerate(parts[:-1]):
        where = ".".join(parts[: i + 1])
        if isinstance(node, list):
            node = _list_item(node, part, where)
        elif isinstance(node, dict):
            if part not in node:
                node[part] = {}
            node = node[part]
        else:
            raise ModelFileError(f"--set {key}: {where} is a value, not a table")
    last = parts[-1]
    if isinstance(node, list):
        # a component of a vector (``elements.push.vector.0``); whole table items stay refused
        if last.isdigit() and int(last) < len(node) and not isinstance(node[int(last)], dict):
            node[int(last)] = value
            return
        raise ModelFileError(f"--set {key}: cannot replace a whole list item")
    if not isinstance(node, dict):
        raise ModelFileError(f"--set {key}: {'.'.join(parts[:-1])} is a value, not a table")
    node[last] = value


def _list_item(items: list, part: str, where: str) -> Any:
    for it in items:
        if isinstance(it, dict) and it.get("name") == part:
            return it
    if part.isdigit() and int(part) < len(items):
        return items[int(part)]
    names = [it.get("name") for it in items if isinstance(it, dict)]
    raise ModelFileError(f"--set: no item {part!r} in {where.rsplit('.', 1)[0]} "
                         f"(names: {', '.join(map(str, names))})")


# -- validation messages -----------------------------------------------------------------
