"""`drivedyn report`: the HTML run report has every section the issue lists, with the run's
own figures."""

from __future__ import annotations

import json
import re

import pytest
import xarray as xr
from click.testing import CliRunner

from drivedyn.cli import main
from drivedyn.report import SECTIONS


def _section(text: str, key: str) -> str:
    m = re.search(rf'<section id="{key}">(.*?)</section>', text, re.S)
    assert m, f"section {key} missing"
    return m.group(1)


@pytest.fixture(scope="module")
def pendulum_run(tmp_path_factory) -> str:
    out = tmp_path_factory.mktemp("report") / "p.nc"
    r = CliRunner().invoke(main, ["run", "pendulum", "--t-end", "0.5", "--out", str(out)])
    assert r.exit_code == 0, r.output
    return str(out)


def test_report_has_every_section_with_the_run_figures(pendulum_run, tmp_path) -> None:
    out = tmp_path / "p-report.html"
    r = CliRunner().invoke(main, ["report", pendulum_run, "--out", str(out)])
    assert r.exit_code == 0, r.output
    text = out.read_text()
    for key in SECTIONS:
        _section(text, key)
    with xr.open_dataset(pendulum_run) as ds:
        stats = json.loads(ds.attrs["stats"])
        summary = json.loads(ds.attrs["model_summary"])
        balance = float(ds["energy.balance_error"].values[-1])
    model = _section(text, "model")
    assert summary == {"bodies": 1, "nodes": 0, "coordinates": 6, "multipliers": 5,
                       "equations": 11, "internal_states": 2,  # hinge: turn, slip
                       "elements": {"rigid_body": {"count": 1, "names": ["rod"]},
                                    "hinge": {"count": 1, "names": ["hinge"]}}}
    assert "<td>hinge</td><td>1</td>" in model and "<td>rigid bodies</td><td>1</td>" in model
    solver = _section(text, "solver")
    assert f"<td>steps accepted</td><td>{stats['steps']}</td>" in solver
    assert f"{stats['newton_iterations']} (" in solver
    assert f"<td>factorizations</td><td>{stats['factorizations']}</td>" in solver
    assert "wall time" in solver
    energy = _section(text, "energy")
    assert f"{balance:.4g} J" in energy and "Balance error relative" in energy
    assert "<img" in _section(text, "plots")  # engineering plots embedded as PNG
    assert "data:image/png;base64," in text
    view = _section(text, "view")
    link = re.search(r'href="([^"]+)"', view).group(1)
    assert (tmp_path / link).is_file() and link == "p-view.html"


def test_report_without_view_and_bad_input(pendulum_run, tmp_path) -> None:
    out = tmp_path / "new" / "r.html"  # folders are made
    r = CliRunner().invoke(main, ["report", pendulum_run, "--out", str(out), "--no-view"])
    assert r.exit_code == 0, r.output
    assert "No 3-D view was written" in _section(out.read_text(), "view")
    assert not list(tmp_path.glob("**/*view.html"))
    bad = tmp_path / "bad.nc"
    bad.write_text("no")
    r = CliRunner().invoke(main, ["report", str(bad)])
    assert r.exit_code == 2 and "not a drivedyn results file" in r.output


def test_report_of_a_differential_has_its_dashboard(tmp_path) -> None:
    run = tmp_path / "tc.nc"
    r = CliRunner().invoke(main, ["run", "torsen-c", "--t-end", "0.01", "--out", str(run)])
    assert r.exit_code == 0, r.output
    out = tmp_path / "tc-report.html"
    r = CliRunner().invoke(main, ["report", str(run), "--out", str(out), "--no-view"])
    assert r.exit_code == 0, r.output
    dash = _section(out.read_text(), "dashboard")
    assert dash.count("<img") >= 1
