"""`fieldkit fit --model MODEL_3D --paths ... --deposits ...` on a terrain (3-D)
model file: the plan fit (:func:`fieldkit.fit.plan_fit.fit_plan`), held-out scores
against the start and the climatology, the calibrated 3-D model file.

The calibrated model file is the base model file as written, with the fitted
values in place, ``provenance.fit`` added, and every file name of its ``terrain``
block rewritten relative to the folder the calibrated file is written to (resolved
against the base model file's folder first), so the calibrated file reads the same
DEM and releases where it is written, and the pair can be moved together.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import typer

from fieldkit.cli.progress import report_written, step
from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.outputs import OutputSet, write_json

#: Settings of the 3-D plan fit left unset on the command line take these values.
PLAN_DEFAULTS = {"rocks": 60, "seed": 0, "screen": 0}
#: Held-out scoring: rocks per run (on streams no fit uses).
HOLDOUT_ROCKS = 200
#: Held-out scoring: fits (seeds seed, seed + 1, ...) the comparison averages over.
HOLDOUT_SEEDS = 3
#: Virtual campaigns drawn from the calibrated model (fieldkit.fit.plan_power).
VIRTUAL_CAMPAIGNS = 200
#: Folds of the block-climatology bound (every block needs this many runs).
GROUP_FOLDS = 5
#: Scores of the held-out comparison.
HOLDOUT_SCORES = ("energy_fair_m", "distance_crps_fair_m")
#: Options of the profile path fit that a 3-D fit has no use for (refused).
NOT_3D = ("dem", "report", "bootstrap", "section", "profile_points", "material",
          "preset", "at", "measured")  # fmt: skip


def is_terrain_model(path: Path) -> bool:
    """Whether ``path`` is a JSON object with a ``terrain`` block (False for any
    file the model reader will refuse anyway: it names the problem then)."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8-sig"))
    except (OSError, ValueError):
        return False
    return isinstance(data, dict) and "terrain" in data


def default_free3d(model) -> list[str]:
    """e_n, e_t and friction angle of every material."""
    return [
        f"materials.{m}.{k}"
        for m in model.materials
        for k in ("e_n", "e_t", "friction_deg")
    ]


def check_releases_on_dem(runs, terrain, path: Path) -> None:
    """Refuse, naming the file and row, a release off the DEM's surface (before
    any simulation; rows in the file's order, as :func:`read_plan_runs` keeps)."""
    for row, run in enumerate(runs, start=2):
        x, y = (float(v) for v in run.release_xy)
        if not math.isfinite(terrain.height(x, y)):
            raise InputFileError(
                f"run {run.run_id}: release (x {x:g}, y {y:g}) is off the model's "
                "DEM (outside its cell centres or beside nodata)",
                source=str(path),
                where=f"row {row}",
            )


def calibrated_model_dict(model_file: Path, values: dict[str, float],
                          fit_record: dict, output: Path) -> dict:  # fmt: skip
    """The base model file's JSON with ``values`` in place, ``provenance.fit``
    added and the ``terrain`` block's file names relative to ``output``'s folder.

    ``values`` are names of :func:`fieldkit.fit.plan_fit.parameters3d`
    (``materials.<m>.<field>``, ``<effect>.<param>``, ``core.<setting>``).
    """
    from fieldkit.io.csv_table import parse_json

    data = parse_json(model_file.read_text(encoding="utf-8-sig"), str(model_file))
    base = model_file.resolve().parent
    target = Path(output).resolve().parent
    block = data["terrain"]
    for key in ("dem", "materials", "releases"):
        value = block.get(key)
        if isinstance(value, str) and (key == "dem" or value not in data["materials"]):
            path = Path(value)
            path = path if path.is_absolute() else (base / path).resolve()
            block[key] = Path(os.path.relpath(path, target)).as_posix()
    for key, value in values.items():
        parts = key.split(".")
        if parts[0] == "materials":
            data["materials"][parts[1]][parts[2]] = float(value)
        elif parts[0] == "core":
            data.setdefault("core", {})[parts[1]] = float(value)
        else:
            data.setdefault("effects", {}).setdefault(parts[0], {})[parts[1]] = float(
                value
            )
    provenance = data.get("provenance")
    data["provenance"] = {**(provenance if isinstance(provenance, dict) else {}),
                          "fit": fit_record}  # fmt: skip
    return data


