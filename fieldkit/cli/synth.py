"""`fieldkit synth`: a synthetic ImpactTable or video track (hidden effects, noise)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from fieldkit.cli.common import note, one_line_errors, random_generator
from fieldkit.cli.progress import report_written, step
from fieldkit.cli.synth_survey import SURVEY_FLAGS, synth_survey
from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.outputs import OutputSet

FLAGS = {
    "effects": "--effects",
    "output": "-o",
    "fps": "--fps",
    "noise_m": "--noise-m",
    "flights": "--flights",
    "launch_speed_mps": "--launch-speed",
    "launch_angle_deg": "--launch-angle",
    "noise_fraction": "--noise",
    "impact_noise_fraction": "--impact-noise",
}


def parse_effect(text: str) -> tuple[str, dict[str, float]]:
    """``NAME[=k=v,...]`` -> (name, parameter values); a parameter given twice
    is refused (one of the two values would be dropped).

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
        _refuse_repeat(name.strip(), key.strip(), values, number)
        values[key.strip()] = number
    return name.strip(), values


def _refuse_repeat(
    name: str, key: str, values: dict[str, float], number: float
) -> None:
    """Refuse parameter ``key`` of effect ``name`` when ``values`` has it already."""
    if key in values:
        raise ArgumentError(
            f"{name} parameter {key} given twice ({key}={values[key]:g} and "
            f"{key}={number:g}): give each effect parameter once",
            source="effects",
        )


def parse_effects(texts: list[str]) -> dict[str, dict[str, float]]:
    """Every ``--effects`` value -> {name: parameter values}.

    The parameters of an effect named more than once are merged; one parameter
    given twice, in one value or in two, is refused.

    Examples
    --------
    >>> parse_effects(["air_drag=cd=0.5", "air_drag=air_density_kg_m3=1.0"])
    {'air_drag': {'cd': 0.5, 'air_density_kg_m3': 1.0}}
    >>> parse_effects(["air_drag=cd=0.5", "air_drag=cd=0.9"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fieldkit.errors.ArgumentError: effects: air_drag parameter cd given twice ...
    """
    hidden: dict[str, dict[str, float]] = {}
    for text in texts:
        name, values = parse_effect(text)
        merged = hidden.setdefault(name, {})
        for key, number in values.items():
            _refuse_repeat(name, key, merged, number)
            merged[key] = number
    return hidden


def effects_words(effects: dict[str, dict[str, float]]) -> str:
    """The effects and every parameter value used, for the command's output.

    Examples
    --------
    >>> effects_words({"air_drag": {"cd": 0.5, "air_density_kg_m3": 1.225}})
    'air_drag (cd 0.5, air_density_kg_m3 1.225)'
    >>> effects_words({})
    'none (base model)'
    """
    if not effects:
        return "none (base model)"
    return "; ".join(
        name + (" (" + ", ".join(f"{k} {v:g}" for k, v in values.items()) + ")"
                if values else "")
        for name, values in effects.items()
    )  # fmt: skip


#: ``--survey`` options: the CampaignDesign field each one sets.
SURVEY_OPTIONS = {
    "scar_energy": "scar_energy_j",
    "scar_spacing": "scar_spacing_m",
    "position_sigma": "position_sigma_m",
    "elevation_sigma": "elevation_sigma_m",
    "correlation_length": "correlation_length_m",
    "canopy": "canopy_x_m",
    "canopy_sigma": "canopy_sigma_m",
    "tree_spacing": "tree_spacing_m",
    "tree_height": "tree_height_m",
    "height_sigma": "strike_height_sigma_m",
    "theta0": "theta0_deg",
    "max_scars": "max_scars",
}
SurveyFloat = float | None


def _survey_option(flag: str, text: str):
    return typer.Option(flag, help=f"--survey: {text}", rich_help_panel="--survey")


