"""The shape of the package: layers that import only downward, no import circle, no test
fixtures in the package, a CLI whose every command shows an example.

The layer order and the acyclicity rule are the import-linter contracts in pyproject.toml
(``[tool.importlinter]``); this test runs ``lint-imports`` on them, so an upward import or a
circle anywhere (between subpackages or between sibling modules inside one) fails here.
"""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from repo import REPO_ROOT

PACKAGE = REPO_ROOT / "src" / "drivedyn"


def _lint_imports() -> str | None:
    """import-linter's ``lint-imports``: the one installed with this interpreter (next to
    ``sys.executable``, whatever the PATH), else the one on the PATH, else None."""
    beside = Path(sys.executable).with_name("lint-imports")
    if beside.is_file():
        return str(beside)
    return shutil.which("lint-imports")


def test_import_contracts() -> None:
    exe = _lint_imports()
    if exe is None:
        pytest.skip("lint-imports (import-linter) is neither next to "
                    f"{sys.executable} nor on the PATH (pip install -e '.[test]')")
    proc = subprocess.run([exe, "--config", str(REPO_ROOT / "pyproject.toml")], cwd=REPO_ROOT,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "0 broken" in proc.stdout


def _imports(path: Path) -> set[str]:
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            out.add(node.module)
    return out


def test_package_imports_no_test_code() -> None:
    """Test fixtures (tangent, gear and contact case tables, FD helpers) live under tests/;
    nothing shipped imports them."""
    test_modules = {p.stem for p in (REPO_ROOT / "tests").rglob("*.py")}
    for path in PACKAGE.rglob("*.py"):
        bad = {m for m in _imports(path)
               if m.split(".")[0] in test_modules | {"tests", "pytest", "hypothesis"}}
        assert not bad, f"{path.relative_to(REPO_ROOT)} imports test code {sorted(bad)}"
        assert not path.stem.endswith("_cases") or path.parent.name == "validation", path


def test_modules_stay_small() -> None:
    """One concept per module: a module past 600 lines has grown a second concern, to be
    split along its seams."""
    big = {str(p.relative_to(REPO_ROOT)): n for p in PACKAGE.rglob("*.py")
           if (n := len(p.read_text(encoding="utf-8").splitlines())) > 600}
    assert not big, big


def test_every_command_help_has_an_example() -> None:
    from click.testing import CliRunner

    from drivedyn.cli import main

    runner = CliRunner()
    for name in main.commands:
        res = runner.invoke(main, [name, "--help"])
        assert res.exit_code == 0, name
        assert "Example" in res.output, f"`drivedyn {name} --help` shows no example"


@pytest.mark.parametrize("module", ["drivedyn.cli.files", "drivedyn.cli.differential",
                                    "drivedyn.cli.validate", "drivedyn.cli.bounce"])
def test_command_modules_do_not_import_their_parent(module: str) -> None:
    path = PACKAGE / Path(*module.split(".")[1:]).with_suffix(".py")
    assert "drivedyn.cli" not in _imports(path)
