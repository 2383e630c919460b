"""Figures of a differential's vehicle configuration (seed 003, Fig. 10-13).

:func:`vehicle_figures` draws, from a :class:`~drivedyn.analysis.vehicle.VehicleRun` or its
:class:`~drivedyn.results.results.Results`, PNG files (Agg canvas, no display needed):

* ``vehicle_torques.png``: housing torque, the two output torques delivered to the axles and
  their sum; output and housing speeds below (Fig. 10, 13);
* ``vehicle_axial.png``: axial displacements of the gears [um] (Type C: sun, internal gear,
  coupling; Type B: side gears), with the torque reversals marked (Fig. 11);
* ``vehicle_washers.png``: normal force and mean pressure of the thrust washers;
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

from drivedyn.library import differentials
from drivedyn.library.differentials import Differential

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


def torques_figure(res: Any, diff: Differential) -> Figure:
    """Housing and output torques (top) and speeds (bottom), seed 003 Fig. 10 and 13."""
    t = res["time"].values
    th = res["engine_torque.torque_z"].values
    first, second = diff.outputs
    t1 = -res[f"{first.name}_speed.torque"].values
    t2 = -res[f"{second.name}_speed.torque"].values
    fig, (a1, a2) = _new(2, f"{diff.title}, vehicle: torque distribution")
    a1.plot(t, th, "k", lw=1.6, label="housing (engine)")
    a1.plot(t, t1, label=first.label)
    a1.plot(t, t2, label=second.label)
    a1.plot(t, t1 + t2, "k:", lw=1.0, label=f"{first.name} + {second.name}")
    _finish(a1, "torque [N m]")
    for o in diff.outputs:
        a2.plot(t, _z(res, f"{o.body}.angular_velocity"), label=f"{o.name} ({o.body})")
    a2.plot(t, _z(res, "housing.angular_velocity"), "k--", lw=1.0, label="housing")
    _finish(a2, "speed [rad/s]")
    return fig


def axial_figure(res: Any, diff: Differential) -> Figure:
    """Axial displacements of the gears [um] (seed 003 Fig. 11); torque reversals dotted;
    housing torque below for reference."""
    t = res["time"].values
    fig, (a1, a2) = _new(2, f"{diff.title}, vehicle: axial motion")
    for body, label in diff.axial_bodies:
        z = np.asarray(res[f"{body}.position"].values)[:, 2]
        a1.plot(t, (z - z[0]) * 1e6, label=label)
    for tr in _reversal_times(res):
        for ax in (a1, a2):
            ax.axvline(tr, color="0.5", ls=":", lw=0.8)
    _finish(a1, "axial displacement [um]")
    a2.plot(t, res["engine_torque.torque_z"].values, "k", label="housing torque")
    _finish(a2, "torque [N m]")
    return fig


def washers_figure(res: Any, diff: Differential) -> Figure:
    """Normal force (top) and mean pressure (bottom) of the thrust washers."""
    t = res["time"].values
    fig, (a1, a2) = _new(2, f"{diff.title}, vehicle: thrust washers")
    for w, label in diff.washers.items():
        a1.plot(t, res[f"{w}.normal_force"].values, label=label)
        a2.plot(t, res[f"{w}.pressure"].values * 1e-6, label=label)
    _finish(a1, "normal force [N]")
    _finish(a2, "mean pressure [MPa]")
    return fig


def dissipation_figure(res: Any, diff: Differential) -> Figure:
    """Dissipated power [W]: each washer, the pockets, the meshes and the total."""
    t = res["time"].values
    names = [n for n in res.names() if n.endswith("." + _DP)]
    element = [n[: -len(_DP) - 1] for n in names]
    pockets = [n for n, e in zip(names, element, strict=True) if diff.pocket_elements(e)]
    meshes = [n for n, e in zip(names, element, strict=True) if diff.mesh_elements(e)]
    fig, (a1,) = _new(1, f"{diff.title}, vehicle: dissipated power", height=4.5)
    for w, label in diff.washers.items():
        a1.plot(t, res[f"{w}.dissipated_power"].values, lw=1.0, label=label)
    a1.plot(t, _sum(res, pockets), lw=1.2, label="pockets")
    a1.plot(t, _sum(res, meshes), lw=1.2, label="gear meshes")
    a1.plot(t, _sum(res, names), "k", lw=1.6, label="total")
    _finish(a1, "dissipated power [W]")
    return fig


FIGURES: dict[str, Callable[[Any, Differential], Figure]] = {
    "vehicle_torques": torques_figure,
    "vehicle_axial": axial_figure,
    "vehicle_washers": washers_figure,
    "vehicle_dissipation": dissipation_figure,
}


def differential_of(run_or_results: Any) -> Differential:
    """The differential of a vehicle run (its parameters) or of results (by the output
    drivers they record)."""
    params = getattr(run_or_results, "params", None)
    if params is not None:
        return differentials.of(params)
    res = _results(run_or_results)
    for key in differentials.TYPES:
        diff = differentials.get(key)
        if all(f"{o.name}_speed.torque" in res for o in diff.outputs):
            return diff
    raise ValueError("vehicle_figures: these results are not a differential's vehicle run")


def vehicle_figures(run_or_results: Any, out_dir: str | Path,
                    diff: Differential | None = None) -> list[Path]:
    """Write the vehicle figures (PNG) of a run or its results into ``out_dir`` (created);
    returns the paths. ``diff``: the differential (default: from the run or the results)."""
    res = _results(run_or_results)
    diff = diff or differential_of(run_or_results)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, draw in FIGURES.items():
        path = out / f"{name}.png"
        draw(res, diff).savefig(path, dpi=110)
        paths.append(path)
    return paths
