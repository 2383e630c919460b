"""Contact elements (temporary: split in the next commit)."""

from drivedyn.elements.contact.friction import FrictionLaw
from drivedyn.elements.contact.impact_laws import NormalLaw
from drivedyn.elements.contact.plane import JournalContact, PlaneContact, ThrustWasherContact
from drivedyn.elements.contact.squeeze_film import SqueezeFilm
from drivedyn.elements.contact.unilateral import UnilateralContact

__all__ = ["FrictionLaw", "JournalContact", "NormalLaw", "PlaneContact", "SqueezeFilm",
           "ThrustWasherContact", "UnilateralContact"]
