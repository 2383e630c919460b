"""The MacPherson strut corner: it builds (bodies, joints, the corner's names, left/right
mirror images, the rack steering both wheels, an anti-roll bar on the lower arms), its
static equilibrium under a wheel load
(rigid and on bushings), its wheel rate, its kinematics against the validation case's loop
closure (left and right), the shipped data set, the RWD vehicle on a MacPherson front, and
bad input. Each test's docstring states the mutation that makes it fail."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from drivedyn.cli import main
from drivedyn.elements import Force
from drivedyn.errors import ModelError
from drivedyn.library.vehicles.suspensions import (
    SHIPPED,
    AntiRollBarFile,
    MacPhersonCorner,
    MacPhersonFile,
    add_anti_roll_bar,
    add_corner,
    add_macpherson,
    add_rack_steering,
    load_suspensions,
    wheel_angles,
)
from drivedyn.library.vehicles.suspensions.geometry import MIRROR
from drivedyn.library.vehicles.suspensions.rig import (
    corner_rig,
    design_point,
    free_length_for_load,
)
from drivedyn.library.vehicles.suspensions.schema import BushingRates, Spring, TopMount
from drivedyn.model import Spec, compile_model
from drivedyn.solver import element_outputs, solve_static
from drivedyn.timefunctions import Table
from drivedyn.validation.suspensions import (
    TRAVEL,
    camber_toe,
    macpherson_loop_closure,
    marker_global,
)

GENERIC = load_suspensions("generic_macpherson")
FRONT = GENERIC.front
#: compliant mounts for the tests (the shipped set has none: Chrono's generic strut is rigid)
ARM_BUSHING = BushingRates(stiffness=(5e6, 5e6, 5e6), rotational_stiffness=(500.0, 500.0, 0.0))
TOP_MOUNT = TopMount(stiffness=(2e6, 2e6, 4e6), rotational_stiffness=(200.0, 200.0, 50.0))


def ground_mount(sp: Spec):
    def mount(name: str, point: np.ndarray) -> str:
        return sp.add_marker(name, "ground", position=point)
    return mount


def compliant(p: MacPhersonFile) -> MacPhersonFile:
    return p.model_copy(update={
        "lower_arm": p.lower_arm.model_copy(update={"bushing": ARM_BUSHING}),
        "top_mount": TOP_MOUNT})


def loaded(p: MacPhersonFile, load: float) -> MacPhersonFile:
    """``p`` with the spring's free length that holds ``load`` [N] at the design position."""
    free = free_length_for_load(p, load)
    return p.model_copy(update={"spring": p.spring.model_copy(update={"free_length": free})})


