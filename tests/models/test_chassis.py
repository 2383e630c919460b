"""The ladder frame (:mod:`drivedyn.library.vehicles.chassis`): the body it carries (mass,
centre of gravity, inertia), its own mass, the torsion test (closed form, mesh convergence,
declared sections), a rail as a cantilever, the mount markers, the drawn radius and the
refusals of bad input. Each test's docstring names a mistake that would make it fail."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

from drivedyn.elements import Fixed, Force, Spherical
from drivedyn.elements.beams.section import HollowRectangular
from drivedyn.errors import ModelError
from drivedyn.library.vehicles.chassis import (
    DeclaredSection,
    LadderFrameFile,
    StiffnessSection,
    add_ladder_frame,
    mass_properties,
    rectangle_frame,
    rectangle_frame_stiffness,
    torsion_test,
    torsional_stiffness,
)
from drivedyn.model.compile import compile_model
from drivedyn.model.spec import GROUND, Spec
from drivedyn.results.scene import scene_description
from drivedyn.solver import solve_static
from drivedyn.solver.system import element_outputs

ORIGIN = np.array([-1.2, 0.3, 0.45])


def _meshed(p: LadderFrameFile, n: int) -> LadderFrameFile:
    return p.model_copy(update={"mesh": p.mesh.model_copy(update={"elements_per_segment": n})})


def _props(p: LadderFrameFile, carry_body: bool):
    sp = Spec(gravity=(0.0, 0.0, -9.81))
    frame = add_ladder_frame(sp, "frame", p, origin=ORIGIN, carry_body=carry_body)
    return frame, mass_properties(compile_model(sp))


def _shift(m: float, c: np.ndarray, to: np.ndarray) -> np.ndarray:
    """Parallel-axis term of a mass ``m`` at ``c`` about the point ``to``."""
    d = c - to
    return m * (d @ d * np.eye(3) - np.outer(d, d))


def test_carried_body_has_the_declared_mass_cg_and_inertia():
    """The carriers reproduce the body exactly: mass, the three coordinates of its centre of
    gravity (its height too) and all six components of its inertia tensor about it, read
    from the compiled model's mass matrix (frame with body minus bare frame). Fails if the
    carriers sat on the rail nodes (height lost), if the left/right split ignored ``cg[1]``,
    or if they carried no share of the left-over inertia."""
    data = LadderFrameFile().model_dump()
    inertia = [[360.0, 0.0, -45.0], [0.0, 1700.0, 0.0], [-45.0, 0.0, 1850.0]]
    data["body"].update(mass=950.0, cg=[2.1, 0.06, 0.42], inertia=inertia)
    p = LadderFrameFile.model_validate(data)
    _, a = _props(p, carry_body=False)
    frame, b = _props(p, carry_body=True)
    assert len(frame.carriers) == 2 * len(p.body.mounts)
    mb = b.mass - a.mass
    cb = (b.mass * b.cg - a.mass * a.cg) / mb
    Ib = b.inertia + _shift(b.mass, b.cg, cb) - a.inertia - _shift(a.mass, a.cg, cb)
    assert mb == pytest.approx(950.0, rel=1e-12)
    assert frame.body_mass == pytest.approx(950.0, rel=1e-12)
    np.testing.assert_allclose(cb, ORIGIN + np.array([2.1, 0.06, 0.42]), atol=1e-12)
    np.testing.assert_allclose(Ib, inertia, atol=1e-9 * 1850.0)


def test_frame_and_body_weigh_on_four_supports_as_one_body():
    """Frame and body under gravity on ball joints at four rail points (at the axles): the
    vertical reactions add up to the total weight, and their front share to the moment of
    the weight about the rear supports, at the centre of gravity of :func:`mass_properties`.
    Fails if the carriers' weight did not reach the rails (a carrier left unfixed would fall)
    or entered them at the wrong station."""
    p = LadderFrameFile()
    sp = Spec(gravity=(0.0, 0.0, -9.81))
    fr = add_ladder_frame(sp, "frame", p, origin=ORIGIN)
    axles = {"rl": (0.8, 0.45), "rr": (0.8, -0.45), "fl": (3.6, 0.45), "fr": (3.6, -0.45)}
    for label, (x, y) in axles.items():
        point = ORIGIN + np.array([x, y, 0.0])
        marker = fr.mount(label, point, max_offset=1e-9)
        sp.add_marker(f"{label}.ground", GROUND, position=point)
        sp.add(Spherical(f"{label}.support", f"{label}.ground", marker))
    model = compile_model(sp)
    props = mass_properties(model)
    out = element_outputs(model, solve_static(model))
    Fz = {label: out[f"{label}.support"]["force_z"] for label in axles}
    weight = (fr.beam_mass + fr.body_mass) * 9.81
    assert props.mass == pytest.approx(fr.beam_mass + fr.body_mass, rel=1e-12)
    assert sum(Fz.values()) == pytest.approx(weight, rel=1e-9)
    x_cg = props.cg[0] - ORIGIN[0]
    # the sag under the weight tilts the carriers (0.35 m up) by a fraction of a mrad
    assert (Fz["fl"] + Fz["fr"]) * 2.8 == pytest.approx(weight * (x_cg - 0.8), rel=1e-4)
    assert Fz["fl"] == pytest.approx(Fz["fr"], rel=1e-9)


def test_bare_frame_mass_and_inertia_of_its_members():
    """The bare frame weighs the members' ``rho A`` times their lengths (2 rails, the cross
    members over the track), its centre of mass is theirs, and its inertia (lumped masses
    plus section rotary inertia, 8 elements per segment) is within 0.3 % of the continuous
    members'. Fails if a cross member were meshed over half the track or the rails' mass
    per length used the cross members' section."""
    p = _meshed(LadderFrameFile(), 8)
    frame, a = _props(p, carry_body=False)
    mat = p.material.material()
    L, b = p.rails.length, p.rails.track
    members = [(p.rails.section, np.array([0.0, y, 0.0]), np.array([L, y, 0.0]))
               for y in (0.5 * b, -0.5 * b)]
    members += [(c.section, np.array([c.x, -0.5 * b, 0.0]), np.array([c.x, 0.5 * b, 0.0]))
                for c in p.cross_members]
    parts = []
    for sec, s, e in members:
        prop = sec.beam_section(mat).properties(mat)
        length = float(np.linalg.norm(e - s))
        ex = (e - s) / length
        m = prop.mass_per_length * length
        # rod about its centre + the section's rotary inertia (x along the member, z up)
        Rs = np.column_stack([ex, np.cross([0.0, 0.0, 1.0], ex), [0.0, 0.0, 1.0]])
        J = m * length**2 / 12.0 * (np.eye(3) - np.outer(ex, ex))
        J += Rs @ np.diag(prop.rotary_inertia * length) @ Rs.T
        parts.append((m, ORIGIN + 0.5 * (s + e), J))
    M = sum(q[0] for q in parts)
    C = sum(q[0] * q[1] for q in parts) / M
    I_ref = sum(q[2] + _shift(q[0], q[1], C) for q in parts)
    assert a.mass == pytest.approx(M, rel=1e-12)
    assert frame.beam_mass == pytest.approx(M, rel=1e-12)
    np.testing.assert_allclose(a.cg, C, atol=1e-12)
    np.testing.assert_allclose(np.diag(a.inertia), np.diag(I_ref), rtol=3e-3)


