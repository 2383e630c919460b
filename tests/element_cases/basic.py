"""Small models that exercise each element family, for the registry tangent test.

Each case function returns a :class:`~drivedyn.model.spec.Spec`. The test perturbs the
compiled initial state randomly (positions off the constraint manifold, random velocities,
accelerations and multipliers) so that every term of every tangent is active.
"""

from __future__ import annotations

import numpy as np

from drivedyn.model.spec import Spec
from drivedyn.rotations import exp_so3

_RA = exp_so3(np.array([0.3, -0.5, 0.8]))
_RB = exp_so3(np.array([-0.7, 0.2, 0.4]))
_RM = exp_so3(np.array([0.2, 0.9, -0.3]))  # common global frame of coinciding markers


def _two_bodies(spec: Spec, ground_a: bool = False) -> tuple[str, str]:
    """Bodies 'A' and 'B' with centre-of-mass offsets and coinciding markers 'mA', 'mB'
    at global point (0.3, -0.2, 0.5) with orientation _RM."""
    J = np.array([[2.0, 0.1, 0.0], [0.1, 3.0, 0.2], [0.0, 0.2, 2.5]])
    target = np.array([0.3, -0.2, 0.5])
    if ground_a:
        spec.add_marker("mA", "ground", position=target, rotation=_RM)
    else:
        xa = np.array([0.1, 0.2, -0.1])
        spec.add_rigid_body("A", 1.5, J, com=(0.05, 0.0, 0.02), position=xa, rotation=_RA)
        spec.add_marker("mA", "A", position=_RA.T @ (target - xa), rotation=_RA.T @ _RM)
    xb = np.array([-0.2, 0.4, 0.3])
    spec.add_rigid_body("B", 2.0, 0.8 * J, com=(-0.03, 0.04, 0.0), position=xb, rotation=_RB)
    spec.add_marker("mB", "B", position=_RB.T @ (target - xb), rotation=_RB.T @ _RM)
    return "mA", "mB"


def spinning_body() -> Spec:
    spec = Spec(gravity=(0.0, -3.0, -9.81))
    spec.add_rigid_body("body", 2.0, np.diag([1.0, 2.0, 2.5]), com=(0.1, 0.0, 0.0),
                        rotation=_RA, angular_velocity=(3.0, -2.0, 5.0))
    return spec


def joint_case(joint_type: type, ground_a: bool = False) -> Spec:
    spec = Spec(gravity=(0.0, 0.0, -9.81))
    a, b = _two_bodies(spec, ground_a)
    kw = {"pitch": 0.05} if joint_type.__name__ == "Screw" else {}
    spec.add(joint_type("j", a, b, k=3.0e2, p=1.0e2, **kw))
    return spec


def screw_friction_case(stick_stiffness: float, ground_a: bool = False,
                        stick_onset: float = 0.0) -> Spec:
    """A screw with flank friction (mu 0.3, radius 0.05 m): with the random test state
    (slide ~1e-2 m, screw force ~1-10 N) a stick stiffness of 1 N/m sticks and one of 1e5
    N/m slips, so both branches of the return mapping and the slip's multiplier column
    are differentiated; with ``stick_onset`` (2 N: comparable to the normal force) the
    stiffness's dependence on the screw force too (in stick, the multiplier column)."""
    from drivedyn.elements.joints import Screw

    spec = Spec(gravity=(0.0, 0.0, -9.81))
    a, b = _two_bodies(spec, ground_a)
    spec.add(Screw("j", a, b, k=3.0e2, p=1.0e2, pitch=0.05, friction=0.3, radius=0.05,
                   stick_stiffness=stick_stiffness, stick_onset=stick_onset))
    return spec


