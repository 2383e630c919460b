"""The FMU interface of a differential model file (TORSEN Type B or C): its variables, and
its run as a resumable :class:`~drivedyn.solver.simulation.Simulation` of the co-simulation
configuration (:mod:`drivedyn.library.differentials.cosim`).

Inputs: ``input_torque`` [N m] on the housing; ``{output}_speed`` [rad/s] of each output
(``left``/``right`` for Type B, ``front``/``rear`` for Type C), imposed. Each is held over a
communication step (zero-order hold). Outputs: ``{output}_torque`` [N m] delivered to each
shaft (positive in drive), ``input_speed`` [rad/s] of the housing (integrated with its
inertia), ``tdr`` (larger over smaller output torque) and ``washer_{name}_force`` [N] of each
thrust washer. Parameters: the model file's friction coefficients, by their dotted keys. The
speed inputs' values at initialisation are the initial output speeds; the housing starts at
the speed the gear kinematics give them. The model runs with the file's ``[solver]``
settings (its own step control between communication points), with the integrator's
``rho_inf`` at most :data:`RHO_INF_MAX`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from drivedyn.fmu.variables import Variable
from drivedyn.library import differentials
from drivedyn.library.differentials.cosim import (
    INPUT_TORQUE,
    cosim_spec,
    delivered_torque_sign,
    speed_input,
)

#: largest ``rho_inf`` of the FMU's integrator (less: the file's). Each communication point
#: steps the imposed speeds (zero-order hold) and excites the gear train above what the
#: steps resolve; more numerical damping of that ringing saves steps. Measured on the bench
#: at 1 ms (benchmarks/fmu_bench.py), Newton iterations at rho_inf 0.8 / 0.5 / 0.4: Type C
#: front side 92 700 / 28 600 / 26 900, Type B right side 23 500 / 18 400 / 16 400; the
#: TDRs of the four modes move by less than 1e-5 relative
RHO_INF_MAX = 0.4

#: what the friction coefficient of a model-file section acts on (descriptions)
_FRICTION_OF = {
    "washers": "thrust washer",
    "pockets": "element gears (planets) on their pocket bores and floors",
    "gears": "tooth flanks of the gear meshes",
    "spline": "helical spline",
}


def friction_keys(params: Any) -> dict[str, float]:
    """Dotted key -> value of every friction coefficient of validated parameters ``params``
    (keys ending in ``mu`` or ``friction``), in file order."""
    out: dict[str, float] = {}

    def walk(node: Any, prefix: str) -> None:
        if isinstance(node, Mapping):
            for k, v in node.items():
                walk(v, f"{prefix}{k}.")
            return
        key = prefix[:-1]
        last = key.rsplit(".", 1)[-1]
        if (last == "mu" or last.endswith("friction")) and isinstance(node, int | float) \
                and not isinstance(node, bool):
            out[key] = float(node)

    data = params.model_dump(mode="json", warnings=False)
    for section in ("gears", "spline", "washers", "pockets"):
        if section in data:
            walk(data[section], f"{section}.")
    return out


def _friction_description(key: str) -> str:
    parts = key.split(".")
    what = _FRICTION_OF.get(parts[0], parts[0])
    if parts[0] == "washers" and len(parts) == 3:
        what = f"thrust washer {parts[1]}"
    elif parts[0] == "washers":
        what = "thrust washers (one coefficient for all)"
    return f"Coulomb friction coefficient of the {what} (model-file key {key})"


class DifferentialCosim:
    """The co-simulation of a differential: variables, initialisation, steps, outputs.

    Args:
        model_file: the model file (TOML) the FMU carries.
        overrides: ``--set`` overrides applied to it (dotted key -> value), the parameters'
            values at initialisation on top.
    """

    kind = "differential"

    def __init__(self, model_file: str | Path, overrides: Mapping[str, Any] | None = None
                 ) -> None:
        from drivedyn.config import read_library_file

        self.model_file = model_file
        self.overrides = dict(overrides or {})
        self.params, _, self.source = read_library_file(model_file, self.overrides)
        self.diff = differentials.of(self.params)
        self.diff.check(self.params)
        self.frictions = friction_keys(self.params)
        self.sim: Any = None
        self._start_time = 0.0
        self._reads: list[tuple[str, np.ndarray, int, int, float]] = []

    @property
    def title(self) -> str:
        """What the FMU simulates (its description's first words)."""
        return f"{self.diff.title} differential, drivedyn model {self.params.model.name!r}"

    @property
    def inputs(self) -> tuple[str, ...]:
        """Input names: the housing torque, then the output speeds."""
        return (INPUT_TORQUE, *(speed_input(o.name) for o in self.diff.outputs))

    def variables(self) -> list[Variable]:
        """Every variable of the FMU: inputs, outputs, parameters."""
        d = self.diff
        out = [Variable(INPUT_TORQUE, "input", "N.m",
                        "torque on the housing about its axis (+z: forward drive), held over "
                        "a communication step")]
        for o in d.outputs:
            out.append(Variable(speed_input(o.name), "input", "rad/s",
                                f"speed of the {o.label} about +z imposed by the vehicle, held "
                                "over a communication step; its value at initialisation is the "
                                "initial speed"))
        for o in d.outputs:
            out.append(Variable(f"{o.name}_torque", "output", "N.m",
                                f"torque the {o.label} delivers to its shaft (positive in "
                                "drive)"))
        out.append(Variable("input_speed", "output", "rad/s",
                            "speed of the housing about +z, integrated with its inertia"))
        out.append(Variable("tdr", "output", "1",
                            "torque distribution ratio: the larger over the smaller output "
                            "torque magnitude (0 while an output carries no torque)"))
        for w, label in d.washers.items():
            out.append(Variable(f"washer_{w}_force", "output", "N",
                                f"normal force of the thrust washer {w} ({label})"))
        for key, value in self.frictions.items():
            out.append(Variable(key, "parameter", "1", _friction_description(key), value))
        return out

    def initialize(self, values: Mapping[str, float], start_time: float = 0.0) -> None:
        """Build and set up the run from the parameters' and inputs' ``values`` at
        ``start_time`` [s] (consistent initial state, compiled model, step controller).

        Raises:
            ValueError: a parameter or input that is not finite.
            ModelFileError, ModelError: parameters the model refuses.
        """
        from drivedyn.config import read_library_file
        from drivedyn.model.compile import compile_model
        from drivedyn.solver.simulation import Simulation

        for name in (*self.frictions, *self.inputs):
            if name in values and not math.isfinite(float(values[name])):
                raise ValueError(f"{name} = {values[name]}: expected a finite value")
        changed = {k: float(values[k]) for k in self.frictions
                   if k in values and float(values[k]) != self.frictions[k]}
        p = self.params
        if changed:
            p = read_library_file(self.model_file, {**self.overrides, **changed})[0]
            self.diff.check(p)
        speeds = tuple(float(values.get(speed_input(o.name), 0.0)) for o in self.diff.outputs)
        sp, _ = cosim_spec(self.diff, p, speeds, float(values.get(INPUT_TORQUE, 0.0)))
        model = compile_model(sp)
        self.sim = Simulation(model, record=False, **p.solver.settings(
            rho_inf=min(p.solver.rho_inf, RHO_INF_MAX)))
        self._start_time = float(start_time)
        self._reads = self._output_reads(model)

    def _output_reads(self, model: Any) -> list[tuple[str, np.ndarray, int, int, float]]:
        """(output, array, row, column, factor) of each output read from the elements'
        outputs (the model's output table, updated in place by the steps)."""
        reads = []
        wanted = [(f"{o.name}_torque", speed_input(o.name), "torque", delivered_torque_sign())
                  for o in self.diff.outputs]
        wanted += [(f"washer_{w}_force", w, "normal_force", 1.0) for w in self.diff.washers]
        for out, element, quantity, factor in wanted:
            g, e = model.group(element)
            col = next(c for c, n, *_ in g.outputs() if n == quantity)
            reads.append((out, g.aux, e, col, factor))
        return reads

    def step(self, current_time: float, step_size: float, inputs: Mapping[str, float]
             ) -> tuple[bool, str]:
        """Hold ``inputs`` and integrate from ``current_time`` over ``step_size`` [s];
        returns (success, why not)."""
        sim = self.sim
        if sim is None:
            return False, "the FMU is not initialised (exitInitializationMode first)"
        if not all(map(math.isfinite, inputs.values())):
            bad = [f"{k} = {v}" for k, v in inputs.items() if not math.isfinite(v)]
            return False, (f"at t = {current_time:.9g} s: non-finite input(s) "
                           f"{', '.join(bad)}; the step is not taken (state kept at "
                           f"t = {current_time:.9g} s)")
        t = current_time - self._start_time
        if abs(t - sim.time) > 1e-9 * max(1.0, abs(t)):
            return False, (f"doStep from t = {current_time:.9g} s, but the FMU is at "
                           f"t = {sim.time + self._start_time:.9g} s (it cannot go back or "
                           "skip time)")
        if not step_size > 0:
            return False, f"communication step {step_size} s: expected > 0"
        for k, v in inputs.items():
            sim.set_input(k, v)
        if not sim.advance(t + step_size):
            return False, sim.message
        return True, ""

    def outputs(self) -> dict[str, float]:
        """Every output's current value (after initialisation or a step)."""
        out = {name: float(a[e, c]) * f for name, a, e, c, f in self._reads}
        t1, t2 = (abs(out[f"{o.name}_torque"]) for o in self.diff.outputs)
        lo, hi = min(t1, t2), max(t1, t2)
        out["tdr"] = hi / lo if lo > 0.0 else 0.0
        st, n = self.sim.state, self.sim.model.node_index["housing"]
        out["input_speed"] = float(st.R[n, 2] @ st.v[6 * n + 3:6 * n + 6])
        return out
