"""The fix of numba's IR inliner (drivedyn.jit): installed on the supported numba, and
inlined code computes what the Python functions compute."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit
from numba.core.inline_closurecall import InlineWorker

from drivedyn import jit


def test_inliner_fix_is_installed() -> None:
    import drivedyn.elements  # noqa: F401 - kernel modules apply it at import

    assert jit.apply() is True
    assert getattr(InlineWorker.inline_ir, "__drivedyn_fixed__", False)


@njit(inline="always")
def _clip(x, lo, hi):
    if x < lo:
        return lo
    if x > hi:
        return hi
    return x


@njit(inline="always")
def _norm_clipped(v, lo, hi):
    s = 0.0
    for i in range(v.shape[0]):
        c = _clip(v[i], lo, hi)  # a helper inlined into an inlined helper
        s += c * c
    return np.sqrt(s)


@njit
def _caller(v):
    # two call sites of a helper with several blocks and a loop
    return _norm_clipped(v, -1.0, 1.0) + 2.0 * _norm_clipped(v[::-1], 0.0, 0.5)


def test_inlined_helpers_compute_what_numpy_computes() -> None:
    v = np.array([-3.0, 0.2, 0.7, 1.5, -0.1, 0.45])
    ref = np.linalg.norm(np.clip(v, -1.0, 1.0)) + 2.0 * np.linalg.norm(np.clip(v, 0.0, 0.5))
    assert _caller(v) == pytest.approx(ref, rel=1e-15)


def test_callee_ir_is_built_once_per_function(monkeypatch) -> None:
    """The inliner builds an inlined helper's untyped IR once, not at every call site (the
    memo of ``drivedyn.jit``): a fresh caller with three call sites of a fresh helper runs the
    helper's untyped pipeline once, and computes what Python computes."""
    jit.apply()
    built = []
    run = InlineWorker.run_untyped_passes

    def counting(self, func, enable_ssa=False):
        built.append(func.__name__)
        return run(self, func, enable_ssa)

    monkeypatch.setattr(InlineWorker, "run_untyped_passes", counting)

    @njit(inline="always")
    def _twice_clipped(x):
        return 2.0 * min(max(x, -1.0), 1.0)

    @njit
    def three_sites(a, b, c):
        return _twice_clipped(a) + 10.0 * _twice_clipped(b) + 100.0 * _twice_clipped(c)

    assert three_sites(0.25, -3.0, 7.0) == 0.5 - 20.0 + 200.0
    assert built.count("_twice_clipped") == 1
