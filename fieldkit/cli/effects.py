"""`fieldkit effects`: the physical effects a model file can switch on."""

from __future__ import annotations

from typing import Annotated

import typer

from fieldkit.cli.common import one_line_errors
from fieldkit.errors import ArgumentError


def _registry():
    from fieldkit.model.effects.registry import EFFECTS

    return {spec.name: spec for spec in EFFECTS}


def describe(spec) -> str:
    """Several lines on one effect: stage, physics, reference, parameters."""
    lines = [
        f"{spec.name} ({spec.stage} stage)",
        f"  {spec.summary}",
        f"  physics:   {spec.physics}",
        f"  reference: {spec.reference}",
        "  parameters (model file: "
        f'"effects": {{"{spec.name}": {{"<name>": value}}}}):',
    ]
    for p in spec.parameters:
        lines.append(
            f"    {spec.name}.{p.name} = {p.default:g} {p.units}  "
            f"[{p.lower:g}, {p.upper:g}], neutral {p.neutral:g}: {p.description}"
        )
    return "\n".join(lines)


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
    known = _registry()
    if name is None:
        for spec in known.values():
            params = ", ".join(p.name for p in spec.parameters)
            typer.echo(f"{spec.name:30s} {spec.stage:7s} {spec.physics}  [{params}]")
        return
    spec = known.get(name)
    if spec is None:
        raise ArgumentError(
            f"unknown effect {name!r}; known: {', '.join(known)}", source="NAME"
        )
    typer.echo(describe(spec))
