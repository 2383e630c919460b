"""One corner of an axle of either suspension type: the builder and the geometry check of
the section's ``type`` (``"double_wishbone"``: :mod:`.double_wishbone`, ``"macpherson"``:
:mod:`.macpherson`), so that a vehicle takes either type per axle."""

from __future__ import annotations

from typing import Literal

from drivedyn.library.vehicles.suspensions import double_wishbone, macpherson
from drivedyn.library.vehicles.suspensions.double_wishbone import Corner
from drivedyn.library.vehicles.suspensions.geometry import Mount
from drivedyn.library.vehicles.suspensions.macpherson import MacPhersonCorner
from drivedyn.library.vehicles.suspensions.schema import DoubleWishboneFile, MacPhersonFile
from drivedyn.model.spec import Spec

#: a built corner of either type (both have ``prefix``, ``side``, ``upright``, ``hub``,
#: ``wheel_center``, ``lower_arm``, ``tie_rod``, ``spring``, ``damper``, the stops,
#: ``joints``, ``bushings``, ``points`` and ``spring_markers``)
AnyCorner = Corner | MacPhersonCorner
#: an axle's section of either type
AnySuspension = DoubleWishboneFile | MacPhersonFile


def check_suspension(p: AnySuspension) -> None:
    """The geometry check of ``p``'s type (:func:`.double_wishbone.check_geometry` or
    :func:`.macpherson.check_geometry`)."""
    if isinstance(p, MacPhersonFile):
        macpherson.check_geometry(p)
    else:
        double_wishbone.check_geometry(p)


def add_corner(sp: Spec, prefix: str, side: Literal["left", "right"], p: AnySuspension,
               mount: Mount, steer: str | None = None,
               rigid_bushings: bool = False) -> AnyCorner:
    """One corner of ``p`` by its type: :func:`.double_wishbone.add_double_wishbone` or
    :func:`.macpherson.add_macpherson` (the same arguments)."""
    if isinstance(p, MacPhersonFile):
        return macpherson.add_macpherson(sp, prefix, side, p, mount, steer=steer,
                                         rigid_bushings=rigid_bushings)
    return double_wishbone.add_double_wishbone(sp, prefix, side, p, mount, steer=steer,
                                               rigid_bushings=rigid_bushings)
