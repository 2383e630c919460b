"""numba's SSA reconstruction and post-processing without their repeated work, no ``del``
statements where they do nothing, and llvmlite's entry-block positioning without its search
(compile-time savings, installed by :func:`drivedyn.jit.apply`).

numba's untyped and typed pipelines spent a sixth of the Type C bench's first compilation in
two analyses that do far more work than their results need (measured, issue 16 twelfth
round: 19.5 -> 12.8 s of CPU in numba's passes other than lowering, same machine, same time):

- **SSA reconstruction** (``numba.core.ssa``). For every variable assigned more than once
  (hundreds in an element loop after inlining) numba rewrites *every* block of the function
  twice, once to give the assignments fresh names and once to point each use at its reaching
  definition: its cost is the number of such variables times the number of statements. Only
  the blocks that name the variable can change, plus the blocks where a phi node of it is
  placed. :func:`_run_ssa` gives numba's two rewrites only those blocks (in the same order,
  so the fresh names and phi nodes are numbered as numba numbers them) and adds the phi nodes
  of the others as numba does. The IR is the same, statement for statement
  (``tests/test_jit_passes.py`` compares the dumps; so did a check of all 90 functions the
  Type C bench compiles). 3.3 -> 0.7 s.
- **Liveness after each IR change** (``numba.core.postproc.PostProcessor.run``). About ten
  passes per function end with a post-processing run, and each run computed the variables
  alive at every block entry (the CFG, use-def maps, live map, dead maps and a fix point).
  That result is read only by the object-mode lowering and the generator analysis, and each
  run overwrites the previous one. The run now stores it as a mapping computed when first
  read (:class:`LazyEntryVars`), for the blocks as they are then; generators get it at once,
  as before, and ``FunctionIR.copy`` passes it on still pending. What a run must do is
  unchanged: the canonical CFG, the variable lifetimes (computed lazily by numba itself) and
  the ``del`` statements when asked.

Every one of these analyses lists the variables of each statement (``list_vars``), which
numba did with a Python call per attribute value of the statement (:func:`_install_list_vars`:
the same lists, about 5 % less compile CPU, measured in simultaneous pairs, issue 16
thirteenth round).

Functions compiled without reference counting are lowered without ``del`` statements, which
only decref (nothing, there) (:func:`_install_no_dels_without_nrt`: the same optimised IR,
about 5 % less compile CPU in simultaneous pairs, issue 16 fourteenth round).

And in lowering, numba puts every stack slot (one per array a statement indexes) before the
entry block's terminator, which llvmlite located by searching the block: a search through
all earlier slots for each new one (:func:`_install_position_before_terminator`).

Each replacement is installed only if numba's (llvmlite's) source contains the passages it
replaces (the post-processor is rebuilt from numba's own source with one passage edited, as
:func:`drivedyn.jit.apply` does for the inliner); otherwise numba is left as it is: slower
first compilation, same results.
"""

from __future__ import annotations

import inspect
import textwrap
from collections import defaultdict
from typing import Any

_state: dict = {"installed": None}


class LazyEntryVars(dict):
    """``FunctionIR.block_entry_vars`` (block -> names possibly alive at its entry), computed
    on first access by ``compute()`` and added to the entries ``previous`` holds."""

    __slots__ = ("_compute",)

    def __init__(self, previous: dict, compute: Any) -> None:
        super().__init__(previous)
        self._compute = compute

    @property
    def pending(self) -> bool:
        """True while the entries are not computed."""
        return self._compute is not None

    def fill(self) -> LazyEntryVars:
        """Compute the entries now (once); returns self."""
        compute, self._compute = self._compute, None
        if compute is not None:
            dict.update(self, compute())
        return self

    __hash__ = None  # a dict

    def copy(self) -> dict:
        return dict(self.fill())

    def __reduce__(self):  # pickled and deep-copied as numba's plain mapping
        return dict, (dict(self.fill()),)


