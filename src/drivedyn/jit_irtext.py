"""llvmlite's IR text of numba's modules, printed with fewer Python calls (a compile-time
saving, installed by :func:`drivedyn.jit.apply`).

numba hands every module to LLVM as text: ``str(module)``, parsed back by LLVM. llvmlite
prints an instruction through four layers of ``str.format`` and string caches (the block
formats the instruction, which formats its name, then its operands' types and names, each
looked up in a cache whose first miss raises and catches an ``AttributeError``). For the
Type C bench's first compilation that is 180 000 instructions and 2.2-2.6 s of CPU, 6-7 % of
it; printed as below, 0.3-0.5 s less (measured, issue 16 fourteenth round).

:func:`install` replaces ``Block.descr`` (the loop over a block's instructions) by one that
prints the common instructions (``extractvalue``, ``insertvalue``, ``load``, ``store``,
``getelementptr``, ``icmp``/``fcmp``, ``select``, ``alloca``, casts, ``phi``, branches,
``ret`` and the binary operators) with one f-string each, reading the same caches without
raising. Every other instruction, and any instruction whose text is already cached, is
printed by llvmlite as before. The text is llvmlite's, character for character: each
formatter reproduces one ``descr`` method, and a class gets a formatter only if its method's
source holds the format string the formatter reproduces (another llvmlite: llvmlite's own
printing for that class). ``tests/test_jit_irtext.py`` compares the two printers on every
module of compiled kernels.
"""

from __future__ import annotations

import inspect
from typing import Any

_state: dict = {"installed": None}

# llvmlite's private cache attributes (name-mangled in _StrCaching and
# _StringReferenceCaching): read with dict.get, so a miss costs no exception
_STR = "_StrCaching__cached_str"
_REF = "_StringReferenceCaching__cached_refstr"


def _ref(v: Any) -> str:
    """``v.get_reference()``: llvmlite's cache, else (for the classes that use llvmlite's
    caching ``get_reference``) computed and cached as it does, without its exception."""
    d = getattr(v, "__dict__", None)
    if d is not None:
        r = d.get(_REF)
        if r is not None:
            return r
        if _caching[type(v)]:
            r = d[_REF] = v._get_reference()
            return r
    return v.get_reference()


def _ty(t: Any) -> str:
    """``str(t)`` of an llvmlite type, from its cache when it holds it."""
    d = getattr(t, "__dict__", None)
    if d is not None:
        s = d.get(_STR)
        if s is not None:
            return s
    return str(t)


def _meta(i: Any) -> str:
    """``i._stringify_metadata(leading_comma=True)``."""
    return i._stringify_metadata(leading_comma=True) if i.metadata else ""


def _typed(v: Any) -> str:
    """``"{type} {reference}"`` of an operand."""
    return f"{_ty(v.type)} {_ref(v)}"


def _align(i: Any) -> str:
    a = i.align
    return "" if a is None else ", align %d" % a  # noqa: UP031 - llvmlite's format


# one formatter per class: the text of NamedValue._to_string (the name, then descr), with
# descr's format string written out; _to_string strips trailing whitespace, so do they

def _extractvalue(i: Any) -> str:
    agg = i.aggregate
    return (f"{_ref(i)} = extractvalue {_ty(agg.type)} {_ref(agg)}, "
            f"{', '.join([str(k) for k in i.indices])} {_meta(i)}").rstrip()


def _insertvalue(i: Any) -> str:
    agg, val = i.aggregate, i.value
    return (f"{_ref(i)} = insertvalue {_ty(agg.type)} {_ref(agg)}, {_ty(val.type)} "
            f"{_ref(val)}, {', '.join([str(k) for k in i.indices])} {_meta(i)}").rstrip()


def _load(i: Any) -> str:
    (p,) = i.operands
    return (f"{_ref(i)} = load {_ty(i.type)}, {_ty(p.type)} {_ref(p)}{_align(i)}"
            f"{_meta(i)}").rstrip()


def _store(i: Any) -> str:
    v, p = i.operands
    return (f"store {_ty(v.type)} {_ref(v)}, {_ty(p.type)} {_ref(p)}{_align(i)}"
            f"{_meta(i)}").rstrip()


def _gep(i: Any) -> str:
    p = i.pointer
    op = "getelementptr inbounds" if i.inbounds else "getelementptr"
    return (f"{_ref(i)} = {op} {_ty(i.source_etype)}, {_ty(p.type)} {_ref(p)}, "
            f"{', '.join([_typed(k) for k in i.indices])} {_meta(i)}").rstrip()


