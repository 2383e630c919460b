"""The TORSEN Type C from the user's side: `drivedyn tdr`, `drivedyn calibrate`, the
parametric model file in the loader, and the `torsen_c_tdr` validation case (full seed
protocol, the four modes against seed 003 Table 1)."""

from __future__ import annotations

import json
import math
import tomllib

import pytest
from click.testing import CliRunner

import drivedyn as dd
from drivedyn.cli import main
from drivedyn.config import read_library_file
from drivedyn.config.loader import ModelFileError, shipped_models
from drivedyn.library.differentials.torsen_c import analytic as at

# a shorter bench protocol: same torque and speed levels, shorter holds (steady state is
# reached within ~0.1 s: the windows below stay on the plateaus)
SHORT = ["--set", "bench.ramp=0.1", "--set", "bench.transition=[0.5, 0.8]",
         "--set", "bench.t_end=1.1", "--set", "bench.window_drive=[0.25, 0.45]",
         "--set", "bench.window_coast=[0.9, 1.1]"]
FREE = ["washers.sun_housing.mu", "washers.coupling_case.mu", "washers.ring_housing.mu",
        "washers.ring_case.mu"]


@pytest.fixture
def runner() -> CliRunner:
    return CliRunner()


def test_tdr_json_short_protocol(runner: CliRunner) -> None:
    res = runner.invoke(main, ["tdr", "torsen-c", "--mode", "1", "--json", *SHORT])
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert {"model", "torque", "speed_diff", "modes", "wall_s"} <= set(out)
    assert out["torque"] == 125.0 and math.isclose(out["speed_diff"], 20.0)
    (m,) = out["modes"]
    assert m["mode"] == 1 and m["name"] == "drive, bias rear"
    assert m["experimental"] == 4.02
    assert abs(m["error_pct"]) < 5.0  # issue target: within 5 % of the measurement
    # simulation vs the independent analytic model (measured agreement ~1e-3)
    assert abs(m["tdr"] / m["analytic"] - 1) < 0.005, m


def test_tdr_analytic_only_and_overrides(runner: CliRunner) -> None:
    res = runner.invoke(main, ["tdr", "--analytic-only", "--json", "--friction-scale", "0.5",
                               "--set", "pockets.mu=0.1", "--torque", "80"])
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    p, _, _ = read_library_file("torsen-c", ["pockets.mu=0.1"])
    for row in out["modes"]:
        assert row["tdr"] == pytest.approx(at.bench_tdr(p, row["mode"], 80.0, None, 0.5),
                                           rel=1e-12)
    # half the friction: every mode closer to the frictionless ratio
    full = json.loads(runner.invoke(main, ["tdr", "--analytic-only", "--json", "--set",
                                           "pockets.mu=0.1"]).stdout)
    for a, b in zip(out["modes"], full["modes"], strict=True):
        nominal = 1.4 if a["mode"] <= 2 else 1 / 1.4
        assert abs(math.log(a["tdr"] / nominal)) < abs(math.log(b["tdr"] / nominal))


@pytest.mark.parametrize("args, needle", [
    (["--torque", "-5"], "--torque"),
    (["--speed-diff", "0"], "--speed-diff"),
    (["--set", "gears.teeth_ring=71"], "gears.teeth_ring"),
    (["--set", "pockets.mu=abc"], "pockets.mu"),
    (["--set", "washers.ring_case.mu=2"], "washers.ring_case.mu"),
    (["--set", "spline.helix_angle=\"-40 deg\""], "spline.helix_angle"),
    (["--set", "bodies.sun.mass=\"-1 kg\""], "bodies.sun.mass"),
    (["--set", "bench.t_end=0.45"], "transition end <= t_end"),
    (["--set", "bench.window_coast=[2.2, 3.5]"], "window_coast"),
])
def test_tdr_bad_input(runner: CliRunner, args: list[str], needle: str) -> None:
    res = runner.invoke(main, ["tdr", "--analytic-only", *args])
    assert res.exit_code == 2, res.output
    assert needle in res.output
    assert "Traceback" not in res.output


def test_calibrate_reproduces_the_shipped_values(runner: CliRunner, tmp_path) -> None:
    """Start from other values (all 0.1): the analytic fit lands on the shipped ones."""
    shipped, _, _ = read_library_file("torsen-c")
    sets = [a for k in FREE for a in ("--set", f"{k}=0.1")]
    out_file = tmp_path / "fitted.toml"
    res = runner.invoke(main, ["calibrate", "torsen-c", "--no-confirm", "--json", *sets,
                               "--out", str(out_file)])
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    for key in FREE:
        name = key.split(".")[1]
        want = getattr(shipped.washers, name).mu
        # the shipped file holds 6 decimals; the fit is exact (4 equations, 4 unknowns)
        assert out["free"][key] == pytest.approx(want, abs=2e-6), key
    for m, err in out["error_pct"].items():
        assert abs(err) < 1e-6, (m, err)
    data = tomllib.loads(out_file.read_text())
    assert data["calibration"]["fitted"] == FREE
    assert data["calibration"]["targets"]["mode1"] == 4.02
    assert "# fitted: see [calibration]" in out_file.read_text()  # comments kept
    p, _, _ = read_library_file(out_file)
    assert p.washers.ring_case.mu == pytest.approx(shipped.washers.ring_case.mu, abs=2e-6)


def test_calibrate_bad_keys(runner: CliRunner) -> None:
    res = runner.invoke(main, ["calibrate", "--no-confirm", "--free", "gears.module"])
    assert res.exit_code == 2 and "friction coefficients" in res.output
    res = runner.invoke(main, ["calibrate", "--no-confirm", "--free", "washers.nope.mu"])
    assert res.exit_code == 2 and "washers.nope.mu" in res.output
    res = runner.invoke(main, ["calibrate", "--no-confirm", "--target", "7=1.5"])
    assert res.exit_code == 2


def test_shipped_file_states_its_calibration() -> None:
    p, data, _ = read_library_file("torsen-c")
    assert "torsen-c" in shipped_models()
    cal = data["calibration"]
    assert set(cal["fitted"]) == set(FREE)
    assert cal["command"].startswith("drivedyn calibrate torsen-c")
    assert p.washers.sun_coupling.mu == 0.03  # the seeds' value, not fitted
    assert "washers.sun_coupling.mu" not in cal["fitted"]
    assert "pockets.mu" not in cal["fitted"]


def test_load_model_library_file() -> None:
    m = dd.load_model("torsen-c")
    assert m.meta["model_name"] == "torsen-c"
    assert m.meta["scenario"].t_end > 5  # the vehicle profile
    bench = dd.load_model("torsen-c", ["scenario.kind=bench", "scenario.modes=front"])
    assert bench.meta["scenario"].t_end == pytest.approx(3.0)
    with pytest.raises(ModelFileError, match=r"scenario\.kind"):
        dd.load_model("torsen-c", ["scenario.kind=track"])
    with pytest.raises(ModelFileError, match=r"gears\.helx_angle"):
        dd.load_model("torsen-c", ["gears.helx_angle=0.3"])


def test_validation_case_torsen_c() -> None:
    """The full seed protocol: four modes within 5 % of seed 003 Table 1 and within 2 % of
    the analytic model; torque balance of the bench."""
    from drivedyn.validation import run_cases

    results = run_cases(["torsen_c_tdr"])
    assert len(results) == 10
    bad = [r for r in results if not r.passed]
    assert not bad, [(r.quantity, r.reference, r.simulated) for r in bad]
