"""drivedyn.elements.framework.work_arrays: views carved from one buffer are the arrays they
stand for, and the groups' work buffers do not change an evaluation."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit
from numba.core.errors import TypingError

from drivedyn.elements.framework.work_arrays import carve


@njit
def _carve_three(n):
    buf = np.zeros(n + 12 * 12 + 2 * 3 * 4)
    a = carve(buf, 0, n)
    B = carve(buf, n, (12, 12))
    C = carve(buf, n + 144, (2, 3, 4))
    return buf, a, B, C


def test_views_have_the_shapes_strides_and_places_asked_for() -> None:
    buf, a, B, C = _carve_three(5)
    assert (a.shape, B.shape, C.shape) == ((5,), (12, 12), (2, 3, 4))
    assert (a.strides, B.strides, C.strides) == ((8,), (96, 8), (96, 32, 8))
    assert all(v.flags.c_contiguous for v in (a, B, C))
    a[:] = 1.0
    B[3, 4] = 7.0
    C[1, 2, 3] = -2.0
    # each view writes where a reshape of the same range would: no overlap, no gap
    ref = np.zeros_like(buf)
    ref[:5] = 1.0
    ref[5:149].reshape(12, 12)[3, 4] = 7.0
    ref[149:].reshape(2, 3, 4)[1, 2, 3] = -2.0
    np.testing.assert_array_equal(buf, ref)


@njit
def _views_outlive_their_buffer():
    buf = np.zeros(1000)  # numba frees a variable after its last use: buf dies here
    return carve(buf, 10, (10, 10)), carve(buf, 500, 20)


def test_views_keep_the_buffer_alive() -> None:
    # if a view did not hold a reference, its memory would be freed (and reused by the
    # allocations below) when the function returns
    A, v = _views_outlive_their_buffer()
    junk = [np.full(1000, 9.0) for _ in range(50)]
    assert A.sum() == 0.0 and v.sum() == 0.0
    A[:] = 3.0
    v[:] = 1.0
    assert A.sum() == 300.0 and v.sum() == 20.0
    del junk


def test_the_same_results_as_separate_allocations_in_a_loop() -> None:
    @njit
    def work(n):
        buf = np.zeros(3 * n + n * n)
        x, y, z = carve(buf, 0, n), carve(buf, n, n), carve(buf, 2 * n, n)
        M = carve(buf, 3 * n, (n, n))
        for i in range(n):
            x[i] = i
            y[i] = 2.0 * i
            for j in range(n):
                M[i, j] = i - j
        z[:] = M @ x + y
        return z.copy()

    n = 7
    M = np.subtract.outer(np.arange(n), np.arange(n)).astype(float)
    np.testing.assert_array_equal(work(n), M @ np.arange(n) + 2.0 * np.arange(n))


def test_wrong_buffers_are_refused_at_typing() -> None:
    @njit
    def on_ints():
        return carve(np.zeros(4, np.int64), 0, 2)

    @njit
    def on_2d():
        return carve(np.zeros((2, 2)), 0, 2)

    for fn in (on_ints, on_2d):
        with pytest.raises(TypingError):
            fn()


# --- the groups' work buffers (elements.framework.scaffold.work_buffer) ----------------------


def _work_params(group) -> list[int]:
    """Indices in ``group.params`` of the kernel's ``work`` buffer (none for a family that
    allocates its work arrays per call)."""
    import inspect

    names = list(inspect.signature(group.kernel.py_func).parameters)
    return [i for i, n in enumerate(names[:len(group.params)]) if n == "work"]


def _evaluations(model, st) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Residual with the matrix, the matrix, and the residual of an evaluation without it."""
    from drivedyn.elements.framework.contract import MODE_DYN
    from drivedyn.solver.system import System

    sys = System(model)
    sys.reset_tangent()
    sys.evaluate(st, 2.0, 3.0, 1.0, MODE_DYN, True)
    r, K = sys.r.copy(), sys.matrix().toarray()
    sys.evaluate(st, 2.0, 3.0, 1.0, MODE_DYN, False)
    return r, K, sys.r.copy()


def _random_state(model, seed: int, dx: float = 0.0):
    """The initial state with random velocities and accelerations, and positions moved by
    about ``dx`` [m] (another contact state)."""
    rng = np.random.default_rng(seed)
    st = model.initial_state()
    st.x[:model.nn] += dx * rng.standard_normal((model.nn, 3))
    st.v[:] = 0.1 * rng.standard_normal(model.nd)
    st.vd[:] = rng.standard_normal(model.nd)
    return st


def _families_with_work():
    from drivedyn.model.compile import compile_model
    from element_cases import TANGENT_CASES

    out = []
    for fam, cases in sorted(TANGENT_CASES.items()):
        model = compile_model(cases[0]())
        if any(_work_params(g) for g in model.groups if g.family == fam):
            out.append(pytest.param(fam, cases, id=fam))
    return out


