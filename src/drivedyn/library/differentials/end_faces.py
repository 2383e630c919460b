"""The end faces of a gear turning in a pocket of the housing (the Type C planets, the Type
B element gears): each axial end of the gear rubs on the pocket's floor, an annular
thrust-washer contact a small axial play beyond it. One builder for every differential."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from drivedyn.elements.contact import FrictionLaw, NormalLaw, ThrustWasherContact
from drivedyn.model.spec import Spec

Z = (0.0, 0.0, 1.0)
MZ = (0.0, 0.0, -1.0)


def add_end_faces(sp: Spec, gear: str, pos: Any, half: float, gap: float, r_int: float,
                  r_ext: float, law: NormalLaw, friction: FrictionLaw | None,
                  tags: tuple[str, str] = ("f", "r"),
                  film: Callable[[str, str, str], Any] | None = None) -> None:
    """The two end faces of ``gear`` (at ``-half`` and ``+half`` [m] along its axis from its
    centre ``pos`` (3,) [m], housing frame) on the pocket floors of the ``housing`` body,
    ``gap`` [m] beyond them.

    Adds, per end ``tag`` (``tags[0]`` at ``-half``, ``tags[1]`` at ``+half``), the markers
    ``floor_{gear}{tag}`` (on the housing, normal towards the gear) and ``face_{gear}{tag}``
    (on the gear) and the contact ``{gear}_end_{tag}``: a :class:`ThrustWasherContact` of the
    annulus ``r_int..r_ext`` [m] with ``law`` and ``friction``, or ``film(name, marker_a,
    marker_b)`` (an oil film element) if given.
    """
    pos = np.asarray(pos, dtype=float)
    for tag, zf, axis in ((tags[0], -half, Z), (tags[1], half, MZ)):
        floor = zf + math.copysign(gap, zf)
        a, b = f"floor_{gear}{tag}", f"face_{gear}{tag}"
        sp.add_marker(a, "housing", position=pos + np.array([0.0, 0.0, floor]), axis=axis)
        sp.add_marker(b, gear, position=(0, 0, zf), axis=Z)
        if film is not None:
            sp.add(film(f"{gear}_end_{tag}", a, b))
        else:
            sp.add(ThrustWasherContact(f"{gear}_end_{tag}", a, b, law=law, r_int=r_int,
                                       r_ext=r_ext, friction=friction))
