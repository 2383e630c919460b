"""The 3-D viewer: shapes declared by elements and library models, their meshes, the scene of
a results file, the HTML page in a real headless browser, glTF and VTK exports."""

from __future__ import annotations

import io
import itertools
import json
import os
import re
import shutil

import numpy as np
import pytest
from click.testing import CliRunner

from drivedyn.cli import main
from drivedyn.config.loader import load_model, resolve_path
from drivedyn.elements import GearPair, Hinge
from drivedyn.elements.framework.visuals import Visual, cylinder
from drivedyn.model import Spec, compile_model
from drivedyn.model.subassembly import include
from drivedyn.results.scene import inertia_box, scene_description
from drivedyn.viewer.gltf import accessor_array, read_glb, write_glb
from drivedyn.viewer.meshes import (
    box_mesh,
    cylinder_mesh,
    gear_mesh,
    gear_profile,
    sphere_mesh,
)
from drivedyn.viewer.scene import (
    _rigid_fit,
    _surface,
    build_scene,
    frame_indices,
    lane_segments,
    quaternions,
    road_colour,
)
from drivedyn.viewer.vtk import _rotation, frame_geometry


# --- meshes ------------------------------------------------------------------------------------
def _closed_outward(V: np.ndarray, F: np.ndarray) -> float:
    """Check that every directed edge has exactly one opposite (closed, consistently
    oriented surface) and return the enclosed volume (positive: normals point outwards)."""
    edges: dict[tuple[int, int], int] = {}
    for a, b, c in F:
        for e in ((a, b), (b, c), (c, a)):
            edges[e] = edges.get(e, 0) + 1
    assert all(n == 1 and edges.get((e[1], e[0])) == 1 for e, n in edges.items())
    v0, v1, v2 = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    return float(np.einsum("ij,ij->i", v0, np.cross(v1, v2)).sum() / 6.0)


