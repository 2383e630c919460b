"""Scalar figures of a run (drivedyn.results.metrics): the peak contact pressure over the
element outputs in Pa, the final energy terms and the counters."""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from drivedyn.results.metrics import run_metrics
from drivedyn.results.results import Results, RunStats


def _results(n: int = 4) -> Results:
    t = np.linspace(0.0, 0.3, n)
    pa = {"units": "Pa"}
    ds = xr.Dataset(
        {
            "washer_a.pressure": ("time", np.array([0.0, 2.0e6, -3.5e6, 1.0e6])[:n], pa),
            "washer_b.pressure": ("time", np.array([1.0e6, np.nan, 3.0e6, 0.5e6])[:n], pa),
            # not a pressure in Pa: ignored however large
            "pump.pressure": ("time", np.full(n, 9.0e9), {"units": "bar"}),
            "washer_a.force": ("time", np.full(n, 8.0e9), {"units": "N"}),
            "energy.dissipated": ("time", np.array([0.0, 1.0, 2.5, 4.0])[:n], {"units": "J"}),
            "energy.balance_error": ("time", np.array([0.0, 1e-9, 2e-9, -3e-9])[:n],
                                     {"units": "J"}),
        },
        coords={"time": ("time", t, {"units": "s"}),
                # a coordinate named like a pressure is not an element output
                "probe.pressure": ("time", np.full(n, 7.0e9), {"units": "Pa"})},
    )
    return Results(ds, True, "", RunStats(steps=12, rejected=2, newton_iterations=40,
                                          factorizations=7, wall_s=0.5))


def test_metrics_of_a_run() -> None:
    m = run_metrics(_results())
    assert m["peak_pressure"] == 3.5e6 and m["peak_pressure_at"] == "washer_a"
    assert m["dissipated_energy"] == 4.0 and m["energy_balance_error"] == -3e-9
    assert m["t_final"] == 0.3
    assert (m["steps"], m["rejected_steps"], m["newton_iterations"], m["factorizations"]) == \
        (12, 2, 40, 7)


def test_metrics_of_a_run_without_samples() -> None:
    m = run_metrics(_results(0))
    assert math.isnan(m["peak_pressure"]) and m["peak_pressure_at"] == ""
    assert math.isnan(m["dissipated_energy"]) and math.isnan(m["t_final"])
