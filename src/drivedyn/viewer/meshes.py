"""Triangle meshes of the visual shapes (:mod:`drivedyn.elements.framework.visuals`).

Each function returns ``(V, F)``: vertices (n, 3) float64 [m] in the shape's frame (z = its
axis, origin at the marker) and triangles (m, 3) int32, counter-clockwise seen from outside.
The same meshes feed the HTML viewer, glTF and VTK exports, so that every view of a run shows
the same geometry.
"""

from __future__ import annotations

from typing import Any

import numpy as np

SEGMENTS = 48  # facets around a circle


def _ring(r: float, z: float, n: int, phase: float = 0.0) -> np.ndarray:
    th = phase + 2.0 * np.pi * np.arange(n) / n
    return np.column_stack([r * np.cos(th), r * np.sin(th), np.full(n, z)])


def _strip(a0: int, b0: int, n: int, closed: bool = True) -> np.ndarray:
    """Quads between two rows of ``n`` vertices starting at ``a0`` (lower) and ``b0``
    (upper), as triangles facing outwards for counter-clockwise rows."""
    i = np.arange(n if closed else n - 1)
    j = (i + 1) % n
    return np.concatenate([np.column_stack([a0 + i, a0 + j, b0 + j]),
                           np.column_stack([a0 + i, b0 + j, b0 + i])])


def _fan(center: int, r0: int, n: int, up: bool) -> np.ndarray:
    i = np.arange(n)
    j = (i + 1) % n
    tri = np.column_stack([np.full(n, center), r0 + i, r0 + j])
    return tri if up else tri[:, [0, 2, 1]]


def cylinder_mesh(radius: float, length: float, inner_radius: float = 0.0,
                  radius_end: float | None = None, z0: float | None = None,
                  n: int = SEGMENTS) -> tuple[np.ndarray, np.ndarray]:
    """A solid or hollow cylinder (or frustum) from ``z0`` to ``z0 + length`` [m]."""
    za = -0.5 * length if z0 is None else z0
    zb = za + length
    r1 = radius if radius_end is None else radius_end
    if inner_radius <= 0.0:
        V = np.vstack([_ring(radius, za, n), _ring(r1, zb, n), [[0, 0, za]], [[0, 0, zb]]])
        F = np.vstack([_strip(0, n, n), _fan(2 * n, 0, n, up=False),
                       _fan(2 * n + 1, n, n, up=True)])
        return V, F.astype(np.int32)
    ri1 = inner_radius * (r1 / radius) if radius > 0 else inner_radius
    V = np.vstack([_ring(radius, za, n), _ring(r1, zb, n), _ring(inner_radius, za, n),
                   _ring(ri1, zb, n)])
    F = np.vstack([_strip(0, n, n),                      # outside
                   _strip(2 * n, 3 * n, n)[:, [0, 2, 1]],  # bore (facing the axis)
                   _strip(2 * n, 0, n),                  # bottom annulus (facing -z)
                   _strip(n, 3 * n, n)])                 # top annulus (facing +z)
    return V, F.astype(np.int32)


def gear_profile(teeth: int, pitch_radius: float, module: float, internal: bool = False,
                 points_per_tooth: int = 8) -> np.ndarray:
    """Transverse tooth outline (teeth * points_per_tooth, 2) [m], counter-clockwise:
    straight flanks from the root circle (1.25 m below the pitch circle) to the tip circle
    (1 m above), tooth and space equally thick on the pitch circle; an internal gear's teeth
    point inward. A drawing, not the involute: enough to see the tooth count and motion."""
    ha, hf = module, 1.25 * module
    r_tip, r_root = ((pitch_radius - ha, pitch_radius + hf) if internal
                     else (pitch_radius + ha, pitch_radius - hf))
    pitch = 2.0 * np.pi / teeth
    # angular half-widths at tip and root (flanks at about 20 deg to the radius; the same
    # for an internal gear, whose tips are its inner ends)
    w_pitch = 0.25 * pitch
    slope = np.tan(np.radians(20.0)) / pitch_radius
    w_tip = max(w_pitch - slope * ha, 0.05 * pitch)
    w_root = min(w_pitch + slope * hf, 0.45 * pitch)
    pts = []
    for k in range(teeth):
        c = k * pitch
        # root land before the tooth, flank up, tip land, flank down
        prof = [(c - 0.5 * pitch, r_root), (c - w_root, r_root), (c - w_tip, r_tip),
                (c + w_tip, r_tip), (c + w_root, r_root)]
        # subdivide the tip land so the outline stays round for few points per tooth
        extra = max(points_per_tooth - 5, 0)
        for i in range(extra):
            f = (i + 1) / (extra + 1)
            prof.insert(3 + i, (c - w_tip + 2 * w_tip * f, r_tip))
        pts.extend(prof)
    a = np.array(pts)
    return np.column_stack([a[:, 1] * np.cos(a[:, 0]), a[:, 1] * np.sin(a[:, 0])])


