"""MkDocs hook: the table of drivedyn's top-level names on the first API reference page.

``drivedyn/__init__.py`` exports its public names lazily (``_EXPORTS``, PEP 562), which the
static analysis behind mkdocstrings cannot follow. This hook replaces the marker line
``<!-- drivedyn-exports -->`` of a page with a table of every name of ``drivedyn.__all__``,
linked to where that name is documented. A name whose documentation is missing from the
API pages is an unresolved cross-reference, which ``mkdocs build --strict`` refuses.
"""

from __future__ import annotations

import ast
from pathlib import Path
from typing import Any

MARKER = "<!-- drivedyn-exports -->"


def _literal(tree: ast.Module, name: str) -> Any:
    for node in tree.body:
        target = (node.targets[0] if isinstance(node, ast.Assign) else
                  node.target if isinstance(node, ast.AnnAssign) else None)
        if isinstance(target, ast.Name) and target.id == name:
            return ast.literal_eval(node.value)
    raise LookupError(f"drivedyn/__init__.py defines no {name}")


def exports_table(src: Path) -> str:
    """Markdown table: top-level name -> module it is imported from, linked to its docs."""
    tree = ast.parse((src / "drivedyn" / "__init__.py").read_text(encoding="utf-8"))
    exports: dict[str, str] = _literal(tree, "_EXPORTS")
    rows = ["| name | imported from |", "|---|---|"]
    for name in sorted(_literal(tree, "__all__"), key=str.lower):
        module = exports[name]
        ident = f"{module}.{name}"
        # `from drivedyn.solver.simulate import simulate` in a package: the static analysis
        # sees the submodule under that name, and the object is documented inside it
        folder = src.joinpath(*module.split("."))
        if (folder / f"{name}.py").is_file() or (folder / name / "__init__.py").is_file():
            ident = f"{ident}.{name}"
        rows.append(f"| [`{name}`][{ident}] | `{module}` |")
    return "\n".join(rows)


def on_page_markdown(markdown: str, page: Any, config: Any, files: Any) -> str:
    if MARKER not in markdown:
        return markdown
    src = Path(config.config_file_path).parent / "src"
    return markdown.replace(MARKER, exports_table(src))
