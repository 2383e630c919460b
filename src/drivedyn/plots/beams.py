"""Beam figures: the stress history of an element and snapshots of the deformed beams.

Both read a :class:`~drivedyn.results.results.Results` (or its dataset): the per-element
outputs ``{element}.von_mises`` etc. and the node positions; the topology comes from the
dataset attribute ``beam_elements`` (element -> [node_a, node_b]) the recorder writes.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
from matplotlib.figure import Figure

STRESSES = (("von_mises", "von Mises"), ("normal_stress", "normal (axial + bending)"),
            ("shear_stress", "shear (torsion + transverse)"))
SECTION = (("axial_force", "N", "N"), ("shear_force_y", "N", "V_y"),
           ("shear_force_z", "N", "V_z"), ("torque", "N m", "T"),
           ("bending_moment_y", "N m", "M_y"), ("bending_moment_z", "N m", "M_z"))


def _dataset(res: Any) -> Any:
    return getattr(res, "dataset", res)


def beam_elements(res: Any) -> dict[str, list[str]]:
    """Element -> [node_a, node_b] of every beam element of a run ({} if none)."""
    return json.loads(_dataset(res).attrs.get("beam_elements", "{}"))


def beam_stress_figure(res: Any, element: str) -> Figure:
    """Outer-fibre stresses [MPa] and section forces and moments of one beam element over
    time. ``KeyError`` naming the beam elements if ``element`` is not one."""
    ds = _dataset(res)
    elems = beam_elements(ds)
    if element not in elems:
        raise KeyError(f"{element!r} is not a beam element of this run (beam elements: "
                       f"{', '.join(elems) or 'none'})")
    t = ds["time"].values
    fig = Figure(figsize=(8, 7.5))
    ax1, ax2, ax3 = fig.subplots(3, 1, sharex=True)
    for key, label in STRESSES:
        ax1.plot(t, ds[f"{element}.{key}"].values / 1e6, label=label)
    ax1.set_ylabel("outer-fibre stress [MPa]")
    ax1.set_title(f"{element}: largest stresses on the outer fibre of the section",
                  fontsize="small")
    for key, unit, label in SECTION:
        ax = ax2 if unit == "N" else ax3
        ax.plot(t, ds[f"{element}.{key}"].values, label=label)
    ax2.set_ylabel("section force [N]")
    ax3.set_ylabel("section moment [N m]")
    ax3.set_xlabel("time [s]")
    for ax in (ax1, ax2, ax3):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small", ncol=3)
    fig.tight_layout()
    return fig


def beam_shape_figure(res: Any, times: Any = None, scale: float = 1.0,
                      snapshots: int = 4) -> Figure:
    """Snapshots of every beam (3-D), the displacement from the initial shape multiplied by
    ``scale``: ``x0 + scale (x(t) - x0)``; elements coloured by their von Mises stress [MPa].
    ``times`` [s] (default: ``snapshots`` instants spread over the run; each is drawn at the
    nearest output time)."""
    import matplotlib as mpl

    ds = _dataset(res)
    elems = beam_elements(ds)
    if not elems:
        raise KeyError("the run has no beam elements")
    if not (np.isfinite(scale) and scale > 0):
        raise ValueError(f"scale must be > 0, got {scale!r}")
    t = ds["time"].values
    if times is None:
        idx = np.unique(np.linspace(0, len(t) - 1, max(1, int(snapshots))).round().astype(int))
    else:
        idx = np.unique([int(np.argmin(np.abs(t - float(tt)))) for tt in np.atleast_1d(times)])
    nodes = sorted({n for ab in elems.values() for n in ab})
    X = {n: ds[f"{n}.position"].values for n in nodes}
    vm = np.array([ds[f"{e}.von_mises"].values[idx] for e in elems]) / 1e6  # (nel, nsnap)
    norm = mpl.colors.Normalize(vmin=0.0, vmax=max(float(np.nanmax(vm)), 1e-12))
    cmap = mpl.colormaps["viridis"]
    fig = Figure(figsize=(8, 6.5))
    ax = fig.add_subplot(111, projection="3d")
    pts = []
    for k, i in enumerate(idx):
        for j, (_e, (a, b)) in enumerate(elems.items()):
            pa = X[a][0] + scale * (X[a][i] - X[a][0])
            pb = X[b][0] + scale * (X[b][i] - X[b][0])
            ax.plot(*np.column_stack([pa, pb]), color=cmap(norm(vm[j, k])), lw=2.5)
            pts += [pa, pb]
        last = X[next(iter(elems.values()))[1]]
        tip = last[0] + scale * (last[i] - last[0])
        ax.text(*tip, f" t = {t[i]:.3g} s", fontsize="x-small")
    P = np.array(pts)
    c = 0.5 * (P.max(0) + P.min(0))
    r = 0.5 * max(float((P.max(0) - P.min(0)).max()), 1e-9)
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.set_title(f"deformed beams, displacements x {scale:g}", fontsize="small")
    sm = mpl.cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(sm, ax=ax, shrink=0.6, label="von Mises stress [MPa]")
    return fig
