"""Packing of time functions into flat arrays for numba kernels: :class:`TimeFunctionPool`
collects them, :class:`PackedTimeFunctions` holds the arrays that
:func:`~drivedyn.timefunctions.kernels.eval_time_functions` reads.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, NamedTuple

import numpy as np

from drivedyn.timefunctions.functions import (
    Constant,
    Held,
    Ramp,
    SmoothStep,
    Table,
    TimeFunction,
    as_time_function,
)
from drivedyn.timefunctions.kernels import (
    KIND_CONSTANT,
    KIND_HELD,
    KIND_RAMP,
    KIND_SMOOTH_STEP,
    KIND_TABLE,
    eval_time_functions,
)


class PackedTimeFunctions(NamedTuple):
    """Flat-array form of a set of time functions, for numba kernels.

    * ``kind`` (nterms,) int64 -- term kinds (0 constant, 1 ramp, 2 smooth step, 3 table,
      4 held input);
    * ``par`` (nterms, 4) float64 -- term parameters: constant ``[value, 0, 0, 0]``,
      ramp / smooth step ``[t0, t1, v0, v1]``, table ``[offset, npoints, 0, 0]``, held
      input ``[value, t_held, integral at t_held, scale]``;
    * ``fstart`` (nf + 1,) int64 -- terms of function ``i`` are ``fstart[i]:fstart[i+1]``;
    * ``tab`` (>= 1,) float64 -- table storage: ``tab[offset:offset+n]`` times [s],
      ``tab[offset+n:offset+2n]`` values (a single 0 if there are no tables).
    """

    kind: np.ndarray
    par: np.ndarray
    fstart: np.ndarray
    tab: np.ndarray

    @property
    def n_functions(self) -> int:
        """Number of packed functions."""
        return int(self.fstart.shape[0] - 1)

    def evaluate(self, t: float) -> np.ndarray:
        """``(nf, 4)`` array of ``[value, d/dt, d2/dt2, int_0^t]`` at ``t`` [s] (allocates)."""
        out = np.zeros((self.n_functions, 4))
        eval_time_functions(float(t), self.kind, self.par, self.fstart, self.tab, out)
        return out


class TimeFunctionPool:
    """Collects time functions and packs them for numba kernels.

    ``add`` returns consecutive integer ids 0, 1, 2, ... (no de-duplication); the id is the
    row of the function in the output of :func:`eval_time_functions`.
    """

    def __init__(self) -> None:
        self._functions: list[TimeFunction] = []

    def add(self, f: TimeFunction | float | Mapping[str, Any]) -> int:
        """Register ``f`` (anything accepted by :func:`as_time_function`); return its id."""
        self._functions.append(as_time_function(f))
        return len(self._functions) - 1

    def __len__(self) -> int:
        return len(self._functions)

    def __getitem__(self, i: int) -> TimeFunction:
        return self._functions[i]

    @property
    def functions(self) -> tuple[TimeFunction, ...]:
        """Registered functions in id order."""
        return tuple(self._functions)

    def held_terms(self) -> dict[str, list[int]]:
        """Input name -> rows of :attr:`PackedTimeFunctions.par` of its :class:`Held` terms
        (in the order :meth:`pack` lays the terms out)."""
        out: dict[str, list[int]] = {}
        k = 0
        for f in self._functions:
            for term in f.terms():
                if isinstance(term, Held):
                    out.setdefault(term.name, []).append(k)
                k += 1
        return out

    def pack(self) -> PackedTimeFunctions:
        """Flat arrays of all registered functions (see :class:`PackedTimeFunctions`)."""
        kinds: list[int] = []
        pars: list[tuple[float, float, float, float]] = []
        fstart = [0]
        tab: list[float] = []
        for f in self._functions:
            for term in f.terms():
                if isinstance(term, Constant):
                    kinds.append(KIND_CONSTANT)
                    pars.append((term.value, 0.0, 0.0, 0.0))
                elif isinstance(term, SmoothStep):
                    kinds.append(KIND_SMOOTH_STEP)
                    pars.append((term.t0, term.t1, term.v0, term.v1))
                elif isinstance(term, Ramp):
                    kinds.append(KIND_RAMP)
                    pars.append((term.t0, term.t1, term.v0, term.v1))
                elif isinstance(term, Held):
                    kinds.append(KIND_HELD)
                    pars.append((term.scale * term.start, 0.0, 0.0, term.scale))
                elif isinstance(term, Table):
                    n = len(term.times)
                    kinds.append(KIND_TABLE)
                    pars.append((float(len(tab)), float(n), 0.0, 0.0))
                    tab.extend(term.times)
                    tab.extend(term.values)
                else:
                    raise TypeError(f"cannot pack time function term {term!r}")
            fstart.append(len(kinds))
        return PackedTimeFunctions(
            kind=np.array(kinds, dtype=np.int64),
            par=np.array(pars, dtype=np.float64).reshape(len(pars), 4),
            fstart=np.array(fstart, dtype=np.int64),
            tab=np.array(tab if tab else [0.0], dtype=np.float64),
        )
