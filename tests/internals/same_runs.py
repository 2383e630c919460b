"""Running a simulation two ways and checking the two runs are the same, bit for bit: the
stepping engine against its oracle (internals/reference_stepper.py)."""

from __future__ import annotations

import numpy as np


def run_both(monkeypatch, run, module, name: str):
    """``run()`` with the oracle (the Python stepper and loop) and with the engine, with
    ``module.name`` (the compiled loop) counting its calls; returns both Results and the
    number of calls of the compiled function."""
    from reference_stepper import reference_runs

    calls = []
    compiled = getattr(module, name)

    def counting(*args):
        calls.append(1)
        return compiled(*args)

    monkeypatch.setattr(module, name, counting)
    with reference_runs(monkeypatch):
        slow = run()
    assert not calls
    fast = run()
    return slow, fast, len(calls)


def assert_identical(slow, fast) -> None:
    """Same success and message, statistics, recorded variables and values (NaN equal)."""
    assert (slow.success, slow.message) == (fast.success, fast.message)
    for k in ("steps", "rejected", "newton_iterations", "factorizations",
              "residual_evaluations", "h_min_used", "h_max_used"):
        assert getattr(slow.stats, k) == getattr(fast.stats, k), k
    a, b = slow.dataset, fast.dataset
    assert sorted(a.data_vars) == sorted(b.data_vars)
    assert np.array_equal(a["time"].values, b["time"].values)
    for name in a.data_vars:
        assert np.array_equal(a[name].values, b[name].values, equal_nan=True), name
