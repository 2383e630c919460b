"""Vehicles that take any differential by name (architecture: ``library/vehicles``): each
a subpackage with a model-file schema (``SCHEMA``) and a builder (``build_spec``).

Adding a vehicle = one subpackage + one default model file + one line in :data:`TYPES`.
"""

from __future__ import annotations

import importlib
from types import ModuleType

#: library key -> module of the vehicle (imported on first use)
TYPES = {
    "vehicle_4wd": "drivedyn.library.vehicles.vehicle_4wd",
}


def get(name: str) -> ModuleType:
    """The vehicle module of a library key (``"vehicle_4wd"``) or model name."""
    key = name.replace("-", "_")
    if key not in TYPES:
        raise KeyError(f"no vehicle {name!r} (known: "
                       f"{', '.join(k.replace('_', '-') for k in TYPES)})")
    return importlib.import_module(TYPES[key])


def schemas() -> dict[str, type]:
    """library key -> model-file schema of every vehicle."""
    return {k: get(k).SCHEMA for k in TYPES}


__all__ = ["TYPES", "get", "schemas"]
