"""A run's animated 3-D scene, built from its results file alone.

:func:`build_scene` combines the scene description that the run stored
(:mod:`drivedyn.results.scene`: shapes on nodes) with the nodes' position and rotation
histories, the beams' node histories and the meshed flexible parts' fields. The HTML viewer,
the glTF and the VTK exports all write this one :class:`Scene`.

Frames: every node's pose at each frame is ``x`` [m] (global) and the unit quaternion
``(x, y, z, w)`` of its rotation (body to global). Deformable bodies carry their own
per-frame vertex data: a beam chain its nodes' positions and the positions of the rigid
motion that fits them best (so that a deformation scale factor magnifies the deformation
only), a flexible part the elastic displacement of its surface nodes in its host frame.
"""

from __future__ import annotations

import itertools
import json
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from drivedyn.viewer.meshes import shape_mesh, transformed

#: default colours by role (RGB 0..1) and opacities
COLOURS = {"gear": (0.80, 0.62, 0.25), "shaft": (0.55, 0.57, 0.62), "washer": (0.30, 0.55, 0.85),
           "case": (0.62, 0.66, 0.72), "housing": (0.55, 0.62, 0.70),
           "body": (0.60, 0.60, 0.66), "wheel": (0.15, 0.15, 0.17), "pin": (0.50, 0.52, 0.58),
           "chassis": (0.70, 0.20, 0.20), "part": (0.65, 0.65, 0.70), "joint": (0.1, 0.1, 0.1),
           "force": (0.85, 0.15, 0.15), "road": (0.4, 0.4, 0.42),
           "spring": (0.95, 0.70, 0.10), "damper": (0.35, 0.36, 0.40),
           "stop": (0.12, 0.12, 0.12), "bushing": (0.08, 0.08, 0.08)}
OPACITY = {"case": 0.3, "housing": 0.3, "chassis": 0.25}


@dataclass
class Mesh:
    """A rigid triangle mesh on one node: vertices (n, 3) [m] in the node frame."""

    name: str
    node: int  # index into Scene.nodes; -1: ground (global frame)
    role: str
    vertices: np.ndarray
    triangles: np.ndarray
    colour: tuple[float, float, float]
    opacity: float
    equivalent: bool = False  # an inertia box standing in for an undeclared shape


@dataclass
class Arrow:
    """A force arrow, per frame in the global frame: where it starts (nf, 3) [m] and the
    force (nf, 3) in ``unit`` (its length on screen follows the force)."""

    name: str
    origin: np.ndarray
    vector: np.ndarray
    unit: str


@dataclass
class Beam:
    """A chain of beam nodes: node indices (nb,), tube radius [m], the per-frame positions
    of the rigid motion fitting the chain (nf, nb, 3) and a per-frame von Mises stress at the
    nodes (nf, nb) [Pa] (NaN: not recorded)."""

    name: str
    nodes: np.ndarray
    radius: float
    rigid: np.ndarray
    stress: np.ndarray


@dataclass
class Part:
    """A meshed flexible part on its host node: the surface triangles (m, 3) over its
    surface nodes, their undeformed positions (ns, 3) and elastic displacements
    (nf, ns, 3) [m] in the host frame, and the von Mises stress (nf, ns) [Pa]."""

    name: str
    node: int
    triangles: np.ndarray
    points: np.ndarray
    displacement: np.ndarray
    stress: np.ndarray


@dataclass
class Link:
    """A tube between two moving points (a shaft joining two bodies, a damper, a bump stop's
    stub) or a coil spring: its ends ``a``, ``b`` (nf, 3) [m] in the global frame, its
    ``radius`` [m] (a coil's: of the helix), and for a coil its ``turns`` and the ``wire``'s
    radius [m] (``turns`` 0: a straight tube)."""

    name: str
    a: np.ndarray
    b: np.ndarray
    radius: float
    colour: tuple[float, float, float]
    role: str = "shaft"
    turns: float = 0.0
    wire: float = 0.0


#: sizes of the links and coils whose radius is 0, as fractions of the initial distance of
#: their ends: a tube, a stub (a bump stop's rubber), a coil and its wire (of the coil)
LINK_RADIUS, STUB_RADIUS, COIL_RADIUS, COIL_WIRE = 0.05, 0.08, 0.15, 0.12
#: the lengths of a shape declared ``relative`` (fractions of the mechanism's size)
_SIZE_KEYS = ("radius", "length", "inner_radius", "radius_end", "z0", "sx", "sy", "sz")


