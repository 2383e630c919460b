"""First compilation in worker processes (drivedyn.solver.precompile), run in a fresh
process with an empty numba cache: the missing kernels are compiled by the workers, the
process loads them from the cache without compiling, and a second pass finds nothing
missing; a later process finds them in the record of compiled kernels and loads them
without workers, until their source file changes. Kernels here are two small functions so
that the test is quick; the library's kernels go the same way."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from drivedyn.solver.precompile import _FORK

KMOD = """
import numpy as np
from numba import njit

@njit(cache=True)
def f(x):
    s = 0.0
    for v in x:
        s += v * v
    return np.sqrt(s)

@njit(cache=True)
def g(a, b):
    return a * b + 1.0
"""

SCRIPT = """
import gc
import json
import os
import numpy as np
from numba import njit, typeof
from numba.core import event
import kmod
from drivedyn.solver.precompile import precompile_kernels

compiled = []
class Count(event.Listener):
    def on_start(self, e):
        compiled.append(e.data["dispatcher"].py_func.__name__)
    def on_end(self, e):
        pass

@njit
def caller(a, b):
    return kmod.g(a, b) + 1.0

waited = []
shown = []

def wait():
    # called in this process while the workers compile; what it raises is only logged
    waited.append(os.getpid())
    raise RuntimeError("ignored")

def main():
    calls = [(kmod.f, (typeof(np.zeros(3)),)), (kmod.g, (typeof(1.0), typeof(2.0)))]
    with event.install_listener("numba:compile", Count()):
        first = precompile_kernels(calls, WORKERS, while_waiting=wait,
                                   progress=lambda *a: shown.append(list(a)))
        by_precompile = list(compiled)
        values = [float(kmod.f(np.array([3.0, 4.0]))), float(kmod.g(2.0, 3.0))]
        # a compiled function calling a kernel loaded from the cache (the compiled Newton
        # step calls kernels; a cache load without registering the kernel's lowering made
        # this fail with "No definition for lowering")
        values.append(float(caller(2.0, 3.0)))
        second = precompile_kernels(calls, WORKERS)
    print(json.dumps({"first": first, "second": second, "values": values,
                      "compiled_here": compiled, "gc": [gc.isenabled(), *gc.get_threshold()],
                      "by_precompile": by_precompile, "shown": shown,
                      "waited": [pid == os.getpid() for pid in waited]}))

if __name__ == "__main__":
    main()
