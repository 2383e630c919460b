"""Pydantic schema of model/scenario files (TOML).

Every physical value may be a plain number (SI) or a string with a unit (``"3 mm"``,
``"1500 rpm"``); see :mod:`drivedyn.units`. Unknown keys are errors (a misspelt key
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

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from drivedyn.schema_base import (
    AccelVec,
    Angle,
    AngVelVec,
    Damping,
    DirVec,
    Force,
    ForceVec,
    Inertia,
    Length,
    LengthVec,
    Mass,
    NonNegLength,
    OutputFile,
    RotationField,
    SolverFile,
    Stiffness,
    Strict,
    Torque,
    TorqueVec,
    TorsionalDamping,
    TorsionalStiffness,
    VelocityVec,
)


class ModelInfo(Strict):
    name: str = "model"
    description: str = ""
    gravity: AccelVec = (0.0, 0.0, 0.0)
    notes: dict[str, str] = Field(default_factory=dict)


class BodyFile(Strict):
    name: str
    mass: Mass
    inertia: Inertia
    com: LengthVec = (0.0, 0.0, 0.0)
    position: LengthVec = (0.0, 0.0, 0.0)
    rotation: RotationField = None
    velocity: VelocityVec = (0.0, 0.0, 0.0)
    angular_velocity: AngVelVec = (0.0, 0.0, 0.0)


class NodeFile(Strict):
    name: str
    position: LengthVec = (0.0, 0.0, 0.0)
    rotation: RotationField = None
    velocity: VelocityVec = (0.0, 0.0, 0.0)
    angular_velocity: AngVelVec = (0.0, 0.0, 0.0)


class MarkerFile(Strict):
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


class JointFile(Strict):
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


class SpringFile(Strict):
    name: str
    marker_a: str
    marker_b: str
    stiffness: Stiffness = 0.0
    damping: Damping = 0.0
    free_length: NonNegLength | None = None
    preload: Force = 0.0


class TorsionalSpringFile(Strict):
    name: str
    marker_a: str
    marker_b: str
    stiffness: TorsionalStiffness = 0.0
    damping: TorsionalDamping = 0.0
    free_angle: Angle = 0.0
    preload: Torque = 0.0


FunctionField = float | str | dict[str, Any]


class ForceFile(Strict):
    name: str
    marker: str
    vector: ForceVec
    function: FunctionField = 1.0
    frame: Literal["global", "marker"] = "global"


class TorqueFile(Strict):
    name: str
    marker: str
    vector: TorqueVec
    function: FunctionField = 1.0
    frame: Literal["global", "marker"] = "global"


class DriverFile(Strict):
    name: str
    joint: str
    quantity: Literal["angle", "speed"] = "speed"
    function: FunctionField = 0.0
    k: float | None = Field(default=None, gt=0)
    p: float | None = Field(default=None, ge=0)


class SpeedDifferenceDriverFile(Strict):
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


class ModelFile(Strict):
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
