"""`fieldkit synth --survey`: a virtual field campaign written as raw field files.

Glue only: the options become a :class:`~fieldkit.campaign.design.CampaignDesign`
(which checks them and names the field at fault), the model's rocks are simulated
and surveyed (:func:`~fieldkit.campaign.virtual.virtual_campaign`), and the files of
:mod:`fieldkit.campaign.files` are written into the output folder all or nothing.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import typer

from fieldkit.cli.common import note, random_generator, warn
from fieldkit.cli.progress import report_written, step
from fieldkit.errors import ArgumentError
from fieldkit.outputs import OutputSet, write_text

#: Library argument names -> ``synth --survey`` flags.
SURVEY_FLAGS = {
    "scar_energy_j": "--scar-energy",
    "scar_spacing_m": "--scar-spacing",
    "position_sigma_m": "--position-sigma",
    "elevation_sigma_m": "--elevation-sigma",
    "correlation_length_m": "--correlation-length",
    "canopy_x_m": "--canopy",
    "canopy_sigma_m": "--canopy-sigma",
    "tree_spacing_m": "--tree-spacing",
    "tree_height_m": "--tree-height",
    "strike_height_sigma_m": "--height-sigma",
    "theta0_deg": "--theta0",
    "max_scars": "--max-scars",
}


def parse_canopy(texts: list[str]) -> tuple[tuple[float, float], ...]:
    """``["X0:X1", ...]`` -> chainage ranges (the design checks X0 < X1).

    Examples
    --------
    >>> parse_canopy(["40:80", "120.5:130"])
    ((40.0, 80.0), (120.5, 130.0))
    """
    ranges = []
    for text in texts:
        parts = text.split(":")
        try:
            pair = tuple(float(p) for p in parts)
        except ValueError:
            pair = ()
        if len(pair) != 2 or not all(math.isfinite(v) for v in pair):
            raise ArgumentError(
                f"{text!r} is not X0:X1 (two chainages in metres, e.g. 40:80)",
                source="canopy_x_m",
            )
        ranges.append(pair)
    return tuple(ranges)


def refuse_foreign_folder(folder: Path) -> list[str]:
    """Refuse an output folder that is a file, or holds anything but a previous
    campaign's files; returns the names of the previous campaign's files found
    (those this campaign does not replace are removed once it is written)."""
    from fieldkit.campaign.files import CAMPAIGN_NAME

    if folder.exists() and not folder.is_dir():
        raise ArgumentError(
            f"{folder} exists and is not a folder (a campaign is a folder of files)",
            source="output",
        )
    if not folder.is_dir():
        return []
    entries = sorted(folder.iterdir())
    names = [p.name for p in entries]
    foreign = [
        p.name
        for p in entries
        if not CAMPAIGN_NAME.match(p.name) or (p.is_dir() and not p.is_symlink())
    ]
    if foreign:
        raise ArgumentError(
            f"{folder} is not empty and holds files a campaign does not write "
            f"({', '.join(foreign[:3])}{', ...' if len(foreign) > 3 else ''}): "
            "give an empty or new folder, or one holding only a previous campaign",
            source="output",
        )
    return names


def synth_survey(
    model_file: Path,
    output: Path,
    hidden: dict[str, dict[str, float]],
    seed: int | None,
    paths: int,
    design_options: dict[str, object],
    effects_words: Callable[[dict[str, dict[str, float]]], str],
) -> None:
    """Simulate, survey and write a virtual campaign (`fieldkit synth --survey`)."""
    from fieldkit.campaign.design import CampaignDesign
    from fieldkit.campaign.files import CAMPAIGN_FILE, campaign_files, path_counts
    from fieldkit.campaign.virtual import check_paths, virtual_campaign
    from fieldkit.fit.synthetic import with_effects
    from fieldkit.model.model_file import read_model

    given = {k: v for k, v in design_options.items() if v is not None}
    if "canopy_x_m" in given:
        given["canopy_x_m"] = parse_canopy(given["canopy_x_m"])
    if "elevation_sigma_m" not in given and "position_sigma_m" in given:
        given["elevation_sigma_m"] = given["position_sigma_m"]
    design = CampaignDesign(**given)
    check_paths(paths)
    previous = refuse_foreign_folder(output)
    with OutputSet(inputs=[model_file]) as outputs:
        outputs.confine(output)
        outputs.plan(output / CAMPAIGN_FILE, argument="-o")
        model = with_effects(read_model(model_file, outputs=outputs), hidden)
        rng, seed = random_generator(seed)
        with step(f"simulating and surveying {paths:,} rocks"):
            campaign = virtual_campaign(
                model, design, paths, rng, source=f"virtual campaign {output}"
            )
        files = campaign_files(
            campaign,
            folder=str(output),
            model_file=str(model_file),
            hidden_effects=hidden,
            seed=seed,
        )
        for name in files:
            if name != CAMPAIGN_FILE:  # planned before the model was read
                outputs.plan(output / name, argument="-o")
        for name, text in files.items():
            write_text(output / name, text, outputs)
        written = outputs.commit()
    for path in campaign.paths:
        c = path_counts(path)
        typer.echo(
            f"{path.path_id}: {c['scars']} scars standing for "
            f"{c['impacts_merged']} of {c['impacts_simulated']} simulated impacts "
            f"({c['impacts_merged'] - c['scars']} merged into them), "
            f"{c['tree_strikes']} tree strikes"
        )
    typer.echo(f"survey: {design.describe()}")
    typer.echo(f"effects: {effects_words(campaign.model.effects)}")
    typer.echo(
        f"seed {seed}: {campaign.rocks_simulated} rocks simulated, "
        f"{len(campaign.paths)} surveyed, {campaign.rocks_too_short} left too few "
        "scars"
    )
    for text in campaign.notes[2:]:  # the first two: the survey and counts above
        note(text)
    # the folder holds exactly this campaign: a previous one's files it did not
    # replace (more paths, trees where this one has none) would be read with it
    stale = sorted(set(previous) - set(files))
    kept = []
    for name in stale:
        try:
            (output / name).unlink(missing_ok=True)
        except OSError:
            kept.append(name)
    if stale:
        note(
            f"removed {len(stale) - len(kept)} files of a previous campaign from "
            f"{output} ({', '.join(stale[:3])}{', ...' if len(stale) > 3 else ''})"
        )
    if kept:
        warn(
            f"could not remove {len(kept)} files of a previous campaign from "
            f"{output} ({', '.join(kept[:3])}): remove them by hand; "
            f"{CAMPAIGN_FILE} lists only this campaign's"
        )
    error_model = _reduce_error_note(design)
    if error_model:
        note(error_model)
    report_written(written)


def _reduce_error_note(design) -> str | None:
    """What the campaign's reduce commands assume about the survey error, when it
    is not what the survey did (nothing silent)."""
    from fieldkit.reduce.uncertainty import (
        DEFAULT_ELEVATION_SIGMA_M,
        DEFAULT_POSITION_SIGMA_M,
        DEFAULT_STRIKE_HEIGHT_SIGMA_M,
    )

    same = (
        design.position_sigma_m == DEFAULT_POSITION_SIGMA_M
        and design.elevation_sigma_m == DEFAULT_ELEVATION_SIGMA_M
        and design.strike_height_sigma_m == DEFAULT_STRIKE_HEIGHT_SIGMA_M
        and not design.canopy_x_m
        and design.correlation_length_m == 0
    )
    if same:
        return None
    return (
        "the reduce commands in campaign.json use reduce's own error model "
        f"({DEFAULT_POSITION_SIGMA_M:g} m per point, independent; "
        f"{DEFAULT_STRIKE_HEIGHT_SIGMA_M:g} m per strike height), not this survey's: "
        "add --position-sigma / --height-sigma to reduce to state yours"
    )