"""


def _run(tmp_path: Path, workers: int, write: bool = True) -> dict:
    if write:
        (tmp_path / "kmod.py").write_text(textwrap.dedent(KMOD))
    (tmp_path / "run.py").write_text(SCRIPT.replace("WORKERS", str(workers)))
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"),
           "DRIVEDYN_CACHE": str(tmp_path / "drivedyn-cache"),
           "PYTHONPATH": os.pathsep.join([str(tmp_path), *sys.path])}
    proc = subprocess.run([sys.executable, "run.py"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


@pytest.mark.skipif(not _FORK, reason="workers are forked (Linux)")
def test_missing_kernels_compile_in_workers_and_load_from_the_cache(tmp_path) -> None:
    out = _run(tmp_path, 2)
    assert out["first"]["missing"] == 2 and out["first"]["compiled_in_workers"] == 2
    # both kernels loaded from the cache the workers wrote; only the caller compiles here
    assert out["compiled_here"] == ["caller"] and out["by_precompile"] == []
    assert out["values"] == [5.0, 7.0, 8.0]
    assert out["second"]["missing"] == 0
    assert out["gc"] == [True, 700, 10, 10]  # as Python starts
    # the work handed over for the wait ran once, here, and its exception was only logged
    assert out["waited"] == [True]
    # what a first run shows: the start, then each kernel as a worker finishes it
    assert out["shown"][0] == [0, 2, ""]
    assert sorted(n for _, _, n in out["shown"][1:]) == ["f", "g"]
    assert [d for d, _, _ in out["shown"]] == [0, 1, 2]


def test_without_workers_the_kernels_compile_in_this_process(tmp_path) -> None:
    out = _run(tmp_path, 0)
    assert out["first"]["missing"] == 2 and out["first"]["compiled_in_workers"] == 0
    # compiled by precompile_kernels itself (the collector's thresholds restored afterwards)
    assert sorted(out["by_precompile"]) == ["f", "g"]
    assert sorted(out["compiled_here"]) == ["caller", "f", "g"]
    assert out["gc"] == [True, 700, 10, 10]  # as Python starts
    assert out["values"] == [5.0, 7.0, 8.0]
    assert out["second"]["missing"] == 0
    assert out["waited"] == []  # nothing compiles in parallel: nothing to wait for
    assert [d for d, _, _ in out["shown"]] == [0, 1, 2]


@pytest.mark.skipif(not _FORK, reason="workers are forked (Linux)")
def test_a_later_process_loads_the_recorded_kernels_until_their_source_changes(
        tmp_path) -> None:
    """The record of compiled kernels (drivedyn's cache folder) tells a later process that
    numba's cache holds the kernels: it loads them in the process, with no worker and no
    compilation. Editing the kernels' source file makes them missing again (numba's cache
    is keyed on that file), so the workers compile them. Fails if the record is ignored
    (workers every time) or if its stamp omits the source file (a stale kernel loaded)."""
    import time

    first = _run(tmp_path, 2)
    assert first["first"]["compiled_in_workers"] == 2
    later = _run(tmp_path, 2, write=False)
    assert later["first"]["missing"] == 0 and later["first"]["compiled_in_workers"] == 0
    assert later["compiled_here"] == ["caller"] and later["values"] == [5.0, 7.0, 8.0]
    record = json.loads((tmp_path / "drivedyn-cache" / "compiled-kernels.json").read_text())
    assert len(record) == 2 and all(v["seconds"] >= 0.0 for v in record.values())
    time.sleep(0.01)
    src = tmp_path / "kmod.py"
    src.write_text(src.read_text().replace("a * b + 1.0", "a * b + 1.0  # edited"))
    edited = _run(tmp_path, 2, write=False)
    # both kernels live in the edited file
    assert edited["first"]["missing"] == 2 and edited["first"]["compiled_in_workers"] == 2
    assert edited["values"] == [5.0, 7.0, 8.0]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/statm")
def test_resident_memory_is_read_for_the_workers_collection_rule() -> None:
    """A worker collects garbage only above WORKER_RSS_MB of resident memory; the reading must
    be this process's resident set: at least the 64 MB array just touched, less than RAM.
    Read in a new process: in a long test session, even a 64 MB array (above glibc's largest
    mmap threshold) was once served from memory already resident (no growth at all)."""
    import subprocess
    import sys

    from drivedyn.solver.precompile import WORKER_RSS_MB

    code = ("import numpy as np\n"
            "from drivedyn.solver.precompile import _rss_mb\n"
            "before = _rss_mb()\n"
            "a = np.ones(2**23)  # 64 MB, every page written\n"
            "after = _rss_mb()\n"
            "print(before, after, a.sum())\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120, check=True).stdout.split()
    before, after, total = (float(v) for v in out)
    assert 64.0 <= after < 1e6 and after - before >= 63.0
    assert total == 2**23 and 0.0 < WORKER_RSS_MB < 1024.0


class _Stop(BaseException):
    pass


def _first_precompile(monkeypatch, run) -> list:
    """The (function name, signature) pairs ``run()`` hands to its first precompile."""
    import drivedyn.solver.precompile as pc

    seen: list = []

    def record(calls, workers=None, while_waiting=None, progress=None):
        seen.extend((d.py_func.__qualname__, sig) for d, sig in calls)
        raise _Stop

    monkeypatch.setattr(pc, "precompile_kernels", record)
    with pytest.raises(_Stop):
        run()
    return seen


def test_load_kernels_compiles_what_the_run_calls(monkeypatch) -> None:
    """``load_kernels`` (what ``drivedyn tdr`` does before forking its second bench side)
    hands the precompile exactly the functions and argument types of the run's first
    evaluation: the kernels, the stepping loop and the linear solver's, nothing else."""
    from drivedyn.model.compile import compile_model
    from drivedyn.solver.settings import AdaptiveStep, GeneralizedAlpha, Newton
    from drivedyn.solver.simulate import load_kernels, simulate
    from small_models import speed_jump_spec

    settings = {"integrator": GeneralizedAlpha(0.8), "newton": Newton(),
                "step": AdaptiveStep(1e-4, 1e-8, 1e-3, 1e-4, 1e-6)}
    by_run = _first_precompile(
        monkeypatch, lambda: simulate(compile_model(speed_jump_spec()), 1e-3, **settings))
    by_load = _first_precompile(
        monkeypatch, lambda: load_kernels(compile_model(speed_jump_spec()), **settings))
    names = {name for name, _ in by_run}
    assert {"rigid_body_kernel", "run_steps", "eval_time_functions"} <= names
    assert sorted(map(repr, by_load)) == sorted(map(repr, by_run))
    with pytest.raises(TypeError, match="output_dtt"):  # a mistyped setting is not ignored
        load_kernels(compile_model(speed_jump_spec()), output_dtt=1e-3, **settings)