def fit_plan_command(
    *,
    model_file: Path,
    releases: Path,
    deposits: Path,
    output: Path,
    json_file: Path | None,
    holdout_releases: Path | None,
    holdout_deposits: Path | None,
    free: list[str] | None,
    bounds: list[str] | None,
    rocks: int | None,
    seed: int | None,
    screen: int | None,
    given: dict,
    tracked_extent: str | None = None,
    holdout_seeds: int | None = None,
    virtual_campaigns: int | None = None,
) -> None:
    """Run the 3-D plan fit (module docstring). ``given``: the other options of
    `fieldkit fit` as given (those of :data:`NOT_3D` are refused)."""
    from fieldkit.cli.fit_paths import parse_bounds
    from fieldkit.fit.plan_fit import fit_plan, read_plan_runs
    from fieldkit.fit.plan_scores import duplicate_runs, unique_runs
    from fieldkit.fit.tracked_extent import clip_model, parse_extent
    from fieldkit.model.model_file import read_model

    bad = [name for name in NOT_3D if given.get(name) not in (None, [], False)]
    if bad:
        raise ArgumentError(
            "is not used by a fit of a terrain (3-D) model (it reads the model's own "
            "DEM and scores deposits in plan)",
            source=bad[0],
        )
    if (holdout_releases is None) != (holdout_deposits is None):
        raise ArgumentError(
            "--holdout-paths and --holdout-deposits go together",
            source="holdout_releases",
        )
    said = []
    if rocks is None:
        rocks = PLAN_DEFAULTS["rocks"]
        said.append(f"rocks {rocks} per run (default)")
    if seed is None:
        seed = PLAN_DEFAULTS["seed"]
        said.append(f"seed {seed} (default)")
    if screen is None:
        screen = PLAN_DEFAULTS["screen"]
        said.append(f"Sobol screen {screen} points (default)")
    if screen < 0:
        raise ArgumentError(f"must be >= 0 (got {screen})", source="screen")
    extent = (
        None
        if tracked_extent is None
        else parse_extent(tracked_extent, "tracked_extent")
    )
    if holdout_seeds is not None and holdout_releases is None:
        raise ArgumentError("needs --holdout-paths and --holdout-deposits",
                            source="holdout_seeds")  # fmt: skip
    if holdout_seeds is None:
        holdout_seeds = HOLDOUT_SEEDS
        if holdout_releases is not None:
            said.append(f"held-out comparison over {holdout_seeds} fits (seeds "
                        f"{seed}..{seed + holdout_seeds - 1}; default)")  # fmt: skip
    if not 1 <= holdout_seeds <= 20:
        raise ArgumentError(f"must be 1..20 (got {holdout_seeds})",
                            source="holdout_seeds")  # fmt: skip
    if virtual_campaigns is not None and holdout_releases is None:
        raise ArgumentError("needs --holdout-paths and --holdout-deposits",
                            source="virtual_campaigns")  # fmt: skip
    if virtual_campaigns is None:
        virtual_campaigns = VIRTUAL_CAMPAIGNS if holdout_releases is not None else 0
        if holdout_releases is not None:
            said.append(
                f"{virtual_campaigns} virtual campaigns from the calibrated model "
                "measure what the held-out test can show (default)"
            )
    if virtual_campaigns != 0 and not 2 <= virtual_campaigns <= 10_000:
        raise ArgumentError(f"must be 0 or 2..10,000 (got {virtual_campaigns})",
                            source="virtual_campaigns")  # fmt: skip
    box = parse_bounds(bounds)
    inputs = [model_file, releases, deposits, holdout_releases, holdout_deposits]
    with OutputSet(inputs=[p for p in inputs if p is not None]) as outputs:
        outputs.plan(output, argument="-o")
        if json_file is not None:
            outputs.plan(json_file, argument="--json")
        model = read_model(model_file, outputs=outputs, terrain=True)
        names = list(free) if free else default_free3d(model)
        if not free:
            said.append("free: e_n, e_t, friction_deg of every material (default)")
        unknown = [n for n in box if n not in names]
        if unknown:
            raise ArgumentError(
                f"{unknown[0]}: a bound of a parameter that is not free "
                f"(free: {', '.join(names)})",
                source="bound",
            )
        runs = read_plan_runs(releases, deposits)
        check_releases_on_dem(runs, model.terrain, releases)
        censor = None
        if extent is not None:
            model_fit, censor = clip_model(model, extent)
            check_releases_on_dem(runs, model_fit.terrain, releases)
            outside = [r.run_id for r in runs if not censor.contains(r.deposit_xy)]
            said.append(
                f"tracked extent {censor.describe()} (the cell centres inside "
                f"{extent.describe()}): every simulated rock ends at its first exit "
                "from it, as an observed last tracked position does; the "
                "climatology's vectors are cut there too"
                + (f"; observed deposits outside it: {', '.join(outside)}"
                   if outside else "")
            )  # fmt: skip
        else:
            model_fit = model
        groups = duplicate_runs(
            np.array([r.release_xy for r in runs]),
            np.array([r.deposit_xy for r in runs]),
        )
        for g in groups:
            said.append(
                f"runs {' = '.join(runs[i].run_id for i in g)} have the same release "
                "and deposit (a run recorded twice): counted once"
            )
        runs = [runs[i] for i in unique_runs(len(runs), groups)]
        hold = None
        if holdout_releases is not None:
            hold = read_plan_runs(holdout_releases, holdout_deposits)
            check_releases_on_dem(hold, model_fit.terrain, holdout_releases)
        for line in said:
            typer.echo(f"note: {line}")
        typer.echo(
            f"3-D plan fit of {model_file.name}: {len(runs)} runs, {rocks} rocks per "
            f"run and evaluation, seed {seed}; objective: mean over runs of the fair "
            "energy score of the simulated deposits in plan against the observed one"
        )
        with step(f"fitting {len(names)} parameters of {model_file.name} "
                  f"({len(runs)} runs x {rocks} rocks per evaluation)"):  # fmt: skip
            result = fit_plan(runs, model_fit, names, rocks=rocks, seed=seed,
                              screen=screen, bounds=box)  # fmt: skip
        fit_record = {
            "method": "3-D plan fit (fieldkit.fit.plan_fit.fit_plan)",
            "objective": "mean fair energy score of deposits in plan [m]",
            "paths": str(releases),
            "deposits": str(deposits),
            "runs": len(runs),
            "rocks": rocks,
            "seed": seed,
            "screen": screen,
            "tracked_extent_m": None
            if censor is None
            else [censor.x_min, censor.y_min, censor.x_max, censor.y_max],
            "evaluations": result.evaluations,
            "objective_start_m": result.objective_start,
            "objective_m": result.objective,
            "exited_share": result.exited_share,
            "parameters": {
                n: {
                    "start": float(s),
                    "value": float(v),
                    "lower": float(lo),
                    "upper": float(hi),
                }
                for n, s, v, lo, hi in zip(
                    result.names,
                    result.start,
                    result.values,
                    result.lower,
                    result.upper,
                    strict=True,
                )
            },  # fmt: skip
        }
        held_lines: list[str] = []
        if hold is not None:
            seeds = [seed + k for k in range(holdout_seeds)]
            held, comparisons = _holdout(
                runs, hold, result, model_fit, names, censor,
                rocks=rocks, seeds=seeds, screen=screen, bounds=box,
            )  # fmt: skip
            held_lines += held
            fit_record["holdout"] = {
                "paths": str(holdout_releases),
                "deposits": str(holdout_deposits),
                "runs": len(hold),
                "rocks": HOLDOUT_ROCKS,
                "seeds": seeds,
                "comparisons": comparisons,
            }
            attainable_lines, attainable = _attainable(
                runs, hold, result.model, censor, seed=seed,
                campaigns=virtual_campaigns,
            )  # fmt: skip
            held_lines += attainable_lines
            fit_record["holdout"]["attainable"] = attainable
        data = calibrated_model_dict(
            model_file, dict(zip(result.names, result.values, strict=True)),
            fit_record, output,
        )  # fmt: skip
        write_json(output, data, outputs)
        if json_file is not None:
            write_json(json_file, fit_record, outputs)
        written = outputs.commit()
    for line in result.lines():
        typer.echo(line)
    for line in held_lines:
        typer.echo(line)
    typer.echo(
        "note: the calibrated model file keeps the base file's terrain block, its "
        "file names relative to the calibrated file's folder"
    )
    report_written(written)