@one_line_errors(flags={**FLAGS, **SURVEY_FLAGS})
def synth(
    model_file: Annotated[
        Path, typer.Argument(metavar="MODEL.json", help="The model file (§5).")
    ],
    output: Annotated[
        Path,
        typer.Option(
            "-o",
            help="The ImpactTable to write (.csv, .parquet); with --track the "
            "track (.csv); with --survey the campaign's folder.",
        ),
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
        float | None,
        typer.Option(
            "--noise",
            help="Relative noise F (default 0.05): each restitution velocity "
            "component gets N(0, (F |vf|)^2), omega_f gets N(0, (F |vf|/r)^2).",
        ),
    ] = None,
    impact_noise: Annotated[
        float,
        typer.Option(
            "--impact-noise",
            help="Relative noise on the impact velocity, independent of --noise: "
            "vi_x, vi_z each get N(0, (F |vi|)^2), omega_i N(0, (F |vi|/r)^2); "
            "written with vin_sd_mps, vit_sd_mps, omega_i_sd_radps and the clean "
            "values in *_true. 0 (default): impact velocities exact.",
        ),
    ] = 0.0,
    paths: Annotated[
        int, typer.Option("--paths", help="Number of rocks (one path each).")
    ] = 100,
    seed: Annotated[
        int | None,
        typer.Option("--seed", help="Random seed (drawn and printed when omitted)."),
    ] = None,
    track: Annotated[
        bool,
        typer.Option(
            "--track",
            help="Write a video track (CSV) of the model's body bouncing down a plane "
            "instead of an ImpactTable; only the body and air_drag act.",
        ),
    ] = False,
    fps: Annotated[
        float, typer.Option("--fps", help="--track: capture rate, frames/s.")
    ] = 200.0,
    noise_m: Annotated[
        float,
        typer.Option("--noise-m", help="--track: SD of the noise on x and z, metres."),
    ] = 0.005,
    flights: Annotated[
        int, typer.Option("--flights", help="--track: number of flights.")
    ] = 8,
    launch_speed: Annotated[
        float,
        typer.Option(
            "--launch-speed",
            help="--track: mean launch speed of a flight, m/s (each drawn within "
            "+-20 %).",
        ),
    ] = 15.0,
    launch_angle: Annotated[
        float,
        typer.Option(
            "--launch-angle",
            help="--track: mean launch angle above the plane, deg (each drawn "
            "within +-5 deg).",
        ),
    ] = 15.0,
    survey: Annotated[
        bool,
        typer.Option(
            "--survey",
            help="Write a virtual field campaign into the folder -o: each rock's "
            "path surveyed as a geologist would (scars, survey error, tree strikes, "
            "no launch angle) as the raw files reduce reads, the truth beside them.",
        ),
    ] = False,
    scar_energy: Annotated[
        SurveyFloat,
        _survey_option(
            "--scar-energy",
            "least normal-impact kinetic energy m vin^2/2 that leaves a scar, J "
            "(default 5000).",
        ),
    ] = None,
    scar_spacing: Annotated[
        SurveyFloat,
        _survey_option(
            "--scar-spacing",
            "scars closer than this in plan read as one, m (default 2).",
        ),
    ] = None,
    position_sigma: Annotated[
        SurveyFloat,
        _survey_option(
            "--position-sigma",
            "SD of each point's plan position error, m (default 0.5).",
        ),
    ] = None,
    elevation_sigma: Annotated[
        SurveyFloat,
        _survey_option(
            "--elevation-sigma",
            "SD of each point's height error, m (default: --position-sigma, 0.5).",
        ),
    ] = None,
    correlation_length: Annotated[
        SurveyFloat,
        _survey_option(
            "--correlation-length",
            "position errors of successive points correlated exp(-dx/L) over this "
            "length, m (default 0: independent).",
        ),
    ] = None,
    canopy: Annotated[
        list[str] | None,
        _survey_option(
            "--canopy",
            "a chainage range X0:X1 under canopy, where the position error is "
            "--canopy-sigma; repeatable.",
        ),
    ] = None,
    canopy_sigma: Annotated[
        SurveyFloat,
        _survey_option("--canopy-sigma", "position error under canopy, m (default 2)."),
    ] = None,
    tree_spacing: Annotated[
        SurveyFloat,
        _survey_option(
            "--tree-spacing",
            "mean spacing of trees along the path (Poisson), m (default 0: no trees).",
        ),
    ] = None,
    tree_height: Annotated[
        SurveyFloat,
        _survey_option(
            "--tree-height", "highest strike a trunk records, m (default 20)."
        ),
    ] = None,
    height_sigma: Annotated[
        SurveyFloat,
        _survey_option(
            "--height-sigma", "SD of each tree-strike height error, m (default 0.25)."
        ),
    ] = None,
    theta0: Annotated[
        SurveyFloat,
        _survey_option(
            "--theta0",
            "launch angle the campaign's preset assumes for the reduction, deg "
            "(default 32.6).",
        ),
    ] = None,
    max_scars: Annotated[
        int | None,
        _survey_option(
            "--max-scars", "at most this many scars surveyed per path (default: all)."
        ),
    ] = None,
) -> None:
    """Make an ImpactTable (or, with --track, a video track) with hidden effects
    and noise.

    The model's rocks are simulated with the hidden effects switched on (added to
    the model's own, or overriding their parameters), every impact recorded, and
    the restitution velocities (and, with --impact-noise, the impact velocities)
    perturbed by relative noise. The clean values are kept in *_true columns
    (vf_x_mps_true, vfn_mps_true, vin_mps_true, ...) and the noise SDs in
    vfn_sd_mps, vft_sd_mps, omega_f_sd_radps (and vin_sd_mps, vit_sd_mps,
    omega_i_sd_radps), so `fieldkit fit` and `fieldkit diagnose` can weight by
    them and a test can compare a fit with the truth.

    Example (from the repository root):

        fieldkit synth surveys/tornado_mountain/model_rocfall_table_7_1.json \\
          --paths 20 --seed 1 \\
          --effects angle_dependent_restitution=b=1.2 --noise 0.05 \\
          -o out/synth.csv

    With --track: a track CSV (t_s, x_m, z_m; clean positions in x_m_true,
    z_m_true, the flight of each sample in flight_true) of the model's body
    bouncing down a plane of the profile's mean dip, each flight launched from the
    previous landing; quadratic air drag when air_drag is on (cd > 0), else exact
    parabolas; Gaussian noise --noise-m on x and z. For `fieldkit diagnose`:

        fieldkit synth surveys/tornado_mountain/model_rocfall_table_7_1.json \\
          --track --fps 200 --noise-m 0.005 --flights 8 --seed 1 \\
          --effects air_drag=cd=0.8 -o out/track.csv

    With --survey: a virtual field campaign in the folder -o. Each rock leaves a
    scar where m vin^2/2 reaches --scar-energy, scars closer than --scar-spacing
    read as one; every point gets survey error (--position-sigma,
    --elevation-sigma, --correlation-length, --canopy with --canopy-sigma); with
    --tree-spacing the first tree each flight strikes is recorded with
    --height-sigma error; the launch angle is not observed (the preset assumes
    --theta0). Written: pathNN_points.csv (what reduce --impacts reads),
    pathNN_trees.csv (reduce --trees), pathNN_truth.csv and pathNN_trees_truth.csv
    (the simulated truth), preset.toml and campaign.json (model, effects with
    every parameter, seed, design, each path's files, counts and reduce command).
    Reduce them all with `fieldkit reduce --campaign DIR -o table.csv`:

        fieldkit synth surveys/tornado_mountain/model_rocfall_table_7_1.json \\
          --survey --paths 3 --seed 1 --tree-spacing 8 -o out/campaign
    """
    from fieldkit.fit.synthetic import (
        check_noise,
        check_paths,
        synthetic_table,
        with_effects,
    )
    from fieldkit.model.model_file import read_model

    hidden = parse_effects(effects or [])
    given = {
        "scar_energy": scar_energy,
        "scar_spacing": scar_spacing,
        "position_sigma": position_sigma,
        "elevation_sigma": elevation_sigma,
        "correlation_length": correlation_length,
        "canopy": canopy or None,
        "canopy_sigma": canopy_sigma,
        "tree_spacing": tree_spacing,
        "tree_height": tree_height,
        "height_sigma": height_sigma,
        "theta0": theta0,
        "max_scars": max_scars,
    }
    options = {
        SURVEY_OPTIONS[name]: value
        for name, value in given.items()
        if value is not None
    }
    if survey:
        if track:
            raise ArgumentError("--survey and --track are two different outputs: "
                                "give one", source="--survey")  # fmt: skip
        for given, flag in ((noise is not None, "--noise"),
                            (impact_noise != 0.0, "--impact-noise")):  # fmt: skip
            if given:
                raise ArgumentError(
                    f"{flag} goes without --survey (a campaign's error is the "
                    "survey's: --position-sigma, --height-sigma)",
                    source=flag,
                )
        synth_survey(model_file, output, hidden, seed, paths, options, effects_words)
        return
    if options:
        flags = [SURVEY_FLAGS[field] for field in options]
        raise ArgumentError(
            f"{', '.join(flags)} {'goes' if len(flags) == 1 else 'go'} with --survey",
            source=flags[0],
        )
    noise = 0.05 if noise is None else noise
    if track:
        _synth_track(
            model_file,
            output,
            hidden,
            seed,
            fps=fps,
            noise_m=noise_m,
            flights=flights,
            speed=launch_speed,
            angle=launch_angle,
        )
        return
    check_paths(paths)
    check_noise(noise, impact_noise)
    with OutputSet(inputs=[model_file]) as outputs:
        outputs.plan(output, argument="-o")
        # the hidden effects are checked before any work
        model = with_effects(read_model(model_file, outputs=outputs), hidden)
        rng, seed = random_generator(seed)
        with step(f"simulating {paths:,} rocks"):
            table = synthetic_table(
                model,
                effects={},
                noise_fraction=noise,
                impact_noise_fraction=impact_noise,
                paths=paths,
                rng=rng,
            )
        with step(f"writing {len(table):,} impacts", announce=len(table) > 100_000):
            table.write(output, outputs=outputs)
            written = outputs.commit()
    typer.echo(
        f"{len(table)} impacts of {paths} rocks (seed {seed}), noise F = {noise:g} "
        f"on vf, F = {impact_noise:g} on vi"
        + (" (impact velocities exact)" if impact_noise == 0 else "")
        + f"; effects: {effects_words(model.effects)}"
    )
    report_written(written)


