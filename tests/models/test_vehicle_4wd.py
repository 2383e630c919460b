"""The 4WD vehicle: sub-assembly placement, the reference differentials on a bench against
their exact quasi-static splits, the split-mu acceptance checks of each configuration (open,
locked, clutch, TORSEN), the model file and the command line."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

from drivedyn.cli import main
from drivedyn.config import read_library_file
from drivedyn.elements import Hinge, JointDriver, Torque
from drivedyn.errors import ModelError
from drivedyn.library.vehicles.bevel_differential import build_bevel, clutch_split
from drivedyn.library.vehicles.vehicle_4wd.schema import BevelDifferential, Vehicle4WDFile
from drivedyn.model.compile import compile_model
from drivedyn.model.spec import Spec
from drivedyn.model.subassembly import include
from drivedyn.solver import simulate
from drivedyn.timefunctions import SmoothStep

#: a rolling start (2 m/s) keeps these runs short: the load ramps from t = 0 over 0.1 s and
#: the checks read 0.5-0.8 s
ROLLING = {"model": {"library": "vehicle_4wd"}, "body": {"speed": 2.0},
           "load": {"start": 0.0, "ramp": 0.1}, "run": {"t_end": 0.8, "window": [0.5, 0.8]}}


def test_include_places_renames_and_rehangs_the_ground():
    sub = Spec()
    sub.add_rigid_body("rotor", 2.0, (0.1, 0.1, 0.2), position=(0.0, 0.0, 0.5),
                       angular_velocity=(0.0, 0.0, 3.0))
    sub.add_marker("g", "ground", position=(0.0, 0.0, 0.5), axis=(0, 0, 1))
    sub.add_marker("r", "rotor", axis=(0, 0, 1))
    sub.add(Hinge("bearing", "g", "r"))
    sub.add(JointDriver("spin", "bearing", function=3.0))
    host = Spec()
    host.add_rigid_body("frame", 10.0, (1.0, 1.0, 1.0), position=(1.0, 2.0, 0.0))
    R = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])  # z -> +x
    names = include(host, sub, "d_", position=(1.0, 0.0, 0.0), rotation=R, ground="frame",
                    velocity=(5.0, 0.0, 0.0))
    assert names["rotor"] == "d_rotor"
    b = host.bodies["d_rotor"]
    np.testing.assert_allclose(b.position, [1.5, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(b.angular_velocity, [3.0, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(b.velocity, [5.0, 0.0, 0.0], atol=1e-15)
    m = host.markers["d_g"]
    assert m.body == "frame"  # the sub-assembly's ground is now the frame
    np.testing.assert_allclose(m.position, [0.5, -2.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(m.rotation[:, 2], [1.0, 0.0, 0.0], atol=1e-15)
    hinge = host.element("d_bearing")
    assert (hinge.marker_a, hinge.marker_b) == ("d_g", "d_r")
    assert host.element("d_spin").joint == "d_bearing"
    compile_model(host)
    with pytest.raises(ModelError, match="not a body or node"):
        include(Spec(), sub, "x_", ground="nowhere")


def _bench(kind: str, load: float = 50.0):
    """Housing driven at 10 rad/s, side gear a driven 2 rad/s faster than the housing, side
    gear b braked by ``load`` [N m]: (input torque, torque on a, torque on b) means."""
    p = BevelDifferential()
    sp = build_bevel(p, kind, omega=10.0)
    sp.add(JointDriver("drive", "housing_bearing", function=10.0))
    sp.add(JointDriver("slip", "a_bearing", function=SmoothStep(0.0, 0.05, 0.0, 2.0)))
    sp.add_marker("load_b", "b", axis=(0, 0, 1))
    sp.add(Torque("brake", "load_b", vector=(0, 0, -load),
                  function=SmoothStep(0.0, 0.1, 0.0, 1.0), frame="marker"))
    res = simulate(compile_model(sp), 0.5, output_dt=1e-3)
    assert res.success, res.message
    sel = res.time > 0.3
    t_a = -float(res["slip.torque"].values[sel].mean())  # what side a delivers
    t_in = float(res["drive.torque"].values[sel].mean()) + t_a  # the a-driver acts on the housing
    return p, t_in, t_a, load


def test_open_differential_splits_evenly_while_slipping():
    _, t_in, t_a, t_b = _bench("open")
    assert t_a == pytest.approx(t_b, rel=1e-8)
    assert t_in == pytest.approx(t_a + t_b, rel=1e-8)


def test_clutch_differential_matches_its_quasi_static_split():
    """Ramp, packs, preload and bevel thrust: the bench's output torques equal the closed-form
    split (:func:`clutch_split`) to 1e-6 (measured 2e-7)."""
    p, t_in, t_a, t_b = _bench("clutch")
    fast, slow = clutch_split(p, t_in, ramp_on_fast=True)
    assert t_a == pytest.approx(fast, rel=1e-6)
    assert t_b == pytest.approx(slow, rel=1e-6)
    assert slow / fast > 4.0  # the slow side takes the torque: a limited-slip differential


@pytest.fixture(scope="module")
def torsen_params():
    tc, _, _ = read_library_file("torsen-c")
    tb, _, _ = read_library_file("torsen-b")
    return {"torsen-c": tc, "torsen-b": tb}


@pytest.fixture(scope="module")
def runs(torsen_params):
    import drivedyn.analysis.vehicle_4wd as V  # noqa: N812

    p = Vehicle4WDFile.model_validate(ROLLING)
    return {s.name: (s, res) for s, res in V.compare(p, torsen_params,
                                                     ["open", "locked", "clutch", "torsen"])}


@pytest.mark.parametrize("config", ["open", "locked", "clutch", "torsen"])
def test_split_mu_checks(runs, config):
    """Every acceptance check of the configuration passes (see analysis.vehicle_4wd)."""
    import drivedyn.analysis.vehicle_4wd as V  # noqa: N812

    s, _ = runs[config]
    failed = [c for c in V.checks(s) if not c[3]]
    assert not failed, failed


def test_central_split_follows_the_torsen_law(runs):
    """The central Type C sticks on the split-mu rolling start (its outputs within 1e-3 of
    each other) and its rear / front split lies inside its locking band; the same split
    with the outputs slipping fails (a TORSEN that slips sits at a band end): seen with the
    central's friction lost in the simulation only (washers, pockets and teeth at mu 0),
    which slips by -43 % and splits at its nominal 1.40, 61 % from the nearest end (3.57);
    a stuck split outside the band fails too."""
    import dataclasses

    import drivedyn.analysis.vehicle_4wd as V  # noqa: N812

    s, _ = runs["torsen"]
    assert abs(s.central_slip) < V.CENTRAL_STICK
    (name, value, _, ok), = V.central_checks(s, 0.02)
    assert ok and "sticks" in name and value == s.central_ratio
    slipping = dataclasses.replace(s, central_slip=-0.43, central_ratio=1.403)
    (name, dev, _, ok), = V.central_checks(slipping, 0.02)
    assert not ok and "slips" in name and dev > 0.5
    outside = dataclasses.replace(s, central_ratio=1.05 * s.central_modes[0] * 1.02)
    assert not V.central_checks(outside, 0.02)[0][3]
    assert V.central_checks(runs["open"][0], 0.02) == []  # no TORSEN in the centre


def test_balances_are_exact_identities(runs):
    """Euler's law on each differential and the driveline power balance hold to the
    integration error (measured <= 1.2e-5 and 1.2e-4), far inside the 0.5 % of the issue."""
    for s, _ in runs.values():
        assert max(s.torque_balance.values()) < 5e-5, (s.name, s.torque_balance)
        assert s.power_balance < 5e-4, (s.name, s.power_balance)


def test_differential_types_rank_as_expected(runs, torsen_params):
    """Open diffs give every wheel the torque of the spinning ice wheel; the TORSEN axles
    bias at the Type B analytic drive TDR (measured 4e-5 and 8e-5); a locked or
    limited-slip vehicle pulls harder than the open one (measured 1.40-1.44 x)."""
    from drivedyn.library.differentials.torsen_b import analytic as ab

    open_, torsen = runs["open"][0], runs["torsen"][0]
    drive = ab.bench_tdr(torsen_params["torsen-b"], 1)
    assert torsen.axle_ratio["front"] == pytest.approx(drive, rel=3e-4)
    assert torsen.axle_ratio["rear"] == pytest.approx(drive, rel=3e-4)
    for name in ("locked", "clutch", "torsen"):
        assert runs[name][0].traction > 1.3 * open_.traction
    # the TORSEN's wheel with more grip gets more torque on each axle
    W = torsen.wheels
    assert W["fr"].torque > W["fl"].torque and W["rr"].torque > W["rl"].torque


def test_vehicle_starts_on_its_static_loads(torsen_params):
    """The layout's static loads are what the tyres carry at t = 0 (the body starts on its
    static deflection, level), and they add up to the weights the model applies."""
    from drivedyn.library.vehicles.vehicle_4wd import build_spec

    p = Vehicle4WDFile.model_validate({**ROLLING, "differentials": {
        "central": "open", "front": "open", "rear": "open"}})
    spec, lay = build_spec(p, torsen_params)
    res = simulate(compile_model(spec), 0.002, output_dt=1e-3)
    weights = -sum(e.vector[2] for e in spec.elements if e.name.endswith("_weight"))
    assert sum(lay.static_load.values()) == pytest.approx(weights, rel=1e-12)
    for w, load in lay.static_load.items():
        assert res[f"tyre_{w}.fz"].values[0] == pytest.approx(load, rel=1e-9)
        assert res[f"wheel_{w}.position"].values[0, 2] == pytest.approx(lay.wheel_height)


def test_model_file_loads_and_refuses_impossible_values(tmp_path):
    from drivedyn.config import load_model

    m = load_model("vehicle-4wd")
    assert m.meta["layout"].types == {"central": "torsen-c", "front": "torsen-b",
                                      "rear": "torsen-b"}
    runner = CliRunner()
    bad = [
        (["--set", "differentials.front=torsen-c"], "torsen-c is the central"),
        (["--set", "body.cg_to_front=3.0"], "body.cg_to_front: must lie between the axles"),
        (["--set", "road.mu.fl=-1"], "road.mu.fl"),
        (["--set", "wheels.tyre=nope"], "wheels.tyre: 'nope' is neither"),
        (["--set", "differentials.front=spool"], "differentials.front"),
        (["--compare", "open,viscous"], "unknown configuration 'viscous'"),
        (["--set", "differentials.torsen_b=torsen-c"], "expected a torsen_b model file"),
    ]
    for args, msg in bad:
        r = runner.invoke(main, ["vehicle", *args, "--t-end", "0.01"])
        assert r.exit_code == 2, (args, r.output)
        assert msg in r.output, (args, r.output)
        assert "Traceback" not in r.output


def test_vehicle_refuses_a_torsen_with_flexible_shafts(tmp_path):
    """A Type C file with ``flexible.shafts = true`` in a vehicle position is refused by key:
    the vehicle's own shafts connect to the output gears."""
    from drivedyn.config.loader import shipped_models

    text = shipped_models()["torsen-c"].read_text()
    tc = tmp_path / "tc.toml"
    tc.write_text(text + "\n[flexible]\nshafts = true\n")
    r = CliRunner().invoke(main, ["vehicle", "--set", f"differentials.torsen_c={tc}",
                                  "--t-end", "0.01"])
    assert r.exit_code == 2, r.output
    assert "flexible.shafts" in r.output and "Traceback" not in r.output, r.output


