"""`fieldkit effects`: the physical effects a model file can switch on."""

from __future__ import annotations

from typing import Annotated

import typer

from fieldkit.cli.common import one_line_errors


@one_line_errors
def effects(
    name: Annotated[
        str | None,
        typer.Argument(metavar="[NAME]", help="Describe this effect only."),
    ] = None,
) -> None:
    """List the physical effects a model file can switch on, or describe one.

    Each effect is one small unit of physics (docs/architecture.md §5): its name,
    the stage it acts in (impact, flight, slide), its formula with the thesis
    reference, and its parameters with defaults, bounds and the neutral value
    that reproduces the base model exactly.

    Examples (from the repository root):

        fieldkit effects

        fieldkit effects angle_dependent_restitution
    """
    from fieldkit.model.effects.registry import EFFECTS, describe

    if name is None:
        for spec in EFFECTS:
            params = ", ".join(p.name for p in spec.parameters)
            typer.echo(f"{spec.name:30s} {spec.stage:7s} {spec.physics}  [{params}]")
        return
    typer.echo(describe(name))  # an unknown name: one line listing the known ones
