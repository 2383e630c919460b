"""numba's structure proxies kept as LLVM values until something writes to them (a
compile-time saving, installed by :func:`drivedyn.jit.apply`).

numba lowers an array (seven fields: data pointer, shape, strides...), a slice, a range
iterator and every other structure through a *proxy* (``cgutils._StructProxy``). A proxy
made from a value stores that value in a new stack slot, and each field it reads is an
address computation and a load from the slot. An array's ``shape`` is one load per dimension
(each with range metadata), and it is read twice per indexing expression. numba also
asks, for every array proxy, whether its type has an ``__array__`` implementation: plain
arrays never have one, and the failed lookup re-reads numba's registries each time. On the
Type C bench's kernels that was 3657 proxies made from values, 2914 failed lookups, and the
stack slots, stores and loads were Python's work to build and print as IR text, then
LLVM's to parse and remove again (SROA).

:func:`install` changes three things:

- A proxy made from a value holds the value. A field read is one ``extractvalue`` and
  ``_getvalue`` returns the value itself.
- Anything that may change the structure or needs its address materialises the proxy:
  a field write, ``_setvalue``, ``_getpointer`` and numba's own ``_value``/``_outer_ref``
  attributes. The stack slot is then made and the value stored *where the proxy was made*:
  that point dominates every use of the proxy, even if the first write happens in a branch.
  From then on the proxy is numba's, reading and writing the slot (187 of the 3657 on the
  Type C bench).
- numba's array proxy class (``arrayobj.make_array``) is made once per array type. For a
  plain ``types.Array`` it skips the ``__array__`` lookup (numba registers none: the
  array is its own array), and its ``shape`` is one ``extractvalue`` of a proxy still held
  as a value. The per-dimension range metadata is then not written: LLVM drops it anyway
  when SROA removes the slot the loads read.

A proxy made without a value (a new array, view or slice that numba fills field by field)
or from a given slot is numba's as before.

The optimised LLVM IR of the Type C element kernels is numba's own up to the names of
values. The stepping loop and the time functions differ only in the order of independent
instructions (the slots are made in another order), so the same numbers are computed. The
Type C kernels compile with 7 % less CPU (ten simultaneous pairs, issue 16 thirteenth
round, benchmarks/README.md).

Each replacement checks that numba's (llvmlite's) source contains the passages it relies
on; otherwise nothing is installed and numba lowers as before. ``DRIVEDYN_JIT_VALUES=0``
(read when the first kernel module is imported) leaves numba as it is too.
"""

from __future__ import annotations

import contextlib
import inspect
import os
import sys
from collections.abc import Callable, Iterator
from typing import Any

_state: dict = {"installed": None, "originals": None}

#: counts of this process's proxies (for the tests and the benchmarks' figures)
STATS = {"values": 0, "materialised": 0}

# keys of a proxy held as a value in its ``__dict__``
_VALUE = "_drivedyn_value"  # the LLVM value the proxy holds
_AT = "_drivedyn_at"  # (block, instruction before the proxy was made, or None)
_REF = "_drivedyn_ref"  # numba's ``_value`` (pointer to the structure)
_OUTER = "_drivedyn_outer"  # numba's ``_outer_ref``

_PASSAGES = {
    "__init__": ("outer_ref, ref = self._make_refs(ref)",
                 "self._builder.store(value, outer_ref)",
                 "self._value = ref",
                 "self._outer_ref = outer_ref"),
    "__getitem__": ("member_val = self._builder.load(self._get_ptr_by_index(index))",
                    "return self._cast_member_to_value(index, member_val)"),
    "_getvalue": ("return self._builder.load(self._outer_ref)",),
    "_get_ptr_by_index": ("gep_inbounds(self._builder, self._value, 0, index)",),
}
_MAKE_ARRAY_PASSAGES = ("array_impl = self._context.get_function('__array__', sig)",
                        "return super(ArrayStruct, self)._make_refs(ref)",
                        "def shape(self):",
                        "ptr = self._get_ptr_by_name(\"shape\")")