def test_vehicle_command_open_json(tmp_path):
    runner = CliRunner()
    r = runner.invoke(main, ["vehicle", "--compare", "open", "--set", "body.speed=2",
                             "--set", "load.ramp=0.1", "--set", "run.window=[0.5,0.8]",
                             "--t-end", "0.8", "--json", "--out", str(tmp_path)])
    assert r.exit_code == 0, r.output
    out = json.loads(r.output.splitlines()[-1])
    assert out["passed"] and out["runs"][0]["configuration"] == "open"
    assert (tmp_path / "wheel_torques.png").stat().st_size > 10_000
    assert (tmp_path / "vehicle-4wd-open.nc").exists()
    assert math.isfinite(out["runs"][0]["wheels"]["fl"]["torque"])
    # the results carry the run's parameters: the report finds the 4WD dashboard (before,
    # "This run comes from no library model with a dashboard")
    nc = tmp_path / "vehicle-4wd-open.nc"
    r = runner.invoke(main, ["report", str(nc), "--out", str(tmp_path / "r.html"),
                             "--no-view"])
    assert r.exit_code == 0, r.output
    page = (tmp_path / "r.html").read_text()
    assert "no library model with a dashboard" not in page
    import xarray as xr

    with xr.open_dataset(nc) as ds:
        assert ds.attrs["configuration"] == "open"
        assert ds.attrs["model_source"].endswith("[open]")