def _filled(name: str):
    """``dict.<name>`` applied after :meth:`LazyEntryVars.fill`."""
    method = getattr(dict, name)

    def filled(self, *args, **kwargs):
        return method(self.fill(), *args, **kwargs)

    filled.__name__ = name
    filled.__doc__ = method.__doc__
    return filled


# every way of reading or changing a dict sees the computed entries
for _name in ("__getitem__", "__setitem__", "__delitem__", "__contains__", "__iter__",
              "__reversed__", "__len__", "__eq__", "__ne__", "__or__", "__ior__", "__repr__",
              "get", "keys", "values", "items", "pop", "popitem", "setdefault", "update",
              "clear"):
    setattr(LazyEntryVars, _name, _filled(_name))


def _computed(entries: dict) -> dict:
    """The entries of ``entries`` already known, without computing a pending lazy part."""
    if isinstance(entries, LazyEntryVars) and entries.pending:
        return {k: v for k, v in dict.items(entries)}
    return entries


def lazy_entry_vars(func_ir) -> LazyEntryVars:
    """The block-entry liveness of ``func_ir`` as numba's post-processor computes it, for
    the function's blocks when first read (the same value as at the run if the IR has not
    changed since, as for numba's readers, which lower the IR the last run saw).

    numba's own run adds to the mapping: earlier entries are kept, except those a pending
    lazy mapping never computed (they describe blocks that are gone)."""
    from numba.core import analysis, postproc

    def compute() -> dict:
        blocks = func_ir.blocks
        vlt = postproc.VariableLifetime(blocks)
        bev = analysis.compute_live_variables(vlt.cfg, blocks, vlt.usedefs.defmap,
                                              vlt.deadmaps.combined)
        return {block: bev[offset] for offset, block in blocks.items()}

    entry = LazyEntryVars(_computed(func_ir.block_entry_vars), compute)
    if func_ir.is_generator:  # the generator analysis reads it at once: as numba does
        entry.fill()
    return entry


_EAGER_ENTRY_VARS = """\
    bev = analysis.compute_live_variables(vlt.cfg, self.func_ir.blocks,
                                          vlt.usedefs.defmap,
                                          vlt.deadmaps.combined)
    for offset, ir_block in self.func_ir.blocks.items():
        self.func_ir.block_entry_vars[ir_block] = bev[offset]
"""
_LAZY_ENTRY_VARS = """\
    # drivedyn.jit_passes: computed when first read (only object mode and generators do)
    self.func_ir.block_entry_vars = _drivedyn_lazy_entry_vars(self.func_ir)
"""


def _install_lazy_entry_liveness() -> bool:
    """Replace ``PostProcessor.run`` by numba's own source with the block-entry liveness made
    lazy (:func:`lazy_entry_vars`), and let ``FunctionIR.copy`` keep it lazy; True if
    installed."""
    try:
        from numba.core import ir, postproc

        src = textwrap.dedent(inspect.getsource(postproc.PostProcessor.run))
        src_copy = inspect.getsource(ir.FunctionIR.copy)
    except (ImportError, AttributeError, OSError, TypeError):  # pragma: no cover - other numba
        return False
    if (src.count(_EAGER_ENTRY_VARS) != 1
            or "block_entry_vars" in src.replace(_EAGER_ENTRY_VARS, "")
            or "if block in self.block_entry_vars:" not in src_copy):
        return False  # pragma: no cover - another numba: its own post-processor
    ns = dict(vars(postproc))
    ns["_drivedyn_lazy_entry_vars"] = lazy_entry_vars
    exec(compile(src.replace(_EAGER_ENTRY_VARS, _LAZY_ENTRY_VARS), postproc.__file__, "exec"),
         ns)  # numba's own source, edited above
    run = ns["run"]
    run.__wrapped__ = postproc.PostProcessor.run
    run.__doc__ = postproc.PostProcessor.run.__doc__
    postproc.PostProcessor.run = run
    copy = ir.FunctionIR.copy

    def copy_ir(self):
        # numba's copy maps each block's entries to the copied block: with entries not yet
        # computed, the copy gets its own pending mapping (the liveness of the same blocks)
        entries = self.block_entry_vars
        if not (isinstance(entries, LazyEntryVars) and entries.pending):
            return copy(self)
        self.block_entry_vars = {}
        try:
            new = copy(self)
        finally:
            self.block_entry_vars = entries
        new.block_entry_vars = lazy_entry_vars(new)
        return new

    copy_ir.__wrapped__ = copy
    copy_ir.__doc__ = copy.__doc__
    ir.FunctionIR.copy = copy_ir
    return True


