"""Registry of validation cases and their result records."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any


@dataclass
class CaseResult:
    """One checked quantity of a validation case.

    Attributes:
        case: case name (e.g. ``"pendulum"``).
        quantity: what is compared (e.g. ``"period, 120 deg amplitude"``).
        reference: exact or published value.
        simulated: drivedyn's value.
        unit: unit of both values.
        error: relative error ``|sim - ref| / |ref|`` (absolute if ``ref == 0``).
        tolerance: largest accepted error.
        source: where the reference comes from (formula or publication).
        wall_s: wall time of the case [s].
        figures: paths of PNG figures written for the case.
        gap: non-empty for a comparison with a measurement that the model is known to miss
            (why, and where it is documented): reported with status GAP when outside the
            tolerance (the goal it misses), not counted as a check. Only for measured
            references whose deviation a calibration has established (``drivedyn calibrate``
            states it); every model-consistency check gates.
    """

    case: str
    quantity: str
    reference: float
    simulated: float
    unit: str
    error: float
    tolerance: float
    source: str = ""
    wall_s: float = 0.0
    figures: list[str] = field(default_factory=list)
    gap: str = ""

    @property
    def within(self) -> bool:
        """The error is within the tolerance."""
        return bool(self.error <= self.tolerance)

    @property
    def passed(self) -> bool:
        """Within the tolerance, or a documented gap (not a check)."""
        return self.within or bool(self.gap)

    @property
    def status(self) -> str:
        """``PASS``, ``FAIL`` or ``GAP`` (a documented gap outside its goal)."""
        return "PASS" if self.within else ("GAP" if self.gap else "FAIL")

    def as_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["passed"] = self.passed
        d["status"] = self.status
        return d


def compare(case: str, quantity: str, reference: float, simulated: float, unit: str,
            tolerance: float, source: str = "") -> CaseResult:
    """Build a :class:`CaseResult` with the relative error (absolute when ref is 0)."""
    ref = float(reference)
    sim = float(simulated)
    err = abs(sim - ref) / abs(ref) if ref != 0 else abs(sim - ref)
    return CaseResult(case, quantity, ref, sim, unit, err, tolerance, source)


# name -> function(quick: bool, figure_dir: str | None) -> list[CaseResult]
CASES: dict[str, Callable[..., list[CaseResult]]] = {}


def register_case(name: str) -> Callable[[Callable[..., list[CaseResult]]],
                                         Callable[..., list[CaseResult]]]:
    """Decorator adding a case function to :data:`CASES`."""

    def deco(fn: Callable[..., list[CaseResult]]) -> Callable[..., list[CaseResult]]:
        CASES[name] = fn
        return fn

    return deco
