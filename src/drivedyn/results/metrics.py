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
    n = len(results.time)

    def last(name: str) -> float:
        return float(results.values(name)[-1]) if n and name in results else float("nan")

    peak, where = float("nan"), ""
    # the variables as stored (``dataset.data_vars.items()`` would build a DataArray for each
    # of them: 0.13 s for the Type C bench's 401, on every ``drivedyn tdr`` run), and only the
    # pressures: reading every variable computed the five flexible washers' stress fields
    # (0.38 s of the Type C flexible-washer command)
    for name, _attrs, values in results.variables(
            lambda name, attrs: name.endswith(".pressure") and attrs.get("units") == "Pa"):
        if values.size:
            value = float(np.nanmax(np.abs(values)))
            if not peak >= value:
                peak, where = value, name.rsplit(".", 1)[0]
    st = results.stats
    return {"t_final": float(results.time[-1]) if n else float("nan"),
            "dissipated_energy": last("energy.dissipated"),
            "energy_balance_error": last("energy.balance_error"),
            "peak_pressure": peak, "peak_pressure_at": where,
            "steps": int(st.steps), "rejected_steps": int(st.rejected),
            "newton_iterations": int(st.newton_iterations),
            "factorizations": int(st.factorizations), "wall_s": float(st.wall_s)}
