"""The driveline of a RWD vehicle run wound up by the engine's torque at the start: its plays
closed and its shafts twisted before the run begins (:func:`wind_up`).

From the parked vehicle's static equilibrium (:mod:`.static_start`) the engine's first
torque has to close every play of the driveline: the differential's gears float centred in
their clearances (the statics solve the TORSEN as the open differential, whose gears have
no stiffness at rest). In the vehicle run that took the TORSEN B launch 1629 steps and 1540
factorisations for its first 0.1 s, 2.0 s of a 3 s run's 4.9 s of wall
(docs/benchmark-log.md): the side gears cross their 50 um of play to the washers in 70 ms,
bouncing, and Newton fails on the element gears in their pockets. The real launch begins
from an idling engine in gear, its driveline already wound up by that torque.

:func:`wind_up` lets the driveline alone settle under the run's first engine torque: the
bodies from the engine's shaft to the driven wheels, everything else held where the static
equilibrium put it (the frame, the carrier, the uprights: their markers become the
ground's), the driven wheels braked, the engine's torque applied at its value at the run's
start (throttle and engine speed of the initial state) and held. Its own elements are the
vehicle's (gears, washers, pockets, joints, the propeller shaft's compliance), so the
settled state is the vehicle model's. After :data:`T_SETTLE` the run's state takes the
driveline's positions; its velocities stay the run's own (the rigid rolling of the static
start). Measured on the TORSEN B launch (5 s, docs/vehicle_rwd.md): the first 0.1 s in 226
steps instead of 1629, the run in 7277 steps instead of 8704; over 1.5-3 s the rear wheel
torques 0.3 % lower and their ratio within 2e-4 of the start with the plays open, the speed
at 3 s 0.5 % lower (the launch begins from another state).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from drivedyn.elements import EngineTorque, Torque, TorsionalSpringDamper
from drivedyn.elements.controllers import SpeedController
from drivedyn.elements.drivers import JointDriver, SpeedDifferenceDriver, TravelDriver
from drivedyn.elements.tyre import TyreContact
from drivedyn.model.compile import compile_model
from drivedyn.model.spec import Spec
from drivedyn.solver.simulation import Simulation

#: settling time [s] under the held torque: the shipped TORSEN B's plays close by 0.3 s
#: (the final drive's and the differential's; the side gears reach their washers), the
#: propeller shaft's twist is the torque over its stiffness within 0.1 % from 0.8 s on
T_SETTLE = 0.8
#: damping of the engine's shaft to the ground during the settling, as a rate [1/s] times
#: the shaft's inertia about its axis: about 0.45 of critical for the driveline's slowest
#: mode (the engine's inertia on the propeller shaft's compliance, 23 rad/s in the shipped
#: file; damping ratio 0.06 of its own), so the settling does not ring. Its torque vanishes
#: at rest: the settled state is the same static equilibrium
RELAX_DAMPING = 20.0
#: elements left out of the settling: the tyres (the wheels are braked) and what drives or
#: controls the vehicle (a controller's sensor or a driver's motion is not the driveline's;
#: the engine's torque is held at its start value instead)
ACTIVE = (TyreContact, SpeedController, JointDriver, TravelDriver, SpeedDifferenceDriver)
#: torsional stiffness of the brakes on the driven wheels during the settling [N m/rad]:
#: stiff (the wheels' spin held within 0.1 mrad at the launch's torques), so that the
#: settling winds the driveline, not the brakes
BRAKE_TORSION = 1.0e7


def driveline_bodies(spec: Spec, drives: dict[str, str], wheels: dict[str, str]) -> list[str]:
    """The bodies of the driveline: the engine's shaft, the propeller shaft and its slip
    yoke, the pinion, the rear differential's bodies (``rear_*``), and per driven wheel its
    half-shaft, plunger and wheel."""
    names = ["engine_shaft", "propshaft", "propshaft_slip", "pinion_shaft"]
    names += [b for b in spec.bodies if b.startswith("rear_")]
    for w in drives:
        names += [f"halfshaft_{w}", f"plunger_{w}", wheels[w]]
    return [b for b in names if b in spec.bodies]


def engine_torque_at(el: Any, model: Any, st: Any, t: float) -> float:
    """The torque [N m] the :class:`~drivedyn.elements.EngineTorque` ``el`` applies to its
    shaft in state ``st`` at time ``t``: ``ratio`` times the engine's torque at the
    throttle ``u(t)`` and the engine speed of the state."""
    def omega(marker: str) -> tuple[np.ndarray, np.ndarray]:
        n, _, Rm = model.marker_frames[marker]
        if n >= model.nn:  # the ground
            return np.zeros(3), Rm
        return st.R[n] @ st.v[6 * n + 3:6 * n + 6], st.R[n] @ Rm

    wa, Ra = omega(el.marker_a)
    wb, _ = omega(el.marker_b)
    speed = el.ratio * float((wb - wa) @ Ra[:, 2])
    u = el.throttle_function
    throttle = float(u(t)) if callable(u) else float(u)
    return el.ratio * el.torque(speed, throttle)


def wind_up(model: Any, st: Any, lay: Any, settings: dict) -> Any:
    """``st`` (the run's initial state, from :func:`~.static_start.static_start`) with the
    driveline's bodies moved to where the run's first engine torque settles them (module
    docstring); ``settings``: the keyword arguments of ``simulate`` for the settling (the
    file's solver settings). Returns a new state."""
    spec = model.spec
    bodies = driveline_bodies(spec, lay.drives, lay.wheels)
    keep = set(bodies)
    s = spec.settings
    sub = Spec(gravity=s.gravity, constraint_scaling=s.constraint_scaling,
               constraint_penalty=s.constraint_penalty,
               assembly_tolerance=s.assembly_tolerance)
    for b in bodies:
        rb = spec.bodies[b]
        i = model.node_index[b]
        R = st.R[i]
        sub.add_rigid_body(b, rb.mass, rb.inertia, com=rb.com, position=st.x[i] - R @ rb.com,
                           rotation=R)

    def on_driveline(marker: str) -> bool:
        return spec.markers[marker].body in keep

    def add_marker(marker: str) -> None:
        if marker in sub.markers:
            return
        m = spec.markers[marker]
        if m.body in keep:
            sub.add_marker(marker, m.body, position=m.position, rotation=m.rotation)
            return
        n, off, Rm = model.marker_frames[marker]  # held where the static start put it
        if n >= model.nn:
            sub.add_marker(marker, "ground", position=off, rotation=Rm)
        else:
            sub.add_marker(marker, "ground", position=st.x[n] + st.R[n] @ off,
                           rotation=st.R[n] @ Rm)

    for el in spec.elements:
        markers = el.markers()
        if (not markers or not any(on_driveline(m) for m in markers)
                or isinstance(el, ACTIVE)):
            continue
        for m in markers:
            add_marker(m)
        if isinstance(el, EngineTorque):  # its torque at the run's start, held
            T = engine_torque_at(el, model, st, st.t)
            sub.add(Torque(f"{el.name}_held", el.marker_b, vector=(0.0, 0.0, T),
                           frame="marker"))
            J = spec.bodies[spec.markers[el.marker_b].body].inertia
            sub.add(TorsionalSpringDamper(f"{el.name}_relax", el.marker_a, el.marker_b,
                                          damping=RELAX_DAMPING * float(np.max(np.diag(J)))))
        else:
            sub.add(el)
    for w in lay.drives:
        hub, bearing = f"{lay.wheels[w]}_hub", f"{lay.wheels[w]}_bearing_hub"
        add_marker(hub)
        add_marker(bearing)
        sub.add(TorsionalSpringDamper(f"brake_{w}", bearing, hub, stiffness=BRAKE_TORSION))
    ms = compile_model(sub)
    sim = Simulation(ms, record=False, **settings)
    sim.advance(T_SETTLE)
    if not sim.success:
        raise RuntimeError(f"the driveline's wind-up did not settle: {sim.message}")
    fin = sim.state
    out = st.copy()
    for b in bodies:
        i, j = model.node_index[b], ms.node_index[b]
        out.x[i] = fin.x[j]
        out.R[i] = fin.R[j]
    return out
