"""``python -m drivedyn.cli``: the ``drivedyn`` command."""

from drivedyn.cli import console

console()