def _synth_track(
    model_file: Path,
    output: Path,
    hidden: dict[str, dict[str, float]],
    seed: int | None,
    *,
    fps: float,
    noise_m: float,
    flights: int,
    speed: float,
    angle: float,
) -> None:
    """`synth --track`: the model's body bouncing down a plane (see :func:`synth`)."""
    from fieldkit.fit.synthetic import with_effects
    from fieldkit.fit.synthetic_track import (
        LAUNCH_JITTER_DEG,
        check_track_options,
        synthetic_track,
    )
    from fieldkit.model.model_file import read_model

    check_track_options(
        flights=flights, launch_speed_mps=speed, launch_angle_deg=angle, fps=fps,
        noise_m=noise_m,
    )  # fmt: skip
    with OutputSet(inputs=[model_file]) as outputs:
        outputs.plan(output, argument="-o")
        model = with_effects(read_model(model_file, outputs=outputs), hidden)
        drag = model.effects.get("air_drag", {"cd": 0.0, "air_density_kg_m3": 1.225})
        ignored = sorted(set(model.effects) - {"air_drag"})
        px, pz = model.profile.x_m, model.profile.z_m
        # x increases in the direction of travel and the dip is positive when the
        # ground descends that way (ARCHITECTURE §2): a profile rising toward +x
        # would launch the block up a slope it cannot climb
        dip = float(np.degrees(np.arctan2(pz[0] - pz[-1], px[-1] - px[0])))
        if not dip > 0:
            raise InputFileError(
                f"the profile rises {pz[-1] - pz[0]:.1f} m from x = {px[0]:g} to "
                f"{px[-1]:g} m (mean dip {dip:.1f} deg): a synthetic track runs in "
                "the direction of travel, +x, down a plane that descends that way",
                source=model_file,
                where="profile",
            )
        rng, seed = random_generator(seed)
        result = synthetic_track(
            radius_m=model.body.radius_m,
            mass_kg=model.body.mass_kg,
            cd=float(drag["cd"]),
            air_density_kg_m3=float(drag["air_density_kg_m3"]),
            launch_speed_mps=speed * rng.uniform(0.8, 1.2, flights),
            launch_angle_deg=angle
            + rng.uniform(-LAUNCH_JITTER_DEG, LAUNCH_JITTER_DEG, flights),
            surface_angle_deg=dip,
            fps=fps,
            noise_m=noise_m,
            rng=rng,
        )
        result.write(output, outputs=outputs)
        written = outputs.commit()
    typer.echo(
        f"track of {flights} flights, {len(result)} samples at {fps:g} frames/s "
        f"(seed {seed}), plane dip {dip:.1f} deg, noise {noise_m:g} m, "
        f"air_drag cd = {float(drag['cd']):g}, air density "
        f"{float(drag['air_density_kg_m3']):g} kg/m3"
    )
    if ignored:  # a track is flights down a plane: nothing else acts on it here
        note(
            f"a synthetic track is ballistic flights (with air_drag) down a plane: "
            f"{', '.join(ignored)} of the model or --effects do not act on it"
        )
    report_written(written)
