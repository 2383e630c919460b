"""Griffe extension: the reStructuredText of drivedyn's docstrings, as Markdown.

drivedyn's docstrings are Google style with a few reStructuredText habits that Markdown would
show verbatim:

* cross-reference roles (``:class:`Spec```, ``:func:`~drivedyn.solver.simulate.simulate```,
  ``:mod:`.scene```) become optional mkdocs-autorefs links: a link where the target is
  documented on the site, plain code where it is not (internals left out of the reference).
  Names are resolved as Python would see them from the docstring's object (its members, its
  module's imports and definitions); ``~`` shows the last component only, as in Sphinx;
* a literal block's ``::`` becomes ``:`` (the indented block after it is code in Markdown
  too);
* a simple table (``=====  =====`` borders) becomes a preformatted block;
* an item that describes several names at once (``marker_a, marker_b: wheel markers``)
  becomes one item per name with that description (the Google parser would read the
  second name as a type; one item per name also gets each its own type).
"""

from __future__ import annotations

import re
from typing import Any

import griffe

ROLE = re.compile(r":(?:class|func|meth|mod|data|attr|exc|obj):`(~?)([^`]+)`")
LITERAL = re.compile(r"(?m)^([ \t]*)(.*?)[ \t]*::[ \t]*$(?=\n[ \t]*\n)")
GROUPED = re.compile(r"^([ \t]+)(\w+(?:, \w+)+):(.*)$")
BORDER = re.compile(r"^\s*=+(?:[ \t]+=+)+\s*$")


def _exists(collection: Any, path: str) -> bool:
    try:
        collection[path]
    except (KeyError, ValueError):
        return False
    return True


def _target(obj: griffe.Object, name: str, collection: Any) -> str:
    if name.startswith("."):  # relative to the package (or the module's package)
        module = obj.module
        bases = [module.path] if module.is_init_module else []
        bases.append(module.path.rpartition(".")[0])
        candidates = [base + name for base in bases]
        return next((c for c in candidates if _exists(collection, c)), candidates[0])
    if name.startswith("drivedyn"):
        return name
    head, _, rest = name.partition(".")
    try:
        path = obj.resolve(head)
    except (griffe.NameResolutionError, KeyError, ValueError):
        return name
    return f"{path}.{rest}" if rest else path


def _literal(match: re.Match) -> str:
    indent, text = match[1], match[2]
    return f"{indent}{text}:" if text else ""


def _tables(text: str) -> str:
    lines = text.split("\n")
    out: list[str] = []
    i = 0
    while i < len(lines):
        if not BORDER.match(lines[i]):
            out.append(lines[i])
            i += 1
            continue
        end = i
        while end < len(lines) and lines[end].strip():
            end += 1
        indent = lines[i][: len(lines[i]) - len(lines[i].lstrip())]
        out += ["", f"{indent}```text", *lines[i:end], f"{indent}```", ""]
        i = end
    return "\n".join(out)


def _split_grouped(text: str) -> str:
    lines = text.split("\n")
    out: list[str] = []
    i = 0
    while i < len(lines):
        match = GROUPED.match(lines[i])
        if not match:
            out.append(lines[i])
            i += 1
            continue
        indent, names, description = match[1], match[2], match[3]
        end = i + 1  # the item's continuation lines are indented deeper
        while end < len(lines) and lines[end].startswith(indent + " "):
            end += 1
        for name in names.split(", "):
            out += [f"{indent}{name}:{description}", *lines[i + 1:end]]
        i = end
    return "\n".join(out)


def _rewrite(obj: griffe.Object, collection: Any) -> None:
    docstring = obj.docstring
    if docstring is None:
        return
    text = docstring.value
    if "::" in text:
        text = LITERAL.sub(_literal, text)
    if "==" in text:
        text = _tables(text)
    if ", " in text:
        text = _split_grouped(text)

    def link(match: re.Match) -> str:
        name = re.sub(r"\s+", "", match[2])
        shown = name.rpartition(".")[2] if match[1] else name
        ident = _target(obj, name, collection)
        return f'<autoref identifier="{ident}" optional><code>{shown}</code></autoref>'

    docstring.value = ROLE.sub(link, text) if ":`" in text else text


def _walk(obj: griffe.Object, collection: Any) -> None:
    _rewrite(obj, collection)
    for member in obj.members.values():
        if not member.is_alias:
            _walk(member, collection)  # type: ignore[arg-type]


class RstDocstrings(griffe.Extension):
    """Rewrite every docstring of a package once it is loaded."""

    def __init__(self) -> None:
        super().__init__()
        self._done: set[str] = set()

    def on_package(self, *, pkg: griffe.Module, loader: griffe.GriffeLoader,
                   **kwargs: Any) -> None:
        if pkg.path not in self._done:  # once: griffe 1 and 2 name the event differently
            self._done.add(pkg.path)
            _walk(pkg, loader.modules_collection)

    on_package_loaded = on_package  # griffe < 2
