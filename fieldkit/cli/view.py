"""`fieldkit view` (being built; see the issue tracker)."""

from __future__ import annotations

import typer


def view() -> None:
    """Not built yet."""
    typer.echo("fieldkit view: not built yet", err=True)
    raise typer.Exit(3)
