"""The suspension and steering library: the double wishbone's kinematics against a
loop-closure solution written here, its static wheel rate, left/right mirror symmetry,
the rack's steering sign, the shipped data set's provenance and bad input."""

from __future__ import annotations

import re

import numpy as np
import pytest

from drivedyn.elements import Force
from drivedyn.errors import ModelError
from drivedyn.library.vehicles.suspensions import (
    SHIPPED,
    DoubleWishboneFile,
    add_anti_roll_bar,
    add_double_wishbone,
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
from drivedyn.library.vehicles.suspensions.schema import Spring
from drivedyn.model import Spec, compile_model
from drivedyn.solver import element_outputs, solve_static
from drivedyn.timefunctions import Ramp, SmoothStep, Table
from drivedyn.validation.suspensions import marker_global, simulated_sweep

HMMWV = load_suspensions("hmmwv")


def rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' rotation about the unit ``axis`` by ``angle``."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]],
                  [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * k @ k


def aligning(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The smallest rotation taking the unit vector ``a`` to the unit vector ``b``."""
    c = np.cross(a, b)
    s = np.linalg.norm(c)
    if s < 1e-15:
        return np.eye(3)
    return rotation(c / s, np.arctan2(s, a @ b))


class AngleLoop:
    """The left corner's loop closure in three angles: the upper and lower arms' rotations
    about their pivot axes and the knuckle's rotation about its kingpin axis (the line of
    its ball joints). Equations: the knuckle's ball-joint distance, the tie rod's length,
    the wheel centre's height. A formulation of its own, independent of the library's
    bodies and joints and of the validation case's nine-coordinate one."""

    def __init__(self, p: DoubleWishboneFile) -> None:
        self.h = {k: p.point(k) for k in type(p.hardpoints).model_fields}
        h = self.h
        self.au = (h["upper_arm_front"] - h["upper_arm_rear"])
        self.au /= np.linalg.norm(self.au)
        self.al = (h["lower_arm_front"] - h["lower_arm_rear"])
        self.al /= np.linalg.norm(self.al)
        self.kp = np.linalg.norm(h["upper_ball_joint"] - h["lower_ball_joint"])
        self.tr = np.linalg.norm(h["tie_rod_outer"] - h["tie_rod_inner"])
        self.axis0 = np.array([np.cos(p.camber) * np.sin(p.toe),
                               np.cos(p.camber) * np.cos(p.toe), -np.sin(p.camber)])
        self.x = np.zeros(3)

    def pose(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Knuckle rotation (3, 3), lower ball joint and lower arm rotation at angles ``x``."""
        h = self.h
        Ru = rotation(self.au, x[0])
        Rl = rotation(self.al, x[1])
        U = h["upper_arm_rear"] + Ru @ (h["upper_ball_joint"] - h["upper_arm_rear"])
        L = h["lower_arm_rear"] + Rl @ (h["lower_ball_joint"] - h["lower_arm_rear"])
        k0 = h["upper_ball_joint"] - h["lower_ball_joint"]
        k = (U - L) / np.linalg.norm(U - L)
        Rk = rotation(k, x[2]) @ aligning(k0 / np.linalg.norm(k0), k)
        return Rk, L, Rl

    def residual(self, x: np.ndarray, dz: float) -> np.ndarray:
        h = self.h
        Rk, L, _ = self.pose(x)
        U = h["upper_arm_rear"] + rotation(self.au, x[0]) @ (h["upper_ball_joint"]
                                                            - h["upper_arm_rear"])
        T = L + Rk @ (h["tie_rod_outer"] - h["lower_ball_joint"])
        W = L + Rk @ (h["wheel_center"] - h["lower_ball_joint"])
        return np.array([np.linalg.norm(U - L) - self.kp,
                         np.linalg.norm(T - h["tie_rod_inner"]) - self.tr,
                         W[2] - h["wheel_center"][2] - dz])

    def jacobian(self, x: np.ndarray, dz: float) -> np.ndarray:
        """Central differences with an absolute step (the solver's own steps are relative
        to ``x``, which is 0 in the design position)."""
        e = 1e-6 * np.eye(3)
        return np.column_stack([(self.residual(x + e[i], dz) - self.residual(x - e[i], dz))
                                / 2e-6 for i in range(3)])

    def solve(self, dz: float) -> dict[str, np.ndarray | float]:
        """Wheel centre, outward spin axis and spring length at wheel travel ``dz`` [m],
        continued from the previous solution."""
        # Newton (MINPACK's hybrid method starts with a trust region scaled by |x|, which
        # is 0 in the design position)
        x = self.x.copy()
        for _ in range(30):
            r = self.residual(x, dz)
            if np.max(np.abs(r)) < 1e-13:
                break
            x -= np.linalg.solve(self.jacobian(x, dz), r)
        assert np.max(np.abs(self.residual(x, dz))) < 1e-13
        self.x = x
        h = self.h
        Rk, L, Rl = self.pose(x)
        spring_arm = h["lower_arm_rear"] + Rl @ (h["spring_arm"] - h["lower_arm_rear"])
        return {"wheel_center": L + Rk @ (h["wheel_center"] - h["lower_ball_joint"]),
                "axis": Rk @ self.axis0,
                "spring": float(np.linalg.norm(spring_arm - h["spring_chassis"]))}


def without_preload(p: DoubleWishboneFile, rate: float = 1.5e5) -> DoubleWishboneFile:
    """``p`` with a linear spring of ``rate`` [N/m] free at the design position, no stops."""
    length = float(np.linalg.norm(p.point("spring_chassis") - p.point("spring_arm")))
    return p.model_copy(update={"spring": Spring(rate=rate, free_length=length),
                                "stops": None})


def ground_mount(sp: Spec):
    def mount(name: str, point: np.ndarray) -> str:
        return sp.add_marker(name, "ground", position=point)
    return mount


def test_kinematics_against_the_loop_closure():
    """Camber, toe and the wheel centre over +-60 mm of wheel travel (rigid pivots, the
    rack held) equal the angle formulation's solution within 1e-9. Fails if a joint sits off
    its hardpoint (e.g. the tie rod's outer ball joint built at ``tie_rod_inner``), if an
    arm's pivot axis is not the line of its pickups, or if the hub's z is not the spin
    axis."""
    p = HMMWV.front
    dz, sim = simulated_sweep(p, 4)
    loop = AngleLoop(p)
    wc0 = p.point("wheel_center")
    assert np.ptp(sim.wheel_center[:, 2]) == pytest.approx(0.12, abs=1e-12)
    for i in np.argsort(np.abs(dz), kind="stable"):
        ref = loop.solve(float(sim.wheel_center[i, 2] - wc0[2]))
        np.testing.assert_allclose(sim.wheel_center[i], ref["wheel_center"], atol=1e-9)
        c_s, t_s, _ = wheel_angles(sim.axis[i], "left")
        c_r, t_r, _ = wheel_angles(ref["axis"], "left")
        assert abs(c_s - c_r) < 1e-9 and abs(t_s - t_r) < 1e-9
    # the sweep covers a real motion: about 2.8 deg of camber and 0.7 deg of toe
    cambers = [wheel_angles(a, "left")[0] for a in sim.axis]
    assert np.degrees(np.ptp(cambers)) > 2.0


def test_static_wheel_rate_is_spring_rate_times_installation_ratio_squared():
    """With a linear spring free at the design position, the rig's vertical force per wheel
    travel there is ``k IR^2``, ``IR = -dL_spring / dz`` from the angle formulation (central
    differences). Fails if the spring is attached to the wrong arm or point (another
    installation ratio), or if the spring's rate is not the file's."""
    k = 1.5e5
    p = without_preload(HMMWV.front, k)
    loop = AngleLoop(p)
    d = 1e-4
    lengths = []
    for dz in (d, -d):
        loop.x = np.zeros(3)
        lengths.append(loop.solve(dz)["spring"])
    ir = -(lengths[0] - lengths[1]) / (2 * d)  # the spring shortens in bump
    assert 0.4 < ir < 0.5
    model, _ = corner_rig(p, Table((0.0, 1.0, 2.0), (0.0, d, -d)))
    forces = []
    st = model.initial_state()
    for t in (1.0, 2.0):
        st = solve_static(model, st, t=t)
        forces.append(element_outputs(model, st)["actuator"]["force"])
    rate = (forces[0] - forces[1]) / (2 * d)
    # central differences of both: O(d^2) relative to the curvature, about 1e-8 here
    assert rate == pytest.approx(k * ir**2, rel=1e-6)


def test_free_length_sets_the_wheel_load_at_the_design_position():
    """The shipped front corner carries 19.9 kN at its design position (the spring's force
    times the installation ratio: the virtual work of a massless linkage); with the free
    length :func:`free_length_for_load` gives for 10 kN it carries 10 kN there, with the
    tabulated spring and with a linear one. Fails if the spring's deflection is taken with
    the wrong sign or the installation ratio is not applied."""
    p = HMMWV.front
    dp = design_point(p)
    # the installation ratio by central differences: O(STEP^2), 1e-8 here
    assert dp.wheel_load == pytest.approx(-dp.spring_force * dp.installation_ratio, rel=1e-7)
    assert dp.wheel_load == pytest.approx(19914.0, rel=1e-4)
    for q in (p, without_preload(p)):
        free = free_length_for_load(q, 1.0e4)
        spring = q.spring.model_copy(update={"free_length": free})
        loaded = design_point(q.model_copy(update={"spring": spring}))
        assert loaded.wheel_load == pytest.approx(1.0e4, rel=1e-7)  # (the same ratio)


def two_corners(p: DoubleWishboneFile, function=0.0, rigid: bool = False,
                arb: bool = False) -> tuple[Spec, dict, object]:
    sp = Spec()
    mount = ground_mount(sp)
    rack = add_rack_steering(sp, "steer", HMMWV.steering, mount, function, quantity="travel")
    corners = {s: add_double_wishbone(sp, f"f{s[0]}", s, p, mount, steer=rack.marker(s),
                                      rigid_bushings=rigid) for s in ("left", "right")}
    if arb:
        add_anti_roll_bar(sp, "arb", p, mount, corners["left"], corners["right"])
    return sp, corners, rack


def test_left_and_right_corners_are_mirror_images():
    """Both front corners with their bushings, the rack and the anti-roll bar, under equal
    vertical wheel loads: every body of the right corner is at the mirror image of its
    left twin, with the mirrored mass distribution, the hub axes mirror images, the spring
    forces equal. Fails if the right corner takes the left's points unmirrored, if its
    links' inertia is not mirrored, or if its hub axis is not turned to the vehicle's
    left."""
    # products of inertia (the shipped links have none, and principal moments alone come
    # out mirrored whatever the builder does)
    J = [[0.1656, 0.01, -0.005], [0.01, 0.1934, 0.002], [-0.005, 0.002, 0.04367]]
    p = HMMWV.front.model_copy(update={
        "upright": HMMWV.front.upright.model_copy(update={"inertia": J}),
        "lower_arm": HMMWV.front.lower_arm.model_copy(update={"inertia": np.add(
            np.diag([0.4, 0.5, 0.8]), [[0, 0.02, 0.03], [0.02, 0, -0.01], [0.03, -0.01, 0]]
        ).tolist()})})
    sp, c, _ = two_corners(p, arb=True)
    for s in ("left", "right"):
        sp.add(Force(f"load_{s}", c[s].hub, vector=(0.0, 0.0, 1.9e4), frame="global"))
    model = compile_model(sp)
    st = solve_static(model, max_iter=100)
    for part in ("upper_arm", "lower_arm", "upright", "tie_rod"):
        bl, br = sp.bodies[f"fl_{part}"], sp.bodies[f"fr_{part}"]
        Jl = bl.rotation @ bl.inertia @ bl.rotation.T
        Jr = br.rotation @ br.inertia @ br.rotation.T
        np.testing.assert_allclose(Jr, MIRROR @ Jl @ MIRROR, atol=1e-12)
        il, ir_ = model.node_index[bl.name], model.node_index[br.name]
        np.testing.assert_allclose(st.x[ir_], MIRROR @ st.x[il], atol=1e-9)
    xl, Rl = marker_global(model, st, c["left"].hub)
    xr, Rr = marker_global(model, st, c["right"].hub)
    np.testing.assert_allclose(xr, MIRROR @ xl, atol=1e-9)
    np.testing.assert_allclose(Rr[:, 2], -(MIRROR @ Rl[:, 2]), atol=1e-9)
    assert Rl[1, 2] > 0.99 and Rr[1, 2] > 0.99  # both hubs' z to the vehicle's left
    out = element_outputs(model, st)
    assert out["fr_spring"]["force"] == pytest.approx(out["fl_spring"]["force"], rel=1e-9)
    assert abs(out["arb_torsion"]["torque"]) < 1e-6  # equal wheel loads: no roll
    cl = wheel_angles(Rl[:, 2], "left")
    cr = wheel_angles(Rr[:, 2], "right")
    np.testing.assert_allclose(cl[:2], cr[:2], atol=1e-9)  # same camber and toe


def test_rack_travel_steers_both_wheels_the_same_way():
    """The rack moved 10 mm to the left (positive travel), tie rods behind the wheel
    centres: both wheels steer right (steer < 0 on both sides: toe-in on the left, toe-out
    on the right), 10 mm to the right steers both left, and the rack's force is the
    driver's. Fails if the rack's travel sign is reversed, if a right tie rod is hung on the
    left rack joint, or if the right side's steer angle takes the left side's sign."""
    p = without_preload(HMMWV.front)
    sp, c, rack = two_corners(p, Table((0.0, 1.0, 2.0), (0.0, 0.01, -0.01)), rigid=True)
    model = compile_model(sp)
    st = model.initial_state()
    steer = {}
    for t in (1.0, 2.0):
        st = solve_static(model, st, t=t)
        x_rack = st.x[model.node_index[rack.body]] - sp.bodies[rack.body].position
        assert x_rack == pytest.approx([0.0, rack.travel(t), 0.0], abs=1e-12)
        steer[t] = {s: wheel_angles(marker_global(model, st, c[s].hub)[1][:, 2], s)
                    for s in ("left", "right")}
    for s in ("left", "right"):
        assert steer[1.0][s][2] < -0.01 and steer[2.0][s][2] > 0.01
        assert np.degrees(abs(steer[1.0][s][2])) < 5.0
    assert steer[1.0]["left"][1] > 0.0 > steer[1.0]["right"][1]
    # the outer wheel of a turn steers less than the inner one (Ackermann): within 25 %
    ratio = steer[1.0]["left"][2] / steer[1.0]["right"][2]
    assert 0.75 < ratio < 1.33


@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_shipped_file_gives_every_number_its_provenance(name):
    """Every value line of each shipped data set carries "source" or "chosen" in its own
    comment or in the comment block or table header just above it. Fails if a number is
    added without its provenance."""
    lines = SHIPPED[name].read_text().splitlines()
    note, table_note, in_info, depth, after_comment = "", "", False, 0, False
    for n, line in enumerate(lines, 1):
        code, _, comment = line.partition("#")
        code = code.strip()
        if depth:  # inside a multi-line array
            depth += code.count("[") - code.count("]")
            continue
        if not code:  # a comment block applies to the key lines below it, up to a blank
            note = (note + comment if after_comment else comment) if comment else ""
            after_comment = bool(comment)
            continue
        after_comment = False
        if code.startswith("["):
            in_info = code == "[info]"
            table_note, note = comment, ""
            continue
        key, _, value = code.partition("=")
        depth = value.count("[") - value.count("]")
        if in_info or key.strip() == "type":
            continue
        told = comment + note + table_note
        assert re.search(r"\b(source|chosen)\b", told), f"line {n} has no provenance: {line}"


def test_bad_input_names_the_key_and_value(tmp_path):
    """A zero-length link, hardpoints that do not assemble (a rack joint 5 mm off the tie
    rod's point, a spring longer than its rebound stop allows), a steering function beyond
    the rack's travel, an unknown suspension type and a negative free length: a ModelError
    naming the key and the value. Fails if any of them is accepted."""
    p = HMMWV.front
    hp = p.hardpoints.model_copy(update={"upper_arm_rear": p.hardpoints.upper_arm_front})
    bad = p.model_copy(update={"hardpoints": hp})
    sp = Spec()
    with pytest.raises(ModelError, match=r"hardpoints\.upper_arm_front = \[.*upper arm pivot"):
        add_double_wishbone(sp, "fl", "left", bad, ground_mount(sp))
    moved = np.add(HMMWV.steering.tie_rod_inner, [0.0, 0.005, 0.0])
    off = HMMWV.steering.model_copy(update={"tie_rod_inner": tuple(moved)})
    sp = Spec()
    rack = add_rack_steering(sp, "steer", off, ground_mount(sp), 0.0)
    with pytest.raises(ModelError, match=r"hardpoints\.tie_rod_inner = \[.*0\.005 m away"):
        add_double_wishbone(sp, "fl", "left", p, ground_mount(sp), steer=rack.left)
    stops = p.stops.model_copy(update={"rebound_length": 0.2})
    sp = Spec()
    with pytest.raises(ModelError, match=r"stops\.rebound_length: 0\.2 m is not above .*0\.246"):
        add_double_wishbone(sp, "fl", "left", p.model_copy(update={"stops": stops}),
                            ground_mount(sp))
    sp = Spec()
    with pytest.raises(ModelError, match=r"pinion angle 0\.6 rad .* travel_limit = 0\.05236"):
        add_rack_steering(sp, "steer", HMMWV.steering, ground_mount(sp),
                          SmoothStep(0.5, 1.0, 0.0, 0.6))
    sp = Spec()
    with pytest.raises(ModelError, match=r"rack travel 0\.06 m at t = 1\.5 s"):
        add_rack_steering(sp, "steer", HMMWV.steering, ground_mount(sp),
                          Ramp(0.5, 1.5, 0.0, 0.03) * 2.0, quantity="travel")
    text = SHIPPED["hmmwv"].read_text()
    for old, new, key in (('[rear]\ntype = "double_wishbone"', '[rear]\ntype = "multi_link"',
                           "rear.type"),
                          ('free_length = "0.339 m"', 'free_length = "-0.339 m"',
                           "front.spring.free_length")):
        f = tmp_path / "bad.toml"
        f.write_text(text.replace(old, new, 1))
        with pytest.raises(ModelError, match=re.escape(key)) as err:
            load_suspensions(f)
        assert new.split("=")[1].strip().strip('"') in str(err.value)


def test_anti_roll_bar_resists_roll_only():
    """Opposite vertical loads of 2 kN on the wheel centres (rigid pivots, springs free at
    the design position): with the bar the wheels' height difference is smaller than
    without it, the bar's torque is its rate times the halves' relative rotation about the
    bar's axis, of the sign of the roll (the left wheel pushed up lifts the left lever's
    front end: the left half turns by a negative angle about +y relative to the right one).
    Fails if a half's torsion marker is turned to -y (the spring then sees heave, not roll)
    or the torsion spring acts about another axis than the bar's."""
    p = without_preload(HMMWV.front)
    heights = {}
    for with_bar in (False, True):
        sp, c, _ = two_corners(p, rigid=True, arb=with_bar)
        for s, f in (("left", 2.0e3), ("right", -2.0e3)):
            sp.add(Force(f"load_{s}", c[s].hub, vector=(0.0, 0.0, f), frame="global"))
        model = compile_model(sp)
        st = solve_static(model)
        z = {s: marker_global(model, st, c[s].hub)[0][2] for s in ("left", "right")}
        heights[with_bar] = z["left"] - z["right"]
    assert heights[False] > 0.0
    assert 0.0 < heights[True] < 0.9 * heights[False]
    out = element_outputs(model, st)
    Rl = st.R[model.node_index["arb_left_half"]]
    Rr = st.R[model.node_index["arb_right_half"]]
    rel = Rr.T @ Rl  # both halves start with the vehicle's axes
    angle = np.arctan2(rel[0, 2] - rel[2, 0], rel[0, 0] + rel[2, 2])  # about y
    assert out["arb_torsion"]["torque"] == pytest.approx(
        p.anti_roll_bar.rate * angle, rel=1e-9)
    assert angle < -1e-3


def test_validation_case_passes():
    """``drivedyn validate --case suspension_kinematics --quick``: every check passes, each
    with its reference stated. Fails if the case's rig or its loop closure drifts from the
    corner (a hub frame or a pivot built differently from the hardpoints)."""
    from drivedyn.validation import CASES

    results = CASES["suspension_kinematics"](quick=True)
    assert len(results) == 5
    for r in results:
        assert r.passed, f"{r.quantity}: error {r.error:.3g} > {r.tolerance:.3g}"
        assert r.source