def _holdout(runs, hold, result, model_fit, names, censor, *, rocks, seeds, screen,
             bounds) -> tuple[list[str], list[dict]]:  # fmt: skip
    """Held-out scores of the calibrated model (refitted at every seed after the
    first), the start and the climatology; paired comparisons over the seeds."""
    from fieldkit.fit.plan_fit import HOLDOUT_STREAM, fit_plan, plan_ensembles
    from fieldkit.fit.plan_scores import (
        mean_direction,
        paired_comparison,
        score_runs,
    )
    from fieldkit.fit.tracked_extent import censored_climatology

    cal_rel = np.array([r.release_xy for r in runs])
    cal_dep = np.array([r.deposit_xy for r in runs])
    rel = np.array([r.release_xy for r in hold])
    dep = np.array([r.deposit_xy for r in hold])
    u = mean_direction(cal_rel, cal_dep)
    per_seed: dict[str, list] = {"calibrated": [], "start": []}
    with step(f"scoring {len(hold)} held-out runs ({HOLDOUT_ROCKS} rocks each, "
              f"calibrated and start) over {len(seeds)} seed(s)"
              + (", refitting at each" if len(seeds) > 1 else "")):  # fmt: skip
        for k, s in enumerate(seeds):
            fitted = result.model if k == 0 else fit_plan(
                runs, model_fit, names, rocks=rocks, seed=s, screen=screen,
                bounds=bounds).model  # fmt: skip
            for name, m in (("calibrated", fitted), ("start", model_fit)):
                ens = plan_ensembles(m, hold, HOLDOUT_ROCKS, s, stream=HOLDOUT_STREAM)
                per_seed[name].append(score_runs(ens.deposits_xy, rel, dep, u))
    clim, _ = censored_climatology(cal_rel, cal_dep, rel, censor)
    clim_scores = score_runs(clim, rel, dep, u)
    lines = [
        f"held-out: {len(hold)} runs, {HOLDOUT_ROCKS} rocks per run on streams no "
        f"fit uses, {len(seeds)} fit(s) (seeds {', '.join(map(str, seeds))}); SE "
        "over runs of the seed-averaged differences; lower is better, A - B < 0: "
        "A better"
    ]
    comparisons = []
    for other in ("start", "climatology"):
        for score in HOLDOUT_SCORES:
            a = np.array([getattr(p, score) for p in per_seed["calibrated"]])
            if other == "climatology":
                b = np.asarray(getattr(clim_scores, score))
            else:
                b = np.array([getattr(p, score) for p in per_seed[other]])
            c = paired_comparison(a, b, score, "calibrated", other, seeds=seeds)
            lines += c.lines()
            comparisons.append(c.to_dict())
    return lines, comparisons


