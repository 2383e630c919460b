"""Schema of the four-wheel-drive vehicle model file (``library = "vehicle_4wd"``).

Every value is SI or a string with units; unknown keys are refused and every problem is reported
with its key path. What cannot be checked key by key (the centre of gravity between the axles,
the tyre file, the differential files) is checked when the model is built
(:func:`drivedyn.library.vehicles.vehicle_4wd.model.check_parameters`).
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import AfterValidator, Field, model_validator

import drivedyn.units as U  # noqa: N812 - short name for units
from drivedyn.library.differentials.schema_sections import (
    Body,
    PositiveTime,
    PositiveVelocity,
    Provenance,
    Solver,
    TorqueValue,
)
from drivedyn.schema_base import (
    MAX_TEETH,
    Angle,
    Damping,
    Inertia,
    Length,
    Mass,
    PositiveLength,
    Strict,
    TorsionalDamping,
    TorsionalStiffness,
    scalar,
)


def _pressure_angle(v: float) -> float:
    if not math.radians(10.0) <= v <= math.radians(30.0):
        raise ValueError(f"expected 10..30 deg, got {math.degrees(v):.6g} deg")
    return v


Velocity = Annotated[float, scalar(U.VELOCITY)]  # signed (initial speed)
#: normal pressure angle of a gear mesh [rad], 10 to 30 deg (standard 20; 14.5 to 25 in use)
PressureAngle = Annotated[float, scalar(U.ANGLE), AfterValidator(_pressure_angle)]
ForceValue = Annotated[float, scalar(U.FORCE, nonneg=True)]
Time = Annotated[float, scalar(U.TIME, nonneg=True)]  # may be 0 (a start time)

#: the differential types a position accepts
DIFF_TYPES = ("open", "locked", "clutch", "torsen-c", "torsen-b")
DiffType = Literal["open", "locked", "clutch", "torsen-c", "torsen-b"]
WHEELS = ("fl", "fr", "rl", "rr")


class Info(Strict):
    library: Literal["vehicle_4wd"]
    name: str = "vehicle-4wd"
    description: str = ""
    notes: dict[str, str] = Field(default_factory=dict)


class CarBody(Strict):
    """The car body: a lumped mass moving in the vertical plane (longitudinal, heave, pitch);
    the wheels are hinged to it (no suspension: the tyres' vertical stiffness carries the
    load transfer), the differentials are hinged to it."""

    mass: Mass = 1400.0
    inertia: Inertia = (450.0, 1800.0, 2000.0)
    wheelbase: PositiveLength = 2.6
    track: PositiveLength = 1.5
    cg_height: PositiveLength = 0.55
    cg_to_front: PositiveLength = 1.3
    speed: Velocity = 0.0


class Wheels(Strict):
    """Each wheel with its hub and the outer half of its half-shaft; ``tyre`` is a shipped
    property file name, a ``.tir`` path (relative to the model file) or ``simple-dry``,
    ``simple-wet``, ``simple-snow``, ``simple-ice`` (the simple B, C, D, E sets, with
    ``simple_radius``). ``vertical_damping`` replaces the file's tyre damping: without
    suspension it stands for the dampers too."""

    mass: Mass = 25.0
    inertia: Inertia = (0.8, 1.2, 0.8)
    tyre: str = "pac2002_235_60R16"
    simple_radius: PositiveLength = 0.33
    relaxation: bool = True
    vertical_damping: Damping | None = 3000.0
    low_speed_damping: float = Field(default=0.2, ge=0.0)


class Patch(Strict):
    """Road friction factor ``mu`` on ``x_start <= x < x_end`` under ``wheels``."""

    wheels: list[Literal["fl", "fr", "rl", "rr"]] = Field(
        default_factory=lambda: list(WHEELS))
    x_start: Length
    x_end: Length
    mu: float = Field(ge=0.0)

    @model_validator(mode="after")
    def _order(self) -> Patch:
        if not self.x_end > self.x_start:
            raise ValueError(f"expected x_start < x_end, got {self.x_start}, {self.x_end} m")
        return self


class WheelMu(Strict):
    """Road friction factor under each wheel."""

    fl: float = Field(default=0.002, ge=0.0)
    fr: float = Field(default=0.05, ge=0.0)
    rl: float = Field(default=0.01, ge=0.0)
    rr: float = Field(default=0.8, ge=0.0)


class Road(Strict):
    """Friction factor of the road under each wheel (on the tyre's LMUX, LMUY: 1 = the
    tyre's test surface, about mu = 1.1 for the shipped tyre), optional patches along x."""

    mu: WheelMu = Field(default_factory=WheelMu)
    patches: list[Patch] = Field(default_factory=list)
    transition: PositiveLength = 0.05


class Shafts(Strict):
    """Propeller shafts (central differential to the axles) and half-shafts: rigid bodies in
    bearings; their torsional compliance is a spring-damper at the differential end."""

    propshaft_mass: Mass = 8.0
    propshaft_inertia: Inertia = (0.02, 0.3, 0.3)
    propshaft_stiffness: TorsionalStiffness = 2.0e4
    propshaft_damping: TorsionalDamping = 100.0
    halfshaft_stiffness: TorsionalStiffness = 8.0e3
    halfshaft_damping: TorsionalDamping = 40.0


class FinalDrive(Strict):
    """Bevel pinion (on the propeller shaft) and ring gear (on the axle differential's
    housing), straight bevel, shaft angle 90 deg; ratio teeth_ring / teeth_pinion."""

    teeth_pinion: int = Field(default=17, gt=4, le=MAX_TEETH)
    teeth_ring: int = Field(default=17, gt=4, le=MAX_TEETH)
    module: PositiveLength = 0.005
    face_width: PositiveLength = 0.02
    pressure_angle: PressureAngle = 0.3490658503988659
    damping_ratio: float = Field(default=0.05, ge=0.0)
    stiffness_variation: bool = False


class BevelBodies(Strict):
    housing: Body = Field(default_factory=lambda: Body(mass=5.0, inertia=(0.02, 0.02, 0.03)))
    side: Body = Field(default_factory=lambda: Body(mass=1.0, inertia=(1e-3, 1e-3, 1.5e-3)))
    spider: Body = Field(default_factory=lambda: Body(mass=0.3, inertia=(1e-4, 1e-4, 1e-4)))


class ClutchPack(Strict):
    """The limited-slip parts of the ``clutch`` differential (see
    :mod:`drivedyn.library.vehicles.bevel_differential`)."""

    preload: ForceValue = 100.0
    ramp_angle: Angle = 1.0471975511965976
    ramp_radius: PositiveLength = 0.03
    mu: float = Field(default=0.1, ge=0.0)
    faces: int = Field(default=4, ge=1)
    r_int: PositiveLength = 0.025
    r_ext: PositiveLength = 0.04
    stiffness: Annotated[float, scalar(U.STIFFNESS, positive=True)] = 5.0e8
    damping: Damping = 2.0e4
    eps_v: PositiveVelocity = 1e-3
    back_offset: PositiveLength = 0.01
    inner_offset: PositiveLength = 0.008
    cross: Body = Field(default_factory=lambda: Body(mass=0.5, inertia=(5e-4, 5e-4, 8e-4)))

    @model_validator(mode="after")
    def _radii(self) -> ClutchPack:
        if not self.r_int < self.r_ext:
            raise ValueError(f"expected r_int < r_ext, got {self.r_int}, {self.r_ext} m")
        if not 0.0 < self.ramp_angle < 1.5707963267948966:
            raise ValueError(f"ramp_angle: expected 0 < angle < 90 deg, got "
                             f"{self.ramp_angle} rad")
        return self


class BevelDifferential(Strict):
    """The open / locked / clutch reference differential (a straight bevel differential)."""

    teeth_side: int = Field(default=16, gt=4, le=MAX_TEETH)
    teeth_spider: int = Field(default=10, gt=4, le=MAX_TEETH)
    spiders: int = Field(default=2, ge=2, le=4)
    profile_shift: float = 0.35  # spider +x, side gears -x (long-addendum spiders)
    module: PositiveLength = 0.0045
    face_width: PositiveLength = 0.012
    pressure_angle: PressureAngle = 0.3490658503988659
    damping_ratio: float = Field(default=0.05, ge=0.0)
    bodies: BevelBodies = Field(default_factory=BevelBodies)
    clutch: ClutchPack = Field(default_factory=ClutchPack)


class Differentials(Strict):
    """The type at each position, and where the TORSEN parameters come from (a shipped model
    name or a path to a ``torsen_c`` / ``torsen_b`` model file; its calibrated friction
    included). ``mesh_stiffness_variation``: the TORSENs' meshes with their stiffness
    varying over the mesh cycle (true) or at its mean (false) in this vehicle; None: as
    their files say (``gears.stiffness_variation``)."""

    central: DiffType = "torsen-c"
    front: DiffType = "torsen-b"
    rear: DiffType = "torsen-b"
    torsen_c: str = "torsen-c"
    torsen_b: str = "torsen-b"
    bevel: BevelDifferential = Field(default_factory=BevelDifferential)
    mesh_stiffness_variation: bool | None = None


class Load(Strict):
    """Engine torque on the central differential's housing (reacted on the car body): 0 up
    to ``start``, a smooth ramp over ``ramp``, then ``torque`` [N m]."""

    torque: TorqueValue = 100.0
    start: Time = 0.0
    ramp: PositiveTime = 0.3


class Run(Strict):
    """What ``drivedyn run`` simulates and the steady window the checks use."""

    t_end: PositiveTime = 3.0
    h_max: PositiveTime = 1e-3
    window: tuple[Time, Time] = (2.0, 3.0)

    @model_validator(mode="after")
    def _window(self) -> Run:
        a, b = self.window
        if not 0.0 <= a < b:
            raise ValueError(f"window: expected 0 <= start < end, got {[a, b]} s")
        return self


class Vehicle4WDFile(Strict):
    """The whole ``vehicle-4wd`` model file."""

    model: Info
    body: CarBody = Field(default_factory=CarBody)
    wheels: Wheels = Field(default_factory=Wheels)
    road: Road = Field(default_factory=Road)
    shafts: Shafts = Field(default_factory=Shafts)
    final_drive: FinalDrive = Field(default_factory=FinalDrive)
    differentials: Differentials = Field(default_factory=Differentials)
    load: Load = Field(default_factory=Load)
    run: Run = Field(default_factory=Run)
    solver: Solver = Field(default_factory=Solver)
    provenance: Provenance = Field(default_factory=Provenance)
