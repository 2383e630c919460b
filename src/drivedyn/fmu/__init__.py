"""FMI 2.0 co-simulation FMUs of drivedyn models (``drivedyn fmu``), built with pythonfmu.

:mod:`.build` builds the FMU (a generated script and the model file in its resources);
:mod:`.slave` is the Python class the FMU runs (pythonfmu's ``Fmi2Slave``);
:mod:`.differential` is the interface of a differential (variables, initialisation, steps,
outputs) on a resumable :class:`~drivedyn.solver.simulation.Simulation`; :mod:`.variables`
holds the variables' description and units. pythonfmu is needed to build an FMU and to run
one (the FMU carries its own copy); drivedyn must be installed where the FMU runs.
"""

from drivedyn.fmu.build import FmuError, build_fmu, model_identifier
from drivedyn.fmu.differential import DifferentialCosim
from drivedyn.fmu.kinds import FMU_KINDS

__all__ = ["FMU_KINDS", "DifferentialCosim", "FmuError", "build_fmu", "model_identifier"]
