"""Comparison of optimised LLVM IR across compilations (the tests of drivedyn's numba
replacements: the same code up to the names of values)."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path


def norm_ir(text: str) -> list[str]:
    """Optimised IR with local names, labels and their padding replaced by their order, and
    the number of the compilation and addresses taken out of the mangled global names."""
    out: list[str] = []
    names: dict[str, str] = {}

    def number(m: re.Match) -> str:
        return names.setdefault(m.group(0), f"%v{len(names)}")

    for line in text.splitlines():
        line = re.sub(r"B\d+v\d+(?=B)", "Bv", re.sub(r"0x[0-9a-f]+", "0x", line))
        if line.startswith("define "):
            names.clear()
        m = re.match(r'^("[^"]*"|[-a-zA-Z$._0-9]+):(.*)$', line)
        if m and not line.startswith(("define", "declare")):
            line = "%" + m.group(1) + ":" + re.sub(r"\s+", " ", m.group(2))
        out.append(re.sub(r'%"[^"]*"|%[-a-zA-Z$._0-9]+', number, line))
    return out


_KERNEL_IR = """
import json, sys
import drivedyn.solver.precompile as pc
calls = []
class Stop(BaseException):
    pass
def record(c, workers=None, while_waiting=None):
    calls.extend(c)
    raise Stop
pc.precompile_kernels = record  # the kernels and argument types of the model's first call
sys.path.insert(0, sys.argv[1])
from small_models import speed_jump_spec
from drivedyn.model.compile import compile_model
from drivedyn.solver.simulate import simulate
try:
    simulate(compile_model(speed_jump_spec()), 1e-6)
except Stop:
    pass
out = {}
for disp, sig in calls:
    if disp.py_func.__name__ == "rigid_body_kernel":
        disp.compile(sig)
        out["ir"] = disp.overloads[sig].library.get_llvm_str()
print(json.dumps(out))
"""


def rigid_body_kernel_ir(tmp_path: Path, variable: str) -> tuple[str, str]:
    """The optimised IR of the rigid-body kernel (its element loop and helpers) compiled in
    two new processes at once, each with an empty cache: with the environment ``variable``
    set to 1, and to 0."""
    script = tmp_path / "kernel_ir.py"
    script.write_text(textwrap.dedent(_KERNEL_IR))
    procs = []
    for value in ("1", "0"):
        cache = tmp_path / f"cache{value}"
        cache.mkdir()
        env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), variable: value,
               "DRIVEDYN_COMPILE_WORKERS": "0"}
        env.pop("NUMBA_DISABLE_JIT", None)
        procs.append(subprocess.Popen([sys.executable, str(script), str(Path(__file__).parent)],
                                      env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                      text=True))
    irs = []
    for proc in procs:
        out, err = proc.communicate(timeout=600)
        assert proc.returncode == 0, err[-3000:]
        irs.append(json.loads(out.strip().splitlines()[-1])["ir"])
    return irs[0], irs[1]
