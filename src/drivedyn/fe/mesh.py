"""Solid meshes: built-in parametric meshers and import/export through meshio.

A :class:`SolidMesh` is the geometry of one meshed part: vertices ``points`` (nv, 3) [m] in the
part frame and ``cells`` (nc, 8) trilinear hexahedra or (nc, 4) linear tetrahedra. The finite
elements (:mod:`drivedyn.fe.solid`) put quadratic fields on it (27-node hexahedra, 10-node
tetrahedra): their extra nodes sit on the edges, faces and cell centres, so a curved part is
faceted by its cells while the displacement inside a cell is quadratic. Imported 10-node
tetrahedra and 27-node hexahedra keep their corner vertices (the mid-side nodes are rebuilt
on straight edges, so curved edges of an imported quadratic mesh are straightened).

Meshers (all lengths in metres, all in the part frame, z the axis of revolution):

* :func:`annular_washer` -- ring ``r_int <= r <= r_ext``, ``0 <= z <= thickness``;
* :func:`tube` -- hollow cylinder ``0 <= z <= length`` with optional flanges (rings of larger
  outer radius over z intervals), e.g. a differential case;
* :func:`box` -- ``[0, lx] x [-ly/2, ly/2] x [-lz/2, lz/2]`` (a cantilever block along x).
"""

from __future__ import annotations

import hashlib
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from drivedyn.errors import ModelError

HEX = "hex"
TET = "tet"
_MESHIO_KINDS = {"hexahedron": HEX, "hexahedron27": HEX, "tetra": TET, "tetra10": TET}
_CORNERS = {"hexahedron": 8, "hexahedron27": 8, "tetra": 4, "tetra10": 4}


@dataclass(frozen=True)
class SolidMesh:
    """Vertices and cells of a meshed part.

    Attributes:
        points: (nv, 3) vertex coordinates [m], part frame.
        cells: (nc, 8) hexahedra (VTK/meshio vertex order) or (nc, 4) tetrahedra.
        kind: ``"hex"`` or ``"tet"``.
        name: where the mesh came from (mesher and parameters, or file name).
    """

    points: np.ndarray
    cells: np.ndarray
    kind: str
    name: str = "mesh"

    def __post_init__(self) -> None:
        nper = 8 if self.kind == HEX else 4
        if self.kind not in (HEX, TET):
            raise ModelError(f"mesh {self.name!r}: kind must be 'hex' or 'tet', got {self.kind!r}")
        if self.points.ndim != 2 or self.points.shape[1] != 3 or len(self.points) < nper:
            raise ModelError(f"mesh {self.name!r}: points must be (n, 3) with n >= {nper}")
        if self.cells.ndim != 2 or self.cells.shape[1] != nper or len(self.cells) == 0:
            raise ModelError(f"mesh {self.name!r}: cells must be (n, {nper}) with n >= 1")
        if self.cells.min() < 0 or self.cells.max() >= len(self.points):
            raise ModelError(f"mesh {self.name!r}: a cell refers to a vertex that does not exist")
        if not np.all(np.isfinite(self.points)):
            raise ModelError(f"mesh {self.name!r}: non-finite vertex coordinates")

    def digest(self) -> str:
        """SHA-1 of the vertices and cells (cache key of derived data)."""
        h = hashlib.sha1(self.kind.encode())
        h.update(np.ascontiguousarray(self.points, float).tobytes())
        h.update(np.ascontiguousarray(self.cells, np.int64).tobytes())
        return h.hexdigest()

    def transformed(self, position: Sequence[float], rotation: np.ndarray) -> SolidMesh:
        """The mesh moved rigidly: ``p' = position + rotation p``."""
        p = np.asarray(position, float) + self.points @ np.asarray(rotation, float).T
        return SolidMesh(p, self.cells, self.kind, self.name)


def _hex_grid(coords: np.ndarray, nx: int, ny: int, nz: int, periodic_y: bool) -> SolidMesh:
    """Hexahedra of a structured (nx+1, ny(+1), nz+1) grid of vertices ``coords`` indexed
    ``[i, j, k]``; ``periodic_y`` closes the j direction (a full revolution)."""
    nyv = ny if periodic_y else ny + 1
    idx = np.arange((nx + 1) * nyv * (nz + 1)).reshape(nx + 1, nyv, nz + 1)
    i, j, k = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")
    j1 = (j + 1) % nyv if periodic_y else j + 1
    cells = np.stack([idx[i, j, k], idx[i + 1, j, k], idx[i + 1, j1, k], idx[i, j1, k],
                      idx[i, j, k + 1], idx[i + 1, j, k + 1], idx[i + 1, j1, k + 1],
                      idx[i, j1, k + 1]], axis=-1).reshape(-1, 8)
    return SolidMesh(coords.reshape(-1, 3), cells, HEX)


def _count(value: int, what: str, low: int = 1) -> int:
    if int(value) != value or value < low:
        raise ModelError(f"{what}: expected an integer >= {low}, got {value!r}")
    return int(value)