def gear_mesh(teeth: float, pitch_radius: float, face_width: float, module: float,
              helix_angle: float = 0.0, internal: float = 0.0, cone_angle: float = 0.0,
              **_: Any) -> tuple[np.ndarray, np.ndarray]:
    """A toothed wheel of face width ``face_width`` centred on z = 0: the transverse outline
    (:func:`gear_profile`) swept along z and turned by ``z tan(beta) / r`` (the helix); an
    internal gear is a ring with an outer rim; a bevel gear (``cone_angle`` > 0) narrows
    towards +z like its pitch cone."""
    z = round(teeth)
    internal = bool(internal)
    prof = gear_profile(z, pitch_radius, module, internal, points_per_tooth=5)
    n = len(prof)
    layers = 1 if helix_angle == 0.0 else max(2, int(np.ceil(abs(np.tan(helix_angle))
                                                             * face_width / pitch_radius
                                                             / (2 * np.pi / z) * 4)) + 1)
    zs = np.linspace(-0.5 * face_width, 0.5 * face_width, layers + 1)
    rows = []
    for zz in zs:
        phi = zz * np.tan(helix_angle) / pitch_radius
        c, s = np.cos(phi), np.sin(phi)
        scale = 1.0 - zz * np.tan(cone_angle) / pitch_radius if cone_angle else 1.0
        xy = scale * (prof @ np.array([[c, s], [-s, c]]))
        rows.append(np.column_stack([xy, np.full(n, zz)]))
    V = np.vstack(rows)
    F = [_strip(k * n, (k + 1) * n, n) for k in range(layers)]
    if internal:
        F = [f[:, [0, 2, 1]] for f in F]  # the teeth face the axis
        rim = pitch_radius + 2.5 * module
        base = len(V)
        # the rim turns with the teeth, layer by layer (one straight quad over a large twist
        # would cut into the ring)
        for row in rows:
            ang = np.arctan2(row[:, 1], row[:, 0])
            V = np.vstack([V, np.column_stack([rim * np.cos(ang), rim * np.sin(ang), row[:, 2]])])
        F += [_strip(base + k * n, base + (k + 1) * n, n) for k in range(layers)]  # outer rim
        F += [_strip(0, base, n),                                     # bottom annulus (-z)
              _strip(layers * n, base + layers * n, n)[:, [0, 2, 1]]]  # top annulus (+z)
    else:
        base = len(V)
        V = np.vstack([V, [[0, 0, zs[0]], [0, 0, zs[-1]]]])
        F += [_fan(base, 0, n, up=False), _fan(base + 1, layers * n, n, up=True)]
    return V, np.vstack(F).astype(np.int32)


def box_mesh(sx: float, sy: float, sz: float) -> tuple[np.ndarray, np.ndarray]:
    """A box centred on the origin with edges (sx, sy, sz) [m] (flat-shaded: 24 vertices)."""
    h = 0.5 * np.array([sx, sy, sz])
    V, F = [], []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            u, v = (axis + 1) % 3, (axis + 2) % 3
            quad = []
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = np.zeros(3)
                p[axis] = sign * h[axis]
                p[u] = a * h[u]
                p[v] = b * h[v]
                quad.append(p)
            k = len(V)
            V.extend(quad)
            tri = [[k, k + 1, k + 2], [k, k + 2, k + 3]]
            F.extend(tri if sign > 0 else [t[::-1] for t in tri])
    return np.array(V), np.array(F, dtype=np.int32)


def sphere_mesh(radius: float, n: int = 24) -> tuple[np.ndarray, np.ndarray]:
    """A UV sphere of ``radius`` [m]."""
    rows = [np.array([[0.0, 0.0, -radius]])]
    for k in range(1, n // 2):
        th = -0.5 * np.pi + np.pi * k / (n // 2)
        rows.append(_ring(radius * np.cos(th), radius * np.sin(th), n))
    rows.append(np.array([[0.0, 0.0, radius]]))
    V = np.vstack(rows)
    nr = n // 2 - 1
    F = [_fan(0, 1, n, up=False)]
    for k in range(nr - 1):
        F.append(_strip(1 + k * n, 1 + (k + 1) * n, n))
    F.append(_fan(len(V) - 1, 1 + (nr - 1) * n, n, up=True))
    return V, np.vstack(F).astype(np.int32)


def shape_mesh(shape: dict[str, Any]) -> tuple[np.ndarray, np.ndarray] | None:
    """The mesh of a scene shape (``kind`` and ``params`` as stored by
    :mod:`drivedyn.results.scene`) in its marker frame, or None for the kinds drawn as lines
    (``axes``, ``arrow``)."""
    p = dict(shape["params"])
    kind = shape["kind"]
    if kind == "cylinder":
        return cylinder_mesh(p["radius"], p["length"], p.get("inner_radius", 0.0),
                             p.get("radius_end"), p.get("z0"))
    if kind == "gear":
        return gear_mesh(**p)
    if kind == "box":
        return box_mesh(p["sx"], p["sy"], p["sz"])
    if kind == "sphere":
        return sphere_mesh(p["radius"])
    return None


def transformed(V: np.ndarray, position: Any, rotation: Any) -> np.ndarray:
    """Vertices moved from a marker frame into its node frame: ``p + R v``."""
    R = np.asarray(rotation, dtype=float).reshape(3, 3)
    return V @ R.T + np.asarray(position, dtype=float)