def mixed_joints_case() -> Spec:
    """Every joint type between the same two bodies, in one group: elements with 2 to 6
    rows side by side (each element's unused rows must stay out of the matrix)."""
    from drivedyn.elements.joints import JOINT_TYPES

    spec = Spec(gravity=(0.0, 0.0, -9.81))
    a, b = _two_bodies(spec)
    for i, jt in enumerate(JOINT_TYPES):
        kw = {"pitch": 0.05} if jt.__name__ == "Screw" else {}
        spec.add(jt(f"j{i}", a, b, k=3.0e2 * (1 + i), p=1.0e2 * (2 + i), **kw))
    return spec


def driver_case() -> Spec:
    from drivedyn.elements.drivers import JointDriver
    from drivedyn.elements.joints import Hinge
    from drivedyn.timefunctions import Ramp

    spec = Spec()
    a, b = _two_bodies(spec)
    spec.add(Hinge("j", a, b))
    spec.add(JointDriver("d_angle", "j", Ramp(0.0, 1.0, 0.0, 2.0), quantity="angle", k=5.0))
    return spec


def speed_driver_case() -> Spec:
    from drivedyn.elements.drivers import JointDriver
    from drivedyn.elements.joints import Hinge
    from drivedyn.timefunctions import SmoothStep

    spec = Spec()
    a, b = _two_bodies(spec)
    spec.add(Hinge("j", a, b))
    spec.add(JointDriver("d_speed", "j", SmoothStep(0.0, 1.0, 1.0, 3.0), quantity="speed",
                         k=7.0, p=2.0))
    return spec


def travel_driver_case() -> Spec:
    from drivedyn.elements.drivers import TravelDriver
    from drivedyn.elements.joints import Prismatic
    from drivedyn.timefunctions import Ramp

    spec = Spec()
    a, b = _two_bodies(spec)
    spec.add(Prismatic("j", a, b))
    spec.add(TravelDriver("d_travel", "j", Ramp(0.0, 1.0, 0.0, 0.2), k=5.0))
    return spec


def travel_speed_driver_case() -> Spec:
    from drivedyn.elements.drivers import TravelDriver
    from drivedyn.elements.joints import Cylindrical
    from drivedyn.timefunctions import SmoothStep

    spec = Spec()
    a, b = _two_bodies(spec, ground_a=True)
    spec.add(Cylindrical("j", a, b))
    spec.add(TravelDriver("d_speed", "j", SmoothStep(0.0, 1.0, 0.1, 0.3), quantity="speed",
                          k=7.0, p=2.0))
    return spec


def speed_difference_case() -> Spec:
    from drivedyn.elements.drivers import SpeedDifferenceDriver
    from drivedyn.elements.joints import Hinge

    spec = Spec()
    J = np.diag([1.0, 1.5, 2.0])
    for i, R in enumerate((_RA, _RB, _RM, _RA.T)):
        spec.add_rigid_body(f"b{i}", 1.0 + i, J, com=(0.01 * i, 0.0, 0.02), rotation=R,
                            position=(0.1 * i, 0.0, 0.0))
    for j, (p, q) in enumerate(((0, 1), (2, 3))):
        Rp = spec.bodies[f"b{p}"].rotation
        Rq = spec.bodies[f"b{q}"].rotation
        xp = spec.bodies[f"b{p}"].position
        xq = spec.bodies[f"b{q}"].position
        target = np.array([0.2 * j, 0.1, 0.0])
        spec.add_marker(f"m{p}", f"b{p}", position=Rp.T @ (target - xp), rotation=Rp.T @ _RM)
        spec.add_marker(f"m{q}", f"b{q}", position=Rq.T @ (target - xq), rotation=Rq.T @ _RM)
        spec.add(Hinge(f"j{j}", f"m{p}", f"m{q}"))
    spec.add(SpeedDifferenceDriver("sd", "j0", "j1", 2.0, k=4.0, p=1.5))
    return spec


