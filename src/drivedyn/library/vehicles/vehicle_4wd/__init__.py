"""The four-wheel-drive vehicle with three differentials on split-mu (seed 003, Figures
14-15): parametric model (:mod:`.model`) and model-file schema (:mod:`.schema`, default file
``vehicle-4wd``)."""

from drivedyn.library.vehicles.vehicle_4wd.model import (
    Layout,
    build_spec,
    check_parameters,
    load_tyre,
)
from drivedyn.library.vehicles.vehicle_4wd.schema import Vehicle4WDFile

SCHEMA = Vehicle4WDFile

__all__ = ["SCHEMA", "Layout", "Vehicle4WDFile", "build_spec", "check_parameters", "load_tyre"]
