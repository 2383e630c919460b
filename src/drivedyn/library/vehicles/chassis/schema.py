"""Schema of a ladder frame: side rails, cross members, their sections and material, the mesh
and the body the frame carries (the ``[chassis]`` table of a vehicle's model file).

Frame coordinates: x forward along the rails from their rear end (x = 0) to their front end
(x = ``rails.length``), y to the left, z up, the origin on the frame's centre line at the
height of the rails' centroids. Every value is SI or a string with units; unknown keys are
refused and every problem names its key and value.

The defaults are a chosen light-truck / body-on-frame car frame (no single vehicle); each
number says where it comes from. The torsional stiffness they give is in ``docs/chassis.md``.
"""

from __future__ import annotations

import itertools
from typing import Annotated, Any, Literal

from pydantic import Discriminator, Field, Tag, model_validator

import drivedyn.units as U  # noqa: N812 - short name for units
from drivedyn.elements.beams.section import GeneralSection, HollowRectangular, Material
from drivedyn.schema_base import (
    Inertia,
    Length,
    LengthVec,
    Mass,
    PositiveLength,
    Strict,
    scalar,
)

Pressure = Annotated[float, scalar(U.PRESSURE, positive=True)]
Density = Annotated[float, scalar(U.DENSITY, positive=True)]
AxialStiffness = Annotated[float, scalar(U.FORCE, positive=True)]
BendingStiffness = Annotated[float, scalar(U.BENDING_STIFFNESS, positive=True)]
MassPerLength = Annotated[float, scalar(U.MASS_PER_LENGTH, positive=True)]
Area = Annotated[float, scalar((2, 0, 0, 0), positive=True)]  # [m^2]
SecondMoment = Annotated[float, scalar((4, 0, 0, 0), positive=True)]  # [m^4]


class FrameMaterial(Strict):
    """Linear elastic isotropic material of every member of the frame."""

    E: Pressure = 210e9  # literature: structural steel, EN 1993-1-1 sec. 3.2.6
    nu: float = Field(default=0.3, gt=-1.0, lt=0.5)  # literature: EN 1993-1-1 sec. 3.2.6
    density: Density = 7850.0  # literature: steel, EN 1991-1-1 table A.4

    def material(self) -> Material:
        """The beam :class:`~drivedyn.elements.beams.section.Material`."""
        return Material.from_nu(self.E, self.nu, self.density)


class BoxSection(Strict):
    """A closed rectangular (box) section of outer ``width`` (horizontal, across the member)
    and ``height`` (vertical) and uniform ``wall`` thickness; Bredt's torsion constant (see
    :class:`~drivedyn.elements.beams.section.HollowRectangular`)."""

    shape: Literal["box"] = "box"
    width: PositiveLength
    height: PositiveLength
    wall: PositiveLength

    @model_validator(mode="after")
    def _wall(self) -> BoxSection:
        if not 2.0 * self.wall < min(self.width, self.height):
            raise ValueError(f"wall = {self.wall:g} m: must be less than half the smaller of "
                             f"width = {self.width:g} m and height = {self.height:g} m")
        return self

    def beam_section(self, material: Material) -> HollowRectangular:
        """The beam section, section y horizontal across the member and z vertical."""
        return HollowRectangular(self.width, self.height, self.wall)


def _sized(width: float | None, height: float | None) -> dict[str, float | None]:
    """Fibre distances of a general section from an optional outer size."""
    return {"y_max": None if width is None else 0.5 * width,
            "z_max": None if height is None else 0.5 * height}