def test_rectangular_frame_matches_the_closed_form():
    """The rectangular frame's stiffness converges at second order to the least-work closed
    form: the Richardson extrapolation of 4 and 8 elements per segment agrees within 1e-5
    (a small torque keeps the response linear). Fails if the closed form lost its shear
    terms, if the torsion and bending stiffnesses of the sections were swapped, or if the
    corners were not rigid (a cross member not sharing the rail nodes)."""
    rect = rectangle_frame(LadderFrameFile())
    exact = rectangle_frame_stiffness(rect)
    k4, k8 = (torsion_test(_meshed(rect, n), torque=10.0).stiffness for n in (4, 8))
    assert (4.0 * k8 - k4) / 3.0 == pytest.approx(exact, rel=1e-5)
    assert abs(k8 / exact - 1.0) < 0.25 * abs(k4 / exact - 1.0) * 1.05


def test_torsional_stiffness_converges_with_the_mesh():
    """The default frame's torsional stiffness at 1, 2, 4, 8 elements per segment: the
    differences shrink about fourfold per halving (second order), the default mesh is within
    0.5 % of the finest, and the centre-line support carries no force. Fails if the default
    mesh were coarsened to one element per segment (1.5 % off the converged value), if an
    element locked as it got shorter (the differences would stop shrinking fourfold), or if
    the two front forces were not equal and opposite (the centre support would take their
    sum)."""
    p = LadderFrameFile()
    tests = [torsion_test(_meshed(p, n)) for n in (1, 2, 4, 8)]
    k = np.array([t.stiffness for t in tests])
    d = np.abs(np.diff(k))
    order = np.log2(d[:-1] / d[1:])
    assert np.all(order > 1.7), order
    assert abs(torsional_stiffness(p) / k[-1] - 1.0) < 5e-3
    for t in tests:
        assert abs(t.centre_reaction) < 1e-9 * t.torque / p.rails.track
    assert 1000.0 < k[-1] < 3000.0  # the defaults' ladder frame: about 1.6 kN m/deg


