"""A virtual campaign as the raw files a geologist brings back, the truth beside them.

:func:`campaign_files` turns a :class:`~fieldkit.campaign.virtual.VirtualCampaign`
into file contents (names relative to the campaign folder):

``pathNN_points.csv``
    ``point,x_m,z_m,material``: the surveyed points in order of travel, the source
    first (a section CSV, what ``fieldkit reduce --impacts`` reads).
``pathNN_trees.csv``
    ``after_impact,horizontal_distance_m,strike_height_m``: the tree strikes (what
    ``reduce --trees`` reads); only when the design has trees and the path has
    strikes.
``pathNN_truth.csv``
    The truth per point (:data:`~fieldkit.campaign.virtual.TRUTH_COLUMNS`).
``pathNN_trees_truth.csv``
    The tree strikes before their height error
    (:data:`~fieldkit.campaign.virtual.TREE_TRUTH_COLUMNS`), beside the trees file.
``preset.toml``
    A survey preset whose ``[reduce]`` holds the assumed launch angle and the
    model's body, so every path reduces as the campaign's own reduce command says.
``campaign.json``
    Everything that made the campaign (:data:`CAMPAIGN_FORMAT`): the model file,
    the effects with every parameter value, the seed, the design, the notes, and
    per path its files, its reduce command and its counts.

:func:`read_campaign` reads ``campaign.json`` back for ``fieldkit reduce
--campaign``. Numbers are written with full precision (``repr``), so a seed gives
byte-identical files.
"""

from __future__ import annotations

import json
import re
import shlex
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from fieldkit.campaign.virtual import (
    TREE_TRUTH_COLUMNS,
    TRUTH_COLUMNS,
    VirtualCampaign,
    VirtualPath,
)
from fieldkit.errors import InputFileError
from fieldkit.outputs import json_text

#: ``campaign.json``'s ``format`` value.
CAMPAIGN_FORMAT = "fieldkit virtual campaign 1"
CAMPAIGN_FILE = "campaign.json"
PRESET_FILE = "preset.toml"
#: The points file's columns (a section CSV).
POINT_COLUMNS = ("point", "x_m", "z_m", "material")
#: The trees file's columns (measured along the section).
TREE_COLUMNS = ("after_impact", "horizontal_distance_m", "strike_height_m")
#: Names of the files a campaign writes into its folder (a folder holding only
#: these may be written again).
CAMPAIGN_NAME = re.compile(
    r"^(campaign\.json|preset\.toml|path\d+_(points|trees|truth|trees_truth)\.csv)$"
)


def path_file_names(path: VirtualPath) -> dict[str, str | None]:
    """The file names of one path: points, trees (None without strikes), truth,
    trees_truth (None without trees)."""
    trees = path.survey.trees
    has_strikes = trees is not None and len(trees.frame) > 0
    return {
        "points": f"{path.path_id}_points.csv",
        "trees": f"{path.path_id}_trees.csv" if has_strikes else None,
        "truth": f"{path.path_id}_truth.csv",
        "trees_truth": f"{path.path_id}_trees_truth.csv" if has_strikes else None,
    }


def reduce_command(folder: str, path_id: str, trees: str | None) -> str:
    """The ``fieldkit reduce`` command line that reduces path ``path_id`` (with the
    trees file ``trees``, or none) of the campaign written into ``folder`` (as the
    user named it).

    Examples
    --------
    >>> reduce_command("out/camp", "path01", None)  # doctest: +NORMALIZE_WHITESPACE
    'fieldkit reduce --impacts out/camp/path01_points.csv --preset
     out/camp/preset.toml --path-id path01 -o out/camp_path01.csv'
    """
    base = folder.rstrip("/") or "/"

    def inside(name: str) -> str:
        return shlex.quote(f"{base}/{name}")

    words = ["fieldkit", "reduce", "--impacts", inside(f"{path_id}_points.csv")]
    if trees is not None:
        words += ["--trees", inside(trees)]
    words += ["--preset", inside(PRESET_FILE), "--path-id", path_id]
    # the table goes beside the folder, not into it (the folder holds the
    # campaign's files only) nor into the working folder
    words += ["-o", shlex.quote(f"{base}_{path_id}.csv")]
    return " ".join(words)


def preset_text(campaign: VirtualCampaign) -> str:
    """The campaign's survey preset: the launch angle the reduction assumes and the
    model's body (``[reduce]`` of :mod:`fieldkit.io.preset`)."""
    body = campaign.model.body
    return (
        "# A virtual campaign's survey preset (fieldkit synth --survey): the launch\n"
        "# angle assumed where no tree defines a flight, and the model's body.\n"
        "[reduce]\n"
        f"theta0_deg = {campaign.design.theta0_deg!r}\n"
        f"mass_kg = {float(body.mass_kg)!r}\n"
        f"radius_m = {float(body.radius_m)!r}\n"
        f"gyration_m = {float(body.gyration_m)!r}\n"
    )


def _csv(frame: pd.DataFrame, columns) -> str:
    return frame.loc[:, list(columns)].to_csv(index=False, lineterminator="\n")


def path_files(path: VirtualPath) -> dict[str, str]:
    """File name -> text of one path's files (see the module docstring)."""
    names = path_file_names(path)
    points = path.survey.points.frame.copy()
    points["material"] = points["material"].astype("string")
    out = {
        names["points"]: _csv(points, POINT_COLUMNS),
        names["truth"]: _csv(path.truth, TRUTH_COLUMNS),
    }
    if names["trees"] is not None:
        out[names["trees"]] = _csv(path.survey.trees.frame, TREE_COLUMNS)
        out[names["trees_truth"]] = _csv(path.trees_truth, TREE_TRUTH_COLUMNS)
    return out