class DeclaredSection(Strict):
    """A section given by its properties, of the frame's material: ``area``, second moments
    ``I_vertical`` (bending in the vertical plane: the member sags) and ``I_lateral``,
    torsion constant ``J``, shear areas ``shear_area_vertical`` / ``shear_area_lateral``
    (an open channel, a pressed member from a handbook table); ``width`` / ``height``
    (optional outer size) set the fibre distances of the normal stress and the drawn
    radius."""

    shape: Literal["declared"]
    area: Area
    I_vertical: SecondMoment
    I_lateral: SecondMoment
    J: SecondMoment
    shear_area_vertical: Area
    shear_area_lateral: Area
    width: PositiveLength | None = None
    height: PositiveLength | None = None

    def beam_section(self, material: Material) -> GeneralSection:
        """The beam section, section y horizontal across the member and z vertical."""
        E, G, rho = material.E, material.G, material.density
        return GeneralSection(
            E * self.area, G * self.shear_area_lateral, G * self.shear_area_vertical,
            G * self.J, E * self.I_vertical, E * self.I_lateral, rho * self.area,
            rotary_inertia=(rho * (self.I_vertical + self.I_lateral), rho * self.I_vertical,
                            rho * self.I_lateral),
            E=E, **_sized(self.width, self.height))


class StiffnessSection(Strict):
    """A section given by its stiffnesses (a measured or composite member): axial ``EA``,
    shear ``GA_vertical`` / ``GA_lateral``, torsion ``GJ``, bending ``EI_vertical`` (the
    member sags) and ``EI_lateral``, ``mass_per_length``; ``width`` / ``height`` (optional
    outer size) set the drawn radius and, with the frame material's E, the normal-stress
    fibres."""

    shape: Literal["stiffness"]
    EA: AxialStiffness
    GA_vertical: AxialStiffness
    GA_lateral: AxialStiffness
    GJ: BendingStiffness
    EI_vertical: BendingStiffness
    EI_lateral: BendingStiffness
    mass_per_length: MassPerLength
    width: PositiveLength | None = None
    height: PositiveLength | None = None

    def beam_section(self, material: Material) -> GeneralSection:
        """The beam section, section y horizontal across the member and z vertical."""
        return GeneralSection(
            self.EA, self.GA_lateral, self.GA_vertical, self.GJ, self.EI_vertical,
            self.EI_lateral, self.mass_per_length, E=material.E,
            **_sized(self.width, self.height))


def _shape_of(v: Any) -> str:
    if isinstance(v, dict):
        return str(v.get("shape", "box"))
    return str(getattr(v, "shape", "box"))


#: a member's section: ``shape = "box"`` (the default), ``"declared"`` or ``"stiffness"``
FrameSection = Annotated[
    Annotated[BoxSection, Tag("box")] | Annotated[DeclaredSection, Tag("declared")]
    | Annotated[StiffnessSection, Tag("stiffness")],
    Discriminator(_shape_of, custom_error_type="shape",
                  custom_error_message="expected shape 'box', 'declared' or 'stiffness'"),
]


# chosen: a boxed rail 140 mm deep x 60 mm wide x 3.5 mm wall for a mid-size frame (an
# estimate, not taken from a vehicle or a source)
RAIL_SECTION = BoxSection(width=0.06, height=0.14, wall=0.0035)
# chosen: a square 70 mm x 3 mm welded cross-member tube (no single vehicle)
CROSS_SECTION = BoxSection(width=0.07, height=0.07, wall=0.003)


def _box_keys(data: Any, default: BoxSection) -> Any:
    """``data`` with a partial box table under ``section`` completed from ``default`` (a
    table of another shape is left whole: the default box's keys do not apply to it)."""
    if isinstance(data, dict) and isinstance(data.get("section"), dict):
        sec = data["section"]
        if _shape_of(sec) == "box":
            data = {**data, "section": {**default.model_dump(), **sec}}
    return data


class Rails(Strict):
    """The two straight side rails, parallel to x at ``y = +-track / 2``."""

    length: PositiveLength = 4.4  # chosen: 2.8 m wheelbase plus overhangs of a mid-size frame
    # distance between the rails' centre lines (the frame's track, not the wheels'); chosen:
    # 0.9 m, the order of the 34 in (0.864 m) outside width common to heavy-truck frames
    track: PositiveLength = 0.9
    section: FrameSection = RAIL_SECTION

    @model_validator(mode="before")
    @classmethod
    def _partial_box(cls, data: Any) -> Any:
        return _box_keys(data, RAIL_SECTION)