def test_declared_and_stiffness_sections_are_the_box_they_declare():
    """A ``declared`` section holding the box rail's area, second moments, torsion constant
    and shear areas, and a ``stiffness`` section holding its stiffnesses, give the frame the
    box's torsional stiffness, and the ``declared`` one its mass too. Fails if the vertical
    and lateral values were mapped to the wrong section axes (I_vertical on the lateral
    axis, the shear areas swapped) or the declared section took E where G belongs."""
    p = LadderFrameFile()
    mat = p.material.material()
    box = p.rails.section
    props = box.beam_section(mat).properties(mat)
    k = props.stiffness  # EA, GA_y, GA_z, GJ, EI_y, EI_z (z vertical)
    declared = DeclaredSection(
        shape="declared", area=k[0] / mat.E, I_vertical=k[4] / mat.E, I_lateral=k[5] / mat.E,
        J=k[3] / mat.G, shear_area_vertical=k[2] / mat.G, shear_area_lateral=k[1] / mat.G,
        width=box.width, height=box.height)
    stiff = StiffnessSection(shape="stiffness", EA=k[0], GA_lateral=k[1], GA_vertical=k[2],
                             GJ=k[3], EI_vertical=k[4], EI_lateral=k[5],
                             mass_per_length=props.mass_per_length)
    ref = torsional_stiffness(p)
    for sec in (declared, stiff):
        q = p.model_copy(update={"rails": p.rails.model_copy(update={"section": sec})})
        assert torsional_stiffness(q) == pytest.approx(ref, rel=1e-9)
    q = p.model_copy(update={"rails": p.rails.model_copy(update={"section": declared})})
    _, a = _props(p, carry_body=False)
    _, b = _props(q, carry_body=False)
    assert b.mass == pytest.approx(a.mass, rel=1e-12)
    np.testing.assert_allclose(b.inertia, a.inertia, rtol=1e-12, atol=1e-12)


def test_sections_from_tables_with_units():
    """Model-file tables: a ``declared`` rail section in cm^2 / cm^4, a cross member's partial
    box table (only its wall) completed from the default box. Fails if the default box's
    keys were merged into a table of another shape (``wall`` refused as an extra key of the
    declared section) or a partial box table were refused."""
    declared = {"shape": "declared", "area": "14 cm^2", "I_vertical": "200 cm^4",
                "I_lateral": "50 cm^4", "J": "60 cm^4", "shear_area_vertical": "9 cm^2",
                "shear_area_lateral": "3 cm^2", "width": "60 mm", "height": "140 mm"}
    p = LadderFrameFile.model_validate({
        "rails": {"length": "4 m", "section": declared},
        "cross_members": [{"x": 0}, {"x": "2 m", "section": {"wall": "2 mm"}}, {"x": "4 m"}],
        "body": {"mounts": ["1 m", "3 m"]}})
    sec = p.rails.section
    assert isinstance(sec, DeclaredSection)
    assert (sec.area, sec.I_vertical, sec.J) == pytest.approx((14e-4, 200e-8, 60e-8))
    box = p.cross_members[1].section
    assert (box.shape, box.width, box.height, box.wall) == ("box", 0.07, 0.07, 0.002)
    assert p.cross_members[0].section.wall == 0.003
    assert torsional_stiffness(p) > 0.0


