"""`fieldkit impact` (being built; see the issue tracker)."""

from __future__ import annotations

import typer


def impact() -> None:
    """Not built yet."""
    typer.echo("fieldkit impact: not built yet", err=True)
    raise typer.Exit(3)
