"""The RWD vehicle (flexible ladder frame, double wishbones on bushings, Magic Formula tyres,
rear differential by name): it builds and rolls, its static loads, the open differential's
equal split and the TORSEN Type B's torque ratio on split-mu, and the command line. Each
test's docstring names a deliberate mutation that makes it fail. Runs are short (0.8 s of a
launch from walking pace) to keep CI cheap."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

import drivedyn.analysis.vehicle_rwd as V  # noqa: N812 - short name for the analysis
from drivedyn.cli import main
from drivedyn.config import read_library_file
from drivedyn.config.loader import read_vehicle_differentials, resolve_path
from drivedyn.library import vehicles

MODELS_DIR = resolve_path("vehicle-rwd").parent
#: the shipped file with a short launch: the throttle ramps over 0.2 s, the checks read
#: 0.5-0.8 s
SHORT = ["run.t_end=0.8", "run.window=[0.5, 0.8]", 'engine.ramp="0.2 s"']


def _params(config: str):
    p, _, source = read_library_file("vehicle-rwd", SHORT)
    q = V.configure(p, config)
    return q, read_vehicle_differentials(q, source, MODELS_DIR)


def test_registered_and_listed():
    """Mutation: drop ``vehicle_rwd`` from ``vehicles.TYPES`` -> the lookup fails."""
    mod = vehicles.get("vehicle-rwd")
    p, _, _ = read_library_file("vehicle-rwd")
    assert mod.SCHEMA is type(p)
    assert mod.CONFIGURATION(p) == "torsen-b"


def test_builds_and_rolls_forward():
    """Mutation: put the ring gear on the +y side of the housing (``ring = centre +
    d_ring * Y``) -> the engine drives the vehicle backwards and the speed check fails."""
    p, torsen = _params("open")
    # 0.5 s: the engine brakes with its friction until the throttle passes 2.5 % (0.1 s),
    # the wheels' drive turns positive at 0.25 s
    res, lay = V.run(p, torsen, MODELS_DIR, t_end=0.5)
    assert res.success, res.message
    assert 2500.0 < lay.total_mass < 2700.0
    v = res.values("wheel_fl.velocity")[:, 0]
    assert v[-1] > p.body.speed + 0.05  # pulled forward by the rear wheels
    for w in ("rl", "rr"):
        assert V.drive_torque(res, lay, w)[-1] > 50.0


def test_engine_map_sees_the_engine_speed():
    """The engine map reads the crankshaft's speed: first gear times the gearbox output's,
    which is the final drive's ratio times the rear wheels' mean spin (an open
    differential), on average over 0.1 s; its torque is the file's map at that speed.

    Mutation: build the engine with ``ratio=1`` (the map read at the gearbox output's
    speed) -> the engine speed is 5.855 times too low."""
    p, torsen = _params("open")
    res, lay = V.run(p, torsen, MODELS_DIR, t_end=0.1)
    assert res.success, res.message
    spins = []
    for w in ("rl", "rr"):
        axis = res.values(f"{lay.wheels[w]}.rotation")[:, :, 2]
        spins.append(np.einsum("ij,ij->i", res.values(f"{lay.wheels[w]}.angular_velocity"),
                               axis))
    expected = p.engine.gear_ratio * lay.ratio * 0.5 * (spins[0] + spins[1])
    w_e = res.values("engine.engine_speed")
    # means: the wheels' spins swing by 2 % about the driveline's (its compliance)
    assert np.mean(w_e) == pytest.approx(np.mean(expected), rel=0.01)
    assert 90.0 < w_e[-1] < 110.0  # about 1000 rpm at the launch's 1.5 m/s
    from drivedyn.elements import EngineTorque

    e = EngineTorque("e", "a", "b", full_load=p.engine.full_load,
                     zero_throttle=p.engine.zero_throttle)
    u = res.values("engine.throttle")[-1]
    assert res.values("engine.engine_torque")[-1] == pytest.approx(e.torque(w_e[-1], u),
                                                                   rel=1e-9)


def test_static_loads():
    """Mutation: keep cancelling the weight of the differential's gears in the static
    solution (``lift=True`` when parked) -> the loads sum to m g only within 1e-3."""
    p, torsen = _params("open")
    s = V.static(p, torsen, MODELS_DIR)
    total = sum(s.loads.values())
    assert abs(total - s.mass * 9.81) <= 1e-6 * s.mass * 9.81
    assert abs(s.rear_share - s.rear_share_cg) <= 5e-3 * s.rear_share_cg
    assert all(c[3] for c in V.static_checks(s))
    # left and right carry the same load within 0.5 % (a symmetric vehicle)
    for a, b in (("fl", "fr"), ("rl", "rr")):
        assert abs(s.loads[a] - s.loads[b]) <= 5e-3 * s.loads[a]


def test_open_differential_splits_evenly_on_split_mu():
    """Mutation: build the ``open`` configuration with the ``locked`` bevel differential
    (``CONFIGS["open"] = "locked"``) -> the dry wheel takes more torque and the 1 % check
    fails."""
    p, torsen = _params("open")
    res, lay = V.run(p, torsen, MODELS_DIR)
    assert res.success, res.message
    s = V.summarize(res, lay, p.run.window)
    tl, tr = s.wheels["rl"].torque, s.wheels["rr"].torque
    assert tl > 50.0
    assert abs(tl - tr) <= 0.01 * 0.5 * (tl + tr)
    assert s.wheels["rl"].kappa > 0.2  # the iced wheel spins
    # the vehicle's motion: a yaw rate and a drift (split-mu pulls towards the dry side,
    # right: negative), histories per sample
    assert abs(s.yaw_rate) < 0.05 and abs(s.drift) < 0.5
    for k in ("speed", "yaw_rate", "drift", "spin_rl", "kappa_rl"):
        assert len(s.history[k]) == len(res.time)
    assert all(c[3] for c in V.checks(s))


def test_power_balance_names_the_driveline_terms():
    """The driveline power balance of a short open launch holds within 1e-3 (validation:
    0.5 %), and it is not blind: leaving the engine shaft out of the driveline's kinetic
    energy (the mutation of ``rwd_split_mu``'s docstring) breaks it by far more than 1 %.
    Mutation: drop the ``- w_c.h`` term or the wheels' work -> the first assertion fails."""
    p, torsen = _params("open")
    res, lay = V.run(p, torsen, MODELS_DIR)
    assert res.success, res.message
    t = res.time
    i0, i1 = (int(i) for i in np.flatnonzero(t >= p.run.window[0] - 1e-12)[[0, -1]])
    pb, w_eng = V.power_balance(res, lay, i0, i1)
    assert w_eng > 0.0
    assert pb <= 1e-3
    h = res.values("engine_shaft.angular_momentum")
    w = res.values("engine_shaft.angular_velocity")
    k_engine = 0.5 * float(w[i1] @ h[i1] - w[i0] @ h[i0])
    assert abs(k_engine) > 0.01 * w_eng  # what the mutation would leave out


def test_validation_cases_pass_quick():
    """The registered cases ``rwd_static_loads`` and ``rwd_split_mu`` (quick: the open
    differential) pass. Mutation: count the tyre loads of three wheels in
    ``analysis.vehicle_rwd.static`` -> the sum check fails."""
    from drivedyn.validation import base

    for name in ("rwd_static_loads", "rwd_split_mu"):
        results = base.CASES[name](quick=True)
        assert results and all(r.source for r in results)
        assert all(r.passed for r in results), [(r.quantity, r.simulated) for r in results
                                                if not r.passed]


def test_run_starts_from_the_static_equilibrium():
    """``drivedyn run vehicle-rwd`` (``load_model``) starts from the parked vehicle's static
    shape, not the built one: the frame's nodes sit where :func:`static_start` puts them
    (the frame sags by millimetres under the body). Mutation: drop ``INITIAL_STATE`` from
    the vehicle module -> the model starts from the built shape and the positions differ."""
    from drivedyn.config import load_model
    from drivedyn.library.vehicles.vehicle_rwd import static_start

    model = load_model("vehicle-rwd", SHORT)
    p, torsen = _params("torsen-b")
    spec, lay = vehicles.get("vehicle-rwd").build_spec(p, torsen, MODELS_DIR)
    from drivedyn.model.compile import compile_model

    built = compile_model(spec)
    ref = static_start(p, torsen, MODELS_DIR, built, lay)
    frame = [i for n, i in model.node_index.items() if n.startswith("frame.")]
    assert np.allclose(model.state0.x, ref.x, atol=1e-12)
    sag = np.max(np.abs(model.state0.x[frame, 2] - built.state0.x[frame, 2]))
    assert 1e-3 < sag < 0.05


@pytest.mark.slow  # about 20 s: the TORSEN's gears make its launch the dearest run here
def test_torsen_b_ratio_within_its_tdr():
    """Mutation: set the TORSEN file's friction coefficients to zero (``--set`` of its
    ``mu`` keys) -> the ratio falls towards 1, below the lowest analytic TDR."""
    p, torsen = _params("torsen-b")
    res, lay = V.run(p, torsen, MODELS_DIR)
    assert res.success, res.message
    s = V.summarize(res, lay, p.run.window)
    lo, hi = lay.tdr
    assert s.wheels["rr"].torque > s.wheels["rl"].torque > 0.0  # the dry wheel takes more
    assert 0.95 * lo <= s.axle_ratio["rear"] <= 1.02 * hi
    assert all(c[3] for c in V.checks(s))


def test_cli_static_json():
    """Mutation: drop the ``vehicle_rwd`` dispatch in ``cli/vehicle.py`` -> the 4WD analysis
    refuses the file (exit 2)."""
    r = CliRunner().invoke(main, ["vehicle", "vehicle-rwd", "--scenario", "static",
                                  "--compare", "open", "--json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    run = out["runs"][0]
    assert run["configuration"] == "open"
    assert {c["check"] for c in run["checks"]} and all(c["passed"] for c in run["checks"])
    assert np.isclose(sum(run["loads"].values()), run["mass"] * 9.81, rtol=1e-6)
    # the wheel centres of the static solution: left and right mirror images, the wheelbase
    c = {w: np.array(x) for w, x in run["wheel_centres"].items()}
    for a, b in (("fl", "fr"), ("rl", "rr")):
        assert abs(c[a][1] + c[b][1]) < 1e-3 and c[a][1] > 0.5
    assert 3.2 < c["fl"][0] - c["rl"][0] < 3.4  # the HMMWV's 3.30 m at ride height


@pytest.mark.parametrize("args, message", [
    (["--scenario", "drift"], "unknown scenario"),
    (["--compare", "torsen"], "unknown configuration"),
])
def test_cli_bad_input(args, message):
    """Mutation: accept any scenario name -> exit 0 or 1 instead of 2."""
    r = CliRunner().invoke(main, ["vehicle", "vehicle-rwd", *args])
    assert r.exit_code == 2
    assert message in r.output


@pytest.mark.parametrize("value, words", [
    ("[[0, 400], [100, 900], [90, 1000]]",
     ["engine.full_load", "increase strictly", "100.0 then 90.0 rad/s"]),
    ("[[-10.472, 406.7], [83.776, 517.9]]", ["engine.full_load", ">= 0 rad/s", "-10.472"]),
])
def test_cli_bad_engine_map(value, words):
    """Mutation: drop the schema's check of the maps' speeds -> the file is accepted (the
    element refuses it later, naming the element instead of the file's key)."""
    r = CliRunner().invoke(main, ["vehicle", "vehicle-rwd", "--scenario", "static",
                                  "--compare", "open", "--set", f"engine.full_load={value}"])
    assert r.exit_code == 2, r.output
    for w in words:
        assert w in r.output, r.output


def test_every_number_of_the_model_file_has_its_provenance():
    """Mutation: delete the comment of any value line of ``vehicle-rwd.toml`` -> it is
    listed here."""
    path = resolve_path("vehicle-rwd")
    section, bare = "", []
    for i, line in enumerate(path.read_text().splitlines(), 1):
        text = line.strip()
        if text.startswith("["):
            section = text
            continue
        if "=" not in text or text.startswith("#") or section == "[model]":
            continue
        comment = line.partition("#")[2]
        if not any(tag in comment for tag in ("source:", "chosen", "switch:")):
            bare.append(f"{i}: {text}")
    assert not bare, "value lines without provenance:\n" + "\n".join(bare)


def test_wind_up_closes_the_driveline_plays_under_the_first_torque():
    """The run begins with the driveline wound up by the engine's first torque
    (``run.wind_up``, :mod:`~drivedyn.library.vehicles.vehicle_rwd.wind_up`): against the
    static start with the plays open (``run.wind_up = false``), the TORSEN's side gears sit
    on their outer washers (moved outwards along the housing's axis by the washers' gap,
    within the contact's few um), the propeller shaft's spring is twisted by the engine's
    torque at the start over its stiffness (within 1 %: settled; measured 0.1 %), the driven
    wheels have not turned (the brakes held them) and the frame has not moved. Mutations:
    the engine's torque left out of the settling -> the side gears move the same way (by
    the weight on the final drive, not to their washers); the brakes left out -> the
    driveline turns freely and one side gear stops 20 um short of its washer; the settling
    cut at 0.3 s -> the twist is 55 % short (all seen failing)."""
    from drivedyn.library.vehicles.vehicle_rwd import static_start
    from drivedyn.library.vehicles.vehicle_rwd.wind_up import engine_torque_at
    from drivedyn.model.compile import compile_model

    p, torsen = _params("torsen-b")
    spec, lay = vehicles.get("vehicle-rwd").build_spec(p, torsen, MODELS_DIR)
    model = compile_model(spec)
    open_ = static_start(p.model_copy(update={"run": p.run.model_copy(
        update={"wind_up": False})}), torsen, MODELS_DIR, model, lay)
    wound = static_start(p, torsen, MODELS_DIR, model, lay)
    ni = model.node_index
    h = ni[lay.housing]
    gap = torsen["torsen-b"].washers.left.gap
    shifts = []
    for side in ("rear_left", "rear_right"):
        i = ni[side]
        rel = [st.R[h].T @ (st.x[i] - st.x[h]) for st in (open_, wound)]
        d = rel[1] - rel[0]
        assert np.hypot(d[0], d[1]) < 1e-6  # along the axis
        shifts.append(d[2])
    assert shifts[0] * shifts[1] < 0.0  # outwards, to opposite washers
    assert all(abs(abs(s) - gap) < 3e-6 for s in shifts), shifts

    def twist(st) -> float:
        (na, _, Ra), (nb, _, Rb) = (model.marker_frames[m] for m in ("prop_rear", "prop_slip_in"))
        R = (st.R[na] @ Ra).T @ (st.R[nb] @ Rb)
        return float(np.arctan2(R[1, 0], R[0, 0]))

    engine = spec.element(lay.engine)
    T = engine_torque_at(engine, model, open_, open_.t)
    k = p.shafts.propshaft_stiffness
    assert T > 10.0
    assert abs(abs(twist(wound) - twist(open_)) - T / k) < 0.01 * T / k
    for w in lay.drives:  # held by the brakes
        i = ni[lay.wheels[w]]
        Q = open_.R[i].T @ wound.R[i]
        assert np.arccos(min(1.0, (np.trace(Q) - 1.0) / 2.0)) < 1e-4
    frame = [i for n, i in ni.items() if n.startswith("frame.")]
    assert np.array_equal(wound.x[frame], open_.x[frame])