def test_cantilevered_rail_tip_deflection_matches_timoshenko():
    """Both rails clamped at their rear ends (a single cross member there, held at both ends,
    carries nothing), a vertical and a lateral tip load on each: the tip deflections are
    Timoshenko's ``P L^3 / (3 EI) + P L / (k G A)`` with the box's vertical and lateral
    stiffnesses, within 0.2 % with 16 elements (the element's bending error is ``1/(4 n^2)``
    of the bending part; shear adds 0.15 % to Euler-Bernoulli on this slender rail). Fails
    if the rail sections were turned (height across the frame) or the wall thickness
    ignored."""
    data = LadderFrameFile().model_dump()
    data.update(cross_members=[{"x": 0.0}], body=None, mesh={"elements_per_segment": 16})
    p = LadderFrameFile.model_validate(data)
    sp = Spec()
    fr = add_ladder_frame(sp, "frame", p)
    Pz, Py = 400.0, 150.0
    for side in ("left", "right"):
        nodes = getattr(fr, side)
        sp.add_marker(f"{side}.wall", GROUND, position=sp.nodes[nodes[0]].position)
        sp.add_marker(f"{side}.root", nodes[0])
        sp.add(Fixed(f"{side}.clamp", f"{side}.wall", f"{side}.root"))
        sp.add_marker(f"{side}.tip", nodes[-1])
        sp.add(Force(f"{side}.load", f"{side}.tip", (0.0, Py, Pz)))
    model = compile_model(sp)
    st = solve_static(model)
    i = model.node_index[fr.left[-1]]
    u = st.x[i] - model.state0.x[i]
    mat = p.material.material()
    _, GAy, GAz, _, EIy, EIz = HollowRectangular(0.06, 0.14, 0.0035).properties(mat).stiffness
    L = p.rails.length
    w_ref = Pz * L**3 / (3.0 * EIy) + Pz * L / GAz
    v_ref = Py * L**3 / (3.0 * EIz) + Py * L / GAy
    assert u[2] == pytest.approx(w_ref, rel=2e-3)
    assert u[1] == pytest.approx(v_ref, rel=2e-3)


def test_mount_markers_land_at_the_asked_points():
    """``Frame.mount`` puts a marker at the global point with the global axes, on the
    nearest frame node (a rail node for an outboard pick-up, a cross member's inner node for
    a point above it), and refuses a point beyond ``max_offset``. Fails if the offset were
    not expressed in the node's frame (the cross members' inner nodes are turned) or the
    nearest node were searched on the rails only."""
    p = LadderFrameFile()
    sp = Spec()
    fr = add_ladder_frame(sp, "frame", p, origin=ORIGIN)
    R_tilt = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    points = {
        "front_upper_left": (ORIGIN + np.array([3.55, 0.72, 0.25]), None),
        "rear_spring_right": (ORIGIN + np.array([0.75, -0.48, -0.05]), None),
        "diff_mount": (ORIGIN + np.array([1.2, 0.1, 0.08]), R_tilt),
    }
    for name, (pt, R) in points.items():
        assert fr.mount(name, pt, rotation=R) == name
    assert sp.markers["diff_mount"].body.startswith("frame.cross2.")
    assert sp.markers["front_upper_left"].body.startswith("frame.left.")
    assert sp.markers["rear_spring_right"].body.startswith("frame.right.")
    model = compile_model(sp)
    st = model.initial_state()
    for name, (pt, R) in points.items():
        node, offset, rot = model.marker_frames[name]
        np.testing.assert_allclose(st.x[node] + st.R[node] @ offset, pt, atol=1e-12)
        np.testing.assert_allclose(st.R[node] @ rot, np.eye(3) if R is None else R,
                                   atol=1e-12)
    with pytest.raises(ModelError, match=r"mount 'far'.*max_offset = 0.1 m"):
        fr.mount("far", ORIGIN + np.array([2.0, 1.5, 0.0]), max_offset=0.1)


def test_box_sections_draw_as_tubes_of_half_their_larger_side():
    """The 3-D viewer draws each member as a tube of half its section's larger outer side
    (rails 140 mm deep: 70 mm; cross members 70 mm square: 35 mm). Fails if the box section
    lost its ``width_y``/``height_z`` names (the viewer would fall back to a default)."""
    sp = Spec()
    add_ladder_frame(sp, "frame", LadderFrameFile(), carry_body=False)
    radius = {b["element"]: b["radius"] for b in scene_description(compile_model(sp))["beams"]}
    assert radius["frame.left.e0"] == pytest.approx(0.07)
    assert radius["frame.cross0.e0"] == pytest.approx(0.035)


def _with(path: str, value) -> dict:
    data = LadderFrameFile().model_dump()
    *keys, last = path.split(".")
    d = data
    for k in keys:
        d = d[int(k)] if isinstance(d, list) else d[k]
    d[last] = value
    return data


