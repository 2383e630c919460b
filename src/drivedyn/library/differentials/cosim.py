"""The co-simulation configuration of a differential: the usual causality of a driveline
coupled to a vehicle model. The housing turns free with its inertia under ``input_torque``
[N m] (about +z, on marker ``b_housing``); each output's speed [rad/s] is imposed by a
driver ``{output}_speed`` on its bearing. All three follow inputs held between the calls of a
resumable run (:class:`~drivedyn.timefunctions.Held`, named like the elements), so a
:class:`~drivedyn.solver.simulation.Simulation` of it advances from one communication
point to the next with the values a master wrote.

The torque an output delivers to its shaft is minus the torque its driver applies on it
(:func:`delivered_torque_sign`): positive in drive, the two adding up to the housing torque in
steady state.
"""

from __future__ import annotations

from typing import Any

from drivedyn.elements import JointDriver, Torque
from drivedyn.library.differentials.base import Differential
from drivedyn.model.spec import Spec
from drivedyn.timefunctions import Held

#: name of the housing-torque input (and of its load element)
INPUT_TORQUE = "input_torque"


def speed_input(output: str) -> str:
    """Name of the speed input (and driver element) of output ``output``."""
    return f"{output}_speed"


def delivered_torque_sign() -> float:
    """Factor from a speed driver's ``torque`` output (on the differential's output body) to
    the torque the output delivers to its shaft [N m]."""
    return -1.0


def cosim_spec(diff: Differential, p: Any, speeds: tuple[float, float],
               torque: float = 0.0) -> tuple[Spec, Any]:
    """The co-simulation configuration of ``diff`` with parameters ``p`` (module doc).

    Args:
        diff: the differential type.
        p: its validated parameters.
        speeds: (first, second) output speeds about +z at the start [rad/s]; the housing
            starts at the speed the gear kinematics give them (``diff.housing_speed``).
        torque: housing torque at the start [N m].
    Returns:
        (spec, geometry).
    """
    w1, w2 = float(speeds[0]), float(speeds[1])
    sp, geo = diff.build(p, (diff.housing_speed(p, w1, w2), w1, w2), 1.0)
    sp.add(Torque(INPUT_TORQUE, "b_housing", vector=(0, 0, 1.0),
                  function=Held(INPUT_TORQUE, float(torque))))
    for o, w in zip(diff.outputs, (w1, w2), strict=True):
        name = speed_input(o.name)
        sp.add(JointDriver(name, o.bearing, Held(name, w), quantity="speed"))
    return sp, geo
