"""`fieldkit reduce` (being built; see the issue tracker)."""

from __future__ import annotations

import typer


def reduce() -> None:
    """Not built yet."""
    typer.echo("fieldkit reduce: not built yet", err=True)
    raise typer.Exit(3)
