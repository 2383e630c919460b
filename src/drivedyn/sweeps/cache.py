"""The cache of computed sweep points: one JSON file per point, named by a hash of everything
that determines its result, so that rerunning a sweep computes only what is missing.

The key covers the model file's bytes, the bytes of the files it names (meshes, tyre
property files, the TORSEN files of a vehicle: any string value of the file that names an
existing file beside it, or a shipped model), the point's overrides, what is computed
(kind and options) and the drivedyn code itself (a hash of the installed package's source
and data files): editing the model, a file it uses or the code makes the cached point stale.
Records are written by the client as they arrive (atomically: a temporary file renamed), so
a killed worker or an interrupted sweep never loses a finished point.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
import tomllib
from functools import cache
from pathlib import Path
from typing import Any

CACHE_FORMAT = 1


@cache
def code_fingerprint() -> str:
    """SHA-256 over the installed drivedyn package's ``.py``, ``.toml`` and ``.tir`` files
    (paths and bytes); computed once per process (about 10 ms)."""
    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for path in sorted(p for ext in ("*.py", "*.toml", "*.tir") for p in root.rglob(ext)):
        if "__pycache__" in path.parts:
            continue
        h.update(str(path.relative_to(root)).encode())
        h.update(hashlib.sha256(path.read_bytes()).digest())
    return h.hexdigest()


def _strings(node: Any) -> list[str]:
    if isinstance(node, dict):
        return [s for v in node.values() for s in _strings(v)]
    if isinstance(node, list):
        return [s for v in node for s in _strings(v)]
    return [node] if isinstance(node, str) else []


def referenced_files(model_path: Path, overrides: dict[str, Any] | None = None) -> dict[str,
                                                                                        str]:
    """name -> SHA-256 of the files a model file names (string values that are existing files
    relative to its folder, or shipped model names), followed into named TOML files."""
    from drivedyn.config.loader import shipped_models

    shipped = shipped_models()
    out: dict[str, str] = {}
    todo = [(Path(model_path), list((overrides or {}).values()))]
    seen = {Path(model_path).resolve()}
    while todo:
        path, extra = todo.pop()
        try:
            data = tomllib.loads(path.read_text())
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
            continue
        for s in _strings(data) + [v for v in extra if isinstance(v, str)]:
            if len(s) > 400 or "\n" in s:
                continue
            cand = Path(s) if Path(s).is_absolute() else path.parent / s
            target = cand if cand.is_file() else shipped.get(s)
            if target is None:
                continue
            target = Path(target).resolve()
            if target in seen:
                continue
            seen.add(target)
            out[s] = hashlib.sha256(target.read_bytes()).hexdigest()
            if target.suffix == ".toml":
                todo.append((target, []))
    return dict(sorted(out.items()))


def point_key(model_sha256: str, refs: dict[str, str], kind: str, options: dict,
              overrides: dict[str, Any]) -> str:
    """The cache key of a point (hex SHA-256)."""
    blob = json.dumps({"format": CACHE_FORMAT, "code": code_fingerprint(),
                       "model": model_sha256, "refs": refs, "kind": kind,
                       "options": options, "overrides": sorted(overrides.items())},
                      sort_keys=True, default=repr)
    return hashlib.sha256(blob.encode()).hexdigest()


class PointCache:
    """A folder of cached point records (``<key>.json``); ``None`` folder: no cache."""

    def __init__(self, folder: str | Path | None) -> None:
        self.folder = Path(folder) if folder is not None else None

    def get(self, key: str) -> dict | None:
        """The cached record of ``key``, or None (absent or unreadable: recomputed)."""
        if self.folder is None:
            return None
        try:
            entry = json.loads((self.folder / f"{key}.json").read_text())
        except (OSError, ValueError):
            return None
        rec = entry.get("record") if isinstance(entry, dict) else None
        return rec if isinstance(rec, dict) and "status" in rec else None

    def put(self, key: str, record: dict, overrides: dict[str, Any], model: str) -> None:
        """Store a record atomically (temporary file in the folder, then a rename)."""
        if self.folder is None:
            return
        self.folder.mkdir(parents=True, exist_ok=True)
        text = json.dumps({"record": record, "overrides": overrides, "model": model},
                          default=repr)
        fd, tmp = tempfile.mkstemp(prefix=f"{key}.", suffix=".part", dir=self.folder)
        try:
            with os.fdopen(fd, "w") as f:
                f.write(text)
            os.replace(tmp, self.folder / f"{key}.json")
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)

    def __len__(self) -> int:
        return 0 if self.folder is None or not self.folder.is_dir() else \
            sum(1 for _ in self.folder.glob("*.json"))
