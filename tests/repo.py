"""Paths of the repository the tests read (README, examples, pyproject.toml, the package
sources), wherever the test module that asks for them sits under ``tests/``."""

from __future__ import annotations

from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = REPO_ROOT / "examples"