def _link(s: dict, node: int, nb: int, X: np.ndarray, Rm: np.ndarray) -> Link:
    """The :class:`Link` of a ``link`` or ``coil`` shape (sizes from its ends' initial
    distance where it gives none; a stub's far end ``fraction`` of the way)."""
    prm = s["params"]
    a = _pose(node, X, Rm, np.asarray(s["position"], dtype=float))
    b = _pose(nb, X, Rm, np.asarray(s["position_b"], dtype=float))
    length0 = float(np.linalg.norm(b[0] - a[0]))
    radius = float(prm.get("radius", 0.0))
    colour = COLOURS[s["role"]]
    if s["kind"] == "coil":
        radius = radius or COIL_RADIUS * length0
        wire = float(prm.get("wire", 0.0)) or COIL_WIRE * radius
        return Link(s["label"], a, b, radius, colour, s["role"], float(prm.get("turns", 7.0)),
                    wire)
    fraction = prm.get("fraction")
    if fraction:
        d = b - a
        n = np.linalg.norm(d, axis=1, keepdims=True)
        reach = np.minimum(float(fraction) * length0, n)
        b = a + d / np.maximum(n, 1e-300) * reach
        radius = radius or STUB_RADIUS * length0
    return Link(s["label"], a, b, radius or LINK_RADIUS * length0, colour, s["role"])


@dataclass
class Footprint:
    """A tyre's contact patch on the road at each frame: ``centre`` (nf, 3) [m] (global,
    on the road plane under the wheel centre), ``heading`` (nf, 3) the unit rolling
    direction in the road plane, ``length`` (nf,) [m] (the chord the road cuts from the
    unloaded tyre circle: 0 when the wheel is off the road) and ``width`` [m]."""

    name: str
    centre: np.ndarray
    heading: np.ndarray
    length: np.ndarray
    width: float


@dataclass
class RoadFriction:
    """One friction value of the road, for the legend: ``mu`` (the tyres' road friction
    factor), its colour and the tyres that run on it."""

    mu: float
    colour: tuple[float, float, float]
    tyres: list[str]


@dataclass
class Scene:
    """Everything the viewer draws, over ``nf`` frames.

    Attributes:
        title: what the page shows as its title.
        time: (nf,) [s].
        nodes: node names (nn).
        position: (nf, nn, 3) [m], global frame.
        quaternion: (nf, nn, 4) rotation of each node, (x, y, z, w), body to global.
        meshes, arrows, beams, parts, links, footprints: see the classes; the road is
            meshes of role ``"road"`` on the ground (one lane per tyre, coloured by its
            friction), ``road`` the legend of its friction values.
        markers: (name, node, position (3,), rotation (3, 3) in the node frame).
        joints: joint frames (same layout as markers), drawn on request.
        length: characteristic size of the mechanism [m] (camera distance, arrow sizes).
        warnings: what could not be drawn, and why.
    """

    title: str
    time: np.ndarray
    nodes: list[str]
    position: np.ndarray
    quaternion: np.ndarray
    meshes: list[Mesh] = field(default_factory=list)
    arrows: list[Arrow] = field(default_factory=list)
    beams: list[Beam] = field(default_factory=list)
    parts: list[Part] = field(default_factory=list)
    links: list[Link] = field(default_factory=list)
    footprints: list[Footprint] = field(default_factory=list)
    road: list[RoadFriction] = field(default_factory=list)
    markers: list[tuple[str, int, np.ndarray, np.ndarray]] = field(default_factory=list)
    joints: list[tuple[str, int, np.ndarray, np.ndarray]] = field(default_factory=list)
    length: float = 1.0
    warnings: list[str] = field(default_factory=list)

    @property
    def frames(self) -> int:
        return len(self.time)