def _compare(i: Any) -> str:
    a, b = i.operands[0], i.operands[1]
    flags = "".join([" " + f for f in i.flags])
    return (f"{_ref(i)} = {i.opname}{flags} {i.op} {_ty(a.type)} {_ref(a)}, {_ref(b)} "
            f"{_meta(i)}").rstrip()


def _select(i: Any) -> str:
    c, a, b = i.operands[0], i.operands[1], i.operands[2]
    return (f"{_ref(i)} = select {' '.join(i.flags)} {_ty(c.type)} {_ref(c)}, "
            f"{_ty(a.type)} {_ref(a)}, {_ty(b.type)} {_ref(b)} {_meta(i)}").rstrip()


def _alloca(i: Any) -> str:
    out = f"{_ref(i)} = {i.opname} {_ty(i.allocated_type)}"
    if i.operands:
        (n,) = i.operands
        out += f", {_ty(n.type)} {_ref(n)}"
    if i.align is not None:
        out += f", align {i.align}"
    if i.metadata:
        out += i._stringify_metadata(leading_comma=True)
    return out.rstrip()


def _cast(i: Any) -> str:
    (v,) = i.operands
    return (f"{_ref(i)} = {i.opname} {_ty(v.type)} {_ref(v)} to {_ty(i.type)} "
            f"{_meta(i)}").rstrip()


def _phi(i: Any) -> str:
    incs = ", ".join([f"[{_ref(v)}, {_ref(b)}]" for v, b in i.incomings])
    return f"{_ref(i)} = phi {' '.join(i.flags)} {_ty(i.type)} {incs} {_meta(i)}".rstrip()


def _terminator(i: Any) -> str:
    return f"{i.opname} {', '.join([_typed(v) for v in i.operands])}{_meta(i)}".rstrip()


def _ret(i: Any) -> str:
    if i.operands:
        v = i.operands[0]
        return f"{i.opname} {_ty(v.type)} {_ref(v)}{_meta(i)}".rstrip()
    return f"{i.opname}{_meta(i)}".rstrip()


def _instruction(i: Any) -> str:
    opname = " ".join([i.opname, *i.flags]) if i.flags else i.opname
    return (f"{_ref(i)} = {opname} {_ty(i.type)} "
            f"{', '.join([_ref(v) for v in i.operands])}{_meta(i)}").rstrip()


#: (class name, formatter, passages of the class's ``descr`` the formatter reproduces)
_FORMATTERS = (
    ("ExtractValue", _extractvalue, (
        'buf.append("extractvalue {0} {1}, {2} {3}\\n".format(', "self.aggregate.type,",
        "self.aggregate.get_reference(),", "', '.join(indices),",
        "indices = [str(i) for i in self.indices]")),
    ("InsertValue", _insertvalue, (
        'buf.append("insertvalue {0} {1}, {2} {3}, {4} {5}\\n".format(',
        "self.aggregate.type, self.aggregate.get_reference(),",
        "self.value.type, self.value.get_reference(),",
        "indices = [str(i) for i in self.indices]")),
    ("LoadInstr", _load, (
        'buf.append("load {0}, {1} {2}{3}{4}\\n".format(', "align = ', align %d' % (self.align)",
        "[val] = self.operands")),
    ("StoreInstr", _store, (
        'buf.append("store {0} {1}, {2} {3}{4}{5}\\n".format(',
        "align = ', align %d' % (self.align)", "val, ptr = self.operands")),
    ("GEPInstr", _gep, (
        'buf.append("{0} {1}, {2} {3}, {4} {5}\\n".format(',
        "indices = ['{0} {1}'.format(i.type, i.get_reference())",
        'op = "getelementptr inbounds" if self.inbounds else "getelementptr"',
        "self.source_etype,", "self.pointer.type,")),
    ("ICMPInstr", _compare, (
        'buf.append("{opname}{flags} {op} {ty} {lhs}, {rhs} {meta}\\n".format(',
        "flags=''.join(' ' + it for it in self.flags),", "ty=self.operands[0].type,")),
    ("FCMPInstr", _compare, (
        'buf.append("{opname}{flags} {op} {ty} {lhs}, {rhs} {meta}\\n".format(',
        "flags=''.join(' ' + it for it in self.flags),", "ty=self.operands[0].type,")),
    ("SelectInstr", _select, (
        'buf.append("select {0} {1} {2}, {3} {4}, {5} {6} {7}\\n".format(',
        "' '.join(self.flags),", "self.cond.type, self.cond.get_reference(),")),
    ("AllocaInstr", _alloca, (
        'buf.append("{0} {1}".format(self.opname, self.allocated_type))',
        'buf.append(", {0} {1}".format(op.type, op.get_reference()))',
        'buf.append(", align {0}".format(self.align))',
        "buf.append(self._stringify_metadata(leading_comma=True))")),
    ("CastInstr", _cast, (
        'buf.append("{0} {1} {2} to {3} {4}\\n".format(', "self.operands[0].type,",
        "self.type,")),
    ("PhiInstr", _phi, (
        "incs = ', '.join('[{0}, {1}]'.format(v.get_reference(),",
        'buf.append("phi {0} {1} {2} {3}\\n".format(', "' '.join(self.flags),")),
    ("Branch", _terminator, (
        'operands = \', \'.join(["{0} {1}".format(op.type, op.get_reference())',
        'buf.append("{0} {1}{2}".format(opname, operands, metadata))')),
    ("ConditionalBranch", _terminator, (
        'operands = \', \'.join(["{0} {1}".format(op.type, op.get_reference())',
        'buf.append("{0} {1}{2}".format(opname, operands, metadata))')),
    ("Ret", _ret, (
        'buf.append("{0} {1} {2}{3}\\n"', 'buf.append("{0}{1}\\n".format(self.opname, metadata))',
        "return_value.get_reference(),")),
    ("Instruction", _instruction, (
        "opname = ' '.join([opname] + self.flags)",
        "operands = ', '.join([op.get_reference() for op in self.operands])",
        'buf.append("{0} {1} {2}{3}\\n"', ".format(opname, typ, operands, metadata))")),
)

