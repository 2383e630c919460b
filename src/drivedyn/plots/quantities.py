"""What ``drivedyn plot`` draws from a results file: the engineering quantities of each body
and element, grouped into figures and panels, with their display units.

:func:`plot_quantities` returns one :class:`PlotQuantity` per line to draw; the figures of
:mod:`drivedyn.plots.engineering` draw exactly these. The choices (``docs/plots.md``):

* bodies (and nodes): displacement of the centre from its start position, one panel per
  global component, only components that move (more than :data:`MOVE_FLOOR`); angular
  velocity about each body's dominant axis, the other components only above
  :data:`SIGNIFICANT` of it. Rotation matrices, velocities and momenta are not drawn.
* joints and drivers: the joint angle, unwrapped, and the relative speed (its time
  derivative); reaction or driver forces and torques, components below :data:`SIGNIFICANT`
  of the element's largest left out; the power of driven rows.
* contacts: gap, normal force, mean pressure, friction torque or force, dissipated power;
  gear pairs: normal force, torques on both wheels, deflection, approach, dissipated power;
  springs, tyres, beams and loads: their forces, deflections, stresses and powers
  (:data:`CATEGORY_QUANTITIES`); other families: their outputs that have a unit.
* the energy budget (kinetic, potential, work in, dissipated), the balance error, and the
  total dissipated power with its largest contributors.

Quantities identically zero or constant are not drawn (constant ones are written in the
panel's note); a panel shows at most :data:`MAX_LINES` lines, the largest. Units:
:func:`drivedyn.plots.units.display_scale` per panel (one unit per panel); angular speeds in
rpm when a part in the panel rotates (:func:`~drivedyn.plots.units.rotating`).
"""

from __future__ import annotations

import fnmatch
import re
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from drivedyn.plots.units import display_scale, peak, rotating

#: displacements [m] and angular speeds [rad/s] below these peaks count as no motion
MOVE_FLOOR = 1e-12
SPIN_FLOOR = 1e-9
#: quantities in these units whose peak stays below the floor are round-off, not drawn
FLOORS = {"m": MOVE_FLOOR, "rad": 1e-9, "rad/s": SPIN_FLOOR}
#: secondary components (angular velocity, force and torque components) smaller than this
#: fraction of the element's largest component are left out
SIGNIFICANT = 0.01
#: force and torque components below this fraction of the run's largest force or torque are
#: round-off (the reaction torques of a planar mechanism's spherical joints)
NOISE = 1e-6
#: most lines per panel (the largest), panels per figure, figures
MAX_LINES = 8
MAX_PANELS = 9
MAX_FIGURES = 12
XYZ = ("x", "y", "z")

#: quantities drawn per category, in panel order (``*``: the components ``_x``, ``_y``, ``_z``)
CATEGORY_QUANTITIES: dict[str, tuple[str, ...]] = {
    "joints": ("angle", "force_*", "torque_*", "power"),
    "drivers and loads": ("torque", "force", "angle", "torque_*", "force_*", "power"),
    "springs": ("force", "torque", "length", "angle", "dissipated_power"),
    "contacts": ("gap", "normal_force", "pressure", "friction_torque", "friction_force",
                 "dissipated_power"),
    "gear meshes": ("normal_force", "torque_a", "torque_b", "deflection", "approach",
                    "dissipated_power"),
    "tyres": ("fx", "fy", "fz", "kappa", "alpha", "dissipated_power"),
    "beams": ("von_mises", "normal_stress", "shear_stress", "axial_force", "torque",
              "bending_moment_y", "bending_moment_z", "shear_force_y", "shear_force_z"),
}
#: never drawn by default (counters, switches, internal states, integrals drawn elsewhere)
SKIPPED = frozenset({"dissipated_energy", "impacts", "in_contact", "impact_speed",
                     "rebound_speed", "friction_coefficient", "stiffness", "angle_a", "angle_b",
                     "rotation", "angular_momentum", "velocity"})
