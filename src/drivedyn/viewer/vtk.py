"""VTK export for ParaView: one ``.vtu`` file per frame and a ``.pvd`` index with the times.

Each frame holds every shape in the global frame: the rigid meshes moved by their nodes,
the meshed flexible parts deformed (times ``scale``) and the beams as polylines through their
nodes (ParaView's *Tube* filter gives them volume) and the force arrows as vertices at their
points of application. Point data: ``von_mises`` [Pa] (NaN where a shape has no stress),
``shape`` (index of the shape, to threshold or colour by part) and ``force`` [N] (the contact
and mesh forces at the arrows' vertices, zero elsewhere: ParaView's *Glyph* filter draws them).
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


def frame_geometry(scene: Scene, f: int, scale: float = 1.0) -> dict[str, np.ndarray]:
    """Frame ``f`` in the global frame: ``points`` (n, 3) [m], ``triangles`` (m, 3),
    ``lines`` (k, 2), ``vertices`` (a,) (the force arrows' points), and per point
    ``von_mises`` (n,) [Pa], ``shape`` (n,) and ``force`` (n, 3) [N]."""
    pts, tris, lines, vm, sid = [], [], [], [], []
    base = 0

    def pose(node: int) -> tuple[np.ndarray, np.ndarray]:
        if node < 0:
            return np.zeros(3), np.eye(3)
        return scene.position[f, node], _rotation(scene.quaternion[f, node])

    def add(P: np.ndarray, stress: np.ndarray | None, k: int) -> int:
        pts.append(P)
        vm.append(np.full(len(P), np.nan) if stress is None else stress)
        sid.append(np.full(len(P), k))
        return base + len(P)

    k = 0
    for m in scene.meshes:
        x, R = pose(m.node)
        tris.append(m.triangles + base)
        base = add(m.vertices @ R.T + x, None, k)
        k += 1
    for p in scene.parts:
        x, R = pose(p.node)
        tris.append(p.triangles + base)
        base = add((p.points + scale * p.displacement[f]) @ R.T + x, p.stress[f], k)
        k += 1
    for b in scene.beams:
        P = scene.position[f, b.nodes]
        n = len(P)
        lines.append(np.column_stack([np.arange(n - 1), np.arange(1, n)]) + base)
        base = add(b.rigid[f] + scale * (P - b.rigid[f]), b.stress[f], k)
        k += 1
    first_arrow = base
    for a in scene.arrows:
        base = add(a.origin[f][None, :], None, k)
        k += 1

    def cat(a: list, shape: tuple) -> np.ndarray:
        return np.concatenate(a) if a else np.zeros(shape)

    points = cat(pts, (0, 3))
    force = np.zeros_like(points)
    if scene.arrows:
        force[first_arrow:] = np.stack([a.vector[f] for a in scene.arrows])
    return {"points": points, "triangles": cat(tris, (0, 3)).astype(np.int64),
            "lines": cat(lines, (0, 2)).astype(np.int64),
            "vertices": np.arange(first_arrow, base, dtype=np.int64),
            "von_mises": cat(vm, (0,)), "shape": cat(sid, (0,)), "force": force}


def write_vtk(scene: Scene, out_dir: str | os.PathLike, scale: float = 1.0,
              name: str = "scene") -> Path:
    """Write ``<out_dir>/<name>_<frame>.vtu`` for every frame and ``<out_dir>/<name>.pvd``;
    returns the ``.pvd`` path."""
    import meshio

    d = Path(out_dir)
    d.mkdir(parents=True, exist_ok=True)
    entries = []
    for f in range(scene.frames):
        g = frame_geometry(scene, f, scale)
        cells = [("triangle", g["triangles"])]
        if len(g["lines"]):
            cells.append(("line", g["lines"]))
        if len(g["vertices"]):
            cells.append(("vertex", g["vertices"][:, None]))
        fn = f"{name}_{f:05d}.vtu"
        meshio.write(d / fn, meshio.Mesh(g["points"], cells, point_data={
            "von_mises": g["von_mises"], "shape": g["shape"].astype(np.float64),
            "force": g["force"]}), binary=True)
        entries.append(f'  <DataSet timestep="{scene.time[f]:.9g}" part="0" '
                       f"file={quoteattr(fn)}/>")
    pvd = d / f"{name}.pvd"
    pvd.write_text('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
                   "<Collection>\n" + "\n".join(entries) + "\n</Collection>\n</VTKFile>\n")
    return pvd
