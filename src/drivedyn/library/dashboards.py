"""What a library model declares about its run's figures: a :class:`Dashboard` of panels,
each a few curves computed from the run's variables (sums, differences, ratios), in data
only. ``drivedyn plot`` (:mod:`drivedyn.plots.dashboard`) draws any dashboard; the library
declares it without knowing matplotlib:

* a differential type: :func:`drivedyn.library.differentials.dashboard` (from the
  :class:`~drivedyn.library.differentials.base.Differential` record: its outputs, washers,
  axial bodies and element groups, and the scenario of the parameters);
* a vehicle: its package's ``dashboard(params)`` (e.g.
  :func:`drivedyn.library.vehicles.vehicle_4wd.dashboard`).

Variables are named as in the results file (``"sun.angular_velocity"``,
``"*_pocket.dissipated_power"``); a term whose pattern matches no variable of a run is left
out, and a curve left with no term is not drawn (a bench run has no engine torque).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal


@dataclass(frozen=True)
class Term:
    """``coefficient * variable[component]``, summed over every variable the glob
    ``pattern`` matches (or their largest value at each sample: ``reduce = "max"``).

    Attributes:
        pattern: variable name or glob pattern of variable names.
        component: index into the last dimension of vector variables (0, 1, 2 = x, y, z of a
            ``(time, xyz)`` variable); None for scalar variables.
        coefficient: factor (-1 for a sign change, e.g. torque delivered = minus the driver's
            torque).
        reduce: how the matched variables combine: ``"sum"``, or ``"max"`` (the largest of
            them at each sample: the peak stress over a frame's beam elements).
    """

    pattern: str
    component: int | None = None
    coefficient: float = 1.0
    reduce: Literal["sum", "max"] = "sum"


@dataclass(frozen=True)
class Curve:
    """One line of a panel.

    Attributes:
        label: legend text.
        terms: the line is the sum of these terms (a difference: coefficients +1 and -1).
        over: denominator terms (summed): the line is ``sum(terms) / sum(over)``, NaN where
            ``|sum(over)|`` is below 5 % of its largest magnitude (a share of nothing).
        ratio: ``"plain"``: the quotient as is; ``"magnitude"``: its magnitude;
            ``"larger_over_smaller"``: the larger of the magnitudes of the numerator and the
            denominator over the smaller one (a torque distribution ratio whichever side is
            favoured).
        relative: draw the change since the first sample (displacements).
        style: matplotlib format string (``"k--"``), empty for the next colour.
    """

    label: str
    terms: tuple[Term, ...]
    over: tuple[Term, ...] = ()
    ratio: Literal["plain", "magnitude", "larger_over_smaller"] = "plain"
    relative: bool = False
    style: str = ""


@dataclass(frozen=True)
class Window:
    """A time window [s] to mark on a panel, e.g. where the TDR of a mode is measured.

    Attributes:
        t0, t1: start and end [s].
        label: what the window is (``"mode 1"``).
        reference: a value to mark in the window (the measured TDR), None for none.
    """

    t0: float
    t1: float
    label: str = ""
    reference: float | None = None


@dataclass(frozen=True)
class Abscissa:
    """What a panel's curves are drawn against instead of time (a path: y against x).

    Attributes:
        quantity: x-axis name, short (``"x"``).
        unit: SI unit of the values (``"m"``).
        curve: the values (its label names them in the axis label).
    """

    quantity: str
    unit: str
    curve: Curve


@dataclass(frozen=True)
class Panel:
    """One small plot: curves sharing a unit.

    Attributes:
        title: panel title (``"output torques"``).
        quantity: y-axis name, short (``"torque"``).
        unit: SI unit of the curves (``"N m"``, ``"rad/s"``, ``"m"``, ``"1"``).
        curves: the lines.
        display: preferred display unit (``"rpm"``, ``"%"``, ``"deg"``); None: SI prefix by
            magnitude (:func:`drivedyn.plots.units.display_scale`).
        windows: time windows to shade; a panel with windows also draws each curve's window
            mean (ratio curves: ratio of the window means) and the windows' references.
        note: one line under the title (what is shown when something could not be).
        abscissa: draw the curves against this instead of time (the start marked with a
            dot; windows are not drawn on such a panel).
    """

    title: str
    quantity: str
    unit: str
    curves: tuple[Curve, ...]
    display: str | None = None
    windows: tuple[Window, ...] = ()
    note: str = ""
    abscissa: Abscissa | None = None


@dataclass(frozen=True)
class Page:
    """One figure of a dashboard: a title and its panels (drawn in a grid)."""

    title: str
    panels: tuple[Panel, ...]


@dataclass(frozen=True)
class Dashboard:
    """The figures a library model contributes to ``drivedyn plot``.

    Attributes:
        name: file stem of its figures (``"dashboard_torsen_c"``).
        title: human title (``"TORSEN Type C, vehicle configuration"``).
        pages: the figures.
    """

    name: str
    title: str
    pages: tuple[Page, ...]
