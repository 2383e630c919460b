"""`drivedyn plot`: the engineering quantities it chooses, their display units (SI prefixes by
magnitude), the dashboards of library models, labels inside the figures, and the command.

Small hand-built Datasets (named and described as the recorder names them) stand in for runs;
the command is checked on a 0.2 s pendulum run.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

from drivedyn.cli import main
from drivedyn.config.loader import read_library_file
from drivedyn.plots.engineering import dashboard_figures, engineering_figures, plot_quantities
from drivedyn.plots.units import angle_scale, pretty_unit, rotating, si_scale

RPM = 60.0 / (2.0 * math.pi)


def _dataset(t: np.ndarray, variables: dict, model_file: dict | None = None) -> xr.Dataset:
    """A results-like Dataset: name -> (values, units, description); 2-D values are
    ``(time, xyz)`` vectors, 3-D ones ``(time, row, col)`` matrices."""
    data = {}
    for name, (values, units, desc) in variables.items():
        v = np.asarray(values, dtype=float)
        dims = {1: ("time",), 2: ("time", "xyz"), 3: ("time", "row", "col")}[v.ndim]
        data[name] = xr.Variable(dims, v, {"units": units, "description": desc})
    attrs = {"model_file": json.dumps(model_file)} if model_file else {}
    return xr.Dataset(data, coords={"time": ("time", t, {"units": "s"}),
                                    "xyz": ("xyz", ["x", "y", "z"])}, attrs=attrs)


def _vec(t: np.ndarray, x=0.0, y=0.0, z=0.0) -> np.ndarray:
    return np.stack([np.broadcast_to(c, t.shape) for c in (x, y, z)], axis=1)


def _body(t: np.ndarray, name: str, pos: np.ndarray, omega: np.ndarray) -> dict:
    rot = np.broadcast_to(np.eye(3), (len(t), 3, 3))
    return {f"{name}.position": (pos, "m", f"position of the centre of mass of {name}"),
            f"{name}.rotation": (rot, "1", f"rotation matrix of {name} (body to global)"),
            f"{name}.angular_velocity": (omega, "rad/s", f"angular velocity of {name}")}


def _energy(t: np.ndarray) -> dict:
    kin = 2.0 + np.sin(t)
    return {"energy.kinetic": (kin, "J", "kinetic energy"),
            "energy.potential": (1.0 - np.sin(t), "J", "potential energy"),
            "energy.work_in": (0.5 * t, "J", "work in"),
            "energy.dissipated": (0.5 * t, "J", "dissipated"),
            "energy.balance_error": (1e-6 * t, "J", "balance error")}


def _lines_of(figs, panel: str) -> tuple[object, list]:
    for _, fig in figs:
        for ax in fig.axes:
            if ax.get_title().split("\n")[0].startswith(panel):
                return ax, ax.get_lines()
    raise AssertionError(f"no panel {panel!r}")


# -- units ---------------------------------------------------------------------------------


@pytest.mark.parametrize("value, unit, scale, shown", [
    (1e-5, "m", 1e6, "µm"),
    (3e-3, "N m", 1e3, "mN m"),
    (2e3, "N", 1e-3, "kN"),
    (4e7, "Pa", 1e-6, "MPa"),
    (0.25, "m/s", 1e3, "mm/s"),
    (50.0, "W", 1.0, "W"),
    (1e-4, "m^2", 1e6, "mm²"),
    (3.0, "kg m^2/s", 1.0, "kg m²/s"),
    (0.3, "1", 1.0, "-"),
])
def test_si_prefix_on_the_first_symbol_by_magnitude(value, unit, scale, shown) -> None:
    got_scale, got_unit = si_scale(np.array([0.0, -value, np.nan, 0.5 * value]), unit)
    assert got_unit == shown
    assert got_scale == pytest.approx(scale, rel=1e-12)


@pytest.mark.parametrize("values", [np.zeros(4), np.array([]), np.full(3, np.nan)])
def test_si_prefix_of_empty_zero_or_nan_data_is_none(values) -> None:
    assert si_scale(values, "N m") == (1.0, "N m")


def test_angles_and_speeds() -> None:
    assert angle_scale(np.array([0.0, 3.0])) == pytest.approx((180.0 / math.pi, "deg"))
    assert angle_scale(np.array([0.0, 200.0])) == pytest.approx((1 / (2 * math.pi), "rev"))
    assert pretty_unit("kg m^2/s") == "kg m²/s"
    t = np.linspace(0.0, 2.0, 201)
    assert rotating(np.full_like(t, 30.0), t)  # a shaft
    assert not rotating(2.0 * np.sin(2 * np.pi * t), t)  # a swinging pendulum
    assert not rotating(np.zeros_like(t), t)


# -- the quantities chosen -----------------------------------------------------------------


def _mechanism(t: np.ndarray) -> xr.Dataset:
    """A slider moving 10 um axially, a spinning shaft, a hinge speeding up from 10 rad/s
    whose angle is recorded wrapped into [-pi, pi], a contact, a still body, the energy
    terms."""
    w = 10.0  # rad/s
    wrapped = np.angle(np.exp(1j * _hinge_angle(t)))
    v = {**_body(t, "slider", _vec(t, 0.1, 0.2, 0.3 + 1e-5 * np.sin(2 * np.pi * t)),
                 _vec(t)),
         **_body(t, "shaft", _vec(t, 1.0, 0.0, 0.0), _vec(t, z=w)),
         **_body(t, "base", _vec(t, 0.0, 0.0, -1.0), _vec(t)),
         "hinge.angle": (wrapped, "rad", "relative rotation of B about the joint axis (hinge)"),
         "hinge.force_x": (2e3 * np.cos(t), "N", "reaction force, global x (hinge)"),
         "hinge.force_y": (1e-12 * np.cos(t), "N", "reaction force, global y (hinge)"),
         "hinge.force_z": (np.zeros_like(t), "N", "reaction force, global z (hinge)"),
         "hinge.torque_x": (3e-3 * np.sin(t), "N m", "reaction torque, global x (hinge)"),
         "hinge.torque_y": (np.zeros_like(t), "N m", "reaction torque, global y (hinge)"),
         "hinge.torque_z": (np.zeros_like(t), "N m", "reaction torque, global z (hinge)"),
         "hinge.power": (np.zeros_like(t), "W", "power supplied by the constraint (hinge)"),
         "stop.gap": (2e-5 * np.cos(t), "m", "gap (plane_contact)"),
         "stop.normal_force": (np.zeros_like(t), "N", "contact force (plane_contact)"),
         "stop.impacts": (np.arange(t.size), "1", "number of contacts started (plane_contact)"),
         "stop.dissipated_power": (np.abs(np.sin(t)), "W", "damping power (plane_contact)"),
         **_energy(t)}
    return _dataset(t, v)


T = np.linspace(0.0, 2.0, 401)


def _hinge_angle(t: np.ndarray) -> np.ndarray:
    return 10.0 * t + 2.0 * t**2  # [rad]: 10 rad/s + 4 rad/s^2 t


def test_a_ten_micrometre_motion_is_drawn_in_micrometres() -> None:
    ds = _mechanism(T)
    q = [q for q in plot_quantities(ds) if q.label == "slider z"]
    assert len(q) == 1 and q[0].display_unit == "µm" and q[0].scale == pytest.approx(1e6)
    ax, lines = _lines_of(engineering_figures(ds), "displacement z")
    z = ds["slider.position"].values[:, 2]
    (line,) = [ln for ln in lines if ln.get_label() == "slider z"]
    np.testing.assert_allclose(line.get_ydata(), 1e6 * (z - z[0]), rtol=1e-12, atol=1e-12)
    assert ax.get_ylabel().endswith("[µm]")
    # only components that move: x and y of the slider and the still body are not drawn
    labels = {q.label for q in plot_quantities(ds) if q.panel.startswith("displacement")}
    assert labels == {"slider z"}


def test_millinewton_metres_and_kilonewtons() -> None:
    ds = _mechanism(T)
    figs = engineering_figures(ds)
    ax, lines = _lines_of(figs, "torque components (global)")
    assert ax.get_ylabel() == "torque [mN m]"
    np.testing.assert_allclose(lines[0].get_ydata(), 1e3 * ds["hinge.torque_x"].values,
                               rtol=1e-12)
    ax, lines = _lines_of(figs, "force components (global)")
    assert ax.get_ylabel() == "force [kN]"
    # the 1e-12 N component is round-off next to 2 kN; zero components are not drawn
    assert [ln.get_label() for ln in lines] == ["hinge x"]
    np.testing.assert_allclose(lines[0].get_ydata(), 1e-3 * ds["hinge.force_x"].values,
                               rtol=1e-12)


def test_no_rotation_matrix_entry_and_no_constant_or_counter_is_drawn() -> None:
    ds = _mechanism(T)
    qs = plot_quantities(ds)
    assert qs and not any(q.variable.endswith(".rotation") for q in qs)
    drawn = {q.variable for q in qs}
    assert not drawn & {"stop.normal_force", "stop.impacts", "hinge.power", "hinge.force_z"}
    assert not any(q.variable.startswith("base.") for q in qs)  # a body that never moves
    for _, fig in engineering_figures(ds):
        for ax in fig.axes:
            texts = [ax.get_title(), ax.get_ylabel(), *(ln.get_label() for ln in ax.lines)]
            assert not any("rotation" in s for s in texts), texts
    # the steady spin is constant: written in the panel's note, not drawn
    spin = [q for q in qs if q.panel == "angular velocity about the spin axis"]
    assert spin == []


def test_a_wrapped_joint_angle_is_unwrapped_and_differentiated() -> None:
    ds = _mechanism(T)
    figs = engineering_figures(ds)
    ax, (angle,) = _lines_of(figs, "angle (unwrapped)")
    y = angle.get_ydata()
    step = np.abs(np.diff(y))
    assert ax.get_ylabel() == "angle [deg]"
    assert step.max() < 0.1 * 360.0  # no 2 pi jump left
    np.testing.assert_allclose(y, np.degrees(_hinge_angle(T)), rtol=1e-9, atol=1e-9)
    ax, (speed,) = _lines_of(figs, "relative speed")
    assert ax.get_ylabel() == "speed [rpm]"  # a part that keeps turning one way
    np.testing.assert_allclose(speed.get_ydata(), (10.0 + 4.0 * T) * RPM, rtol=1e-9)


def test_an_accumulated_angle_is_not_unwrapped() -> None:
    t = np.linspace(0.0, 1.0, 11)
    fast = 400.0 * t  # 4 rad between samples: np.unwrap would take 2 pi off each step
    ds = _dataset(t, {"shaft_bearing.angle": (fast, "rad", "relative rotation of B about the "
                                                            "joint axis (accumulated) (hinge)"),
                      "shaft_bearing.force_x": (np.zeros_like(t), "N", "(hinge)"),
                      "shaft_bearing.torque_x": (np.zeros_like(t), "N m", "(hinge)")})
    (q,) = [q for q in plot_quantities(ds) if q.panel == "angle (unwrapped)"]
    np.testing.assert_array_equal(q.values, fast)
    assert q.display_unit == "rev"


def test_energy_budget_figure() -> None:
    ds = _mechanism(T)
    figs = dict(engineering_figures(ds))
    assert "energy" in figs
    ax, lines = _lines_of(figs.items(), "energy budget")
    by_label = {ln.get_label(): ln.get_ydata() for ln in lines}
    kin = ds["energy.kinetic"].values
    np.testing.assert_allclose(by_label["kinetic T - T0"], kin - kin[0], rtol=1e-12, atol=1e-15)
    assert {"work in W_in", "dissipated D", "potential V - V0"} <= set(by_label)
    ax, _ = _lines_of(figs.items(), "energy balance error")
    assert ax.get_ylabel() == "error [µJ]"
    ax, lines = _lines_of(figs.items(), "dissipated power")
    assert [ln.get_label() for ln in lines] == ["total", "stop"]


def _assert_labels_inside(fig) -> None:
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    box = fig.bbox
    for ax in fig.axes:
        for text in (ax.xaxis.label, ax.yaxis.label, ax.title):
            if not text.get_text():
                continue
            e = text.get_window_extent(renderer)
            assert (e.x0 >= box.x0 - 0.5 and e.x1 <= box.x1 + 0.5 and e.y0 >= box.y0 - 0.5
                    and e.y1 <= box.y1 + 0.5), (text.get_text(), e, box)


def test_axis_labels_lie_inside_the_figures() -> None:
    ds = _mechanism(T)
    long = ds["stop.gap"].attrs | {"units": "m"}
    ds["a_contact_with_a_rather_long_name_indeed.gap"] = ("time", 1e4 * np.cos(T), long)
    for _, fig in engineering_figures(ds) + dashboard_figures(_type_c(np.linspace(0, 0.1, 101))):
        _assert_labels_inside(fig)


# -- dashboards ----------------------------------------------------------------------------


def _type_c(t: np.ndarray, kind: str = "vehicle") -> xr.Dataset:
    """Results of a Type C run with the recorder's names: engine torque ramping to 100 N m,
    the rear output taking 4/5 of it (TDR 4), the sun moving 50 um axially, washers loaded
    to 40 MPa."""
    _, data, _ = read_library_file("torsen-c", ["vehicle.ramp=0.01", "vehicle.hold=0.03",
                                                f'scenario.kind="{kind}"'])
    T_h = 100.0 * np.clip(t / 0.01, 0.0, 1.0)
    v = {"engine_torque.torque_z": (T_h, "N m", "applied torque, global z (torque)"),
         "front_speed.torque": (-0.2 * T_h, "N m", "driver torque (joint_driver)"),
         "rear_speed.torque": (-0.8 * T_h, "N m", "driver torque (joint_driver)"),
         **_body(t, "housing", _vec(t), _vec(t, z=30.0)),
         **_body(t, "sun", _vec(t, z=5e-5 * np.clip(t / 0.01, 0.0, 1.0)), _vec(t, z=31.0)),
         **_body(t, "coupling", _vec(t, z=0.01), _vec(t, z=29.0)),
         **_body(t, "ring", _vec(t, z=0.02), _vec(t, z=29.0)),
         **_energy(t)}
    for w in ("sun_housing", "sun_coupling", "coupling_case", "ring_housing", "ring_case"):
        v[f"{w}.normal_force"] = (4e3 * np.clip(t / 0.01, 0, 1), "N", "(thrust_washer_contact)")
        v[f"{w}.pressure"] = (4e7 * np.clip(t / 0.01, 0, 1), "Pa", "(thrust_washer_contact)")
        v[f"{w}.dissipated_power"] = (np.full_like(t, 1.0), "W", "(thrust_washer_contact)")
    for e in ("planet1_pocket", "sun_planet1", "planet1_ring"):
        v[f"{e}.dissipated_power"] = (np.full_like(t, 2.0), "W", "(journal_contact)")
    return _dataset(t, v, data)


def test_type_c_dashboard_shows_the_tdr_in_its_windows_and_axial_travel_in_um() -> None:
    t = np.linspace(0.0, 0.1, 101)
    ds = _type_c(t)
    figs = dashboard_figures(ds)
    assert [title for title, _ in figs] == [
        "dashboard_torsen_c: torques and speeds",
        "dashboard_torsen_c: axial motion, thrust washers and losses"]
    ax, (tdr,) = _lines_of(figs, "torque distribution ratio")
    y = tdr.get_ydata()
    loaded = 100.0 * np.clip(t / 0.01, 0.0, 1.0) >= 5.0
    np.testing.assert_allclose(y[loaded], 4.0, rtol=1e-12)
    assert np.isnan(y[~loaded]).all()
    # the levels held within 0.1 s: windows [0.022, 0.04] and [0.062, 0.08] s, means 4.00
    assert len(ax.patches) == 2
    assert sum("4.00" in tx.get_text() for tx in ax.texts) == 2
    ax, lines = _lines_of(figs, "axial travel")
    assert ax.get_ylabel() == "travel [µm]"
    sun = next(ln for ln in lines if ln.get_label() == "sun")
    np.testing.assert_allclose(sun.get_ydata(), 5e1 * np.clip(t / 0.01, 0, 1), rtol=1e-12)
    ax, _ = _lines_of(figs, "thrust washers: mean pressure")
    assert ax.get_ylabel() == "pressure [MPa]"
    ax, lines = _lines_of(figs, "speeds")
    assert ax.get_ylabel() == "speed [rpm]"
    np.testing.assert_allclose(lines[1].get_ydata(), 31.0 * RPM, rtol=1e-12)
    ax, lines = _lines_of(figs, "dissipated power by element group")
    got = {ln.get_label(): ln.get_ydata()[-1] for ln in lines}
    assert got == pytest.approx({"thrust washers": 5.0, "pockets": 2.0, "gear meshes": 4.0,
                                 "total": 11.0})


def test_bench_dashboard_marks_the_measured_tdr() -> None:
    t = np.linspace(0.0, 3.0, 301)
    ds = _type_c(t, kind="bench")
    s = np.clip(t / 0.3, 0.0, 1.0)
    ds["applied_torque.torque_z"] = ("time", -125.0 * s, {"units": "N m"})
    ds["speed_control.torque"] = ("time", 125.0 / 3.0 * s, {"units": "N m"})
    figs = dashboard_figures(ds)
    ax, (tdr,) = _lines_of(figs, "torque distribution ratio")
    np.testing.assert_allclose(tdr.get_ydata()[t > 0.1], 3.0, rtol=1e-12)
    texts = " ".join(tx.get_text() for tx in ax.texts)
    # the rear side runs modes 1 and 2; the file's measured TDRs are 4.02 and 2.82
    assert "mode 1" in texts and "meas. 4.02" in texts and "mode 2" in texts
    assert "3.00" in texts


def test_vehicle_dashboard_shows_wheel_torques_splits_and_ratios() -> None:
    t = np.linspace(0.0, 3.0, 301)
    _, data, _ = read_library_file("vehicle-4wd")
    ramp = np.clip(t / 0.3, 0.0, 1.0)
    drive = {"fl": 10.0, "fr": 30.0, "rl": 20.0, "rr": 40.0}  # [N m] when ramped up
    v = {f"halfshaft_{w}.torque": (-d * ramp, "N m", "(torsional_spring_damper)")
         for w, d in drive.items()}
    v |= {f"tyre_{w}.kappa": (0.02 * ramp, "1", "(tyre)") for w in drive}
    v |= {f"wheel_{w}.angular_velocity": (_vec(t, y=10.0 * t), "rad/s", "") for w in drive}
    v |= {"body.velocity": (_vec(t, x=3.0 * t), "m/s", ""),
          "prop_front_spring.torque": (-20.0 * ramp, "N m", ""),
          "prop_rear_spring.torque": (-30.0 * ramp, "N m", "")}
    figs = dashboard_figures(_dataset(t, v, data))
    assert [title for title, _ in figs] == ["dashboard_vehicle_4wd: wheels and torque split",
                                            "dashboard_vehicle_4wd: driveline and tyres"]
    ax, lines = _lines_of(figs, "torque splits")
    assert ax.get_ylabel() == "share [%]"
    front = {ln.get_label(): ln.get_ydata()[-1] for ln in lines}
    assert front == pytest.approx({"front / total": 40.0, "left / front axle": 25.0,
                                   "left / rear axle": 100.0 / 3.0})
    ax, lines = _lines_of(figs, "torque ratios")
    assert {ln.get_label(): ln.get_ydata()[-1] for ln in lines} == pytest.approx(
        {"central (propeller shafts)": 1.5, "front axle": 3.0, "rear axle": 2.0})
    assert len(ax.patches) == 1  # the analysis window run.window = [2, 3] s
    ax, _ = _lines_of(figs, "tyre longitudinal slip")
    assert ax.get_ylabel() == "slip [%]"
    ax, (fl, *_) = _lines_of(figs, "wheel drive torques")
    np.testing.assert_allclose(fl.get_ydata(), 10.0 * ramp, rtol=1e-12)


def test_no_dashboard_for_a_plain_mechanism() -> None:
    assert dashboard_figures(_mechanism(T)) == []


# -- the command ---------------------------------------------------------------------------


def test_plot_command_writes_the_engineering_figures(tmp_path: Path) -> None:
    runner = CliRunner()
    res = runner.invoke(main, ["run", "pendulum", "--t-end", "0.2", "--out",
                               str(tmp_path / "p.nc")])
    assert res.exit_code == 0, res.output
    res = runner.invoke(main, ["plot", str(tmp_path / "p.nc"), "--out", str(tmp_path / "f")])
    assert res.exit_code == 0, res.output
    written = sorted(p.name for p in (tmp_path / "f").iterdir())
    assert written == ["bodies.png", "energy.png", "joints.png"]
    assert res.output.split() == [str(tmp_path / "f" / n) for n in
                                  ("energy.png", "bodies.png", "joints.png")]
    assert all((tmp_path / "f" / n).stat().st_size > 10_000 for n in written)
    res = runner.invoke(main, ["plot", str(tmp_path / "p.nc"), "--vars", "rod.*", "--out",
                               str(tmp_path / "g")])
    assert res.exit_code == 0, res.output
    assert sorted(p.name for p in (tmp_path / "g").iterdir()) == ["bodies.png"]
    res = runner.invoke(main, ["plot", str(tmp_path / "p.nc"), "--vars", "rod.rotation",
                               "--out", str(tmp_path / "h")])
    assert res.exit_code == 2 and "rotation matrices" in res.output
    assert not (tmp_path / "h").exists()
