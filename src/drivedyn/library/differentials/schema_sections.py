"""Schema sections shared by the differential model files: contact law, bodies, the bench
protocol, the vehicle-configuration profile, solver settings, measured data and the record of
a calibration. Each differential's schema adds its own geometry sections."""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import ConfigDict, Field, ValidationInfo, field_validator, model_validator

import drivedyn.units as U  # noqa: N812 - short name for units
from drivedyn.elements.contact import NormalLaw
from drivedyn.elements.contact.impact_laws import LAW_NAMES
from drivedyn.elements.framework.checks import declared_unit
from drivedyn.schema_base import (
    AdaptiveStepFile,
    Force,
    Inertia,
    Mass,
    NewtonFile,
    PositiveLength,
    Strict,
    Time,
    scalar,
)

AngularVelocity = Annotated[float, scalar(U.ANGULAR_VELOCITY)]
PositiveAngularVelocity = Annotated[float, scalar(U.ANGULAR_VELOCITY, positive=True)]
TorqueValue = Annotated[float, scalar(U.TORQUE)]
PositiveTorque = Annotated[float, scalar(U.TORQUE, positive=True)]
PositiveVelocity = Annotated[float, scalar(U.VELOCITY, positive=True)]
PositiveTime = Time
Coefficient = Annotated[float, Field(ge=0.0, le=1.0)]
Modulus = Annotated[float, scalar((-1, 1, -2, 0), positive=True)]


class ElasticWashers(Strict):
    """Thrust-washer contact stiffness from the washer's elastic properties.

    With ``enabled``, each washer contact gets the law ``F = K delta^n`` (``n`` =
    ``contact.exponent``) whose tangent stiffness at ``rated_load`` equals the series
    stiffness of the two compliances of a flat, lubricated washer joint:

    * the washer layer in compression, ``k_layer = E S / t`` (S the annulus area, t the
      thickness; thin layer free to expand sideways on oiled faces);
    * the rough faces: Persson's contact theory (B.N.J. Persson, Phys. Rev. Lett. 99, 125502,
      2007) gives ``p ~ exp(-u / (gamma h_rms))`` for the mean separation ``u``, hence a
      normal stiffness proportional to the load, ``k_rough = F / (gamma h_rms)``, with
      ``gamma ~ 0.4`` and ``h_rms`` the combined rms roughness of the two faces
      (``h_rms = sqrt(2) Rq``, ``Rq = sqrt(pi/2) Ra`` for Gaussian heights).

    Hence ``k = 1 / (t/(E S) + gamma h_rms / F_r)`` and the penetration at the rated load
    ``delta_r = n F_r / k``, a few tenths of a micrometre for ground steel washers, where the
    power law of ``contact.stiffness`` (a Hertz point-contact default) sinks tens of
    micrometres. The pocket contacts keep ``contact.stiffness``.
    """

    enabled: bool = False
    youngs_modulus: Modulus = 206e9
    thickness: PositiveLength = 2e-3
    roughness: PositiveLength = 4e-7
    gamma: float = Field(default=0.4, gt=0.0, le=2.0)
    rated_load: Force = 2000.0

    @model_validator(mode="after")
    def _load(self) -> ElasticWashers:
        if not self.rated_load > 0.0:
            raise ValueError(f"rated_load = {self.rated_load} N: expected > 0")
        return self


