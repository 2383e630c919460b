"""Vehicles that take any differential by name (architecture: ``library/vehicles``): each
a subpackage with a model-file schema (``SCHEMA``), a builder (``build_spec``) and the
dashboard of its runs (``DASHBOARD``: params -> :class:`~drivedyn.library.dashboards.
Dashboard`, drawn by ``drivedyn plot``) and the name of a run's configuration
(``CONFIGURATION``: params -> str, recorded with the results); optionally the state a run
of the compiled model starts from (``INITIAL_STATE``: (params, torsen, base_dir, model,
layout) -> State, e.g. the static equilibrium; :func:`drivedyn.config.load_model` makes it
the model's initial state).

Adding a vehicle = one subpackage + one default model file + one line in :data:`TYPES`.
"""

from __future__ import annotations

import importlib
from types import ModuleType
from typing import Any

from drivedyn.library.dashboards import Dashboard

#: library key -> module of the vehicle (imported on first use)
TYPES = {
    "vehicle_4wd": "drivedyn.library.vehicles.vehicle_4wd",
    "vehicle_rwd": "drivedyn.library.vehicles.vehicle_rwd",
}


def get(name: str) -> ModuleType:
    """The vehicle module of a library key (``"vehicle_4wd"``) or model name."""
    key = name.replace("-", "_")
    if key not in TYPES:
        raise KeyError(f"no vehicle {name!r} (known: "
                       f"{', '.join(k.replace('_', '-') for k in TYPES)})")
    return importlib.import_module(TYPES[key])


def dashboard_of(params: Any) -> Dashboard:
    """The dashboard of a run of the vehicle of validated parameters ``params``."""
    return get(params.model.library).DASHBOARD(params)


def configuration(params: Any) -> str:
    """The name of the configuration of the vehicle of validated parameters ``params``
    (``"torsen"``, ``"open"``...; recorded with a run's results)."""
    return get(params.model.library).CONFIGURATION(params)


def schemas() -> dict[str, type]:
    """library key -> model-file schema of every vehicle."""
    return {k: get(k).SCHEMA for k in TYPES}


__all__ = ["TYPES", "configuration", "dashboard_of", "get", "schemas"]
