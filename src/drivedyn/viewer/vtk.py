"""VTK export for ParaView: one ``.vtu`` file per frame and a ``.pvd`` index with the times.

Each frame holds every shape in the global frame: the rigid meshes moved by their nodes,
the meshed flexible parts deformed (times ``scale``) and the beams as polylines through their
nodes (ParaView's *Tube* filter gives them volume). Point data: ``von_mises`` [Pa] (NaN where
a shape has no stress) and ``shape`` (index of the shape, to threshold or colour by part).
"""

from __future__ import annotations

import os
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from drivedyn.viewer.scene import Scene


def _rotation(q: np.ndarray) -> np.ndarray:
    """Rotation matrix of a unit quaternion (x, y, z, w)."""
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def frame_geometry(scene: Scene, f: int, scale: float = 1.0):
    """(points (n, 3), triangles (m, 3), lines (k, 2), von_mises (n,), shape id (n,)) of
    frame ``f`` in the global frame [m, Pa]."""
    pts, tris, lines, vm, sid = [], [], [], [], []
    base = 0

    def pose(node: int) -> tuple[np.ndarray, np.ndarray]:
        if node < 0:
            return np.zeros(3), np.eye(3)
        return scene.position[f, node], _rotation(scene.quaternion[f, node])

    k = 0
    for m in scene.meshes:
        x, R = pose(m.node)
        pts.append(m.vertices @ R.T + x)
        tris.append(m.triangles + base)
        vm.append(np.full(len(m.vertices), np.nan))
        sid.append(np.full(len(m.vertices), k))
        base += len(m.vertices)
        k += 1
    for p in scene.parts:
        x, R = pose(p.node)
        pts.append((p.points + scale * p.displacement[f]) @ R.T + x)
        tris.append(p.triangles + base)
        vm.append(p.stress[f])
        sid.append(np.full(len(p.points), k))
        base += len(p.points)
        k += 1
    for b in scene.beams:
        P = scene.position[f, b.nodes]
        P = b.rigid[f] + scale * (P - b.rigid[f])
        pts.append(P)
        n = len(P)
        lines.append(np.column_stack([np.arange(n - 1), np.arange(1, n)]) + base)
        vm.append(b.stress[f])
        sid.append(np.full(n, k))
        base += n
        k += 1
    def cat(a: list, shape: tuple) -> np.ndarray:
        return np.concatenate(a) if a else np.zeros(shape)

    return (cat(pts, (0, 3)), cat(tris, (0, 3)).astype(np.int64),
            cat(lines, (0, 2)).astype(np.int64), cat(vm, (0,)), cat(sid, (0,)))


def write_vtk(scene: Scene, out_dir: str | os.PathLike, scale: float = 1.0,
              name: str = "scene") -> Path:
    """Write ``<out_dir>/<name>_<frame>.vtu`` for every frame and ``<out_dir>/<name>.pvd``;
    returns the ``.pvd`` path."""
    import meshio

    d = Path(out_dir)
    d.mkdir(parents=True, exist_ok=True)
    entries = []
    for f in range(scene.frames):
        P, T, L, vm, sid = frame_geometry(scene, f, scale)
        cells = [("triangle", T)] + ([("line", L)] if len(L) else [])
        fn = f"{name}_{f:05d}.vtu"
        meshio.write(d / fn, meshio.Mesh(P, cells, point_data={
            "von_mises": vm, "shape": sid.astype(np.float64)}), binary=True)
        entries.append(f'  <DataSet timestep="{scene.time[f]:.9g}" part="0" '
                       f"file={quoteattr(fn)}/>")
    pvd = d / f"{name}.pvd"
    pvd.write_text('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
                   "<Collection>\n" + "\n".join(entries) + "\n</Collection>\n</VTKFile>\n")
    return pvd
