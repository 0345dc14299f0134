"""`fieldkit synth`: a synthetic ImpactTable (simulator, hidden effects, noise)."""

from __future__ import annotations

import secrets
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from fieldkit.cli.common import note, one_line_errors
from fieldkit.errors import ArgumentError
from fieldkit.outputs import OutputSet

FLAGS = {"effects": "--effects", "output": "-o"}


def parse_effect(text: str) -> tuple[str, dict[str, float]]:
    """``NAME[=k=v,...]`` -> (name, parameter values).

    Examples
    --------
    >>> parse_effect("angle_dependent_restitution=b=1.2,theta_ref_deg=25")
    ('angle_dependent_restitution', {'b': 1.2, 'theta_ref_deg': 25.0})
    >>> parse_effect("rotation_friction")
    ('rotation_friction', {})
    """
    name, _, rest = text.partition("=")
    values: dict[str, float] = {}
    for part in filter(None, (p.strip() for p in rest.split(","))):
        key, sep, value = part.partition("=")
        try:
            number = float(value)
        except ValueError:
            number = float("nan")
        if not sep or not key.strip() or number != number:
            raise ArgumentError(
                f"{part!r} in {text!r}: expected NAME=key=value,key=value",
                source="effects",
            )
        values[key.strip()] = number
    return name.strip(), values


@one_line_errors(flags=FLAGS)
def synth(
    model_file: Annotated[
        Path, typer.Argument(metavar="MODEL.json", help="The model file (§5).")
    ],
    output: Annotated[
        Path, typer.Option("-o", help="The ImpactTable to write (.csv, .parquet).")
    ],
    effects: Annotated[
        list[str] | None,
        typer.Option(
            "--effects",
            help="A hidden effect, NAME[=key=value,...] (parameters as in "
            "`fieldkit effects NAME`), added to the model's; repeatable.",
        ),
    ] = None,
    noise: Annotated[
        float,
        typer.Option(
            "--noise",
            help="Relative noise F: each restitution velocity component gets "
            "N(0, (F |vf|)^2), omega_f gets N(0, (F |vf|/r)^2); impact velocities "
            "stay exact.",
        ),
    ] = 0.05,
    paths: Annotated[
        int, typer.Option("--paths", help="Number of rocks (one path each).")
    ] = 100,
    seed: Annotated[
        int | None,
        typer.Option("--seed", help="Random seed (drawn and printed when omitted)."),
    ] = None,
) -> None:
    """Make an ImpactTable with the simulator: hidden effects plus measurement noise.

    The model's rocks are simulated with the hidden effects switched on (added to
    the model's own, or overriding their parameters), every impact recorded, and
    the restitution velocities perturbed by relative noise. The clean values are
    kept in *_true columns (vf_x_mps_true, vfn_mps_true, ...) and the noise SDs in
    vfn_sd_mps, vft_sd_mps, omega_f_sd_radps, so `fieldkit fit` can weight by them
    and a test can compare a fit with the truth.

    Example (from the repository root):

        fieldkit synth surveys/tornado_mountain/model_rocfall_table_7_1.json \\
          --paths 20 --seed 1 \\
          --effects angle_dependent_restitution=b=1.2 --noise 0.05 \\
          -o out/synth.csv
    """
    from fieldkit.fit.synthetic import synthetic_table
    from fieldkit.model.model_file import read_model

    hidden = dict(parse_effect(text) for text in (effects or []))
    with OutputSet(inputs=[model_file]) as outputs:
        outputs.plan(output, argument="-o")
        model = read_model(model_file)
        if seed is None:
            seed = secrets.randbits(32)
            note(f"`seed` not given: used {seed}; pass --seed {seed} to reproduce")
        table = synthetic_table(
            model,
            effects=hidden,
            noise_fraction=noise,
            paths=paths,
            rng=np.random.default_rng(seed),
        )
        table.write(output, outputs=outputs)
        outputs.commit()
    active = {**model.effects, **hidden}
    typer.echo(
        f"{len(table)} impacts of {paths} rocks (seed {seed}), noise F = {noise:g} "
        f"on vf; effects: {', '.join(active) or 'none (base model)'} -> {output}"
    )
