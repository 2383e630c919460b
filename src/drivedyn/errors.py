"""Exceptions shared by every layer (the bottom of the import graph: it imports nothing)."""

from __future__ import annotations


class ModelError(ValueError):
    """A model description that cannot be built; the message names the element and the value."""
