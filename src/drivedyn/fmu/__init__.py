"""FMI 2.0 co-simulation FMUs of drivedyn models (``drivedyn fmu``), built with pythonfmu:
the TORSEN differentials, the 4WD and the RWD vehicle.

:mod:`.build` builds the FMU (a generated script and the model file in its resources);
:mod:`.slave` is the Python class the FMU runs (pythonfmu's ``Fmi2Slave``);
:mod:`.differential`, :mod:`.vehicle` and :mod:`.vehicle_rwd` are the interfaces of a
differential, of the 4WD and of the RWD vehicle (variables, initialisation, steps,
outputs) on a resumable :class:`~drivedyn.solver.simulation.Simulation`, :mod:`.kinds`
says which models have one;
:mod:`.variables` holds the variables' description and units. pythonfmu is needed to build
an FMU and to run one (the FMU carries its own copy); drivedyn must be installed where the
FMU runs.
"""

from drivedyn.fmu.build import FmuError, build_fmu, model_identifier
from drivedyn.fmu.differential import DifferentialCosim
from drivedyn.fmu.kinds import FMU_KINDS
from drivedyn.fmu.vehicle import VehicleCosim
from drivedyn.fmu.vehicle_rwd import VehicleRWDCosim

__all__ = ["FMU_KINDS", "DifferentialCosim", "FmuError", "VehicleCosim", "VehicleRWDCosim",
           "build_fmu", "model_identifier"]
