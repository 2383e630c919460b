"""The ``[[materials]]``, ``[[sections]]`` and ``[[beams]]`` sections of model files.

Materials and sections are named; a section names its material and a beam its section.
Unknown names, impossible values (non-positive moduli, areas or inertias, an inner diameter
not below the outer one, zero-length elements, nodes that do not exist) are refused with the
key and the value (the element's own checks run when the model is compiled).
"""

from __future__ import annotations

from typing import Any

from drivedyn.elements.beams import (
    GeneralSection,
    GeometricallyExactBeam,
    HollowCircular,
    HollowRectangular,
    Material,
    Rectangular,
    SolidCircular,
)
from drivedyn.errors import ModelError, did_you_mean
from drivedyn.model.beams import add_straight_beam
from drivedyn.model.spec import Spec


def _materials(mf: Any) -> dict[str, Material]:
    out = {}
    for i, m in enumerate(mf.materials):
        where = f"materials[{i}] ({m.name})"
        if m.name in out:
            raise ModelError(f"{where}.name: duplicate material name {m.name!r}")
        try:
            out[m.name] = (Material.from_nu(m.E, m.nu, m.density) if m.nu is not None
                           else Material(m.E, m.G, m.density))
        except ModelError as exc:
            raise ModelError(f"{where}: {exc}") from None
    return out


def _sections(mf: Any, materials: dict[str, Material]) -> dict[str, tuple[Any, Any]]:
    """Section name -> (section, material or None)."""
    out: dict[str, tuple[Any, Any]] = {}
    for i, s in enumerate(mf.sections):
        where = f"sections[{i}] ({s.name})"
        if s.name in out:
            raise ModelError(f"{where}.name: duplicate section name {s.name!r}")
        mat = None
        if s.material is not None:
            mat = materials.get(s.material)
            if mat is None:
                raise ModelError(f"{where}.material: unknown material {s.material!r}"
                                 f"{did_you_mean(s.material, materials)}")
        try:
            if s.shape == "solid_circular":
                sec: Any = SolidCircular(s.diameter)
            elif s.shape == "hollow_circular":
                sec = HollowCircular(s.outer_diameter, s.inner_diameter)
            elif s.shape == "rectangular":
                sec = Rectangular(s.width_y, s.height_z)
            elif s.shape == "hollow_rectangular":
                sec = HollowRectangular(s.width_y, s.height_z, s.thickness)
            else:
                sec = GeneralSection(s.EA, s.GAy, s.GAz, s.GJ, s.EIy, s.EIz, s.mass_per_length,
                                     s.rotary_inertia, s.E, s.y_max, s.z_max,
                                     s.torsion_modulus)
            sec.properties(mat)
        except ModelError as exc:
            raise ModelError(f"{where}: {exc}") from None
        out[s.name] = (sec, mat)
    return out


def add_beams(spec: Spec, mf: Any) -> None:
    """Add the file's beams to ``spec`` (after its nodes and bodies)."""
    if not mf.beams:
        return
    sections = _sections(mf, _materials(mf))
    known = set(spec.nodes) | set(spec.bodies)
    for i, b in enumerate(mf.beams):
        where = f"beams[{i}] ({b.name})"
        if b.section not in sections:
            raise ModelError(f"{where}.section: unknown section {b.section!r}"
                             f"{did_you_mean(b.section, sections)}")
        sec, mat = sections[b.section]
        ends = [("node_a", b.node_a), ("node_b", b.node_b)] + \
            [(f"nodes[{k}]", n) for k, n in enumerate(b.nodes or [])]
        for key, n in ends:
            if n is not None and n not in known:
                raise ModelError(f"{where}.{key}: unknown node or body {n!r}"
                                 f"{did_you_mean(n, known)}")
        try:
            if b.nodes is not None:
                for k in range(len(b.nodes) - 1):
                    spec.add(GeometricallyExactBeam(
                        f"{b.name}.e{k}", b.nodes[k], b.nodes[k + 1], sec, mat,
                        orientation=b.orientation, damping=b.damping, curved=b.curved,
                        mass_matrix=b.mass_matrix))
            else:
                add_straight_beam(spec, b.name, b.start, b.end, b.elements, sec, mat,
                                  orientation=b.orientation, damping=b.damping,
                                  node_a=b.node_a, node_b=b.node_b, velocity=b.velocity,
                                  angular_velocity=b.angular_velocity,
                                  mass_matrix=b.mass_matrix)
        except ModelError as exc:
            raise ModelError(f"{where}: {exc}") from None
        known = set(spec.nodes) | set(spec.bodies)