def test_builds_a_corner_of_four_bodies_with_the_corner_names():
    """A corner on the ground: four bodies (lower arm, upright, strut, tie rod), the joints
    of the strut template (hinge, ball joint, cylindrical joint, universal joint at the top,
    the tie rod's two joints), the hub at the wheel centre with z along the spin axis to the
    left; ``add_corner`` picks this builder by the section's type. Fails if the strut rod
    is left out (three bodies), if the top mount is built as a ball joint, or if
    ``add_corner`` builds a double wishbone from a MacPherson section."""
    sp = Spec()
    c = add_corner(sp, "fl", "left", FRONT, ground_mount(sp), rigid_bushings=True)
    assert isinstance(c, MacPhersonCorner)
    assert sorted(sp.bodies) == ["fl_lower_arm", "fl_strut", "fl_tie_rod", "fl_upright"]
    elements = {e.name: e for e in sp.elements}
    kinds = {role: type(elements[name]).__name__ for role, name in c.joints.items()}
    assert kinds == {"lower_pivot": "Hinge", "lower_ball_joint": "Spherical",
                     "strut_slide": "Cylindrical", "strut_top": "Universal",
                     "tie_rod_outer": "Spherical", "tie_rod_inner": "Universal"}
    assert c.upper_arm is None and c.bushings == ()
    np.testing.assert_allclose(c.wheel_center, FRONT.point("wheel_center"))
    model = compile_model(sp)
    x, R = marker_global(model, model.initial_state(), c.hub)
    np.testing.assert_allclose(x, FRONT.point("wheel_center"), atol=1e-12)
    np.testing.assert_allclose(R[:, 2], [0.0, 1.0, 0.0], atol=1e-12)  # camber, toe 0
    # the strut's frame: z along the strut axis, its centre of mass midway (Chrono's)
    strut = sp.bodies["fl_strut"]
    s = FRONT.point("strut_top") - FRONT.point("strut_lower")
    np.testing.assert_allclose(strut.rotation[:, 2], s / np.linalg.norm(s), atol=1e-12)
    np.testing.assert_allclose(strut.position, FRONT.point("strut_lower") + 0.5 * s,
                               atol=1e-12)
    # with the mounts' rates: three bushings, no hinge, no top universal joint
    sp = Spec()
    c = add_macpherson(sp, "fl", "left", compliant(FRONT), ground_mount(sp))
    assert c.bushings == ("fl_lower_arm_front_bushing", "fl_lower_arm_rear_bushing",
                          "fl_top_mount")
    assert "lower_pivot" not in c.joints and "strut_top" not in c.joints


def two_corners(p: MacPhersonFile, function=0.0) -> tuple[Spec, dict, object]:
    sp = Spec()
    mount = ground_mount(sp)
    rack = add_rack_steering(sp, "steer", GENERIC.steering, mount, function, quantity="travel")
    corners = {s: add_corner(sp, f"f{s[0]}", s, p, mount, steer=rack.marker(s))
               for s in ("left", "right")}
    return sp, corners, rack


def test_left_and_right_corners_are_mirror_images():
    """Both front corners on their bushings and top mounts, on the rack, under equal
    vertical wheel loads: every body of the right corner is at the mirror image of its left
    twin with the mirrored mass distribution, the hub axes are mirror images turned to the
    left, the spring forces equal. Fails if the right corner takes the left's points
    unmirrored or if its strut's inertia is not mirrored."""
    J = [[0.0138, 0.001, -0.002], [0.001, 0.0146, 0.0005], [-0.002, 0.0005, 0.00283]]
    p = compliant(loaded(FRONT, 4000.0))
    p = p.model_copy(update={
        "upright": p.upright.model_copy(update={"inertia": J}),
        "strut": p.strut.model_copy(update={"inertia": [[0.01, 0.001, 0.002],
                                                        [0.001, 0.011, -0.001],
                                                        [0.002, -0.001, 0.005]]})})
    sp, c, _ = two_corners(p)
    for s in ("left", "right"):
        sp.add(Force(f"load_{s}", c[s].hub, vector=(0.0, 0.0, 4500.0), frame="global"))
    model = compile_model(sp)
    st = solve_static(model, max_iter=100)
    for part in ("lower_arm", "upright", "strut", "tie_rod"):
        bl, br = sp.bodies[f"fl_{part}"], sp.bodies[f"fr_{part}"]
        Jl = bl.rotation @ bl.inertia @ bl.rotation.T
        Jr = br.rotation @ br.inertia @ br.rotation.T
        np.testing.assert_allclose(Jr, MIRROR @ Jl @ MIRROR, atol=1e-12)
        il, ir_ = model.node_index[bl.name], model.node_index[br.name]
        np.testing.assert_allclose(st.x[ir_], MIRROR @ st.x[il], atol=1e-9)
    xl, Rl = marker_global(model, st, c["left"].hub)
    xr, Rr = marker_global(model, st, c["right"].hub)
    assert xl[2] - FRONT.point("wheel_center")[2] > 1e-4  # the extra 500 N lifted it
    np.testing.assert_allclose(xr, MIRROR @ xl, atol=1e-9)
    np.testing.assert_allclose(Rr[:, 2], -(MIRROR @ Rl[:, 2]), atol=1e-9)
    out = element_outputs(model, st)
    assert out["fr_spring"]["force"] == pytest.approx(out["fl_spring"]["force"], rel=1e-9)