# --- SSA reconstruction over the blocks that name each variable --------------------------------

#: passages of numba's SSA module that :func:`_run_ssa` reproduces with fewer blocks
_SSA_PASSAGES = {
    "_run_ssa": ("blocks, defmap = _fresh_vars(blocks, varname)",
                 "blocks = _fix_ssa_vars(blocks, varname, defmap, cfg, df_plus,",
                 "violators = _find_defs_violators(blocks, cfg)",
                 "cache_list_vars = _CacheListVars()",
                 'raise errors.CompilerError("CFG mutated in SSA pass")'),
    "_fresh_vars": ("newblocks = _run_block_rewrite(blocks, states, _FreshVarHandler())",),
    "_fix_ssa_vars": ("states['phi_locations'] = _compute_phi_locations(df_plus, defmap)",
                      "newblocks = _run_block_rewrite(blocks, states, "
                      "_FixSSAVars(cache_list_vars))",
                      "curblk.body = philist + curblk.body"),
}


def _naming_blocks(blocks: dict) -> dict:
    """Variable name -> labels of the blocks that assign or use it, in block order."""
    where: dict = defaultdict(list)
    for label, block in blocks.items():
        names = set()
        for stmt in block.body:
            names.update(var.name for var in stmt.list_vars())
        for name in names:
            where[name].append(label)
    return where


def _run_ssa(blocks: dict) -> dict:
    """numba's ``ssa._run_ssa`` with each violating variable's two rewrites run over the
    blocks that name it, not over all blocks (same statements, names and phi nodes)."""
    from numba.core import errors, ir, ssa

    if not blocks:
        return {}
    cfg = ssa.compute_cfg_from_blocks(blocks)
    df_plus = ssa._iterated_domfronts(cfg)
    violators = ssa._find_defs_violators(blocks, cfg)
    cache_list_vars = ssa._CacheListVars()
    # a rewrite for one variable changes only its own names: what the others name stays
    where = _naming_blocks(blocks) if violators else {}
    for varname in violators:
        labels = where[varname]
        # fresh names for the assignments (numba's _fresh_vars over those blocks)
        states = ssa._make_states(blocks)
        states["varname"] = varname
        states["defmap"] = defmap = defaultdict(list)
        fresh = ssa._run_block_rewrite({k: blocks[k] for k in labels}, states,
                                       ssa._FreshVarHandler())
        blocks = {k: fresh.get(k, b) for k, b in blocks.items()}
        # uses to reaching definitions, phi nodes where needed (numba's _fix_ssa_vars)
        states = ssa._make_states(blocks)
        states["varname"] = varname
        states["defmap"] = defmap
        states["phimap"] = phimap = defaultdict(list)
        states["cfg"] = cfg
        states["phi_locations"] = ssa._compute_phi_locations(df_plus, defmap)
        fixed = ssa._run_block_rewrite({k: blocks[k] for k in labels}, states,
                                       ssa._FixSSAVars(cache_list_vars))
        for label, philist in phimap.items():
            block = fixed.get(label)
            if block is None:  # a phi in a block that does not name the variable
                old = blocks[label]
                block = fixed[label] = ir.Block(scope=old.scope, loc=old.loc)
                block.body = list(old.body)
            block.body = philist + block.body
        blocks = {k: fixed.get(k, b) for k, b in blocks.items()}
    if ssa.compute_cfg_from_blocks(blocks) != cfg:
        raise errors.CompilerError("CFG mutated in SSA pass")
    return blocks


