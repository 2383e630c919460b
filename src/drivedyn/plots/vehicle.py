"""Figures of the TORSEN Type C vehicle configuration (seed 003, Fig. 10-11).

:func:`vehicle_figures` draws, from a :class:`~drivedyn.analysis.vehicle.VehicleRun` or its
:class:`~drivedyn.results.results.Results`, PNG files (Agg canvas, no display needed):

* ``vehicle_torques.png``: housing torque, the two output torques delivered to the axles and
  their sum; output and housing speeds below (Fig. 10);
* ``vehicle_axial.png``: axial displacements of sun, internal gear (ring) and coupling [um],
  with the torque reversals marked (Fig. 11);
* ``vehicle_washers.png``: normal force and mean pressure of the five thrust washers;
* ``vehicle_dissipation.png``: dissipated power of the washers, the pockets, the meshes and
  the total.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from drivedyn.library.torsen_c import WASHERS

WASHER_LABELS = {
    "sun_housing": "W1 sun - housing",
    "sun_coupling": "W2 sun - coupling",
    "coupling_case": "W3 coupling - case",
    "ring_housing": "W4 ring - housing",
    "ring_case": "W5 ring - case",
}


_DP = "dissipated_power"


def _results(run_or_results: Any) -> Any:
    res = getattr(run_or_results, "results", run_or_results)
    if res is None or "time" not in res.dataset.coords:
        raise ValueError("vehicle_figures: no results to plot")
    return res


def _z(res: Any, name: str) -> np.ndarray:
    """z component of a vector sensor."""
    return np.asarray(res[name].values)[:, 2]


def _sum(res: Any, names: list[str]) -> np.ndarray:
    t = res["time"].values
    return sum((np.asarray(res[n].values) for n in names if n in res), np.zeros_like(t))


def _reversal_times(res: Any) -> np.ndarray:
    """Times [s] at which the housing torque changes sign (linear interpolation)."""
    t = res["time"].values
    th = res["engine_torque.torque_z"].values
    nz = np.flatnonzero(np.abs(th) > 1e-9)
    out = []
    for i, j in itertools.pairwise(nz):
        if th[i] * th[j] < 0:
            out.append(t[i] + (t[j] - t[i]) * th[i] / (th[i] - th[j]))
    return np.array(out)


def _finish(ax: Any, ylabel: str, legend: bool = True) -> None:
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    if legend:
        ax.legend(fontsize="small", loc="best")


def _new(rows: int, title: str, height: float = 3.0) -> tuple[Figure, list[Any]]:
    fig = Figure(figsize=(9, height * rows + 0.8), layout="constrained")
    FigureCanvasAgg(fig)
    axes = list(fig.subplots(rows, 1, sharex=True, squeeze=False)[:, 0])
    fig.suptitle(title)
    axes[-1].set_xlabel("time [s]")
    return fig, axes


def torques_figure(res: Any) -> Figure:
    """Housing and output torques (top) and speeds (bottom), seed 003 Fig. 10."""
    t = res["time"].values
    th = res["engine_torque.torque_z"].values
    tf = -res["front_speed.torque"].values
    tr = -res["rear_speed.torque"].values
    fig, (a1, a2) = _new(2, "TORSEN C, vehicle: torque distribution")
    a1.plot(t, th, "k", lw=1.6, label="housing (engine)")
    a1.plot(t, tf, label="front output (sun)")
    a1.plot(t, tr, label="rear output (coupling)")
    a1.plot(t, tf + tr, "k:", lw=1.0, label="front + rear")
    _finish(a1, "torque [N m]")
    a2.plot(t, _z(res, "sun.angular_velocity"), label="front (sun)")
    a2.plot(t, _z(res, "coupling.angular_velocity"), label="rear (coupling)")
    a2.plot(t, _z(res, "housing.angular_velocity"), "k--", lw=1.0, label="housing")
    _finish(a2, "speed [rad/s]")
    return fig


def axial_figure(res: Any) -> Figure:
    """Axial displacements of sun, ring and coupling [um] (seed 003 Fig. 11); torque
    reversals dotted; housing torque below for reference."""
    t = res["time"].values
    fig, (a1, a2) = _new(2, "TORSEN C, vehicle: axial motion (front = -z)")
    for body, label in (("sun", "sun"), ("ring", "internal gear (ring)"),
                        ("coupling", "coupling")):
        z = np.asarray(res[f"{body}.position"].values)[:, 2]
        a1.plot(t, (z - z[0]) * 1e6, label=label)
    for tr in _reversal_times(res):
        for ax in (a1, a2):
            ax.axvline(tr, color="0.5", ls=":", lw=0.8)
    _finish(a1, "axial displacement [um]")
    a2.plot(t, res["engine_torque.torque_z"].values, "k", label="housing torque")
    _finish(a2, "torque [N m]")
    return fig


def washers_figure(res: Any) -> Figure:
    """Normal force (top) and mean pressure (bottom) of the five thrust washers."""
    t = res["time"].values
    fig, (a1, a2) = _new(2, "TORSEN C, vehicle: thrust washers")
    for w in WASHERS:
        a1.plot(t, res[f"{w}.normal_force"].values, label=WASHER_LABELS[w])
        a2.plot(t, res[f"{w}.pressure"].values * 1e-6, label=WASHER_LABELS[w])
    _finish(a1, "normal force [N]")
    _finish(a2, "mean pressure [MPa]")
    return fig


def dissipation_figure(res: Any) -> Figure:
    """Dissipated power [W]: each washer, the pockets, the meshes and the total."""
    t = res["time"].values
    names = [str(n) for n in res.dataset.data_vars if str(n).endswith("." + _DP)]
    pockets = [n for n in names if "_pocket." in n]
    meshes = [n for n in names if n.startswith("sun_planet") or n.endswith("_ring." + _DP)]
    fig, (a1,) = _new(1, "TORSEN C, vehicle: dissipated power", height=4.5)
    for w in WASHERS:
        a1.plot(t, res[f"{w}.dissipated_power"].values, lw=1.0, label=WASHER_LABELS[w])
    a1.plot(t, _sum(res, pockets), lw=1.2, label="planet pockets")
    a1.plot(t, _sum(res, meshes), lw=1.2, label="gear meshes")
    a1.plot(t, _sum(res, names), "k", lw=1.6, label="total")
    _finish(a1, "dissipated power [W]")
    return fig


FIGURES: dict[str, Callable[[Any], Figure]] = {
    "vehicle_torques": torques_figure,
    "vehicle_axial": axial_figure,
    "vehicle_washers": washers_figure,
    "vehicle_dissipation": dissipation_figure,
}


def vehicle_figures(run_or_results: Any, out_dir: str | Path) -> list[Path]:
    """Write the vehicle figures (PNG) of a run or its results into ``out_dir`` (created);
    returns the paths."""
    res = _results(run_or_results)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, draw in FIGURES.items():
        path = out / f"{name}.png"
        draw(res).savefig(path, dpi=110)
        paths.append(path)
    return paths
