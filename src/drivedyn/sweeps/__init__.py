"""Parameter sweeps, Monte Carlo tolerance studies and sensitivities on Dask.

``sweep(model, vary=..., sample=..., sensitivity_keys=...)`` computes independent runs of a
model file (its scenario, or the TDR of a differential on the bench) on a Dask cluster (an
embedded local cluster by default, any scheduler by address, or the caller's client), caches
each finished point and returns one xarray Dataset. ``drivedyn sweep`` is its command line.
"""

from drivedyn.sweeps.assemble import BOOKKEEPING, physical_outputs
from drivedyn.sweeps.design import (
    Sample,
    SweepInputError,
    Vary,
    parse_sample,
    parse_sensitivity,
    parse_vary,
)
from drivedyn.sweeps.evaluate import Metric, Task, evaluate_point, parse_metric
from drivedyn.sweeps.sweep import SweepInterrupted, sweep

__all__ = [
    "BOOKKEEPING",
    "Metric",
    "Sample",
    "SweepInputError",
    "SweepInterrupted",
    "Task",
    "Vary",
    "evaluate_point",
    "parse_metric",
    "parse_sample",
    "parse_sensitivity",
    "parse_vary",
    "physical_outputs",
    "sweep",
]
