"""Tangent cases of the geometrically exact beam (family ``beam``)."""

from __future__ import annotations

import numpy as np

from drivedyn.elements.beams import GeneralSection, GeometricallyExactBeam, Material
from drivedyn.elements.beams.section import HollowCircular
from drivedyn.model.beams import add_straight_beam
from drivedyn.model.spec import Spec

# well-conditioned stiffnesses of one order, so that the FD check sees every term
_SEC = GeneralSection(3.0, 1.2, 1.5, 0.7, 0.9, 1.1, 2.0, rotary_inertia=(0.3, 0.1, 0.2))


def straight_case() -> Spec:
    """Two straight elements, lumped mass, material damping, gravity, spin."""
    spec = Spec(gravity=(0.0, 0.0, -9.81))
    add_straight_beam(spec, "b", (0.1, 0.2, 0.3), (1.0, 0.5, 0.1), 2, _SEC, damping=0.05,
                      velocity=(0.1, 0.0, 0.2), angular_velocity=(0.3, 1.0, 2.0))
    return spec


def body_case() -> Spec:
    """A consistent-mass element between a rigid body's node and a plain node whose frame
    is not aligned with the section (constant section rotations at both ends)."""
    spec = Spec(gravity=(0.0, -2.0, -9.81))
    spec.add_rigid_body("hub", 1.5, (0.2, 0.3, 0.35), position=(0.0, 0.0, 0.0),
                        angular_velocity=(1.0, 0.5, -2.0))
    c, s = np.cos(0.4), np.sin(0.4)
    spec.add_node("tip", (0.8, 0.1, -0.2), rotation=[[c, -s, 0.0], [s, c, 0.0], [0, 0, 1.0]])
    steel = Material.from_nu(3.0, 0.3, 1.0)  # scaled "steel": stiffness O(1)
    spec.add(GeometricallyExactBeam("e", "hub", "tip", HollowCircular(1.0, 0.5), steel,
                                    damping=0.02, mass_matrix="consistent",
                                    orientation=(0.0, 1.0, 1.0)))
    return spec


def curved_case() -> Spec:
    """A curved (helix) element: reference strain from the initial node frames."""
    spec = Spec()
    c, s = np.cos(0.5), np.sin(0.5)
    spec.add_node("a", (0.0, 0.0, 0.0))
    spec.add_node("b", (0.9, 0.3, 0.1), rotation=[[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0, c]])
    spec.add(GeometricallyExactBeam("e", "a", "b", _SEC, curved=True, damping=0.1))
    return spec


CASES = (straight_case, body_case, curved_case)