class Contact(Strict):
    """Normal law of every washer and pocket contact, and the friction regularisation."""

    exponent: float = Field(default=1.5, ge=1.0, le=3.0)  # first: the stiffness's unit uses it
    stiffness: float = 1e10  # [N/m^exponent]
    law: str = "hunt-crossley"
    # (0, 1): the continuous-impact laws' range (the penalty law does not use it)
    restitution: float = Field(default=0.5, gt=0.0, lt=1.0)
    eps_v: PositiveVelocity = 1e-3
    elastic_washers: ElasticWashers = Field(default_factory=ElasticWashers)

    @field_validator("stiffness", mode="before")
    @classmethod
    def _stiffness(cls, v: Any, info: ValidationInfo) -> Any:
        """K in the normal law's unit N/m^exponent (N/m^1.5 for the default Hertz law): an SI
        number or a unit string, > 0 and plausible, the messages in that unit. Left to the
        type check if the exponent itself is refused."""
        n = info.data.get("exponent")
        if n is None:
            return v
        unit = declared_unit(NormalLaw, "stiffness", {"exponent": n})
        dim = U.parse_unit(unit)[1]
        x = U.to_si(v, dim)
        U.check_plausible(x, dim)
        if not x > 0.0:
            raise ValueError(f"must be > 0 {U.unit_label(dim)}")
        return x

    @field_validator("law")
    @classmethod
    def _known_law(cls, v: str) -> str:
        if v not in LAW_NAMES:
            raise ValueError(f"unknown law {v!r} (known: {', '.join(LAW_NAMES)})")
        return v

    def law_of(self, stiffness: float | None = None) -> NormalLaw:
        """The normal law with this file's exponent and damping, ``stiffness`` [N/m^n] or
        ``self.stiffness``."""
        return NormalLaw(self.stiffness if stiffness is None else stiffness, self.exponent,
                         law=self.law, restitution=self.restitution)

    def washer_law(self, r_int: float, r_ext: float, layer: bool = True) -> NormalLaw:
        """Normal law of a thrust washer r_int..r_ext [m] (see :class:`ElasticWashers`);
        ``layer=False`` leaves out the washer's own compression (a flexible washer body
        carries it)."""
        e = self.elastic_washers
        if not e.enabled:
            return self.law_of()
        return self.law_of(elastic_washer_stiffness(e, r_int, r_ext, self.exponent, layer))


def elastic_washer_stiffness(e: ElasticWashers, r_int: float, r_ext: float, exponent: float,
                             layer: bool = True) -> float:
    """K [N/m^n] of ``F = K delta^n`` whose tangent at ``e.rated_load`` is the series
    stiffness of the washer layer (if ``layer``) and the rough faces (see
    :class:`ElasticWashers`)."""
    area = math.pi * (r_ext**2 - r_int**2)
    h_rms = math.sqrt(2.0) * math.sqrt(math.pi / 2.0) * e.roughness
    compliance = e.gamma * h_rms / e.rated_load
    if layer:
        compliance += e.thickness / (e.youngs_modulus * area)
    delta = exponent * e.rated_load * compliance          # penetration at the rated load [m]
    return e.rated_load / delta**exponent


class FlexibleWashers(Strict):
    """Meshed flexible thrust washers (Craig-Bampton reduced, floating frame of reference).

    ``washers = true`` replaces every rigid washer contact by a flexible steel annulus of the
    washer's radii and ``washer_thickness`` (chosen: a usual thrust-washer thickness), mounted
    by its back face on the body that carries the washer, its face where the rigid washer's
    face is, pressed by the rigid gear face
    (:class:`~drivedyn.elements.flexible.FlexibleWasherContact`; the washer's own compression
    is then the mesh's, the law keeps the rough faces). The contact is evaluated at the
    points of a quadrature rule of the annulus, ``face_quadrature = [n_r, n_theta]`` (Gauss
    radii times equal angles, :func:`drivedyn.fe.annulus_quadrature`), or at every node of
    the face mesh with ``"nodes"``. The default ``[2, 6]`` (24 points against 240 nodes)
    gives the Type C bench's four TDRs within 0.012 % of the node sums extrapolated to a
    fine mesh, the node sums of the default mesh 0.1-0.25 % below them. Two radii per
    radial cell resolve the radial pressure (one radius: the largest von Mises stress 11 %
    low); six angles integrate exactly every product of the face's fields up to the fifth
    harmonic (a tilt times a tilt is the second: a tilted face in full contact gives the
    stress of 36 angles within 1e-11, 3 angles +4.8 %), and on both benches the washers'
    load is axisymmetric but for a tilt: the TDRs, largest pressures and stresses of 6 and
    24 angles agree within 1e-5 (``docs/flexible.md``). Each washer keeps ``washer_modes``
    fixed-interface modes and the static modes of its face loads: the four normal pressure
    patterns and ``friction_patterns`` circumferential friction patterns (1: the friction of
    the mean pressure, the torque the friction puts through the washer; 4: exact for the
    friction of a tilted or conical pressure as well, 3 more coordinates per washer; 0: the
    friction does not deform the washer, see :func:`drivedyn.fe.face_load_patterns`)."""

    washers: bool = False
    washer_thickness: PositiveLength = 2e-3
    washer_modes: int = Field(default=2, ge=0, le=60)
    washer_cells: tuple[int, int] = (2, 24)  # across the width, around
    friction_patterns: Literal[0, 1, 4] = 1
    face_quadrature: tuple[int, int] | Literal["nodes"] = (2, 6)  # radii, angles
    youngs_modulus: Modulus = 210e9
    poisson_ratio: float = Field(default=0.3, gt=-1.0, lt=0.5)
    density: Annotated[float, scalar(U.DENSITY, positive=True)] = 7850.0

    @model_validator(mode="after")
    def _washer_cells(self) -> FlexibleWashers:
        nr, nt = self.washer_cells
        if nr < 1 or nt < 6:
            raise ValueError(f"washer_cells = {[nr, nt]}: expected [n_r >= 1, n_theta >= 6]")
        if self.face_quadrature != "nodes":
            qr, qt = self.face_quadrature
            if qr < 1 or qt < 3 or nt % qt:
                raise ValueError(f"face_quadrature = {[qr, qt]}: expected \"nodes\" or "
                                 "[n_r >= 1 radii, n_theta >= 3 angles] with n_theta dividing "
                                 f"washer_cells[1] = {nt} (the points on the mesh's vertex "
                                 "radii)")
        return self


