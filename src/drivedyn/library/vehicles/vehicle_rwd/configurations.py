"""The named configurations of the RWD vehicle: the rear differential's type.
``drivedyn vehicle vehicle-rwd --compare`` runs them side by side; a run's results record
the name of its configuration."""

from __future__ import annotations

from drivedyn.library.vehicles.vehicle_rwd.schema import VehicleRWDFile

#: configuration name -> rear differential type
CONFIGS = {"open": "open", "locked": "locked", "clutch": "clutch", "torsen-b": "torsen-b"}


def config_name(p: VehicleRWDFile | dict[str, str]) -> str:
    """The :data:`CONFIGS` key of the parameters (or of ``{"rear": type}``)."""
    rear = p["rear"] if isinstance(p, dict) else p.differentials.rear
    for k, v in CONFIGS.items():
        if v == rear:
            return k
    return rear
