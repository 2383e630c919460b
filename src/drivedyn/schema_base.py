"""Building blocks of the model-file schemas: unit-checked quantities (a plain SI number or a
string with a unit, see :mod:`drivedyn.units`), strict sections (unknown keys are errors) and
the solver and output sections. Used by :mod:`drivedyn.config.schema` and by each library
model's own schema section (which sits below ``config`` in the layers)."""

from __future__ import annotations

import typing
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, field_validator, model_validator

import drivedyn.units as U  # noqa: N812 - short name for units


def scalar(dim: U.Dim, positive: bool = False, nonneg: bool = False) -> BeforeValidator:
    """Validator of a quantity of dimension ``dim``: SI number or unit string, finite, of
    plausible magnitude (:data:`drivedyn.units.PLAUSIBLE_MAX`; a positive one also at least
    :data:`drivedyn.units.PLAUSIBLE_MIN_POSITIVE`), optionally > 0 or >= 0; every message
    gives the SI unit (none for a dimensionless quantity)."""
    unit = f" {U.unit_label(dim)}" if U.unit_label(dim) else ""

    def conv(v: Any) -> float:
        x = U.to_si(v, dim)
        U.check_plausible(x, dim)
        if positive and x <= 0:
            raise ValueError(f"must be > 0{unit}")
        low = U.PLAUSIBLE_MIN_POSITIVE.get(dim, 0.0)
        if positive and x < low:
            raise ValueError(f"{x:g}{unit} is implausibly small (>= {low:g}{unit}): a unit "
                             "mistake?")
        if nonneg and x < 0:
            raise ValueError(f"must be >= 0{unit}")
        return x

    return BeforeValidator(conv)


def vector(dim: U.Dim) -> BeforeValidator:
    """Validator of a 3-vector of dimension ``dim`` (finite, plausible components)."""
    unit = f" [{U.unit_label(dim)}]" if U.unit_label(dim) else ""

    def conv(v: Any) -> tuple[float, float, float]:
        if not isinstance(v, (list, tuple)) or len(v) != 3:
            raise ValueError(f"expected a list of 3 values{unit}")
        out = tuple(U.to_si(x, dim) for x in v)
        for x in out:
            U.check_plausible(x, dim)
        return out  # type: ignore[return-value]

    return BeforeValidator(conv)


#: most teeth of a gear in a model file: beyond any driveline gear (large ring gears have a
#: few hundred), and the mesh geometry and ISO 6336 stiffness lose their meaning (and their
#: precision) long before 1e9
MAX_TEETH = 1000

Length = Annotated[float, scalar(U.LENGTH)]
PositiveLength = Annotated[float, scalar(U.LENGTH, positive=True)]
NonNegLength = Annotated[float, scalar(U.LENGTH, nonneg=True)]
Mass = Annotated[float, scalar(U.MASS, positive=True)]
Time = Annotated[float, scalar(U.TIME, positive=True)]
Angle = Annotated[float, scalar(U.ANGLE)]
Force = Annotated[float, scalar(U.FORCE)]
Torque = Annotated[float, scalar(U.TORQUE)]
Stiffness = Annotated[float, scalar(U.STIFFNESS, nonneg=True)]
Damping = Annotated[float, scalar(U.DAMPING, nonneg=True)]
TorsionalStiffness = Annotated[float, scalar(U.TORSIONAL_STIFFNESS, nonneg=True)]
TorsionalDamping = Annotated[float, scalar(U.TORSIONAL_DAMPING, nonneg=True)]
LengthVec = Annotated[tuple[float, float, float], vector(U.LENGTH)]
VelocityVec = Annotated[tuple[float, float, float], vector(U.VELOCITY)]
AngVelVec = Annotated[tuple[float, float, float], vector(U.ANGULAR_VELOCITY)]
AccelVec = Annotated[tuple[float, float, float], vector(U.ACCELERATION)]
ForceVec = Annotated[tuple[float, float, float], vector(U.FORCE)]
TorqueVec = Annotated[tuple[float, float, float], vector(U.TORQUE)]
DirVec = Annotated[tuple[float, float, float], vector(U.DIMENSIONLESS)]


def _plausible(x: float, dim: U.Dim) -> float:
    U.check_plausible(x, dim)
    return x


def inertia_value(v: Any) -> list:
    """Principal moments (3 values) or a 3x3 tensor [kg m^2] of a real body: symmetric,
    positive definite, principal moments within the triangle inequality (as
    :func:`drivedyn.model.spec.check_inertia` requires of a body, checked here so that the
    message names the key)."""
    if isinstance(v, (list, tuple)) and len(v) == 3 and all(
            not isinstance(x, (list, tuple)) for x in v):
        out: list = [_plausible(U.to_si(x, U.INERTIA), U.INERTIA) for x in v]
        J = np.diag(out)
    elif (isinstance(v, (list, tuple)) and len(v) == 3
            and all(isinstance(r, (list, tuple)) and len(r) == 3 for r in v)):
        out = [[_plausible(U.to_si(x, U.INERTIA), U.INERTIA) for x in r] for r in v]
        J = np.array(out)
    else:
        raise ValueError("expected 3 principal moments or a 3x3 tensor [kg m^2]")
    if not np.allclose(J, J.T, rtol=1e-9, atol=1e-12 * max(1.0, np.abs(J).max())):
        raise ValueError("the inertia tensor is not symmetric")
    ev = np.linalg.eigvalsh(0.5 * (J + J.T))
    if ev[0] <= 0.0:
        raise ValueError(f"the inertia tensor is not positive definite (principal moments "
                         f"{ev.tolist()} kg m^2)")
    if ev[0] + ev[1] < ev[2] * (1.0 - 1e-9):
        raise ValueError(f"principal moments {ev.tolist()} kg m^2 violate the triangle "
                         "inequality J1 + J2 >= J3 (no real mass distribution has them)")
    return out


