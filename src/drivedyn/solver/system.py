"""Global residual and iteration matrix of a compiled model (no element knowledge here)."""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from drivedyn.elements.framework.contract import MODE_DYN, MODE_VEL
from drivedyn.model.model import Model, State
from drivedyn.rotations import tangent_into
from drivedyn.solver.redundancy import (
    Redundancy,
    hold_multipliers,
    jacobian,
    report_start,
    set_aside,
    watched,
)
from drivedyn.timefunctions import eval_time_functions

log = logging.getLogger("drivedyn")

if TYPE_CHECKING:
    import scipy.sparse as sp

    from drivedyn.solver.kernel_calls import KernelTable


# Rodrigues' coefficients sin(t)/t and (1 - cos t)/t^2 of a node's rotation increment by
# their Taylor series up to t^10 below t = 0.1 (SERIES_T2 = t^2): the first term left out is
# below 1e-17 of the sum there, and the series is within 0.25 ulp of the exact values
# (measured against 40-digit arithmetic) where sin(t)/t and 2 sin^2(t/2)/t^2 are within
# 0.64 and 1.5 ulp; it takes no sin. A spinning part turns by 1e-3-1e-2 rad per step.
SERIES_T2 = 1e-2
_A1, _A2, _A3, _A4, _A5 = -1 / 6, 1 / 120, -1 / 5040, 1 / 362880, -1 / 39916800
_B1, _B2, _B3, _B4, _B5 = -1 / 24, 1 / 720, -1 / 40320, 1 / 3628800, -1 / 479001600


@njit(cache=True)
def lie_update(x0, R0, hdq, nn, x, R, Tn, with_tangent):
    """Positions ``x = x0 + hdq_x`` and rotations ``R = R0 exp(hdq_theta)`` of all nodes.

    ``hdq`` (6 nn,) is the Lie-algebra increment of the step; if ``with_tangent``, ``Tn``
    receives the tangent operators T(hdq_theta) (the ground row stays identity).
    Written without temporaries (Rodrigues' formula expanded) because it runs every
    Newton iteration over all nodes.
    """
    E = np.empty((3, 3))
    for i in range(nn):
        d = 6 * i
        for a in range(3):
            x[i, a] = x0[i, a] + hdq[d + a]
        p0 = hdq[d + 3]
        p1 = hdq[d + 4]
        p2 = hdq[d + 5]
        t2 = p0 * p0 + p1 * p1 + p2 * p2
        if t2 < SERIES_T2:
            ca = 1.0 + t2 * (_A1 + t2 * (_A2 + t2 * (_A3 + t2 * (_A4 + t2 * _A5))))
            cb = 0.5 + t2 * (_B1 + t2 * (_B2 + t2 * (_B3 + t2 * (_B4 + t2 * _B5))))
        else:
            t = np.sqrt(t2)
            ca = np.sin(t) / t
            sh = np.sin(0.5 * t) / t
            cb = 2.0 * sh * sh
        # E = I + ca S + cb S^2, S = skew(p); S^2 = p p^T - t2 I
        E[0, 0] = 1.0 + cb * (p0 * p0 - t2)
        E[1, 1] = 1.0 + cb * (p1 * p1 - t2)
        E[2, 2] = 1.0 + cb * (p2 * p2 - t2)
        E[0, 1] = -ca * p2 + cb * p0 * p1
        E[1, 0] = ca * p2 + cb * p0 * p1
        E[0, 2] = ca * p1 + cb * p0 * p2
        E[2, 0] = -ca * p1 + cb * p0 * p2
        E[1, 2] = -ca * p0 + cb * p1 * p2
        E[2, 1] = ca * p0 + cb * p1 * p2
        for a in range(3):
            r0 = R0[i, a, 0]
            r1 = R0[i, a, 1]
            r2 = R0[i, a, 2]
            for b in range(3):
                R[i, a, b] = r0 * E[0, b] + r1 * E[1, b] + r2 * E[2, b]
        if with_tangent:
            tangent_into(p0, p1, p2, Tn, i)


@njit(cache=True)
def tangents(hdq, nn, Tn):
    """Tangent operators T(hdq_theta) (3, 3) of all nodes into ``Tn``."""
    for i in range(nn):
        tangent_into(hdq[6 * i + 3], hdq[6 * i + 4], hdq[6 * i + 5], Tn, i)


