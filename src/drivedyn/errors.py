"""Exceptions shared by every layer (the bottom of the import graph: it imports nothing)."""

from __future__ import annotations


class ModelError(ValueError):
    """A model description that cannot be built; the message names the element and the value."""


def did_you_mean(name: str, candidates: object) -> str:
    """``" (did you mean 'x'?)"`` for the closest of ``candidates`` to a misspelt ``name``,
    or ``""`` when nothing is close (difflib ratio >= 0.6)."""
    import difflib

    close = difflib.get_close_matches(str(name), [str(c) for c in candidates], n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""