Inertia = Annotated[list, BeforeValidator(inertia_value)]


def _numeric(annotation: Any) -> bool:
    """Does a field's annotation take numbers and not true/false (``int``, ``float``,
    ``list[float]``, ``float | None`` ...)?"""
    if annotation is bool or annotation is Any:
        return False
    if annotation in (int, float):
        return True
    args = typing.get_args(annotation)
    if typing.get_origin(annotation) is Annotated:
        return _numeric(args[0])
    if any(a is bool or a is Any for a in args):
        return False
    return any(_numeric(a) for a in args)


def _bool_as_text(v: Any) -> Any:
    """``v`` with ``true``/``false`` (also inside lists and tables) as the strings
    ``"true"``/``"false"``."""
    if isinstance(v, bool):
        return str(v).lower()
    if isinstance(v, (list, tuple)):
        return [_bool_as_text(x) for x in v]
    if isinstance(v, dict):
        return {k: _bool_as_text(x) for k, x in v.items()}
    return v


class Strict(BaseModel):
    """A section of a model file: unknown keys are errors; numbers are finite (NaN and the
    infinities are refused, also inside lists and tables) and never ``true``/``false``; a
    partial table of a section with a default takes the keys it cannot do without (a body's
    mass and inertia, an adaptive step's mode) from that default."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    @model_validator(mode="before")
    @classmethod
    def _prepare(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data
        fields = cls.model_fields
        out = {}
        for k, v in data.items():
            f = fields.get(k)
            if f is not None and _numeric(f.annotation):
                # pydantic reads true/false as 1/0 where a number is expected: given to the
                # field as text instead, they fail its own validation, reported at the key
                v = _bool_as_text(v)
            elif f is not None and isinstance(v, dict) and f.default_factory is not None:
                # a partial table (``--set section.body.mass=2`` where the file leaves the
                # body at its default) takes the keys it lacks and cannot do without from
                # the section's default (the others keep their own defaults, as before)
                default = f.default_factory()  # type: ignore[call-arg]
                if isinstance(default, BaseModel):
                    dump = default.model_dump(warnings=False)
                    required = {n: dump[n] for n, g in type(default).model_fields.items()
                                if g.is_required()}
                    v = {**required, **v}
            out[k] = v
        return out


class Rotation(Strict):
    """A rotation by ``angle`` about ``axis`` (an axis-angle pair)."""

    axis: DirVec
    angle: Angle = 0.0

    @field_validator("axis")
    @classmethod
    def _axis_nonzero(cls, v: tuple[float, float, float]) -> tuple[float, float, float]:
        if not any(v):
            raise ValueError("the rotation axis must be a non-zero vector")
        return v


def rotation_value(v: Any) -> Any:
    if v is None or isinstance(v, dict):
        return v
    arr = np.asarray(v, dtype=float) if isinstance(v, (list, tuple)) else None
    if arr is not None and arr.shape == (3, 3):
        return arr.tolist()
    raise ValueError("expected {axis = [x, y, z], angle = ...} or a 3x3 rotation matrix")


RotationField = Annotated[Rotation | list[list[float]] | None, BeforeValidator(rotation_value)]


class FixedStepFile(Strict):
    mode: Literal["fixed"] = "fixed"
    h: Time = 1e-3


class AdaptiveStepFile(Strict):
    mode: Literal["adaptive"]
    h0: Time = 1e-4
    h_min: Time = 1e-10
    h_max: Time = 1e-2
    rtol: float = Field(default=1e-3, gt=0, allow_inf_nan=False)
    atol: float = Field(default=1e-7, gt=0, allow_inf_nan=False)
    # [rad] absolute tolerance of the nodes' rotations; none: atol (AdaptiveStep.atol_rot)
    atol_rot: Annotated[float, scalar(U.ANGLE, positive=True)] | None = None

    @model_validator(mode="after")
    def _ordered(self) -> AdaptiveStepFile:
        if not self.h_min <= self.h0 <= self.h_max:
            raise ValueError(f"expected h_min <= h0 <= h_max, got h_min = {self.h_min:g} s, "
                             f"h0 = {self.h0:g} s, h_max = {self.h_max:g} s")
        return self


class NewtonFile(Strict):
    strategy: Literal["modified", "full"] = "modified"
    tol: float = Field(default=1e-8, gt=0, lt=1, allow_inf_nan=False)
    phi_tol: float = Field(default=1e-10, gt=0, lt=1, allow_inf_nan=False)
    max_iter: int = Field(default=12, ge=1, le=1000)


class SolverFile(Strict):
    t_end: Time = 1.0
    rho_inf: float = Field(default=0.8, ge=0.0, le=1.0)
    step: Annotated[FixedStepFile | AdaptiveStepFile, Field(discriminator="mode")] = Field(
        default_factory=FixedStepFile)
    newton: NewtonFile = Field(default_factory=NewtonFile)

    @model_validator(mode="after")
    def _step_within_run(self) -> SolverFile:
        if isinstance(self.step, FixedStepFile) and self.step.h > self.t_end:
            raise ValueError(f"step.h = {self.step.h:g} s is longer than t_end = "
                             f"{self.t_end:g} s")
        return self


class OutputFile(Strict):
    dt: Time | None = None
    times: list[Annotated[float, scalar(U.TIME, nonneg=True)]] | None = None
    variables: list[str] | None = None
