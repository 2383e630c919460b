"""The differentials with flexible washers (``[flexible] washers = true``): the parts are built
where the rigid washers are, impossible combinations are refused by key, and the friction
radius correction of the flexible validation is an identity when nothing moves. The bench
figures themselves (flexible against rigid) are the validation cases ``torsen_b_flexible``
and ``torsen_c_flexible``."""

from __future__ import annotations

import numpy as np
import pytest

from drivedyn.model.compile import compile_model


def test_torsen_b_flexible_washers_sit_where_the_rigid_ones_are():
    """Each flexible washer's face (mounting marker + thickness along the washer normal) is
    the rigid washer face, on the same body, and the counter faces are unchanged. Seen to
    fail: the mounting marker placed at the face (no thickness offset) puts every face 2 mm
    into its gear."""
    from drivedyn.config import read_library_file
    from drivedyn.library.differentials import get
    from drivedyn.library.differentials.scenarios import bench_spec
    from drivedyn.library.differentials.torsen_b.model import WASHERS

    rigid, _, _ = read_library_file("torsen-b")
    flex, _, _ = read_library_file("torsen-b", ["flexible.washers=true",
                                                "flexible.washer_cells=[1, 12]"])
    sr, _ = bench_spec(get("torsen_b"), rigid, "right")
    sf, _ = bench_spec(get("torsen_b"), flex, "right")
    t = flex.flexible.washer_thickness
    for name in WASHERS:
        a, b = sr.markers[f"w_{name}"], sf.markers[f"w_{name}"]
        normal = a.rotation[:, 2]
        assert b.body == a.body
        np.testing.assert_allclose(b.position + t * normal, a.position, atol=1e-15)
        fr, ff = sr.markers[f"f_{name}"], sf.markers[f"f_{name}"]
        assert ff.body == fr.body
        np.testing.assert_allclose(ff.position, fr.position, atol=1e-15)
    model = compile_model(sf)
    parts = {n for g in model.groups if g.family == "flexible_body" for n in g.names}
    assert parts == {f"washer_{n}" for n in WASHERS}
    contacts = {n for g in model.groups if g.family == "flexible_washer_contact"
                for n in g.names}
    assert contacts == set(WASHERS)
    # each washer: 2 fixed-interface modes, 4 normal and 1 friction pattern
    assert all(p.nq == 2 + 4 + 1 for g in model.groups for p in g.extra.get("parts", ()))


@pytest.mark.slow
def test_face_quadrature_default_resolves_the_washer_load():
    """The default contact rule of the flexible washers (``face_quadrature = [2, 6]``: 2 Gauss
    radii per radial cell, 6 angles) gives the figures of four times the angles on a Type B
    bench side: both TDRs within 1e-5, each washer's largest von Mises stress and largest
    contact pressure within 1e-4 (measured: 3e-6, and the same to five digits). Seen to fail
    with one radius per cell (``[1, 6]``: TDRs -0.03 / -0.07 %, stresses -11 %)."""
    from drivedyn.analysis.tdr import run_bench
    from drivedyn.config import read_library_file
    from drivedyn.library.differentials.schema_sections import FlexibleWashers
    from drivedyn.library.differentials.torsen_b.model import WASHERS

    assert FlexibleWashers().face_quadrature == (2, 6)
    figures = []
    for extra in ([], ["flexible.face_quadrature=[2, 24]"]):
        p, _, _ = read_library_file("torsen-b", ["flexible.washers=true", *extra])
        run = run_bench(p, "right")
        assert run.success, run.message
        res = run.results
        figures.append(([run.tdr[1], run.tdr[2]],
                        [res.values(f"washer_{w}.max_von_mises").max() for w in WASHERS],
                        [res.values(f"{w}.max_pressure").max() for w in WASHERS]))
    (tdr, vm, pmax), (tdr_f, vm_f, pmax_f) = figures
    np.testing.assert_allclose(tdr, tdr_f, rtol=1e-5)
    np.testing.assert_allclose(vm, vm_f, rtol=1e-4)
    np.testing.assert_allclose(pmax, pmax_f, rtol=1e-4)