#: panel titles of quantity names (others: the name with spaces)
TITLES = {
    "angle": "angle (unwrapped)", "speed": "relative speed (d angle / dt)",
    "force_*": "force components (global)", "torque_*": "torque components (global)",
    "torque": "torque about the axis", "force": "force along the axis",
    "power": "power supplied", "gap": "gap (< 0: penetration)", "normal_force": "normal force",
    "pressure": "mean pressure", "dissipated_power": "dissipated power",
    "torque_a": "torque on wheel A", "torque_b": "torque on wheel B",
    "deflection": "mesh deflection", "approach": "drive-flank approach",
    "fx": "longitudinal force", "fy": "lateral force", "fz": "vertical load",
    "kappa": "longitudinal slip", "alpha": "slip angle", "length": "length change",
    "von_mises": "von Mises stress (outer fibre)", "normal_stress": "normal stress (outer fibre)",
    "shear_stress": "shear stress (outer fibre)",
}
#: short y-axis names of quantity names
SHORT = {"force_*": "force", "torque_*": "torque", "normal_force": "force",
         "friction_torque": "torque", "friction_force": "force", "dissipated_power": "power",
         "torque_a": "torque", "torque_b": "torque", "fx": "force", "fy": "force", "fz": "force",
         "kappa": "slip", "alpha": "angle", "angular_momentum": "momentum", "length": "change",
         "deflection": "deflection", "von_mises": "stress", "normal_stress": "stress",
         "shear_stress": "stress", "axial_force": "force", "shear_force_y": "force",
         "shear_force_z": "force", "bending_moment_y": "moment", "bending_moment_z": "moment"}
_FAMILY = re.compile(r"\((\w+)\)\s*$")


@dataclass
class PlotQuantity:
    """One line of a figure.

    Attributes:
        figure: figure title (``"bodies"``, ``"joints"``, ``"energy"``...).
        panel: panel title (``"displacement z (from the start)"``).
        quantity: short y-axis name (``"displacement"``).
        label: legend text (``"sun z"``).
        variable: the results variable (or glob of the summed variables).
        component: index into its last dimension, None for a scalar variable.
        transform: ``""`` (as recorded), ``"displacement"`` (change since the first sample),
            ``"unwrap"`` (angle, 2 pi jumps removed), ``"speed"`` (time derivative of the
            unwrapped angle) or ``"sum"`` (sum of the variables ``variable`` matches).
        unit: SI unit of ``values``.
        display_unit: unit of the drawn values.
        scale: drawn values = ``scale * values``.
        note: a remark on the panel (lines left out, constant values), shared by its lines.
        values: the values [``unit``], one per output time.
        constant: the values do not vary (such a line is reported in the panel's note and
            not drawn; internal).
    """

    figure: str
    panel: str
    quantity: str
    label: str
    variable: str
    component: int | None
    transform: str
    unit: str
    display_unit: str = ""
    scale: float = 1.0
    note: str = ""
    values: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False, compare=False)
    constant: bool = field(default=False, repr=False)

    def as_dict(self) -> dict[str, Any]:
        """The description without the values."""
        return {k: getattr(self, k) for k in ("figure", "panel", "quantity", "label",
                                               "variable", "component", "transform", "unit",
                                               "display_unit", "scale", "note")}


def _varies(v: np.ndarray) -> bool:
    """Not constant (zero included), NaN ignored."""
    f = v[np.isfinite(v)]
    return f.size > 1 and float(np.ptp(f)) > 1e-9 * peak(f)


def _family(ds: Any, names: Iterable[str]) -> str:
    for n in names:
        m = _FAMILY.search(str(ds.variables[n].attrs.get("description", "")))
        if m:
            return m.group(1)
    return ""


def category(family: str, quantities: set[str]) -> str:
    """Figure of an element of ``family`` recording ``quantities``."""
    if {"force_x", "torque_x", "angle"} <= quantities:
        return "joints"
    if "driver" in family or family in ("torque", "force"):
        return "drivers and loads"
    if "spring" in family or family == "bump_stop":
        return "springs"
    if family == "gear_pair" or "torque_a" in quantities:
        return "gear meshes"
    if family == "tyre":
        return "tyres"
    if family == "beam":
        return "beams"
    if "contact" in family or family == "squeeze_film":
        return "contacts: " + family.replace("_", " ").removesuffix(" contact")
    return family.replace("_", " ") or "other"


def unwrap(angle: np.ndarray, accumulated: bool) -> np.ndarray:
    """An angle [rad] without 2 pi jumps: unchanged when the recorder accumulated it (an
    accumulated angle may advance by more than pi between samples), else unwrapped when it
    lies within [-pi, pi] and jumps."""
    a = np.asarray(angle, dtype=float)
    if accumulated or a.size < 2 or peak(a) > np.pi + 1e-9:
        return a
    if np.nanmax(np.abs(np.diff(a))) <= np.pi:
        return a
    return np.unwrap(a)


def _rate(t: np.ndarray, a: np.ndarray) -> np.ndarray | None:
    if len(t) < 2 or not np.all(np.diff(t) > 0):
        return None
    return np.gradient(a, t, edge_order=2 if len(t) > 2 else 1)


