"""What the RWD vehicle's parameters must satisfy beyond their schema, checked before
anything is built, each refusal naming the key and the value: the suspension set with its
overrides and each axle's geometry, the steering's travel, the tyre file and the side it
was measured on, the differentials and the final drive.

Tyre sides (:func:`measured_side`): a property file describes the tyre on the side of the
vehicle it was measured on. The file's ``[MODEL] TYRESIDE`` says which, and the tyre is
mirrored for the wheels on the other side (with a note, :func:`tyre_notes`), as MF-Tyre
and Adams do. A file without ``TYRESIDE`` is used as it is on both sides only if its tyre
is symmetric (:func:`~drivedyn.tyres.side_asymmetry` below :data:`SYMMETRY_TOLERANCE`);
an asymmetric one (ply-steer, conicity) is refused until ``wheels.tyre_side`` says where
it was measured: guessing would put its ply-steer on the wrong side of the vehicle, a
pull of the same sign on both axles. A ``wheels.tyre_side`` that contradicts the file's
``TYRESIDE`` is refused.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from drivedyn.elements import GearPair
from drivedyn.errors import ModelError
from drivedyn.library.vehicles.bevel_differential import check_bevel, check_mesh
from drivedyn.library.vehicles.suspensions import (
    SHIPPED,
    SuspensionSet,
    check_suspension,
    load_suspensions,
)
from drivedyn.library.vehicles.suspensions.steering import peak_magnitude
from drivedyn.library.vehicles.vehicle_4wd.model import FINAL_DRIVE_KEYS, _final_drive_geometry
from drivedyn.library.vehicles.vehicle_rwd.schema import VehicleRWDFile
from drivedyn.timefunctions import as_time_function
from drivedyn.tyres import Tyre, read_tir, resolve_tyre, shipped, shipped_files, side_asymmetry
from drivedyn.tyres.tir import file_side, parse_tir

#: the wheels' sides
SIDES = {"l": "left", "r": "right"}


#: largest :func:`~drivedyn.tyres.side_asymmetry` of a tyre used as it is on both sides
#: when its file does not say which side it was measured on
SYMMETRY_TOLERANCE = 1e-3


def _tyre_file(p: VehicleRWDFile, base_dir: str | Path) -> Path | None:
    """The property file of ``wheels.tyre`` (relative to ``base_dir`` first, then a shipped
    name or a path as given); None for a simple formula or a file that does not exist
    (:func:`~drivedyn.tyres.resolve_tyre` says which)."""
    name = p.wheels.tyre
    path = Path(base_dir) / name
    if path.exists() and not Path(name).is_absolute():
        return path
    if name in shipped_files():
        return shipped(name)
    return Path(name) if Path(name).is_file() else None


def measured_side(p: VehicleRWDFile, base_dir: str | Path = ".") -> str | None:
    """The side of the vehicle the tyre file was measured on (``"left"``, ``"right"``,
    ``"symmetric"``; None for a simple formula), by the rules of
    :class:`~drivedyn.library.vehicles.vehicle_rwd.schema.Wheels`: the file's ``[MODEL]
    TYRESIDE``, else ``wheels.tyre_side``, else ``"symmetric"`` for a symmetric tyre.
    :class:`ModelError` naming the keys and values for a ``tyre_side`` that contradicts the
    file and for a file without ``TYRESIDE`` whose tyre is not symmetric."""
    path = _tyre_file(p, base_dir)
    if path is None:
        return None
    name, given = p.wheels.tyre, p.wheels.tyre_side
    try:
        in_file = file_side(parse_tir(path))
        tyre = read_tir(path) if in_file is None and given is None else None
    except ModelError as exc:
        raise ModelError(f"wheels.tyre = {name!r}: {exc}") from None
    if in_file is not None:
        if given is not None and given != in_file:
            raise ModelError(
                f"wheels.tyre_side = {given!r} contradicts the file of wheels.tyre = {name!r}, "
                f"whose [MODEL] TYRESIDE = {in_file.upper()!r}: remove wheels.tyre_side (the "
                "file's side is used, mirrored for the wheels on the other side) or correct "
                "the file")
        return in_file
    if given is not None:
        return given
    asym = side_asymmetry(tyre)
    if not asym <= SYMMETRY_TOLERANCE:
        raise ModelError(
            f"wheels.tyre = {name!r}: the file gives no [MODEL] TYRESIDE and its tyre is not "
            f"symmetric (mirrored, its lateral force or aligning moment changes by "
            f"{asym:.1%} of its largest value: ply-steer, conicity, camber terms), so the "
            "side it was measured on matters; set wheels.tyre_side = 'left' or 'right' (it "
            "is mirrored for the wheels on the other side) or 'symmetric' (used as it is on "
            "both sides)")
    return "symmetric"


def load_tyre(p: VehicleRWDFile, base_dir: str | Path = ".", side: str | None = None) -> Tyre:
    """The tyre of ``wheels.tyre`` (shipped name or a path relative to ``base_dir``) for a
    wheel on ``side`` (``"left"``, ``"right"``; None: as the file gives it): a file measured
    on the other side (:func:`measured_side`) is mirrored."""
    name = p.wheels.tyre
    measured = measured_side(p, base_dir)
    path = _tyre_file(p, base_dir)
    try:
        if path is None:
            return resolve_tyre(name, side)
        return read_tir(path, side, measured=measured)
    except ModelError as exc:
        text = str(exc)
        raise ModelError(f"wheels.{text}" if text.startswith("tyre") else
                         f"wheels.tyre = {name!r}: {text}") from None


def tyre_notes(p: VehicleRWDFile, base_dir: str | Path = ".") -> list[str]:
    """What the user should know about the tyres: which wheels get the file mirrored."""
    measured = measured_side(p, base_dir)
    if measured not in ("left", "right"):
        return []
    other = "right" if measured == "left" else "left"
    how = ("wheels.tyre_side" if p.wheels.tyre_side is not None
           else "its [MODEL] TYRESIDE")
    return [f"wheels.tyre = {p.wheels.tyre!r} was measured on the {measured} ({how}): "
            f"mirrored for the {other} wheels"]


def check_parameters(p: VehicleRWDFile, base_dir: str | Path = ".") -> None:
    """Refuse what cannot be built, naming the key: the chassis, the differentials, the
    final drive, the suspension set and its geometry, the steering's travel, the tyre file
    and its side (relative files are read from ``base_dir``)."""
    if "body" in p.chassis.model_fields_set:
        raise ModelError("chassis.body: the body the frame carries comes from [body] (mass, "
                         "cg, inertia, mounts); remove [chassis.body]")
    if p.differentials.rear in ("open", "locked", "clutch"):
        check_bevel(p.differentials.bevel)
    fd = p.final_drive
    geo = _final_drive_geometry(fd)
    check_mesh(GearPair("check", "pinion", "ring", fd.teeth_pinion, fd.teeth_ring,
                        module=fd.module, face_width=fd.face_width,
                        pressure_angle=fd.pressure_angle, kind="bevel",
                        cone_angle_a=geo["cone_pinion"], cone_angle_b=geo["cone_ring"],
                        damping_ratio=fd.damping_ratio),
               "final_drive", FINAL_DRIVE_KEYS, fd)
    susp = vehicle_suspensions(p, base_dir)
    _check_steering(p, susp)
    for side in SIDES.values():
        load_tyre(p, base_dir, side)


def _suspension_source(p: VehicleRWDFile, base_dir: str | Path) -> str | Path:
    """A shipped set's name, or the file (relative to ``base_dir`` if it is there)."""
    name = p.suspensions
    if name in SHIPPED or Path(name).is_absolute():
        return name
    path = Path(base_dir) / name
    return path if path.exists() else name


