"""Differentials on one framework: each type is a subpackage declaring a
:class:`~drivedyn.library.differentials.base.Differential` (builder, schema, default model
file, analytic TDR), and shares the bench protocol, the vehicle configuration
(:mod:`.scenarios`), the TDR evaluation and the calibration (:mod:`drivedyn.analysis`).

Adding a differential = one subpackage + one default model file + one line in
:data:`TYPES`; the CLI (``drivedyn tdr NAME``, ``drivedyn calibrate NAME``,
``drivedyn models``) finds it by name, and ``drivedyn plot`` draws its dashboard
(:func:`dashboard_of`, from the record's outputs, washers, axial bodies and element groups).
"""

from __future__ import annotations

import importlib
from typing import Any

from drivedyn.library.dashboards import Dashboard
from drivedyn.library.differentials.base import Differential, Mode, Output

#: library key -> module declaring ``DIFFERENTIAL`` (imported on first use)
TYPES = {
    "torsen_c": "drivedyn.library.differentials.torsen_c",
    "torsen_b": "drivedyn.library.differentials.torsen_b",
}


def get(name: str) -> Differential:
    """The differential of a library key (``"torsen_c"``) or model name (``"torsen-c"``)."""
    key = name.replace("-", "_")
    if key not in TYPES:
        raise KeyError(f"no differential {name!r} (known: "
                       f"{', '.join(k.replace('_', '-') for k in TYPES)})")
    return importlib.import_module(TYPES[key]).DIFFERENTIAL


def of(params: Any) -> Differential:
    """The differential a validated parameter set belongs to (by ``[model] library``)."""
    return get(params.model.library)


def dashboard_of(params: Any) -> Dashboard:
    """The dashboard (figures of ``drivedyn plot``) of a run of the differential and scenario
    of validated parameters ``params``
    (:func:`~drivedyn.library.differentials.dashboard.differential_dashboard`)."""
    # imported here: the builders' elements stay unloaded until a dashboard is wanted
    from drivedyn.library.differentials.dashboard import differential_dashboard

    return differential_dashboard(of(params), params)


def with_mesh_variation(params: Any, variation: bool | None) -> Any:
    """``params`` (a TORSEN's validated parameters) with its meshes' stiffness varying over
    the mesh cycle (``variation`` True) or at its mean (False); None: as they are. A
    vehicle's switch (``differentials.mesh_stiffness_variation``)."""
    if variation is None or variation == params.gears.stiffness_variation:
        return params
    return params.model_copy(update={"gears": params.gears.model_copy(
        update={"stiffness_variation": variation})})


def configuration(params: Any, side: str | None = None) -> str:
    """Which configuration of the differential a run of ``params`` is: ``"bench, torque on
    the rear output (modes 1, 2)"`` (``side``, or the scenario's loaded output) or
    ``"vehicle configuration"`` (recorded with the results, shown by the report)."""
    diff = of(params)
    if side is None and params.scenario.kind != "bench":
        return "vehicle configuration"
    side = side or params.scenario.modes or diff.sides[0]
    a, b = diff.side_modes[side]
    return f"bench, torque on the {side} output (modes {a}, {b})"


def schemas() -> dict[str, type]:
    """library key -> model-file schema of every differential."""
    return {k: get(k).schema for k in TYPES}


__all__ = ["TYPES", "Differential", "Mode", "Output", "configuration", "dashboard_of", "get",
           "of", "schemas"]
