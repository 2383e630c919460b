"""glTF 2.0 export (binary ``.glb``) of a :class:`~drivedyn.viewer.scene.Scene`.

One glTF node per mechanism node, animated by translation and rotation channels sampled at
the scene's frame times (linear interpolation); the shapes are meshes under their node, with
the viewer's colours (cases and housings blended semi-transparent). Meshed flexible parts are
exported undeformed under their host node; beams, whose shape is their nodes' deformation,
and force arrows are not (the HTML viewer and the VTK export have them). Units: metres,
seconds; the glTF +y-up convention is met by a root node turning drivedyn's z-up world.
"""

from __future__ import annotations

import json
import os
import struct
from pathlib import Path
from typing import Any

import numpy as np

from drivedyn.viewer.scene import COLOURS, Scene

_FLOAT, _UINT = 5126, 5125
_ARRAY, _ELEMENTS = 34962, 34963


class _Builder:
    def __init__(self) -> None:
        self.bin = bytearray()
        self.views: list[dict[str, Any]] = []
        self.accessors: list[dict[str, Any]] = []

    def add(self, a: np.ndarray, kind: str, target: int | None = None,
            bounds: bool = False) -> int:
        """Append array ``a`` as an accessor of ``kind`` ("SCALAR", "VEC3", "VEC4"); returns
        the accessor index."""
        comp = _UINT if a.dtype.kind in "ui" else _FLOAT
        data = np.ascontiguousarray(a, dtype=np.uint32 if comp == _UINT else np.float32)
        while len(self.bin) % 4:
            self.bin.append(0)
        view: dict[str, Any] = {"buffer": 0, "byteOffset": len(self.bin),
                                "byteLength": data.nbytes}
        if target is not None:
            view["target"] = target
        self.bin.extend(data.tobytes())
        self.views.append(view)
        ncomp = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[kind]
        acc: dict[str, Any] = {"bufferView": len(self.views) - 1, "componentType": comp,
                               "count": int(data.size // ncomp), "type": kind}
        if bounds:
            flat = data.reshape(-1, ncomp)
            acc["min"] = [float(v) for v in flat.min(axis=0)]
            acc["max"] = [float(v) for v in flat.max(axis=0)]
        self.accessors.append(acc)
        return len(self.accessors) - 1


def gltf_document(scene: Scene) -> tuple[dict[str, Any], bytes]:
    """The glTF JSON document and its binary buffer."""
    b = _Builder()
    materials: list[dict[str, Any]] = []
    mat_index: dict[tuple, int] = {}

    def material(colour: tuple, opacity: float) -> int:
        key = (tuple(round(c, 4) for c in colour), round(opacity, 4))
        if key not in mat_index:
            m: dict[str, Any] = {"pbrMetallicRoughness": {
                "baseColorFactor": [*map(float, colour), float(opacity)],
                "metallicFactor": 0.25, "roughnessFactor": 0.55}, "doubleSided": True}
            if opacity < 1.0:
                m["alphaMode"] = "BLEND"
            materials.append(m)
            mat_index[key] = len(materials) - 1
        return mat_index[key]

    meshes: list[dict[str, Any]] = []
    nodes: list[dict[str, Any]] = [{"name": n} for n in scene.nodes]
    ground: dict[str, Any] = {"name": "ground", "children": []}

    def attach(name: str, node: int, V: np.ndarray, F: np.ndarray, mat: int) -> None:
        pa = b.add(V.astype(np.float32), "VEC3", _ARRAY, bounds=True)
        ia = b.add(F.astype(np.uint32).ravel(), "SCALAR", _ELEMENTS)
        meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": pa},
                                                     "indices": ia, "material": mat}]})
        nodes.append({"name": name, "mesh": len(meshes) - 1})
        child = len(nodes) - 1
        parent = ground if node < 0 else nodes[node]
        parent.setdefault("children", []).append(child)

    for m in scene.meshes:
        attach(m.name, m.node, m.vertices, m.triangles, material(m.colour, m.opacity))
    for p in scene.parts:
        attach(p.name, p.node, p.points, p.triangles, material(COLOURS["part"], 1.0))
    nodes.append(ground)
    gi = len(nodes) - 1
    # z-up (drivedyn) to y-up (glTF): a quarter turn about x
    s = float(np.sqrt(0.5))
    nodes.append({"name": "drivedyn (z up)", "rotation": [-s, 0.0, 0.0, s],
                  "children": [*range(len(scene.nodes)), gi]})
    root = len(nodes) - 1
    t_acc = b.add(scene.time - scene.time[0], "SCALAR", bounds=True)
    samplers, channels = [], []
    for i in range(len(scene.nodes)):
        for path, data, kind in (("translation", scene.position[:, i], "VEC3"),
                                 ("rotation", scene.quaternion[:, i], "VEC4")):
            samplers.append({"input": t_acc, "output": b.add(data, kind),
                             "interpolation": "LINEAR"})
            channels.append({"sampler": len(samplers) - 1, "target": {"node": i, "path": path}})
        nodes[i]["translation"] = [float(v) for v in scene.position[0, i]]
        nodes[i]["rotation"] = [float(v) for v in scene.quaternion[0, i]]
    while len(b.bin) % 4:
        b.bin.append(0)
    doc: dict[str, Any] = {
        "asset": {"version": "2.0", "generator": "drivedyn view"},
        "scene": 0, "scenes": [{"name": scene.title, "nodes": [root]}],
        "nodes": nodes, "meshes": meshes, "materials": materials or [{}],
        "accessors": b.accessors, "bufferViews": b.views,
        "buffers": [{"byteLength": len(b.bin)}],
    }
    if scene.frames > 1:
        doc["animations"] = [{"name": "run", "samplers": samplers, "channels": channels}]
    return doc, bytes(b.bin)


