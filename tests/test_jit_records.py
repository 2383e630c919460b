"""Compilation without numba's LLVM-lock events and cache-entry type annotations
(drivedyn.jit_records): installed on this numba, the lock kept, cached functions load and run
the same, and the annotations come back with ``DRIVEDYN_JIT_RECORDS=0``."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import llvmlite.binding as ll
import pytest

from drivedyn import jit, jit_records

pytestmark = pytest.mark.skipif(not jit.apply() or not jit_records.install(),
                                reason="numba without the passages jit_records relies on")


def test_installed_on_this_numba():
    from numba.core import compiler

    assert jit_records._state == {"events": True, "annotations": True}
    assert jit_records._numba_lock_callbacks() == []
    assert compiler.CompileResult._reduce.__wrapped__ is not None
    lock = ll.ffi.lib._lock  # the lock itself still guards every call into LLVM
    with lock:
        assert lock._lock._is_owned()


_MODULE = """
import numpy as np
from numba import njit

@njit(cache=True)
def weighted(a, w):
    s = 0.0
    for i in range(a.shape[0]):
        s += a[i] * w
    return s
"""

_RUN = """
import sys
sys.path.insert(0, sys.argv[1])
import numpy as np
import drivedyn.jit as jit
jit.apply()
from numba.core import base  # noqa: F401 - numba's lock callbacks, unless removed
import llvmlite.binding as ll
from cached_fn import weighted
print(weighted(np.arange(4.0), 0.5))
print(len(weighted.stats.cache_hits), len(ll.ffi.lib._lock._cblist))
weighted.inspect_types()
"""


def _run(tmp_path, records: str) -> list[str]:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / f"cache{records}"),
           "DRIVEDYN_JIT_RECORDS": records}
    env.pop("NUMBA_DISABLE_JIT", None)
    proc = subprocess.run([sys.executable, str(tmp_path / "run.py"), str(tmp_path)], env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc.stdout.splitlines()


@pytest.mark.parametrize("records", ["1", "0"])
def test_cached_function_loads_and_runs_the_same(tmp_path, records):
    (tmp_path / "cached_fn.py").write_text(textwrap.dedent(_MODULE))
    (tmp_path / "run.py").write_text(textwrap.dedent(_RUN))
    first = _run(tmp_path, records)  # compiles and writes the cache
    second = _run(tmp_path, records)  # loads it
    assert first[0] == second[0] == "3.0"
    hits, callbacks = second[1].split()
    assert hits == "1"
    if records == "1":
        assert callbacks == "0"
        assert jit_records.NOTE in "\n".join(second)  # the entry holds the note
        assert "s += a[i] * w" in "\n".join(first)  # compiled here: numba's annotation
    else:  # numba's callbacks and the annotated source, as without drivedyn
        assert callbacks == "1"  # one (enter, exit) pair
        assert "s += a[i] * w" in "\n".join(second)
        assert jit_records.NOTE not in "\n".join(second)
