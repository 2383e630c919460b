"""Schema of the rear-wheel-drive vehicle model file (``library = "vehicle_rwd"``).

Every value is SI or a string with units; unknown keys are refused and every problem is reported
with its key path. ``suspensions`` names the suspension set (a shipped name or a TOML file,
relative to the model file), whose values ``[suspension_overrides]`` may replace by key
(``suspension_overrides.front.hardpoints.wheel_center``). What cannot be checked key by key
(the suspension set and its geometry, the steering's travel, the tyre file and its side, the
TORSEN file, the final-drive mesh) is checked when the model is built
(:func:`drivedyn.library.vehicles.vehicle_rwd.inputs.check_parameters`).
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field, field_validator, model_validator

from drivedyn.library.differentials.schema_sections import (
    AngularVelocity,
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
    Angle,
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
    file); ``vertical_damping`` None keeps the file's tyre damping.

    ``tyre_side``: the side of the vehicle the tyre file was measured on, for a file without
    ``[MODEL] TYRESIDE``: ``"left"`` or ``"right"`` (the file is mirrored for the wheels on
    the other side) or ``"symmetric"`` (used as it is on both sides). None: the file's
    ``TYRESIDE`` (mirrored for the other side, with a note), or, for a file without it,
    as it is if its tyre is symmetric; a file without ``TYRESIDE`` whose tyre is not
    symmetric, and a ``tyre_side`` that contradicts the file's ``TYRESIDE``, are refused
    (:func:`~drivedyn.library.vehicles.vehicle_rwd.inputs.load_tyre`)."""

    mass: Mass = 71.105
    inertia: Inertia = (4.345, 7.388, 4.345)
    tyre: str = "hmmwv_pac02_37x12.5R16.5"
    tyre_side: Literal["left", "right", "symmetric"] | None = None
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


#: a torque-speed map: ``[[engine speed rad/s, torque N m], ...]``
EngineMap = list[tuple[AngularVelocity, TorqueValue]]

#: Chrono's HMMWV maps (``HMMWV_EngineSimpleMap.cpp``, commit 7689fbc) from 0 rad/s: the first
#: point is the map's linear interpolation at 0 (Chrono clamps the speed to >= 0), the others
#: are Chrono's points; the last one is the maximum engine speed, 2700 rpm
HMMWV_FULL_LOAD = [(0.0, 419.06), (83.776, 517.9), (104.720, 926.0), (125.664, 1216.2),
                   (146.608, 1300.2), (167.552, 1300.2), (188.496, 1227.0), (209.440, 1136.2),
                   (230.383, 1041.3), (251.327, -271.2), (282.743, -800.0)]
HMMWV_ZERO_THROTTLE = [(0.0, -2.222), (83.776, -20.0), (104.720, -20.0), (125.664, -30.0),
                       (146.608, -30.0), (167.552, -30.0), (188.496, -40.0), (209.440, -50.0),
                       (230.383, -70.0), (251.327, -100.0), (282.743, -800.0)]


