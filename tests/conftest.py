"""Fixtures shared by every tier of the tests (``tests/verification``, ``elements``,
``models``, ``files_cli``, ``internals`` and the modules left at the top level).

Helpers that test modules import by name sit next to this file, on ``sys.path`` through
``pythonpath`` in pyproject.toml: ``repo`` (``REPO_ROOT``, ``EXAMPLES``), ``fdcheck``
(finite-difference tangent checks), ``small_models`` (small models, ``rot_y``/``rot_z``),
``element_cases`` (``TANGENT_CASES``), ``same_runs``, ``ir_compare`` and
``torsen_protocol`` (the short Type C bench protocol). The markers
(``slow``, ``fuzz_long``) are registered in pyproject.toml.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner


@pytest.fixture
def runner() -> CliRunner:
    """A click test runner: the command line in-process (``runner.invoke(main, [...])``)."""
    return CliRunner()


@pytest.fixture
def drivedyn_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """``$DRIVEDYN_CACHE`` (the on-disk cache of Craig-Bampton reductions) set to the test's
    own ``tmp_path / "cache"``: nothing is read from or left in the user's cache."""
    cache = tmp_path / "cache"
    monkeypatch.setenv("DRIVEDYN_CACHE", str(cache))
    return cache


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Test files that hold a ``slow`` test run first, in their collected order (the rest
    after them, in theirs). With ``-n`` (pytest-xdist, a file per process) the long files then
    start early instead of ending a two-process run on one core while the other waits.
    Measured cold on 2 cores: 29:36 before, 28:32 with it; the three-minute BLAS comparison
    (``verification/test_machine_independence.py``), the last slow file collected, still
    starts about 25 min in."""
    slow_files = {item.path for item in items if item.get_closest_marker("slow")}
    items.sort(key=lambda item: item.path not in slow_files)