@pytest.mark.parametrize(("family", "cases"), _families_with_work())
def test_a_used_or_short_work_buffer_gives_the_same_evaluation(family, cases) -> None:
    """The kernels do not zero their group's work buffer at each call: every array they read
    is set within the element that reads it. So residual and matrix are the same bit for
    bit after evaluations at other states (with and without the matrix) have left their
    values in the buffer, as with a fresh buffer; and when the buffer is too short (the
    kernel then allocates one: a wrong size costs time, never results). Every element case
    of the family (tests/element_cases), moving (random velocities and accelerations)."""
    import dataclasses

    from drivedyn.model.compile import compile_model

    for case in cases:
        model = compile_model(case())
        st = _random_state(model, 5)
        r0, K0, q0 = _evaluations(model, st)  # fresh buffers
        groups = [g for g in model.groups if _work_params(g)]
        assert any(g.family == family for g in groups)
        used = compile_model(case())
        for seed in (6, 7):  # earlier use at other states, both passes
            _evaluations(used, _random_state(used, seed, 1e-4))
        r1, K1, q1 = _evaluations(used, st)
        np.testing.assert_array_equal(r1, r0)
        np.testing.assert_array_equal(K1, K0)
        np.testing.assert_array_equal(q1, q0)
        for k, g in enumerate(model.groups):
            if _work_params(g):
                params = list(g.params)
                for i in _work_params(g):
                    params[i] = np.full(3, np.nan)
                model.groups[k] = dataclasses.replace(g, params=tuple(params))
        r2, K2, q2 = _evaluations(model, st)
        np.testing.assert_array_equal(r2, r0)
        np.testing.assert_array_equal(K2, K0)
        np.testing.assert_array_equal(q2, q0)


_ALLOCATIONS_SCRIPT = r"""
import json, sys
import numpy as np
from numba import njit
from numba.core.runtime import rtsys
sys.path.insert(0, sys.argv[1])
from element_cases import TANGENT_CASES
from drivedyn.elements.framework.contract import MODE_DYN
from drivedyn.model.compile import compile_model
from drivedyn.solver.kernel_calls import KernelTable, call_groups, entry_address
from drivedyn.solver.system import System


@njit
def caller(G, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want, n):
    for _ in range(n):
        call_groups(G, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want)


out = {}
for fam in sys.argv[2:]:
    worst = 0.0
    for case in TANGENT_CASES[fam]:
        model = compile_model(case())
        st = model.initial_state()
        sys_ = System(model)
        sys_.reset_tangent()
        sys_.evaluate(st, 2.0, 3.0, 1.0, MODE_DYN, True)
        for want in (True, False):
            for g, (k, pre, mid, post) in zip(
                    model.groups, sys_._kernel_args(st, 2.0, 3.0, 1.0, MODE_DYN, want)):
                if g.family != fam:
                    continue
                sig = sys_._signature(k, pre, mid, post)
                G = KernelTable([(entry_address(k, sig), pre, post)])
                caller(G, *mid, 1)
                a0 = rtsys.get_allocation_stats().alloc
                caller(G, *mid, 20)
                # the caller's own unboxing of its array arguments, once per call of it
                n = rtsys.get_allocation_stats().alloc - a0
                n -= sum(isinstance(a, np.ndarray) for a in mid)
                worst = max(worst, n / 20)
    out[fam] = worst
print(json.dumps(out))
"""


@pytest.mark.slow
def test_kernels_with_a_work_buffer_allocate_nothing_in_the_stepping_loop(tmp_path) -> None:
    """Every family whose kernel takes a ``work`` buffer makes no allocation when the
    stepping loop calls it (through a KernelTable, residual and matrix passes, every
    element case of the family): an allocation inside the element loop costs ``malloc``
    and ``free``, and every view of the array an atomic reference count. Counted with
    numba's NRT statistics (``NUMBA_NRT_STATS=1``, in a subprocess: the switch is read at
    numba's start). It fails when a helper of an element loop allocates a temporary (seen:
    a one-entry ``np.ones`` in ``log_se3``, one allocation per beam element; the former
    ``log_se3`` made three). After editing a module that a kernel calls, run it with an
    empty ``NUMBA_CACHE_DIR``: numba's cache of the kernel does not see the edit
    (docs/numba-notes.md, note 4)."""
    import json
    import os
    import subprocess
    import sys
    from pathlib import Path

    from drivedyn.model.compile import compile_model
    from element_cases import TANGENT_CASES

    fams = [fam for fam, cases in sorted(TANGENT_CASES.items())
            if any(_work_params(g) for g in compile_model(cases[0]()).groups
                   if g.family == fam)]
    script = tmp_path / "allocations.py"
    script.write_text(_ALLOCATIONS_SCRIPT)
    here = str(Path(__file__).resolve().parents[1])
    proc = subprocess.run([sys.executable, str(script), here, *fams], capture_output=True,
                          text=True, env={**os.environ, "NUMBA_NRT_STATS": "1"}, timeout=1200)
    assert proc.returncode == 0, proc.stderr[-3000:]
    counts = json.loads(proc.stdout.strip().splitlines()[-1])
    assert set(counts) == set(fams)
    assert counts == {fam: 0.0 for fam in fams}