def _line(figure: str, key: str, label: str, var: str, comp: int | None, transform: str,
          unit: str, values: np.ndarray, title: str | None = None) -> PlotQuantity:
    return PlotQuantity(figure, title or TITLES.get(key, key.replace("_", " ")),
                        SHORT.get(key, key.split("_")[0]), label, var, comp, transform, unit,
                        values=np.asarray(values, dtype=float))


def _body_lines(ds: Any, body: str, figure: str, explicit: bool) -> list[PlotQuantity]:
    out = []
    pos = f"{body}.position"
    if pos in ds:
        X = np.asarray(ds.variables[pos].values, dtype=float)
        D = X - X[:1]
        for j in range(3):
            if explicit or peak(D[:, j]) > MOVE_FLOOR:
                out.append(_line(figure, "displacement", f"{body} {XYZ[j]}", pos, j,
                                 "displacement", "m", D[:, j],
                                 f"displacement {XYZ[j]} (from the start)"))
    om = f"{body}.angular_velocity"
    if om in ds:
        W = np.asarray(ds.variables[om].values, dtype=float)
        peaks = [peak(W[:, j]) for j in range(3)]
        k = int(np.argmax(peaks))
        for j in range(3):
            dominant = j == k
            if not explicit and (peaks[j] <= SPIN_FLOOR or (
                    not dominant and peaks[j] < SIGNIFICANT * peaks[k])):
                continue
            q = _line(figure, "speed", f"{body} ({XYZ[j]})", om, j, "", "rad/s", W[:, j],
                      "angular velocity about the spin axis" if dominant
                      else "angular velocity, other components")
            q.quantity = "speed"
            out.append(q)
    for name in ("velocity", "angular_momentum") if explicit else ():
        var = f"{body}.{name}"
        if var in ds:
            V = np.asarray(ds.variables[var].values, dtype=float)
            out += [_line(figure, name, f"{body} {XYZ[j]}", var, j, "",
                          str(ds.variables[var].attrs.get("units", "")), V[:, j]) for j in range(3)]
    return _mark_constant(out, explicit)


def _mark_constant(lines: list[PlotQuantity], explicit: bool = False) -> list[PlotQuantity]:
    """Drop the lines identically zero or below :data:`FLOORS`, flag the other constant ones
    (reported in notes). ``explicit`` (``--vars``): flag them all, drop none (a panel of
    constant lines only is then drawn)."""
    out = []
    for q in lines:
        if peak(q.values) <= FLOORS.get(q.unit, 0.0) and not explicit:
            continue
        if not _varies(q.values) or peak(q.values) <= FLOORS.get(q.unit, 0.0):
            q.constant = True
        out.append(q)
    return out


def _element_lines(ds: Any, el: str, quantities: dict[str, str], figure: str,
                   wanted: tuple[str, ...] | None) -> list[PlotQuantity]:
    """Lines of one element; ``wanted``: the category's quantities (None: every recorded
    one, as ``--vars`` selects them)."""
    t = ds["time"].values
    order = list(wanted) if wanted is not None else sorted(
        {re.sub(r"_[xyz]$", "_*", q) for q in quantities}, key=lambda q: q != "angle")
    out: list[PlotQuantity] = []
    for key in order:
        if key.endswith("_*"):
            base = key[:-2]
            comps = [(j, f"{base}_{c}") for j, c in enumerate(XYZ) if f"{base}_{c}" in quantities]
            vals = {j: np.asarray(ds.variables[quantities[q]].values, dtype=float)
                    for j, q in comps}
            top = max((peak(v) for v in vals.values()), default=0.0)
            for j, q in comps:
                if wanted is None or peak(vals[j]) >= SIGNIFICANT * top:
                    unit = str(ds.variables[quantities[q]].attrs.get("units", ""))
                    out.append(_line(figure, key, f"{el} {XYZ[j]}", quantities[q], None, "",
                                     unit, vals[j]))
            continue
        if key not in quantities or (wanted is not None and key in SKIPPED):
            continue
        var = quantities[key]
        v = np.asarray(ds.variables[var].values, dtype=float)
        unit = str(ds.variables[var].attrs.get("units", ""))
        if v.ndim == 2:  # a vector output of an element
            out += [_line(figure, key, f"{el} {j}", var, j, "", unit, v[:, j])
                    for j in range(v.shape[1])]
            continue
        if key == "length":
            out.append(_line(figure, key, el, var, None, "displacement", unit, v - v[:1]))
        elif key == "angle" and unit == "rad":
            acc = "accumulated" in str(ds.variables[var].attrs.get("description", ""))
            a = unwrap(v, acc)
            out.append(_line(figure, key, el, var, None, "unwrap", unit, a))
            w = _rate(t, a)
            if w is not None:
                out.append(_line(figure, "speed", el, var, None, "speed", "rad/s", w))
        else:
            out.append(_line(figure, key, el, var, None, "", unit, v))
    return _mark_constant(out, explicit=wanted is None)