def _length(value: float, what: str, low: float = 0.0, strict: bool = True) -> float:
    v = float(value)
    if not math.isfinite(v) or (v <= low if strict else v < low):
        raise ModelError(f"{what}: expected a length {'>' if strict else '>='} {low} m, "
                         f"got {value!r}")
    return v


def annular_washer(r_int: float, r_ext: float, thickness: float, n_r: int = 2,
                   n_theta: int = 36, n_z: int = 1) -> SolidMesh:
    """Hexahedral ring ``r_int <= r <= r_ext``, ``0 <= z <= thickness`` [m]: ``n_r`` cells
    across the width, ``n_theta`` around, ``n_z`` through the thickness."""
    ri = _length(r_int, "annular_washer.r_int")
    re = _length(r_ext, "annular_washer.r_ext")
    h = _length(thickness, "annular_washer.thickness")
    if ri >= re:
        raise ModelError(f"annular_washer: r_int = {r_int!r} must be < r_ext = {r_ext!r}")
    nr = _count(n_r, "annular_washer.n_r")
    nt = _count(n_theta, "annular_washer.n_theta", 6)
    nz = _count(n_z, "annular_washer.n_z")
    r = np.linspace(ri, re, nr + 1)
    th = np.linspace(0.0, 2 * math.pi, nt + 1)[:-1]
    z = np.linspace(0.0, h, nz + 1)
    R, T, Z = np.meshgrid(r, th, z, indexing="ij")
    coords = np.stack([R * np.cos(T), R * np.sin(T), Z], axis=-1)
    m = _hex_grid(coords, nr, nt, nz, periodic_y=True)
    return SolidMesh(m.points, m.cells, HEX,
                     f"annular_washer(r_int={ri}, r_ext={re}, thickness={h}, n_r={nr}, "
                     f"n_theta={nt}, n_z={nz})")


def tube(r_int: float, r_ext: float, length: float, flanges: Sequence[Sequence[float]] = (),
         n_r: int = 1, n_theta: int = 24, n_z: int = 8,
         r_stations: Sequence[float] = ()) -> SolidMesh:
    """Hexahedral tube ``r_int <= r <= r_ext``, ``0 <= z <= length`` [m] with flanges.

    Each flange ``(z0, z1, r_flange)`` adds a ring ``r_ext <= r <= r_flange`` (outer flange,
    ``r_flange > r_ext``: a bolting flange) or ``r_flange <= r <= r_int`` (inner flange,
    ``r_flange < r_int``: an end plate, a shoulder or a washer seat) over ``z0 <= z <= z1``.
    The axial grid holds every flange end, so flanges share vertices with the tube wall;
    the radial grid of every ring holds the ``r_stations`` inside it (the edges of a washer
    seat, so that the seat is a union of whole cell faces).
    """
    ri = _length(r_int, "tube.r_int", strict=False)
    re = _length(r_ext, "tube.r_ext")
    L = _length(length, "tube.length")
    if ri >= re:
        raise ModelError(f"tube: r_int = {r_int!r} must be < r_ext = {r_ext!r}")
    if ri == 0.0:
        raise ModelError("tube: r_int must be > 0 (a solid shaft is a beam or a box mesh)")
    nr = _count(n_r, "tube.n_r")
    nt = _count(n_theta, "tube.n_theta", 6)
    nz = _count(n_z, "tube.n_z")
    fl = []
    for i, f in enumerate(flanges):
        if len(f) != 3:
            raise ModelError(f"tube.flanges[{i}]: expected (z0, z1, r_flange), got {f!r}")
        z0, z1, rf = (float(v) for v in f)
        if not (0.0 <= z0 < z1 <= L):
            raise ModelError(f"tube.flanges[{i}]: need 0 <= z0 < z1 <= length, got {f!r}")
        if not (rf > re or 0.0 < rf < ri):
            raise ModelError(f"tube.flanges[{i}]: r_flange = {rf!r} must be > r_ext = {re!r} "
                             f"(outer flange) or in (0, r_int = {ri!r}) (inner flange)")
        fl.append((z0, z1, rf))
    zs = set(np.linspace(0.0, L, nz + 1).tolist())
    for z0, z1, _ in fl:
        zs.update((z0, z1))
    z = np.array(sorted(zs))
    z = z[np.concatenate([[True], np.diff(z) > 1e-9 * L])]
    th = np.linspace(0.0, 2 * math.pi, nt + 1)[:-1]
    pts: list[np.ndarray] = []
    cells: list[np.ndarray] = []

    def ring(r: np.ndarray, zz: np.ndarray) -> None:
        R, T, Z = np.meshgrid(r, th, zz, indexing="ij")
        g = _hex_grid(np.stack([R * np.cos(T), R * np.sin(T), Z], axis=-1), len(r) - 1, nt,
                      len(zz) - 1, periodic_y=True)
        off = sum(len(p) for p in pts)
        pts.append(g.points)
        cells.append(g.cells + off)

    ring(_radii(ri, re, nr, r_stations), z)
    for z0, z1, rf in fl:
        zz = z[(z >= z0 - 1e-12 * L) & (z <= z1 + 1e-12 * L)]
        lo, hi = (re, rf) if rf > re else (rf, ri)
        nfr = max(1, round(nr * (hi - lo) / (re - ri)))
        ring(_radii(lo, hi, nfr, r_stations), zz)
    m = _merge(np.concatenate(pts), np.concatenate(cells), 1e-9 * L)
    return SolidMesh(m[0], m[1], HEX, f"tube(r_int={ri}, r_ext={re}, length={L}, "
                     f"flanges={fl}, n_r={nr}, n_theta={nt}, n_z={nz})")


