"""Figures of meshed flexible parts: contact pressure maps of flexible washers and
stress-coloured snapshots of deformed parts (from the field variables of
:mod:`drivedyn.results.flexible_fields`)."""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.figure import Figure


def _dataset(res: Any) -> Any:
    return getattr(res, "dataset", res)


def pressure_contacts(res: Any) -> list[str]:
    """Names of the flexible washer contacts of a run."""
    return sorted(str(k)[:-len(".face_points")] for k in _dataset(res).data_vars
                  if str(k).endswith(".face_points"))


def flexible_parts(res: Any) -> list[str]:
    """Names of the meshed flexible parts of a run."""
    return sorted(str(k)[:-len(".mesh_points")] for k in _dataset(res).data_vars
                  if str(k).endswith(".mesh_points"))


def _pick(names: list[str], name: str, kind: str) -> None:
    if name not in names:
        raise KeyError(f"{name!r} is not a {kind} of this run ({kind}s: "
                       f"{', '.join(names) or 'none'})")


def pressure_map_figure(res: Any, contact: str, time: float | None = None) -> Figure:
    """Contact pressure [MPa] of a flexible washer over its face at ``time`` (default: when
    the normal force is largest), and the history of the largest and mean pressure and of
    the pressure-weighted contact radius."""
    ds = _dataset(res)
    _pick(pressure_contacts(ds), contact, "flexible washer contact")
    t = ds["time"].values
    P = ds[f"{contact}.contact_pressure"].values
    F = ds[f"{contact}.normal_force"].values
    k = int(np.argmax(F)) if time is None else int(np.argmin(np.abs(t - time)))
    xy = ds[f"{contact}.face_points"].values[:, :2] * 1e3
    fig = Figure(figsize=(11, 4.6))
    a1 = fig.add_subplot(1, 2, 1)
    a2 = fig.add_subplot(1, 2, 2)
    import matplotlib.tri as mtri

    tri = mtri.Triangulation(xy[:, 0], xy[:, 1])
    # drop the triangles spanning the hole of the annulus (centroid inside the inner radius)
    c = xy[tri.triangles].mean(axis=1)
    tri.set_mask(np.hypot(c[:, 0], c[:, 1]) < np.hypot(xy[:, 0], xy[:, 1]).min())
    cs = a1.tricontourf(tri, P[k] * 1e-6, levels=20, cmap="viridis")
    fig.colorbar(cs, ax=a1, label="pressure [MPa]")
    a1.set_aspect("equal")
    a1.set_xlabel("x [mm]")
    a1.set_ylabel("y [mm]")
    a1.set_title(f"{contact}: pressure at t = {t[k]:.3f} s, F = {F[k]:.0f} N", fontsize="small")
    a2.plot(t, P.max(axis=1) * 1e-6, label="largest point pressure")
    a2.plot(t, ds[f"{contact}.pressure"].values * 1e-6, label="mean (F / S)")
    a2.set_xlabel("time [s]")
    a2.set_ylabel("pressure [MPa]")
    a2.grid(True, alpha=0.3)
    a2.legend(fontsize="small")
    a3 = a2.twinx()
    a3.plot(t, ds[f"{contact}.pressure_radius"].values * 1e3, "k--", lw=0.8,
            label="contact radius")
    a3.set_ylabel("pressure-weighted radius [mm]")
    fig.suptitle(f"flexible washer contact {contact}")
    fig.tight_layout()
    return fig


def part_stress_figure(res: Any, part: str, snapshots: int = 3, scale: float = 1.0) -> Figure:
    """Snapshots of the deformed part (displacement times ``scale``, host frame) coloured by
    the nodal von Mises stress, and the history of the largest von Mises stress."""
    ds = _dataset(res)
    _pick(flexible_parts(ds), part, "flexible part")
    t = ds["time"].values
    X = ds[f"{part}.mesh_points"].values
    from drivedyn.results.flexible_fields import displacement

    U = displacement(ds, part)
    vm = ds[f"{part}.von_mises"].values * 1e-6
    idx = np.unique(np.linspace(0, len(t) - 1, snapshots).round().astype(int))
    fig = Figure(figsize=(4.2 * len(idx) + 1, 8))
    vmax = float(vm.max()) or 1.0
    for j, k in enumerate(idx):
        ax = fig.add_subplot(2, len(idx), j + 1, projection="3d")
        P = (X + scale * U[k]) * 1e3
        sc = ax.scatter(P[:, 0], P[:, 1], P[:, 2], c=vm[k], s=4, cmap="inferno", vmin=0,
                        vmax=vmax)
        ax.set_title(f"t = {t[k]:.3f} s", fontsize="small")
        ax.set_xlabel("x [mm]", fontsize="x-small")
        ax.set_ylabel("y [mm]", fontsize="x-small")
        ax.set_zlabel("z [mm]", fontsize="x-small")
    fig.colorbar(sc, ax=fig.axes, shrink=0.5, label="von Mises [MPa]")
    a = fig.add_subplot(2, 1, 2)
    a.plot(t, vm.max(axis=1))
    a.set_xlabel("time [s]")
    a.set_ylabel("largest von Mises [MPa]")
    a.grid(True, alpha=0.3)
    fig.suptitle(f"{part}: deformed shape (x{scale:g}) and von Mises stress")
    return fig
