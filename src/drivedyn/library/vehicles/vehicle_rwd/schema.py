"""Schema of the rear-wheel-drive vehicle model file (``library = "vehicle_rwd"``).

Every value is SI or a string with units; unknown keys are refused and every problem is reported
with its key path. What cannot be checked key by key (the suspension set, the tyre file, the
TORSEN file, the final-drive mesh) is checked when the model is built
(:func:`drivedyn.library.vehicles.vehicle_rwd.model.check_parameters`).
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from drivedyn.library.differentials.schema_sections import (
    PositiveTime,
    Provenance,
    Solver,
    TorqueValue,
)
from drivedyn.library.vehicles.chassis.schema import LadderFrameFile
from drivedyn.library.vehicles.vehicle_4wd.schema import (
    BevelDifferential,
    FinalDrive,
    Patch,
    PressureAngle,
    Time,
    Velocity,
)
from drivedyn.library.vehicles.vehicle_rwd.scenario_schema import Scenarios
from drivedyn.schema_base import (
    Damping,
    Inertia,
    Length,
    LengthVec,
    Mass,
    PositiveLength,
    Strict,
    TorsionalDamping,
    TorsionalStiffness,
)

WHEELS = ("fl", "fr", "rl", "rr")
#: the differential types the rear axle accepts
RearType = Literal["open", "locked", "clutch", "torsen-b"]

__all__ = ["WHEELS", "PressureAngle", "RearType", "VehicleRWDFile"]


class Info(Strict):
    library: Literal["vehicle_rwd"]
    name: str = "vehicle-rwd"
    description: str = ""
    notes: dict[str, str] = Field(default_factory=dict)


class SprungBody(Strict):
    """The sprung mass the frame carries besides its own beams and the driveline parts on
    it: ``mass`` [kg], centre of gravity ``cg`` (vehicle coordinates: x forward from mid-
    wheelbase, y left, z up from the suspensions' reference plane, the plane of Chrono's
    chassis reference) and ``inertia`` about it [kg m^2]. The frame's beams and the driveline
    parts (engine shaft, propeller shaft, rear carrier, differential) are subtracted from
    ``mass`` when the model is built, so that the sprung mass is ``mass``. ``speed``: the
    vehicle's initial forward speed [m/s] (the wheels rolling)."""

    mass: Mass = 2086.52
    cg: LengthVec = (0.056, 0.0, 0.213)
    inertia: Inertia = (1078.52, 2955.66, 3570.20)
    speed: Velocity = 0.0
    mounts: list[Length] = Field(default_factory=lambda: [1.0, 1.8, 2.7, 3.5])


class Wheels(Strict):
    """Each wheel (rim, tyre and the spindle the corner does not build) and its tyre:
    ``tyre`` is a shipped property file name or a ``.tir`` path (relative to the model
    file); ``vertical_damping`` None keeps the file's tyre damping."""

    mass: Mass = 71.105
    inertia: Inertia = (4.345, 7.388, 4.345)
    tyre: str = "hmmwv_pac02_37x12.5R16.5"
    relaxation: bool = True
    vertical_damping: Damping | None = None
    low_speed_damping: float = Field(default=0.2, ge=0.0)


class WheelMu(Strict):
    """Road friction factor under each wheel (on the tyre's LMUX, LMUY)."""

    fl: float = Field(default=1.0, ge=0.0)
    fr: float = Field(default=1.0, ge=0.0)
    rl: float = Field(default=0.1, ge=0.0)
    rr: float = Field(default=1.0, ge=0.0)


class Road(Strict):
    mu: WheelMu = Field(default_factory=WheelMu)
    patches: list[Patch] = Field(default_factory=list)
    transition: PositiveLength = 0.05


class Engine(Strict):
    """Engine and gearbox as one shaft on the frame (the gearbox output): the engine torque
    ``throttle(t) * torque`` times ``gear_ratio`` drives it, reacted on the frame; its
    inertia about its axis is ``inertia * gear_ratio^2 + output_inertia`` (the crankshaft seen
    through the gear, the torque converter locked). ``throttle`` rises smoothly from 0 at
    ``start`` to ``throttle`` at ``start + ramp``."""

    torque: TorqueValue = 926.0
    inertia: float = Field(default=1.1, gt=0.0)
    output_inertia: float = Field(default=0.5, ge=0.0)
    shaft_mass: Mass = 20.0
    gear_ratio: float = Field(default=5.855, gt=0.0)
    throttle: float = Field(default=0.08, ge=0.0, le=1.0)
    start: Time = 0.0
    ramp: PositiveTime = 0.5


class Shafts(Strict):
    """The propeller shaft (on the rear carrier, coaxial with the pinion) and its torsional
    compliance to the gearbox output, and the rigid half-shafts (a universal joint at the
    side gear, a plunging universal joint at the wheel)."""

    propshaft_mass: Mass = 12.0
    propshaft_inertia: Inertia = (0.05, 1.2, 1.2)
    propshaft_stiffness: TorsionalStiffness = 2.0e4
    propshaft_damping: TorsionalDamping = 100.0
    halfshaft_mass: Mass = 8.0
    halfshaft_inertia: Inertia = (0.4, 0.4, 0.01)
    plunger_mass: Mass = 0.5
    plunger_inertia: Inertia = (1e-3, 1e-3, 1e-3)


class Carrier(Strict):
    """The rear axle's carrier (the differential's case mounted on the frame's rear cross
    member, a rigid body fixed to the frame node there)."""

    mass: Mass = 40.0
    inertia: Inertia = (0.6, 0.4, 0.6)
    pinion_offset: PositiveLength = 0.25


class Differentials(Strict):
    rear: RearType = "torsen-b"
    torsen_b: str = "torsen-b"
    bevel: BevelDifferential = Field(default_factory=BevelDifferential)


class Steering(Strict):
    """The rack's pinion angle [rad], held (0: straight ahead)."""

    pinion_angle: float = 0.0


class Run(Strict):
    t_end: PositiveTime = 3.0
    h_max: PositiveTime = 2e-3
    window: tuple[Time, Time] = (0.8, 3.0)

    @model_validator(mode="after")
    def _window(self) -> Run:
        a, b = self.window
        if not 0.0 <= a < b:
            raise ValueError(f"window: expected 0 <= start < end, got {[a, b]} s")
        return self


class VehicleRWDFile(Strict):
    """The whole ``vehicle-rwd`` model file."""

    model: Info
    chassis: LadderFrameFile = Field(default_factory=LadderFrameFile)
    frame_origin: LengthVec = (-2.2, 0.0, 0.0)
    suspensions: str = "hmmwv"
    body: SprungBody = Field(default_factory=SprungBody)
    wheels: Wheels = Field(default_factory=Wheels)
    road: Road = Field(default_factory=Road)
    engine: Engine = Field(default_factory=Engine)
    shafts: Shafts = Field(default_factory=Shafts)
    carrier: Carrier = Field(default_factory=Carrier)
    final_drive: FinalDrive = Field(default_factory=lambda: FinalDrive(
        teeth_pinion=12, teeth_ring=60, module=0.0055, face_width=0.03,
        pressure_angle=0.4363323129985824))
    differentials: Differentials = Field(default_factory=Differentials)
    steering: Steering = Field(default_factory=Steering)
    run: Run = Field(default_factory=Run)
    scenarios: Scenarios = Field(default_factory=Scenarios)
    solver: Solver = Field(default_factory=Solver)
    provenance: Provenance = Field(default_factory=Provenance)
