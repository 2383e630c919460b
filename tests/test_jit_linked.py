"""Linked overloads (drivedyn.jit_linked): a function compiled for a compiled caller has no
entry points and no machine code of its own; Python calls still get a complete overload; the
on-disk cache keeps the two kinds apart."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from numba import njit

from drivedyn import jit, jit_linked

jit.apply()
pytestmark = pytest.mark.skipif(not jit_linked.install(), reason="numba without the API used")


def _pair():
    """A helper and a caller compiled afresh (new dispatchers, no cache)."""

    @njit
    def helper(a, s):
        t = 0.0
        for i in range(a.shape[0]):
            t += s * a[i] * a[i]
        return t

    @njit
    def caller(a):
        return helper(a, 2.0) + 1.0

    return helper, caller


def test_nested_overload_is_linked_and_not_callable():
    helper, caller = _pair()
    a = np.arange(5.0)
    assert caller(a) == 2.0 * 30.0 + 1.0
    (cres,) = helper.overloads.values()
    assert jit_linked.is_linked(cres)
    assert not jit_linked.is_linked(next(iter(caller.overloads.values())))
    # no machine code of its own, no wrappers: its entry point says so instead of crashing
    with pytest.raises(TypeError, match="linked into a compiled caller"):
        cres.entry_point(a, 2.0)
    assert cres.library.get_pointer_to_function(cres.fndesc.llvm_cpython_wrapper_name) == 0


def test_python_call_replaces_the_linked_overload():
    helper, caller = _pair()
    a = np.linspace(0.0, 1.0, 7)
    want = float(np.sum(3.0 * a * a))
    caller(a)
    assert helper(a, 3.0) == pytest.approx(want, rel=1e-15)
    (cres,) = helper.overloads.values()
    assert not jit_linked.is_linked(cres)
    assert jit_linked.callable_overload(helper, cres.signature.args) is cres
    # the caller compiled before keeps working; a caller compiled after links the complete one
    assert caller(a) == pytest.approx(float(np.sum(2.0 * a * a)) + 1.0, rel=1e-15)

    @njit
    def caller2(a):
        return helper(a, 1.0)

    assert caller2(a) == pytest.approx(float(np.sum(a * a)), rel=1e-15)
    assert not jit_linked.is_linked(next(iter(helper.overloads.values())))


def test_callable_overload_compiles_a_linked_one_complete():
    helper, caller = _pair()
    a = np.ones(3)
    caller(a)
    sig = next(iter(helper.overloads))
    cres = jit_linked.callable_overload(helper, sig)
    assert not jit_linked.is_linked(cres)
    assert cres.library.get_pointer_to_function(cres.fndesc.llvm_cfunc_wrapper_name) != 0
    assert cres.entry_point(a, 0.5) == 1.5


_MODULE = '''
import numpy as np
from numba import njit
import drivedyn.jit

drivedyn.jit.apply()  # installs the linked compilation, as importing an element module does


@njit(cache=True)
def helper(a, s):
    t = 0.0
    for i in range(a.shape[0]):
        t += s * a[i] * a[i]
    return t


@njit(cache=True)
def caller(a):
    return helper(a, 2.0) + 1.0


@njit(cache=True)
def caller2(a):
    return helper(a, 1.0) - 1.0
'''

_STEP = '''
import json, sys
import numpy as np
from drivedyn import jit_linked
import linkmod
a = np.arange(4.0)
out = {}
for what in sys.argv[1:]:
    if what == "caller":
        out["caller"] = linkmod.caller(a)
    elif what == "caller2":
        out["caller2"] = linkmod.caller2(a)
    elif what == "helper":
        out["helper"] = linkmod.helper(a, 3.0)
    hits = dict(linkmod.helper._cache_hits)
    out[what + "_helper_hits"] = sum(hits.values())
    out[what + "_helper_linked"] = [jit_linked.is_linked(c)
                                    for c in linkmod.helper.overloads.values()]
print(json.dumps(out))
'''


def _run(tmp_path, *what):
    env = {**os.environ, "PYTHONPATH": f"{tmp_path}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    env.pop("NUMBA_CACHE_DIR", None)  # the cache next to linkmod.py, in tmp_path
    env.pop("NUMBA_DISABLE_JIT", None)
    proc = subprocess.run([sys.executable, str(tmp_path / "step.py"), *what], env=env,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_cache_keeps_linked_and_complete_overloads_apart(tmp_path):
    (tmp_path / "linkmod.py").write_text(textwrap.dedent(_MODULE))
    (tmp_path / "step.py").write_text(textwrap.dedent(_STEP))
    # 1: the caller compiles the helper linked; both are cached
    out = _run(tmp_path, "caller")
    assert out["caller"] == 29.0
    assert out["caller_helper_hits"] == 0 and out["caller_helper_linked"] == [True]
    # 2: a new process: the caller loads from the cache (the helper is not needed); a second
    # caller loads the helper's linked overload from the cache instead of compiling it
    out = _run(tmp_path, "caller", "caller2")
    assert out["caller"] == 29.0 and out["caller2"] == 13.0
    assert out["caller_helper_linked"] == []
    assert out["caller2_helper_hits"] == 1 and out["caller2_helper_linked"] == [True]
    # 3: Python calls the helper: the linked overload is not what it loads or runs; the
    # complete one is compiled and cached under the usual key
    out = _run(tmp_path, "caller2", "helper")
    assert out["helper"] == 42.0 and out["helper_helper_linked"] == [False]
    # 4: a new process calling the helper first loads the complete overload from the cache
    out = _run(tmp_path, "helper", "caller2")
    assert out["helper"] == 42.0
    assert out["helper_helper_hits"] == 1 and out["helper_helper_linked"] == [False]
    assert out["caller2"] == 13.0