SIZED = """
from numba import njit
import helpers

@njit
def c(x):
    return x + 1.0

@njit
def b(x):
    return c(x) * 2.0

@njit
def a(x):
    return b(x) + b(2.0 * x) + c(x) + helpers.h(x)
"""

HELPERS = """
from numba import njit

@njit
def h(x):
    return x * x
"""


def test_code_size_counts_each_numba_function_reached_once(tmp_path, monkeypatch) -> None:
    """code_size sums the bytecode of a function and of every numba function it reaches by
    name or as ``module.name``, each once: ``a`` calls ``b`` twice, ``c`` directly and
    through ``b``, and ``helpers.h``; the total is the four functions' bytecode, each
    counted once. Fails if the module-attribute walk is dropped (``h`` missing) or if the
    functions already counted are not passed down (``c`` counted twice)."""
    import importlib

    from drivedyn.solver.precompile import code_size

    (tmp_path / "sized.py").write_text(SIZED)
    (tmp_path / "helpers.py").write_text(HELPERS)
    monkeypatch.syspath_prepend(str(tmp_path))
    sized = importlib.import_module("sized")
    helpers = importlib.import_module("helpers")
    expected = sum(len(f.py_func.__code__.co_code)
                   for f in (sized.a, sized.b, sized.c, helpers.h))
    assert code_size(sized.a.py_func) == expected
    assert code_size(sized.b.py_func) == sum(len(f.py_func.__code__.co_code)
                                             for f in (sized.b, sized.c))


def test_kernels_unknown_to_the_record_are_ordered_by_code_size() -> None:
    """expected_seconds: a kernel in the record takes the record's seconds; one not in it
    SECONDS_PER_BYTE times its code size, so on a fresh machine the workers take the gear
    kernel (the largest code of the Type C bench) before the rigid bodies' kernel. Fails if
    the estimate falls back to one constant for every kernel (the order of the model's
    groups then decides)."""
    from drivedyn.elements.bodies import rigid_body_kernel
    from drivedyn.elements.gears.kernel import parallel_gear_kernel
    from drivedyn.solver.precompile import SECONDS_PER_BYTE, code_size, expected_seconds

    gear = expected_seconds("gear", parallel_gear_kernel, {})
    rigid = expected_seconds("rigid", rigid_body_kernel, {})
    assert gear == SECONDS_PER_BYTE * code_size(parallel_gear_kernel.py_func)
    assert gear > 2.0 * rigid > 0.0
    assert expected_seconds("rigid", rigid_body_kernel, {"rigid": {"seconds": 99.0}}) == 99.0
