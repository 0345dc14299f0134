"""The one error type that bad input raises, and how it prints.

Every reader, physics guard and command raises :class:`FieldkitError` (or a
subclass) for problems with the *user's input*. The command line turns it into a
single line on stderr and a non-zero exit code; anything else escaping is a bug and
keeps its traceback.

Library messages name the *arguments* of the function the user called, never
command-line flags: ``source="mass_kg"`` for the argument at fault, and inside a
message its name (``"mass_kg must be > 0"``). Other arguments a message mentions go
in backticks (``"unit_weight_kn_m3 needs `shape`"``), to tell them from prose and
from column names. The command line maps these names to its flags
(:data:`fieldkit.cli.common.FLAGS`).
"""

from __future__ import annotations

from os import PathLike


class FieldkitError(Exception):
    """Bad input, described in one line.

    Parameters
    ----------
    message
        What is wrong, e.g. ``"elevation missing"``.
    source
        The file (or argument name, e.g. ``"mass_kg"``) the problem is in. Left out
        of the printed line when the message already starts with it.
    where
        The row, point or frame, e.g. ``"row 7"``, ``"point 12"``, ``"frames 210-245"``.

    Examples
    --------
    >>> str(FieldkitError("elevation missing", source="a.gpx", where="point 3"))
    'a.gpx: point 3: elevation missing'
    >>> str(FieldkitError("mass_kg must be > 0 (got -3)", source="mass_kg"))
    'mass_kg must be > 0 (got -3)'
    """

    def __init__(
        self,
        message: str,
        *,
        source: str | PathLike[str] | None = None,
        where: str | None = None,
    ) -> None:
        self.message = " ".join(str(message).split())  # always one line
        self.source = None if source is None else str(source)
        self.where = where
        super().__init__(str(self))

    def __str__(self) -> str:
        source = self.source
        if source and (self.message + " ").startswith(source + " "):
            source = None  # "mass_kg must be > 0", not "mass_kg: mass_kg must be > 0"
        parts = [p for p in (source, self.where) if p]
        return ": ".join([*parts, self.message])


class InputFileError(FieldkitError):
    """A file that cannot be read, is empty, truncated, or has a bad value."""


class PhysicsError(FieldkitError):
    """Inputs that no physical solution satisfies (e.g. an unreachable point)."""


class ArgumentError(FieldkitError):
    """A parameter outside its physical range (negative mass, e_n < 0, ...)."""


class OutputFileError(FieldkitError):
    """An output that cannot be written: it would overwrite an input, its folder is
    read-only, the disk is full, ... (:mod:`fieldkit.outputs`)."""
