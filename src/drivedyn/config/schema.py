"""Pydantic schema of model/scenario files (TOML).

Every physical value may be a plain number (SI) or a string with a unit (``"3 mm"``,
``"1500 rpm"``); see :mod:`drivedyn.units`. Unknown keys are errors (a misspelt key
must not be silently ignored). Errors name the key path, the bad value and what was expected.

File layout (every section optional except what the model needs)::

    [model]                # name, description, gravity, notes
    [[bodies]]             # rigid bodies
    [[nodes]]              # massless 6-dof nodes
    [[markers]]            # frames on bodies, nodes or "ground"
    [[materials]]          # beam materials: E, nu or G, density
    [[sections]]           # beam sections: solid_circular | hollow_circular | rectangular |
                           #                hollow_rectangular | general (EA ... EIz,
                           #                mass_per_length)
    [[beams]]              # geometrically exact beams: a straight shaft of N elements from
                           # start to end, or a chain through existing nodes
    [[parts]]              # meshed flexible parts (Craig-Bampton, floating frame): mesh
                           # (annular_washer | tube | box | file), material, interfaces
                           # (the first is the mounting face, on marker 'mount'), modes
    [[washer_contacts]]    # a rigid face (marker) on the face nodes of a flexible part
    [[elements]]           # every element by its class name: joints (type = "Hinge",
                           # "Fixed"...), "SpringDamper", "Force", "JointDriver", gears,
                           # contacts...: type = "GearPair", name = ..., its constructor's
                           # parameters (checked against the element class, see
                           # drivedyn.config.elements_section)
    [functions]            # named time functions, referenced by name
    [solver]               # t_end, rho_inf, step, newton
    [output]               # dt or times, variables

The dedicated sections of older files (``[[joints]]``, ``[[springs]]``,
``[[torsional_springs]]``, ``[[forces]]``, ``[[torques]]``, ``[[drivers]]``,
``[[speed_difference_drivers]]``) are deprecated aliases, translated into ``[[elements]]``
entries before validation (:mod:`drivedyn.config.legacy_sections`).
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, PrivateAttr, model_validator

import drivedyn.units as U  # noqa: N812 - short name, as in schema_base
from drivedyn.schema_base import (
    AccelVec,
    AngVelVec,
    DirVec,
    Inertia,
    Length,
    LengthVec,
    Mass,
    NonNegLength,
    OutputFile,
    RotationField,
    SolverFile,
    Strict,
    VelocityVec,
    scalar,
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


#: a time function: a number, the name of a ``[functions]`` entry or a table
FunctionField = float | str | dict[str, Any]


Pressure = Annotated[float, scalar(U.PRESSURE, positive=True)]
Density = Annotated[float, scalar(U.DENSITY, positive=True)]
PositiveLen = Annotated[float, scalar(U.LENGTH, positive=True)]
AxialStiffness = Annotated[float, scalar(U.FORCE, positive=True)]
BendingStiffness = Annotated[float, scalar(U.BENDING_STIFFNESS, positive=True)]
MassPerLength = Annotated[float, scalar(U.MASS_PER_LENGTH, positive=True)]
MassLength = Annotated[float, scalar(U.MASS_LENGTH, positive=True)]
Volume = Annotated[float, scalar(U.VOLUME, positive=True)]
DampingTime = Annotated[float, scalar(U.TIME, nonneg=True)]


class MaterialFile(Strict):
    """A beam material: ``E`` and one of ``nu`` / ``G``, and ``density``."""

    name: str
    E: Pressure
    nu: float | None = Field(default=None, gt=-1.0, lt=0.5)
    G: Pressure | None = None
    density: Density

    @model_validator(mode="after")
    def _one_shear(self) -> MaterialFile:
        if (self.nu is None) == (self.G is None):
            raise ValueError("give exactly one of 'nu' (Poisson's ratio) or 'G' (shear "
                             "modulus)")
        return self


class SectionFile(Strict):
    """A beam section; the keys needed depend on ``shape``."""

    name: str
    shape: Literal["solid_circular", "hollow_circular", "rectangular", "hollow_rectangular",
                   "general"]
    material: str | None = None
    diameter: PositiveLen | None = None
    outer_diameter: PositiveLen | None = None
    inner_diameter: NonNegLength | None = None
    width_y: PositiveLen | None = None
    height_z: PositiveLen | None = None
    thickness: PositiveLen | None = None
    EA: AxialStiffness | None = None
    GAy: AxialStiffness | None = None
    GAz: AxialStiffness | None = None
    GJ: BendingStiffness | None = None
    EIy: BendingStiffness | None = None
    EIz: BendingStiffness | None = None
    mass_per_length: MassPerLength | None = None
    rotary_inertia: tuple[MassLength, MassLength, MassLength] | None = None
    E: Pressure | None = None
    y_max: PositiveLen | None = None
    z_max: PositiveLen | None = None
    torsion_modulus: Volume | None = None

    @model_validator(mode="after")
    def _keys_of_shape(self) -> SectionFile:
        need = {"solid_circular": ("diameter", "material"),
                "hollow_circular": ("outer_diameter", "inner_diameter", "material"),
                "rectangular": ("width_y", "height_z", "material"),
                "hollow_rectangular": ("width_y", "height_z", "thickness", "material"),
                "general": ("EA", "GAy", "GAz", "GJ", "EIy", "EIz", "mass_per_length")}
        missing = [k for k in need[self.shape] if getattr(self, k) is None]
        if missing:
            raise ValueError(f"a {self.shape} section needs {', '.join(missing)}")
        geometric = {"diameter", "outer_diameter", "inner_diameter", "width_y", "height_z",
                     "thickness"}
        general = {"EA", "GAy", "GAz", "GJ", "EIy", "EIz", "mass_per_length",
                   "rotary_inertia", "E", "y_max", "z_max", "torsion_modulus"}
        allowed = set(need[self.shape]) | ({"material"} if self.shape != "general" else
                                           general)
        extra = sorted(k for k in geometric | general | {"material"}
                       if getattr(self, k) is not None and k not in allowed)
        if extra:
            raise ValueError(f"{', '.join(extra)} do(es) not apply to a {self.shape} section "
                             f"(keys: {', '.join(sorted(allowed))})")
        return self


class BeamFile(Strict):
    """A beam: a straight shaft of ``elements`` elements from ``start`` to ``end``
    (optionally starting/ending on existing nodes or bodies ``node_a``/``node_b``), or a
    chain of elements through existing ``nodes``."""

    name: str
    section: str
    start: LengthVec | None = None
    end: LengthVec | None = None
    elements: int | None = Field(default=None, ge=1)
    nodes: list[str] | None = Field(default=None, min_length=2)
    node_a: str | None = None
    node_b: str | None = None
    orientation: DirVec | None = None
    damping: DampingTime = 0.0
    mass_matrix: Literal["lumped", "consistent"] = "lumped"
    curved: bool = False
    velocity: VelocityVec = (0.0, 0.0, 0.0)
    angular_velocity: AngVelVec = (0.0, 0.0, 0.0)

    @model_validator(mode="after")
    def _one_layout(self) -> BeamFile:
        straight = [k for k in ("start", "end", "elements") if getattr(self, k) is not None]
        if self.nodes is not None:
            if straight or self.node_a or self.node_b:
                raise ValueError("give either 'nodes' (a chain through existing nodes) or "
                                 "'start', 'end', 'elements' (a straight beam), not both")
        elif len(straight) != 3:
            raise ValueError("a straight beam needs 'start', 'end' and 'elements' (or give "
                             "'nodes')")
        if self.curved and self.nodes is None:
            raise ValueError("'curved' applies to a chain through existing 'nodes' (whose "
                             "frames give the initial shape)")
        return self


class MeshFile(Strict):
    """A part's mesh: a built-in shape with its dimensions, or a file read by meshio (Gmsh
    ``.msh``, Abaqus ``.inp``...; ``path`` relative to the model file, ``scale`` to metres).
    ``cells``: (n_r, n_theta, n_z) for washers and tubes, (nx, ny, nz) for boxes."""

    shape: Literal["annular_washer", "tube", "box", "file"]
    r_int: NonNegLength | None = None
    r_ext: PositiveLen | None = None
    thickness: PositiveLen | None = None
    length: PositiveLen | None = None
    flanges: list[tuple[Length, Length, PositiveLen]] = Field(default_factory=list)
    lx: PositiveLen | None = None
    ly: PositiveLen | None = None
    lz: PositiveLen | None = None
    cells: tuple[int, int, int] | None = None
    path: str | None = None
    scale: float = Field(default=1.0, gt=0.0)

    @model_validator(mode="after")
    def _keys_of_shape(self) -> MeshFile:
        need = {"annular_washer": ("r_int", "r_ext", "thickness"),
                "tube": ("r_int", "r_ext", "length"), "box": ("lx", "ly", "lz"),
                "file": ("path",)}[self.shape]
        missing = [k for k in need if getattr(self, k) is None]
        if missing:
            raise ValueError(f"a {self.shape} mesh needs {', '.join(missing)}")
        if self.cells is not None and min(self.cells) < 1:
            raise ValueError(f"cells = {list(self.cells)}: expected three integers >= 1")
        return self


class SelectionFile(Strict):
    """Nodes of a part: on the plane ``axis = value`` (part frame) and/or within
    ``r_min <= r <= r_max`` (r: distance from the part's z axis)."""

    name: str = ""
    axis: Literal["x", "y", "z"] | None = None
    value: Length | None = None
    r_min: NonNegLength | None = None
    r_max: PositiveLen | None = None
    connection: Literal["rigid", "average"] = "rigid"  # interfaces: RBE2 spider or RBE3

    @model_validator(mode="after")
    def _something(self) -> SelectionFile:
        if self.axis is None and self.r_min is None and self.r_max is None:
            raise ValueError("a node selection needs 'axis' and 'value', or 'r_min'/'r_max'")
        if (self.axis is None) != (self.value is None):
            raise ValueError("give 'axis' and 'value' together")
        return self


class PartFile(Strict):
    """A meshed flexible part: reduced by Craig-Bampton with ``modes`` fixed-interface modes
    (plus 4 static modes of the normal pressure patterns of each of ``load_faces``, the faces
    contacts press on) and mounted on ``mount`` by its first interface (rigid spider), whose
    node centroid is the part frame's origin."""

    name: str
    mount: str
    material: str
    mesh: MeshFile
    interfaces: list[SelectionFile] = Field(min_length=1)
    modes: Annotated[int, Field(ge=0, le=200)] | Literal["all"] = 6
    load_faces: list[SelectionFile] = Field(default_factory=list)
    damping: DampingTime = 0.0


class WasherContactFile(Strict):
    """A rigid face (``marker``: origin on the face, z towards the part) pressed on the
    ``face`` nodes of the flexible ``part``; ``law`` and ``friction`` as for contacts. With
    ``quadrature = [n_r, n_theta]`` the contact is evaluated at the points of a face
    quadrature instead (:func:`drivedyn.fe.annulus_quadrature`: ``n_r`` Gauss radii per
    radial cell, ``n_theta`` angles dividing the cells around): for a part meshed as an
    ``annular_washer`` and a face on one of its z planes."""

    name: str
    part: str
    marker: str
    face: SelectionFile
    law: dict[str, Any]
    friction: dict[str, Any] | None = None
    quadrature: tuple[int, int] | None = None


class GenericElementFile(BaseModel):
    """Any registered element type by its class name; the other keys are its parameters,
    checked against the element class's dataclass fields and ``units`` when the elements are
    built (:func:`drivedyn.config.elements_section.generic_element`): numbers in SI or
    strings with units, converted to SI."""

    model_config = ConfigDict(extra="allow")
    type: str
    name: str


class ModelFile(Strict):
    """The whole file."""

    model: ModelInfo = Field(default_factory=ModelInfo)
    bodies: list[BodyFile] = Field(default_factory=list)
    nodes: list[NodeFile] = Field(default_factory=list)
    markers: list[MarkerFile] = Field(default_factory=list)
    materials: list[MaterialFile] = Field(default_factory=list)
    sections: list[SectionFile] = Field(default_factory=list)
    beams: list[BeamFile] = Field(default_factory=list)
    parts: list[PartFile] = Field(default_factory=list)
    washer_contacts: list[WasherContactFile] = Field(default_factory=list)
    elements: list[GenericElementFile] = Field(default_factory=list)
    functions: dict[str, FunctionField] = Field(default_factory=dict)
    solver: SolverFile = Field(default_factory=SolverFile)
    output: OutputFile = Field(default_factory=OutputFile)

    # where each [[elements]] entry comes from (set by the loader) and the deprecation notes
    _element_labels: list[str] = PrivateAttr(default_factory=list)
    _notes: list[str] = PrivateAttr(default_factory=list)

    def set_origin(self, element_labels: list[str], notes: list[str]) -> None:
        """Record how messages name each ``[[elements]]`` entry (an entry translated from a
        deprecated section by that section: ``"joints[1] (hinge)"``) and the file's
        deprecation notes."""
        self._element_labels = list(element_labels)
        self._notes = list(notes)

    def element_label(self, i: int) -> str:
        """How messages name ``elements[i]``: ``"elements[0] (mesh)"`` or, for an entry of a
        deprecated section, ``"joints[1] (hinge)"``."""
        if i < len(self._element_labels):
            return self._element_labels[i]
        return f"elements[{i}] ({self.elements[i].name})"

    @property
    def notes(self) -> list[str]:
        """Deprecation notes about the file (one per deprecated section it uses)."""
        return list(self._notes)
