"""Element specs, families and the registry: an element *family* is a frozen parameter record
(an :class:`ElementSpec`, what the user writes) plus a :class:`Family` that turns every spec of
that family in a model into one :class:`~drivedyn.elements.framework.group.Group`.
``REGISTRY`` maps the family names (``ElementSpec.family``) to their :class:`Family`; each
family module registers its own with :func:`register`."""

from __future__ import annotations

import abc
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

from drivedyn.elements.framework.group import Group


class ElementSpec:
    """Base class of element parameter records (frozen dataclasses).

    Subclasses set ``family`` (the registry key) and ``units`` (the SI unit of each float
    parameter, used by model files and in messages), and implement ``markers()`` (names of
    the markers they attach to, used for validation) and ``validate()``.
    """

    family: ClassVar[str] = ""
    #: SI unit of each float parameter (``{"stiffness": "N/m", "mu": "1"}``): ``"1"`` declares
    #: a dimensionless one, ``"N/m or N m/rad"`` one number used in either dimension,
    #: ``"N/m^{exponent}"`` a unit depending on another parameter
    #: (:mod:`drivedyn.elements.framework.checks`). Model files may give a dimensional
    #: parameter in any unit of its dimension, a dimensionless one only as a plain number;
    #: range checks (:func:`~drivedyn.elements.framework.checks.check_param`) and
    #: plausibility checks print the unit.
    units: ClassVar[dict[str, str]] = {}
    name: str

    def markers(self) -> tuple[str, ...]:
        return ()

    def validate(self) -> None:  # pragma: no cover - default accepts
        return None

    def visuals(self) -> tuple:
        """The shapes the 3-D viewer draws for this element
        (:class:`drivedyn.elements.framework.visuals.Visual` records on its markers); none by
        default."""
        return ()


@dataclass(frozen=True)
class TwoMarkerSpec(ElementSpec):
    """Base of the elements between two markers: ``name``, ``marker_a``, ``marker_b`` first,
    then the family's own fields."""

    name: str
    marker_a: str
    marker_b: str

    def markers(self) -> tuple[str, ...]:
        return (self.marker_a, self.marker_b)


class Family(abc.ABC):
    """Registry entry: builds a :class:`Group` from all specs of one family.

    ``build(specs, ctx)`` receives the element specs (in model order) and a
    :class:`drivedyn.model.compile.BuildContext` giving marker frames, multiplier and state
    allocation and time-function ids. The small models that exercise each family for the
    registry tangent test are test fixtures (``tests/element_cases``), keyed by ``name``.
    """

    name: ClassVar[str] = ""
    spec_types: ClassVar[tuple[type, ...]] = ()

    @abc.abstractmethod
    def build(self, specs: Sequence[Any], ctx: Any) -> Group:
        """The group of all ``specs`` of this family."""


REGISTRY: dict[str, Family] = {}


def register(family: Family) -> Family:
    """Add a family to the registry (one line in each element module)."""
    if family.name in REGISTRY:
        raise ValueError(f"element family {family.name!r} registered twice")
    REGISTRY[family.name] = family
    return family


def family_of(spec: Any) -> Family:
    """Return the registered family of an element spec."""
    fam = REGISTRY.get(getattr(spec, "family", ""))
    if fam is None:
        raise TypeError(f"{type(spec).__name__} is not a registered element type")
    return fam
