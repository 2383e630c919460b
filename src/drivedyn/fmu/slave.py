"""The Python class an FMU built by ``drivedyn fmu`` runs (pythonfmu's ``Fmi2Slave``): it reads
the model file and the overrides the FMU carries in its resources, declares the interface of
the model (:mod:`drivedyn.fmu.differential`) with units and descriptions, builds the run at
``exitInitializationMode`` and advances it at each ``doStep``.

A step that cannot be taken (the solver failed, an input is NaN or infinite, the master's
time does not follow on) is logged with its reason at error level and ``doStep`` returns
``fmi2Discard`` with the FMU asking to terminate (pythonfmu's status for a step the slave did
not complete; an exception would make it ``fmi2Fatal``); the state stays at the last
communication point.
"""

from __future__ import annotations

import json
from functools import partial
from pathlib import Path
from typing import Any
from xml.etree.ElementTree import Element, SubElement

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.default_experiment import DefaultExperiment
from pythonfmu.enums import Fmi2Initial, Fmi2Status

from drivedyn.fmu.kinds import cosim
from drivedyn.fmu.resources import META_FILE, MODEL_FILE
from drivedyn.fmu.variables import UNITS, Variable

_CAUSALITY = {"input": Fmi2Causality.input, "output": Fmi2Causality.output,
              "parameter": Fmi2Causality.parameter}
_VARIABILITY = {"input": Fmi2Variability.continuous, "output": Fmi2Variability.continuous,
                "parameter": Fmi2Variability.fixed}


class UnitReal(Real):
    """pythonfmu's Real with a ``unit`` attribute."""

    def __init__(self, name: str, unit: str, **kwargs: Any) -> None:
        super().__init__(name, **kwargs)
        self.unit = unit

    def to_xml(self) -> Element:
        node = super().to_xml()
        node.find("Real").set("unit", self.unit)
        return node


class DrivedynSlave(Fmi2Slave):
    """An FMU running a drivedyn model (see the module doc); pythonfmu instantiates the
    subclass that the FMU's script declares, with ``instance_name`` and ``resources``."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        from drivedyn.solver.simulation import _version

        res = Path(self.resources)
        meta = json.loads((res / META_FILE).read_text(encoding="utf-8"))
        self.cosim = cosim(meta.get("kind", ""), res / MODEL_FILE, meta.get("overrides", {}))
        self.author = "drivedyn"
        self.version = _version()
        self.license = "MIT"
        self.description = (
            f"{self.cosim.title}. Runs drivedyn (Python), which must be installed in the "
            "Python that loads this FMU: pip install 'drivedyn[fmu]'.")
        self.default_experiment = DefaultExperiment(start_time=0.0, stop_time=1.0,
                                                    step_size=1e-3)
        self._variables: list[Variable] = self.cosim.variables()
        self._values = {v.name: float(v.start) for v in self._variables}
        self._inputs = tuple(v.name for v in self._variables if v.causality == "input")
        self._outputs = {v.name: 0.0 for v in self._variables if v.causality == "output"}
        self._start_time = 0.0
        for v in self._variables:
            self._register(v)

    def _register(self, v: Variable) -> None:
        name = v.name
        if v.causality == "output":
            getter, setter = partial(self._outputs.__getitem__, name), None
            initial = Fmi2Initial.calculated
        else:
            getter = partial(self._values.__getitem__, name)
            setter = partial(self._set_value, name)
            initial = None
        self.register_variable(UnitReal(
            name, v.unit, causality=_CAUSALITY[v.causality], description=v.description,
            variability=_VARIABILITY[v.causality], initial=initial, getter=getter,
            setter=setter), nested=False)

    def _set_value(self, name: str, value: float) -> None:
        self._values[name] = float(value)

    def to_xml(self, model_options: dict[str, str] | None = None) -> Element:
        """modelDescription.xml's tree, with the unit definitions of the variables' units."""
        root = super().to_xml(model_options or {})
        units = Element("UnitDefinitions")
        for name in sorted({v.unit for v in self._variables}):
            unit = SubElement(units, "Unit", name=name)
            if UNITS[name]:
                SubElement(unit, "BaseUnit", {k: str(e) for k, e in UNITS[name].items()})
        root.insert(list(root).index(root.find("CoSimulation")) + 1, units)
        # the outputs are computed at initialisation too (FMI 2.0: listed as initial unknowns)
        structure = root.find("ModelStructure")
        outputs = structure.find("Outputs")
        if outputs is not None:
            initial = SubElement(structure, "InitialUnknowns")
            for unknown in outputs:
                SubElement(initial, "Unknown", index=unknown.get("index"))
        return root

    def setup_experiment(self, start_time: float, stop_time: float | None,
                         tolerance: float | None) -> None:
        self._start_time = float(start_time)

    def exit_initialization_mode(self) -> None:
        self.cosim.initialize(self._values, self._start_time)
        self._outputs.update(self.cosim.outputs())

    def do_step(self, current_time: float, step_size: float) -> bool:
        values = self._values
        ok, message = self.cosim.step(current_time, step_size,
                                      {k: values[k] for k in self._inputs})
        if not ok:
            self.log(message, Fmi2Status.error)
            return False
        self._outputs.update(self.cosim.outputs())
        return True
