"""Where a run comes from, written into its results' attributes so that the report, the
plots and the viewer of a results file find the library model's dashboard and say which
configuration ran, whichever command produced the file (``run``, ``vehicle``, ``tdr
--out``, a sweep's ``--keep-runs``).

Attributes written (all strings, netCDF-safe):

* ``model_file``: the parameters of the run as JSON (a model file's content; a library
  model's validated parameters with the scenario and bench settings the run used);
* ``model_source``: the file or shipped model name, with the configuration in brackets;
* ``overrides``: the ``--set`` overrides as a JSON list (``"[]"`` for none);
* ``library_model``: the library type (``"torsen_c"``, ``"vehicle_4wd"``), empty for a plain
  mechanism file;
* ``configuration``: which configuration of the library model ran (``"bench, torque on the
  rear output (modes 1, 2)"``, ``"vehicle configuration"``, ``"torsen"``), empty for none.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from typing import Any

ATTRIBUTES = ("model_file", "model_source", "overrides", "library_model", "configuration")


def record_provenance(results: Any, *, model_file: str, source: str,
                      overrides: Iterable[str] | dict[str, Any] = (),
                      library_model: str | None = None,
                      configuration: str | None = None) -> None:
    """Write the :data:`ATTRIBUTES` of a run into ``results.attrs`` (module doc).

    Args:
        results: the run's :class:`~drivedyn.results.results.Results` or
            ``xarray.Dataset``.
        model_file: the run's parameters as JSON text.
        source: model file path or shipped name.
        overrides: ``--set`` texts (``["pockets.mu=0.1"]``) or a key -> value dict.
        library_model: library type of a parametric model file, None for a mechanism file.
        configuration: the configuration that ran, None when the model has only one.
    """
    if isinstance(overrides, dict):
        overrides = [f"{k}={v}" for k, v in overrides.items()]
    a = results.attrs
    a["model_file"] = model_file
    a["model_source"] = f"{source} [{configuration}]" if configuration else source
    a["overrides"] = json.dumps(list(overrides))
    a["library_model"] = library_model or ""
    a["configuration"] = configuration or ""
