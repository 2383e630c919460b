"""Pydantic schema of model/scenario files (TOML).

Every physical value may be a plain number (SI) or a string with a unit (``"3 mm"``,
``"1500 rpm"``); see :mod:`drivedyn.config.units`. Unknown keys are errors (a misspelt key
must not be silently ignored). Errors name the key path, the bad value and what was expected.

File layout (every section optional except what the model needs)::

    [model]                # name, description, gravity, notes
    [[bodies]]             # rigid bodies
    [[nodes]]              # massless 6-dof nodes
    [[markers]]            # frames on bodies, nodes or "ground"
    [[joints]]             # type = spherical | fixed | hinge | cylindrical | prismatic |
                           #        universal | planar | screw
    [[springs]]            # linear spring-dampers
    [[torsional_springs]]  # torsional spring-dampers
    [[forces]] / [[torques]]
    [[drivers]]            # prescribed joint angle or speed
    [[speed_difference_drivers]]
    [[elements]]           # any other element type by class name (gears, contacts...):
                           # type = "GearPair", name = ..., its constructor's parameters
    [functions]            # named time functions, referenced by name
    [solver]               # t_end, rho_inf, step, newton
    [output]               # dt or times, variables
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, model_validator

from drivedyn.config import units as U  # noqa: N812 - short name for units


def _scalar(dim: U.Dim, positive: bool = False, nonneg: bool = False):
    def conv(v: Any) -> float:
        x = U.to_si(v, dim)
        if not np.isfinite(x):
            raise ValueError(f"must be finite [{U.dim_name(dim)}]")
        if positive and x <= 0:
            raise ValueError(f"must be > 0 {U.dim_name(dim)}")
        if nonneg and x < 0:
            raise ValueError(f"must be >= 0 {U.dim_name(dim)}")
        return x

    return BeforeValidator(conv)


def _vector(dim: U.Dim):
    def conv(v: Any) -> tuple[float, float, float]:
        if not isinstance(v, (list, tuple)) or len(v) != 3:
            raise ValueError(f"expected a list of 3 values [{U.dim_name(dim)}]")
        return tuple(U.to_si(x, dim) for x in v)  # type: ignore[return-value]

    return BeforeValidator(conv)


Length = Annotated[float, _scalar(U.LENGTH)]
PositiveLength = Annotated[float, _scalar(U.LENGTH, positive=True)]
NonNegLength = Annotated[float, _scalar(U.LENGTH, nonneg=True)]
Mass = Annotated[float, _scalar(U.MASS, positive=True)]
Time = Annotated[float, _scalar(U.TIME, positive=True)]
Angle = Annotated[float, _scalar(U.ANGLE)]
Force = Annotated[float, _scalar(U.FORCE)]
Torque = Annotated[float, _scalar(U.TORQUE)]
Stiffness = Annotated[float, _scalar(U.STIFFNESS, nonneg=True)]
Damping = Annotated[float, _scalar(U.DAMPING, nonneg=True)]
TorsionalStiffness = Annotated[float, _scalar(U.TORSIONAL_STIFFNESS, nonneg=True)]
TorsionalDamping = Annotated[float, _scalar(U.TORSIONAL_DAMPING, nonneg=True)]
LengthVec = Annotated[tuple[float, float, float], _vector(U.LENGTH)]
VelocityVec = Annotated[tuple[float, float, float], _vector(U.VELOCITY)]
AngVelVec = Annotated[tuple[float, float, float], _vector(U.ANGULAR_VELOCITY)]
AccelVec = Annotated[tuple[float, float, float], _vector(U.ACCELERATION)]
ForceVec = Annotated[tuple[float, float, float], _vector(U.FORCE)]
TorqueVec = Annotated[tuple[float, float, float], _vector(U.TORQUE)]
DirVec = Annotated[tuple[float, float, float], _vector(U.DIMENSIONLESS)]


def _inertia(v: Any) -> list:
    """Principal moments (3 values) or a 3x3 tensor [kg m^2]."""
    if isinstance(v, (list, tuple)) and len(v) == 3 and all(
            not isinstance(x, (list, tuple)) for x in v):
        return [U.to_si(x, U.INERTIA) for x in v]
    if (isinstance(v, (list, tuple)) and len(v) == 3
            and all(isinstance(r, (list, tuple)) and len(r) == 3 for r in v)):
        return [[U.to_si(x, U.INERTIA) for x in r] for r in v]
    raise ValueError("expected 3 principal moments or a 3x3 tensor [kg m^2]")


Inertia = Annotated[list, BeforeValidator(_inertia)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class Rotation(_Strict):
    """A rotation by ``angle`` about ``axis`` (an axis-angle pair)."""

    axis: DirVec
    angle: Angle = 0.0


def _rotation(v: Any) -> Any:
    if v is None or isinstance(v, dict):
        return v
    arr = np.asarray(v, dtype=float) if isinstance(v, (list, tuple)) else None
    if arr is not None and arr.shape == (3, 3):
        return arr.tolist()
    raise ValueError("expected {axis = [x, y, z], angle = ...} or a 3x3 rotation matrix")


RotationField = Annotated[Rotation | list[list[float]] | None, BeforeValidator(_rotation)]


class ModelInfo(_Strict):
    name: str = "model"
    description: str = ""
    gravity: AccelVec = (0.0, 0.0, 0.0)
    notes: dict[str, str] = Field(default_factory=dict)


class BodyFile(_Strict):
    name: str
    mass: Mass
    inertia: Inertia
    com: LengthVec = (0.0, 0.0, 0.0)
    position: LengthVec = (0.0, 0.0, 0.0)
    rotation: RotationField = None
    velocity: VelocityVec = (0.0, 0.0, 0.0)
    angular_velocity: AngVelVec = (0.0, 0.0, 0.0)


class NodeFile(_Strict):
    name: str
    position: LengthVec = (0.0, 0.0, 0.0)
    rotation: RotationField = None
    velocity: VelocityVec = (0.0, 0.0, 0.0)
    angular_velocity: AngVelVec = (0.0, 0.0, 0.0)


class MarkerFile(_Strict):
    name: str
    body: str
    position: LengthVec = (0.0, 0.0, 0.0)
    axis: DirVec | None = None
    rotation: RotationField = None

    @model_validator(mode="after")
    def _one_orientation(self) -> MarkerFile:
        if self.axis is not None and self.rotation is not None:
            raise ValueError("give either 'axis' or 'rotation', not both")
        return self


class JointFile(_Strict):
    type: Literal["spherical", "fixed", "hinge", "cylindrical", "prismatic", "universal", "planar",
                  "screw"]
    name: str
    marker_a: str
    marker_b: str
    pitch: Length | None = None  # screw only: advance per revolution [m]
    k: float | None = Field(default=None, gt=0)
    p: float | None = Field(default=None, ge=0)

    @model_validator(mode="after")
    def _pitch(self) -> JointFile:
        if (self.type == "screw") != (self.pitch is not None):
            raise ValueError("'pitch' [m per revolution] is required for a screw joint and "
                             "only for it")
        return self


class SpringFile(_Strict):
    name: str
    marker_a: str
    marker_b: str
    stiffness: Stiffness = 0.0
    damping: Damping = 0.0
    free_length: NonNegLength | None = None
    preload: Force = 0.0


class TorsionalSpringFile(_Strict):
    name: str
    marker_a: str
    marker_b: str
    stiffness: TorsionalStiffness = 0.0
    damping: TorsionalDamping = 0.0
    free_angle: Angle = 0.0
    preload: Torque = 0.0


FunctionField = float | str | dict[str, Any]


class ForceFile(_Strict):
    name: str
    marker: str
    vector: ForceVec
    function: FunctionField = 1.0
    frame: Literal["global", "marker"] = "global"


class TorqueFile(_Strict):
    name: str
    marker: str
    vector: TorqueVec
    function: FunctionField = 1.0
    frame: Literal["global", "marker"] = "global"


class DriverFile(_Strict):
    name: str
    joint: str
    quantity: Literal["angle", "speed"] = "speed"
    function: FunctionField = 0.0
    k: float | None = Field(default=None, gt=0)
    p: float | None = Field(default=None, ge=0)


class SpeedDifferenceDriverFile(_Strict):
    name: str
    joint_1: str
    joint_2: str
    function: FunctionField = 0.0
    k: float | None = Field(default=None, gt=0)
    p: float | None = Field(default=None, ge=0)


class GenericElementFile(BaseModel):
    """Any registered element type by its class name; the other keys are its parameters
    (numbers in SI or strings with units, converted to SI; dimensions are checked by the
    element's own validation)."""

    model_config = ConfigDict(extra="allow")
    type: str
    name: str


class FixedStepFile(_Strict):
    mode: Literal["fixed"] = "fixed"
    h: Time = 1e-3


class AdaptiveStepFile(_Strict):
    mode: Literal["adaptive"]
    h0: Time = 1e-4
    h_min: Time = 1e-10
    h_max: Time = 1e-2
    rtol: float = Field(default=1e-3, gt=0)
    atol: float = Field(default=1e-7, gt=0)


class NewtonFile(_Strict):
    strategy: Literal["modified", "full"] = "modified"
    tol: float = Field(default=1e-8, gt=0)
    phi_tol: float = Field(default=1e-10, gt=0)
    max_iter: int = Field(default=12, ge=1)


class SolverFile(_Strict):
    t_end: Time = 1.0
    rho_inf: float = Field(default=0.8, ge=0.0, le=1.0)
    step: Annotated[FixedStepFile | AdaptiveStepFile, Field(discriminator="mode")] = Field(
        default_factory=FixedStepFile)
    newton: NewtonFile = Field(default_factory=NewtonFile)


class OutputFile(_Strict):
    dt: Time | None = None
    times: list[float] | None = None
    variables: list[str] | None = None


class ModelFile(_Strict):
    """The whole file."""

    model: ModelInfo = Field(default_factory=ModelInfo)
    bodies: list[BodyFile] = Field(default_factory=list)
    nodes: list[NodeFile] = Field(default_factory=list)
    markers: list[MarkerFile] = Field(default_factory=list)
    joints: list[JointFile] = Field(default_factory=list)
    springs: list[SpringFile] = Field(default_factory=list)
    torsional_springs: list[TorsionalSpringFile] = Field(default_factory=list)
    forces: list[ForceFile] = Field(default_factory=list)
    torques: list[TorqueFile] = Field(default_factory=list)
    drivers: list[DriverFile] = Field(default_factory=list)
    speed_difference_drivers: list[SpeedDifferenceDriverFile] = Field(default_factory=list)
    elements: list[GenericElementFile] = Field(default_factory=list)
    functions: dict[str, FunctionField] = Field(default_factory=dict)
    solver: SolverFile = Field(default_factory=SolverFile)
    output: OutputFile = Field(default_factory=OutputFile)
