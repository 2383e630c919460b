"""Scalar figures of a finished run, shared by ``drivedyn run --json``, ``drivedyn tdr`` and
sweeps."""

from __future__ import annotations

import numpy as np


def run_metrics(results) -> dict:
    """Scalar outputs of a simulation (a :class:`~drivedyn.results.results.Results`).

    Returns a dict: ``t_final`` [s], ``dissipated_energy`` [J] (``energy.dissipated`` at the
    end), ``energy_balance_error`` [J], ``peak_pressure`` [Pa] (the largest contact pressure
    of any element output named ``*.pressure`` over the run, NaN if none) and
    ``peak_pressure_at`` (that output's element name), ``steps``, ``rejected_steps``,
    ``newton_iterations``, ``factorizations``, ``wall_s``.
    """
    ds = results.dataset
    n = len(results.time)

    def last(name: str) -> float:
        return float(ds[name].values[-1]) if n and name in ds else float("nan")

    peak, where = float("nan"), ""
    # the dataset's variables as stored: ``data_vars.items()`` builds a DataArray for each of
    # them (0.13 s for the Type C bench's 401, on every ``drivedyn tdr`` run)
    for name, var in ds.variables.items():
        if (str(name).endswith(".pressure") and name not in ds.coords
                and var.attrs.get("units") == "Pa" and var.size):
            value = float(np.nanmax(np.abs(var.values)))
            if not peak >= value:
                peak, where = value, str(name).rsplit(".", 1)[0]
    st = results.stats
    return {"t_final": float(results.time[-1]) if n else float("nan"),
            "dissipated_energy": last("energy.dissipated"),
            "energy_balance_error": last("energy.balance_error"),
            "peak_pressure": peak, "peak_pressure_at": where,
            "steps": int(st.steps), "rejected_steps": int(st.rejected),
            "newton_iterations": int(st.newton_iterations),
            "factorizations": int(st.factorizations), "wall_s": float(st.wall_s)}