def _energy_lines(ds: Any, explicit: bool, selected: set[str]) -> list[PlotQuantity]:
    out = []
    budget = "energy budget: T - T0 + V - V0 = W_in - D"
    for term, label in (("kinetic", "kinetic T - T0"), ("potential", "potential V - V0"),
                        ("work_in", "work in W_in"), ("dissipated", "dissipated D"),
                        ("work_loads", "work of loads"), ("work_drivers", "work of drivers"),
                        ("balance_error", "balance error")):
        var = f"energy.{term}"
        if var not in selected or (not explicit and term in ("work_loads", "work_drivers")):
            continue
        v = np.asarray(ds.variables[var].values, dtype=float)
        if term in ("kinetic", "potential"):  # the budget is about changes
            out.append(_line("energy", "energy", label, var, None, "displacement", "J",
                             v - v[:1], budget))
        elif term == "balance_error":
            q = _line("energy", "energy", label, var, None, "", "J", v,
                      "energy balance error T + V - T0 - V0 - W_in + D")
            q.quantity = "error"
            ref = max((peak(ds.variables[f"energy.{k}"].values) for k in
                       ("kinetic", "potential", "work_in", "dissipated")
                       if f"energy.{k}" in ds), default=0.0)
            if ref > 0:
                q.note = (f"largest |error| {peak(v):.3g} J = {100 * peak(v) / ref:.2g} % of "
                          "the largest energy term")
            out.append(q)
        else:
            out.append(_line("energy", "energy", label, var, None, "", "J", v, budget))
    if explicit:
        return out
    out = [q for q in out if q.label == "balance error" or _varies(q.values)]
    powers = [n for n in selected if n.endswith(".dissipated_power")]
    if powers:
        t = ds["time"].values
        total = sum((np.asarray(ds.variables[n].values, dtype=float) for n in powers),
                    np.zeros(len(t)))
        if _varies(total):
            title = "dissipated power: total and largest contributors"
            out.append(_line("energy", "power", "total", "*.dissipated_power", None, "sum", "W",
                             total, title))
            work = {n: float(np.trapezoid(np.nan_to_num(ds.variables[n].values), t)) if len(t) > 1
                    else 0.0 for n in powers}
            top = sorted((n for n in powers if work[n] > 0), key=lambda n: -work[n])
            out += [_line("energy", "power", n.rsplit(".", 1)[0], n, None, "", "W",
                          ds.variables[n].values, title) for n in top[:5]]
    return out


def _panel_order(figure: str) -> list[str]:
    """Panel titles of a figure in drawing order (others after them, as they come)."""
    if figure in ("bodies", "nodes"):
        return [*(f"displacement {c} (from the start)" for c in XYZ),
                "angular velocity about the spin axis", "angular velocity, other components"]
    keys: list[str] = []
    for k in CATEGORY_QUANTITIES.get(figure.split(":")[0], ()):
        keys += [k, "speed"] if k == "angle" else [k]
    return [TITLES.get(k, k.replace("_", " ")) for k in keys]


def _time_histories(ds: Any, patterns: tuple[str, ...]) -> list[str]:
    nt = ds.sizes.get("time", 0)
    names = []
    for n in ds.data_vars:
        v = ds.variables[n]
        n = str(n)
        if (n.startswith("solver.") or not v.dims or v.dims[0] != "time" or v.ndim > 2
                or v.size > 16 * max(nt, 1) or n.endswith(".rotation")):
            continue
        if patterns and not any(fnmatch.fnmatchcase(n, p) for p in patterns):
            continue
        names.append(n)
    return names


