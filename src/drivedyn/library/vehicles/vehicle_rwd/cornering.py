"""The RWD vehicle set up for cornering: a steering time function, the engine in the
scenario's gear, and a PI speed controller (:class:`~drivedyn.elements.SpeedController`)
driving the engine shaft against the frame from the vehicle's forward speed.

The speed is measured at a marker on the frame's centre line at the node nearest the
vehicle's centre of gravity (x forward); the controller's torque acts on the gearbox output
(``engine_out``) and is reacted on the frame at the engine's bearing, like the engine torque
(:mod:`.model`). Its gains and limits are the scenario's throttle figures times the
full-load torque at the gearbox output at the speed held (:func:`full_load_torque`); its
torque lies in
``[0, (1 - throttle) * full load]`` so that the throttle ramp on top never asks more than
full load. The controller holds its output from ``throttle_start`` on: its gate closes
smoothly over the :data:`GATE_CLOSE` before it (the speed is steady there, so the output
does not jump), and the throttle ramp adds to the held output.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from drivedyn.elements import SpeedController
from drivedyn.library.vehicles.vehicle_rwd.model import Layout, build_spec
from drivedyn.library.vehicles.vehicle_rwd.scenario_schema import PowerOnCornering
from drivedyn.library.vehicles.vehicle_rwd.schema import VehicleRWDFile
from drivedyn.model.spec import Spec
from drivedyn.timefunctions import Constant, SmoothStep

#: names of the controller element and its speed sensor marker
CONTROLLER = "speed_control"
SENSOR = "speed_sensor"
#: time [s] over which the controller's gate closes, ending when the throttle ramp starts
GATE_CLOSE = 0.1


@dataclass
class Cornering:
    """What a cornering run adds to the :class:`~.model.Layout`: the controller's and the
    sensor's names, the sensor's node, the full-load torque at the gearbox output [N m] and
    the steering's pinion angle as a time function."""

    controller: str
    sensor: str
    node: str
    full_torque: float
    steer: Any


def cornering_parameters(p: VehicleRWDFile, c: PowerOnCornering) -> VehicleRWDFile:
    """``p`` moving at the scenario's speed on a road of friction ``road_mu`` everywhere, the
    engine in its gear, the throttle ramp from ``throttle_start`` over ``throttle_ramp`` to
    ``throttle``; the run starts from the static equilibrium without the driveline's wind-up
    (``run.wind_up``): the speed controller drives the driveline from the start, which the
    wind-up's held engine torque does not stand for (measured with it, TORSEN B: 4687 steps
    against 4364, the steady circle's figures within 2e-5)."""
    eng = p.engine.model_copy(update={"gear_ratio": c.gear_ratio, "throttle": c.throttle,
                                      "start": c.throttle_start, "ramp": c.throttle_ramp})
    body = p.body.model_copy(update={"speed": c.speed})
    mu = p.road.mu.model_copy(update=dict.fromkeys(("fl", "fr", "rl", "rr"), c.road_mu))
    road = p.road.model_copy(update={"mu": mu, "patches": []})
    run = p.run.model_copy(update={"wind_up": False})
    return p.model_copy(update={"engine": eng, "body": body, "road": road, "run": run})


def steering_function(c: PowerOnCornering) -> Any:
    """The pinion angle [rad]: 0 until ``steer_start``, then a smooth step to
    ``pinion_angle`` over ``steer_ramp``."""
    if c.pinion_angle == 0.0:
        return Constant(0.0)
    return SmoothStep(c.steer_start, c.steer_start + c.steer_ramp, 0.0, c.pinion_angle)


def sensor_node(sp: Spec, cg: np.ndarray) -> str:
    """The frame node on the centre line (y = 0) nearest the centre of gravity ``cg``."""
    names = [n for n, nd in sp.nodes.items() if n.startswith("frame.")
             and abs(nd.position[1]) < 1e-9]
    d = [abs(sp.nodes[n].position[0] - cg[0]) for n in names]
    return names[int(np.argmin(d))]


def full_load_torque(p: VehicleRWDFile, lay: Layout, speed: float) -> float:
    """The engine's full-load torque at the gearbox output [N m] when the vehicle rolls at
    ``speed`` [m/s]: ``gear_ratio * T_F(omega_e)``, ``omega_e = gear_ratio * final drive
    ratio * speed / rolling radius`` (the map read linearly between its points)."""
    table = np.asarray(p.engine.full_load, float)
    w_e = p.engine.gear_ratio * lay.ratio * speed / lay.rolling_radius
    return float(p.engine.gear_ratio * np.interp(w_e, table[:, 0], table[:, 1]))


def add_speed_controller(sp: Spec, lay: Layout, p: VehicleRWDFile, c: PowerOnCornering,
                         reference: Any = None) -> Cornering:
    """The speed sensor and the controller of ``c`` in ``sp`` (``p``: the parameters the
    vehicle was built with, :func:`cornering_parameters`). ``reference``: the reference
    speed's time function (default ``c.speed``)."""
    node = sensor_node(sp, lay.cg)
    nd = sp.nodes[node]
    sp.add_marker(SENSOR, node, rotation=nd.rotation.T)  # x forward, as the vehicle
    full = full_load_torque(p, lay, c.speed)
    t1 = c.throttle_start
    sp.add(SpeedController(CONTROLLER, SENSOR, "engine_bearing_frame", "engine_out",
                           function=c.speed if reference is None else reference,
                           gain=c.kp * full, integral_gain=c.ki * full, torque_min=0.0,
                           torque_max=(1.0 - c.throttle) * full,
                           initial_torque=min(c.initial_throttle, 1.0 - c.throttle) * full,
                           gate_function=SmoothStep(max(t1 - GATE_CLOSE, 0.0), t1, 1.0, 0.0)))
    return Cornering(CONTROLLER, SENSOR, node, full, steering_function(c))


def build_cornering(p: VehicleRWDFile, c: PowerOnCornering, torsen: dict,
                    base_dir: str | Path = ".", reference: Any = None,
                    steer: Any = None) -> tuple[Spec, Layout, Cornering, VehicleRWDFile]:
    """The vehicle of ``p`` set up for the scenario ``c``: (spec, layout, cornering, the
    parameters it was built with). ``steer``: the pinion angle's time function (default
    :func:`steering_function`)."""
    q = cornering_parameters(p, c)
    steer = steering_function(c) if steer is None else steer
    sp, lay = build_spec(q, torsen, base_dir, steer=steer)
    cor = add_speed_controller(sp, lay, q, c, reference)
    cor.steer = steer
    return sp, lay, cor, q
