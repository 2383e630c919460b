"""The rear-wheel-drive vehicle: flexible ladder frame, double-wishbone corners on bushings,
rack steering, Magic Formula tyres and a rear differential of any type: parametric model
(:mod:`.model`), model-file schema (:mod:`.schema`, default file ``vehicle-rwd``), the checks
of its parameters (:mod:`.inputs`) and the dashboard of its runs (:mod:`.dashboard`)."""

from drivedyn.library.vehicles.vehicle_rwd.configurations import CONFIGS, config_name
from drivedyn.library.vehicles.vehicle_rwd.dashboard import vehicle_dashboard
from drivedyn.library.vehicles.vehicle_rwd.inputs import (
    check_parameters,
    load_tyre,
    measured_side,
    tyre_notes,
)
from drivedyn.library.vehicles.vehicle_rwd.model import Layout, build_spec
from drivedyn.library.vehicles.vehicle_rwd.schema import VehicleRWDFile

SCHEMA = VehicleRWDFile
#: params -> the Dashboard of a run (drivedyn plot)
DASHBOARD = vehicle_dashboard
#: params -> the name of its configuration (recorded with a run's results)
CONFIGURATION = config_name

__all__ = [
    "CONFIGS",
    "CONFIGURATION",
    "DASHBOARD",
    "SCHEMA",
    "Layout",
    "VehicleRWDFile",
    "build_spec",
    "check_parameters",
    "config_name",
    "load_tyre",
    "measured_side",
    "tyre_notes",
    "vehicle_dashboard",
]
