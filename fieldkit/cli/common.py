"""What every command shares: one-line errors and shared option types."""

from __future__ import annotations

import functools
import sys
from collections.abc import Callable
from typing import Annotated, ParamSpec, TypeVar

import typer

from fieldkit.errors import FieldkitError
from fieldkit.physics.bodies import SHAPES

P = ParamSpec("P")
R = TypeVar("R")


def one_line_errors(func: Callable[P, R]) -> Callable[P, R]:
    """Turn :class:`FieldkitError` into ``error: <one line>`` on stderr, exit 1."""

    @functools.wraps(func)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        try:
            return func(*args, **kwargs)
        except FieldkitError as exc:
            typer.echo(f"error: {exc}", err=True)
            raise typer.Exit(1) from None

    return wrapper


def warn(message: str) -> None:
    """Print a one-line warning to stderr."""
    typer.echo(f"warning: {' '.join(message.split())}", err=True)


def echo_err(message: str) -> None:
    """Print a line to stderr (progress and notes that must not pollute stdout)."""
    print(message, file=sys.stderr)


# Body options shared by `reduce`, `impact` and `track` (SI units).
MassOpt = Annotated[float | None, typer.Option("--mass", help="Body mass (kg).")]
RadiusOpt = Annotated[
    float | None, typer.Option("--radius", help="Contact radius r (m).")
]
GyrationOpt = Annotated[
    float | None,
    typer.Option("--gyration", help="Radius of gyration k (m); I = m k^2."),
]
ShapeOpt = Annotated[
    str | None,
    typer.Option(
        "--shape",
        help=f"Body shape from thesis Table 4-1: {', '.join(SHAPES)} (gives k, volume, "
        "mass and contact radius; instead of --mass/--gyration).",
    ),
]
DimensionsOpt = Annotated[
    str | None,
    typer.Option(
        "--dimensions",
        help="Shape dimensions (m), comma-separated: cube L; sphere r (radius); "
        "cylinder L,r; ellipsoid 2a,2b,2c (full axis lengths, rotating about c).",
    ),
]