class Body(Strict):
    mass: Mass
    inertia: Inertia


class Bench(Strict):
    """Test-bench protocol (seed 003): drive then coast in one run, steady windows."""

    torque: PositiveTorque = 125.0
    speed_diff: PositiveAngularVelocity = 2.0943951023931953
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
    it for ``hold``, ramps to the next level, and so on (positive = drive in forward motion);
    ``speed_diff`` is the second-minus-first output speed [rad/s] of each level (Type C: rear
    minus front; Type B: right minus left); ``speed`` is the mean output speed (positive =
    forward, about +z). With ``backward = true`` the profile then reverses both output speeds
    over ``reversal`` (the last torque level held) and runs the same torque levels again in
    backwards motion with the speed differences negated (seed 003, second half of the Type B
    run): each level shows the mode of the same torque with the favoured side exchanged.
    ``h_max`` caps the step of this run: the turning gears excite the meshes, and long steps
    cost Newton failures and leave numerical oscillations in the held torques. ``atol_rot``
    [rad], if given, replaces ``solver.step.atol_rot`` in this run: a tolerance measured on
    the bench need not hold in the vehicle (parts whose pockets turn with the housing). ``rho_inf``,
    if given, replaces ``solver.rho_inf`` in this run: more numerical damping of what rings
    above the step's resolution (gear meshes, washer and pocket contacts at each tip-in)."""

    speed: AngularVelocity = 30.0
    torque_levels: list[float] = Field(default_factory=lambda: [
        60.0, 125.0, 60.0, -60.0, -125.0, -60.0, 60.0, 125.0, 60.0, -60.0, -125.0, -60.0])
    speed_diff: list[float] = Field(default_factory=lambda: [
        -2.0, -2.0, -2.0, -2.0, -2.0, -2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0])
    hold: PositiveTime = 0.6
    ramp: PositiveTime = 0.25
    backward: bool = False
    reversal: PositiveTime = 0.5
    h_max: PositiveTime = 2e-4
    atol_rot: Annotated[float, scalar(U.ANGLE, positive=True)] | None = None
    rho_inf: float | None = Field(default=None, ge=0.0, le=1.0)

    @model_validator(mode="after")
    def _levels(self) -> Vehicle:
        if len(self.torque_levels) != len(self.speed_diff) or not self.torque_levels:
            raise ValueError(f"torque_levels ({len(self.torque_levels)} values) and speed_diff "
                             f"({len(self.speed_diff)} values) must have the same length >= 1")
        return self


class Solver(Strict):
    rho_inf: float = Field(default=0.8, ge=0.0, le=1.0)
    step: AdaptiveStepFile = Field(default_factory=lambda: AdaptiveStepFile(
        mode="adaptive", h0=1e-4, h_min=1e-9, h_max=2e-3, rtol=1e-3, atol=1e-6))
    newton: NewtonFile = Field(default_factory=NewtonFile)
    output_dt: PositiveTime = 5e-3

    def settings(self, h_max: float | None = None, atol_rot: float | None = None,
                 rho_inf: float | None = None) -> dict:
        """``integrator``, ``step`` and ``newton`` arguments of ``simulate``; ``h_max`` [s]
        caps the largest step, ``atol_rot`` [rad] replaces the step's rotation tolerance and
        ``rho_inf`` the integrator's (the vehicle run)."""
        from drivedyn.solver.settings import AdaptiveStep, GeneralizedAlpha, Newton

        st, nw = self.step, self.newton
        hm = st.h_max if h_max is None else min(st.h_max, h_max)
        return {"integrator": GeneralizedAlpha(self.rho_inf if rho_inf is None else rho_inf),
                "step": AdaptiveStep(st.h0, st.h_min, hm, st.rtol, st.atol,
                                     atol_rot=st.atol_rot if atol_rot is None else atol_rot),
                "newton": Newton(nw.strategy, nw.tol, nw.phi_tol, nw.max_iter)}