def _attainable(
    runs, hold, model, censor, *, seed, campaigns
) -> tuple[list[str], dict]:
    """What the held-out test can show (:mod:`fieldkit.fit.plan_power`): virtual
    campaigns from the calibrated model, and the block-climatology bound where
    every block has :data:`GROUP_FOLDS` runs among the calibration and held-out
    runs."""
    from fieldkit.fit.plan_power import group_climatology_skill, virtual_campaigns

    lines = [
        "what this held-out test can show (the climatology's fair score is unbiased: "
        "a forecast beats it only by what it knows of each run):"
    ]
    out: dict = {}
    if campaigns:
        with step(f"{campaigns} virtual campaigns from the calibrated model"):
            v = virtual_campaigns(model, runs, hold, campaigns=campaigns,
                                  holdout_rocks=HOLDOUT_ROCKS, seed=seed,
                                  extent=censor)  # fmt: skip
        lines += v.lines()
        out["virtual_campaigns"] = v.to_dict()
    every = [*runs, *hold]
    labels = [r.group for r in every]
    counts = {g: labels.count(g) for g in set(labels)}
    if all(labels) and len(counts) > 1 and min(counts.values()) >= GROUP_FOLDS:
        g = group_climatology_skill(
            np.array([r.release_xy for r in every]),
            np.array([r.deposit_xy for r in every]),
            labels, k=GROUP_FOLDS, extent=censor, split_runs=len(hold), label="block",
        )  # fmt: skip
        lines += g.lines()
        lines.append(
            "  note: the block bound reads every run, held-out ones included "
            "(a property of the data, used by no fit)"
        )
        out["block_climatology"] = g.to_dict()
    elif all(labels) and len(counts) > 1:
        lines.append(f"  block-climatology bound: not computed (a block has fewer "
                     f"than {GROUP_FOLDS} runs)")  # fmt: skip
    return (lines if len(lines) > 1 else []), out
