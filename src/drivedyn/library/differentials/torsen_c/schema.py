"""Schema of the parametric TORSEN Type C model file (``library = "torsen_c"``).

Every value is SI or a string with units (``"1.5 mm"``, ``"30 deg"``, ``"20 rpm"``); keys are
checked (unknown keys are refused) and every problem is reported with its key path. The
geometry itself (tooth counts against the planet count, radii against the gears) is checked
when the model is built (:func:`drivedyn.library.differentials.torsen_c.model.check_parameters`).
The sections shared with the other differentials are in
:mod:`drivedyn.library.differentials.schema_sections`.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

import drivedyn.units as U  # noqa: N812 - short name for units
from drivedyn.library.differentials.schema_sections import (
    Bench,
    Body,
    Calibration,
    Coefficient,
    Contact,
    Experiment,
    FlexibleWashers,
    Modulus,
    Provenance,
    Scenario,
    Solver,
    Vehicle,
)
from drivedyn.schema_base import MAX_TEETH, Angle, NonNegLength, PositiveLength, Strict, scalar


class Info(Strict):
    library: Literal["torsen_c"]
    name: str = "torsen-c"
    description: str = ""
    notes: dict[str, str] = Field(default_factory=dict)


class Gears(Strict):
    """Epicyclic set: sun (front output), planets in housing pockets, internal gear."""

    teeth_sun: int = Field(gt=0, le=MAX_TEETH)
    teeth_planet: int = Field(gt=0, le=MAX_TEETH)
    teeth_ring: int = Field(gt=0, le=MAX_TEETH)
    planets: int = Field(ge=2, le=12)
    module: PositiveLength
    helix_angle: Angle  # of the sun, > 0 right hand
    pressure_angle: Angle = 0.3490658503988659
    face_width: PositiveLength
    damping_ratio: float = Field(default=0.05, ge=0.0)
    stiffness: Annotated[float, scalar(U.STIFFNESS, positive=True)] | None = None
    stiffness_variation: bool = False
    backlash: NonNegLength = 0.0
    tooth_friction: Coefficient = 0.0
    youngs_modulus: Modulus = 206e9
    # C1 onset of the flank stiffness (GearPair.flank_onset): a numerical regularisation
    flank_onset: NonNegLength = 0.0


class Spline(Strict):
    """Helical spline between internal gear and coupling (the seeds' screw joint).

    ``mu``: Coulomb friction of the spline's flanks, with stick
    (:class:`~drivedyn.elements.joints.Screw`); ``stick_stiffness`` [N/m]: the flanks'
    stiffness along the helix while they stick, under load; ``stick_onset`` [N]: the flanks'
    normal force at which it is half that (0: constant)."""

    radius: PositiveLength
    helix_angle: Angle  # > 0: lead of the same sign as the sun's helix
    mu: Coefficient = 0.0
    stick_stiffness: Annotated[float, scalar(U.STIFFNESS, positive=True)] = 1e9
    stick_onset: Annotated[float, scalar(U.FORCE, nonneg=True)] = 0.0


class Washer(Strict):
    """One thrust-washer contact: annular face r_int..r_ext, axial play, friction."""

    r_int: NonNegLength
    r_ext: PositiveLength
    mu: Coefficient
    gap: NonNegLength = 5e-5


class Washers(Strict):
    sun_housing: Washer
    sun_coupling: Washer
    coupling_case: Washer
    ring_housing: Washer
    ring_case: Washer


class Pockets(Strict):
    """Planets in the housing pockets: the tips in the bore (radial ``clearance``) and, with
    ``end_faces`` (default), the planet's end faces on the pocket floors (annulus
    ``end_r_int..end_r_ext``, axial play ``end_gap``); ``mu`` is the coefficient of both.

    The two meshes of a planet push it axially with ``tan(beta) (F_ring - F_sun)``: the
    pocket friction makes the ring-mesh force differ from the sun-mesh force, so a net
    thrust of 40-60 % of one mesh's thrust remains, which the floor carries with friction
    against the planet's spin. ``end_faces = false``: a planar joint holds the planet
    axially without friction (the floors' friction left out). ``end_film`` (off by default): the
    gear oil (``viscosity``) between each end face and its floor, a squeeze film with metal
    contact below the faces' roughness (``contact.elastic_washers.roughness``) and viscous
    drag."""

    clearance: PositiveLength
    mu: Coefficient
    end_faces: bool = True
    end_r_int: NonNegLength = 0.002
    end_r_ext: PositiveLength = 0.006
    end_gap: NonNegLength = 5e-5
    end_film: bool = False
    viscosity: Annotated[float, scalar((-1, 1, -1, 0), positive=True)] = 0.05


class Shaft(Strict):
    """An output shaft as a geometrically exact beam: a steel tube (``inner_diameter`` 0: a
    solid bar) of ``length`` [m] from the output gear's centre outwards, in ``elements``
    equal beam elements."""

    length: PositiveLength
    outer_diameter: PositiveLength
    inner_diameter: NonNegLength = 0.0
    elements: int = Field(default=6, ge=1, le=100)

    @model_validator(mode="after")
    def _section(self) -> Shaft:
        if not self.inner_diameter < self.outer_diameter:
            raise ValueError(f"inner_diameter = {self.inner_diameter} m: expected < "
                             f"outer_diameter = {self.outer_diameter} m")
        return self


class FlexibleParts(FlexibleWashers):
    """Meshed flexible parts (Craig-Bampton reduced, floating frame of reference): the five
    washers (``washers``, see :class:`FlexibleWashers`) and the case.

    ``case = true`` replaces the rigid case by a meshed steel cup bolted to the housing by its
    flange face (schematic geometry, chosen, not fitted: a wall ``case_wall`` from the
    ring-gear washer seat to the coupling washer seat, a bolting flange out to
    ``case_flange_radius``, a lip carrying the ring-gear seat and an end plate carrying the
    coupling seat, all ``case_plate`` thick); the coupling and the internal gear then press
    directly on the case's seat faces, so the case deforms under the washer loads. Its mass
    and inertia come from the mesh (2.6 kg of steel with the defaults), not from
    ``bodies.case``.

    ``shafts = true`` adds the two output shafts as geometrically exact beams (seed 002's
    flexible driveshafts): the front one (``shaft_front``) from the sun outwards along -z,
    the rear one (``shaft_rear``) from the coupling along +z, each ending in a bearing to
    the ground; the bench and the vehicle configuration then drive and load the outputs at
    the shaft ends, and the shafts' section forces and stresses are recorded. Chosen
    dimensions (no source: a short solid front output shaft and a tubular propeller shaft
    to the rear) and ``shaft_damping`` (stiffness-proportional, about 3 % of critical on the
    first torsion mode near 1 kHz)."""

    case: bool = False
    shafts: bool = False
    shaft_front: Shaft = Field(default_factory=lambda: Shaft(
        length=0.45, outer_diameter=0.030, elements=6))
    shaft_rear: Shaft = Field(default_factory=lambda: Shaft(
        length=1.2, outer_diameter=0.070, inner_diameter=0.064, elements=8))
    shaft_damping: Annotated[float, scalar(U.TIME), Field(ge=0.0)] = 1e-5
    case_modes: int = Field(default=6, ge=0, le=60)
    case_wall: tuple[PositiveLength, PositiveLength] = (0.076, 0.085)  # inner, outer radius
    case_flange_radius: PositiveLength = 0.100
    case_plate: PositiveLength = 0.006  # thickness of the flange, the seat lip, the end plate
    case_cells: tuple[int, int] = (1, 24)

    @model_validator(mode="after")
    def _case_cells(self) -> FlexibleParts:
        nr, nt = self.case_cells
        if nr < 1 or nt < 6:
            raise ValueError(f"case_cells = {[nr, nt]}: expected [n_r >= 1, n_theta >= 6]")
        ri, ro = self.case_wall
        if not ri < ro < self.case_flange_radius:
            raise ValueError(f"case_wall = {[ri, ro]} and case_flange_radius = "
                             f"{self.case_flange_radius}: expected inner < outer < flange radius")
        return self


class Bodies(Strict):
    housing: Body
    case: Body
    sun: Body
    ring: Body
    coupling: Body
    planet: Body


class TorsenCFile(Strict):
    """The whole ``torsen-c`` model file."""

    model: Info
    gears: Gears
    spline: Spline
    washers: Washers
    pockets: Pockets
    contact: Contact = Field(default_factory=Contact)
    flexible: FlexibleParts = Field(default_factory=FlexibleParts)
    bodies: Bodies
    bench: Bench = Field(default_factory=Bench)
    vehicle: Vehicle = Field(default_factory=Vehicle)
    solver: Solver = Field(default_factory=Solver)
    scenario: Scenario = Field(default_factory=Scenario)
    experiment: Experiment = Field(default_factory=Experiment)
    calibration: Calibration = Field(default_factory=Calibration)
    provenance: Provenance = Field(default_factory=Provenance)