def test_differential_commands_refuse_a_vehicle_file():
    r = CliRunner().invoke(main, ["tdr", "vehicle-4wd"])
    assert r.exit_code == 2 and "is not a differential" in r.output


def test_engine_braking_biases_at_the_coast_tdr(torsen_params):
    """Coasting at 3 m/s with -100 N m on the central housing (engine braking): the TORSEN
    axles bias at the Type B coast TDR (analytic 1.6780; measured 1.6786, 4e-4), the wheel
    with more grip takes the larger braking torque, and every check passes."""
    import drivedyn.analysis.vehicle_4wd as V  # noqa: N812
    from drivedyn.library.differentials.torsen_b import analytic as ab

    p = Vehicle4WDFile.model_validate({**ROLLING, "body": {"speed": 3.0},
                                       "load": {"torque": -100.0, "start": 0.0, "ramp": 0.1}})
    (s, _), = V.compare(p, torsen_params, ["torsen"])
    coast = ab.bench_tdr(torsen_params["torsen-b"], 2)
    assert s.axle_ratio["front"] == pytest.approx(coast, rel=1e-3)
    assert s.axle_ratio["rear"] == pytest.approx(coast, rel=1e-3)
    assert s.wheels["fr"].torque < s.wheels["fl"].torque < 0  # braking: negative
    failed = [c for c in V.checks(s) if not c[3]]
    assert not failed, failed


@pytest.mark.parametrize("vehicle", ["vehicle-4wd", "vehicle-rwd"])
def test_mesh_stiffness_variation_is_the_vehicles_switch(vehicle):
    """``differentials.mesh_stiffness_variation`` of a vehicle file sets the TORSENs' meshes
    to a stiffness varying over the mesh cycle (true) or at its mean (false); None keeps
    their files' (varying); the final drives keep their own (``final_drive``). Mutation: a
    builder that passes the TORSEN parameters as read (``with_mesh_variation`` dropped) ->
    the false case still has varying meshes."""
    from drivedyn.config.loader import read_vehicle_differentials, resolve_path
    from drivedyn.library import vehicles

    counts = {}
    p0, _, source = read_library_file(vehicle)
    torsen = read_vehicle_differentials(p0, source, resolve_path(vehicle).parent)
    for var in (None, True, False):
        p = p0.model_copy(update={"differentials": p0.differentials.model_copy(
            update={"mesh_stiffness_variation": var})})
        spec = vehicles.get(vehicle).build_spec(p, torsen)[0]
        counts[var] = sum(e.stiffness_variation for e in spec.elements
                          if type(e).__name__ == "GearPair")
    assert counts[False] == 0
    assert counts[True] == counts[None] >= 20