_BUILDER_PASSAGES = {"position_at_end": "self._anchor = len(block.instructions)",
                     "_insert": "self._block.instructions.insert(self._anchor, instr)"}


def _insert_at(builder: Any, block: Any, index: int, emit: Callable[[], Any]) -> Any:
    """Emit ``emit()``'s instruction at ``index`` of ``block`` and put the builder back where
    it was (one place further if it was after ``index`` in the same block)."""
    saved_block, saved_anchor = builder._block, builder._anchor
    builder._block, builder._anchor = block, index
    try:
        return emit()
    finally:
        if saved_block is block and saved_anchor >= index:
            saved_anchor += 1
        builder._block, builder._anchor = saved_block, saved_anchor


def _materialise(proxy: Any) -> None:
    """numba's stack slot for ``proxy``, with its value stored where the proxy was made."""
    from numba.core import debuginfo

    d = proxy.__dict__
    value = d.pop(_VALUE)
    block, after = d.pop(_AT)
    builder = proxy._builder
    entry = builder.function.entry_basic_block
    with debuginfo.suspend_emission(builder):
        if block is entry:  # first in the entry block: before the store
            ref = _insert_at(builder, entry, 0, lambda: builder.alloca(proxy._be_type))
        else:  # where numba puts its slots (the end of the entry block)
            with builder.goto_entry_block():
                ref = builder.alloca(proxy._be_type)
        if after is not None:
            index = block.instructions.index(after) + 1
        else:  # the proxy was made at the start of its block
            index = 1 if block is entry else 0
        _insert_at(builder, block, index, lambda: builder.store(value, ref))
    d[_REF] = d[_OUTER] = ref
    STATS["materialised"] += 1


def _slot_property(key: str) -> property:
    """numba's ``_value`` or ``_outer_ref`` attribute (``key``): the slot, made (and filled)
    on first access if the proxy still holds a value."""
    def get(self: Any) -> Any:
        d = self.__dict__
        if _VALUE in d:
            _materialise(self)
        return d[key]

    def set_(self: Any, ref: Any) -> None:
        self.__dict__[key] = ref

    return property(get, set_)


def _passages_found() -> bool:
    """True if numba's proxy, array proxy and llvmlite's builder are those this relies on."""
    try:
        from llvmlite.ir import builder as irbuilder
        from numba.core import cgutils
        from numba.np import arrayobj

        proxy = cgutils._StructProxy
        for name, passages in _PASSAGES.items():
            src = inspect.getsource(getattr(proxy, name))
            if not all(p in src for p in passages):
                return False
        src = inspect.getsource(arrayobj.make_array)
        if not all(p in src for p in _MAKE_ARRAY_PASSAGES):
            return False
        for name, passage in _BUILDER_PASSAGES.items():
            if passage not in inspect.getsource(getattr(irbuilder.IRBuilder, name)):
                return False
        return hasattr(irbuilder.IRBuilder, "function")
    except (ImportError, AttributeError, OSError, TypeError):  # pragma: no cover - other numba
        return False


