"""Model and scenario files (TOML), validated with pydantic; ``--set`` overrides."""

from drivedyn.config.loader import (
    ModelFileError,
    Scenario,
    load_model,
    parse_override,
    read_library_file,
    read_model_file,
    shipped_models,
)
from drivedyn.units import UnitError, to_si

__all__ = [
    "ModelFileError",
    "Scenario",
    "UnitError",
    "load_model",
    "parse_override",
    "read_library_file",
    "read_model_file",
    "shipped_models",
    "to_si",
]
