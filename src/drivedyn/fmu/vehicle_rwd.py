"""The FMU interface of the rear-wheel-drive vehicle (``vehicle-rwd``: flexible ladder frame,
HMMWV corners, a rear differential of any type) as a resumable
:class:`~drivedyn.solver.simulation.Simulation`.

Inputs: the engine's ``throttle`` [1] (0 to 1, on the engine's torque maps: zero-throttle
curve + throttle x (full load - zero throttle), in place of the file's ramp) and the road
friction factor under each wheel ``mu_fl``, ``mu_fr``, ``mu_rl``, ``mu_rr`` (on the tyre's
LMUX, LMUY: 1 = the tyre's test surface), each held over a communication step. The
throttle, not an engine torque, is the input: the engine is part of the model (its maps of
the engine speed, its inertia and first gear in the driveline, reacted on the frame), so a
throttle is what a driver model or a test bench gives it, and the torque follows the
engine's speed as in ``drivedyn vehicle``.

Outputs: each rear wheel's drive torque ``torque_rl``, ``torque_rr`` [N m] (the outboard
universal joint's reaction torque on the wheel about its spin axis, forward rolling
positive: :func:`drivedyn.analysis.vehicle_rwd.drive_torque`), each wheel's spin
``speed_{w}`` [rad/s], tyre longitudinal force ``fx_{w}`` [N] and load ``fz_{w}`` [N], the
car's ``vehicle_speed`` [m/s] and ``yaw_rate`` [rad/s] (of the rear axle's carrier, the rigid
body fixed to the frame's rear cross member). No parameters (as the 4WD vehicle's FMU):
the model file and its ``--set`` overrides are fixed when the FMU is built.

The run starts as ``drivedyn vehicle`` does: from the parked vehicle's static equilibrium
(:func:`~drivedyn.library.vehicles.vehicle_rwd.static_start.static_start`) at the file's
``body.speed``, with the throttle and friction factors the master gives at initialisation,
the file's ``[solver]`` settings and ``run.h_max``.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from drivedyn.fmu.variables import Variable
from drivedyn.fmu.vehicle import _WHEEL, WHEELS, VehicleCosim, _column

THROTTLE = "throttle"
#: the rear wheels (driven)
DRIVEN = ("rl", "rr")


class VehicleRWDCosim(VehicleCosim):
    """The co-simulation of the RWD vehicle: variables, initialisation, steps, outputs.

    Args:
        model_file: the vehicle's model file (TOML) the FMU carries; the differential,
            tyre and suspension files it names are read relative to its folder (or shipped
            by name).
        overrides: ``--set`` overrides applied to it.
    """

    kind = "vehicle_rwd"
    driver = THROTTLE

    @property
    def title(self) -> str:
        """What the FMU simulates."""
        return (f"RWD vehicle on a flexible ladder frame ({self.params.differentials.rear} "
                f"rear differential), drivedyn model {self.params.model.name!r}")

    @property
    def inputs(self) -> tuple[str, ...]:
        """Input names: the throttle, then the friction factor under each wheel."""
        return (THROTTLE, *(f"mu_{w}" for w in WHEELS))

    def variables(self) -> list[Variable]:
        """Every variable of the FMU: inputs and outputs."""
        p = self.params
        mu = p.road.mu
        out = [Variable(THROTTLE, "input", "1",
                        "engine throttle, 0 to 1 (torque = zero-throttle curve + throttle x "
                        "(full load - zero throttle) at the engine's speed, first gear), held "
                        "over a communication step", float(p.engine.throttle))]
        for w in WHEELS:
            out.append(Variable(f"mu_{w}", "input", "1",
                                f"road friction factor under the {_WHEEL[w]} wheel (on the "
                                "tyre's LMUX, LMUY: 1 = the tyre's test surface), held over a "
                                "communication step", float(getattr(mu, w))))
        for w in DRIVEN:
            out.append(Variable(f"torque_{w}", "output", "N.m",
                                f"drive torque of the {_WHEEL[w]} wheel: the reaction torque "
                                "of its half-shaft's outboard universal joint on it about its "
                                "spin axis, forward rolling positive"))
        for w in WHEELS:
            out.append(Variable(f"speed_{w}", "output", "rad/s",
                                f"spin rate of the {_WHEEL[w]} wheel about its axis"))
        for w in WHEELS:
            out.append(Variable(f"fx_{w}", "output", "N",
                                f"longitudinal tyre force of the {_WHEEL[w]} wheel (forward "
                                "positive)"))
        for w in WHEELS:
            out.append(Variable(f"fz_{w}", "output", "N",
                                f"vertical tyre load of the {_WHEEL[w]} wheel"))
        out.append(Variable("vehicle_speed", "output", "m/s",
                            "forward speed of the car (the rear axle's carrier, fixed to the "
                            "frame, along its own x axis)"))
        out.append(Variable("yaw_rate", "output", "rad/s",
                            "yaw rate of the car (the rear axle's carrier about the global "
                            "vertical, to the left positive)"))
        return out

    def initialize(self, values: Mapping[str, float], start_time: float = 0.0) -> None:
        """Build the run from the parked vehicle's static equilibrium with the inputs'
        ``values`` at ``start_time`` [s].

        Raises:
            ValueError: an input that is not finite, a throttle outside 0-1 or a negative
                friction factor.
        """
        from drivedyn.library.vehicles.vehicle_rwd import build_spec, static_start
        from drivedyn.model.compile import compile_model
        from drivedyn.solver.simulation import Simulation
        from drivedyn.timefunctions import Held

        why = self._check(values)
        if why:
            raise ValueError(why)
        p = self.params
        throttle = float(values.get(THROTTLE, p.engine.throttle))
        sp, lay = build_spec(p, self.torsen, self.base, throttle=Held(THROTTLE, throttle))
        model = compile_model(sp)
        state = static_start(p, self.torsen, self.base, model, lay)
        self.sim = Simulation(model, state=state, record=False,
                              **p.solver.settings(h_max=p.run.h_max))
        self._start_time = float(start_time)
        self._body = model.node_index["carrier"]
        self._mu = {}
        self._reads = []
        self._drives: list[tuple[str, np.ndarray, int, list[int], int]] = []
        for w in WHEELS:
            g, e = model.group(lay.tyres[w])
            self._mu[w] = (g.params[1], e)  # the tyre's options: road mu first
            self._reads.append((f"speed_{w}", g.aux, e, _column(g, "spin"), 1.0))
            self._reads.append((f"fx_{w}", g.aux, e, _column(g, "fx"), 1.0))
            self._reads.append((f"fz_{w}", g.aux, e, _column(g, "fz"), 1.0))
        for w in DRIVEN:
            g, e = model.group(lay.drives[w])
            self._drives.append((f"torque_{w}", g.aux, e,
                                 [_column(g, f"torque_{c}") for c in "xyz"],
                                 model.node_index[lay.wheels[w]]))
        self._write_mu(values)

    def _check(self, values: Mapping[str, float]) -> str:
        """Why the inputs' values cannot be taken ("" if they can)."""
        why = super()._check(values)
        u = values.get(THROTTLE, 0.0)
        if not why and not 0.0 <= u <= 1.0:
            why = f"throttle = {u}: expected 0 to 1"
        return why

    def outputs(self) -> dict[str, float]:
        """Every output's current value (after initialisation or a step)."""
        st = self.sim.state
        out = {name: float(a[e, c]) * f for name, a, e, c, f in self._reads}
        for name, a, e, cols, n in self._drives:
            out[name] = float(a[e, cols] @ st.R[n][:, 2])
        n = self._body
        R = st.R[n]
        out["vehicle_speed"] = float(R[:, 0] @ st.v[6 * n:6 * n + 3])
        out["yaw_rate"] = float(R[2] @ st.v[6 * n + 3:6 * n + 6])
        return out