def install() -> bool:
    """Install the proxies held as values (once); True if installed."""
    if _state["installed"] is not None:
        return _state["installed"]
    _state["installed"] = False
    if os.environ.get("DRIVEDYN_JIT_VALUES", "1") == "0" or not _passages_found():
        return False
    from numba.core import cgutils, datamodel, types
    from numba.np import arrayobj

    Proxy = cgutils._StructProxy
    init, getitem, getvalue = Proxy.__init__, Proxy.__getitem__, Proxy._getvalue
    make_array = arrayobj.make_array
    classes: dict = {}

    def init_(self, context, builder, value=None, ref=None):
        cls = type(self)
        if (value is None or ref is not None
                or not getattr(cls, "_drivedyn_values", cls._make_refs is Proxy._make_refs)):
            return init(self, context, builder, value, ref)
        # numba's checks, then the value kept (no slot, no store)
        d = self.__dict__
        d["_context"] = context
        model = context.data_model_manager[self._fe_type]
        if not isinstance(model, datamodel.StructModel):
            raise TypeError(f"Not a structure model: {model}")
        d["_datamodel"] = model
        d["_builder"] = builder
        be_type = d["_be_type"] = self._get_be_type(model)
        if value.type != be_type:
            raise AssertionError(f"bad value type: expected {be_type}, got {value.type}")
        block, anchor = builder._block, builder._anchor
        d[_AT] = (block, block.instructions[anchor - 1] if anchor else None)
        d[_VALUE] = value
        STATS["values"] += 1

    def getitem_(self, index):
        value = self.__dict__.get(_VALUE)
        if value is None:
            return getitem(self, index)
        return self._cast_member_to_value(index, self._builder.extract_value(value, index))

    def getvalue_(self):
        value = self.__dict__.get(_VALUE)
        return getvalue(self) if value is None else value

    def proxy_make_refs(self, ref):  # a plain array's: no __array__ to look up
        return Proxy._make_refs(self, ref)

    def make_array_(array_type):
        cls = classes.get(array_type)
        if cls is not None:
            return cls
        cls = make_array(array_type)
        if type(array_type) is types.Array:
            cls._make_refs = proxy_make_refs
            cls._drivedyn_values = True
            if array_type.ndim > 0:
                cls.shape = _value_shape(cls.shape)
        classes[array_type] = cls
        return cls

    for fn, orig in ((init_, init), (getitem_, getitem), (getvalue_, getvalue),
                     (make_array_, make_array)):
        fn.__wrapped__ = orig
        fn.__doc__ = orig.__doc__
    _state["originals"] = (init, getitem, getvalue, make_array)
    Proxy.__init__, Proxy.__getitem__, Proxy._getvalue = init_, getitem_, getvalue_
    Proxy._value = _slot_property(_REF)
    Proxy._outer_ref = _slot_property(_OUTER)
    _set_make_array(make_array, make_array_)
    _state["make_array"] = make_array_
    _state["installed"] = True
    return True


def _value_shape(shape: property) -> property:
    """An array proxy's ``shape``: one ``extractvalue`` while the proxy holds a value,
    numba's per-dimension loads once it has a slot."""
    def value_shape(self):
        value = self.__dict__.get(_VALUE)
        if value is None:
            return shape.fget(self)
        return self._builder.extract_value(value,
                                           self._datamodel.get_field_position("shape"))

    value_shape.__doc__ = shape.__doc__
    return property(value_shape)


def _set_make_array(old: Callable, new: Callable) -> None:
    """Point numba's modules that hold ``make_array`` from ``old`` to ``new`` (those that
    import it later get the module attribute, ``new``)."""
    for name, module in list(sys.modules.items()):
        if (module is not None and name.split(".")[0] == "numba"
                and getattr(module, "make_array", None) is old):
            module.make_array = new


@contextlib.contextmanager
def suspended() -> Iterator[None]:
    """numba's own proxies inside the block (for comparisons in the tests)."""
    if not _state["installed"]:
        yield
        return
    from numba.core import cgutils

    Proxy = cgutils._StructProxy
    init, getitem, getvalue, make_array = _state["originals"]
    mine = (Proxy.__init__, Proxy.__getitem__, Proxy._getvalue, Proxy._value,
            Proxy._outer_ref)
    Proxy.__init__, Proxy.__getitem__, Proxy._getvalue = init, getitem, getvalue
    del Proxy._value, Proxy._outer_ref
    _set_make_array(_state["make_array"], make_array)
    try:
        yield
    finally:
        (Proxy.__init__, Proxy.__getitem__, Proxy._getvalue, Proxy._value,
         Proxy._outer_ref) = mine
        _set_make_array(make_array, _state["make_array"])
