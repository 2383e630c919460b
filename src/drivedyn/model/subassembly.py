"""Sub-assemblies: one :class:`~drivedyn.model.spec.Spec` placed inside another.

:func:`include` copies a sub-assembly (a differential built in its own frame, say) into a
larger mechanism under a name prefix, moved by a rigid placement, with the sub-assembly's
ground replaced by a body of the host (the car body a differential is bolted to). Every
reference an element holds to a marker, body, node or element of the sub-assembly is
renamed with it, so the sub-assembly's builder needs no knowledge of where it goes.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from drivedyn.errors import ModelError
from drivedyn.model.spec import GROUND, Spec

#: element families whose data hold geometry in their own frame (not moved by include)
_NOT_MOVABLE = ("flexible_body", "flexible_interface", "flexible_washer_contact")


def _rename(value: Any, names: dict[str, str]) -> Any:
    if isinstance(value, str):
        return names.get(value, value)
    if isinstance(value, tuple) and value and all(isinstance(v, str) for v in value):
        return tuple(names.get(v, v) for v in value)
    return value


def include(host: Spec, sub: Spec, prefix: str, *, position: Any = (0.0, 0.0, 0.0),
            rotation: Any = None, ground: str = GROUND,
            velocity: Any = (0.0, 0.0, 0.0)) -> dict[str, str]:
    """Copy ``sub`` into ``host``.

    Args:
        host: the mechanism receiving the copy.
        sub: the sub-assembly (unchanged).
        prefix: prepended to every name of the copy (bodies, nodes, markers, elements).
        position: (3,) [m] and rotation (3, 3): placement of the sub-assembly's global frame
            in the host's global frame (``x_host = rotation @ x_sub + position``).
        ground: host body (or node) that replaces the sub-assembly's ground: its ground
            markers become markers on it at the same place (default: the host's ground).
        velocity: (3,) [m/s] added to every copied body's initial velocity (a sub-assembly
            riding on a moving vehicle).
    Returns:
        old name -> new name of everything copied.
    Raises:
        ModelError: name clash, unknown ``ground``, or a flexible part (its mesh data are
        in its own frame).
    """
    Rp = np.eye(3) if rotation is None else np.asarray(rotation, dtype=float)
    p0 = np.asarray(position, dtype=float)
    v0 = np.asarray(velocity, dtype=float)
    if ground != GROUND and ground not in host.bodies and ground not in host.nodes:
        raise ModelError(f"include {prefix!r}: ground = {ground!r} is not a body or node of "
                         "the host")
    for e in sub.elements:
        if getattr(e, "family", "") in _NOT_MOVABLE:
            raise ModelError(f"include {prefix!r}: {type(e).__name__} {e.name!r} cannot be "
                             "moved into another assembly (flexible parts keep their mesh in "
                             "their own frame); build it in place")
    names: dict[str, str] = {}
    for n in (*sub.bodies, *sub.nodes, *sub.markers, *(e.name for e in sub.elements)):
        names[n] = prefix + n
    if ground != GROUND:
        g = host.bodies.get(ground) or host.nodes[ground]
        Rg, pg = g.rotation, g.position
    for b in sub.bodies.values():
        host.add_rigid_body(names[b.name], b.mass, b.inertia, com=b.com,
                            position=Rp @ b.position + p0, rotation=Rp @ b.rotation,
                            velocity=Rp @ b.velocity + v0,
                            angular_velocity=Rp @ b.angular_velocity)
    for nd in sub.nodes.values():
        host.add_node(names[nd.name], position=Rp @ nd.position + p0,
                      rotation=Rp @ nd.rotation, velocity=Rp @ nd.velocity + v0,
                      angular_velocity=Rp @ nd.angular_velocity)
    for m in sub.markers.values():
        if m.body == GROUND:
            pos, rot = Rp @ m.position + p0, Rp @ m.rotation
            if ground == GROUND:
                host.add_marker(names[m.name], GROUND, position=pos, rotation=rot)
            else:
                host.add_marker(names[m.name], ground, position=Rg.T @ (pos - pg),
                                rotation=Rg.T @ rot)
        else:
            host.add_marker(names[m.name], names[m.body], position=m.position,
                            rotation=m.rotation)
    for e in sub.elements:
        changes = {f.name: _rename(getattr(e, f.name), names) for f in dataclasses.fields(e)}
        host.add(dataclasses.replace(e, **changes))
    for v in sub.visuals:
        host.add_visual(v.renamed(names))
    return names
