"""Which models have an FMU interface, and the class of each kind's interface."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from drivedyn.fmu.differential import DifferentialCosim
from drivedyn.fmu.vehicle import VehicleCosim
from drivedyn.fmu.vehicle_rwd import VehicleRWDCosim

#: library keys of the models with an FMU interface -> their kind
FMU_KINDS = {"torsen_b": "differential", "torsen_c": "differential",
             "vehicle_4wd": "vehicle", "vehicle_rwd": "vehicle_rwd"}
#: kind -> class of its co-simulation interface (``cls(model_file, overrides)``)
COSIM: dict[str, type] = {"differential": DifferentialCosim, "vehicle": VehicleCosim,
                          "vehicle_rwd": VehicleRWDCosim}
#: kind -> dotted keys of the model file that name other files (read relative to the file's
#: folder unless shipped by name): the FMU carries the files they name
REFERENCES: dict[str, tuple[str, ...]] = {
    "vehicle": ("differentials.torsen_c", "differentials.torsen_b", "wheels.tyre"),
    "vehicle_rwd": ("differentials.torsen_b", "wheels.tyre", "suspensions")}


def cosim(kind: str, model_file: str | Path, overrides: Mapping[str, Any]) -> Any:
    """The co-simulation interface of a model file of ``kind``.

    Raises:
        ValueError: an unknown kind (an FMU built by another drivedyn version).
    """
    if kind not in COSIM:
        raise ValueError(f"unknown FMU model kind {kind!r} (this drivedyn knows "
                         f"{', '.join(COSIM)}): built by another drivedyn version?")
    return COSIM[kind](model_file, overrides)