def _install_sparse_ssa() -> bool:
    """Replace ``numba.core.ssa._run_ssa`` by :func:`_run_ssa`; True if installed."""
    try:
        from numba.core import ssa

        for name, passages in _SSA_PASSAGES.items():
            src = inspect.getsource(getattr(ssa, name))
            if not all(p in src for p in passages):
                return False  # pragma: no cover - another numba: its own SSA
        for name in ("compute_cfg_from_blocks", "_iterated_domfronts", "_make_states",
                     "_run_block_rewrite", "_FreshVarHandler", "_FixSSAVars",
                     "_compute_phi_locations", "_CacheListVars", "reconstruct_ssa"):
            getattr(ssa, name)
    except (ImportError, AttributeError, OSError, TypeError):  # pragma: no cover - other numba
        return False
    _run_ssa.__wrapped__ = ssa._run_ssa
    ssa._run_ssa = _run_ssa  # reconstruct_ssa reads the module global at each call
    return True


# --- lowering: the entry block's position ------------------------------------------------------


def _install_position_before_terminator() -> bool:
    """Let llvmlite's ``IRBuilder.position_before`` find a block's last instruction without
    searching the block; True if installed.

    numba puts every stack slot in the function's entry block, before its terminator
    (``goto_entry_block``), and llvmlite finds that terminator with ``list.index``: a search
    through all the slots made so far, for each new one (an element loop has thousands). The
    position is the same: an instruction is inserted in one place, so the last one's index is
    the length less one (the search is kept for any other instruction)."""
    try:
        from llvmlite.ir import builder

        src = inspect.getsource(builder.IRBuilder.position_before)
    except (ImportError, AttributeError, OSError, TypeError):  # pragma: no cover - other llvmlite
        return False
    if "self._anchor = self._block.instructions.index(instr)" not in src:
        return False  # pragma: no cover - another llvmlite
    position_before = builder.IRBuilder.position_before

    def position_before_last(self, instr):
        block = instr.parent
        insts = block.instructions
        if insts and insts[-1] is instr:
            self._block = block
            self._anchor = len(insts) - 1
        else:
            position_before(self, instr)

    position_before_last.__wrapped__ = position_before
    position_before_last.__doc__ = position_before.__doc__
    builder.IRBuilder.position_before = position_before_last
    return True


def _install_list_vars() -> bool:
    """List the variables of numba's IR statements without a Python call per leaf value;
    True if installed.

    numba's ``Inst._rec_list_vars`` lists the variables a statement reads or writes by
    recursing into every attribute value (locations, strings, numbers, nested lists), one
    call per value: every liveness, use-def and SSA analysis calls it on every statement, 1.8
    million calls in the Type C bench's first compilation. :func:`_collect` walks the same
    values in the same order, iterating containers in place and skipping values whose type
    cannot hold a variable; any other value goes through numba's own tests, in numba's
    order, so the result is numba's list (checked against numba's on all 2.8 million calls of
    that compilation, and in ``tests/test_jit_passes.py``)."""
    try:
        from numba.core import ir

        src = inspect.getsource(ir.Inst._rec_list_vars)
    except (ImportError, AttributeError, OSError, TypeError):  # pragma: no cover - other numba
        return False
    if not ("if isinstance(val, Var):" in src and "elif isinstance(val, Inst):" in src
            and "return val.list_vars()" in src and "for v in val.values():" in src
            and "elif isinstance(val, (list, tuple)):" in src):
        return False  # pragma: no cover - another numba
    original = ir.Inst._rec_list_vars
    var, inst = ir.Var, ir.Inst
    # types that are none of Var, Inst, list, tuple, dict (nor subclasses): no variables
    leaves = frozenset((str, int, float, bool, complex, bytes, type(None), ir.Loc))

    def _collect(val, out):
        t = type(val)
        if t is dict:
            items = val.values()
        elif t is list or t is tuple:
            items = val
        elif t is var:
            out.append(val)
            return
        elif t in leaves:
            return
        elif isinstance(val, var):  # numba's tests, in numba's order
            out.append(val)
            return
        elif isinstance(val, inst):
            out.extend(val.list_vars())
            return
        elif isinstance(val, (list, tuple)):
            items = val
        elif isinstance(val, dict):
            items = val.values()
        else:
            return
        for v in items:
            tv = type(v)
            if tv is var:
                out.append(v)
            elif tv not in leaves:
                _collect(v, out)

    def _rec_list_vars(self, val):
        out: list = []
        _collect(val, out)
        return out

    _rec_list_vars.__wrapped__ = original
    _rec_list_vars.__doc__ = original.__doc__
    ir.Inst._rec_list_vars = _rec_list_vars
    return True


