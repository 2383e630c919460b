"""The 3-D viewer on the RWD vehicle: the scene of a short run draws the ladder frame (beams),
the suspension links, the coil springs, dampers and bump stops between their markers, the
bushings at their frames, the wheels and the driveline's shafts, and the page shows the
springs in a real headless browser."""

from __future__ import annotations

import io
import json
import os
import shutil

import numpy as np
import pytest
import xarray as xr

import drivedyn.analysis.vehicle_rwd as V  # noqa: N812 - short name for the analysis
from drivedyn.config import read_library_file
from drivedyn.config.loader import read_vehicle_differentials, resolve_path
from drivedyn.results.results import write_netcdf_atomic
from drivedyn.viewer.html import scene_payload, write_html
from drivedyn.viewer.scene import COIL_RADIUS, build_scene

CORNERS = ("fl", "fr", "rl", "rr")


@pytest.fixture(scope="module")
def rwd_run(tmp_path_factory) -> str:
    """The RWD vehicle (open differential) for 20 ms from its static start."""
    base = resolve_path("vehicle-rwd").parent
    p, _, source = read_library_file("vehicle-rwd")
    p = V.configure(p, "open")
    res, _ = V.run(p, read_vehicle_differentials(p, source, base), base, t_end=0.02,
                   source=source)
    assert res.success, res.message
    out = tmp_path_factory.mktemp("rwd_view") / "rwd.nc"
    write_netcdf_atomic(res.dataset, out)
    return str(out)


def test_rwd_scene_draws_frame_suspension_springs_bushings_and_wheels(rwd_run) -> None:
    """Every part of the vehicle has its own shape: the frame's 60 beam elements as tubes, a
    coil per corner spring whose ends are the spring's markers (its drawn length is the
    spring's length output at every frame), a damper tube and two bump-stop stubs per
    corner, a rubber cylinder per bushing on the frame, the wheels, and no stand-in inertia
    box for any body.

    Mutations that fail it: no ``visuals()`` on NonlinearSpringDamper (no coils), on
    BumpStop (no stubs) or Bushing (no cylinders); a coil between the wrong markers (its
    length is not the spring's); the body carriers or the half-shafts left undeclared
    (inertia boxes)."""
    with xr.open_dataset(rwd_run) as ds:
        ds = ds.load()
    scene = build_scene(ds, frames=5)
    assert not scene.warnings
    idx = np.unique(np.round(np.linspace(0, ds.sizes["time"] - 1, 5)).astype(int))
    # the frame: every beam element in a chain, drawn with its stress
    topo = json.loads(ds.attrs["beam_elements"])
    assert len(topo) == 60 and all(e.startswith("frame.") for e in topo)
    drawn = {scene.nodes[i] for b in scene.beams for i in b.nodes}
    assert drawn == {n for ab in topo.values() for n in ab}
    assert all(np.isfinite(b.stress).all() for b in scene.beams)
    links = {}
    for k in scene.links:
        links.setdefault((k.role, k.name), []).append(k)
    for w in CORNERS:
        (spring,) = links[("spring", f"{w}_spring")]
        assert spring.turns > 0 and spring.wire > 0
        length = np.linalg.norm(spring.b - spring.a, axis=1)
        assert np.allclose(length, ds[f"{w}_spring.length"].values[idx], rtol=1e-6)
        assert spring.radius == pytest.approx(COIL_RADIUS * length[0], rel=1e-6)
        assert ("damper", f"{w}_damper") in links
        for stop in ("bump_stop", "rebound_stop"):
            (stub,) = links[("stop", f"{w}_{stop}")]
            reach = np.linalg.norm(stub.b - stub.a, axis=1)
            assert np.all(reach <= 0.2 * length[0] * (1 + 1e-9)) and reach[0] > 0
        for arm in ("upper", "lower"):
            assert len(links[("part", f"{w}_{arm}_arm")]) == 2  # a wishbone's two legs
    bushings = [m for m in scene.meshes if m.role == "bushing"]
    assert len(bushings) == 16  # two per arm
    assert all(scene.nodes[m.node].startswith("frame.") for m in bushings)
    wheels = {scene.nodes[m.node] for m in scene.meshes if m.role == "wheel"}
    assert wheels == {f"wheel_{w}" for w in CORNERS}
    assert {k.name for k in scene.links if k.role == "shaft"} >= {
        "propshaft", "halfshaft_rl", "halfshaft_rr"}
    assert not [m.name for m in scene.meshes if m.equivalent]
    payload = scene_payload(scene)
    assert sum(1 for k in payload["links"] if k["turns"] > 0) == 4


def _browser():
    """Debian's chromium driven by Playwright; on CI both must be there, elsewhere the test
    is skipped without them (as in test_viewer.py)."""
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


def test_rwd_page_shows_the_coil_springs_in_headless_chromium(rwd_run, tmp_path) -> None:
    """The page of the RWD run renders without a script error, and the coil springs are on
    the canvas: hiding them changes pixels, and the last frame's coils (reshaped to the
    springs' lengths then) still draw.

    Mutations that fail it: coils left out of the page, or a coil geometry without
    vertices (nothing changes when they are hidden)."""
    exe, sync_playwright = _browser()
    html = write_html(build_scene(xr.open_dataset(rwd_run).load(), frames=5),
                      tmp_path / "rwd.html")
    problems: list[str] = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=exe, args=[
            "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"])
        try:
            page = browser.new_page(viewport={"width": 1000, "height": 700},
                                    device_scale_factor=2)
            page.on("console", lambda m: problems.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: problems.append(str(e)))
            page.goto(html.as_uri())
            page.wait_for_function("window.drivedynViewer && window.drivedynViewer.ready",
                                   timeout=30000)
            canvas = page.locator("canvas")
            # a coil shrunk to nothing (setFrame places the coils, it does not scale them)
            coils = ("(s) => { const v = window.drivedynViewer; for (const w of "
                     f"{list(CORNERS)!r}) v.scene.getObjectByName(w + '_spring')"
                     ".scale.setScalar(s); }")
            shown = []
            for frame in (0, 4):
                page.evaluate(f"window.drivedynViewer.setFrame({frame})")
                on = _pixels(canvas.screenshot())
                page.evaluate(coils, 0.0)
                page.evaluate(f"window.drivedynViewer.setFrame({frame})")
                off = _pixels(canvas.screenshot())
                page.evaluate(coils, 1.0)
                shown.append(np.mean(np.abs(on - off).max(axis=2) > 0.1))
        finally:
            browser.close()
    assert not problems, problems
    assert all(s > 2e-4 for s in shown), shown