def test_rack_travel_steers_both_wheels_the_same_way():
    """The rack 10 mm to the left (tie rods behind the wheel centres) steers both wheels
    right, 10 mm to the right steers both left, by similar angles: the upright turns about
    the strut in its tube. Fails if the cylindrical joint is built as a prismatic one (the
    upright cannot turn: the steering locks) or if a right tie rod hangs on the left rack
    joint."""
    p = FRONT.model_copy(update={"spring": Spring(rate=1.5e5, free_length=0.34000528880256387),
                                 "stops": None})
    sp, c, _ = two_corners(p, Table((0.0, 1.0, 2.0), (0.0, 0.01, -0.01)))
    model = compile_model(sp)
    st = model.initial_state()
    steer = {}
    for t in (1.0, 2.0):
        st = solve_static(model, st, t=t)
        steer[t] = {s: wheel_angles(marker_global(model, st, c[s].hub)[1][:, 2], s)[2]
                    for s in ("left", "right")}
    for s in ("left", "right"):
        assert steer[1.0][s] < -0.02 and steer[2.0][s] > 0.02
        assert np.degrees(abs(steer[1.0][s])) < 6.0
    assert 0.75 < steer[1.0]["left"] / steer[1.0]["right"] < 1.33


def test_anti_roll_bar_on_the_lower_arms_resists_roll():
    """An anti-roll bar on the struts' lower arms (rigid pivots, opposite 2 kN loads on the
    wheel centres): the wheels' height difference is smaller with the bar than without it
    and the bar carries a torque. Fails if the bar's drop links are not joined to the
    MacPherson corners' lower arms (the bar then carries nothing)."""
    h = load_suspensions("hmmwv").front.anti_roll_bar
    bar = AntiRollBarFile(rate=1e4, pivot=(-0.35, 0.70, -0.10), lever_end=(-0.10, 0.80, -0.10),
                          drop_link_arm=(-0.10, 0.80, -0.16), half=h.half, drop_link=h.drop_link)
    length = float(np.linalg.norm(FRONT.point("strut_top") - FRONT.point("strut_lower")))
    p = FRONT.model_copy(update={"spring": Spring(rate=1.5e5, free_length=length),
                                 "stops": None, "anti_roll_bar": bar})
    heights = {}
    for with_bar in (False, True):
        sp = Spec()
        mount = ground_mount(sp)
        c = {s: add_corner(sp, f"f{s[0]}", s, p, mount, rigid_bushings=True)
             for s in ("left", "right")}
        if with_bar:
            add_anti_roll_bar(sp, "arb", p, mount, c["left"], c["right"])
        for s, f in (("left", 2.0e3), ("right", -2.0e3)):
            sp.add(Force(f"load_{s}", c[s].hub, vector=(0.0, 0.0, f), frame="global"))
        model = compile_model(sp)
        st = solve_static(model)
        z = {s: marker_global(model, st, c[s].hub)[0][2] for s in ("left", "right")}
        heights[with_bar] = z["left"] - z["right"]
    assert 0.0 < heights[True] < 0.9 * heights[False]
    assert abs(element_outputs(model, st)["arb_torsion"]["torque"]) > 50.0