# --- legalization: no ``del`` statements where they do nothing ------------------------------


def _install_no_dels_without_nrt() -> bool:
    """Let numba's last pass before lowering leave out the ``del`` statements of functions
    compiled without reference counting; True if installed.

    ``check_and_legalize_ir`` runs the post-processor once more to insert a ``del`` after the
    last use of every variable (a liveness analysis of the whole function), and lowering turns
    each ``del`` into a decref of the variable's value. Without reference counting (numba's
    ``_nrt=False``: the element loops of :func:`drivedyn.jit.outlined`) a decref is nothing:
    the ``del`` statements only make lowering create the variables' stack slots up front (in
    the entry block, where it also creates any slot a variable first needs), and a dead load
    from each slot that LLVM removes. The Type C bench's 30 such functions carry 13 000
    ``del`` statements: their analysis and lowering were about 2 % of its first compilation.
    Functions with reference counting, Python objects (object mode), debug information,
    extended lifetimes or generators are legalised as numba does it."""
    try:
        from numba.core import ir_utils, lowering, postproc, typed_passes

        legalize = typed_passes.check_and_legalize_ir
        src = inspect.getsource(legalize)
        run_src = inspect.getsource(typed_passes.IRLegalization.run_pass)
        getvar_src = inspect.getsource(lowering.Lower.getvar)
        delvar_src = inspect.getsource(lowering.Lower.delvar)
    except (ImportError, AttributeError, OSError, TypeError):  # pragma: no cover - other numba
        return False
    if not ("enforce_no_phis(func_ir)" in src and "enforce_no_dels(func_ir)" in src
            and "post_proc.run(True, extend_lifetimes=flags.dbg_extend_lifetimes)" in src
            and "check_and_legalize_ir(state.func_ir, flags=state.flags)" in run_src
            and "if name not in self.varmap:" in getvar_src
            and "self._alloca_var(name, self.typeof(name))" in getvar_src
            and "self.decref(fetype, llval)" in delvar_src):
        return False  # pragma: no cover - another numba

    def check_and_legalize_ir(func_ir, flags):
        if (flags.nrt or flags.debuginfo or flags.dbg_extend_lifetimes
                or flags.force_pyobject or flags.enable_pyobject or func_ir.is_generator):
            return legalize(func_ir, flags)
        ir_utils.enforce_no_phis(func_ir)
        ir_utils.enforce_no_dels(func_ir)
        postproc.PostProcessor(func_ir).run(False)
        return None

    check_and_legalize_ir.__wrapped__ = legalize
    check_and_legalize_ir.__doc__ = legalize.__doc__
    typed_passes.check_and_legalize_ir = check_and_legalize_ir  # IRLegalization's global
    return True


def install() -> bool:
    """Install the five replacements (once); True if all are installed."""
    if _state["installed"] is not None:
        return _state["installed"]
    _state["lazy_entry_liveness"] = _install_lazy_entry_liveness()
    _state["sparse_ssa"] = _install_sparse_ssa()
    _state["position_before"] = _install_position_before_terminator()
    _state["list_vars"] = _install_list_vars()
    _state["no_dels"] = _install_no_dels_without_nrt()
    _state["installed"] = all(_state[k] for k in ("lazy_entry_liveness", "sparse_ssa",
                                                   "position_before", "list_vars",
                                                   "no_dels"))
    return _state["installed"]
