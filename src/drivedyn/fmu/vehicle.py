"""The FMU interface of the 4WD vehicle (``vehicle-4wd``, TORSEN or bevel differentials on
split-mu) as a resumable :class:`~drivedyn.solver.simulation.Simulation`.

Inputs: ``engine_torque`` [N m] on the central differential's housing (reacted on the car
body) and the road friction factor under each wheel ``mu_fl``, ``mu_fr``, ``mu_rl``,
``mu_rr`` (on the tyre's LMUX, LMUY: 1 = the tyre's test surface), each held over a
communication step. Outputs: each wheel's drive torque ``torque_{w}`` [N m] (what its
half-shaft applies to it, forward rolling positive), spin ``speed_{w}`` [rad/s] and the car's
speed ``vehicle_speed`` [m/s]. The car starts as the file says (``body.speed``, the static
tyre deflection) with the engine torque and the friction factors the master gives at
initialisation; the model runs with the file's ``[solver]`` settings and ``run.h_max``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from drivedyn.fmu.variables import Variable

WHEELS = ("fl", "fr", "rl", "rr")
_WHEEL = {"fl": "front left", "fr": "front right", "rl": "rear left", "rr": "rear right"}
ENGINE = "engine_torque"


class VehicleCosim:
    """The co-simulation of the 4WD vehicle: variables, initialisation, steps, outputs.

    Args:
        model_file: the vehicle's model file (TOML) the FMU carries; the differential and
            tyre files it names are read relative to its folder (or shipped by name).
        overrides: ``--set`` overrides applied to it.
    """

    kind = "vehicle"
    #: the input that drives the vehicle (held, a Held term of the model)
    driver = ENGINE

    def __init__(self, model_file: str | Path, overrides: Mapping[str, Any] | None = None
                 ) -> None:
        from drivedyn.config import read_library_file
        from drivedyn.config.loader import read_vehicle_differentials, resolve_path

        self.model_file = model_file
        self.overrides = dict(overrides or {})
        self.params, _, self.source = read_library_file(model_file, self.overrides)
        self.base = resolve_path(model_file).parent
        self.torsen = read_vehicle_differentials(self.params, self.source, self.base)
        self.sim: Any = None
        self._start_time = 0.0
        self._mu: dict[str, tuple[np.ndarray, int]] = {}
        self._reads: list[tuple[str, np.ndarray, int, int, float]] = []
        self._body = -1

    @property
    def title(self) -> str:
        """What the FMU simulates."""
        d = self.params.differentials
        return (f"4WD vehicle on split-mu ({d.central} central, {d.front} front, {d.rear} "
                f"rear differentials), drivedyn model {self.params.model.name!r}")

    @property
    def inputs(self) -> tuple[str, ...]:
        """Input names: the engine torque, then the friction factor under each wheel."""
        return (ENGINE, *(f"mu_{w}" for w in WHEELS))

    def variables(self) -> list[Variable]:
        """Every variable of the FMU: inputs and outputs."""
        mu = self.params.road.mu
        out = [Variable(ENGINE, "input", "N.m",
                        "engine torque on the central differential's housing, reacted on the "
                        "car body, held over a communication step")]
        for w in WHEELS:
            out.append(Variable(f"mu_{w}", "input", "1",
                                f"road friction factor under the {_WHEEL[w]} wheel (on the "
                                "tyre's LMUX, LMUY: 1 = the tyre's test surface), held over a "
                                "communication step", float(getattr(mu, w))))
        for w in WHEELS:
            out.append(Variable(f"torque_{w}", "output", "N.m",
                                f"drive torque of the {_WHEEL[w]} wheel: what its half-shaft "
                                "applies to it, forward rolling positive"))
        for w in WHEELS:
            out.append(Variable(f"speed_{w}", "output", "rad/s",
                                f"spin rate of the {_WHEEL[w]} wheel about its axis"))
        out.append(Variable("vehicle_speed", "output", "m/s", "forward speed of the car body"))
        return out

    def initialize(self, values: Mapping[str, float], start_time: float = 0.0) -> None:
        """Build and set up the run with the inputs' ``values`` at ``start_time`` [s].

        Raises:
            ValueError: an input that is not finite, or a negative friction factor.
        """
        from drivedyn.library.vehicles.vehicle_4wd import build_spec
        from drivedyn.model.compile import compile_model
        from drivedyn.solver.simulation import Simulation
        from drivedyn.timefunctions import Held

        why = self._check(values)
        if why:
            raise ValueError(why)
        sp, lay = build_spec(self.params, self.torsen, self.base,
                             engine=Held(ENGINE, float(values.get(ENGINE, 0.0))))
        model = compile_model(sp)
        p = self.params
        self.sim = Simulation(model, record=False, **p.solver.settings(h_max=p.run.h_max))
        self._start_time = float(start_time)
        self._body = model.node_index["body"]
        self._mu = {}
        self._reads = []
        for w in WHEELS:
            g, e = model.group(lay.tyres[w])
            self._mu[w] = (g.params[1], e)  # the tyre's options: road mu first
            self._reads.append((f"speed_{w}", g.aux, e, _column(g, "spin"), 1.0))
            g, e = model.group(lay.halfshafts[w])
            self._reads.append((f"torque_{w}", g.aux, e, _column(g, "torque"), -1.0))
        self._write_mu(values)

    def _check(self, values: Mapping[str, float]) -> str:
        """Why the inputs' values cannot be taken ("" if they can)."""
        bad = [f"{k} = {v}" for k, v in values.items() if not math.isfinite(v)]
        if bad:
            return f"non-finite input(s) {', '.join(bad)}"
        neg = [f"{k} = {v}" for k, v in values.items() if k.startswith("mu_") and v < 0]
        return f"negative road friction {', '.join(neg)}" if neg else ""

    def _write_mu(self, values: Mapping[str, float]) -> bool:
        """Write the friction factors into the tyres; whether one changed."""
        changed = False
        for w, (opts, e) in self._mu.items():
            v = float(values.get(f"mu_{w}", opts[e, 0]))
            if opts[e, 0] != v:
                opts[e, 0] = v
                changed = True
        return changed

    def step(self, current_time: float, step_size: float, inputs: Mapping[str, float]
             ) -> tuple[bool, str]:
        """Hold ``inputs`` and integrate from ``current_time`` over ``step_size`` [s];
        returns (success, why not)."""
        sim = self.sim
        if sim is None:
            return False, "the FMU is not initialised (exitInitializationMode first)"
        why = self._check(inputs)
        if why:
            return False, (f"at t = {current_time:.9g} s: {why}; the step is not taken "
                           f"(state kept at t = {current_time:.9g} s)")
        t = current_time - self._start_time
        if abs(t - sim.time) > 1e-9 * max(1.0, abs(t)):
            return False, (f"doStep from t = {current_time:.9g} s, but the FMU is at "
                           f"t = {sim.time + self._start_time:.9g} s (it cannot go back or "
                           "skip time)")
        if not step_size > 0:
            return False, f"communication step {step_size} s: expected > 0"
        sim.set_input(self.driver, inputs.get(self.driver, 0.0))
        if self._write_mu(inputs):
            sim.discontinuity()
        if not sim.advance(t + step_size):
            return False, sim.message
        return True, ""

    def outputs(self) -> dict[str, float]:
        """Every output's current value (after initialisation or a step)."""
        out = {name: float(a[e, c]) * f for name, a, e, c, f in self._reads}
        out["vehicle_speed"] = float(self.sim.state.v[6 * self._body])
        return out


def _column(group: Any, quantity: str) -> int:
    """The aux column of a group's output ``quantity``."""
    return next(c for c, n, *_ in group.outputs() if n == quantity)