def test_static_equilibrium_under_a_wheel_load():
    """With the spring's free length from :func:`free_length_for_load` for 4 kN, a 4 kN
    vertical force on the hub holds the free corner (no rig) at its design position; 5 kN
    lifts it by 1 kN over the wheel rate (within its curvature); on bushings and a rubber
    top mount it settles within 1 mm of the rigid corner with the same spring force within
    1 %. At the design position the spring pushes the wheel load over the installation
    ratio (virtual work). Fails if the spring acts on the strut rod instead of the upright
    (no wheel rate: the corner falls through), or if its deflection takes the wrong sign."""
    p = loaded(FRONT, 4000.0)
    dp = design_point(p)
    assert dp.wheel_load == pytest.approx(4000.0, rel=1e-7)
    assert dp.spring_force == pytest.approx(-4000.0 / dp.installation_ratio, rel=1e-7)
    wc0 = FRONT.point("wheel_center")
    result = {}
    for what, q in (("rigid", p), ("bushings", compliant(p))):
        for load in (4000.0, 5000.0):
            sp = Spec()
            c = add_macpherson(sp, "fl", "left", q, ground_mount(sp),
                               rigid_bushings=(what == "rigid"))
            sp.add(Force("load", c.hub, vector=(0.0, 0.0, load), frame="global"))
            model = compile_model(sp)
            st = solve_static(model, max_iter=100)
            result[what, load] = (marker_global(model, st, c.hub)[0],
                                  element_outputs(model, st)[c.spring]["force"])
    np.testing.assert_allclose(result["rigid", 4000.0][0], wc0, atol=1e-9)
    rise = result["rigid", 5000.0][0][2] - wc0[2]
    assert rise == pytest.approx(1000.0 / dp.wheel_rate, rel=0.02)
    for load in (4000.0, 5000.0):
        x_r, f_r = result["rigid", load]
        x_b, f_b = result["bushings", load]
        assert 1e-6 < np.linalg.norm(x_b - x_r) < 1e-3  # the rubber gives a little
        assert f_b == pytest.approx(f_r, rel=0.01)


def test_wheel_rate_is_spring_rate_times_installation_ratio_squared():
    """With a linear spring free at the design position, the rig's vertical force per wheel
    travel is ``k IR^2``; the strut stands nearly along the wheel's path, so the ratio is
    0.92. Fails if the spring is hung on the strut rod (its length then never changes: ratio
    0) or between the wrong points."""
    k = 1.5e5
    length = float(np.linalg.norm(FRONT.point("strut_top") - FRONT.point("strut_lower")))
    p = FRONT.model_copy(update={"spring": Spring(rate=k, free_length=length), "stops": None})
    dp = design_point(p)
    assert dp.wheel_load == pytest.approx(0.0, abs=1e-6)
    assert 0.91 < dp.installation_ratio < 0.93
    assert dp.wheel_rate == pytest.approx(k * dp.installation_ratio ** 2, rel=1e-6)


@pytest.mark.parametrize("side", ["left", "right"])
def test_kinematics_against_the_loop_closure(side):
    """Camber, toe and the wheel centre over +-60 mm of wheel travel on the rig (rigid
    pivots, the rack held) equal the validation case's loop closure within 1e-9, on the
    left and (mirrored) on the right. Fails if the strut's cylindrical joint is not on the
    strut axis, if the top mount's joint is not at ``strut_top``, or if the right corner's
    strut frame is not mirrored."""
    travel = Table((0.0, 1.0, 3.0), (0.0, -TRAVEL, TRAVEL))
    model, c = corner_rig(FRONT, travel, side=side)
    st = model.initial_state()
    wc, ax = [], []
    for t in np.linspace(0.0, 3.0, 13):
        st = solve_static(model, st, t=float(t))
        x, R = marker_global(model, st, c.hub)
        wc.append(x)
        ax.append(R[:, 2])
    wc, ax = np.array(wc), np.array(ax)
    if side == "right":  # seen as a left corner
        wc = wc @ MIRROR
        ax = -(ax @ MIRROR)
    ref = macpherson_loop_closure(FRONT, wc[:, 2] - FRONT.point("wheel_center")[2])
    assert np.ptp(wc[:, 2]) == pytest.approx(2 * TRAVEL, abs=1e-12)
    np.testing.assert_allclose(wc, ref.wheel_center, atol=1e-9)
    cs, ts = camber_toe(ax)
    cr, tr = camber_toe(ref.axis)
    np.testing.assert_allclose(cs, cr, atol=1e-9)
    np.testing.assert_allclose(ts, tr, atol=1e-9)
    assert np.degrees(np.ptp(cs)) > 1.5 and np.degrees(np.ptp(ts)) > 3.5  # a real motion


