"""The exceptions the native module raises (defined here so that they pickle)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Sequence

if TYPE_CHECKING:
    from ._hstl import Diagnostic


class SpecError(ValueError):
    """A spec text that gave no spec.

    ``diagnostics`` lists every diagnostic of the file (errors and warnings, as
    ``hstl.Diagnostic`` objects with the fields of ``hstlc check --format json``), and
    ``str(error)`` is what ``hstlc check --format concise`` prints for it. When the text
    checks but holds no spec, several specs and no ``name=``, or no spec of that name,
    ``diagnostics`` is empty and the message says which.
    """

    diagnostics: "list[Diagnostic]"

    def __init__(self, message: str, diagnostics: "Sequence[Diagnostic]" = ()) -> None:
        super().__init__(message)
        self.diagnostics = list(diagnostics)

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (self.args[0], self.diagnostics))


class SpecWarning(UserWarning):
    """A warning of a spec that loads (``Spec.load``, ``Spec.parse``), such as HSTL150 on
    ``x >= 8`` over an ``int`` variable: issued through ``warnings``, so filters apply
    (``warnings.simplefilter("error", hstl.SpecWarning)`` makes them errors, ``"ignore"``
    silences them). ``str(warning)`` is the ``hstlc check --format concise`` line and the
    hint; ``diagnostic`` is the ``hstl.Diagnostic``. ``hstl.check`` lists them all without
    warning, and ``hstl.explain(code)`` explains one.
    """

    diagnostic: "Diagnostic"

    def __init__(self, message: str, diagnostic: "Diagnostic") -> None:
        super().__init__(message)
        self.diagnostic = diagnostic

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (self.args[0], self.diagnostic))


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
