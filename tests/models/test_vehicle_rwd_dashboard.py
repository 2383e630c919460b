"""The RWD vehicle's dashboard: ``drivedyn vehicle vehicle-rwd --out`` writes it beside the
results, and the figure ``drivedyn plot`` draws from a result has the named panels with
their data. One short launch (0.1 s, the open differential) serves both tests."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

from drivedyn.cli import main
from drivedyn.library.dashboards import Curve, Term
from drivedyn.library.vehicles.vehicle_rwd.dashboard import TITLES
from drivedyn.plots.dashboard import curve_values, declared_dashboard, window_mean
from drivedyn.plots.engineering import dashboard_figures


@pytest.fixture(scope="module")
def launch(tmp_path_factory):
    """(output folder, dataset) of a 0.1 s launch through the command line."""
    out = tmp_path_factory.mktemp("rwd")
    r = CliRunner().invoke(main, [
        "vehicle", "vehicle-rwd", "--compare", "open", "--t-end", "0.1", "--json",
        "--set", "run.window=[0.05, 0.1]", "--set", 'engine.ramp="0.05 s"',
        "--out", str(out)])
    assert r.exit_code in (0, 1), r.output  # a 0.1 s launch may fail the open check
    assert json.loads(r.stdout)["runs"][0]["configuration"] == "open"
    with xr.open_dataset(out / "vehicle-rwd-open.nc") as ds:
        return out, ds.load()


def test_out_writes_the_dashboard_beside_the_results(launch):
    """Mutation: drop the dashboard's ``outputs.write`` in ``cli/vehicle_rwd.py`` -> no PNG
    beside the .nc."""
    out, _ = launch
    png = out / "vehicle-rwd-open-dashboard.png"
    assert png.exists() and png.stat().st_size > 50_000
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_dashboard_has_the_named_panels_with_their_data(launch):
    """The run's attributes name its library model, whose dashboard is one figure of nine
    panels with their curves: the rear wheel torques with the window, wheel speeds, slips,
    tyre forces and loads, speed, yaw rate, path and frame stresses.

    Mutations: sum the stresses over the elements instead of taking the largest
    (``reduce="sum"``) -> the rails' curve is far above every element's own stress; draw
    the path against time -> its x axis is not the body's x; drop a panel -> the titles
    differ."""
    _, ds = launch
    assert ds.attrs["library_model"] == "vehicle_rwd"
    figs = dashboard_figures(ds)
    assert len(figs) == 1
    title, fig = figs[0]
    assert title == "dashboard_vehicle_rwd: split-mu launch"
    titles = [ax.get_title().strip() for ax in fig.axes]
    assert titles == list(TITLES)
    panels = {ax.get_title().strip(): ax for ax in fig.axes}
    torques = panels["rear wheel drive torques"]
    assert {ln.get_label() for ln in torques.get_lines()} >= {"rear left (road 0.1)",
                                                             "rear right (road 1)"}
    for name in ("wheel speeds", "tyre longitudinal slip", "tyre longitudinal forces",
                 "tyre vertical loads"):
        assert len([ln for ln in panels[name].get_lines()
                    if not ln.get_label().startswith("_")]) == 4, name
    # the path: y against the body's x (the mean of its carriers), the start dotted
    dash = declared_dashboard(ds)
    path = next(p for p in dash.pages[0].panels if p.title == "path")
    x, _ = curve_values(ds, path.abscissa.curve)
    carriers = [n for n in ds.data_vars if str(n).startswith("frame.body.")
                and str(n).endswith(".position")]
    assert len(carriers) == 8
    mean_x = np.mean([ds[n].values[:, 0] for n in carriers], axis=0)
    assert np.allclose(x, mean_x)
    line = panels["path"].get_lines()[0]
    assert np.allclose(line.get_xdata(), mean_x * 1e3) or np.allclose(line.get_xdata(), mean_x)
    # frame stresses: the largest element stress at each time, in MPa on the axis
    rails = [n for n in ds.data_vars if str(n).startswith(("frame.left.", "frame.right."))
             and str(n).endswith(".von_mises")]
    peak = np.max([ds[n].values for n in rails], axis=0)
    v, _ = curve_values(ds, Curve("rails", (Term("frame.[lr]*.von_mises", reduce="max"),)))
    assert np.array_equal(v, peak) and 1e6 < peak.max() < 355e6
    stress_lines = {ln.get_label(): ln for ln in panels["frame stresses (peak von Mises)"]
                    .get_lines()}
    assert np.allclose(stress_lines["rails"].get_ydata(), peak / 1e6)
    assert "MPa" in panels["frame stresses (peak von Mises)"].get_ylabel()
    # the window mean of the torques is drawn (the run covers the window)
    window = dash.pages[0].panels[0].windows[0]
    m = window_mean(ds["time"].values, ds, dash.pages[0].panels[0].curves[0],
                    [str(n) for n in ds.data_vars], window)
    assert m is not None and np.isfinite(m) and window.t1 == pytest.approx(0.1)
