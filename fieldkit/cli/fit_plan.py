"""`fieldkit fit --model MODEL_3D --paths ... --deposits ...` on a terrain (3-D)
model file: the plan fit (:func:`fieldkit.fit.plan_fit.fit_plan`), held-out scores
against the start and the climatology, the calibrated 3-D model file.

The calibrated model file is the base model file as written, with the fitted
values in place, ``provenance.fit`` added, and every file name of its ``terrain``
block made absolute (resolved against the base model file's folder), so the file
reads from wherever it is written.
"""

from __future__ import annotations

import json
import math
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
                          fit_record: dict) -> dict:  # fmt: skip
    """The base model file's JSON with ``values`` in place, ``provenance.fit``
    added and the ``terrain`` block's file names absolute.

    ``values`` are names of :func:`fieldkit.fit.plan_fit.parameters3d`
    (``materials.<m>.<field>``, ``<effect>.<param>``, ``core.<setting>``).
    """
    from fieldkit.io.csv_table import parse_json

    data = parse_json(model_file.read_text(encoding="utf-8-sig"), str(model_file))
    base = model_file.resolve().parent
    block = data["terrain"]
    for key in ("dem", "materials", "releases"):
        value = block.get(key)
        if isinstance(value, str) and (key == "dem" or value not in data["materials"]):
            path = Path(value)
            block[key] = str(path if path.is_absolute() else (base / path).resolve())
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
) -> None:
    """Run the 3-D plan fit (module docstring). ``given``: the other options of
    `fieldkit fit` as given (those of :data:`NOT_3D` are refused)."""
    from fieldkit.cli.fit_paths import parse_bounds
    from fieldkit.fit.plan_fit import (
        HOLDOUT_STREAM,
        fit_plan,
        plan_ensembles,
        read_plan_runs,
    )
    from fieldkit.fit.plan_scores import (
        duplicate_runs,
        mean_direction,
        paired_comparison,
        plan_climatology,
        score_runs,
        unique_runs,
    )
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
            check_releases_on_dem(hold, model.terrain, holdout_releases)
        for line in said:
            typer.echo(f"note: {line}")
        typer.echo(
            f"3-D plan fit of {model_file.name}: {len(runs)} runs, {rocks} rocks per "
            f"run and evaluation, seed {seed}; objective: mean over runs of the fair "
            "energy score of the simulated deposits in plan against the observed one"
        )
        with step(f"fitting {len(names)} parameters of {model_file.name} "
                  f"({len(runs)} runs x {rocks} rocks per evaluation)"):  # fmt: skip
            result = fit_plan(runs, model, names, rocks=rocks, seed=seed,
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
            cal_rel = np.array([r.release_xy for r in runs])
            cal_dep = np.array([r.deposit_xy for r in runs])
            rel = np.array([r.release_xy for r in hold])
            dep = np.array([r.deposit_xy for r in hold])
            u = mean_direction(cal_rel, cal_dep)
            with step(f"scoring {len(hold)} held-out runs ({HOLDOUT_ROCKS} rocks "
                      "each, calibrated and start)"):  # fmt: skip
                scores = {
                    name: score_runs(
                        plan_ensembles(
                            m, hold, HOLDOUT_ROCKS, seed, stream=HOLDOUT_STREAM
                        ).deposits_xy,
                        rel,
                        dep,
                        u,
                    )  # fmt: skip
                    for name, m in (("calibrated", result.model), ("start", model))
                }
            scores["climatology"] = score_runs(
                plan_climatology(cal_rel, cal_dep, rel), rel, dep, u
            )
            held_lines.append(
                f"held-out: {len(hold)} runs, {HOLDOUT_ROCKS} rocks per run on streams "
                f"no fit uses, one seed ({seed}): the SE is over runs only; "
                "lower is better, A - B < 0: A better"
            )
            comparisons = []
            for other in ("start", "climatology"):
                for score in HOLDOUT_SCORES:
                    c = paired_comparison(
                        np.asarray(getattr(scores["calibrated"], score))[None, :],
                        np.asarray(getattr(scores[other], score))[None, :],
                        score, "calibrated", other, seeds=[seed],
                    )  # fmt: skip
                    held_lines += c.lines()
                    comparisons.append(c.to_dict())
            fit_record["holdout"] = {
                "paths": str(holdout_releases),
                "deposits": str(holdout_deposits),
                "runs": len(hold),
                "rocks": HOLDOUT_ROCKS,
                "seed": seed,
                "comparisons": comparisons,
            }
        data = calibrated_model_dict(
            model_file, dict(zip(result.names, result.values, strict=True)),
            fit_record,
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
        "note: the calibrated model file keeps the base file's terrain block with "
        "its file names made absolute"
    )
    report_written(written)