class _CachingClasses(dict):
    """class -> True if its ``get_reference`` is llvmlite's caching one (set by
    :func:`install`), False if the class has its own."""

    method: Any = None

    def __missing__(self, cls: type) -> bool:
        ok = self[cls] = self.method is not None and getattr(cls, "get_reference",
                                                             None) is self.method
        return ok


_caching = _CachingClasses()


#: formatter by exact class, and whether it prints a name (a non-void instruction):
#: subclasses and anything else print as llvmlite prints them
_fast: dict = {}
#: formatters of void instructions (no name printed), as NamedValue._to_string decides
_VOID = (_store, _terminator, _ret)


def install() -> bool:
    """Install the block printer (once); True if installed with a formatter for every class
    of :data:`_FORMATTERS`."""
    if _state["installed"] is not None:
        return _state["installed"]
    _state["installed"] = False
    try:
        from llvmlite.ir import _utils, instructions, types, values

        block_src = inspect.getsource(values.Block.descr)
        str_src = inspect.getsource(_utils._StrCaching.__str__)
        ref_src = inspect.getsource(_utils._StringReferenceCaching.get_reference)
        named_src = inspect.getsource(values.NamedValue._to_string)
    except (ImportError, AttributeError, OSError, TypeError):  # pragma: no cover - other llvmlite
        return False
    if not ('buf += ["  {0}\\n".format(instr) for instr in self.instructions]' in block_src
            and 'buf.append("{0}:\\n".format(self._format_name()))' in block_src
            and "s = self.__cached_str = self._to_string()" in str_src
            and "s = self.__cached_refstr = self._get_reference()" in ref_src
            and 'buf.append("{0} = ".format(self.get_reference()))' in named_src
            and 'return "".join(buf).rstrip()' in named_src
            and "if not isinstance(self.type, types.VoidType):" in named_src):
        return False  # pragma: no cover - another llvmlite
    for name, fmt, passages in _FORMATTERS:
        cls = getattr(instructions, name, None)
        try:
            src = inspect.getsource(cls.descr)
        except (AttributeError, OSError, TypeError):  # pragma: no cover - other llvmlite
            continue
        if all(p in src for p in passages):
            _fast[cls] = (fmt, fmt not in _VOID)
    void = types.VoidType
    _CachingClasses.method = _utils._StringReferenceCaching.get_reference

    def text(instr: Any) -> str:
        """``str(instr)``: llvmlite's cached text, else the class's formatter (its text
        cached as llvmlite caches its own), else llvmlite's printing."""
        d = instr.__dict__
        s = d.get(_STR)
        if s is not None:
            return s
        entry = _fast.get(type(instr))
        if entry is None or entry[1] == isinstance(instr.type, void):
            return str(instr)
        s = d[_STR] = entry[0](instr)
        return s

    def descr(self, buf):
        buf.append(f"{self._format_name()}:\n")
        buf += [f"  {text(instr)}\n" for instr in self.instructions]

    descr.__wrapped__ = values.Block.descr
    descr.__doc__ = values.Block.descr.__doc__
    values.Block.descr = descr
    _state["installed"] = len(_fast) == len(_FORMATTERS)
    return _state["installed"]
