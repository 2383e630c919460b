"""The four-wheel-drive vehicle with three differentials on split-mu (seed 003, Figures
14-15): parametric model (:mod:`.model`), model-file schema (:mod:`.schema`, default file
``vehicle-4wd``) and the dashboard of its runs (:mod:`.dashboard`)."""

from drivedyn.library.vehicles.vehicle_4wd.configurations import CONFIGS, config_name
from drivedyn.library.vehicles.vehicle_4wd.dashboard import vehicle_dashboard
from drivedyn.library.vehicles.vehicle_4wd.model import (
    Layout,
    build_spec,
    check_parameters,
    load_tyre,
)
from drivedyn.library.vehicles.vehicle_4wd.schema import Vehicle4WDFile

SCHEMA = Vehicle4WDFile
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
    "Vehicle4WDFile",
    "build_spec",
    "check_parameters",
    "config_name",
    "load_tyre",
    "vehicle_dashboard",
]