@pytest.mark.parametrize(("sets", "message"), [
    (["flexible.washers=true", "flexible.washer_thickness=\"4 mm\""],
     r"flexible\.washer_thickness.*must fit between the side gears"),
    (["flexible.washers=true", "washers.squeeze_film=true"],
     r"washers\.squeeze_film.*not coupled to a flexible washer"),
    (["flexible.friction_patterns=2"], r"flexible\.friction_patterns"),
    (["flexible.washer_cells=[1, 4]"], r"n_theta >= 6"),
])
def test_torsen_b_flexible_refusals(sets, message):
    """Impossible flexible parameters: exit code 2, the key named, no traceback."""
    import re

    from click.testing import CliRunner

    from drivedyn.cli import main

    args = ["tdr", "torsen-b", "--analytic-only"]
    for s in sets:
        args += ["--set", s]
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 2, r.output
    assert re.search(message, r.output, re.S) and "Traceback" not in r.output, r.output


def test_radius_correction_is_the_analytic_model_with_moved_radii():
    """Unmoved radii give the rigid TDR back exactly; moving the case washer's radius by 20 %
    gives the analytic TDR with that washer's coefficient raised by 20 % (a friction torque
    is mu F r), times the rigid/analytic ratio. Seen to fail: the ratio inverted
    (``r_rigid / r_flex``) lowers mode 4 instead of raising it."""
    from drivedyn.config import read_library_file
    from drivedyn.library.differentials.torsen_c.analytic import bench_tdr
    from drivedyn.validation.flexible_torsen import radius_corrected_tdr

    p, _, _ = read_library_file("torsen-c")
    radii = {"coupling_case": 0.0331, "sun_coupling": 0.02}
    assert radius_corrected_tdr(p, 4, 1.7, radii, radii) == 1.7
    moved = dict(radii, coupling_case=0.0331 * 1.2)
    w3 = p.washers.coupling_case
    q = p.model_copy(update={"washers": p.washers.model_copy(update={
        "coupling_case": w3.model_copy(update={"mu": 1.2 * w3.mu})})})
    got = radius_corrected_tdr(p, 4, 1.7, radii, moved)
    assert got == pytest.approx(1.7 * bench_tdr(q, 4) / bench_tdr(p, 4), rel=1e-12)
    assert got > 1.7 * 1.02  # W3 carries the coast load of mode 4


def test_torsen_c_shafts_carry_the_outputs_to_their_bearings():
    """``flexible.shafts``: each output gear keeps its own bearing (``*_support``) and a beam
    shaft runs to the bearing the bench and the vehicle drive (``*_bearing``) and to the
    loaded marker, at the shaft's end. Seen to fail: the driver left on the gear's own
    bearing (the shaft would carry no torque, and the shaft stress check would read 0)."""
    from drivedyn.config import read_library_file
    from drivedyn.library import differentials
    from drivedyn.library.differentials.scenarios import bench_spec

    p, _, _ = read_library_file("torsen-c", ["flexible.shafts=true"])
    diff = differentials.of(p)
    sp, _ = bench_spec(diff, p, "rear")
    joints = {e.name: e for e in sp.elements}
    fx = p.flexible
    for o, shaft, sign in zip(diff.outputs, (fx.shaft_front, fx.shaft_rear), (-1, 1),
                              strict=True):
        bearing = joints[o.bearing]
        tip = f"{o.body}_shaft.n{shaft.elements}"
        assert sp.markers[bearing.marker_b].body == tip
        assert sp.markers[o.marker].body == tip
        assert sp.markers[joints[f"{o.body}_support"].marker_b].body == o.body
        ground = sp.markers[bearing.marker_a].position
        z0 = sp.bodies[o.body].position[2] if o.body in sp.bodies else 0.0
        assert ground[2] == pytest.approx(z0 + sign * shaft.length)
        beams = [e for e in sp.elements if e.name.startswith(f"{o.body}_shaft.e")]
        assert len(beams) == shaft.elements
    # torque on the rear: the bench drives the front output's speed at its shaft's end
    assert joints["speed_control"].joint == "sun_bearing"


