"""Small models exercising every element family (test fixtures, not shipped).

:data:`TANGENT_CASES` maps each family's registry name (``drivedyn.elements.REGISTRY``) to
functions returning a small :class:`~drivedyn.model.spec.Spec` that exercises it; the registry
tangent test (``tests/elements/test_tangents.py``) checks every family's tangent matrices on
them and fails for a registered family that has no entry here, so a new family cannot be
forgotten.

The tables themselves: :mod:`element_cases.basic` (bodies, joints, drivers, springs, loads),
:mod:`element_cases.nonlinear_springs` (tabulated springs, dampers, bump stops),
:mod:`element_cases.contact` (force-type and unilateral contacts, squeeze film),
:mod:`element_cases.gears` (gear pairs), :mod:`element_cases.beams` (beams),
:mod:`element_cases.flexible` (reduced flexible bodies), :mod:`element_cases.tyres` (tyres)
and :mod:`element_cases.bushings` (bushings). Tests in every tier import this package as a
top-level module (``pythonpath`` in pyproject.toml puts ``tests/`` on
``sys.path``, as for ``fdcheck``).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial

from drivedyn.elements.joints import JOINT_TYPES
from drivedyn.model.spec import Spec
from element_cases import (
    basic,
    beams,
    bushings,
    contact,
    flexible,
    gears,
    nonlinear_springs,
    tyres,
)

TANGENT_CASES: dict[str, list[Callable[[], Spec]]] = {
    "rigid_body": [basic.spinning_body],
    "joint": [*(partial(basic.joint_case, j, ground_a=g) for j in JOINT_TYPES
                for g in (False, True)), basic.mixed_joints_case,
              *(partial(basic.screw_friction_case, k, ground_a=g, stick_onset=n)
                for k in (1.0, 1e5) for g in (False, True) for n in (0.0, 2.0))],
    "joint_driver": [basic.driver_case, basic.speed_driver_case],
    "travel_driver": [basic.travel_driver_case, basic.travel_speed_driver_case],
    "speed_difference_driver": [basic.speed_difference_case],
    "speed_controller": [basic.speed_controller_case,
                         partial(basic.speed_controller_case, ground_a=True),
                         partial(basic.speed_controller_case, saturated=True)],
    "spring_damper": [basic.spring_case],
    "torsional_spring_damper": [basic.torsion_case],
    "engine_torque": [basic.engine_case],
    "nonlinear_spring_damper": list(nonlinear_springs.SPRING_CASES),
    "bump_stop": list(nonlinear_springs.STOP_CASES),
    "force": [partial(basic.load_case, False, "global"), partial(basic.load_case, False, "marker")],
    "torque": [partial(basic.load_case, True, "global"), partial(basic.load_case, True, "marker")],
    "plane_contact": [contact.plane_case, contact.sphere_case, contact.plane_ground_case],
    "thrust_washer_contact": [contact.washer_case, contact.washer_ground_case],
    "journal_contact": [contact.journal_case, contact.journal_ground_case],
    "journal_film": [contact.journal_film_case, contact.journal_film_blend_case,
                     contact.journal_film_contact_case, contact.journal_film_centred_case],
    "squeeze_film": [contact.squeeze_case, contact.squeeze_metal_case],
    "unilateral_contact": [contact.unilateral_case, contact.unilateral_ground_case],
    "gear_pair": list(gears.CASES),
    "beam": list(beams.CASES),
    "flexible_body": list(flexible.CASES),
    "flexible_washer_contact": [flexible.washer_case, flexible.washer_points_case],
    "flexible_interface": [flexible.free_case, flexible.tie_case, flexible.average_tie_case],
    "tyre": list(tyres.CASES),
    "bushing": list(bushings.CASES),
}
