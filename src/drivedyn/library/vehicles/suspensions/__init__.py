"""Suspension and steering library: parametric subsystems a vehicle is assembled from.

* :func:`add_double_wishbone` builds one corner of a :class:`DoubleWishboneFile` (arms,
  upright, tie rod, coil-over, stops; bushings or ideal pivots at the chassis pickups) and
  returns a :class:`Corner` (its upright, hub marker, wheel centre and element names);
* :func:`add_macpherson` builds one corner of a :class:`MacPhersonFile` (lower arm, upright
  with the damper tube, strut rod sliding in it, top mount, tie rod, spring and damper on the
  strut axis, stops) and returns a :class:`MacPhersonCorner` with the same names;
  :func:`add_corner` builds either by the section's ``type`` (:func:`check_suspension`
  checks either's geometry);
* :func:`add_rack_steering` builds a :class:`SteeringFile`'s rack on a prismatic joint
  driven by a steering function and returns a :class:`Rack` (whose markers the front
  corners' tie rods attach to);
* :func:`add_anti_roll_bar` builds a suspension's anti-roll bar between its two corners;
* :func:`corner_rig` puts a corner on a wheel-pad rig (kinematics and wheel rate by
  statics), :func:`design_point` gives its wheel load, installation ratio and wheel rate at
  the design position and :func:`free_length_for_load` the spring's free length for a
  wanted wheel load there (the ride height);
* :func:`load_suspensions` reads a :class:`SuspensionSet` (front, rear, steering) from a
  TOML file or a shipped name (:data:`SHIPPED`: ``"hmmwv"``, the data set of Project
  Chrono's HMMWV, double wishbones; ``"generic_macpherson"``, Chrono's generic MacPherson
  struts; the provenance of each number in the file).

Each builder takes ``mount(name, point)``, a function of the vehicle that creates a marker on
the chassis at a global point and returns its name: the library does not know whether the
chassis is a rigid body or a frame of beams. See docs/suspensions.md.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from drivedyn.errors import ModelError
from drivedyn.library.vehicles.suspensions.anti_roll_bar import AntiRollBar, add_anti_roll_bar
from drivedyn.library.vehicles.suspensions.corner import (
    AnyCorner,
    AnySuspension,
    add_corner,
    check_suspension,
)
from drivedyn.library.vehicles.suspensions.double_wishbone import (
    Corner,
    add_double_wishbone,
    check_geometry,
)
from drivedyn.library.vehicles.suspensions.geometry import Mount, wheel_angles
from drivedyn.library.vehicles.suspensions.macpherson import MacPhersonCorner, add_macpherson
from drivedyn.library.vehicles.suspensions.rig import (
    DesignPoint,
    corner_rig,
    design_point,
    free_length_for_load,
)
from drivedyn.library.vehicles.suspensions.schema import (
    AntiRollBarFile,
    DoubleWishboneFile,
    MacPhersonFile,
    SteeringFile,
    SuspensionFile,
    SuspensionSet,
)
from drivedyn.library.vehicles.suspensions.steering import Rack, add_rack_steering

#: shipped data sets: name -> file beside this module
SHIPPED = {"hmmwv": Path(__file__).with_name("hmmwv.toml"),
           "generic_macpherson": Path(__file__).with_name("generic_macpherson.toml")}


def load_suspensions(source: str | Path, overrides: dict[str, Any] | None = None,
                     overrides_key: str = "overrides") -> SuspensionSet:
    """The :class:`SuspensionSet` of a shipped name (:data:`SHIPPED`) or a TOML file path,
    with ``overrides`` (a nested table of the file's keys, e.g. ``{"front": {"spring":
    {"rate": 5e4}}}``) replacing the file's values; :class:`ModelError` naming the file, the
    key path (``<overrides_key>.<path>`` for a value the overrides gave) and the value
    otherwise."""
    path = SHIPPED.get(str(source), Path(source))
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except OSError as exc:
        raise ModelError(f"suspension file {str(source)!r}: {exc.strerror} (shipped: "
                         f"{', '.join(SHIPPED)})") from None
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"suspension file {str(path)!r}: {exc}") from None
    merged(data, overrides or {})
    try:
        return SuspensionSet.model_validate(data)
    except ValidationError as exc:
        lines = []
        for e in exc.errors():
            key = ".".join(str(x) for x in e["loc"])
            if _given(overrides or {}, e["loc"]):
                key = f"{overrides_key}.{key}"
            lines.append(f"{key}: {e['msg']} (got {e.get('input')!r})")
        raise ModelError(f"suspension file {str(path)!r}: " + "; ".join(lines)) from None


def merged(data: dict[str, Any], overrides: dict[str, Any]) -> dict[str, Any]:
    """``data`` with the values of the nested table ``overrides`` put in by key (tables
    merged, anything else replaced), in place; returns ``data``."""
    for k, v in overrides.items():
        if isinstance(v, dict) and isinstance(data.get(k), dict):
            merged(data[k], v)
        else:
            data[k] = v
    return data


def _given(overrides: dict[str, Any], loc: tuple) -> bool:
    """Whether the overrides give the value at ``loc`` (or a table that holds it)."""
    node: Any = overrides
    for part in loc:
        if not isinstance(node, dict) or part not in node:
            return False
        node = node[part]
        if not isinstance(node, dict):
            return True
    return True


__all__ = [
    "SHIPPED",
    "AntiRollBar",
    "AntiRollBarFile",
    "AnyCorner",
    "AnySuspension",
    "Corner",
    "DesignPoint",
    "DoubleWishboneFile",
    "MacPhersonCorner",
    "MacPhersonFile",
    "Mount",
    "Rack",
    "SteeringFile",
    "SuspensionFile",
    "SuspensionSet",
    "add_anti_roll_bar",
    "add_corner",
    "add_double_wishbone",
    "add_macpherson",
    "add_rack_steering",
    "check_geometry",
    "check_suspension",
    "corner_rig",
    "design_point",
    "free_length_for_load",
    "load_suspensions",
    "merged",
    "wheel_angles",
]