def _polygon_area(P: np.ndarray) -> float:
    x, y = P[:, 0], P[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def test_cylinder_and_tube_meshes_are_closed_with_the_volume_of_their_prism() -> None:
    n = 48
    ngon = 0.5 * n * np.sin(2 * np.pi / n)  # area of the unit n-gon
    V, F = cylinder_mesh(0.02, 0.1, n=n)
    assert _closed_outward(V, F) == pytest.approx(ngon * 0.02**2 * 0.1, rel=1e-12)
    V, F = cylinder_mesh(0.02, 0.1, inner_radius=0.015, z0=0.0, n=n)
    assert _closed_outward(V, F) == pytest.approx(ngon * (0.02**2 - 0.015**2) * 0.1,
                                                  rel=1e-12)
    assert V[:, 2].min() == 0.0 and V[:, 2].max() == pytest.approx(0.1)


def test_box_and_sphere_meshes() -> None:
    V, F = box_mesh(0.1, 0.2, 0.3)
    v0, v1, v2 = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    assert np.einsum("ij,ij->i", v0, np.cross(v1, v2)).sum() / 6 == pytest.approx(0.006)
    V, F = sphere_mesh(0.5)
    vol = _closed_outward(V, F)
    assert 0.9 * 4 / 3 * np.pi * 0.125 < vol < 4 / 3 * np.pi * 0.125  # inscribed polyhedron
    assert np.allclose(np.linalg.norm(V, axis=1), 0.5)


@pytest.mark.parametrize("internal", [False, True])
def test_gear_mesh_has_its_teeth_helix_and_volume(internal: bool) -> None:
    z, r, m, b, beta = 20, 0.0166, 1.5e-3, 0.012, np.radians(25.0)
    prof = gear_profile(z, r, m, internal, points_per_tooth=5)  # as gear_mesh draws it
    rad = np.hypot(prof[:, 0], prof[:, 1])
    tips = (np.abs(rad - (rad.min() if internal else rad.max())) < 1e-9 * r)
    # one tip land per tooth: count the runs of tip points around the outline
    assert int(np.sum(tips & ~np.roll(tips, 1))) == z
    assert rad.max() == pytest.approx(r + (1.25 if internal else 1.0) * m)
    assert rad.min() == pytest.approx(r - (1.0 if internal else 1.25) * m)
    V, F = gear_mesh(z, r, b, m, helix_angle=beta, internal=float(internal))
    vol = _closed_outward(V, F)
    area = abs(_polygon_area(prof))
    ang = np.arctan2(prof[:, 1], prof[:, 0])
    rim = abs(_polygon_area((r + 2.5 * m) * np.column_stack([np.cos(ang), np.sin(ang)])))
    exact = (rim - area if internal else area) * b
    # the twisted faces between layers are planar triangles, not the ruled helicoid
    # (0.38 % here); a spur gear is an exact prism
    assert vol == pytest.approx(exact, rel=5e-3)
    spur = _closed_outward(*gear_mesh(z, r, b, m, internal=float(internal)))
    assert spur == pytest.approx(exact, rel=1e-12)
    # the helix: the outline at +b/2 is the one at -b/2 turned by b tan(beta) / r
    n = len(prof)
    top = V[V[:, 2] == V[:, 2].max()][:n]
    bottom = V[:n]
    turn = np.arctan2(top[:, 1], top[:, 0]) - np.arctan2(bottom[:, 1], bottom[:, 0])
    turn = (turn + np.pi) % (2 * np.pi) - np.pi
    assert np.allclose(turn, b * np.tan(beta) / r, atol=1e-12)


# --- scene descriptions ------------------------------------------------------------------------
def test_inertia_box_has_the_mass_and_inertia_of_the_body() -> None:
    rng = np.random.default_rng(3)
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    J = Q @ np.diag([0.02, 0.05, 0.06]) @ Q.T
    a, R = inertia_box(3.0, J)
    Jb = 3.0 / 12 * np.diag([a[1] ** 2 + a[2] ** 2, a[0] ** 2 + a[2] ** 2, a[0] ** 2 + a[1] ** 2])
    assert np.allclose(R @ Jb @ R.T, J, rtol=1e-12, atol=1e-15)
    assert np.linalg.det(R) == pytest.approx(1.0)


def test_torsen_c_scene_draws_each_wheel_once_with_its_geometry() -> None:
    model = load_model(resolve_path("torsen-c"))
    d = scene_description(model)
    p = json.loads(model.meta["model_file"])["gears"]
    gears = [s for s in d["shapes"] if s["kind"] == "gear"]
    # the sun and the ring mesh with four planets each, but are drawn once
    by_node = {s["node"]: s["params"] for s in gears}
    assert sorted(by_node) == ["planet1", "planet2", "planet3", "planet4", "ring", "sun"]
    beta = float(np.radians(float(str(p["helix_angle"]).split()[0])))
    m = 1.5e-3
    for node, z in (("sun", p["teeth_sun"]), ("planet1", p["teeth_planet"]),
                    ("ring", p["teeth_ring"])):
        g = by_node[node]
        assert g["teeth"] == z
        assert g["pitch_radius"] == pytest.approx(z * m / (2 * np.cos(beta)), rel=1e-12)
        assert g["internal"] == (1.0 if node == "ring" else 0.0)
    # the sun and the planets have opposite hands, the planets and the ring the same
    assert by_node["sun"]["helix_angle"] == pytest.approx(-by_node["planet1"]["helix_angle"])
    assert by_node["ring"]["helix_angle"] == pytest.approx(by_node["planet1"]["helix_angle"])
    washers = [s for s in d["shapes"] if s["role"] == "washer"]
    # five thrust washers and the two end faces of each of the four planets
    assert len(washers) == 5 + 2 * 4
    assert sum(s["label"].startswith("planet") for s in washers) == 8
    roles = {s["role"] for s in d["shapes"]}
    assert {"housing", "case", "shaft"} <= roles
    # every body is drawn by a declared shape: no stand-in box
    assert not [s for s in d["shapes"] if s.get("equivalent")]


def test_sub_assemblies_carry_their_shapes_and_undrawn_bodies_get_their_inertia_box() -> None:
    sub = Spec()
    sub.add_rigid_body("wheel", 1.0, [1e-3, 1e-3, 2e-3])
    sub.add_marker("axle", "ground", axis=(0, 0, 1))
    sub.add_marker("hub", "wheel", axis=(0, 0, 1))
    sub.add(Hinge("bearing", "axle", "hub"))
    sub.add_visual(cylinder("hub", 0.05, 0.01, role="wheel", label="wheel"))
    host = Spec()
    host.add_rigid_body("frame", 2.0, [0.1, 0.2, 0.25])
    host.add_marker("frame_m", "frame")
    host.add_marker("g", "ground")
    from drivedyn.elements import Fixed

    host.add(Fixed("weld", "g", "frame_m"))
    include(host, sub, "left_", ground="frame")
    d = scene_description(compile_model(host))
    solids = {s["node"]: s for s in d["shapes"] if s["role"] not in ("joint", "force")}
    assert solids["left_wheel"]["kind"] == "cylinder"
    assert solids["left_wheel"]["label"] == "left_wheel"  # labels that name a body follow it
    box = solids["frame"]
    assert box["equivalent"] and box["kind"] == "box"
    with pytest.raises(Exception, match="does not exist"):
        host.add_visual(cylinder("nowhere", 1.0, 1.0))
    with pytest.raises(ValueError, match="kind"):
        Visual("hub", "teapot", "body")


def test_gear_pair_declares_bevel_and_crossed_wheels() -> None:
    pair = GearPair("bevel", "a", "b", 10, 20, 3e-3, 0.01, kind="bevel",
                    cone_angle_a=np.arctan(0.5), cone_angle_b=np.arctan(2.0))
    a, b = pair.visuals()
    assert a.values["pitch_radius"] == pytest.approx(0.015)
    assert b.values["cone_angle"] == pytest.approx(np.arctan(2.0))
    assert a.values["helix_angle"] == 0.0


# --- scene of a run ------------------------------------------------------------------------
def test_quaternions_round_trip_including_half_turns() -> None:
    rng = np.random.default_rng(7)
    Rs = []
    for _ in range(200):
        Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        Rs.append(Q * np.sign(np.linalg.det(Q)))
    Rs += [np.diag([1.0, -1.0, -1.0]), np.diag([-1.0, 1.0, -1.0]), np.diag([-1.0, -1.0, 1.0])]
    q = quaternions(np.array(Rs))
    for Rm, qq in zip(Rs, q, strict=True):
        assert np.allclose(_rotation(qq), Rm, atol=1e-14)
    # a spin about z over many turns: consecutive quaternions never flip sign
    th = np.linspace(0, 20 * np.pi, 400)
    Rz = np.array([[[np.cos(t), -np.sin(t), 0], [np.sin(t), np.cos(t), 0], [0, 0, 1]]
                   for t in th])[:, None]
    qz = quaternions(Rz)[:, 0]
    assert np.all(np.einsum("ik,ik->i", qz[1:], qz[:-1]) > 0.9)


def test_frame_indices_and_rigid_fit() -> None:
    idx = frame_indices(1001, 7)
    assert idx[0] == 0 and idx[-1] == 1000 and len(idx) == 7
    assert np.array_equal(frame_indices(5, 10), np.arange(5))
    rng = np.random.default_rng(1)
    P0 = rng.normal(size=(6, 3))
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    Q *= np.sign(np.linalg.det(Q))
    P = np.stack([P0, P0 @ Q.T + [1.0, 2.0, 3.0]])
    assert np.allclose(_rigid_fit(P, P0), P, atol=1e-12)  # a rigid motion is all rigid
    bent = P.copy()
    bent[1, 0] += 0.1
    assert not np.allclose(_rigid_fit(bent, P0), bent)


def test_surface_of_a_hexahedron_is_its_six_faces_outward() -> None:
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                    [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    two = np.array([[0, 1, 2, 3, 4, 5, 6, 7], [4, 5, 6, 7, 8, 9, 10, 11]])
    pts2 = np.vstack([pts, np.add(pts[4:], (0.0, 0.0, 1.0))])
    T = _surface(two)
    assert len(T) == 20  # 10 outer quads; the shared face is inside
    assert _closed_outward(pts2, T) == pytest.approx(2.0)


@pytest.fixture(scope="module")
def torsen_c_run(tmp_path_factory) -> str:
    """A short Type C bench run with an output every 0.5 ms (the planets turn visibly)."""
    out = tmp_path_factory.mktemp("view") / "tc.nc"
    r = CliRunner().invoke(main, ["run", "torsen-c", "--t-end", "0.01", "--out", str(out),
                                  "--set", "solver.output_dt=0.5 ms"])
    assert r.exit_code == 0, r.output
    return str(out)


def test_scene_of_a_run_follows_the_recorded_poses(torsen_c_run) -> None:
    import xarray as xr

    with xr.open_dataset(torsen_c_run) as ds:
        ds = ds.load()
    scene = build_scene(ds, frames=8)
    idx = frame_indices(ds.sizes["time"], 8)
    assert scene.frames == len(idx)
    for i, n in enumerate(scene.nodes):
        assert np.allclose(scene.position[:, i], ds[f"{n}.position"].values[idx])
        R = ds[f"{n}.rotation"].values[idx]
        for f in range(scene.frames):
            assert np.allclose(_rotation(scene.quaternion[f, i]), R[f], atol=1e-12)
    assert not scene.warnings
    # force arrows: 5 washers, 4 pockets, 8 planet end faces, 8 gear meshes
    arrows = {a.name: a for a in scene.arrows}
    assert len(arrows) == 25
    d = json.loads(ds.attrs["scene"])
    geo = {s["label"]: s for s in d["shapes"]}
    f = scene.frames - 1
    pos = {n: scene.position[f, i] for i, n in enumerate(scene.nodes)}
    # a washer's force is its normal force along the washer normal (the housing's z here)
    w = arrows["sun_housing"]
    R_h = _rotation(scene.quaternion[f, scene.nodes.index("housing")])
    n_w = R_h @ np.asarray(geo["sun_housing"]["rotation"]).reshape(3, 3)[:, 2]
    assert np.allclose(w.vector[f], ds["sun_housing.normal_force"].values[idx[f]] * n_w)
    # a mesh force is the element's global force on wheel B, at the pitch point: on the line
    # of centres, at the sun's pitch radius from the sun's centre
    g = arrows["sun_planet1"]
    assert np.allclose(g.vector[f], [ds[f"sun_planet1.force_{c}"].values[idx[f]] for c in "xyz"])
    gears = [s for s in d["shapes"] if s["kind"] == "gear"]
    r_sun = next(s["params"]["pitch_radius"] for s in gears if s["node"] == "sun")
    r_pl = next(s["params"]["pitch_radius"] for s in gears if s["node"] == "planet1")
    c_sun, c_pl = pos["sun"], pos["planet1"]
    plane = np.array([1.0, 1.0, 0.0])  # the gears' axes are z
    assert np.linalg.norm((g.origin[f] - c_sun) * plane) == pytest.approx(r_sun, rel=1e-9)
    assert np.linalg.norm((g.origin[f] - c_pl) * plane) == pytest.approx(r_pl, rel=2e-3)
    # planet inside the ring: the pitch point is on the planet's far side from the axis
    gr = arrows["planet1_ring"]
    assert np.linalg.norm(gr.origin[f] * plane) == pytest.approx(
        np.linalg.norm(c_pl * plane) + r_pl, rel=2e-3)
    # a pocket pushes the planet back towards the pocket's axis, from the bore wall (the
    # pockets do not touch in these 10 ms: a force of 7 N is put into a copy of the results)
    ds7 = ds.copy()
    ds7["planet1_pocket.normal_force"] = ds["planet1_pocket.normal_force"] * 0.0 + 7.0
    pk = {a.name: a for a in build_scene(ds7, frames=8).arrows}["planet1_pocket"]
    bore = next(s for s in d["shapes"] if s["label"] == "planet1_pocket")
    pocket = (pos["housing"] + _rotation(scene.quaternion[f, scene.nodes.index("housing")])
              @ np.asarray(bore["position"]))
    n = (c_pl - pocket) * plane
    n /= np.linalg.norm(n)
    r_bore = bore["params"]["reach"]
    assert np.allclose(pk.vector[f], -7.0 * n, atol=1e-12)
    assert np.allclose(pk.origin[f], pocket + r_bore * n, atol=1e-12)
    # VTK: a rigid mesh's points are its node's pose applied to its vertices; the arrows are
    # vertices carrying their force
    geom = frame_geometry(scene, 3)
    m = scene.meshes[0]
    x, Rm = scene.position[3, m.node], _rotation(scene.quaternion[3, m.node])
    assert np.allclose(geom["points"][: len(m.vertices)], m.vertices @ Rm.T + x)
    v = geom["vertices"]
    assert len(v) == 25 and np.allclose(geom["points"][v], [a.origin[3] for a in scene.arrows])
    assert np.allclose(geom["force"][v], [a.vector[3] for a in scene.arrows])
    assert geom["triangles"].max() < len(geom["points"]) and len(geom["lines"]) == 0


def test_gltf_export_animates_every_node(torsen_c_run, tmp_path) -> None:
    import xarray as xr

    with xr.open_dataset(torsen_c_run) as ds:
        scene = build_scene(ds.load(), frames=12)
    doc, binary = read_glb(write_glb(scene, tmp_path / "tc.glb"))
    assert doc["asset"]["version"] == "2.0"
    assert len(doc["meshes"]) == len(scene.meshes)
    chans = doc["animations"][0]["channels"]
    samplers = doc["animations"][0]["samplers"]
    for c in chans:
        i = c["target"]["node"]
        out = accessor_array(doc, binary, samplers[c["sampler"]]["output"])
        ref = scene.position[:, i] if c["target"]["path"] == "translation" \
            else scene.quaternion[:, i]
        assert np.allclose(out, ref, atol=1e-6)
    t = accessor_array(doc, binary, samplers[0]["input"])[:, 0]
    assert np.allclose(t, scene.time - scene.time[0], atol=1e-7)
    for acc in doc["accessors"]:  # glTF requires min/max on positions and inputs
        view = doc["bufferViews"][acc["bufferView"]]
        assert view["byteOffset"] % 4 == 0
        assert view["byteOffset"] + view["byteLength"] <= len(binary)


def test_view_command_writes_html_gltf_and_vtk(torsen_c_run, tmp_path) -> None:
    import meshio

    html = tmp_path / "tc.html"
    r = CliRunner().invoke(main, ["view", torsen_c_run, "--out", str(html), "--frames", "5",
                                  "--gltf", str(tmp_path / "tc.glb"),
                                  "--vtk", str(tmp_path / "vtk")])
    assert r.exit_code == 0, r.output
    pvd = (tmp_path / "vtk" / "tc.pvd").read_text()
    files = re.findall(r'file="([^"]+)"', pvd)
    assert len(files) == 5
    mesh = meshio.read(tmp_path / "vtk" / files[-1])
    assert mesh.points.shape[1] == 3
    assert {"von_mises", "shape", "force"} <= set(mesh.point_data)
    # no network address: the only URLs in the page are the XHTML namespace name (an
    # identifier that browsers never fetch) and a link inside a three.js warning text
    text = html.read_text()
    urls = set(re.findall(r"(?:https?|wss?|ftp)://[^\s\"'<>)]*", text))
    assert urls <= {"http://www.w3.org/1999/xhtml",
                    "https://github.com/mrdoob/three.js/pull/23228"}, urls
    assert not re.search(r"""(src|href)\s*=\s*["'](?!#)""", text)
    assert "@import" not in text and "url(" not in text


def test_view_refuses_bad_input(tmp_path) -> None:
    bad = tmp_path / "x.nc"
    bad.write_text("not netcdf")
    r = CliRunner().invoke(main, ["view", str(bad)])
    assert r.exit_code == 2 and "cannot be viewed" in r.output
    assert "Traceback" not in r.output


# --- the page in a real browser ----------------------------------------------------------------
def _browser():
    """Debian's chromium driven by Playwright; on CI both must be there (.ci/run installs
    them), elsewhere the test is skipped without them."""
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        sync_playwright = None
    if exe is None or sync_playwright is None:
        if os.environ.get("CI"):
            pytest.fail("CI must provide chromium and playwright (see .ci/run)")
        pytest.skip("needs Debian's chromium and the playwright package")
    return exe, sync_playwright


def _pixels(png: bytes) -> np.ndarray:
    import matplotlib.image as mpimg

    return mpimg.imread(io.BytesIO(png), format="png")[..., :3]


def test_viewer_renders_in_headless_chromium_and_the_slider_moves_it(torsen_c_run,
                                                                      tmp_path) -> None:
    exe, sync_playwright = _browser()
    html = tmp_path / "tc.html"
    r = CliRunner().invoke(main, ["view", torsen_c_run, "--out", str(html)])
    assert r.exit_code == 0, r.output
    problems: list[str] = []
    requests: list[str] = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=exe, args=[
            "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
            "--disable-background-networking", "--disable-component-update",
            "--disable-sync", "--no-first-run"])
        try:
            page = browser.new_page(viewport={"width": 1000, "height": 700})
            page.on("console", lambda m: problems.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: problems.append(str(e)))
            page.on("request", lambda q: requests.append(q.url))
            page.goto(html.as_uri())
            page.wait_for_function("window.drivedynViewer && window.drivedynViewer.ready",
                                   timeout=30000)
            nf = page.evaluate("window.drivedynViewer.frames")
            canvas = page.locator("canvas")
            first = _pixels(canvas.screenshot())
            label0 = page.inner_text("#tlabel")
            # move the time slider as a user does: set its value and fire its input event
            page.locator("#time").evaluate(
                "(el, v) => { el.value = v; el.dispatchEvent(new Event('input')); }",
                str(nf - 1))
            last = _pixels(canvas.screenshot())
            label1 = page.inner_text("#tlabel")
            page.locator("#time").evaluate(
                "(el, v) => { el.value = v; el.dispatchEvent(new Event('input')); }", "0")
            back = _pixels(canvas.screenshot())
        finally:
            browser.close()
    assert not problems, problems
    assert all(u.startswith(("file:", "data:", "blob:")) for u in requests), requests
    assert nf > 10
    # not blank: many colours, and a good part of the canvas differs from the background
    background = first[0, 0]
    covered = np.mean(np.abs(first - background).sum(axis=2) > 0.05)
    assert len(np.unique((first * 255).astype(int).reshape(-1, 3), axis=0)) > 200
    assert covered > 0.05
    # the gears turned by 0.3 rad between the first and the last frame (0.75 % of the
    # pixels change: most of the gears are behind the housing); back at the first frame,
    # the picture is the first one again
    changed = np.mean(np.abs(last - first).sum(axis=2) > 0.05)
    assert changed > 0.004, changed
    assert np.mean(np.abs(back - first).sum(axis=2) > 0.05) < 1e-4
    assert label0 != label1 and "t = 0.0100 s" in label1


# --- the road of a vehicle run ---------------------------------------------------------------

#: the 4WD file's friction under each wheel, and a patch of 0.3 under the front wheels
ROAD_MU = {"tyre_fl": 0.002, "tyre_fr": 0.05, "tyre_rl": 0.01, "tyre_rr": 0.8}
PATCH = (1.4, 1.7, 0.3)


@pytest.fixture(scope="module")
def vehicle_run(tmp_path_factory) -> str:
    """The 4WD vehicle for 10 ms at rest, with a friction patch under the front wheels."""
    out = tmp_path_factory.mktemp("vehicle") / "v.nc"
    x0, x1, mu = PATCH
    r = CliRunner().invoke(main, [
        "run", "vehicle-4wd", "--t-end", "0.01", "--out", str(out), "--set",
        f'road.patches=[{{x_start={x0}, x_end={x1}, mu={mu}, wheels=["fl","fr"]}}]'])
    assert r.exit_code == 0, r.output
    return str(out)


def test_lane_segments_follow_the_tyre_element_s_patch_rule() -> None:
    """The lane drawn under a tyre is its friction over x as the element reads it: ``mu``
    outside the patches, later patches winning where they overlap, equal neighbours merged.

    Deliberate mutations that fail it: the first patch winning an overlap ((3, 4) at 0.1);
    no merging of equal neighbours (two segments of 1.0 after the last patch)."""
    segs = lane_segments(1.0, [[2.0, 4.0, 0.1], [3.0, 5.0, 0.5], [6.0, 7.0, 1.0]], 0.0, 10.0)
    assert segs == [(0.0, 2.0, 1.0), (2.0, 3.0, 0.1), (3.0, 5.0, 0.5), (5.0, 10.0, 1.0)]
    assert lane_segments(0.2, [[-50.0, 50.0, 0.9]], -1.0, 1.0) == [(-1.0, 1.0, 0.9)]


def test_road_colours_tell_the_seed_s_friction_values_apart() -> None:
    """Road colours darken as the friction rises (ice pale, asphalt dark), and the split-mu
    values of the 4WD file (0.002 to 0.8) are told apart.

    Deliberate mutation that fails it: a linear instead of a logarithmic ramp (0.002 and
    0.01 get nearly the same colour)."""
    mus = [0.001, 0.002, 0.01, 0.05, 0.3, 0.8, 1.0]
    lum = [sum(road_colour(m)) for m in mus]
    assert all(a > b for a, b in itertools.pairwise(lum)), lum
    for a, b in itertools.pairwise(mus[1:-1]):
        assert np.abs(np.subtract(road_colour(a), road_colour(b))).max() > 0.08, (a, b)


def test_vehicle_scene_draws_the_road_footprints_and_shafts(vehicle_run) -> None:
    """The scene of a 4WD run: one lane per tyre with the file's friction and the patch under
    the front wheels, a legend of every value with its tyres, each tyre's footprint on the
    road under its wheel at every frame (its length the chord the road cuts from the
    unloaded tyre), and the propeller and half-shafts as links that follow their bodies.

    Deliberate mutations that fail it: lanes from each tyre's ``mu`` only (no 0.3 lane);
    the footprint at the wheel centre instead of on the road; a half-shaft's ends swapped
    (its end at the hub is not the wheel centre); the propeller shafts' links on the central
    outputs' markers (the shafts get inertia boxes again)."""
    import xarray as xr

    with xr.open_dataset(vehicle_run) as ds:
        ds = ds.load()
    desc = json.loads(ds.attrs["scene"])
    assert {r["name"]: r["mu"] for r in desc["road"]} == ROAD_MU
    scene = build_scene(ds, frames=6)
    assert not scene.warnings
    legend = {r.mu: r.tyres for r in scene.road}
    assert legend == {**{mu: [t] for t, mu in ROAD_MU.items()}, 0.3: ["tyre_fl", "tyre_fr"]}
    lanes = [m for m in scene.meshes if m.role == "road"]
    assert all(m.node == -1 for m in lanes)
    patch = [m for m in lanes if m.name == "tyre_fl road (mu 0.3)"]
    assert len(patch) == 1
    assert patch[0].vertices[:, 0].min() == pytest.approx(PATCH[0])
    assert patch[0].vertices[:, 0].max() == pytest.approx(PATCH[1])
    radius = {r["name"]: r["radius"] for r in desc["road"]}
    for fp in scene.footprints:
        wheel = scene.nodes.index("wheel_" + fp.name.removeprefix("tyre_"))
        centre = scene.position[:, wheel]
        assert np.allclose(fp.centre[:, :2], centre[:, :2]) and np.all(fp.centre[:, 2] == 0.0)
        chord = 2 * np.sqrt(radius[fp.name] ** 2 - centre[:, 2] ** 2)
        assert np.allclose(fp.length, chord) and np.all(fp.length > 0)
        own = [m for m in lanes if m.name.startswith(fp.name + " ")]
        for f in range(scene.frames):
            x, y = fp.centre[f, :2]
            assert any(m.vertices[:, 0].min() <= x <= m.vertices[:, 0].max()
                       and m.vertices[:, 1].min() <= y <= m.vertices[:, 1].max()
                       for m in own), (fp.name, f)
    links = {k.name: k for k in scene.links}
    assert set(links) == {"prop_front", "prop_rear", *(f"halfshaft_{w}" for w in
                                                     ("fl", "fr", "rl", "rr"))}
    for w in ("fl", "fr", "rl", "rr"):
        k = links[f"halfshaft_{w}"]
        assert np.allclose(k.a, scene.position[:, scene.nodes.index(f"wheel_{w}")])
        assert np.all(np.abs(k.b[:, 1]) < 0.3)  # at the axle's differential, mid-track
    assert not any(m.equivalent and m.name.startswith("prop_") for m in scene.meshes)


def test_viewer_draws_the_road_in_headless_chromium(vehicle_run, tmp_path) -> None:
    """The page of a 4WD run in a real browser: the road's legend lists the five friction
    values, and the lanes are on the canvas: switching the road off changes a good part of
    the picture, and what it removes is mostly the blue of the low-friction lanes.

    Deliberate mutations that fail it: road meshes left out of the page, or the toggle not
    hiding them (nothing changes); the legend not filled."""
    exe, sync_playwright = _browser()
    html = tmp_path / "v.html"
    r = CliRunner().invoke(main, ["view", vehicle_run, "--out", str(html)])
    assert r.exit_code == 0, r.output
    problems: list[str] = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=exe, args=[
            "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"])
        try:
            page = browser.new_page(viewport={"width": 1000, "height": 700})
            page.on("console", lambda m: problems.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: problems.append(str(e)))
            page.goto(html.as_uri())
            page.wait_for_function("window.drivedynViewer && window.drivedynViewer.ready",
                                   timeout=30000)
            legend = page.inner_text("#road-legend")
            canvas = page.locator("canvas")
            on = _pixels(canvas.screenshot())
            page.locator("#road").evaluate("(el) => { el.checked = false; "
                                           "el.dispatchEvent(new Event('input')); }")
            off = _pixels(canvas.screenshot())
        finally:
            browser.close()
    assert not problems, problems
    for mu in ("0.002", "0.01", "0.05", "0.3", "0.8"):
        assert f"mu {mu}:" in legend, legend
    # the road's pixels: those that change when it is switched off, bluish (the lanes of
    # mu 0.002-0.05 are pale to mid blue; shading changes their exact colour)
    road = np.abs(on - off).max(axis=2) > 0.1
    assert road.mean() > 0.02, road.mean()
    bluish = on[road][:, 2] > on[road][:, 0] + 0.1
    assert bluish.mean() > 0.3, bluish.mean()