class CrossMember(Strict):
    """A straight cross member from the right rail to the left one at ``x`` (welded: it shares
    the rails' nodes there, a rigid joint); it gets a node on the centre line."""

    x: Length
    section: FrameSection = CROSS_SECTION

    @model_validator(mode="before")
    @classmethod
    def _partial_box(cls, data: Any) -> Any:
        return _box_keys(data, CROSS_SECTION)


def _cross_members() -> list[CrossMember]:
    # chosen: rear end, behind and ahead of the rear axle (x about 0.8 m), mid-frame (gearbox
    # mount), at the front axle (x about 3.6 m, engine and suspension cross member), front end
    return [CrossMember(x=x) for x in (0.0, 0.5, 1.2, 2.3, 3.6, 4.4)]


class Mesh(Strict):
    """Beam elements: every rail segment between two consecutive stations (rail ends, cross
    members, body mounts, ``stations``) and every half cross member (rail to centre line) gets
    ``elements_per_segment`` equal elements. ``stations``: further x positions where the
    rails get nodes (suspension pick-ups, engine mounts)."""

    # chosen: 2 is within 0.5 % of the converged torsional stiffness (docs/chassis.md)
    elements_per_segment: int = Field(default=2, ge=1, le=64)
    stations: list[Length] = Field(default_factory=list)


class CarriedBody(Strict):
    """The body the frame carries: ``mass``, centre of gravity ``cg`` (frame coordinates) and
    ``inertia`` about the centre of gravity in frame axes (3 principal moments or a 3x3
    tensor), lumped on the rails at the body mounts ``mounts`` (x positions; a mount on each
    rail), see :func:`drivedyn.library.vehicles.chassis.body.carriers`."""

    mass: Mass = 1000.0  # chosen: body shell, trim, occupants (powertrain and axles apart)
    # chosen: a little ahead of mid-frame, 0.35 m above the rails' centroids
    cg: LengthVec = (2.3, 0.0, 0.35)
    # chosen: a uniform box 4.4 m x 1.7 m x 1.1 m of the body's mass, m (b^2 + c^2) / 12
    inertia: Inertia = Field(default_factory=lambda: [341.7, 1714.2, 1854.2])
    # chosen: four pairs of body mounts spread along the cabin and load floor
    mounts: list[Length] = Field(default_factory=lambda: [0.8, 1.7, 2.9, 3.8])


class LadderFrameFile(Strict):
    """A ladder frame: two side rails, cross members, one material, the mesh density and the
    body carried (``body = None``: the bare frame)."""

    rails: Rails = Field(default_factory=Rails)
    cross_members: list[CrossMember] = Field(default_factory=_cross_members, min_length=1)
    material: FrameMaterial = Field(default_factory=FrameMaterial)
    mesh: Mesh = Field(default_factory=Mesh)
    body: CarriedBody | None = Field(default_factory=CarriedBody)

    @model_validator(mode="after")
    def _on_the_rails(self) -> LadderFrameFile:
        L = self.rails.length
        places = [(f"cross_members[{i}].x", c.x) for i, c in enumerate(self.cross_members)]
        places += [(f"mesh.stations[{i}]", x) for i, x in enumerate(self.mesh.stations)]
        if self.body is not None:
            places += [(f"body.mounts[{i}]", x) for i, x in enumerate(self.body.mounts)]
        for key, x in places:
            if not 0.0 <= x <= L:
                raise ValueError(f"{key} = {x:g} m lies outside the rails (0 to rails.length "
                                 f"= {L:g} m)")
        xs = sorted(c.x for c in self.cross_members)
        for a, b in itertools.pairwise(xs):
            if b - a < 1e-6 * L:
                raise ValueError(f"cross_members: two at x = {a:g} m (one per position)")
        if self.body is not None:
            mounts = sorted(set(self.body.mounts))
            if len(mounts) < 2:
                raise ValueError(f"body.mounts = {self.body.mounts}: expected at least two "
                                 "different x positions [m]")
            half = 0.5 * self.rails.track
            if not abs(self.body.cg[1]) < half:
                raise ValueError(f"body.cg[1] = {self.body.cg[1]:g} m: the centre of gravity "
                                 f"must lie between the rails (|y| < {half:g} m)")
        return self
