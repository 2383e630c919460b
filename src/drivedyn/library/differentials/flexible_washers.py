"""Flexible thrust washers of the differentials (``[flexible] washers = true``).

A washer is a meshed steel annulus (:func:`drivedyn.fe.annular_washer`), Craig-Bampton
reduced with its back face as the mounting interface, mounted on the body that carries the
washer in the rigid model and pressed by the counter face at the points of a quadrature rule
of the annulus (``face_quadrature``) or at every face node
(:class:`~drivedyn.elements.flexible.FlexibleWasherContact`). One builder for every
differential: the schema section is
:class:`~drivedyn.library.differentials.schema_sections.FlexibleWashers`.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from drivedyn.elements.contact import FrictionLaw
from drivedyn.library.differentials.schema_sections import Contact, FlexibleWashers
from drivedyn.model.spec import Spec


def washer_part(f: FlexibleWashers, name: str, r_int: float, r_ext: float) -> tuple[Any, Any]:
    """(solid, reduced part) of washer ``name``: steel annulus ``r_int..r_ext`` [m] of
    ``f.washer_thickness``, part frame on its back face (z = 0, face at z = thickness),
    ``f.washer_modes`` fixed-interface modes and the static modes of the face loads (cached
    on disk, and in this process: a bench builds each side's model, and the Type C's five
    washers took 0.11 s of each build from the disk cache). The parts are read, never
    changed, by the models that use them."""
    return _washer_part(f.washer_thickness, f.washer_modes, tuple(f.washer_cells),
                        f.friction_patterns, f.youngs_modulus, f.poisson_ratio, f.density,
                        name, float(r_int), float(r_ext))


# ten parts: the washers of both differentials (five and three); about 8 MB each
@functools.lru_cache(maxsize=10)
def _washer_part(thickness: float, modes: int, cells: tuple[int, int], friction: int,
                 youngs: float, poisson: float, density: float, name: str, r_int: float,
                 r_ext: float) -> tuple[Any, Any]:
    from drivedyn.fe import (
        Interface,
        SolidMaterial,
        SolidModel,
        annular_washer,
        craig_bampton,
        face_load_patterns,
    )

    nr, nt = cells
    solid = SolidModel(annular_washer(r_int, r_ext, thickness, nr, nt, 1),
                       SolidMaterial(youngs, poisson, density))
    back = Interface("back", solid.select("z", 0.0), np.zeros(3))
    loads = face_load_patterns(solid, solid.select("z", thickness), friction=friction)
    return solid, craig_bampton(solid, [back], modes, f"washer_{name}", loads=loads)


def add_flexible_washer(sp: Spec, f: FlexibleWashers, contact: Contact, name: str,
                        body_a: str, za: float, normal: float, body_b: str, zb: float,
                        r_int: float, r_ext: float, friction: FrictionLaw | None) -> None:
    """Washer ``name`` as a flexible part on ``body_a``, pressed by ``body_b``'s face.

    Args:
        sp: the model being built.
        f: the ``[flexible]`` section.
        contact: the ``[contact]`` section (the washer law without its layer: the mesh
            carries the washer's compression).
        name: washer name; adds markers ``w_{name}`` (mounting, on ``body_a``) and
            ``f_{name}`` (counter face, on ``body_b``), the part ``washer_{name}`` and the
            contact ``{name}``.
        body_a, za: the body carrying the washer and the z [m] (body frame) of the washer's
            face, where the rigid washer's face is; the back face is ``washer_thickness``
            behind it.
        normal: +1 or -1, the washer face's normal along the body's z (towards ``body_b``).
        body_b, zb: the pressing body and the z [m] (its frame) of its face.
        r_int, r_ext: radii of the annulus [m].
        friction: the face friction law, or None.
    """
    from drivedyn.elements.flexible import FlexibleWasherContact
    from drivedyn.fe import annulus_quadrature
    from drivedyn.model.flexible import add_flexible_body

    solid, part = washer_part(f, name, r_int, r_ext)
    t = f.washer_thickness
    sp.add_marker(f"w_{name}", body_a, position=(0, 0, za - t * normal),
                  axis=(0.0, 0.0, normal))
    sp.add_marker(f"f_{name}", body_b, position=(0, 0, zb), axis=(0.0, 0.0, -normal))
    fb = add_flexible_body(sp, f"washer_{name}", part, f"w_{name}")
    if f.face_quadrature == "nodes":
        face = {"face": solid.select("z", t)}
    else:
        pts, areas = annulus_quadrature(r_int, r_ext, t, *f.face_quadrature,
                                        cells=f.washer_cells[0])
        face = {"points": pts, "weights": areas}
    sp.add(FlexibleWasherContact(name, f"w_{name}", f"f_{name}", body=fb.name,
                                 **face, friction=friction,
                                 law=contact.washer_law(r_int, r_ext, layer=False)))