def quaternions(R: np.ndarray) -> np.ndarray:
    """Unit quaternions (..., 4) as (x, y, z, w) of rotation matrices (..., 3, 3), by the
    largest-diagonal branch (Shepperd), continuous in sign along the first axis."""
    R = np.asarray(R, dtype=float)
    shp = R.shape[:-2]
    M = R.reshape(-1, 3, 3)
    q = np.empty((len(M), 4))
    tr = np.trace(M, axis1=1, axis2=2)
    d = np.stack([M[:, 0, 0], M[:, 1, 1], M[:, 2, 2], tr], axis=1)
    k = np.argmax(d, axis=1)
    for i in range(len(M)):
        m = M[i]
        if k[i] == 3:
            s = 2.0 * np.sqrt(1.0 + tr[i])
            q[i] = ((m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s,
                    0.25 * s)
        elif k[i] == 0:
            s = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
            q[i] = (0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s,
                    (m[2, 1] - m[1, 2]) / s)
        elif k[i] == 1:
            s = 2.0 * np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
            q[i] = ((m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s,
                    (m[0, 2] - m[2, 0]) / s)
        else:
            s = 2.0 * np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
            q[i] = ((m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s,
                    (m[1, 0] - m[0, 1]) / s)
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    q = q.reshape(*shp, 4)
    if q.ndim == 3:  # (nf, nn, 4): keep each node's sign continuous for interpolation
        for f in range(1, q.shape[0]):
            flip = np.einsum("nk,nk->n", q[f], q[f - 1]) < 0
            q[f, flip] *= -1.0
    return q


def frame_indices(nt: int, frames: int) -> np.ndarray:
    """At most ``frames`` output indices spread evenly over ``nt`` outputs, the first and the
    last included."""
    if nt <= frames:
        return np.arange(nt)
    return np.unique(np.round(np.linspace(0, nt - 1, frames)).astype(int))


def _rigid_fit(P: np.ndarray, P0: np.ndarray) -> np.ndarray:
    """Per frame, the positions of the rigid motion of ``P0`` (nb, 3) that best fits ``P``
    (nf, nb, 3) in least squares (Kabsch)."""
    c0 = P0.mean(axis=0)
    out = np.empty_like(P)
    for f in range(len(P)):
        c = P[f].mean(axis=0)
        H = (P0 - c0).T @ (P[f] - c)
        U, _, Vt = np.linalg.svd(H)
        D = np.diag([1.0, 1.0, np.sign(np.linalg.det(Vt.T @ U.T)) or 1.0])
        R = Vt.T @ D @ U.T
        out[f] = (P0 - c0) @ R.T + c
    return out


def _chains(elements: dict[str, list[str]]) -> list[tuple[list[str], list[str]]]:
    """Beam elements joined into chains of nodes: [(node names, element names)]."""
    left = dict(elements)
    chains = []
    while left:
        e, (a, b) = next(iter(left.items()))
        del left[e]
        nodes, elems = [a, b], [e]
        grown = True
        while grown:
            grown = False
            for k, (p, q) in list(left.items()):
                if p == nodes[-1]:
                    nodes.append(q)
                elif q == nodes[0]:
                    nodes.insert(0, p)
                else:
                    continue
                elems.append(k)
                del left[k]
                grown = True
        chains.append((nodes, elems))
    return chains


def _surface(cells: np.ndarray) -> np.ndarray:
    """Boundary triangles (m, 3) of a linear hexahedral (8) or tetrahedral (4) mesh, outward
    for the usual node orders (faces used by one cell only)."""
    if cells.shape[1] == 8:
        faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6),
                 (3, 0, 4, 7)]
    else:
        faces = [(0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)]
    allf = [cells[:, list(f)] for f in faces]
    F = np.concatenate(allf)
    key = np.sort(F, axis=1)
    _, idx, cnt = np.unique(key, axis=0, return_index=True, return_counts=True)
    outer = F[idx[cnt == 1]]
    if outer.shape[1] == 4:
        outer = np.concatenate([outer[:, [0, 1, 2]], outer[:, [0, 2, 3]]])
    return outer


def build_scene(ds: Any, frames: int = 400, title: str = "") -> Scene:
    """The :class:`Scene` of a results Dataset ``ds`` with at most ``frames`` frames.

    Raises:
        ValueError: the file holds no scene (written before drivedyn recorded one) or no
            node histories.
    """
    raw = ds.attrs.get("scene")
    if raw is None:
        raise ValueError("this results file holds no scene description (written by an older "
                         "drivedyn); run the model again to view it")
    desc = json.loads(raw)
    if "error" in desc:
        raise ValueError(f"the run could not record its scene: {desc['error']}")
    nodes = sorted({str(v)[:-len(".rotation")] for v in ds.data_vars
                    if str(v).endswith(".rotation") and ds[v].dims[1:] == ("row", "col")},
                   key=lambda n: list(ds.data_vars).index(n + ".rotation"))
    if not nodes:
        raise ValueError("this results file records no node positions and rotations")
    nt = ds.sizes["time"]
    idx = frame_indices(nt, frames)
    t = np.asarray(ds["time"].values, dtype=float)[idx]
    X = np.stack([np.asarray(ds[f"{n}.position"].values)[idx] for n in nodes], axis=1)
    Rm = np.stack([np.asarray(ds[f"{n}.rotation"].values)[idx] for n in nodes], axis=1)
    index = {n: i for i, n in enumerate(nodes)}
    index["ground"] = -1
    scene = Scene(title or str(ds.attrs.get("model_source", "drivedyn run")), t, nodes, X,
                  quaternions(Rm))
    size = _spread(X)  # the mechanism's size: the scale of the "relative" shapes
    for s in desc.get("shapes", []):
        node = index.get(s["node"])
        if node is None:
            scene.warnings.append(f"{s['label']}: node {s['node']!r} not recorded")
            continue
        if s["kind"] == "axes":
            scene.joints.append((s["label"], node, np.asarray(s["position"]),
                                 np.asarray(s["rotation"]).reshape(3, 3)))
            continue
        if s["kind"] in ("link", "coil"):
            nb = index.get(s.get("node_b", ""))
            if nb is not None:
                scene.links.append(_link(s, node, nb, X, Rm))
            continue
        if s["kind"] in ("arrow", "point_force"):
            arrow = _arrow(s, ds, idx, index, X, Rm)
            if arrow is not None:
                scene.arrows.append(arrow)
            continue
        if s["params"].get("relative"):
            s = {**s, "params": {k: v * size if k in _SIZE_KEYS else v
                                 for k, v in s["params"].items()}}
        mesh = shape_mesh(s)
        if mesh is None:
            continue
        V = transformed(mesh[0], s["position"], s["rotation"])
        role = s["role"]
        scene.meshes.append(Mesh(s["label"], node, role, V, mesh[1], COLOURS[role],
                                 float(s.get("opacity", OPACITY.get(role, 1.0))),
                                 bool(s.get("equivalent", False))))
    for name, node, pos, rot in ((m["name"], index.get(m["node"]), m["position"],
                                  m["rotation"]) for m in desc.get("markers", [])):
        if node is not None:
            scene.markers.append((name, node, np.asarray(pos), np.asarray(rot).reshape(3, 3)))
    _add_beams(scene, ds, desc, idx, index)
    _add_parts(scene, ds, idx, index)
    _add_road(scene, desc.get("road", []), index, X, Rm)
    scene.length = max(size, float(desc.get("length", 0.0)), 1e-3)
    return scene


def _spread(X: np.ndarray) -> float:
    """The largest extent [m] of the nodes (nf, nn, 3) at the first frame (0 for one node)."""
    return float(np.ptp(X[0], axis=0).max()) if X.shape[1] > 1 else 0.0


def _pose(node: int, X: np.ndarray, Rm: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Global positions (nf, 3) of point ``p`` (3,) of a node (-1: ground) over the frames."""
    if node < 0:
        return np.broadcast_to(p, (X.shape[0], 3)).copy()
    return X[:, node] + np.einsum("fij,j->fi", Rm[:, node], p)


def _arrow(s: dict, ds: Any, idx: np.ndarray, index: dict[str, int], X: np.ndarray,
           Rm: np.ndarray) -> Arrow | None:
    """The per-frame global origin and force of an ``arrow`` or ``point_force`` shape, or
    None when its variables are not in the results."""
    var = s.get("variable", "")
    node = index.get(s["node"])
    Rs = np.asarray(s["rotation"]).reshape(3, 3)
    pa = _pose(node, X, Rm, np.asarray(s["position"], dtype=float))
    nf = len(idx)
    # the marker's axis over the frames (global)
    axis = (np.broadcast_to(Rs[:, 2], (nf, 3)) if node < 0
            else np.einsum("fij,j->fi", Rm[:, node], Rs[:, 2]))
    if s["kind"] == "arrow":
        if var not in ds:
            return None
        v = np.asarray(ds[var].values, dtype=float)[idx]
        return Arrow(s["label"], pa, v[:, None] * axis, ds[var].attrs.get("units", ""))
    nb = index.get(s.get("node_b", ""))
    if nb is None:
        return None
    pb = _pose(nb, X, Rm, np.asarray(s["position_b"], dtype=float))
    d = pb - pa
    d -= np.einsum("fi,fi->f", d, axis)[:, None] * axis  # in the plane normal to the axis
    n = d / np.maximum(np.linalg.norm(d, axis=1), 1e-300)[:, None]
    origin = pa + s["params"]["reach"] * n
    if s["params"].get("radial"):
        if var not in ds:
            return None
        vec = -np.asarray(ds[var].values, dtype=float)[idx][:, None] * n
        unit = ds[var].attrs.get("units", "")
    else:
        comps = [f"{var}_{c}" for c in "xyz"]
        if any(c not in ds for c in comps):
            return None
        vec = np.stack([np.asarray(ds[c].values, dtype=float)[idx] for c in comps], axis=1)
        unit = ds[comps[0]].attrs.get("units", "")
    return Arrow(s["label"], origin, vec, unit)


def _add_beams(scene: Scene, ds: Any, desc: dict, idx: np.ndarray,
               index: dict[str, int]) -> None:
    topo = json.loads(ds.attrs.get("beam_elements", "{}"))
    if not topo:
        return
    radius = {b["element"]: b["radius"] for b in desc.get("beams", [])}
    X = scene.position
    for k, (names, elems) in enumerate(_chains(topo)):
        if any(n not in index for n in names):
            scene.warnings.append(f"beam chain {elems[0]}: nodes not recorded")
            continue
        ni = np.array([index[n] for n in names])
        P = X[:, ni]
        rigid = _rigid_fit(P, P[0]) if len(ni) > 2 else P.copy()
        # nodal stress: mean of the adjacent elements' von Mises stress
        stress = np.full((len(idx), len(ni)), np.nan)
        acc = np.zeros((len(idx), len(ni)))
        cnt = np.zeros(len(ni))
        for e in elems:
            a, b = topo[e]
            var = f"{e}.von_mises"
            if var not in ds:
                continue
            v = np.asarray(ds[var].values, dtype=float)[idx]
            for n in (a, b):
                j = names.index(n)
                acc[:, j] += v
                cnt[j] += 1
        ok = cnt > 0
        stress[:, ok] = acc[:, ok] / cnt[ok]
        r = max(radius.get(e, 0.0) for e in elems) or 0.01 * scene.length
        scene.beams.append(Beam(f"beam {k + 1} ({elems[0]}...)", ni, r, rigid, stress))


def _add_parts(scene: Scene, ds: Any, idx: np.ndarray, index: dict[str, int]) -> None:
    for v in ds.data_vars:
        name = str(v)
        if not name.endswith(".mesh_points"):
            continue
        part = name[:-len(".mesh_points")]
        host = ds[name].attrs.get("host")
        if host not in index or f"{part}.q" not in ds:
            scene.warnings.append(f"{part}: host node or elastic coordinates not recorded")
            continue
        cells = np.asarray(ds[f"{part}.mesh_cells"].values, dtype=np.int64)
        tri = _surface(cells)
        used = np.unique(tri)
        remap = -np.ones(int(cells.max()) + 1, dtype=np.int64)
        remap[used] = np.arange(len(used))
        basis = np.asarray(ds[f"{part}.basis"].values)[used]          # (ns, 3, nq)
        q = np.asarray(ds[f"{part}.q"].values)[idx]                    # (nf, nq)
        u = np.einsum("ndk,tk->tnd", basis, q)
        vm = (np.asarray(ds[f"{part}.von_mises"].values)[idx][:, used]
              if f"{part}.von_mises" in ds else np.full(u.shape[:2], np.nan))
        scene.parts.append(Part(part, index[host], remap[tri].astype(np.int32),
                                np.asarray(ds[name].values)[used], u, vm))


#: road colours: pale ice at mu <= 0.001, blue at 0.03, asphalt at mu >= 1 (log scale)
_ROAD_STOPS = ((-3.0, (0.86, 0.94, 1.00)), (np.log10(0.03), (0.30, 0.55, 0.88)),
               (0.0, (0.22, 0.22, 0.25)))


def road_colour(mu: float) -> tuple[float, float, float]:
    """The colour of road friction ``mu`` (ramp over log10 mu, :data:`_ROAD_STOPS`)."""
    x = float(np.clip(np.log10(max(mu, 1e-12)), _ROAD_STOPS[0][0], _ROAD_STOPS[-1][0]))
    for (x0, c0), (x1, c1) in itertools.pairwise(_ROAD_STOPS):
        if x <= x1:
            f = (x - x0) / (x1 - x0)
            return tuple(float(a + f * (b - a)) for a, b in zip(c0, c1, strict=True))
    return _ROAD_STOPS[-1][1]


def lane_segments(mu: float, patches: list[list[float]], x0: float, x1: float
                  ) -> list[tuple[float, float, float]]:
    """``(start, end, mu)`` [m] covering ``[x0, x1]``: ``mu`` outside the patches, a patch's
    value inside it, later patches winning where they overlap (as the tyre element reads
    them; the element blends over its ``transition`` at the edges, drawn sharp here)."""
    cuts = sorted({x0, x1, *(x for p in patches for x in p[:2] if x0 < x < x1)})
    out: list[tuple[float, float, float]] = []
    for a, b in itertools.pairwise(cuts):
        m = 0.5 * (a + b)
        value = mu
        for p in patches:
            if p[0] <= m < p[1]:
                value = p[2]
        if out and out[-1][2] == value:
            out[-1] = (out[-1][0], b, value)
        else:
            out.append((a, b, value))
    return out


def _add_road(scene: Scene, road: list[dict], index: dict[str, int], X: np.ndarray,
              Rm: np.ndarray) -> None:
    """The lane of road each tyre runs on (ground meshes coloured by friction over the
    wheel's travel, with a run-up of two tyre radii each way), the tyres' footprints and
    the legend. Lanes that would overlap (a front and a rear tyre on one track with their
    own friction each) share the track's width side by side, the front tyre's outside."""
    from drivedyn.viewer.meshes import box_mesh

    lanes = []
    for r in road:
        node = index.get(r["node"])
        if node is None:
            scene.warnings.append(f"{r['name']}: node {r['node']!r} not recorded")
            continue
        R0, width, h = r["radius"], r["width"], r["height"]
        centre = _pose(node, X, Rm, np.asarray(r["position"], dtype=float))
        Rs = np.asarray(r["rotation"]).reshape(3, 3)
        axle = (np.broadcast_to(Rs[:, 2], centre.shape) if node < 0
                else np.einsum("fij,j->fi", Rm[:, node], Rs[:, 2]))
        heading = np.cross(axle, [0.0, 0.0, 1.0])
        heading /= np.maximum(np.linalg.norm(heading, axis=1), 1e-300)[:, None]
        above = centre[:, 2] - h
        chord = 2.0 * np.sqrt(np.maximum(R0 * R0 - above * above, 0.0))
        ground = centre.copy()
        ground[:, 2] = h
        scene.footprints.append(Footprint(r["name"], ground, heading, chord, width))
        pad = 2.0 * R0
        lanes.append({"road": r, "x0": float(centre[:, 0].min()) - pad,
                      "x1": float(centre[:, 0].max()) + pad,
                      "y": 0.5 * float(centre[:, 1].min() + centre[:, 1].max()),
                      "w": float(np.ptp(centre[:, 1])) + 2.5 * width,
                      "front": float(centre[:, 0].mean())})
    # tracks: lanes whose strips overlap are split across the track's width
    tracks: list[list[dict]] = []
    for lane in lanes:
        for t in tracks:
            if any(abs(lane["y"] - o["y"]) < 0.5 * (lane["w"] + o["w"])
                   and lane["x0"] < o["x1"] and o["x0"] < lane["x1"] for o in t):
                t.append(lane)
                break
        else:
            tracks.append([lane])
    legend: dict[float, list[str]] = {}
    for t in tracks:
        t.sort(key=lambda o: -o["front"])
        w = max(o["w"] for o in t)
        y_out = float(np.mean([o["y"] for o in t]))
        side = 1.0 if y_out >= 0 else -1.0  # outside: away from the vehicle's centre line
        for k, lane in enumerate(t):
            r = lane["road"]
            strip = w / len(t)
            y = y_out + side * (0.5 * w - (k + 0.5) * strip)
            for a, b, mu in lane_segments(r["mu"], r["patches"], lane["x0"], lane["x1"]):
                thick = 1e-3 * r["radius"]
                V, F = box_mesh(b - a, strip, thick)
                V = V + np.array([0.5 * (a + b), y, r["height"] - 0.5 * thick])
                scene.meshes.append(Mesh(f"{r['name']} road (mu {mu:g})", -1, "road", V, F,
                                         road_colour(mu), 1.0))
                legend.setdefault(mu, []).append(r["name"])
    scene.road = [RoadFriction(mu, road_colour(mu), sorted(set(names)))
                  for mu, names in sorted(legend.items())]
