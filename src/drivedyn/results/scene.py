"""The visual scene of a model, stored in its results file for the 3-D viewer.

:func:`scene_description` resolves every visual shape the model declares (element specs'
``visuals()``, the spec's own ``Spec.visuals`` added by library models) from its marker to
the node carrying it, so that a results file alone is enough to draw the mechanism: the
viewer (:mod:`drivedyn.viewer`) combines this description with the nodes' ``position`` and
``rotation`` histories. Bodies that no shape covers are drawn as the box of equal mass and
principal moments of inertia. Beams and meshed flexible parts are drawn from their own
results variables (topology attribute ``beam_elements``; ``<part>.mesh_points`` ...).

The description is a JSON-ready dict::

    {"version": 1,
     "shapes":  [{"kind", "role", "label", "params", "node", "position" (3,) [m],
                  "rotation" (9,) row-major, marker frame in the node frame,
                  "variable"? , "opacity"?, "node_b"? "position_b"? (point forces)}, ...],
     "markers": [{"name", "node", "position", "rotation"}, ...],
     "beams":   [{"element", "radius" [m]}, ...],
     "road":    [{"name", "node", "position", "rotation" (the wheel marker), "height",
                  "mu", "patches" [[x_start, x_end, mu], ...], "transition", "radius",
                  "width"}, ...]  (one per tyre: the road under it, from its element),
     "length":  size of the largest shape [m]}

``node`` is a node name or ``"ground"`` (fixed global frame).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from drivedyn.model.model import Model

#: roles that do not count as a body's own shape (a body with only these gets a box): a
#: washer on a housing's face is not the housing, a spring or bushing on an arm not the arm
_NOT_SOLID = ("joint", "force", "washer", "spring", "damper", "stop", "bushing")
#: opacity of the inertia boxes: stand-ins, they must not hide the declared shapes
EQUIVALENT_OPACITY = 0.35


def _node_name(model: Model, i: int) -> str:
    return "ground" if i >= model.nn else model.nodes[i].name


def inertia_box(mass: float, inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Edge lengths (3,) [m] and orientation (3, 3) of the homogeneous box with the given
    mass [kg] and inertia tensor about its centre (3, 3) [kg m^2]: with principal moments
    J_i, the edges are a_i = sqrt(6 (J_j + J_k - J_i) / m)."""
    J, V = np.linalg.eigh(0.5 * (inertia + inertia.T))
    if np.linalg.det(V) < 0:
        V[:, 2] *= -1.0
    s = np.array([J[1] + J[2] - J[0], J[0] + J[2] - J[1], J[0] + J[1] - J[2]])
    a = np.sqrt(6.0 * np.maximum(s, 0.0) / mass)
    floor = 0.02 * a.max() if a.max() > 0 else 1e-3  # a flat body still shows some thickness
    return np.maximum(a, floor), V


def _beam_radius(section: Any) -> float:
    for name in ("outer_diameter", "diameter"):
        d = getattr(section, name, None)
        if d:
            return 0.5 * float(d)
    dims = [getattr(section, n, None) for n in ("width_y", "height_z", "y_max", "z_max")]
    dims = [float(d) for d in dims if d]
    if dims:
        return 0.5 * max(dims) if hasattr(section, "width_y") else max(dims)
    area = getattr(section, "area", None)
    return float(np.sqrt(area / np.pi)) if area else 0.0


def _same_gear(a: dict, b: dict) -> bool:
    """Two gear shapes are one wheel drawn twice (a sun in four meshes) when they sit on
    the same node, at the same place, with the same axis and tooth count."""
    return (a["node"] == b["node"] and a["params"]["teeth"] == b["params"]["teeth"]
            and np.allclose(a["position"], b["position"], atol=1e-9)
            and np.allclose(a["rotation"][2::3], b["rotation"][2::3], atol=1e-9))


def scene_description(model: Model) -> dict[str, Any]:
    """The visual scene of ``model`` (see the module docstring)."""
    spec = model.spec
    shapes: list[dict[str, Any]] = []
    visuals = [*spec.visuals]
    for e in spec.elements:
        visuals.extend(e.visuals())
    for v in visuals:
        if v.marker not in model.marker_frames:
            continue
        node, pos, rot = model.marker_frames[v.marker]
        d = v.as_dict()
        d.update(node=_node_name(model, node), position=[float(p) for p in pos],
                 rotation=[float(r) for r in np.asarray(rot).ravel()])
        if v.marker_b:
            if v.marker_b not in model.marker_frames:
                continue
            nb, pb, _ = model.marker_frames[v.marker_b]
            d.update(node_b=_node_name(model, nb), position_b=[float(p) for p in pb])
        if d["kind"] == "gear" and any(s["kind"] == "gear" and _same_gear(s, d)
                                       for s in shapes):
            continue
        shapes.append(d)
    covered = {s["node"] for s in shapes if s["role"] not in _NOT_SOLID}
    beam_nodes = {model.nodes[int(n)].name for g in model.groups if g.family == "beam"
                  for n in g.lnodes.ravel() if int(n) < model.nn}
    for info in model.nodes:
        if info.body is None or info.name in covered or info.name in beam_nodes:
            continue
        if info.mass <= 0.0:
            continue
        size, V = inertia_box(info.mass, np.asarray(info.inertia, dtype=float))
        shapes.append({"kind": "box", "role": "body", "label": info.name,
                       "params": {"sx": float(size[0]), "sy": float(size[1]),
                                  "sz": float(size[2])},
                       "node": info.name, "position": [0.0, 0.0, 0.0],
                       "rotation": [float(r) for r in V.ravel()], "equivalent": True,
                       "opacity": EQUIVALENT_OPACITY})
    markers = [{"name": name, "node": _node_name(model, n),
                "position": [float(p) for p in pos],
                "rotation": [float(r) for r in np.asarray(rot).ravel()]}
               for name, (n, pos, rot) in model.marker_frames.items()]
    beams = [{"element": e.name, "radius": _beam_radius(e.section)}
             for e in spec.elements if getattr(e, "family", "") == "beam"]
    return {"version": 1, "shapes": shapes, "markers": markers, "beams": beams,
            "road": _road(model), "length": _length_scale(shapes)}


def _road(model: Model) -> list[dict[str, Any]]:
    """The road under each tyre element (its ``road()`` description on its wheel marker)."""
    out = []
    for e in model.spec.elements:
        describe = getattr(e, "road", None)
        if not callable(describe):
            continue
        road = describe()
        marker = e.markers()[0]
        if road is None or marker not in model.marker_frames:
            continue
        node, pos, rot = model.marker_frames[marker]
        road.update(name=e.name, node=_node_name(model, node),
                    position=[float(p) for p in pos],
                    rotation=[float(r) for r in np.asarray(rot).ravel()])
        out.append(road)
    return out


_SIZE_KEYS = ("radius", "length", "pitch_radius", "face_width", "sx", "sy", "sz")


def _length_scale(shapes: list[dict[str, Any]]) -> float:
    """Size of the largest shape [m] (the viewer combines it with the nodes' spread)."""
    sizes = [abs(v) for s in shapes for k, v in s["params"].items() if k in _SIZE_KEYS]
    return max([*sizes, 1e-3])
