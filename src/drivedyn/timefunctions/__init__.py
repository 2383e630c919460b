"""Time functions ``f(t)`` of simulated time ``t`` [s] for loads and drivers.

A time function returns a value in the unit of whatever it drives (N, N m, rad, rad/s, ...).
Available kinds:

* :class:`Constant` -- ``f(t) = value``.
* :class:`Ramp` -- ``v0`` up to ``t0``, linear to ``v1`` at ``t1``, ``v1`` afterwards.
* :class:`SmoothStep` -- ``v0`` up to ``t0``, cubic blend ``3 s^2 - 2 s^3`` with
  ``s = (t - t0)/(t1 - t0)`` to ``v1`` at ``t1``, ``v1`` afterwards (C1 continuous).
* :class:`Table` -- piecewise linear through ``(times[i], values[i])``, constant
  extrapolation outside the table.
* :class:`Held` -- an input held constant between the calls of a resumable run, its value
  written in place in the packed arrays (:func:`hold_value`).
* :class:`Sum` -- sum of any of the above; built with ``+`` (``f + g``, ``sum([f, g])``)
  and scaled with ``*`` (``2.0 * f``).

Every function provides the value, first and second time derivative and the exact integral
``int_0^t f(tau) dtau``. At breakpoints (``t0``, ``t1``, table times), where a derivative
jumps, the *right-hand* limit is returned (the derivative that applies just after the
breakpoint), both in Python and in the compiled kernels. Kinks of ramps and tables are
ignored by the second derivative (it is 0 there).

For use inside numba kernels, functions are registered in a :class:`TimeFunctionPool` and
packed into flat arrays (:class:`PackedTimeFunctions`), evaluated by
:func:`eval_time_functions` (all functions) or :func:`eval_function` / :func:`eval_term`
(one function / one term). The Python methods run the very same per-kind routines
interpreted (``.py_func``), so both paths agree to round-off.

The package: :mod:`~drivedyn.timefunctions.kernels` (the compiled per-kind routines and
evaluation kernels), :mod:`~drivedyn.timefunctions.functions` (the Python classes and
:func:`as_time_function`) and :mod:`~drivedyn.timefunctions.packing` (the pool and its flat
arrays).
"""

from drivedyn.timefunctions.functions import (
    Constant,
    Held,
    Ramp,
    SmoothStep,
    Sum,
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
    eval_function,
    eval_term,
    eval_time_functions,
    hold_value,
)
from drivedyn.timefunctions.packing import PackedTimeFunctions, TimeFunctionPool

__all__ = [
    "KIND_CONSTANT",
    "KIND_HELD",
    "KIND_RAMP",
    "KIND_SMOOTH_STEP",
    "KIND_TABLE",
    "Constant",
    "Held",
    "PackedTimeFunctions",
    "Ramp",
    "SmoothStep",
    "Sum",
    "Table",
    "TimeFunction",
    "TimeFunctionPool",
    "as_time_function",
    "eval_function",
    "eval_term",
    "eval_time_functions",
    "hold_value",
]