def speed_controller_case(saturated: bool = False, ground_a: bool = False) -> Spec:
    """A speed controller sensing body B's marker (offset from its node, so every term of
    the speed's derivative is active) and driving B against A; ``saturated``: limits that
    clip the output (the clipped tangent is zero), else limits wide enough to stay inside."""
    from drivedyn.elements.controllers import SpeedController
    from drivedyn.timefunctions import SmoothStep

    spec = Spec()
    a, b = _two_bodies(spec, ground_a)
    spec.add_marker("sense", "B", position=(0.3, -0.1, 0.2), rotation=_RA.T @ _RM)
    lim = 0.5 if saturated else 50.0
    spec.add(SpeedController("c", "sense", a, b, SmoothStep(0.0, 1.0, 1.0, 3.0), gain=4.0,
                             integral_gain=2.5, torque_min=-lim, torque_max=lim,
                             initial_torque=0.2, gate_function=SmoothStep(0.0, 1.0, 0.5, 0.9)))
    return spec


def spring_case() -> Spec:
    from drivedyn.elements.springs import SpringDamper

    spec = Spec()
    _two_bodies(spec)
    J = np.eye(3)
    spec.add_rigid_body("C", 1.0, J, position=(1.0, 0.5, -0.2), rotation=_RB)
    spec.add_marker("mC", "C", position=(0.1, 0.2, 0.3))
    spec.add_marker("mA2", "A", position=(-0.2, 0.1, 0.05))
    spec.add(SpringDamper("s", "mA2", "mC", stiffness=1e3, damping=20.0, free_length=0.7,
                          preload=30.0))
    return spec


def torsion_case() -> Spec:
    from drivedyn.elements.springs import TorsionalSpringDamper

    spec = Spec()
    a, b = _two_bodies(spec)
    spec.add(TorsionalSpringDamper("t", a, b, stiffness=500.0, damping=3.0, free_angle=0.2,
                                   preload=4.0))
    return spec


def load_case(is_torque: bool, frame: str) -> Spec:
    from drivedyn.elements.loads import Force, Torque
    from drivedyn.timefunctions import Ramp

    spec = Spec()
    spec.add_rigid_body("A", 1.0, np.diag([1.0, 2.0, 3.0]), com=(0.1, 0.0, 0.0), rotation=_RA)
    spec.add_marker("m", "A", position=(0.3, -0.2, 0.1), rotation=_RM)
    cls = Torque if is_torque else Force
    spec.add(cls("load", "m", vector=(3.0, -2.0, 5.0), function=Ramp(-1.0, 1.0, 0.5, 2.0),
                 frame=frame))
    return spec


#: engine maps of the tangent case [(rad/s, N m)]: the relative speeds of the markers at the
#: tangent test's perturbed state (seed 7: about -0.07 and 0.22 rad/s about A's z, the two
#: directions) times the ratios fall below, inside and beyond them
ENGINE_FULL = ((0.0, 40.0), (2.0, 75.0), (4.0, 120.0), (7.0, 110.0), (9.0, -30.0))
ENGINE_ZERO = ((0.0, 0.0), (3.0, -5.0), (6.0, -9.0), (9.0, -40.0))


def engine_case() -> Spec:
    """Engine torques both ways between A and B (one of them turns forward), with and
    without a zero-throttle curve, ratios that put the engine speed in the first segment, in
    the middle of the tables and beyond either end, a throttle ramp under way at the test's
    time."""
    from drivedyn.elements.engine import EngineTorque
    from drivedyn.timefunctions import Ramp

    spec = Spec()
    a, b = _two_bodies(spec)
    u = Ramp(0.0, 0.8, 0.0, 1.0)
    for i, (ratio, zero) in enumerate(((2.5, ENGINE_ZERO), (25.0, ENGINE_ZERO), (25.0, None),
                                       (150.0, None))):
        for j, (m1, m2) in enumerate(((a, b), (b, a))):
            spec.add(EngineTorque(f"e{i}{j}", m1, m2, full_load=ENGINE_FULL,
                                  zero_throttle=zero, throttle_function=u if zero else 0.6,
                                  ratio=ratio))
    return spec
