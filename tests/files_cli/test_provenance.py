"""Every command that writes a library model's results records where they come from, so the
report and the plots of the file find the library model's dashboard and name the
configuration that ran: ``run`` (a differential, the 4WD vehicle), ``vehicle``, ``tdr
--out`` and a sweep's ``--keep-runs`` points (scenario runs and bench runs).

Each case runs the command cheaply (a few ms simulated, or one bench side), writes the
report and checks (a) the dashboard section holds the figures of the library model's
dashboard (``dashboard_<library>: <page>`` captions, one per page), (b) the model section
names the library model and the configuration, (c) ``drivedyn plot`` writes the dashboard
pages. Mutations that fail them: drop :func:`~drivedyn.results.provenance.record_provenance`
from a command's path (the report says "no library model with a dashboard"); record the
scenario's parameters instead of the bench side's for ``tdr --out`` (the bench dashboard's
windows and loaded side are lost: the configuration check fails); pass no ``run_file`` to
the sweep's tasks (no point files).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
import xarray as xr
from click.testing import CliRunner

from drivedyn.cli import main

DASHBOARD_PAGES = {
    "torsen_b": ("torques and speeds", "axial motion, thrust washers and losses"),
    "vehicle_4wd": None,  # any page: the vehicle's pages are checked in test_vehicle_4wd
}


def _invoke(args: list[str], codes: tuple[int, ...] = (0,)) -> str:
    r = CliRunner().invoke(main, args)
    assert r.exit_code in codes, (args, r.output)
    assert "Traceback" not in r.output
    return r.output


def _dashboard_captions(report: Path) -> list[str]:
    page = report.read_text(encoding="utf-8")
    m = re.search(r'<section id="dashboard">(.*?)</section>', page, re.S)
    assert m, "report without a dashboard section"
    return re.findall(r"<figcaption>([^<]*)</figcaption>", m.group(1))


def _check(nc: Path, library: str, configuration: str, tmp_path: Path) -> None:
    with xr.open_dataset(nc) as ds:
        attrs = dict(ds.attrs)
    assert attrs["library_model"] == library
    assert attrs["configuration"] == configuration
    assert json.loads(attrs["model_file"])["model"]["library"] == library
    report = tmp_path / (nc.stem + "-report.html")
    _invoke(["report", str(nc), "--out", str(report), "--no-view"])
    captions = _dashboard_captions(report)
    wanted = DASHBOARD_PAGES[library]
    assert captions, f"{nc.name}: no dashboard figure in the report"
    assert all(c.startswith(f"dashboard_{library}: ") for c in captions), captions
    if wanted:
        assert {c.split(": ", 1)[1] for c in captions} == set(wanted), captions
    page = report.read_text(encoding="utf-8")
    assert f"<td>library model</td><td>{library}</td>" in page
    assert f"<td>configuration</td><td>{configuration}</td>" in page
    figs = tmp_path / (nc.stem + "-figs")
    _invoke(["plot", str(nc), "--out", str(figs)])
    assert list(figs.glob(f"dashboard_{library}_*.png")), sorted(figs.iterdir())


def test_run_of_a_differential_and_of_the_vehicle(tmp_path: Path) -> None:
    """``drivedyn run`` of a differential file (its vehicle-configuration scenario) and of
    the 4WD vehicle file."""
    nc = tmp_path / "tb.nc"
    _invoke(["run", "torsen-b", "--t-end", "0.005", "--out", str(nc)])
    _check(nc, "torsen_b", "vehicle configuration", tmp_path)
    nc = tmp_path / "v.nc"
    _invoke(["run", "vehicle-4wd", "--t-end", "0.005", "--out", str(nc)])
    _check(nc, "vehicle_4wd", "torsen", tmp_path)


def test_vehicle_command(tmp_path: Path) -> None:
    """``drivedyn vehicle --compare open --out DIR``: one file per configuration. Over a
    10 ms launch the vehicle's checks (a steady split-mu window) need not hold: exit 1 is
    allowed, the file is written either way."""
    _invoke(["vehicle", "--compare", "open", "--set", "run.window=[0.0,0.01]",
             "--t-end", "0.01", "--out", str(tmp_path)], codes=(0, 1))
    _check(tmp_path / "vehicle-4wd-open.nc", "vehicle_4wd", "open", tmp_path)


def test_tdr_out_writes_each_bench_run(tmp_path: Path) -> None:
    """``drivedyn tdr torsen-b --mode 1 --out DIR``: the right-hand bench run, recorded with
    the bench scenario on that side (its dashboard is the bench's: applied and resistant
    torques, the TDR windows of modes 1 and 2)."""
    out = _invoke(["tdr", "torsen-b", "--mode", "1", "--out", str(tmp_path)])
    nc = tmp_path / "torsen-b-bench-right.nc"
    assert f"results: {nc}" in out
    _check(nc, "torsen_b", "bench, torque on the right output (modes 1, 2)", tmp_path)
    with xr.open_dataset(nc) as ds:
        data = json.loads(ds.attrs["model_file"])
    assert data["scenario"] == {"kind": "bench", "modes": "right"}


@pytest.mark.slow
def test_sweep_keeps_the_points_runs(tmp_path: Path) -> None:
    """``drivedyn sweep --keep-runs DIR``: scenario runs (``point-NNNN.nc``) and bench runs
    (``point-NNNN-<side>.nc``), each with its point's overrides; a rerun from the cache
    writes the files again when they were deleted."""
    runs = tmp_path / "runs"
    _invoke(["sweep", "torsen-b", "--vary", "pockets.mu=0.10,0.14", "--t-end", "0.005",
             "--scheduler", "serial", "--out", str(tmp_path / "s.nc"), "--keep-runs",
             str(runs)])
    listed = json.loads((runs / "points.json").read_text())
    assert [p["file"] for p in listed] == ["point-0000", "point-0001"]
    with xr.open_dataset(runs / "point-0001.nc") as ds:
        assert json.loads(ds.attrs["overrides"]) == ["pockets.mu=0.14"]
    _check(runs / "point-0001.nc", "torsen_b", "vehicle configuration", tmp_path)
    (runs / "point-0000.nc").unlink()
    out = _invoke(["sweep", "torsen-b", "--vary", "pockets.mu=0.10,0.14", "--t-end", "0.005",
                   "--scheduler", "serial", "--out", str(tmp_path / "s.nc"), "--keep-runs",
                   str(runs)])
    assert "1 computed, 1 from the cache" in out and (runs / "point-0000.nc").exists()
    bench = tmp_path / "bench"
    _invoke(["sweep", "torsen-b", "--tdr", "--mode", "1", "--vary", "pockets.mu=0.12",
             "--scheduler", "serial", "--out", str(tmp_path / "t.nc"), "--keep-runs",
             str(bench)])
    _check(bench / "point-0000-right.nc", "torsen_b",
           "bench, torque on the right output (modes 1, 2)", tmp_path)