class Calibration(Strict):
    """What may be fitted, within which ranges, and what was fitted to what (the record is
    written by ``drivedyn calibrate``).

    Inputs: ``bounds`` gives the physical range ``[low, high]`` of each friction
    coefficient that may be fitted (dotted key -> range), with its source in
    ``bounds_source``; ``uncertainty`` is the relative uncertainty of a measured TDR (0.03:
    +-3 %; its source in ``uncertainty_source``), used for the cost profile and the spread.

    Record: ``fitted`` lists the dotted keys whose values were fitted; ``tied`` groups keys
    that share one fitted value (one group per fitted number); ``left_out_together`` the
    modes the model cannot tell apart (one distinct measurement each); ``cross_validation``
    the error [%] of each mode's prediction by a fit without its distinct measurement (NaN:
    too few distinct measurements left); ``profile`` the range of each fitted number where
    the chi-square rises by less than 1; ``spread`` the range of each fitted number and
    predicted TDR with the measurements scaled by 1 +- uncertainty. A number the fit could not
    compute is kept as NaN."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=True)

    bounds: dict[str, list[float]] = Field(default_factory=dict)
    bounds_source: str = ""
    uncertainty: float = Field(default=0.03, gt=0.0, le=0.5)
    uncertainty_source: str = ""
    fitted: list[str] = Field(default_factory=list)
    tied: list[list[str]] = Field(default_factory=list)
    targets: dict[str, float] = Field(default_factory=dict)
    source: str = ""
    command: str = ""
    method: str = ""
    result: dict[str, float] = Field(default_factory=dict)
    left_out_together: list[list[int]] = Field(default_factory=list)
    cross_validation: dict[str, float] = Field(default_factory=dict)
    profile: dict[str, list[float]] = Field(default_factory=dict)
    spread: dict[str, list[float]] = Field(default_factory=dict)

    @field_validator("bounds")
    @classmethod
    def _ranges(cls, v: dict[str, list[float]]) -> dict[str, list[float]]:
        for key, rng in v.items():
            if not key.endswith("mu"):
                raise ValueError(f"{key!r}: bounds are for friction coefficients (keys ending "
                                 "in 'mu')")
            if (len(rng) != 2 or not all(math.isfinite(x) for x in rng)
                    or not 0.0 <= rng[0] < rng[1] <= 1.0):
                raise ValueError(f"{key} = {rng!r}: expected [low, high] with "
                                 "0 <= low < high <= 1")
        return v


class Experiment(Strict):
    """Measured TDR of the four modes and the seeds' simulated values (seed 003, Table 1):
    ``{mode1 = 4.02, ...}``, keys ``mode1`` to ``mode4``, ratios > 0."""

    tdr: dict[str, float] = Field(default_factory=dict)
    seeds: dict[str, float] = Field(default_factory=dict)
    source: str = ""

    @field_validator("tdr", "seeds")
    @classmethod
    def _modes(cls, v: dict[str, float]) -> dict[str, float]:
        for key, ratio in v.items():
            if key not in MODE_KEYS:
                raise ValueError(f"{key!r}: expected one of {', '.join(MODE_KEYS)}")
            if not ratio > 0.0:
                raise ValueError(f"{key} = {ratio!r}: a torque ratio, expected > 0")
        return v


#: keys of the per-mode tables
MODE_KEYS = ("mode1", "mode2", "mode3", "mode4")


class Scenario(Strict):
    """What ``drivedyn run`` simulates: the vehicle configuration, or the bench with the
    torque on output ``modes`` (an output name of the differential)."""

    kind: Literal["vehicle", "bench"] = "vehicle"
    modes: str | None = None


class Provenance(Strict):
    """Where each parameter comes from: dotted key (or section) -> ``"paper: ..."``,
    ``"literature: ..."``, ``"chosen: ..."`` or ``"fitted: ..."`` (printed by the docs)."""

    sources: dict[str, str] = Field(default_factory=dict)