@pytest.mark.parametrize(("path", "value", "message"), [
    ("rails.section.width", 0.0, r"rails\.section\.box\.width\n.*must be > 0 m.*input_value=0\.0"),
    ("rails.section.wall", 0.04, r"wall = 0\.04 m: must be less than half"),
    ("rails.section.shape", "channel", r"expected shape 'box', 'declared' or 'stiffness'"),
    ("cross_members.1.x", 5.0, r"cross_members\[1\]\.x = 5 m lies outside the rails"),
    ("cross_members.1.x", -0.2, r"cross_members\[1\]\.x = -0\.2 m lies outside the rails"),
    ("mesh.elements_per_segment", 0, r"mesh\.elements_per_segment\n.*greater than or equal "
                                     r"to 1.*input_value=0"),
    ("body.mounts", [1.0], r"body\.mounts = \[1\.0\]: expected at least two"),
    ("material.E", "-210 GPa", r"material\.E\n.*must be > 0 Pa"),
    ("rails.section", {"shape": "declared", "area": "14 cm^2", "I_vertical": "-1 cm^4",
                       "I_lateral": "50 cm^4", "J": "60 cm^4", "shear_area_vertical": "9 cm^2",
                       "shear_area_lateral": "3 cm^2"},
     r"rails\.section\.declared\.I_vertical\n.*must be > 0 m\^4"),
])
def test_bad_input_is_refused_naming_the_key_and_value(path, value, message):
    """Non-positive or inconsistent section dimensions, a cross member off the rails, a mesh
    of no elements, a body on one mount station and a negative modulus are refused by the
    schema with the key and the value. Fails if a check were dropped or its message lost
    the key (a bare "must be > 0")."""
    with pytest.raises(ValidationError, match=message):
        LadderFrameFile.model_validate(_with(path, value))


@pytest.mark.parametrize(("path", "value", "message"), [
    ("body.cg", [4.3, 0.0, 0.35], r"body\.cg\[0\] = 4\.3 m lies too far .* x = 0\.8 m"),
    ("body.inertia", [150.0, 160.0, 200.0], r"body\.inertia: the mounts spread the mass"),
])
def test_bodies_the_mounts_cannot_carry_are_refused(path, value, message):
    """A centre of gravity so far forward that the rear mounts would carry a negative mass,
    and a body narrower (in roll inertia) than the rails are apart, are refused when the
    frame is built, naming the key. Fails if negative carrier masses or an inertia left over
    that is not one were let through to the rigid bodies."""
    p = LadderFrameFile.model_validate(_with(path, value))
    with pytest.raises(ModelError, match=message):
        add_ladder_frame(Spec(), "frame", p)


def test_box_section_refusals_name_the_field():
    """``HollowRectangular`` refuses a wall of half the smaller side or more and
    non-positive dimensions, naming the field."""
    with pytest.raises(ModelError, match=r"section\.thickness: must be < half .* got 0\.03"):
        HollowRectangular(0.05, 0.1, 0.03)
    with pytest.raises(ModelError, match=r"section\.height_z: must be > 0 m, got -0\.1"):
        HollowRectangular(0.05, -0.1, 0.003)


def test_torsion_test_refuses_a_frame_it_cannot_hold():
    """A frame whose only cross member is at the rear end leaves no centre-line support off
    the rear axle line (the frame could pitch): refused, as is a non-positive torque."""
    data = LadderFrameFile().model_dump()
    data.update(cross_members=[{"x": 0.0}], body=None)
    p = LadderFrameFile.model_validate(data)
    with pytest.raises(ModelError, match="needs a cross member ahead"):
        torsion_test(p)
    with pytest.raises(ModelError, match="torque: must be > 0"):
        torsion_test(LadderFrameFile(), torque=-1.0)
    assert math.isfinite(torsional_stiffness(LadderFrameFile(), torque=50.0))


def test_validation_case_chassis_torsion_passes():
    """``drivedyn validate --case chassis_torsion --quick``: the closed form and the 4x mesh
    agree within 2 % (observed 0.8 % and 0.3 %). Fails if the default mesh or sections
    drifted far from the ones the case was written for."""
    from drivedyn.validation import CASES

    results = CASES["chassis_torsion"](quick=True)
    assert len(results) == 2
    for r in results:
        assert r.passed, f"{r.quantity}: {r.simulated} vs {r.reference} ({r.error:.3g})"
        assert r.error < 0.01
