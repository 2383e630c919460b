"""The ``[[parts]]`` and ``[[washer_contacts]]`` sections of model files: meshed flexible
parts (mesh, material, interfaces, modes) mounted on markers, and rigid faces pressed on
their face nodes. Bad meshes, unknown names and selections that hold no node are refused
with the key and the value."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np

from drivedyn.config.elements_section import parameter_value
from drivedyn.errors import ModelError, did_you_mean
from drivedyn.model.spec import Spec

#: cells (across, around, through) of an annular_washer mesh without ``cells``
CELLS_ANNULAR_WASHER = (2, 36, 1)


def _solid_material(mf: Any, name: str, where: str):
    from drivedyn.fe import SolidMaterial

    for m in mf.materials:
        if m.name == name:
            nu = m.nu if m.nu is not None else m.E / (2.0 * m.G) - 1.0
            try:
                return SolidMaterial(m.E, nu, m.density)
            except ModelError as exc:
                raise ModelError(f"{where}.material ({name}): {exc}") from None
    raise ModelError(f"{where}.material: unknown material {name!r}"
                     f"{did_you_mean(name, [m.name for m in mf.materials])}")


def _mesh(m: Any, where: str, base_dir: Path):
    from drivedyn.fe import annular_washer, box, read_mesh, tube

    c = m.cells
    try:
        if m.shape == "annular_washer":
            return annular_washer(m.r_int, m.r_ext, m.thickness, *(c or CELLS_ANNULAR_WASHER))
        if m.shape == "tube":
            return tube(m.r_int, m.r_ext, m.length, m.flanges, *(c or (1, 24, 8)))
        if m.shape == "box":
            return box(m.lx, m.ly, m.lz, *(c or (10, 2, 2)))
        path = Path(m.path)
        return read_mesh(path if path.is_absolute() else base_dir / path, m.scale)
    except ModelError as exc:
        raise ModelError(f"{where}.mesh: {exc}") from None


def select(solid: Any, s: Any, where: str) -> np.ndarray:
    """Node indices of a :class:`~drivedyn.config.schema.SelectionFile`."""
    try:
        return solid.select(s.axis, s.value, s.r_min, s.r_max)
    except ModelError as exc:
        raise ModelError(f"{where}: {exc}") from None


def add_parts(spec: Spec, mf: Any, base_dir: Path) -> dict[str, Any]:
    """Reduce and mount the file's parts (after markers); returns name -> (solid, part)."""
    from drivedyn.fe import Interface, SolidModel, craig_bampton, face_load_patterns
    from drivedyn.model.flexible import add_flexible_body

    out: dict[str, Any] = {}
    for i, pf in enumerate(mf.parts):
        where = f"parts[{i}] ({pf.name})"
        if pf.mount not in spec.markers:
            raise ModelError(f"{where}.mount: unknown marker {pf.mount!r}"
                             f"{did_you_mean(pf.mount, spec.markers)}")
        mat = _solid_material(mf, pf.material, where)
        mesh = _mesh(pf.mesh, where, base_dir)
        try:
            solid = SolidModel(mesh, mat)
        except ModelError as exc:
            raise ModelError(f"{where}.mesh: {exc}") from None
        itfs = []
        for k, s in enumerate(pf.interfaces):
            nodes = select(solid, s, f"{where}.interfaces[{k}]")
            itfs.append(Interface(s.name or f"interface{k}", nodes,
                                  solid.nodes[nodes].mean(axis=0), s.connection))
        loads = [face_load_patterns(solid, select(solid, s, f"{where}.load_faces[{k}]"),
                                    "xyz".index(s.axis or "z"))
                 for k, s in enumerate(pf.load_faces)]
        try:
            part = craig_bampton(solid, itfs, pf.modes, pf.name,
                                 loads=np.hstack(loads) if loads else None)
            add_flexible_body(spec, pf.name, part, pf.mount, damping=pf.damping)
        except ModelError as exc:
            raise ModelError(f"{where}: {exc}") from None
        out[pf.name] = (solid, part)
    return out


def add_washer_contacts(spec: Spec, mf: Any, parts: dict[str, Any]) -> None:
    """Add the file's rigid-face-on-flexible-part contacts."""
    from drivedyn.elements.flexible import FlexibleWasherContact

    for i, w in enumerate(mf.washer_contacts):
        where = f"washer_contacts[{i}] ({w.name})"
        if w.part not in parts:
            raise ModelError(f"{where}.part: unknown part {w.part!r}"
                             f"{did_you_mean(w.part, parts)}")
        solid, _ = parts[w.part]
        mount = next(p.mount for p in mf.parts if p.name == w.part)
        # the face is given in the part's mesh frame; interface 0 is the part frame origin
        face = select(solid, w.face, f"{where}.face")
        where_points = {"face": face}
        if w.quadrature is not None:
            where_points = _quadrature_points(mf, w, where)
        fields = {f.name: f for f in dataclasses.fields(FlexibleWasherContact)}
        law = parameter_value(FlexibleWasherContact, fields["law"].type, "law", w.law,
                              f"{where}.law")
        fric = parameter_value(FlexibleWasherContact, fields["friction"].type, "friction",
                               w.friction, f"{where}.friction")
        try:
            spec.add(FlexibleWasherContact(w.name, mount, w.marker, body=w.part, **where_points,
                                           law=law, friction=fric))
        except (ModelError, TypeError) as exc:
            raise ModelError(f"{where}: {exc}") from None


def _quadrature_points(mf: Any, w: Any, where: str) -> dict[str, Any]:
    """``points`` and ``weights`` of the face quadrature of contact ``w`` (its part an
    annular washer, its face a z plane of it)."""
    from drivedyn.fe import annulus_quadrature

    m = next(p.mesh for p in mf.parts if p.name == w.part)
    f = w.face
    if m.shape != "annular_washer" or f.axis != "z" or f.value is None:
        raise ModelError(f"{where}.quadrature: expected a part meshed as an annular_washer and "
                         f"a face on a z plane (face = {{ axis = \"z\", value = ... }}), got "
                         f"mesh shape {m.shape!r} and face axis {f.axis!r}")
    n_r, n_theta = w.quadrature
    cells_r, cells_theta, _ = m.cells or CELLS_ANNULAR_WASHER
    if n_r < 1 or n_theta < 3 or cells_theta % n_theta:
        raise ModelError(f"{where}.quadrature = {[n_r, n_theta]}: expected n_r >= 1 radii per "
                         f"cell and n_theta >= 3 angles dividing the mesh's {cells_theta} cells "
                         "around (the points on its vertex radii)")
    pts, areas = annulus_quadrature(m.r_int, m.r_ext, f.value, n_r, n_theta, cells=cells_r)
    return {"points": pts, "weights": areas}
