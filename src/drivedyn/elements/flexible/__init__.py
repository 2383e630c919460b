"""Reduced flexible bodies (floating frame of reference, Craig-Bampton modes) and the
contact of a rigid face on a flexible washer at its face nodes or at quadrature points."""

from drivedyn.elements.flexible.family import FlexibleBody
from drivedyn.elements.flexible.interface import FlexibleInterface
from drivedyn.elements.flexible.washer import FlexibleWasherContact

__all__ = ["FlexibleBody", "FlexibleInterface", "FlexibleWasherContact"]
