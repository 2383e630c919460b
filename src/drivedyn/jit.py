"""Compile-time fix for numba's IR inliner, applied when a kernel module is imported.

drivedyn's kernels inline their helpers at numba's IR level (``inline="always"``): the
helpers' arithmetic then sits in the element loops, where LLVM optimises it with the loop
(measured: 13 % faster stepping than leaving the inlining to LLVM). numba's inliner copies
the callee's IR at every call site, block by block with ``copy.deepcopy``, and every
variable copies the function's whole scope with it: the cost of one copy grows with the
number of blocks times the number of variables. A copy also is made a second time only to be
returned to callers that discard it (numba issues 8989 and 9204; NVIDIA/numba-cuda#689 removes
the same two costs). On the Type C bench these copies took half of the first compilation.

:func:`apply` replaces ``InlineWorker.inline_ir`` by the same method with the two copies
fixed: the blocks are deep-copied in one call (one memo: the scope is copied once, and all
blocks share it, as they share it in the original), and the unmutated input is returned
instead of a second copy. The method is rebuilt from numba's own source, and only if both
passages are found exactly as expected; otherwise numba is left as it is (slower first
compilation, same results). The compiled machine code is the same either way.

It also replaces ``InlineWorker.inline_function``, which runs the callee's whole untyped
pipeline (bytecode to IR, and its own nested inlining) at every call site, by the same
method with that IR computed once per function (:func:`_inline_function`): 7 % of the Type C
bench's first compilation (82 s -> 76 s of CPU, measured).

Inlining at numba's IR level is what costs first compilation: every inlined call site is
typed and lowered again. Helpers of a few statements that LLVM inlines anyway (``mv``,
``cross``, ``unwrap``...) are therefore plain ``njit`` functions: LLVM inlines them in the
final module (checked in the optimised IR; only the gear's ``_smoothstep`` stays a call),
stepping costs the same, and the Type C bench's first compilation fell from 76 s to 58 s of
CPU. Helpers LLVM would not inline (the projections, the scatter, the contact laws) or whose
literal ``full`` argument matters stay ``inline="always"``: left to LLVM they cost 12-15 % of
the stepping (measured).
"""

from __future__ import annotations

import inspect
import textwrap

_COPY_PER_BLOCK = """\
        kernel_copy.blocks = {}
        for block_label, block in the_ir.blocks.items():
            new_block = copy.deepcopy(the_ir.blocks[block_label])
            kernel_copy.blocks[block_label] = new_block
"""
_COPY_ONCE = """\
        # one deepcopy of all blocks: the scope they share is copied once
        kernel_copy.blocks = copy.deepcopy(the_ir.blocks)
"""
_FIRST_COPY = "    callee_ir = copy_ir(callee_ir)\n"
_FIRST_COPY_KEEP = "    callee_ir_original = callee_ir\n    callee_ir = copy_ir(callee_ir)\n"
_SECOND_COPY = "    callee_ir_original = copy_ir(callee_ir)\n"

_state = {"applied": None}

#: untyped IR of inlined functions, by (function, untyped pipeline): see :func:`apply`
_untyped_ir: dict = {}


def _inline_function(self, caller_ir, block, i, function, arg_typs=None):
    """``InlineWorker.inline_function`` with the callee's untyped IR computed once per
    function (numba runs the callee's whole untyped pipeline, nested inlining included, at
    every call site). Safe because :meth:`inline_ir` copies the IR before it changes it
    ("Always copy the callee IR, it gets mutated") and returns that unchanged input."""
    key = (function, self._compiler_pipeline)
    callee_ir = _untyped_ir.get(key)
    if callee_ir is None:
        callee_ir = self.run_untyped_passes(function)
        _untyped_ir[key] = callee_ir
    return self.inline_ir(caller_ir, block, i, callee_ir, function.__code__.co_freevars,
                          arg_typs=arg_typs)


def apply() -> bool:
    """Install the fixed ``InlineWorker.inline_ir`` (once); True if it is installed."""
    if _state["applied"] is not None:
        return _state["applied"]
    ok = False
    try:
        from numba.core import inline_closurecall as icc

        src = textwrap.dedent(inspect.getsource(icc.InlineWorker.inline_ir))
        body = src.split("\n", 1)[1]  # after the def line; the passages are indented once
        if (src.count(_COPY_PER_BLOCK) == 1 and src.count(_SECOND_COPY) == 1
                and body.count(_FIRST_COPY) == 1):
            new = (src.replace(_COPY_PER_BLOCK, _COPY_ONCE)
                   .replace(_SECOND_COPY, "")
                   .replace(_FIRST_COPY, _FIRST_COPY_KEEP))
            ns = dict(vars(icc))
            exec(compile(new, icc.__file__, "exec"), ns)  # numba's own source, edited above
            fixed = ns["inline_ir"]
            fixed.__doc__ = icc.InlineWorker.inline_ir.__doc__
            fixed.__drivedyn_fixed__ = True
            icc.InlineWorker.inline_ir = fixed
            icc.InlineWorker.inline_function = _inline_function
            ok = True
    except (ImportError, OSError, TypeError, SyntaxError):  # pragma: no cover - other numba
        ok = False
    _state["applied"] = ok
    return ok