def _finish_panels(lines: list[PlotQuantity], t: np.ndarray, explicit: bool
                   ) -> list[PlotQuantity]:
    """Keep the largest lines of each panel and choose its display unit."""
    out: list[PlotQuantity] = []
    panels: dict[tuple[str, str], list[PlotQuantity]] = {}
    for q in lines:
        panels.setdefault((q.figure, q.panel), []).append(q)
    for group in panels.values():
        units = {q.unit for q in group}
        if len(units) > 1:  # a name shared by different quantities: one panel per unit
            for u in sorted(units):
                out += _finish_panels([replace(q, panel=f"{q.panel} [{u}]") for q in group
                                       if q.unit == u], t, explicit)
            continue
        drawn = [q for q in group if not q.constant]
        if not drawn and explicit:  # asked for: drawn even if constant
            group = [replace(q, constant=False) for q in group]
            drawn = group
        if not drawn:
            continue
        keep = drawn if explicit and len(drawn) <= 2 * MAX_LINES else sorted(
            drawn, key=lambda q: -peak(q.values))[:MAX_LINES]
        keep = [q for q in drawn if any(q is k for k in keep)]
        unit = group[0].unit
        prefer = ("rpm" if unit == "rad/s" and any(rotating(q.values, t) for q in group)
                  else None)
        scale, shown = display_scale(np.concatenate([q.values for q in keep]), unit, prefer)
        notes = list(dict.fromkeys(q.note for q in keep if q.note))
        if len(keep) < len(drawn):
            notes.append(f"the {len(keep)} largest of {len(drawn)} shown")
        const = [f"{q.label} {scale * float(np.nanmean(q.values)):.4g}" for q in group
                 if q.constant]
        if const:
            notes.append(f"constant [{shown}]: " + ", ".join(const[:4])
                         + (f" and {len(const) - 4} more" if len(const) > 4 else ""))
        out += [replace(q, scale=scale, display_unit=shown, note="; ".join(notes))
                for q in keep]
    return out


def _drop_noise(lines: list[PlotQuantity]) -> list[PlotQuantity]:
    """Leave out force and torque components below :data:`NOISE` times the largest force
    or torque of the run (reaction components that are zero up to round-off)."""
    top: dict[str, float] = {}
    for q in lines:
        top[q.unit] = max(top.get(q.unit, 0.0), peak(q.values))
    return [q for q in lines if q.panel not in (TITLES["force_*"], TITLES["torque_*"])
            or peak(q.values) >= NOISE * top[q.unit]]


def plot_quantities(ds: Any, patterns: tuple[str, ...] = ()) -> list[PlotQuantity]:
    """The lines ``drivedyn plot`` draws for a run's ``xarray.Dataset``, in figure and
    panel order (see the module doc).

    Args:
        ds: the results (``Results.dataset`` or a Dataset with the same variable names).
        patterns: glob patterns of variables (``--vars``): only these are drawn, each
            quantity they name (constant ones too, no category filter); rotation matrices
            are never drawn. Empty: the default choice.
    """
    explicit = bool(patterns)
    names = _time_histories(ds, patterns)
    selected = set(names)
    elements: dict[str, dict[str, str]] = {}
    for n in names:
        el, _, q = n.rpartition(".")
        elements.setdefault(el or n, {})[q] = n
    lines = _energy_lines(ds, explicit, selected) if "energy" in elements else []
    other: list[PlotQuantity] = []
    for el, qs in elements.items():
        if el in ("energy", "solver"):
            continue
        if "position" in qs or "angular_velocity" in qs:
            desc = str(ds.variables[qs.get("position", qs.get("angular_velocity"))].attrs.get(
                "description", ""))
            figure = "nodes" if "node origin" in desc else "bodies"
            other += _body_lines(ds, el, figure, explicit)
            continue
        recorded = {str(n).rpartition(".")[2] for n in ds.data_vars
                    if str(n).rpartition(".")[0] == el} if explicit else set(qs)
        figure = category(_family(ds, qs.values()), recorded)
        wanted = None if explicit else CATEGORY_QUANTITIES.get(figure.split(":")[0], ())
        if wanted == ():  # an element family without a curated list: its dimensional outputs
            wanted = tuple(q for q in qs if q not in SKIPPED
                           and ds.variables[qs[q]].attrs.get("units", "1") not in ("1", ""))
        other += _element_lines(ds, el, qs, figure, wanted)
    order = ["energy", "bodies", "nodes", "joints", "drivers and loads", "springs"]
    figures = list(dict.fromkeys(q.figure for q in other))
    figures.sort(key=lambda f: order.index(f) if f in order else len(order))
    for f in figures:
        mine = [q for q in other if q.figure == f]
        ranks = _panel_order(f)
        lines += sorted(mine, key=lambda q: ranks.index(q.panel) if q.panel in ranks
                        else len(ranks))
    if not explicit:
        lines = _drop_noise(lines)
    lines = _finish_panels(lines, ds["time"].values, explicit)
    keep_figures = list(dict.fromkeys(q.figure for q in lines))[:MAX_FIGURES]
    out = []
    for f in keep_figures:
        panels = list(dict.fromkeys(q.panel for q in lines if q.figure == f))[:MAX_PANELS]
        out += [q for q in lines if q.figure == f and q.panel in panels]
    return out


def figure_titles(quantities: list[PlotQuantity]) -> list[str]:
    """The figures of ``quantities`` in order."""
    return list(dict.fromkeys(q.figure for q in quantities))
