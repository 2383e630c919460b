"""One self-contained HTML file that shows a :class:`~drivedyn.viewer.scene.Scene`.

The page inlines three.js (vendored under ``vendor/``, MIT), its orbit controls, the viewer
script (``viewer.js``) and the scene data (JSON, arrays as base64 float32 / uint32), so it
opens offline from a file or an e-mail attachment and fetches nothing. Controls: time slider,
play/pause and speed, deformation scale factor, camera presets, a section plane along x, y or
z, toggles for force arrows, semi-transparent cases, the road (lanes coloured by friction, with
a legend, and the tyres' footprints), markers and joint axes.
"""

from __future__ import annotations

import base64
import html
import json
import os
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from drivedyn.viewer.scene import Scene


def _b64(a: np.ndarray, dtype: Any = np.float32) -> str:
    return base64.b64encode(np.ascontiguousarray(a, dtype=dtype).tobytes()).decode("ascii")


def scene_payload(scene: Scene) -> dict[str, Any]:
    """The JSON-ready data the viewer script reads (see ``viewer.js``)."""
    def frame(t: tuple) -> dict[str, Any]:
        name, node, p, R = t
        return {"name": name, "node": int(node), "position": [float(v) for v in p],
                "rotation": [float(v) for v in np.asarray(R).ravel()]}

    n_shapes = len(scene.meshes) + len(scene.beams) + len(scene.parts)
    summary = (f"{scene.title}: {len(scene.nodes)} nodes, {n_shapes} shapes, "
               f"{len(scene.arrows)} force arrows, t = {scene.time[0]:.4g} to "
               f"{scene.time[-1]:.4g} s")
    return {
        "title": scene.title, "summary": summary, "nf": scene.frames, "nodes": scene.nodes,
        "length": float(scene.length), "time": _b64(scene.time),
        "position": _b64(scene.position), "quaternion": _b64(scene.quaternion),
        "meshes": [{"name": m.name, "node": m.node, "role": m.role,
                    "vertices": _b64(m.vertices), "triangles": _b64(m.triangles, np.uint32),
                    "colour": list(m.colour), "opacity": m.opacity} for m in scene.meshes],
        "arrows": [{"name": a.name, "origin": _b64(a.origin), "vector": _b64(a.vector),
                    "unit": a.unit} for a in scene.arrows],
        "beams": [{"name": b.name, "nodes": b.nodes.tolist(), "radius": b.radius,
                   "rigid": _b64(b.rigid), "stress": _b64(b.stress)} for b in scene.beams],
        "parts": [{"name": p.name, "node": p.node, "triangles": _b64(p.triangles, np.uint32),
                   "points": _b64(p.points), "displacement": _b64(p.displacement),
                   "stress": _b64(p.stress)} for p in scene.parts],
        "links": [{"name": k.name, "a": _b64(k.a), "b": _b64(k.b), "radius": k.radius,
                   "colour": list(k.colour), "turns": k.turns, "wire": k.wire}
                  for k in scene.links],
        "footprints": [{"name": f.name, "centre": _b64(f.centre), "heading": _b64(f.heading),
                        "length": _b64(f.length), "width": f.width} for f in scene.footprints],
        "road": [{"mu": r.mu, "colour": list(r.colour), "tyres": r.tyres} for r in scene.road],
        "markers": [frame(m) for m in scene.markers],
        "joints": [frame(j) for j in scene.joints],
    }


def _asset(name: str) -> str:
    return (resources.files("drivedyn.viewer") / name).read_text(encoding="utf-8")


_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title} - drivedyn view</title>
<style>
 html, body {{ margin: 0; height: 100%; font: 13px system-ui, sans-serif; color: #222; }}
 #bar {{ position: absolute; left: 0; right: 0; bottom: 0; padding: 6px 10px;
        background: rgba(255,255,255,0.92); border-top: 1px solid #ccc; display: flex;
        flex-wrap: wrap; gap: 6px 14px; align-items: center; }}
 #view {{ position: absolute; top: 0; left: 0; right: 0; bottom: 76px; }}
 #time {{ flex: 1 1 300px; }}
 #info {{ position: absolute; top: 6px; left: 10px; color: #555; }}
 #legend {{ position: absolute; top: 6px; right: 10px; display: none; text-align: right; }}
 #legend div {{ width: 160px; height: 10px; background: linear-gradient(90deg, #30123b,
        #4569f0, #1acbd1, #5cfa66, #e3db36, #fa8021, #cc290a, #7a0503); }}
 button {{ font: inherit; }}
 #road-legend {{ position: absolute; top: 40px; right: 10px; display: none;
        background: rgba(255,255,255,0.85); padding: 4px 6px; }}
 #road-legend .swatch {{ display: inline-block; width: 14px; height: 10px; margin-right: 6px;
        border: 1px solid #888; }}
 fieldset {{ border: none; padding: 0; margin: 0; display: flex; gap: 4px; align-items: center; }}
</style></head>
<body>
<div id="view"></div>
<div id="info"></div>
<div id="legend">von Mises stress<div></div>0 &#8211; <span id="legend-max"></span></div>
<div id="road-legend"><b>road friction factor</b> (tyres' mu scale; footprints in orange)</div>
<div id="bar">
 <button id="play">play</button>
 <label>speed <select id="speed"><option value="0.1">0.1x</option>
  <option value="0.25">0.25x</option> <option value="1" selected>1x</option>
  <option value="4">4x</option></select></label>
 <input id="time" type="range" min="0" max="0" value="0" step="1">
 <span id="tlabel"></span>
 <fieldset>camera
  <button id="cam-iso">iso</button><button id="cam-front">front</button>
  <button id="cam-side">side</button><button id="cam-top">top</button></fieldset>
 <label>deformation x <input id="scale" type="number" value="1" min="0" step="any"
   style="width: 6em"></label>
 <fieldset><label><input id="section" type="checkbox"> section</label>
  <select id="section-axis"><option>x</option><option selected>y</option><option>z</option></select>
  <input id="section-offset" type="range" min="-100" max="100" value="0"></fieldset>
 <label><input id="forces" type="checkbox" checked> forces</label>
 <label><input id="ghost" type="checkbox" checked> cases</label>
 <label id="road-toggle"><input id="road" type="checkbox" checked> road</label>
 <label><input id="markers" type="checkbox"> markers</label>
 <label><input id="joints" type="checkbox"> joint axes</label>
</div>
<script id="scene-data" type="application/json">{data}</script>
<script>{three}</script>
<script>{orbit}</script>
<script>{viewer}</script>
</body></html>
"""


def write_html(scene: Scene, path: str | os.PathLike) -> Path:
    """Write the viewer page of ``scene`` to ``path`` (atomically); returns the path."""
    data = json.dumps(scene_payload(scene), separators=(",", ":")).replace("</", "<\\/")
    page = _PAGE.format(title=html.escape(scene.title), data=data,
                        three=_asset("vendor/three.min.js"),
                        orbit=_asset("vendor/OrbitControls.js"), viewer=_asset("viewer.js"))
    out = Path(path)
    tmp = out.with_name(out.name + ".part")
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp.write_text(page, encoding="utf-8")
    os.replace(tmp, out)
    return out
