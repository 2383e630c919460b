"""Schema of the parametric TORSEN Type C model file (``library = "torsen_c"``).

Every value is SI or a string with units (``"1.5 mm"``, ``"30 deg"``, ``"20 rpm"``); keys are
checked (unknown keys are refused) and every problem is reported with its key path. The
geometry itself (tooth counts against the planet count, radii against the gears) is checked
when the model is built (:func:`drivedyn.library.torsen_c.check_parameters`).
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

import drivedyn.units as U  # noqa: N812 - short name for units
from drivedyn.schema_base import (
    AdaptiveStepFile,
    Angle,
    Inertia,
    Mass,
    NewtonFile,
    NonNegLength,
    PositiveLength,
    Strict,
    Time,
    scalar,
)

AngularVelocity = Annotated[float, scalar(U.ANGULAR_VELOCITY)]
TorqueValue = Annotated[float, scalar(U.TORQUE)]
PositiveVelocity = Annotated[float, scalar(U.VELOCITY, positive=True)]
PositiveTime = Time
Coefficient = Annotated[float, Field(ge=0.0, le=1.0)]


class Info(Strict):
    library: Literal["torsen_c"]
    name: str = "torsen-c"
    description: str = ""
    notes: dict[str, str] = Field(default_factory=dict)


class Gears(Strict):
    """Epicyclic set: sun (front output), planets in housing pockets, internal gear."""

    teeth_sun: int = Field(gt=0)
    teeth_planet: int = Field(gt=0)
    teeth_ring: int = Field(gt=0)
    planets: int = Field(ge=2, le=12)
    module: PositiveLength
    helix_angle: Angle  # of the sun, > 0 right hand
    pressure_angle: Angle = 0.3490658503988659
    face_width: PositiveLength
    damping_ratio: float = Field(default=0.05, ge=0.0)
    stiffness: Annotated[float, scalar(U.STIFFNESS, positive=True)] | None = None
    youngs_modulus: Annotated[float, scalar((-1, 1, -2, 0), positive=True)] = 206e9


class Spline(Strict):
    """Helical spline between internal gear and coupling (the seeds' screw joint)."""

    radius: PositiveLength
    helix_angle: Angle  # > 0: lead of the same sign as the sun's helix


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
    """Planet tips in the housing pockets (radial clearance, friction)."""

    clearance: PositiveLength
    mu: Coefficient


class Contact(Strict):
    """Normal law of every washer and pocket contact, and the friction regularisation."""

    stiffness: Annotated[float, Field(gt=0)] = 1e10
    exponent: float = Field(default=1.5, ge=1.0, le=3.0)
    law: str = "hunt-crossley"
    restitution: float = Field(default=0.5, gt=0.0, le=1.0)
    eps_v: PositiveVelocity = 1e-3


class FlexibleParts(Strict):
    """Meshed flexible parts (Craig-Bampton reduced, floating frame of reference).

    ``washers = true`` replaces the five rigid washer contacts by flexible steel washers
    (annular meshes of ``washer_thickness`` mounted by their back face on the body that
    carries them), pressed by the rigid gear faces node by node
    (:class:`~drivedyn.elements.flexible.FlexibleWasherContact`).

    ``case = true`` replaces the rigid case by a meshed steel cup bolted to the housing by its
    flange face (schematic geometry, chosen, not fitted: a wall ``case_wall`` from the
    ring-gear washer seat to the coupling washer seat, a bolting flange out to
    ``case_flange_radius``, a lip carrying the ring-gear seat and an end plate carrying the
    coupling seat, all ``case_plate`` thick); the coupling and the internal gear then press
    directly on the case's seat faces, so the case deforms under the washer loads. Its mass
    and inertia come from the mesh (2.6 kg of steel with the defaults), not from
    ``bodies.case``."""

    washers: bool = False
    case: bool = False
    washer_thickness: PositiveLength = 2e-3
    washer_modes: int = Field(default=2, ge=0, le=60)
    washer_cells: tuple[int, int] = (2, 24)  # across the width, around
    case_modes: int = Field(default=6, ge=0, le=60)
    case_wall: tuple[PositiveLength, PositiveLength] = (0.076, 0.085)  # inner, outer radius
    case_flange_radius: PositiveLength = 0.100
    case_plate: PositiveLength = 0.006  # thickness of the flange, the seat lip, the end plate
    case_cells: tuple[int, int] = (1, 24)
    youngs_modulus: Annotated[float, scalar((-1, 1, -2, 0), positive=True)] = 210e9
    poisson_ratio: float = Field(default=0.3, gt=-1.0, lt=0.5)
    density: Annotated[float, scalar(U.DENSITY, positive=True)] = 7850.0

    @model_validator(mode="after")
    def _cells(self) -> FlexibleParts:
        for key in ("washer_cells", "case_cells"):
            nr, nt = getattr(self, key)
            if nr < 1 or nt < 6:
                raise ValueError(f"{key} = {[nr, nt]}: expected [n_r >= 1, n_theta >= 6]")
        ri, ro = self.case_wall
        if not ri < ro < self.case_flange_radius:
            raise ValueError(f"case_wall = {[ri, ro]} and case_flange_radius = "
                             f"{self.case_flange_radius}: expected inner < outer < flange radius")
        return self


class Body(Strict):
    mass: Mass
    inertia: Inertia


class Bodies(Strict):
    housing: Body
    case: Body
    sun: Body
    ring: Body
    coupling: Body
    planet: Body


class Bench(Strict):
    """Test-bench protocol (seed 003): drive then coast in one run, steady windows."""

    torque: TorqueValue = 125.0
    speed_diff: AngularVelocity = 2.0943951023931953
    ramp: PositiveTime = 0.3
    transition: tuple[Time, Time] = (1.2, 2.0)
    t_end: PositiveTime = 3.0
    window_drive: tuple[Time, Time] = (0.4, 1.0)
    window_coast: tuple[Time, Time] = (2.2, 2.8)

    @model_validator(mode="after")
    def _order(self) -> Bench:
        t1, t2 = self.transition
        if not self.ramp <= t1 < t2 <= self.t_end:
            raise ValueError(f"expected ramp <= transition start < transition end <= t_end, got "
                             f"ramp {self.ramp}, transition {list(self.transition)}, t_end "
                             f"{self.t_end} [s]")
        for label, (a, b), lo, hi in (("window_drive", self.window_drive, self.ramp, t1),
                                      ("window_coast", self.window_coast, t2, self.t_end)):
            if not lo <= a < b <= hi:
                raise ValueError(f"{label} = {[a, b]} s must lie in a steady part, within "
                                 f"[{lo}, {hi}] s")
        return self


class Vehicle(Strict):
    """Vehicle configuration: torque on the housing, both output speeds prescribed.

    The engine torque starts at 0, ramps to ``torque_levels[0]`` [N m] over ``ramp``, holds
    it for ``hold``, ramps to the next level, and so on (positive = drive); ``speed_diff``
    is the rear-minus-front speed [rad/s] of each level; ``speed`` is the mean output speed
    (positive = forward, about +z). ``h_max`` caps the step of this run: the turning
    planets excite the meshes, and long steps cost Newton failures and leave numerical
    oscillations in the held torques."""

    speed: AngularVelocity = 30.0
    torque_levels: list[float] = Field(default_factory=lambda: [
        60.0, 125.0, 60.0, -60.0, -125.0, -60.0, 60.0, 125.0, 60.0, -60.0, -125.0, -60.0])
    speed_diff: list[float] = Field(default_factory=lambda: [
        -2.0, -2.0, -2.0, -2.0, -2.0, -2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0])
    hold: PositiveTime = 0.6
    ramp: PositiveTime = 0.25
    h_max: PositiveTime = 2e-4


class Solver(Strict):
    rho_inf: float = Field(default=0.8, ge=0.0, le=1.0)
    step: AdaptiveStepFile = Field(default_factory=lambda: AdaptiveStepFile(
        mode="adaptive", h0=1e-4, h_min=1e-9, h_max=2e-3, rtol=1e-3, atol=1e-6))
    newton: NewtonFile = Field(default_factory=NewtonFile)
    output_dt: PositiveTime = 5e-3

    def settings(self, h_max: float | None = None) -> dict:
        """``integrator``, ``step`` and ``newton`` arguments of ``simulate``; ``h_max`` [s]
        caps the largest step (the vehicle run)."""
        from drivedyn.solver.settings import AdaptiveStep, GeneralizedAlpha, Newton

        st, nw = self.step, self.newton
        hm = st.h_max if h_max is None else min(st.h_max, h_max)
        return {"integrator": GeneralizedAlpha(self.rho_inf),
                "step": AdaptiveStep(st.h0, st.h_min, hm, st.rtol, st.atol),
                "newton": Newton(nw.strategy, nw.tol, nw.phi_tol, nw.max_iter)}


class Calibration(Strict):
    """What was fitted to what (written by ``drivedyn calibrate``)."""

    fitted: list[str] = Field(default_factory=list)
    targets: dict[str, float] = Field(default_factory=dict)
    source: str = ""
    command: str = ""
    method: str = ""
    result: dict[str, float] = Field(default_factory=dict)


class Experiment(Strict):
    """Measured TDR of the four modes and the seeds' simulated values (seed 003, Table 1)."""

    tdr: dict[str, float] = Field(default_factory=dict)
    seeds: dict[str, float] = Field(default_factory=dict)
    source: str = ""


class Scenario(Strict):
    kind: Literal["vehicle", "bench"] = "vehicle"
    modes: Literal["rear", "front"] = "rear"


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
