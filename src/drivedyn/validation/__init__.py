"""Validation cases run by ``drivedyn validate``: each compares a simulated quantity with an
exact or published reference. One module per subject registers its cases:
:mod:`~drivedyn.validation.engine` (rigid bodies, joints),
:mod:`~drivedyn.validation.integrator` (convergence order, energy account),
:mod:`~drivedyn.validation.contact`, :mod:`~drivedyn.validation.gears`,
:mod:`~drivedyn.validation.beams`, :mod:`~drivedyn.validation.fe`,
:mod:`~drivedyn.validation.torsen`, :mod:`~drivedyn.validation.torsen_b`,
:mod:`~drivedyn.validation.flexible_torsen`,
:mod:`~drivedyn.validation.vehicles`, :mod:`~drivedyn.validation.bushings`,
:mod:`~drivedyn.validation.chassis`, :mod:`~drivedyn.validation.suspensions`,
:mod:`~drivedyn.validation.vehicle_rwd` and :mod:`~drivedyn.validation.rwd_cornering`."""

from __future__ import annotations

import time

# import order = the order of the cases in reports (engine first)
# isort: off
from drivedyn.validation import engine  # noqa: F401  (registers the cases)
from drivedyn.validation import integrator  # noqa: F401
from drivedyn.validation import contact  # noqa: F401
from drivedyn.validation import gears  # noqa: F401
from drivedyn.validation import beams  # noqa: F401
from drivedyn.validation import fe  # noqa: F401
from drivedyn.validation import torsen  # noqa: F401
from drivedyn.validation import torsen_b  # noqa: F401
from drivedyn.validation import flexible_torsen  # noqa: F401
from drivedyn.validation import vehicles  # noqa: F401
from drivedyn.validation import bushings  # noqa: F401
from drivedyn.validation import chassis  # noqa: F401
from drivedyn.validation import suspensions  # noqa: F401
from drivedyn.validation import vehicle_rwd  # noqa: F401
from drivedyn.validation import rwd_cornering  # noqa: F401
# isort: on
from drivedyn.validation.base import CASES, CaseResult, compare, register_case


def run_cases(names: list[str] | None = None, quick: bool = False,
              figure_dir: str | None = None) -> list[CaseResult]:
    """Run the named cases (default all) and return their results with wall times."""
    out: list[CaseResult] = []
    for name in names or list(CASES):
        t0 = time.perf_counter()
        res = CASES[name](quick=quick, figure_dir=figure_dir)
        wall = time.perf_counter() - t0
        for r in res:
            r.wall_s = wall
        out += res
    return out


__all__ = ["CASES", "CaseResult", "compare", "register_case", "run_cases"]