def check_map(table: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """``table`` if it is a map the engine can read (at least two points, speeds >= 0 and
    strictly increasing); ``ValueError`` naming the offending point and value otherwise (the
    schema's message puts the key in front)."""
    if len(table) < 2:
        raise ValueError(f"a map needs at least 2 points [engine speed rad/s, torque N m], "
                         f"got {len(table)}")
    for i, (w, _) in enumerate(table):
        if w < 0.0:
            raise ValueError(f"engine speeds must be >= 0 rad/s, got {w!r} at point {i}")
        if i and not w > table[i - 1][0]:
            raise ValueError(f"engine speeds must increase strictly, got {table[i - 1][0]!r} "
                             f"then {w!r} rad/s at point {i}")
    return table


class Engine(Strict):
    """Engine and gearbox as one shaft on the frame (the gearbox output), driven by an
    :class:`~drivedyn.elements.EngineTorque` reacted on the frame: the engine's torque
    ``T_0 + throttle(t) (T_F - T_0)`` [N m] from the ``full_load`` curve ``T_F`` and the
    ``zero_throttle`` curve ``T_0`` (None: 0) at the engine speed, ``gear_ratio`` times the
    gearbox output's speed relative to the frame; the output gets ``gear_ratio`` times the
    torque. Its inertia about its axis is ``inertia * gear_ratio^2 + output_inertia`` (the
    crankshaft seen through the gear, the torque converter locked). The throttle is
    ``idle_throttle`` until ``start`` and rises smoothly to ``throttle`` at ``start + ramp``
    (``idle_throttle``: the driver holding the engine off its friction curve before the
    ramp, so that the driveline does not start in engine braking)."""

    full_load: EngineMap = Field(default_factory=lambda: list(HMMWV_FULL_LOAD))
    zero_throttle: EngineMap | None = Field(default_factory=lambda: list(HMMWV_ZERO_THROTTLE))
    inertia: float = Field(default=1.1, gt=0.0)
    output_inertia: float = Field(default=0.5, ge=0.0)
    shaft_mass: Mass = 20.0
    gear_ratio: float = Field(default=5.855, gt=0.0)
    throttle: float = Field(default=0.1, ge=0.0, le=1.0)
    idle_throttle: float = Field(default=0.0, ge=0.0, le=1.0)
    start: Time = 0.0
    ramp: PositiveTime = 0.5

    @field_validator("full_load", "zero_throttle")
    @classmethod
    def _map(cls, v: list[tuple[float, float]] | None) -> list[tuple[float, float]] | None:
        return None if v is None else check_map(v)


class Shafts(Strict):
    """The propeller shaft from the gearbox output (on the frame) to the pinion (on the rear
    carrier): a rigid tube with a universal joint at each end and a slip yoke at the rear
    (a small body sliding and turning on the tube, held to it in rotation by the shaft's
    torsional compliance ``propshaft_stiffness``, ``propshaft_damping``); and the rigid
    half-shafts (a universal joint at the side gear, a plunging universal joint at the
    wheel). Inertias in the shafts' own frames, z along the shaft."""

    propshaft_mass: Mass = 12.0
    propshaft_inertia: Inertia = (1.2, 1.2, 0.05)
    propshaft_stiffness: TorsionalStiffness = 2.0e4
    propshaft_damping: TorsionalDamping = 100.0
    slip_mass: Mass = 1.5
    slip_inertia: Inertia = (2e-3, 2e-3, 2e-3)
    halfshaft_mass: Mass = 8.0
    halfshaft_inertia: Inertia = (0.4, 0.4, 0.01)
    plunger_mass: Mass = 0.5
    plunger_inertia: Inertia = (1e-3, 1e-3, 1e-3)


class Carrier(Strict):
    """The rear axle's carrier (the differential's case mounted on the frame's rear cross
    member, a rigid body fixed to the frame node there) and the pinion shaft hinged in it
    (``pinion_offset`` ahead of the pinion, where the propeller shaft's rear universal joint
    is; inertia in the shaft's frame, z along it)."""

    mass: Mass = 40.0
    inertia: Inertia = (0.6, 0.4, 0.6)
    pinion_offset: PositiveLength = 0.25
    pinion_mass: Mass = 4.0
    pinion_inertia: Inertia = (0.03, 0.03, 5e-3)


class Differentials(Strict):
    """The rear differential: ``rear`` (a TORSEN by its file ``torsen_b``, or the ``bevel``
    differential open, locked or with a clutch). ``mesh_stiffness_variation``: the TORSEN's
    meshes with their stiffness varying over the mesh cycle (true) or at its mean (false)
    in this vehicle; None: as its file says (``gears.stiffness_variation``)."""

    rear: RearType = "torsen-b"
    torsen_b: str = "torsen-b"
    bevel: BevelDifferential = Field(default_factory=BevelDifferential)
    mesh_stiffness_variation: bool | None = None


class Steering(Strict):
    """The rack's pinion angle [rad] (0: straight ahead): a number (held) or a time function
    (``{type = "smooth_step", t0 = 1.0, t1 = 1.5, v0 = 0.0, v1 = 0.2}``, values in rad;
    types: :func:`drivedyn.timefunctions.as_time_function`). Its rack travel (the steering
    file's ``ratio`` times the angle) must stay within the steering file's
    ``travel_limit``."""

    pinion_angle: Angle | dict[str, Any] = 0.0

    @field_validator("pinion_angle")
    @classmethod
    def _function(cls, v: Any) -> Any:
        if isinstance(v, dict):
            from drivedyn.timefunctions import as_time_function

            try:
                as_time_function(v)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"expected a number [rad] or a time function: {exc}") from None
        return v


class Run(Strict):
    """The run: ``t_end`` [s], the step size's cap ``h_max`` [s], the analysis ``window``
    [s]; ``wind_up``: the run begins with the driveline wound up by the engine's first torque
    (its plays closed, its shafts twisted, as an idling engine in gear leaves it;
    :mod:`~drivedyn.library.vehicles.vehicle_rwd.wind_up`), false: with the plays open, as
    the parked vehicle's static equilibrium leaves them."""

    t_end: PositiveTime = 3.0
    h_max: PositiveTime = 2e-3
    window: tuple[Time, Time] = (0.8, 3.0)
    wind_up: bool = True

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
    #: values replacing the suspension file's, by its keys (``front.spring.rate``...)
    suspension_overrides: dict[str, Any] = Field(default_factory=dict)
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
