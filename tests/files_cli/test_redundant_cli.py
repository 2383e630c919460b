"""A model file with redundant joint rows runs from the command line and says which rows it
set aside (``drivedyn run``: the text summary, the JSON summary and the results file)."""

from __future__ import annotations

import json

import xarray as xr
from click.testing import CliRunner

from drivedyn.cli import main
from files_cli.test_malformed_input import BASE

# the pendulum with a second hinge on the same axis, 0.1 m along it: its 5 rows repeat the
# first hinge's (a door on two hinges)
TWO_HINGES = BASE + """
[[markers]]
name = "pivot2"
body = "ground"
position = [0, "0.1 m", 0]
axis = [0, 1, 0]

[[markers]]
name = "rod_end2"
body = "rod"
position = [0, "0.1 m", 0]
axis = [0, 1, 0]

[[elements]]
type = "Hinge"
name = "hinge2"
marker_a = "pivot2"
marker_b = "rod_end2"
"""


def test_run_reports_the_rows_set_aside(tmp_path):
    """A pendulum hung on two coaxial hinges (10 rows, 5 independent) runs; the JSON
    summary lists the 5 rows set aside, the text summary names them, the results file
    keeps them, and the swing equals the one-hinge pendulum's. Fails if the rows are not
    set aside (exit 2: singular initial accelerations) or not reported."""
    two, one = tmp_path / "two.toml", tmp_path / "one.toml"
    two.write_text(TWO_HINGES)
    one.write_text(BASE)
    runner = CliRunner()
    res = runner.invoke(main, ["run", str(two), "--out", str(tmp_path / "two.nc"), "--json"])
    assert res.exit_code == 0, res.output
    summary = json.loads(res.output.strip().splitlines()[-1])
    assert len(summary["redundant_constraints"]) == 5
    assert all(r.startswith("hinge hinge") for r in summary["redundant_constraints"])
    text = runner.invoke(main, ["run", str(two), "--out", str(tmp_path / "t.nc")])
    assert "5 redundant constraint row(s) set aside" in text.output
    assert runner.invoke(main, ["run", str(one), "--out", str(tmp_path / "one.nc")]
                         ).exit_code == 0
    with xr.open_dataset(tmp_path / "two.nc") as a, xr.open_dataset(tmp_path / "one.nc") as b:
        assert len(a.attrs["redundant_constraints"].split("; ")) == 5
        assert abs(a["rod.position"].values - b["rod.position"].values).max() < 1e-12
