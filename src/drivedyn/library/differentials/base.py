"""What a differential model declares to the shared framework (bench, TDR, calibration,
vehicle configuration, CLI): one :class:`Differential` record per type.

A differential has a housing turning on ``housing_bearing`` (a hinge to the ground, marker
``b_housing`` on it) and two outputs, each on a bearing joint to the ground with a marker on
the output body where the bench applies its torque. The outputs are ordered (first, second);
speed differences are second minus first (Type C: front = sun, rear = coupling; Type B: left
and right side gears).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from fnmatch import fnmatchcase
from typing import Any


def matcher(patterns: tuple[str, ...]) -> Callable[[str], bool]:
    """``f(name) -> bool``: does an element name match one of the glob ``patterns``."""
    return lambda name: any(fnmatchcase(name, p) for p in patterns)


@dataclass(frozen=True)
class Output:
    """One output of a differential.

    Attributes:
        name: ``"front"``, ``"rear"``, ``"left"``, ``"right"``.
        body: the output body (its ``angular_velocity`` is the output speed).
        bearing: joint to the ground whose speed the bench and the vehicle prescribe.
        marker: marker on the body where the bench applies its torque.
        label: for tables and figures (``"front output (sun)"``).
    """

    name: str
    body: str
    bearing: str
    marker: str
    label: str


@dataclass(frozen=True)
class Mode:
    """A locking mode: number (1-4), name, favoured output (the bench's loaded output) and
    whether the torque drives (power from the housing to the outputs)."""

    number: int
    name: str
    side: str
    drive: bool


@dataclass(frozen=True)
class Differential:
    """The declaration of one differential type.

    Attributes:
        name: CLI name and name of the default model file (``"torsen-c"``).
        library: the ``[model] library`` key of its model files (``"torsen_c"``).
        title: human name.
        schema: pydantic class of the whole model file.
        outputs: (first, second) :class:`Output`.
        modes: the four locking modes; each bench side runs its drive then its coast mode.
        check: ``check(p)`` refuses impossible parameters (ModelError), returns the geometry.
        build: ``build(p, omega, friction_scale) -> (spec, geometry)``: the differential
            without loads or drivers, ``omega = (housing, first, second)`` initial speeds about
            +z [rad/s].
        housing_fixed_speeds: ``f(p, dw) -> (|w_first|, |w_second|)`` [rad/s]: output speeds
            with the housing held and the outputs differing by ``dw``.
        housing_speed: ``f(p, w_first, w_second) -> w_housing`` (kinematics, Willis).
        analytic_bench: ``f(p, mode, torque, speed_diff, friction_scale) -> TDR`` of the
            independent quasi-static model.
        analytic_vehicle: ``f(p, (w_h, w_first, w_second), housing_torque, friction_scale)
            -> (T_first, T_second)``: output torques delivered to the axles [N m].
        free: default calibration parameters; each entry is a tuple of dotted keys that share
            one fitted value.
        washers: names of the thrust-washer contacts, with figure labels.
        axial_bodies: (body, label) whose axial motion the vehicle figures show.
        mesh_elements: ``f(name) -> bool``: is this element a gear mesh (dissipation figure).
        pocket_elements: ``f(name) -> bool``: is this element a pocket contact.
        seed_coordinates: coordinates of the seeds' flexible bench model of this type (seed
            003: the Type C with four flexible washers, the Type B with three), 0 if none.
        element_groups: (label, glob patterns of element names) of the dissipative element
            groups other than the washers that the dashboard sums (``("pockets",
            ("*_pocket",))``, the gear meshes...).
    """

    name: str
    library: str
    title: str
    schema: type
    outputs: tuple[Output, Output]
    modes: tuple[Mode, ...]
    check: Callable[[Any], Any]
    build: Callable[..., tuple[Any, Any]]
    housing_fixed_speeds: Callable[[Any, float], tuple[float, float]]
    housing_speed: Callable[[Any, float, float], float]
    analytic_bench: Callable[..., float]
    analytic_vehicle: Callable[..., tuple[float, float]]
    free: tuple[tuple[str, ...], ...]
    washers: dict[str, str] = field(default_factory=dict)
    axial_bodies: tuple[tuple[str, str], ...] = ()
    mesh_elements: Callable[[str], bool] = lambda name: False
    pocket_elements: Callable[[str], bool] = lambda name: "_pocket" in name
    element_groups: tuple[tuple[str, tuple[str, ...]], ...] = ()
    seed_coordinates: int = 0

    def output(self, side: str) -> Output:
        """The output called ``side``."""
        for o in self.outputs:
            if o.name == side:
                return o
        raise KeyError(f"{self.name}: no output {side!r} (outputs: "
                       f"{', '.join(o.name for o in self.outputs)})")

    def other(self, side: str) -> Output:
        """The output that is not ``side``."""
        self.output(side)
        return next(o for o in self.outputs if o.name != side)

    @property
    def sides(self) -> tuple[str, ...]:
        """Output names in bench order (the side of mode 1 first)."""
        out: list[str] = []
        for m in self.modes:
            if m.side not in out:
                out.append(m.side)
        return tuple(out)

    @property
    def side_modes(self) -> dict[str, tuple[int, int]]:
        """side -> (drive mode, coast mode), in the order the bench runs them."""
        return {s: tuple(m.number for m in sorted(
            (m for m in self.modes if m.side == s), key=lambda m: not m.drive))
            for s in self.sides}

    def mode(self, number: int) -> Mode:
        """Mode ``number`` (1-4)."""
        for m in self.modes:
            if m.number == number:
                return m
        raise KeyError(f"{self.name}: no mode {number}")