def test_validation_case_passes():
    """``drivedyn validate --case macpherson_kinematics --quick``: every check passes, each
    with its reference stated. Fails if the case's rig or its loop closure drifts from the
    corner."""
    from drivedyn.validation import CASES

    results = CASES["macpherson_kinematics"](quick=True)
    assert len(results) == 5
    for r in results:
        assert r.passed, f"{r.quantity}: error {r.error:.3g} > {r.tolerance:.3g}"
        assert r.source


def test_shipped_set_is_chronos_generic_strut():
    """The shipped set reads as two MacPherson axles at the generic vehicle's places
    ([VEH.json]: 1.25 m either side, 0.21 m down) with Chrono's numbers, the rack's joints
    at the front tie rods' inner points. Fails if a hardpoint is copied wrong or the
    steering does not assemble with the front struts."""
    assert isinstance(GENERIC.front, MacPhersonFile) and isinstance(GENERIC.rear, MacPhersonFile)
    np.testing.assert_allclose(GENERIC.front.location, [1.25, 0.0, -0.21])
    np.testing.assert_allclose(GENERIC.rear.location, [-1.25, 0.0, -0.21])
    np.testing.assert_allclose(FRONT.hardpoints.strut_top, [-0.115, 0.785, 0.579])
    np.testing.assert_allclose(FRONT.hardpoints.lower_ball_joint,
                               [-0.02165371, 0.94057703, -0.17402826])
    assert FRONT.spring.rate == 369149.0 and FRONT.spring.free_length == 0.306
    assert FRONT.damper.rebound == FRONT.damper.compression == 22459.0
    assert FRONT.top_mount is None and FRONT.lower_arm.bushing is None
    np.testing.assert_allclose(GENERIC.steering.point("left"), FRONT.point("tie_rod_inner"),
                               atol=1e-12)
    _, c, _ = two_corners(FRONT)  # assembles with the rack
    assert c["left"].spring_markers[0] == "fl_strut_top_axis"


def vehicle_file(tmp_path: Path, strut_top_z: str = "0.579 m") -> Path:
    """A suspension set for the RWD vehicle: the generic MacPherson front at the HMMWV's
    front axle with its rack, the HMMWV's rear."""
    g = SHIPPED["generic_macpherson"].read_text()
    h = SHIPPED["hmmwv"].read_text()
    here = 'location = ["1.25 m", 0.0, "-0.21 m"]'
    front = g[g.index("[front]"):g.index("# The rear:")].replace(
        here, 'location = ["1.688965 m", 0.0, 0.0]').replace(
        'strut_top = ["-0.115 m", "0.785 m", "0.579 m"]',
        f'strut_top = ["-0.115 m", "0.785 m", "{strut_top_z}"]')
    rear = h[h.index("[rear]"):h.index("[steering]")]
    steering = g[g.index("[steering]"):].replace(here, 'location = ["1.688965 m", 0.0, 0.0]')
    f = tmp_path / "mixed.toml"
    f.write_text('[info]\nname = "mixed"\n\n' + front + rear + steering)
    return f


