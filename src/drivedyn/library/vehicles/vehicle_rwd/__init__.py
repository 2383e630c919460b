"""The rear-wheel-drive vehicle: flexible ladder frame, double-wishbone corners on bushings,
rack steering, Magic Formula tyres and a rear differential of any type: parametric model
(:mod:`.model`), model-file schema (:mod:`.schema`, default file ``vehicle-rwd``), the checks
of its parameters (:mod:`.inputs`), the dashboard of its runs (:mod:`.dashboard`) and the
static start of a run (:mod:`.static_start`)."""

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
from drivedyn.library.vehicles.vehicle_rwd.static_start import static_start

SCHEMA = VehicleRWDFile
#: params -> the Dashboard of a run (drivedyn plot)
DASHBOARD = vehicle_dashboard
#: params -> the name of its configuration (recorded with a run's results)
CONFIGURATION = config_name
#: (params, torsen, base_dir, model, layout) -> the state a run starts from (drivedyn run)
INITIAL_STATE = static_start

__all__ = [
    "CONFIGS",
    "CONFIGURATION",
    "DASHBOARD",
    "INITIAL_STATE",
    "SCHEMA",
    "Layout",
    "VehicleRWDFile",
    "build_spec",
    "check_parameters",
    "config_name",
    "load_tyre",
    "measured_side",
    "static_start",
    "tyre_notes",
    "vehicle_dashboard",
]
