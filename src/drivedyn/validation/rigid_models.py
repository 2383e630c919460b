"""Small rigid-body mechanisms of the engine validation cases (pendulum, heavy top, slider-crank,
screw, torque-free body) and their parameters."""

from __future__ import annotations

from typing import Any

import numpy as np

from drivedyn.elements import (
    Force,
    Hinge,
    JointDriver,
    Prismatic,
    Screw,
    Spherical,
    SpringDamper,
    TorsionalSpringDamper,
    Universal,
)
from drivedyn.model import Model, Spec, compile_model
from drivedyn.rotations import frame_from_axis, rotation_from_euler_zxz
from drivedyn.validation.common import (
    G,
    rot_y,
    rot_z,
)
from drivedyn.validation.exact import slider_crank_position

PEND_M = 1.0
PEND_D = 1.0
PEND_J = np.diag([1e-4, 1e-2, 1e-2])  # about the centre of mass, body frame (x along the rod)
PEND_IO = PEND_J[1, 1] + PEND_M * PEND_D ** 2  # about the pivot


def pendulum_model(theta0: float, damper: tuple[float, float] | None = None) -> Model:
    """Physical pendulum swinging in the x-z plane about the global y axis.

    ``theta`` is measured from the downward vertical towards +x (hinge axis -y, so the hinge
    angle output is ``theta - theta0``). ``damper``: optional (stiffness, damping) of a torsional
    spring-damper in parallel with the hinge (free angle = the initial angle).
    """
    Rb = rot_y(0.5 * np.pi - theta0)  # body x (the rod) points at angle theta0 from -z
    spec = Spec(gravity=(0.0, 0.0, -G))
    spec.add_rigid_body("rod", PEND_M, PEND_J, com=(PEND_D, 0.0, 0.0), rotation=Rb)
    spec.add_marker("pivot", "ground", axis=(0.0, -1.0, 0.0))
    spec.add_marker("rod_pivot", "rod", rotation=Rb.T @ frame_from_axis([0.0, -1.0, 0.0]))
    spec.add(Hinge("hinge", "pivot", "rod_pivot"))
    if damper is not None:
        spec.add(TorsionalSpringDamper("damper", "pivot", "rod_pivot",
                                          stiffness=damper[0], damping=damper[1]))
    return compile_model(spec)


def _pendulum_angle(res: Any) -> np.ndarray:
    x = res["rod.position"].values
    return np.arctan2(x[:, 0], -x[:, 2])


# heavy symmetric top (fixed point at the origin, symmetry axis = body z)
TOP_M = 1.0
TOP_L = 0.05  # fixed point to centre of mass [m]
TOP_I1C = 1.5e-3  # transverse moment about the centre of mass [kg m^2]
TOP_I3 = 2.5e-3  # axial moment [kg m^2]
TOP_I1 = TOP_I1C + TOP_M * TOP_L ** 2  # transverse moment about the fixed point


def top_model(theta0: float, w3: float, phidot0: float) -> Model:
    """Heavy symmetric top on a spherical joint at the origin, symmetry axis tilted by
    ``theta0`` from +z (Euler z-x-z angles (0, theta0, 0)), spin component ``w3`` along the
    axis, precession rate ``phidot0`` about +z, ``thetadot = 0``."""
    R0 = rotation_from_euler_zxz(0.0, theta0, 0.0)
    k = R0[:, 2]
    psidot = w3 - phidot0 * np.cos(theta0)
    w = phidot0 * np.array([0.0, 0.0, 1.0]) + psidot * k
    spec = Spec(gravity=(0.0, 0.0, -G))
    spec.add_rigid_body("top", TOP_M, [TOP_I1C, TOP_I1C, TOP_I3], com=(0.0, 0.0, TOP_L),
                        rotation=R0, angular_velocity=w)
    spec.add_marker("fixed_point", "ground")
    spec.add_marker("top_tip", "top")
    spec.add(Spherical("ball", "fixed_point", "top_tip"))
    return compile_model(spec)


