"""Model building: bad input is refused at build time with a message naming the element."""

from __future__ import annotations

import numpy as np
import pytest

import drivedyn as dd
from drivedyn.model.spec import ModelError


def _two_bodies() -> dd.Spec:
    spec = dd.Spec()
    spec.add_rigid_body("a", 1.0, [1.0, 1.0, 1.0])
    spec.add_rigid_body("b", 1.0, [1.0, 1.0, 1.0], position=(1.0, 0.0, 0.0))
    spec.add_marker("ma", "a", position=(0.5, 0.0, 0.0), axis=(0, 0, 1))
    spec.add_marker("mb", "b", position=(-0.5, 0.0, 0.0), axis=(0, 0, 1))
    return spec


@pytest.mark.parametrize(
    ("mass", "inertia", "message"),
    [
        (-1.0, [1, 1, 1], "rigid body 'x'.mass: must be > 0 kg, got -1.0"),
        (0.0, [1, 1, 1], "rigid body 'x'.mass: must be > 0 kg, got 0.0"),
        ("heavy", [1, 1, 1], "rigid body 'x'.mass: expected a number [kg], got 'heavy'"),
        (1.0, [1, -1, 1], "rigid body 'x': inertia tensor is not positive definite"),
        (1.0, [1, 1, 3], "violate the triangle inequality J1 + J2 >= J3"),
        (1.0, [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]], "rigid body 'x': inertia tensor is not "
                                                   "symmetric"),
    ],
)
def test_impossible_bodies_are_refused(mass, inertia, message):
    spec = dd.Spec()
    with pytest.raises(ModelError) as exc:
        spec.add_rigid_body("x", mass, inertia)
    assert message in str(exc.value)


def test_triangle_inequality_limit_is_accepted():
    # a thin rod or flat plate reaches J1 + J2 = J3 exactly: physically possible
    spec = dd.Spec()
    spec.add_rigid_body("plate", 1.0, [1.0, 2.0, 3.0])


def test_unknown_marker_names_the_element():
    spec = _two_bodies()
    spec.add(dd.Hinge("h1", "ma", "nowhere"))
    with pytest.raises(ModelError, match="Hinge 'h1': unknown marker 'nowhere'"):
        dd.compile_model(spec)


def test_joint_on_the_same_body_twice():
    spec = _two_bodies()
    spec.add_marker("ma2", "a", position=(0.5, 0.0, 0.0), axis=(0, 0, 1))
    spec.add(dd.Hinge("h1", "ma", "ma2"))
    with pytest.raises(ModelError, match="Hinge 'h1': both markers 'ma' and 'ma2' are on body "
                                         "'a'; a joint must connect two different bodies"):
        dd.compile_model(spec)


def test_unassembled_joint_is_refused():
    spec = _two_bodies()
    spec.add_marker("far", "b", position=(0.0, 0.0, 0.0), axis=(0, 0, 1))
    spec.add(dd.Spherical("s", "ma", "far"))
    with pytest.raises(ModelError, match="Spherical 's': markers 'ma' and 'far' are not "
                                         "assembled"):
        dd.compile_model(spec)


def test_marker_on_unknown_body():
    spec = _two_bodies()
    spec.add_marker("m", "ghost")
    with pytest.raises(ModelError, match="marker 'm': unknown body or node 'ghost'"):
        dd.compile_model(spec)


def test_duplicate_names():
    spec = _two_bodies()
    with pytest.raises(ModelError, match="rigid body 'a': duplicate name"):
        spec.add_rigid_body("a", 1.0, [1, 1, 1])
    spec.add(dd.Hinge("h", "ma", "mb"))
    with pytest.raises(ModelError, match="Hinge 'h': duplicate name"):
        spec.add(dd.Hinge("h", "ma", "mb"))


def test_driver_needs_a_rotational_joint():
    spec = _two_bodies()
    spec.add(dd.Spherical("s", "ma", "mb"))
    spec.add(dd.JointDriver("d", "s", 1.0))
    with pytest.raises(ModelError, match="JointDriver 'd': joint 's' is a Spherical"):
        dd.compile_model(spec)
    spec = _two_bodies()
    spec.add(dd.JointDriver("d", "missing", 1.0))
    with pytest.raises(ModelError, match="JointDriver 'd': unknown joint 'missing'"):
        dd.compile_model(spec)


def test_load_on_ground_and_bad_parameters():
    spec = _two_bodies()
    spec.add_marker("g", "ground")
    spec.add(dd.Force("f", "g", (1.0, 0.0, 0.0)))
    with pytest.raises(ModelError, match="Force 'f': marker 'g' is on the ground"):
        dd.compile_model(spec)
    spec = _two_bodies()
    spec.add(dd.SpringDamper("s", "ma", "mb", stiffness=-5.0))
    with pytest.raises(ModelError, match=r"SpringDamper 's'.stiffness: must be >= 0 N/m, got -5.0"):
        dd.compile_model(spec)
    spec = _two_bodies()
    spec.add(dd.Hinge("h", "ma", "mb", k=-1.0))
    with pytest.raises(ModelError, match=r"Hinge 'h'.k: must be > 0 N/m or N m/rad, got -1.0"):
        dd.compile_model(spec)


def test_bad_rotation_and_vectors():
    spec = dd.Spec()
    with pytest.raises(ModelError, match="not a proper rotation"):
        spec.add_rigid_body("b", 1.0, [1, 1, 1], rotation=np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(ModelError, match=r"rigid body 'c'.position: expected 3 finite numbers"):
        spec.add_rigid_body("c", 1.0, [1, 1, 1], position=(0.0, np.nan, 0.0))


def test_node_is_at_centre_of_mass_and_markers_follow():
    """A body with a centre-of-mass offset: the node sits at the centre of mass and the
    initial velocity of the centre of mass is v + omega x (R c)."""
    spec = dd.Spec()
    R = dd.rotations.exp_so3(np.array([0.0, 0.0, np.pi / 2]))
    spec.add_rigid_body("b", 2.0, [1, 1, 1], com=(1.0, 0.0, 0.0), position=(0.0, 0.0, 0.0),
                        rotation=R, velocity=(0.0, 0.0, 1.0), angular_velocity=(0.0, 0.0, 3.0))
    model = dd.compile_model(spec)
    st = model.initial_state()
    np.testing.assert_allclose(st.x[0], [0.0, 1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(st.v[:3], [-3.0, 0.0, 1.0], atol=1e-15)
    np.testing.assert_allclose(st.v[3:6], [0.0, 0.0, 3.0], atol=1e-15)
