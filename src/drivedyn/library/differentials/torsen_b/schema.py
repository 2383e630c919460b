"""Schema of the parametric TORSEN Type B model file (``library = "torsen_b"``).

Every value is SI or a string with units; unknown keys are refused and every problem is
reported with its key path. The geometry itself (pockets against each other, the element
gears' relief against the other side gear, undercut, contact ratio) is checked when the model
is built (:func:`drivedyn.library.differentials.torsen_b.model.check_parameters`). The
sections shared with the other differentials are in
:mod:`drivedyn.library.differentials.schema_sections`.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field

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
    library: Literal["torsen_b"]
    name: str = "torsen-b"
    description: str = ""
    notes: dict[str, str] = Field(default_factory=dict)


class Gears(Strict):
    """Two helical side gears (left at -z, right at +z) and ``pairs`` pairs of element gears.

    Each element gear meshes one side gear over that gear's face width and its partner at both
    of its ends, beyond the side gears (``end_width`` each): ``2 pairs`` side meshes and
    ``2 pairs`` end meshes. ``helix_angle`` is the left side gear's (> 0: right hand); the
    right side gear is its mirror image (opposite hand), each element gear has the opposite
    hand of its side gear along its whole length, so the two element gears of a pair (of
    opposite hands) also mesh as a crossed-hand external helical pair at their ends."""

    teeth_side: int = Field(gt=0, le=MAX_TEETH)
    teeth_element: int = Field(gt=0, le=MAX_TEETH)
    pairs: int = Field(ge=2, le=8)
    module: PositiveLength
    helix_angle: Angle
    pressure_angle: Angle = 0.3490658503988659
    face_width: PositiveLength  # of each side gear
    end_width: PositiveLength  # of each element-element end mesh
    side_gap: PositiveLength = 0.004  # axial space between the side gears (middle washer)
    damping_ratio: float = Field(default=0.05, ge=0.0)
    stiffness: Annotated[float, scalar(U.STIFFNESS, positive=True)] | None = None
    stiffness_variation: bool = True
    backlash: NonNegLength = 5e-5
    tooth_friction: Coefficient = 0.0
    youngs_modulus: Modulus = 206e9
    # C1 onset of the flank stiffness (GearPair.flank_onset): a numerical regularisation
    flank_onset: NonNegLength = 0.0


class WasherFace(Strict):
    """One thrust washer: annular face r_int..r_ext and axial play."""

    r_int: NonNegLength
    r_ext: PositiveLength
    gap: NonNegLength = 5e-5


class Washers(Strict):
    """The three thrust washers: behind each side gear (on the housing) and between the side
    gears; one friction coefficient ``mu`` shared by all (seed 003: "the friction
    coefficients have similar values for all contacts with thrust washers")."""

    mu: Coefficient
    left: WasherFace
    middle: WasherFace
    right: WasherFace
    squeeze_film: bool = False
    viscosity: Annotated[float, scalar((-1, 1, -1, 0), positive=True)] = 0.05
    # the faces' roughness (the film's metal-contact height) is contact.elastic_washers.roughness


class Pockets(Strict):
    """Element gears in the housing pockets: radial clearance of the tips in the bore, and
    the end faces on the pocket floors (annulus ``end_r_int..end_r_ext``, axial play
    ``end_gap``); ``mu`` is the coefficient of both (tips and end faces). ``oil_film``: the
    gear oil (``washers.viscosity``) in each pocket's clearance as a squeeze film on the tip
    lands (:class:`~drivedyn.elements.contact.JournalFilm`)."""

    clearance: PositiveLength
    mu: Coefficient
    end_r_int: NonNegLength = 0.004
    end_r_ext: PositiveLength = 0.010
    end_gap: NonNegLength = 5e-5
    oil_film: bool = False


class Bodies(Strict):
    housing: Body
    side: Body  # each side gear (with its share of the half-axle spline hub)
    element: Body  # each element gear


class TorsenBFile(Strict):
    """The whole ``torsen-b`` model file."""

    model: Info
    gears: Gears
    washers: Washers
    pockets: Pockets
    contact: Contact = Field(default_factory=Contact)
    flexible: FlexibleWashers = Field(default_factory=FlexibleWashers)
    bodies: Bodies
    bench: Bench = Field(default_factory=Bench)
    vehicle: Vehicle = Field(default_factory=Vehicle)
    solver: Solver = Field(default_factory=Solver)
    scenario: Scenario = Field(default_factory=Scenario)
    experiment: Experiment = Field(default_factory=Experiment)
    calibration: Calibration = Field(default_factory=Calibration)
    provenance: Provenance = Field(default_factory=Provenance)
