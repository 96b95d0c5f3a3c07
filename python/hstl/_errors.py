"""The exceptions the native module raises (defined here so that they pickle)."""

from __future__ import annotations

from typing import Sequence


class SpecError(ValueError):
    """A spec text that gave no spec.

    ``diagnostics`` lists every diagnostic of the file (errors and warnings, as
    ``hstl.Diagnostic`` objects with the fields of ``hstlc check --format json``), and
    ``str(error)`` is what ``hstlc check --format concise`` prints for it. When the text
    checks but holds no spec, several specs and no ``name=``, or no spec of that name,
    ``diagnostics`` is empty and the message says which.
    """

    def __init__(self, message: str, diagnostics: Sequence[object] = ()) -> None:
        super().__init__(message)
        self.diagnostics = list(diagnostics)

    def __reduce__(self):
        return (type(self), (self.args[0], self.diagnostics))


class MissingVariableError(KeyError):
    """A trace or state without one of the spec's state variables (a ``KeyError``)."""

    def __str__(self) -> str:
        # KeyError shows the repr of its argument; the message reads better as it is.
        return str(self.args[0]) if self.args else ""


class WorldError(ValueError):
    """A world file or name that gives no world (a ``ValueError``): the message names the
    file, line and column, as ``hstlc --world`` prints it."""


class PolicyError(ValueError):
    """A ``policy.json`` that cannot be replayed (a ``ValueError``): unreadable, edited,
    damaged, or not what its own spec and world give, as ``hstlc eval`` reports it."""
