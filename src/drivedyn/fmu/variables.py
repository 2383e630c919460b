"""The variables of an FMU's interface: name, causality, unit, description, start value,
and the FMI unit definitions of the units they use (SI base-unit exponents)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

Causality = Literal["input", "output", "parameter"]

#: FMI unit name -> exponents of the SI base units and the radian (``UnitDefinitions``)
UNITS: dict[str, dict[str, int]] = {
    "N.m": {"kg": 1, "m": 2, "s": -2},
    "N": {"kg": 1, "m": 1, "s": -2},
    "rad/s": {"rad": 1, "s": -1},
    "m/s": {"m": 1, "s": -1},
    "1": {},
}


@dataclass(frozen=True)
class Variable:
    """One real variable of an FMU.

    Attributes:
        name: FMI name (``left_torque``; parameters by their model-file key,
            ``washers.mu``).
        causality: ``"input"``, ``"output"`` or ``"parameter"``.
        unit: FMI unit name, a key of :data:`UNITS`.
        description: what it is, for modelDescription.xml.
        start: start value (inputs and parameters), in ``unit``.
    """

    name: str
    causality: Causality
    unit: str
    description: str
    start: float = 0.0

    def __post_init__(self) -> None:
        if self.unit not in UNITS:
            raise ValueError(f"variable {self.name!r}: unit {self.unit!r} has no FMI "
                             f"definition (known: {', '.join(UNITS)})")