class System:
    """Evaluates the model's residual and iteration matrix into preallocated arrays.

    Attributes:
        r: (neq,) residual of the last evaluation.
        rabs: (neq,) sum of absolute element contributions per equation (scales for the
            convergence test).
        data: (nnz,) CSC values of the last assembled matrix.
        tfv: (nfun, 4) time-function values at the last evaluation time.
        Tn: (nn+1, 3, 3) tangent operators used in ``MODE_DYN`` assembly.
        redundancy: the constraint rows set aside as redundant
            (:class:`~drivedyn.solver.redundancy.Redundancy`; none until
            :meth:`detect_redundancy`).
    """

    def __init__(self, model: Model) -> None:
        self.model = model
        self.r = np.zeros(model.neq)
        self.rabs = np.zeros(model.neq)
        self.data = np.zeros(model.nnz)
        tf = model.tf
        self.tfv = np.zeros((max(1, len(tf.fstart) - 1), 4))
        self.Tn = np.tile(np.eye(3), (model.nn + 1, 1, 1))
        self.kscale = model.meta["kscale"]
        bilateral = model.meta.get("bilateral")
        self.redundancy = Redundancy(
            model.indices, model.indptr, model.nd, self.kscale, model.eq_labels,
            np.ones(model.nm, bool) if bilateral is None else np.asarray(bilateral, bool))
        self.nevals = 0
        # per (mode, want): each group's compiled entry point and its fixed arguments, or
        # False where a group's overload could not be identified (see _bind)
        self._calls: dict[tuple[int, bool], list | bool] = {}
        self._state_types: tuple | None = None
        self._last_state: State | None = None
        self._precompiled = False
        # (dispatcher, signature) of other functions to compile with the kernels (the
        # stepper's compiled Newton step)
        self.precompile_also: list[tuple] = []

    def time_functions(self, t: float) -> None:
        tf = self.model.tf
        eval_time_functions(t, tf.kind, tf.par, tf.fstart, tf.tab, self.tfv)

    def evaluate(self, st: State, cM: float = 0.0, cC: float = 0.0, cK: float = 1.0,
                 mode: int = MODE_DYN, want: bool = False) -> None:
        """Residual (and matrix if ``want``) at state ``st`` and time ``st.t``."""
        self.r[:] = 0.0
        self.rabs[:] = 0.0
        if want:
            self.data[:] = 0.0
        self.ensure_compiled(st, cM, cC, cK, mode, want)
        self.time_functions(st.t)
        mode, want = int(mode), bool(want)
        rows, diag, rptr, rpos, dscale, viol, _watch = self.redundancy.arrays
        masked = rows.size > 0
        if masked:
            hold_multipliers(st.lam, rows, self.model.nd)
        calls = self._calls.get((mode, want))
        if calls and (st is self._last_state or self._same_types(st)):
            # one compiled call per group, straight into the overload chosen at binding:
            # the dispatcher's argument typing (about 0.5 us of 29 arguments per group) is
            # paid once, not at every Newton iteration
            mid = (st.x, st.R, st.v, st.vd, st.lam, st.es, self.tfv, st.t, self.Tn,
                   float(cM), float(cC), float(cK), mode, want)
            for entry, pre, post in calls:
                entry(*pre, *mid, *post)
        else:
            for g in self.model.groups:
                g.evaluate(st, self.tfv, st.t, self.Tn, cM, cC, cK, mode, want,
                           self.r, self.rabs, self.data)
            if calls is None:
                self._calls[(mode, want)] = self._bind(st, cM, cC, cK, mode, want)
        if masked:
            set_aside(self.r, self.rabs, self.data, want, rows, diag, rptr, rpos, dscale,
                      viol)
        self.nevals += 1

    def dependent_constraints(self, st: State) -> np.ndarray:
        """Equation indices of the constraint rows that are combinations of the others at
        the configuration of ``st`` (:mod:`~drivedyn.solver.redundancy`), every row
        considered: one evaluation of the velocity-level matrix, after which everything it
        wrote is put back (``r``, ``rabs``, ``data``, ``Tn``, the elements' outputs, the
        rows set aside and their violations): a run goes on as if it had not happened."""
        red = self.redundancy
        m = self.model
        if m.nm == 0:
            return red.rows[:0]
        live = [a for a in (self.r, self.rabs, self.data, self.Tn, m.aux_all, m.eout_all)
                if a is not None]
        kept = [a.copy() for a in live]
        keep = red.rows, red.arrays  # the compiled loop holds these arrays
        red.set_rows(keep[0][:0])
        try:
            self.Tn[:] = np.eye(3)
            self.evaluate(st, 1.0, 0.0, 0.0, MODE_VEL, True)
            G = jacobian(self.data, m.indices, m.indptr, m.nd)
            return red.found(G, st.x[: m.nn])
        finally:
            red.rows, red.arrays = keep
            for a, b in zip(live, kept, strict=True):
                a[...] = b

    def detect_redundancy(self, st: State) -> np.ndarray:
        """Set aside the dependent constraint rows at ``st`` (:meth:`dependent_constraints`)
        as the rows of a run or analysis starting there (logged, and reported by
        :meth:`~drivedyn.solver.redundancy.Redundancy.attrs`); returns them."""
        red = self.redundancy
        rows = self.dependent_constraints(st)
        red.set_rows(rows)
        red.at_start = rows.copy()
        red.events.clear()
        report_start(red)
        return rows

    def redundancy_on_singular(self, st: State, t: float) -> bool:
        """After a singular factorisation at the configuration of ``st`` (time ``t`` [s]):
        if more rows are dependent there than are set aside, set them aside (logged, and
        kept in the results' attributes) and return True: the step is tried again. False:
        the matrix is singular for another reason."""
        red = self.redundancy
        if self.model.nm == 0:
            return False
        rows = self.dependent_constraints(st)
        if rows.size <= red.rows.size:
            return False
        added = red.describe(np.setdiff1d(rows, red.rows))
        red.set_rows(rows)
        red.events.append((t, "set aside", added))
        log.warning("t = %.9g s: the constraint rows %s became dependent on the others and "
                    "are set aside while they stay so (their joints' reactions are not "
                    "unique)", t, ", ".join(added))
        return True

    def redundancy_restore(self, st: State, t: float) -> bool:
        """Give back the rows set aside that are independent again at ``st`` (time ``t``
        [s]); returns True if the rows set aside changed. Runs only when a row set aside is
        violated beyond its watch limit at the last evaluation
        (:func:`~drivedyn.solver.redundancy.watched`); when none is independent, the
        limit doubles above the violation (they stay aside, watched less closely).
        """
        red = self.redundancy
        if red.rows.size == 0 or not watched(red.arrays):
            return False
        rows = self.dependent_constraints(st)
        if rows.size >= red.rows.size:
            red.arrays[6][0] = 2.0 * red.violation
            return False
        back = red.describe(np.setdiff1d(red.rows, rows))
        red.set_rows(rows)
        red.events.append((t, "restored", back))
        log.info("t = %.9g s: constraint rows %s are independent again", t, ", ".join(back))
        return True

    def _state_signature(self, st: State) -> tuple:
        from numba import typeof

        return tuple(typeof(a) for a in (st.x, st.R, st.v, st.vd, st.lam, st.es))

    def _same_types(self, st: State) -> bool:
        """True if ``st``'s arrays have the types (dtype, dimensions, layout) the entry
        points were bound for; remembers ``st`` so that the check runs once per State."""
        if self._state_types is None or self._state_signature(st) != self._state_types:
            return False
        self._last_state = st
        return True

    def ensure_compiled(self, st: State, cM: float = 0.0, cC: float = 0.0, cK: float = 1.0,
                        mode: int = MODE_DYN, want: bool = False) -> None:
        """Compile, or load from the cache, the kernels of evaluations with these argument
        types and the functions of :attr:`precompile_also`, once (the first evaluation does
        it; in parallel processes on a first run)."""
        if not self._precompiled:
            self._precompile(st, cM, cC, cK, mode, want)

    def _kernel_args(self, st: State, cM: float, cC: float, cK: float, mode: int,
                     want: bool) -> list[tuple[object, tuple, tuple, tuple]]:
        """Per group: the kernel, its fixed leading arguments, the per-evaluation middle ones
        and its fixed trailing ones, as :meth:`evaluate` passes them."""
        mid = (st.x, st.R, st.v, st.vd, st.lam, st.es, self.tfv, st.t, self.Tn,
               float(cM), float(cC), float(cK), int(mode), bool(want))
        return [(g.kernel, (*g.params, g.lnodes, g.dofs, g.kmap, g.eoff), mid,
                 (self.r, self.rabs, self.data, g.eout, g.aux)) for g in self.model.groups]

    @staticmethod
    def _signature(kernel, pre: tuple, mid: tuple, post: tuple) -> tuple:
        """numba argument types of one kernel call (AttributeError: not a numba dispatcher;
        TypeError/ValueError: an argument numba cannot type)."""
        return tuple(kernel.typeof_pyval(a) for a in (*pre, *mid, *post))

    def _precompile(self, st: State, cM: float, cC: float, cK: float, mode: int,
                    want: bool) -> None:
        """Before the first evaluation: compile the kernels that are neither compiled nor
        cached in parallel processes (:mod:`drivedyn.solver.precompile`)."""
        from drivedyn.results.recorder import import_dataset_stack
        from drivedyn.solver.precompile import precompile_kernels

        self._precompiled = True
        calls = []
        for k, pre, mid, post in self._kernel_args(st, cM, cC, cK, mode, want):
            try:
                calls.append((k, self._signature(k, pre, mid, post)))
            except (AttributeError, TypeError, ValueError):
                continue
        tf = self.model.tf
        try:
            calls.append((eval_time_functions, tuple(
                eval_time_functions.typeof_pyval(a)
                for a in (float(st.t), tf.kind, tf.par, tf.fstart, tf.tab, self.tfv))))
        except (AttributeError, TypeError, ValueError):  # compiled on first use
            pass
        precompile_kernels(calls + self.precompile_also, while_waiting=import_dataset_stack)

    def _bind(self, st: State, cM: float, cC: float, cK: float, mode: int,
              want: bool) -> list | bool:
        """Each group's kernel overload for the argument types of this evaluation (the
        dispatcher has just compiled or loaded it) with its fixed leading and trailing
        arguments; False if an overload cannot be identified exactly (then the dispatcher
        keeps choosing)."""
        calls = []
        for k, pre, mid, post in self._kernel_args(st, cM, cC, cK, mode, want):
            try:
                entry = k.overloads[self._signature(k, pre, mid, post)].entry_point
            except (AttributeError, KeyError, TypeError, ValueError):
                return False
            calls.append((entry, pre, post))
        self._state_types = self._state_signature(st)
        self._last_state = st
        return calls

    def kernel_table(self, st: State) -> KernelTable | None:
        """Every group's kernel overload for the argument types of ``st``, with its fixed
        arguments (:class:`~drivedyn.solver.kernel_calls.KernelTable`); None if an overload
        is not compiled yet (evaluate once first) or a kernel is not a numba function."""
        from drivedyn.solver.kernel_calls import KernelTable, entry_address

        out = []
        for k, pre, mid, post in self._kernel_args(st, 1.0, 1.0, 1.0, MODE_DYN, True):
            try:
                addr = entry_address(k, self._signature(k, pre, mid, post))
            except (AttributeError, KeyError, TypeError, ValueError):
                return None
            out.append((addr, pre, post))
        try:
            return KernelTable(out)
        except TypeError:
            return None

    def matrix(self) -> sp.csc_matrix:
        import scipy.sparse as sp  # here: SciPy's sparse package off every run's start

        m = self.model
        return sp.csc_matrix((self.data.copy(), m.indices, m.indptr), shape=(m.neq, m.neq))

    def factor(self, lin) -> None:
        """Factorise the last assembled matrix with ``lin`` (a
        :class:`~drivedyn.solver.linear.LinearSolver`) straight from the CSC arrays."""
        m = self.model
        lin.factor_csc(self.data, m.indices, m.indptr, m.neq)

    def reset_tangent(self) -> None:
        self.Tn[:] = np.eye(3)

    def constraint_violation(self, r: np.ndarray | None = None) -> np.ndarray:
        """|Phi| of every constraint row [m or rad] from a MODE_DYN residual."""
        r = self.r if r is None else r
        nd = self.model.nd
        return np.abs(r[nd:]) / self.kscale[nd:]


def redundant_constraints(model: Model, state: State | None = None) -> list[str]:
    """Labels (element and row) of the constraint rows that are combinations of the others
    at the configuration of ``state`` (default: the model's initial state), found as a run
    finds them when it starts (:mod:`~drivedyn.solver.redundancy`): what a run of the model
    will set aside, asked for before any run. The reactions of the joints listed are not
    unique. Evaluates the model's kernels once (compiling them on a first run)."""
    sys = System(model)
    st = model.initial_state() if state is None else state
    return sys.redundancy.describe(sys.dependent_constraints(st))


def element_outputs(model: Model, state: State) -> dict[str, dict[str, float]]:
    """Every element's named outputs at ``state`` (e.g. after :func:`solve_static`):
    ``{element: {output: value}}`` in the units of ``Group.outputs()``."""
    sys = System(model)
    sys.evaluate(state)
    out: dict[str, dict[str, float]] = {}
    for g in model.groups:
        for ei, name in enumerate(g.names):
            row = g.aux[ei].copy()
            if g.derived is not None:  # outputs computed when read
                row[list(g.derived.cols)] = g.derived.at(ei, row)
            out[name] = {o: float(row[col]) for col, o, _u, _d in g.outputs()}
    return out
