"""`fieldkit fence` (being built; see the issue tracker)."""

from __future__ import annotations

import typer


def fence() -> None:
    """Not built yet."""
    typer.echo("fieldkit fence: not built yet", err=True)
    raise typer.Exit(3)