def _top_angles(res: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(theta, unwrapped phi, udot) of the top's symmetry axis k = R e3."""
    R = res["top.rotation"].values
    k = R[:, :, 2]
    w = res["top.angular_velocity"].values
    theta = np.arccos(np.clip(k[:, 2], -1.0, 1.0))
    phi = np.unwrap(np.arctan2(k[:, 0], -k[:, 1]))
    udot = np.cross(w, k)[:, 2]
    return theta, phi, udot


# slider-crank (in the x-y plane, crank centre at the origin, stroke along +x)
SC_R = 0.1
SC_L = 0.3


def slider_crank_model(theta: float, driver: tuple[str, Any] = ("speed", 2.0 * np.pi),
                       piston_force: float = 0.0, rod_com_offset: float = 0.0,
                       guide_spring: tuple[float, float] | None = None) -> Model:
    """Slider-crank at crank angle ``theta``, driven by a :class:`JointDriver` on the main
    bearing (``driver = (quantity, function)``).

    Joints (non-redundant, 17 constraints for 3 bodies, 1 dof): main bearing hinge (ground -
    crank), spherical crank pin (crank - rod), universal piston pin (rod - slider; cross axes
    z and y), prismatic guide (ground - slider along x). Planar hinges everywhere would give
    3 redundant rows, which the solver rightly refuses (singular matrix).

    ``piston_force``: force P [N] on the piston towards the crank (-x). ``rod_com_offset``:
    lateral offset [m] of the rod's centre of mass from the pin line (does not change the
    statics). ``guide_spring``: (stiffness, damping) of a spring-damper from the slider to a
    ground point on the stroke line beyond the piston.
    """
    phi = np.arcsin(SC_R * np.sin(theta) / SC_L)
    A = SC_R * np.array([np.cos(theta), np.sin(theta), 0.0])
    B = np.array([float(slider_crank_position(SC_R, SC_L, theta)), 0.0, 0.0])
    Rr = rot_z(-phi)  # rod body x from crank pin A to piston pin B
    spec = Spec()
    spec.add_rigid_body("crank", 1.0, [1e-4, 1e-3, 1e-3], com=(SC_R / 2, 0.0, 0.0),
                        rotation=rot_z(theta))
    spec.add_rigid_body("rod", 2.0, [1e-4, 2e-2, 2e-2], com=(SC_L / 2, rod_com_offset, 0.0),
                        position=A, rotation=Rr)
    spec.add_rigid_body("slider", 0.5, [1e-4, 1e-4, 1e-4], position=B)
    z = (0.0, 0.0, 1.0)
    spec.add_marker("main", "ground", axis=z)
    spec.add_marker("crank_main", "crank", axis=z)
    spec.add_marker("crank_pin", "crank", position=(SC_R, 0.0, 0.0))
    spec.add_marker("rod_big_end", "rod")
    # universal: x of the rod marker along global z, y of the slider marker along global y
    Ru = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    spec.add_marker("rod_small_end", "rod", position=(SC_L, 0.0, 0.0), rotation=Rr.T @ Ru)
    spec.add_marker("slider_pin", "slider")
    spec.add_marker("guide", "ground", axis=(1.0, 0.0, 0.0))
    spec.add_marker("slider_guide", "slider", axis=(1.0, 0.0, 0.0))
    spec.add(Hinge("main_bearing", "main", "crank_main"))
    spec.add(Spherical("crank_pin_joint", "crank_pin", "rod_big_end"))
    spec.add(Universal("piston_pin", "rod_small_end", "slider_pin"))
    spec.add(Prismatic("guide_joint", "guide", "slider_guide"))
    spec.add(JointDriver("crank_drive", "main_bearing", driver[1], quantity=driver[0]))
    if piston_force:
        spec.add(Force("gas", "slider_guide", vector=(-piston_force, 0.0, 0.0)))
    if guide_spring is not None:
        spec.add_marker("spring_anchor", "ground", position=(SC_R + SC_L + 0.2, 0.0, 0.0))
        spec.add(SpringDamper("guide_spring", "spring_anchor", "slider_guide",
                                 stiffness=guide_spring[0], damping=guide_spring[1]))
    return compile_model(spec)


SCREW_PITCH = 0.01  # [m/rev]
SCREW_M = 2.0
SCREW_J = (0.01, 0.01, 0.02)


def screw_model(speed: float, pitch: float = SCREW_PITCH) -> Model:
    """A nut (axisymmetric about z) on a screw joint along +z, under gravity -z, turned by a
    speed driver at ``speed`` [rad/s] (initial velocities consistent with the screw)."""
    v = pitch * speed / (2.0 * np.pi)
    spec = Spec(gravity=(0.0, 0.0, -G))
    spec.add_rigid_body("nut", SCREW_M, SCREW_J, velocity=(0.0, 0.0, v),
                        angular_velocity=(0.0, 0.0, speed))
    spec.add_marker("thread", "ground", axis=(0.0, 0.0, 1.0))
    spec.add_marker("nut_thread", "nut", axis=(0.0, 0.0, 1.0))
    spec.add(Screw("screw", "thread", "nut_thread", pitch=pitch))
    spec.add(JointDriver("turn", "screw", speed, quantity="speed"))
    return compile_model(spec)


# ---------------------------------------------------------------------------------------------
# cases
# ---------------------------------------------------------------------------------------------

TF_J = np.array([1.0, 2.0, 3.0])
TF_W0 = np.array([0.2, 1.0, 0.3])  # body frame [rad/s], not along a principal axis


def torque_free_model(pinned: bool) -> Model:
    """Asymmetric body spinning about a non-principal axis, centre of mass at the origin.

    ``pinned=False``: a free body, no gravity. ``pinned=True``: the same body held at its
    centre of mass by a spherical joint, under gravity (the weight and the reaction both act
    at the centre of mass, so the rotation is still torque-free).
    """
    spec = Spec(gravity=(0.0, 0.0, -G) if pinned else (0.0, 0.0, 0.0))
    spec.add_rigid_body("body", 1.0, TF_J, angular_velocity=TF_W0)
    if pinned:
        spec.add_marker("origin", "ground")
        spec.add_marker("body_com", "body")
        spec.add(Spherical("pin", "origin", "body_com"))
    return compile_model(spec)