def path_counts(path: VirtualPath) -> dict[str, int]:
    """Scars (source not counted), tree strikes recorded and simulated impacts of
    one path, and the simulated impacts its scars stand for."""
    trees = path.survey.trees
    return {
        "scars": len(path.survey.points.frame) - 1,
        "tree_strikes": 0 if trees is None else len(trees.frame),
        "impacts_simulated": len(path.impacts.frame),
        "impacts_merged": int(path.truth["impacts_merged"].sum()),
    }


def campaign_record(
    campaign: VirtualCampaign,
    *,
    folder: str,
    model_file: str,
    hidden_effects: dict[str, dict[str, float]],
    seed: int,
) -> dict:
    """The content of ``campaign.json`` (module docstring)."""
    paths = []
    for path in campaign.paths:
        names = path_file_names(path)
        paths.append(
            {
                "path_id": path.path_id,
                "files": names,
                "reduce": reduce_command(folder, path.path_id, names["trees"]),
                "counts": path_counts(path),
            }
        )
    counts = {
        key: sum(p["counts"][key] for p in paths)
        for key in ("scars", "tree_strikes", "impacts_simulated", "impacts_merged")
    }
    return {
        "format": CAMPAIGN_FORMAT,
        "model": model_file,
        "hidden_effects": {
            name: dict(campaign.model.effects[name]) for name in hidden_effects
        },
        "effects": {k: dict(v) for k, v in campaign.model.effects.items()},
        "seed": seed,
        "design": campaign.design.to_json(),
        "design_description": campaign.design.describe(),
        "preset": PRESET_FILE,
        "notes": list(campaign.notes),
        "counts": {
            "paths": len(paths),
            "rocks_simulated": campaign.rocks_simulated,
            "rocks_too_short": campaign.rocks_too_short,
            **counts,
        },
        "paths": paths,
    }


def campaign_files(
    campaign: VirtualCampaign,
    *,
    folder: str,
    model_file: str,
    hidden_effects: dict[str, dict[str, float]],
    seed: int,
) -> dict[str, str]:
    """File name -> text of every file of the campaign (module docstring)."""
    out: dict[str, str] = {}
    for path in campaign.paths:
        out.update(path_files(path))
    out[PRESET_FILE] = preset_text(campaign)
    record = campaign_record(
        campaign,
        folder=folder,
        model_file=model_file,
        hidden_effects=hidden_effects,
        seed=seed,
    )
    out[CAMPAIGN_FILE] = json_text(record) + "\n"
    return out


@dataclass(frozen=True)
class CampaignPath:
    """One path of a campaign file: its id and its raw files (absolute or relative
    to the working folder)."""

    path_id: str
    points: Path
    trees: Path | None


@dataclass(frozen=True)
class CampaignFile:
    """``campaign.json`` as :func:`read_campaign` reads it."""

    source: str
    preset: Path
    paths: tuple[CampaignPath, ...]


def read_campaign(folder: str | Path) -> CampaignFile:
    """Read ``folder/campaign.json`` (file names in it are relative to ``folder``).

    Raises
    ------
    InputFileError
        No campaign file, not JSON, not a campaign, or a path entry without its
        points file.
    """
    folder = Path(folder)
    path = folder / CAMPAIGN_FILE
    source = str(path)
    if not folder.is_dir():
        raise InputFileError(
            "not a folder (give the folder fieldkit synth --survey wrote)",
            source=str(folder),
        )
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputFileError(
            "file not found (not a folder fieldkit synth --survey wrote)",
            source=source,
        ) from None
    except UnicodeDecodeError:
        raise InputFileError("not UTF-8 text", source=source) from None
    except json.JSONDecodeError as exc:
        raise InputFileError(f"not JSON: {exc}", source=source) from None
    except OSError as exc:
        raise InputFileError(str(exc.strerror or exc).lower(), source=source) from None
    if not isinstance(data, dict) or data.get("format") != CAMPAIGN_FORMAT:
        raise InputFileError(
            f"not a virtual campaign (format must be {CAMPAIGN_FORMAT!r})",
            source=source,
            where="format",
        )
    preset = data.get("preset")
    if not (isinstance(preset, str) and preset):
        raise InputFileError("must name the preset file", source=source, where="preset")
    entries = data.get("paths")
    if not (isinstance(entries, list) and entries):
        raise InputFileError(
            "must list at least one path", source=source, where="paths"
        )
    paths = []
    for k, entry in enumerate(entries):
        where = f"paths[{k}]"
        files = entry.get("files") if isinstance(entry, dict) else None
        path_id = entry.get("path_id") if isinstance(entry, dict) else None
        if not (isinstance(path_id, str) and path_id and isinstance(files, dict)):
            raise InputFileError(
                "each path needs a path_id and its files", source=source, where=where
            )
        points = files.get("points")
        trees = files.get("trees")
        if not (isinstance(points, str) and points):
            raise InputFileError(
                "must name the points file",
                source=source,
                where=f"{where}.files.points",
            )
        if trees is not None and not (isinstance(trees, str) and trees):
            raise InputFileError(
                "must name the trees file or be null",
                source=source,
                where=f"{where}.files.trees",
            )
        paths.append(
            CampaignPath(
                path_id=path_id,
                points=folder / points,
                trees=None if trees is None else folder / trees,
            )
        )
    return CampaignFile(source=source, preset=folder / preset, paths=tuple(paths))
