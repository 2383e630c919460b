"""What an FMU built by ``drivedyn fmu`` carries in its ``resources`` folder: the model file's
text and a JSON record of the model (its kind, name, source and ``--set`` overrides)."""

from __future__ import annotations

#: the model file (TOML), as given to ``drivedyn fmu``
MODEL_FILE = "drivedyn_model.toml"
#: ``{"kind", "model", "source", "overrides", "drivedyn_version"}``
META_FILE = "drivedyn_fmu.json"