def _radii(lo: float, hi: float, n: int, stations: Sequence[float]) -> np.ndarray:
    """``n`` equal radial cells from ``lo`` to ``hi``, split further at the stations inside."""
    r = set(np.linspace(lo, hi, n + 1).tolist())
    r.update(float(x) for x in stations if lo < x < hi)
    out = np.array(sorted(r))
    return out[np.concatenate([[True], np.diff(out) > 1e-9 * hi])]


def box(lx: float, ly: float, lz: float, nx: int = 10, ny: int = 2, nz: int = 2) -> SolidMesh:
    """Hexahedral block ``[0, lx] x [-ly/2, ly/2] x [-lz/2, lz/2]`` [m]."""
    a = _length(lx, "box.lx")
    b = _length(ly, "box.ly")
    c = _length(lz, "box.lz")
    nx_ = _count(nx, "box.nx")
    ny_ = _count(ny, "box.ny")
    nz_ = _count(nz, "box.nz")
    X, Y, Z = np.meshgrid(np.linspace(0, a, nx_ + 1), np.linspace(-b / 2, b / 2, ny_ + 1),
                          np.linspace(-c / 2, c / 2, nz_ + 1), indexing="ij")
    m = _hex_grid(np.stack([X, Y, Z], axis=-1), nx_, ny_, nz_, periodic_y=False)
    return SolidMesh(m.points, m.cells, HEX, f"box({a}, {b}, {c}, nx={nx_}, ny={ny_}, nz={nz_})")


def _merge(points: np.ndarray, cells: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Merge coincident vertices (within ``tol``) and renumber the cells."""
    key = np.round(points / tol).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    return points[first], inverse.reshape(-1)[cells]


# --- files ------------------------------------------------------------------------------------


def read_mesh(path: str | os.PathLike, scale: float = 1.0) -> SolidMesh:
    """Read a volume mesh (Gmsh ``.msh``, Abaqus ``.inp``, VTK/VTU, anything meshio reads).

    The volume cells must be hexahedra (8 or 27 nodes) or tetrahedra (4 or 10 nodes) of one
    kind; ``scale`` converts the file's length unit to metres (1e-3 for millimetres). Raises
    :class:`ModelError` naming the file for a missing or unreadable file and for a mesh
    without usable volume cells.
    """
    import meshio

    p = os.fspath(path)
    if not os.path.isfile(p):
        raise ModelError(f"mesh file {p!r}: no such file")
    s = float(scale)
    if not (math.isfinite(s) and s > 0):
        raise ModelError(f"mesh file {p!r}: scale must be > 0, got {scale!r}")
    import contextlib
    import io

    msg = io.StringIO()
    try:
        # meshio prints its diagnostics and, for some formats, calls sys.exit
        with contextlib.redirect_stdout(msg), contextlib.redirect_stderr(msg):
            m = meshio.read(p)
    except (Exception, SystemExit) as exc:  # meshio raises many types for bad files
        why = " ".join(msg.getvalue().split()) or f"{type(exc).__name__}: {exc}"
        raise ModelError(f"mesh file {p!r}: cannot be read ({why})") from None
    blocks = [(c.type, np.asarray(c.data)) for c in m.cells if c.type in _MESHIO_KINDS]
    kinds = {_MESHIO_KINDS[t] for t, _ in blocks}
    if not blocks:
        found = sorted({c.type for c in m.cells}) or ["none"]
        raise ModelError(f"mesh file {p!r}: no volume cells drivedyn can use (found "
                         f"{', '.join(found)}; expected tetra, tetra10, hexahedron or "
                         "hexahedron27)")
    if len(kinds) > 1:
        raise ModelError(f"mesh file {p!r}: mixes hexahedra and tetrahedra; use one kind")
    kind = kinds.pop()
    cells = np.concatenate([d[:, :_CORNERS[t]] for t, d in blocks]).astype(np.int64)
    used = np.unique(cells)
    remap = np.full(len(m.points), -1, np.int64)
    remap[used] = np.arange(len(used))
    pts = np.asarray(m.points, float)[used] * s
    if pts.shape[1] == 2:
        raise ModelError(f"mesh file {p!r}: the mesh is two-dimensional")
    return SolidMesh(pts, remap[cells], kind, os.path.basename(p))


def write_mesh(path: str | os.PathLike, mesh: SolidMesh) -> None:
    """Write the vertices and cells with meshio (format from the file extension)."""
    import meshio

    meshio.write(os.fspath(path), meshio.Mesh(
        mesh.points, [("hexahedron" if mesh.kind == HEX else "tetra", mesh.cells)]))