def test_rwd_vehicle_on_a_macpherson_front(tmp_path):
    """``drivedyn vehicle vehicle-rwd --scenario static --set suspensions=<file>`` with a
    MacPherson front and the HMMWV's double-wishbone rear: the vehicle builds each axle by
    its type and its static checks pass (the tyre loads sum to m g). Fails if the vehicle
    builds every corner as a double wishbone (a MacPherson section has no upper arm)."""
    f = vehicle_file(tmp_path)
    r = CliRunner().invoke(main, ["vehicle", "vehicle-rwd", "--scenario", "static",
                                  "--compare", "open", "--json", "--set", f"suspensions={f}"])
    assert r.exit_code == 0, r.output
    run = json.loads(r.stdout)["runs"][0]
    assert all(c["passed"] for c in run["checks"])
    assert np.isclose(sum(run["loads"].values()), run["mass"] * 9.81, rtol=1e-6)


def test_bad_input_names_the_key_and_value(tmp_path):
    """A zero-length lower arm, a strut top below the ball joint, a tie-rod joint on the
    steering axis, a spring longer than its rebound stop allows, a top mount without a rate
    about the strut axis and an unknown suspension type: a ModelError naming the key and
    the value; through the command line, exit 2 with the vehicle's key. Fails if any of
    them is accepted."""
    hp = FRONT.hardpoints

    def build(**points) -> None:
        p = FRONT.model_copy(update={"hardpoints": hp.model_copy(update=points)})
        sp = Spec()
        add_macpherson(sp, "fl", "left", p, ground_mount(sp))

    with pytest.raises(ModelError, match=r"hardpoints\.lower_arm_front = \[0\.22, 0\.52, "
                                         r"-0\.156\] m .* lower arm pivot axis of length 0"):
        build(lower_arm_rear=hp.lower_arm_front)
    with pytest.raises(ModelError, match=r"hardpoints\.strut_top = \[-0\.115, 0\.785, -0\.2\] "
                                         r"m is not above hardpoints\.lower_ball_joint"):
        build(strut_top=(-0.115, 0.785, -0.2))
    on_axis = np.add(hp.lower_ball_joint, 0.3 * np.subtract(hp.strut_top, hp.lower_ball_joint))
    with pytest.raises(ModelError, match=r"hardpoints\.tie_rod_outer = .* on the steering axis"):
        build(tie_rod_outer=tuple(on_axis))
    stops = FRONT.stops.model_copy(update={"rebound_length": 0.3})
    sp = Spec()
    with pytest.raises(ModelError, match=r"stops\.rebound_length: 0\.3 m is not above .*0\.34"):
        add_macpherson(sp, "fl", "left", FRONT.model_copy(update={"stops": stops}),
                       ground_mount(sp))
    text = SHIPPED["generic_macpherson"].read_text()
    mount = '[front.top_mount]\nstiffness = [1e6, 1e6, 1e6]\nrotational_stiffness = [10, 10, 0]\n'
    for old, new, key, value in (
            ('[rear]\ntype = "macpherson"', '[rear]\ntype = "multi_link"', "rear.type",
             "'multi_link'"),
            ("[front.strut]\n", mount + "[front.strut]\n",
             "front.top_mount.rotational_stiffness", "[10, 10, 0]")):
        f = tmp_path / "bad.toml"
        f.write_text(text.replace(old, new, 1))
        with pytest.raises(ModelError, match=re.escape(key)) as err:
            load_suspensions(f)
        assert value in str(err.value)
    # the command line: exit 2, the message names the key as the vehicle's user gives it
    f = vehicle_file(tmp_path, strut_top_z="-0.3 m")
    r = CliRunner().invoke(main, ["vehicle", "vehicle-rwd", "--scenario", "static",
                                  "--set", f"suspensions={f}"])
    assert r.exit_code == 2, r.output
    assert "front.hardpoints.strut_top = [-0.115, 0.785, -0.3] m is not above" in r.output
    r = CliRunner().invoke(main, ["vehicle", "vehicle-rwd", "--scenario", "static",
                                  "--set", f"suspensions={f}",
                                  "--set", 'suspension_overrides.rear.type="multi_link"'])
    assert r.exit_code == 2, r.output
    assert "suspension_overrides.rear.type" in r.output and "multi_link" in r.output
