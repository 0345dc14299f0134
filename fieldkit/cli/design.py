"""Measured values and design quantities on the command line (``simulate``, ``fit``,
``diagnose -o``).

* :func:`parse_measured` -- ``--measured x=610,speed=18,ke=600e3`` into a
  :class:`fieldkit.measured.Measured` (shared by ``fieldkit simulate`` and
  ``fieldkit fit``);
* :func:`design_points` -- where a fit reads its design quantities: ``--at``,
  else the model's ``analysis_points``, stated;
* :func:`run_design` -- simulate the start and calibrated models there
  (:func:`fieldkit.fit.consequences.design_quantities`) with a progress step;
* :func:`print_design` and :func:`design_markdown` -- the verdicts first, then
  the table, on the console and at the top of report.md.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Annotated

import numpy as np
import typer

from fieldkit.errors import ArgumentError
from fieldkit.measured import Measured, measured_problem

#: ``--measured`` keys -> :class:`~fieldkit.measured.Measured` fields.
MEASURED_KEYS = {
    "x": "x_m",
    "speed": "speed_mps",
    "ke": "ke_j",
    "total": "total_j",
    "height": "height_m",
}
#: Rocks per model of the fit's design quantities (``--design-rocks``).
DEFAULT_DESIGN_ROCKS = 2000
#: Largest ``--design-rocks``: each model is simulated once with them.
MAX_DESIGN_ROCKS = 1_000_000

#: The options of every command that reports design quantities (``fit``,
#: ``fit --paths``, ``diagnose -o``).
AtOpt = Annotated[
    list[float] | None,
    typer.Option(
        "--at",
        help="Design quantities at this x (m) (repeatable; default the model "
        "file's analysis_points, else the measured values' x).",
    ),
]
MeasuredOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--measured",
        help="A value measured at an analysis point, e.g. "
        "x=610,speed=18,ke=600e3[,total=690e3][,height=1.5] (J, m/s, m; "
        "repeatable; the --preset's measured entries too): the start and "
        "calibrated models are set beside it and a line says when one is "
        "unconservative.",
    ),
]
DesignRocksOpt = Annotated[
    int,
    typer.Option(
        "--design-rocks",
        help=f"Rocks per model for the design quantities (default "
        f"{DEFAULT_DESIGN_ROCKS:,}), on a random stream the calibration never uses.",
    ),
]


def parse_measured(text: str) -> Measured:
    """``x=610,speed=18,ke=600e3[,total=690e3][,height=1.5]`` -> a Measured.

    ``x`` is required and each key may be given once; a speed, energy (J) or
    bounce height must be from 0 to its bound (:func:`fieldkit.measured.
    measured_bounds`: 100 m/s, 5e10 J translational, 1e11 J total, 510 m): a
    negative or larger value is a typo or a unit slip.

    Examples
    --------
    >>> parse_measured("x=610,speed=18,ke=600e3")  # doctest: +NORMALIZE_WHITESPACE
    Measured(x_m=610.0, speed_mps=18.0, ke_j=600000.0, height_m=None,
             total_j=None, source='')
    >>> parse_measured("x=50,speed=-5")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fieldkit.errors.ArgumentError: measured: speed=-5 in 'x=50,speed=-5' must be ...
    """
    values: dict[str, float] = {}
    for part in text.split(","):
        key, sep, value = part.partition("=")
        key = key.strip().lower()
        if not sep or key not in MEASURED_KEYS:
            raise ArgumentError(
                f"{part.strip()!r} in {text!r}: expected key=value with key one of "
                f"{', '.join(MEASURED_KEYS)}",
                source="measured",
            )
        name = MEASURED_KEYS[key]
        if name in values:
            raise ArgumentError(
                f"{key} given twice in {text!r} ({key}={values[name]:g} and "
                f"{key}={value.strip()}): give each key once",
                source="measured",
            )
        try:
            number = float(value)
        except ValueError:
            number = math.nan
        if not math.isfinite(number):
            raise ArgumentError(
                f"{key}={value!r} is not a finite number", source="measured"
            )
        problem = measured_problem(name, number)
        if problem is not None:
            raise ArgumentError(
                f"{key}={value.strip()} in {text!r} {problem}", source="measured"
            )
        values[name] = number
    if "x_m" not in values:
        raise ArgumentError(f"{text!r} lacks x=<position m>", source="measured")
    return Measured(**values)


def design_points(
    model, at: Sequence[float] | None, measured: Sequence[Measured]
) -> tuple[list[float], list[str], str | None]:
    """Where the design quantities are read: x [m], their names, and the line
    that says where they came from (None when ``--at`` gave them).

    ``--at`` wins; else the model's ``analysis_points``; else the points of the
    measured values. A measured value whose x is not among the points is refused
    (its comparison needs the rocks crossing its x).
    """
    names: list[str] = []
    said = None
    if at:
        xs = [float(x) for x in at]
        names = [""] * len(xs)
    elif model.analysis_points:
        xs = [p.x_m for p in model.analysis_points]
        names = [p.name for p in model.analysis_points]
        said = (
            "--at not given: design quantities at the model's analysis points "
            + ", ".join(
                f"x = {p.x_m:g} m" + (f" ({p.name})" if p.name else "")
                for p in model.analysis_points
            )
        )
    else:
        xs = sorted({float(m.x_m) for m in measured})
        names = [""] * len(xs)
        said = (
            "--at not given and the model names no analysis point: design "
            "quantities at the measured values' x = "
            + ", ".join(f"{x:g}" for x in xs) + " m"
            if xs
            else "no analysis point: give --at or an analysis_points block in the "
            "model file; runout only"
        )
    from fieldkit.model.simulate import check_run

    check_run(1, (float(model.profile.x_m[0]), float(model.profile.x_m[-1])), xs)
    for m in measured:
        if not any(np.isclose(m.x_m, x) for x in xs):
            raise ArgumentError(
                f"x={m.x_m:g} is not an analysis point "
                f"({', '.join(f'{x:g} m' for x in xs) or 'none'}); its values are "
                f"compared with the rocks crossing it: add --at {m.x_m:g}",
                source="measured",
            )
    return xs, names, said


def check_design_rocks(rocks: int) -> None:
    """``--design-rocks`` from 1 to :data:`MAX_DESIGN_ROCKS`."""
    if not 1 <= rocks <= MAX_DESIGN_ROCKS:
        raise ArgumentError(
            f"must be from 1 to {MAX_DESIGN_ROCKS:,} (got {rocks})",
            source="design_rocks",
        )


def run_design(
    models: Mapping[str, object],
    xs: Sequence[float],
    names: Sequence[str],
    measured: Sequence[Measured],
    *,
    rocks: int,
    seed: int,
):
    """The design quantities of ``models`` (a progress step while they run)."""
    from fieldkit.cli.progress import step
    from fieldkit.fit.consequences import design_quantities

    with step(
        f"design quantities: {rocks:,} rocks for each of the {len(models)} models"
    ):
        return design_quantities(
            models, xs, measured, rocks=rocks, seed=seed, names=names
        )


def print_design(consequences, said: str | None) -> None:
    """The verdicts first, then where the points came from and the table."""
    for line in consequences.verdicts():
        typer.echo(line)
    if said is not None:
        typer.echo(said)
    for line in consequences.lines():
        typer.echo(line)


def design_markdown(consequences, said: str | None) -> list[str]:
    """The report's first section: verdicts as a list, then the tables."""
    verdicts = consequences.verdicts()
    lines = ["## Design quantities at the analysis points", ""]
    lines += [f"* **{v}**" for v in verdicts] or [
        "* no measured value lies above the p95 of any model"
        if consequences.has_measured()
        else "* no measured value to compare with"
    ]
    if said is not None:
        lines += ["", said]
    lines += ["", *consequences.markdown(), ""]
    return lines


def measured_values(
    texts: Sequence[str] | None, preset_file=None
) -> list[Measured]:
    """The ``--measured`` values, then the preset's ``[[measured]]`` entries."""
    values = [parse_measured(t) for t in texts or []]
    if preset_file is not None:
        from fieldkit.io.preset import read_preset

        values += list(read_preset(preset_file).measured)
    return values


def design_for_fit(
    models: Mapping[str, object], *, at, measured: Sequence[Measured], rocks: int,
    seed: int,
):  # fmt: skip
    """The design quantities of the fit's named models (``{"start": ...,
    "calibrated": ...}``, more when a fit has them), at the first model's points:
    (consequences, the line saying where the points came from, or None)."""
    first = next(iter(models.values()))
    xs, names, said = design_points(first, at, measured)
    consequences = run_design(models, xs, names, measured, rocks=rocks, seed=seed)
    return consequences, said
