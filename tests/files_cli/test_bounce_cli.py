"""``drivedyn bounce`` (the seeds' bouncing-ball benchmark) and the contact validation cases
of ``drivedyn validate``."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from click.testing import CliRunner

from drivedyn.cli import main
from drivedyn.elements.contact.impact_laws import damping_factor, restitution_from_chi
from drivedyn.validation import base

CONTACT_CASES = ("bouncing_ball", "restitution_laws", "contact_friction", "thrust_washer",
                 "squeeze_film")


def test_bounce_json_defaults(runner: CliRunner) -> None:
    res = runner.invoke(main, ["bounce", "--json", "--t-end", "1.5"])
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    for key in ("law", "e_target", "apex_heights", "restitution", "steps", "wall_s"):
        assert key in out
    assert out["law"] == "lankarani-nikravesh"
    assert out["e_target"] == 0.8
    assert len(out["restitution"]) == 2  # impacts at 0.447 s and 1.163 s
    e_pred = restitution_from_chi(0.75 * (1 - 0.64))
    for e in out["restitution"]:
        assert e == pytest.approx(e_pred, abs=3e-4)
    assert out["apex_heights"][0] == pytest.approx(e_pred**2, rel=1e-3)
    assert out["steps"] > 100 and out["wall_s"] > 0
    assert out["impact_speeds"][0] == pytest.approx(math.sqrt(20.0), rel=1e-12)


@pytest.mark.parametrize("law", ["hunt-crossley", "flores", "gonthier", "hu-guo", "exact"])
def test_bounce_laws_and_options(runner: CliRunner, law: str) -> None:
    args = ["bounce", "--json", "--law", law, "--e", "0.5", "--n", "1.0", "--k", "1e8",
            "--mass", "2", "--h0", "0.2", "--gravity", "9.81", "--t-end", "0.5"]
    res = runner.invoke(main, args)
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert out["law"] == law and out["e_target"] == 0.5
    e_pred = restitution_from_chi(damping_factor(law, 0.5))
    assert out["restitution"][0] == pytest.approx(e_pred, abs=1e-3)
    assert out["impact_speeds"][0] == pytest.approx(math.sqrt(2 * 9.81 * 0.2), rel=1e-10)


def test_bounce_table_and_plot(runner: CliRunner, tmp_path: Path) -> None:
    png = tmp_path / "fig" / "bounce.png"
    res = runner.invoke(main, ["bounce", "--t-end", "1.5", "--plot", str(png)])
    assert res.exit_code == 0, res.output
    assert "restitution" in res.stdout and "steps" in res.stdout and "wall time" in res.stdout
    assert "0.847102" in res.stdout  # the exact relation's prediction for chi = 0.27
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("args", [["--law", "hertz"], ["--e", "1.0"], ["--e", "0"],
                                  ["--k", "-1"], ["--n", "0.5"], ["--mass", "0"],
                                  ["--t-end", "abc"]])
def test_bounce_bad_input_exits_2(runner: CliRunner, args: list[str]) -> None:
    res = runner.invoke(main, ["bounce", *args])
    assert res.exit_code == 2


def test_bounce_help(runner: CliRunner) -> None:
    res = runner.invoke(main, ["bounce", "--help"])
    assert res.exit_code == 0
    for opt in ("--law", "--e", "--n", "--k", "--mass", "--h0", "--gravity", "--t-end",
                "--json"):
        assert opt in res.stdout


@pytest.mark.parametrize("name", CONTACT_CASES)
def test_contact_validation_cases_pass(name: str) -> None:
    results = base.CASES[name](quick=True, figure_dir=None)
    assert results
    for r in results:
        assert r.source and r.tolerance > 0
    failed = [f"{r.quantity}: ref {r.reference}, sim {r.simulated}, err {r.error:.3g} "
              f"(tol {r.tolerance:g})" for r in results if not r.passed]
    assert not failed, failed


def test_validate_bouncing_ball_writes_the_figure(runner: CliRunner, tmp_path: Path) -> None:
    res = runner.invoke(main, ["validate", "--quick", "--case", "bouncing_ball", "--report",
                               str(tmp_path)])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "bouncing_ball.png").exists()
    assert "bouncing_ball.png" in (tmp_path / "report.md").read_text()
