"""Small gear-pair models for the registry tangent test (``tests/elements/test_tangents.py``).

Every case places two wheels on bodies with off-centre masses and arbitrary orientations and
switches on every term of the mesh law that applies: helix, backlash, transmission error,
stiffness varying over the mesh cycle, damping and tooth friction (in and outside its
regularisation band). The test perturbs positions by ~1e-2 m and rotations by ~0.05 rad, so
the gears are sized (centre distances ~0.4 m) to keep the involute term well defined, and
one flank is always loaded (0.05 rad of wheel rotation is far beyond the backlash).
"""

from __future__ import annotations

import numpy as np

from drivedyn.model.spec import Spec
from drivedyn.rotations import exp_so3
from small_models import rot_y, rot_z

_RA = exp_so3(np.array([0.3, -0.5, 0.8]))
_RB = exp_so3(np.array([-0.7, 0.2, 0.4]))
_RM = exp_so3(np.array([0.2, 0.9, -0.3]))  # global frame of the gear set
_J = np.array([[2.0, 0.1, 0.0], [0.1, 3.0, 0.2], [0.0, 0.2, 2.5]])


def _wheel(spec: Spec, name: str, centre, frame, body_rot, body_pos, ground: bool) -> str:
    """A wheel marker ``m<name>`` at global ``centre`` with global ``frame`` (z = axis), on a
    new body ``<name>`` (or on the ground)."""
    centre = np.asarray(centre, float)
    if ground:
        spec.add_marker(f"m{name}", "ground", position=centre, rotation=frame)
    else:
        pos = np.asarray(body_pos, float)
        spec.add_rigid_body(name, 1.5, _J, com=(0.03, -0.02, 0.01), position=pos,
                            rotation=body_rot)
        spec.add_marker(f"m{name}", name, position=body_rot.T @ (centre - pos),
                        rotation=body_rot.T @ frame)
    return f"m{name}"


def parallel_case(internal: str | None = None, ground_a: bool = False,
                  flip_b: bool = False) -> Spec:
    """Helical pair with parallel axes (external, or internal with ring ``internal``)."""
    from drivedyn.elements.gears import CylindricalPair, GearPair

    spec = Spec(gravity=(0.0, 0.0, -9.81))
    za, zb = (20, 31) if internal is None else ((20, 47) if internal == "b" else (47, 20))
    beta = np.radians(17.0)
    mn, an = 0.02, np.radians(25.0)
    if internal == "a":
        geo = CylindricalPair.build(zb, -za, mn, an, beta)
    elif internal == "b":
        geo = CylindricalPair.build(za, -zb, mn, an, beta)
    else:
        geo = CylindricalPair.build(za, zb, mn, an, beta)
    c0 = np.array([0.1, -0.2, 0.3])
    FA = _RM
    FB = _RM @ rot_z(0.4)
    if flip_b:
        FB = FB @ rot_y(np.pi)  # wheel B's marker z against A's
    cB = c0 + geo.centre_distance * _RM[:, 0]
    a = _wheel(spec, "A", c0, FA, _RA, c0 + np.array([0.05, 0.0, -0.03]), ground_a)
    b = _wheel(spec, "B", cB, FB, _RB, cB + np.array([-0.02, 0.04, 0.01]), False)
    spec.add(GearPair("g", a, b, za, zb, mn, 0.04, pressure_angle=an,
                      helix_angle=beta if internal is None else -beta, internal=internal,
                      stiffness=2.0e6, stiffness_variation=True, variation_smoothing=0.5,
                      mesh_phase=0.15, damping=300.0, backlash=2e-3, initial_gap=5e-4,
                      transmission_error=3e-4, friction=0.2, friction_velocity=0.5,
                      flank_onset=1e-6))
    return spec


def bevel_case() -> Spec:
    """Spiral bevel pair, shaft angle 90 deg, wheel B's axis pointing towards the apex."""
    from drivedyn.elements.gears import GearPair

    spec = Spec()
    za, zb = 18, 31
    beta, mn = np.radians(25.0), 0.05
    gA = float(np.arctan2(np.sin(np.pi / 2), zb / za + np.cos(np.pi / 2)))
    gB = np.pi / 2 - gA
    Rm = za * mn / (2 * np.cos(beta)) / np.sin(gA)
    O = np.array([0.2, 0.1, -0.1])
    ao, bo = _RM[:, 2], _RM[:, 0]
    cA = O + Rm * np.cos(gA) * ao
    cB = O + Rm * np.cos(gB) * bo
    FA = _RM @ rot_z(0.2)
    FB = _RM @ rot_y(-np.pi / 2)  # z along -bo (towards the apex)
    a = _wheel(spec, "A", cA, FA, _RA, cA + np.array([0.02, 0.0, 0.01]), False)
    b = _wheel(spec, "B", cB, FB, _RB, cB + np.array([0.0, -0.03, 0.02]), False)
    spec.add(GearPair("g", a, b, za, zb, mn, 0.05, helix_angle=beta, kind="bevel",
                      cone_angle_a=gA, cone_angle_b=gB, stiffness=3.0e6, damping=200.0,
                      backlash=1e-3, friction=0.15, friction_velocity=1e-3))
    return spec


def crossed_case() -> Spec:
    """Crossed helical pair (same hands, 30 + 45 deg), with tooth friction."""
    from drivedyn.elements.gears import GearPair

    spec = Spec()
    bA, bB = np.radians(30.0), np.radians(45.0)
    mn = 0.02
    za, zb = 15, 12
    rA = za * mn / (2 * np.cos(bA))
    rB = zb * mn / (2 * np.cos(bB))
    c0 = np.array([-0.1, 0.2, 0.0])
    e = _RM[:, 0]
    FA = _RM
    # B's axis: A's axis turned about the common perpendicular e by -(beta_A + beta_B), so
    # that the tooth traces cos(beta) axis + sin(beta) axis x e_wheel coincide at the pitch
    # point (e_A = e, e_B = -e)
    Sig = -(bA + bB)
    FB = _RM @ np.array([[1.0, 0, 0], [0, np.cos(Sig), -np.sin(Sig)],
                         [0, np.sin(Sig), np.cos(Sig)]]) @ rot_z(0.7)
    cB = c0 + np.array([rA + rB]) * e
    a = _wheel(spec, "A", c0, FA, _RA, c0 + np.array([0.0, 0.02, 0.03]), False)
    b = _wheel(spec, "B", cB, FB, _RB, cB + np.array([0.01, 0.0, -0.02]), False)
    spec.add(GearPair("g", a, b, za, zb, mn, 0.03, helix_angle=bA, helix_angle_b=bB,
                      kind="crossed", stiffness=1.5e6, damping=150.0, backlash=5e-4,
                      initial_gap=1e-4, friction=0.1, friction_velocity=5.0))
    return spec


CASES = [
    lambda: parallel_case(),
    lambda: parallel_case(flip_b=True),
    lambda: parallel_case(internal="b", ground_a=True),
    lambda: parallel_case(internal="a"),
    bevel_case,
    crossed_case,
]
