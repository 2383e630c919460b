"""Model-file sections of the suspension and steering library.

A :class:`DoubleWishboneFile` describes one axle's double-wishbone suspension, a
:class:`MacPhersonFile` one axle's MacPherson struts (both corners: the file gives the LEFT
side, the right side is its mirror image ``y -> -y``; ``type`` tells which, see
:data:`SuspensionFile`), a :class:`SteeringFile` a rack-and-pinion steering, a
:class:`SuspensionSet` the two axles and the steering of a vehicle as one file (``[front]``,
``[rear]``, ``[steering]``). Every value
is SI or a string with a unit (``"17.5575 in"``, ``"35 kN/mm"``); unknown keys are refused,
curves must be monotone, and every problem is reported with its key path. What needs the
whole geometry (a link of zero length, a wheel centre inboard of the knuckle, hardpoints
that do not assemble, a design length outside the stops) is checked when the suspension is
built (:mod:`drivedyn.library.vehicles.suspensions.double_wishbone`,
:mod:`drivedyn.library.vehicles.suspensions.macpherson`).

Points are in the vehicle frame (x forward, y left, z up) [m], given relative to
``location`` (a point in the vehicle frame: the position of the suspension's own reference,
0 by default), so that a published data set can be copied as printed together with the
place where its vehicle puts it.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

import numpy as np
from pydantic import (
    BeforeValidator,
    Field,
    ValidationInfo,
    ValidatorFunctionWrapHandler,
    WrapValidator,
    field_validator,
    model_validator,
)

import drivedyn.units as U  # noqa: N812 - short name for units
from drivedyn.elements.framework.curves import check_table
from drivedyn.schema_base import (
    Angle,
    Damping,
    DirVec,
    Inertia,
    LengthVec,
    Mass,
    PositiveLength,
    Strict,
    TorsionalDamping,
    TorsionalStiffness,
    scalar,
    vector,
)


def _table(dx: U.Dim, dy: U.Dim, what: str) -> BeforeValidator:
    """Validator of a table of ``[x, y]`` pairs (each a number in SI or a unit string of its
    column's dimension), at least two rows, ``x`` strictly increasing and ``y`` not
    decreasing (a spring, damper or stop curve is monotone: a falling one has points of
    negative stiffness where the suspension would snap through)."""

    def conv(v: Any) -> tuple[tuple[float, float], ...]:
        if isinstance(v, np.ndarray):
            v = v.tolist()
        if not isinstance(v, (list, tuple)) or len(v) < 2:
            raise ValueError(f"expected a list of at least two [{what}] pairs")
        out = []
        for i, row in enumerate(v):
            if not isinstance(row, (list, tuple)) or len(row) != 2:
                raise ValueError(f"row {i}: expected a pair [{what}], got {row!r}")
            out.append((U.to_si(row[0], dx), U.to_si(row[1], dy)))
        check_table([x for x, _ in out], [y for _, y in out], f"table [{what}]")
        return tuple(out)

    return BeforeValidator(conv)


#: spring curve: deflection (extension positive) [m] -> tension (pulling positive) [N]
SpringTable = Annotated[tuple[tuple[float, float], ...],
                        _table(U.LENGTH, U.FORCE, "deflection m, tension N")]
#: damper curve: speed magnitude [m/s] -> force magnitude [N], from (0, 0)
DamperTable = Annotated[tuple[tuple[float, float], ...],
                        _table(U.VELOCITY, U.FORCE, "speed m/s, force N")]
#: stop curve: deflection beyond contact [m] -> force [N], from (0, 0)
StopTable = Annotated[tuple[tuple[float, float], ...],
                      _table(U.LENGTH, U.FORCE, "deflection m, force N")]
StiffnessVec = Annotated[tuple[float, float, float], vector(U.STIFFNESS)]
DampingVec = Annotated[tuple[float, float, float], vector(U.DAMPING)]
RotStiffnessVec = Annotated[tuple[float, float, float], vector(U.TORSIONAL_STIFFNESS)]
RotDampingVec = Annotated[tuple[float, float, float], vector(U.TORSIONAL_DAMPING)]
PositiveStiffness = Annotated[float, scalar(U.STIFFNESS, positive=True)]
RackRatio = Annotated[float, scalar((1, 0, 0, -1), positive=True)]  # m/rad


class DoubleWishboneHardpoints(Strict):
    """The hardpoints of the left corner [m], relative to the suspension's ``location``.

    Attributes:
        upper_arm_front, upper_arm_rear: chassis pickups of the upper arm (its pivot axis).
        upper_ball_joint: upper arm to upright.
        lower_arm_front, lower_arm_rear: chassis pickups of the lower arm.
        lower_ball_joint: lower arm to upright.
        tie_rod_inner: tie rod to rack (front) or chassis (a rear toe link).
        tie_rod_outer: tie rod to upright.
        wheel_center: the wheel centre on the spin axis.
        spring_chassis, spring_arm: the coil spring's ends (the arm of ``coil_over_arm``).
        damper_chassis, damper_arm: the damper's ends (a coil-over when they equal the
            spring's).
    """

    upper_arm_front: LengthVec
    upper_arm_rear: LengthVec
    upper_ball_joint: LengthVec
    lower_arm_front: LengthVec
    lower_arm_rear: LengthVec
    lower_ball_joint: LengthVec
    tie_rod_inner: LengthVec
    tie_rod_outer: LengthVec
    wheel_center: LengthVec
    spring_chassis: LengthVec
    spring_arm: LengthVec
    damper_chassis: LengthVec
    damper_arm: LengthVec


class BushingRates(Strict):
    """A rubber bushing at a chassis pickup, in the frame of its arm's pivot: z along the
    pivot axis (front pickup minus rear pickup), x and y across it. Each arm has two, one at
    each pickup.

    Attributes:
        stiffness: (3,) translational rates [N/m].
        damping: (3,) [N s/m].
        rotational_stiffness: (3,) [N m/rad]; about z the arm's swing (usually 0: free).
        rotational_damping: (3,) [N m s/rad].
    """

    stiffness: StiffnessVec
    damping: DampingVec = (0.0, 0.0, 0.0)
    rotational_stiffness: RotStiffnessVec = (0.0, 0.0, 0.0)
    rotational_damping: RotDampingVec = (0.0, 0.0, 0.0)


class Link(Strict):
    """A rigid link's mass properties (left corner).

    Attributes:
        mass: [kg].
        inertia: principal moments [kg m^2] about the centre of mass in the link's frame
            (an arm: x along its pivot axis, z normal to the plane of its pickups and ball
            joint; the upright and the spindle: the vehicle's axes; a tie rod or drop link: z
            along it), or a 3x3 tensor in that frame.
        com: centre of mass [m] relative to ``location``; None: the middle of the link (a
            tie rod, a drop link).
    """

    mass: Mass
    inertia: Inertia
    com: LengthVec | None = None


class Arm(Link):
    """A control arm: a link with two chassis pickups; ``bushing`` None hinges it to the
    chassis (an ideal revolute joint on the pickups' axis)."""

    bushing: BushingRates | None = None


class Spring(Strict):
    """The coil spring: ``curve`` (tension against deflection, extension positive) or a
    linear ``rate``, and its ``free_length``."""

    curve: SpringTable | None = None
    rate: PositiveStiffness | None = None
    free_length: PositiveLength

    @model_validator(mode="after")
    def _one_law(self) -> Spring:
        if (self.curve is None) == (self.rate is None):
            raise ValueError("give either curve or rate")
        return self


class Damper(Strict):
    """The damper: force magnitude against speed magnitude, in rebound (extension) and in
    compression; each a table from (0, 0) or a linear rate [N s/m]."""

    rebound: DamperTable | Damping
    compression: DamperTable | Damping

    @model_validator(mode="before")
    @classmethod
    def _rates(cls, data: Any) -> Any:
        # a scalar (number or unit string) is a linear rate, a list is a table
        if isinstance(data, dict):
            data = {k: (U.to_si(v, U.DAMPING) if k in ("rebound", "compression")
                        and not isinstance(v, (list, tuple)) else v) for k, v in data.items()}
        return data

    def table(self, side: str) -> tuple[tuple[float, float], ...]:
        """The curve of ``side`` (``"rebound"`` or ``"compression"``) as a table (a rate
        ``c`` as the line through (0, 0) and (1 m/s, c), continued linearly)."""
        v = getattr(self, side)
        return ((0.0, 0.0), (1.0, float(v))) if isinstance(v, float) else v


class Stops(Strict):
    """Bump and rebound stops on the spring's line: contact when the spring's length goes
    below ``bump_length`` or above ``rebound_length``; the force against the deflection
    beyond contact is ``bump_curve`` / ``rebound_curve``."""

    bump_length: PositiveLength
    rebound_length: PositiveLength
    bump_curve: StopTable
    rebound_curve: StopTable
    transition: Annotated[float, scalar(U.LENGTH, nonneg=True)] = 0.0

    @model_validator(mode="after")
    def _order(self) -> Stops:
        if not self.bump_length < self.rebound_length:
            raise ValueError(f"expected bump_length < rebound_length, got "
                             f"{self.bump_length} m, {self.rebound_length} m")
        return self


class AntiRollBarFile(Strict):
    """An anti-roll bar as two rigid halves hinged to the chassis on the bar's axis (the
    global y axis through ``pivot``), coupled by a torsional spring-damper ``rate`` on
    their relative rotation (the bar's torsion), each half's lever end joined to its lower
    arm by a drop link (a rigid link: ball joint at the arm, universal joint at the lever).
    Points of the left side [m], relative to the suspension's ``location``.

    Attributes:
        rate: torsional rate of the bar [N m/rad] (relative rotation of the halves).
        damping: [N m s/rad].
        pivot: the left half's bearing on the chassis (on the bar's axis).
        lever_end: the left lever's end (drop link, upper end).
        drop_link_arm: the drop link's lower end, on the lower arm.
        half: mass and inertia of one half (frame: the vehicle's axes).
        drop_link: mass and inertia of a drop link (frame: z along it).
    """

    rate: TorsionalStiffness
    damping: TorsionalDamping = 0.0
    pivot: LengthVec
    lever_end: LengthVec
    drop_link_arm: LengthVec
    half: Link
    drop_link: Link


class _Placed:
    """Points of an axle's section (a model with ``location`` and ``hardpoints``): the
    hardpoints are relative to ``location``."""

    def point(self, name: str) -> np.ndarray:
        """Hardpoint ``name`` of the left corner in the vehicle frame [m] (3,)."""
        me: Any = self
        return np.asarray(me.location) + np.asarray(getattr(me.hardpoints, name))

    def translated(self, offset: Any) -> Any:
        """The same suspension moved by ``offset`` (3,) [m] in the vehicle frame."""
        me: Any = self
        loc = tuple(float(a + b) for a, b in zip(me.location, offset, strict=True))
        return me.model_copy(update={"location": loc})


class DoubleWishboneFile(_Placed, Strict):
    """One axle's double-wishbone suspension (the left corner; the right one mirrored).

    Attributes:
        type: ``"double_wishbone"``.
        location: the suspension's reference in the vehicle frame [m]; every point of the
            section is relative to it.
        hardpoints: see :class:`DoubleWishboneHardpoints`.
        upper_arm, lower_arm: the control arms (mass, inertia, centre of mass, bushings).
        upright: the knuckle.
        tie_rod: tie rod (front) or toe link (rear); its centre of mass is its middle.
        spindle: the hub's rotating part: not built here (the vehicle's wheel carries it).
        coil_over_arm: the arm carrying the spring and the damper, ``"lower"`` or
            ``"upper"``.
        spring, damper, stops: the coil-over and the stops on the spring's line.
        camber, toe: static angles of the spin axis [rad] in the design position (camber
            positive: top of the wheel outward; toe positive: toe-in).
        anti_roll_bar: the axle's anti-roll bar, or None.
    """

    type: Literal["double_wishbone"] = "double_wishbone"
    location: LengthVec = (0.0, 0.0, 0.0)
    hardpoints: DoubleWishboneHardpoints
    upper_arm: Arm
    lower_arm: Arm
    upright: Link
    tie_rod: Link
    spindle: Link | None = None
    coil_over_arm: Literal["lower", "upper"] = "lower"
    spring: Spring
    damper: Damper
    stops: Stops | None = None
    camber: Angle = 0.0
    toe: Angle = 0.0
    anti_roll_bar: AntiRollBarFile | None = None



class MacPhersonHardpoints(Strict):
    """The hardpoints of a MacPherson strut's left corner [m], relative to the suspension's
    ``location``.

    Attributes:
        lower_arm_front, lower_arm_rear: chassis pickups of the lower control arm (its pivot
            axis).
        lower_ball_joint: lower arm to upright.
        strut_top: the strut's top mount on the chassis (the top of the strut axis; the
            spring's and the damper's upper end).
        strut_lower: the strut's lower spring seat on the damper tube, which is part of the
            upright: the strut axis runs from it to ``strut_top``; the spring and the damper
            act between the two points.
        tie_rod_inner: tie rod to rack (front) or chassis (a rear toe link).
        tie_rod_outer: tie rod to upright.
        wheel_center: the wheel centre on the spin axis.
    """

    lower_arm_front: LengthVec
    lower_arm_rear: LengthVec
    lower_ball_joint: LengthVec
    strut_top: LengthVec
    strut_lower: LengthVec
    tie_rod_inner: LengthVec
    tie_rod_outer: LengthVec
    wheel_center: LengthVec


class TopMount(BushingRates):
    """The strut's rubber top mount, in its frame on the chassis: z along the strut axis
    (``strut_top`` minus ``strut_lower``), x and y across it. The rate about z must be
    positive: the mount is what holds the strut rod's spin about its own axis (the upright
    turns about the rod in the damper tube), so ``rotational_stiffness`` has no default."""

    rotational_stiffness: RotStiffnessVec

    @field_validator("rotational_stiffness")
    @classmethod
    def _holds_spin(cls, v: tuple[float, float, float]) -> tuple[float, float, float]:
        if not v[2] > 0.0:
            raise ValueError(f"the rate about z (the strut axis) must be > 0 N m/rad, got "
                             f"{v[2]:g}: nothing else holds the strut rod's spin")
        return v


class MacPhersonFile(_Placed, Strict):
    """One axle's MacPherson struts (the left corner; the right one mirrored).

    Attributes:
        type: ``"macpherson"``.
        location: the suspension's reference in the vehicle frame [m]; every point of the
            section is relative to it.
        hardpoints: see :class:`MacPhersonHardpoints`.
        lower_arm: the lower control arm (mass, inertia, centre of mass, bushings).
        strut: the strut rod (the damper's piston rod, sliding in the damper tube), frame z
            along the strut axis; its centre of mass is the middle of ``strut_top`` and
            ``strut_lower`` unless given.
        top_mount: the strut top's rubber mount, or None: a universal joint on the chassis
            (both tilts free, the rod's spin held).
        upright: the knuckle with the damper tube.
        tie_rod: tie rod (front) or toe link (rear); its centre of mass is its middle.
        spindle: the hub's rotating part: not built here (the vehicle's wheel carries it).
        spring, damper, stops: the coil spring and the damper on the strut axis (from
            ``strut_top`` to ``strut_lower``) and the stops on that line.
        camber, toe: static angles of the spin axis [rad] in the design position.
        anti_roll_bar: the axle's anti-roll bar (its drop links on the lower arms), or None.
    """

    type: Literal["macpherson"]
    location: LengthVec = (0.0, 0.0, 0.0)
    hardpoints: MacPhersonHardpoints
    lower_arm: Arm
    strut: Link
    top_mount: TopMount | None = None
    upright: Link
    tie_rod: Link
    spindle: Link | None = None
    spring: Spring
    damper: Damper
    stops: Stops | None = None
    camber: Angle = 0.0
    toe: Angle = 0.0
    anti_roll_bar: AntiRollBarFile | None = None


#: suspension types: the value of ``type`` -> the section's class
TYPES: dict[str, type[Strict]] = {"double_wishbone": DoubleWishboneFile,
                                  "macpherson": MacPhersonFile}


class _Type(Strict):
    """The ``type`` key alone (the other keys are the type's class's to check)."""

    type: Literal["double_wishbone", "macpherson"]


def _by_type(v: Any, handler: ValidatorFunctionWrapHandler, info: ValidationInfo) -> Any:
    """Validate an axle's table by the class of its ``type`` (``"double_wishbone"`` when
    absent): its errors keep their key paths (``front.hardpoints.x``, ``front.type``)."""
    if isinstance(v, dict):
        t = v.get("type", "double_wishbone")
        if not isinstance(t, str) or t not in TYPES:
            _Type.model_validate({"type": t})  # raises, naming the key and the value
        return TYPES[t].model_validate(v)
    return handler(v)


#: one axle's suspension: the class of its ``type`` key
SuspensionFile = Annotated[DoubleWishboneFile | MacPhersonFile, WrapValidator(_by_type)]


class SteeringFile(Strict):
    """A rack-and-pinion steering: the rack slides along ``axis`` on a prismatic joint; its
    ends carry the tie rods' inner joints.

    Attributes:
        location: the steering's reference in the vehicle frame [m].
        tie_rod_inner: the rack's left tie-rod joint [m] relative to ``location`` (the right
            one mirrored): must be the front suspension's ``tie_rod_inner``.
        axis: the rack's sliding axis (a direction; positive travel moves the rack along it).
        ratio: rack travel per radian of the pinion [m/rad] (the pinion's pitch radius).
        travel_limit: largest rack travel either way from centre [m].
        rack: the rack's mass and inertia (frame: the vehicle's axes; centre of mass between
            the tie-rod joints).
    """

    location: LengthVec = (0.0, 0.0, 0.0)
    tie_rod_inner: LengthVec
    axis: DirVec = (0.0, 1.0, 0.0)
    ratio: RackRatio
    travel_limit: PositiveLength
    rack: Link

    @model_validator(mode="after")
    def _axis(self) -> SteeringFile:
        if not any(self.axis):
            raise ValueError("axis: must be a non-zero direction")
        return self

    def point(self, side: str = "left") -> np.ndarray:
        """The tie-rod joint on the rack of ``side`` in the vehicle frame [m] (3,)."""
        p = np.asarray(self.location) + np.asarray(self.tie_rod_inner)
        return p if side == "left" else p * np.array([1.0, -1.0, 1.0])


class SuspensionSet(Strict):
    """A vehicle's suspensions and steering as one file: ``[front]``, ``[rear]`` (each a
    :class:`DoubleWishboneFile` or a :class:`MacPhersonFile`, by its ``type``) and
    ``[steering]`` (a :class:`SteeringFile`); ``[info]`` holds a name and notes."""

    info: dict[str, str] = Field(default_factory=dict)
    front: SuspensionFile
    rear: SuspensionFile
    steering: SteeringFile