def what_suspensions(p: VehicleRWDFile) -> str:
    with_ = " with suspension_overrides" if p.suspension_overrides else ""
    return f"suspensions = {p.suspensions!r}{with_}"


def axle_error(p: VehicleRWDFile, axle: str, exc: ModelError) -> ModelError:
    """A corner's error with its keys as the user gives them: ``front.hardpoints.x``, or
    ``suspension_overrides.front.hardpoints.x`` for a value the overrides set."""

    def key(m: re.Match) -> str:
        full = f"{axle}.{m.group(0)}"
        node: Any = p.suspension_overrides
        for part in full.split("."):
            node = node.get(part) if isinstance(node, dict) else None
        return full if node is None else f"suspension_overrides.{full}"

    return ModelError(f"{what_suspensions(p)}: " + _KEY.sub(key, str(exc)))


#: keys of a corner named in the suspension library's messages
_KEY = re.compile(r"(?<![\w.])(?:hardpoints|stops|spring|damper)\.\w+")


def vehicle_suspensions(p: VehicleRWDFile, base_dir: str | Path = ".") -> SuspensionSet:
    """The suspension set with its overrides, each axle's geometry checked."""
    try:
        s = load_suspensions(_suspension_source(p, base_dir), p.suspension_overrides,
                             "suspension_overrides")
    except ModelError as exc:
        raise ModelError(f"{what_suspensions(p)}: {exc}") from None
    for axle in ("front", "rear"):
        try:
            check_suspension(getattr(s, axle))
        except ModelError as exc:
            raise axle_error(p, axle, exc) from None
    return s


def _check_steering(p: VehicleRWDFile, s: SuspensionSet) -> None:
    """Refuse a pinion angle whose rack travel exceeds the steering's ``travel_limit``."""
    st = s.steering
    travel = st.ratio * as_time_function(p.steering.pinion_angle)
    peak, t_peak = peak_magnitude(travel)
    if not peak <= st.travel_limit * (1.0 + 1e-12):  # NaN too
        raise ModelError(f"steering.pinion_angle = {p.steering.pinion_angle!r}: pinion angle "
                         f"{peak / st.ratio:.6g} rad (rack travel {peak:.6g} m) at t = "
                         f"{t_peak:g} s exceeds the rack's travel_limit = "
                         f"{st.travel_limit:g} m ({what_suspensions(p)}: "
                         f"steering.travel_limit, ratio {st.ratio:g} m/rad)")
