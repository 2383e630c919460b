"""The documentation site (mkdocs.yml) builds with ``mkdocs build --strict``.

Strict mode turns every warning into a failure, so this test fails on, for instance, a
``::: drivedyn.no_such_module`` block in an API page (a module renamed or moved without its
page), a link to a page that does not exist, a top-level name of ``drivedyn.__all__`` whose
object no API page documents, or a docstring ``Args:`` entry naming a parameter the function
does not have. It also fails when the API pages lose the top-level table or show Sphinx roles
verbatim (the hooks in docs/hooks). Skipped without the docs extra (pip install -e ".[docs]").
"""

import ast
import importlib.util
import os
import re
import subprocess
import sys

import pytest

from repo import REPO_ROOT

ROOT = REPO_ROOT
NEEDED = ("mkdocs", "material", "mkdocstrings", "mkdocstrings_handlers.python")


def _top_level_names() -> list[str]:
    tree = ast.parse((ROOT / "src" / "drivedyn" / "__init__.py").read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", None) == "__all__":
            return ast.literal_eval(node.value)
    raise AssertionError("drivedyn/__init__.py has no __all__")


def _missing() -> list[str]:
    missing = []
    for name in NEEDED:
        try:
            if importlib.util.find_spec(name) is None:
                missing.append(name)
        except ModuleNotFoundError:
            missing.append(name)
    return missing


def test_docs_site_builds_strict(tmp_path):
    if missing := _missing():
        pytest.skip(f"docs extra not installed ({', '.join(missing)}): pip install -e '.[docs]'")
    site = tmp_path / "site"
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}  # mkdocs-material's banner, not a warning
    proc = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
        cwd=ROOT, capture_output=True, text=True, env=env, timeout=600,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr

    for page in ("index.html", "api/index.html", "api/model/index.html",
                 "api/solver/index.html", "api/elements/index.html", "torsen_c/index.html"):
        assert (site / page).is_file(), page
    api_pages = sorted((site / "api").glob("**/index.html"))
    assert len(api_pages) > 10

    # every top-level name is in the table, linked to its documentation
    index = (site / "api" / "index.html").read_text(encoding="utf-8")
    for name in _top_level_names():
        assert re.search(rf'<a class="autorefs[^"]*"[^>]*><code>{name}</code></a>', index), name

    # docstrings' Sphinx roles became links or code
    for page in api_pages:
        text = page.read_text(encoding="utf-8")
        assert not re.search(r":(class|func|mod|meth|data):`", text), page