def write_glb(scene: Scene, path: str | os.PathLike) -> Path:
    """Write ``scene`` as a binary glTF file; returns the path."""
    doc, binary = gltf_document(scene)
    js = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    js += b" " * (-len(js) % 4)
    total = 12 + 8 + len(js) + 8 + len(binary)
    out = Path(path)
    tmp = out.with_name(out.name + ".part")
    out.parent.mkdir(parents=True, exist_ok=True)
    with open(tmp, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, total))
        f.write(struct.pack("<I4s", len(js), b"JSON"))
        f.write(js)
        f.write(struct.pack("<I4s", len(binary), b"BIN\x00"))
        f.write(binary)
    os.replace(tmp, out)
    return out


def read_glb(path: str | os.PathLike) -> tuple[dict[str, Any], bytes]:
    """The JSON document and binary chunk of a ``.glb`` file (for checks and tests)."""
    raw = Path(path).read_bytes()
    magic, version, total = struct.unpack_from("<4sII", raw, 0)
    if magic != b"glTF" or version != 2 or total != len(raw):
        raise ValueError(f"{path}: not a glTF 2.0 binary file")
    n, kind = struct.unpack_from("<I4s", raw, 12)
    doc = json.loads(raw[20:20 + n])
    m, kind2 = struct.unpack_from("<I4s", raw, 20 + n)
    if kind != b"JSON" or kind2 != b"BIN\x00":
        raise ValueError(f"{path}: chunks out of order")
    return doc, raw[28 + n:28 + n + m]


def accessor_array(doc: dict[str, Any], binary: bytes, index: int) -> np.ndarray:
    """The data of accessor ``index`` as an array (count, components)."""
    acc = doc["accessors"][index]
    view = doc["bufferViews"][acc["bufferView"]]
    dtype = np.uint32 if acc["componentType"] == _UINT else np.float32
    ncomp = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[acc["type"]]
    a = np.frombuffer(binary, dtype=dtype, count=acc["count"] * ncomp,
                      offset=view["byteOffset"] + acc.get("byteOffset", 0))
    return a.reshape(acc["count"], ncomp)
