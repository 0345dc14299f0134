"""`fieldkit track` (being built; see the issue tracker)."""

from __future__ import annotations

import typer


def track() -> None:
    """Not built yet."""
    typer.echo("fieldkit track: not built yet", err=True)
    raise typer.Exit(3)
