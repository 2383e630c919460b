"""Arrays of a finite-element computation kept on disk between runs, in drivedyn's cache
folder (:func:`drivedyn.settings.cache_dir`, sub-folder ``fe``).

A part's geometric data that a model build needs each time, and that depends only on the
mesh and the points asked for: the element nodes of a mesh (a scikit-fem basis, after the
cells' orientation check), the tributary areas of a face's nodes (a facet basis) and the
shape functions at a face's contact points (the cells' maps inverted point by point). With
them on disk a washer loaded from the reduction cache builds no scikit-fem object: about
0.2 s of each ``drivedyn tdr`` with the Type C's five flexible washers, on the critical path
of the bench (the model is built before the second side is forked).
The Craig-Bampton reductions have their own entries (:mod:`drivedyn.fe.reduction`).
"""

from __future__ import annotations

import functools
import hashlib
import importlib.metadata
import os
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np

from drivedyn import settings

#: bumped when a cached computation changes, so that old entries are not read
CACHE_VERSION = 1


@functools.lru_cache(maxsize=1)
def _computed_by() -> str:
    """What computes the entries: this cache's version and scikit-fem's (its numbering of a
    mesh's nodes could change with it), read from the installed package's metadata (no
    import of scikit-fem)."""
    try:
        skfem = importlib.metadata.version("scikit-fem")
    except importlib.metadata.PackageNotFoundError:
        skfem = "?"
    return f"{CACHE_VERSION}/scikit-fem {skfem}"


def entry(kind: str, key: Iterable[bytes | str]) -> Path:
    """The file of the entry ``kind`` (a computation's name) for ``key`` (the bytes or strings
    its result depends on, e.g. the solid's digest and the points)."""
    h = hashlib.sha1(f"{_computed_by()}/{kind}".encode())
    for part in key:
        h.update(part if isinstance(part, bytes) else part.encode())
    return settings.cache_dir() / "fe" / f"{kind}-{h.hexdigest()}.npz"


def cached(kind: str, key: Iterable[bytes | str],
           compute: Callable[[], dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """The arrays ``compute()`` returns (name -> array), read from the entry of ``kind`` and
    ``key`` if it exists, else computed and written. A damaged entry is computed again; a
    cache folder that cannot be written leaves the result uncached. Errors of ``compute``
    pass through and write nothing."""
    path = entry(kind, key)
    if path.is_file():
        try:
            with np.load(path, allow_pickle=False) as z:
                return {k: z[k] for k in z.files}
        except (OSError, ValueError, KeyError, EOFError):
            pass  # damaged: computed again below
    out = compute()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp.npz")
        np.savez(tmp, **out)
        os.replace(tmp, path)
    except OSError:
        pass
    return out