def test_dashboard_has_the_stresses_of_the_flexible_parts():
    """A model with flexible parts gets a third dashboard page: the case, the washers and
    each shaft's largest von Mises stress, and the shafts' torques; a rigid one does not."""
    from drivedyn.config import read_library_file
    from drivedyn.library import differentials
    from drivedyn.library.differentials.dashboard import differential_dashboard

    rigid, _, _ = read_library_file("torsen-c")
    diff = differentials.of(rigid)
    assert len(differential_dashboard(diff, rigid).pages) == 2
    flex, _, _ = read_library_file("torsen-c", ["flexible.shafts=true", "flexible.case=true",
                                                "flexible.washers=true"])
    page = differential_dashboard(diff, flex).pages[2]
    stress = page.panels[0]
    patterns = [t.pattern for c in stress.curves for t in c.terms]
    assert patterns == ["case.max_von_mises", "washer_*.max_von_mises",
                        "sun_shaft.e*.von_mises", "coupling_shaft.e*.von_mises"]
    assert all(t.reduce == "max" for c in stress.curves for t in c.terms)
    b, _, _ = read_library_file("torsen-b", ["flexible.washers=true"])
    assert len(differential_dashboard(differentials.of(b), b).pages) == 3


def test_torsen_c_shaft_refusals():
    from click.testing import CliRunner

    from drivedyn.cli import main

    r = CliRunner().invoke(main, ["tdr", "torsen-c", "--analytic-only", "--set",
                                  'flexible.shaft_rear.inner_diameter="80 mm"'])
    assert r.exit_code == 2, r.output
    assert "shaft_rear" in r.output and "outer_diameter" in r.output, r.output
    assert "Traceback" not in r.output


@pytest.fixture(scope="module")
def shafts_run(tmp_path_factory) -> str:
    """A 20 ms vehicle-configuration run of the Type C with the case and the output shafts
    flexible (the engine torque ramping up), an output every millisecond."""
    from click.testing import CliRunner

    from drivedyn.cli import main

    out = tmp_path_factory.mktemp("shafts") / "run.nc"
    r = CliRunner().invoke(main, ["run", "torsen-c", "--t-end", "0.02", "--out", str(out),
                                  "--set", "flexible.shafts=true", "--set",
                                  "flexible.case=true", "--set", "solver.output_dt=1 ms"])
    assert r.exit_code == 0, r.output
    return str(out)


def test_flexible_figures_of_a_vehicle_run(shafts_run, tmp_path):
    """The validation report's figures of a vehicle run with the case and the shafts
    flexible: the case seats' pressure maps, the case's stress snapshots and each shaft's
    gear-end stress history."""
    import xarray as xr

    from drivedyn.validation.flexible_torsen import _flexible_figures

    with xr.open_dataset(shafts_run) as ds:
        paths = _flexible_figures("tc", ds.load(), str(tmp_path / "fig"), (0.0, 0.01, 0.02))
    names = sorted(p.rsplit("/", 1)[-1] for p in paths)
    assert names == ["tc_flexible_case_stress.png", "tc_flexible_coupling_shaft_stress.png",
                     "tc_flexible_pressure_coupling_case.png",
                     "tc_flexible_pressure_ring_case.png", "tc_flexible_sun_shaft_stress.png"]


def test_scene_draws_the_flexible_shafts_and_case_coloured_by_stress(shafts_run):
    """The 3-D viewer's scene of that run: the two output shafts as beam chains of their
    elements' nodes (6 + 1 and 8 + 1) carrying a stress per frame, and the case as a meshed
    part with its nodal stresses (seed 002's stress histories in the viewer)."""
    import xarray as xr

    from drivedyn.viewer.scene import build_scene

    with xr.open_dataset(shafts_run) as ds:
        scene = build_scene(ds.load(), frames=8)
    assert sorted(len(b.nodes) for b in scene.beams) == [7, 9]
    for b in scene.beams:
        assert b.stress.shape[0] == 8 and np.all(np.isfinite(b.stress))
        assert b.stress.max() > 0.0  # the engine torque ramps up: the shafts are loaded
    assert [p.name for p in scene.parts] == ["case"]
