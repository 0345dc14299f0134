"""`fieldkit fit --paths`: calibrate the simulator on observed runs (issue 11).

Glue only: read the observations, the DEM and the base model, build each run's
section (:func:`fieldkit.fit.path_sections.path_runs`), fit
(:func:`fieldkit.fit.path_fit.fit_paths`), score the held-out runs
(:func:`fieldkit.fit.path_validation.validate`) and write the outputs.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import typer

from fieldkit.errors import ArgumentError
from fieldkit.outputs import OutputSet, write_json


def default_free(model) -> list[str]:
    """e_n, e_t and friction angle of every material of ``model``."""
    return [
        f"materials.{m}.{k}"
        for m in model.materials
        for k in ("e_n", "e_t", "friction_deg")
    ]


def parse_bounds(items: list[str] | None) -> dict[str, tuple[float, float]]:
    """``NAME=LO,HI`` items -> {name: (lo, hi)} (one-line error on a bad one)."""
    out = {}
    for item in items or []:
        name, _, rest = item.partition("=")
        parts = rest.split(",")
        try:
            lo, hi = (float(v) for v in parts)
        except ValueError:
            raise ArgumentError(
                f"{item!r}: expected NAME=LO,HI (a parameter and two numbers)",
                source="bound",
            ) from None
        if not (name and lo < hi):
            raise ArgumentError(
                f"{item!r}: expected NAME=LO,HI with LO < HI", source="bound"
            )
        out[name.strip()] = (lo, hi)
    return out


def fit_paths_command(
    *,
    releases: Path,
    deposits: Path | None,
    dem: Path | None,
    model_file: Path,
    output: Path,
    json_file: Path | None,
    report: Path | None,
    holdout_releases: Path | None,
    holdout_deposits: Path | None,
    free: list[str] | None,
    rocks: int,
    seed: int,
    bootstrap: int,
    section: str,
    screen: int = 0,
    bounds: list[str] | None = None,
) -> None:
    """Run the path-level fit (see the command's help)."""
    from fieldkit.fit.path_fit import fit_paths
    from fieldkit.fit.path_runs import section_runs
    from fieldkit.fit.path_sections import path_runs
    from fieldkit.fit.path_validation import validate
    from fieldkit.impact_table import ImpactTable
    from fieldkit.io.dem import read_dem
    from fieldkit.io.path_observations import (
        observations_from_impact_table,
        read_release_deposit,
    )
    from fieldkit.model.model_file import read_model, write_model

    box = parse_bounds(bounds)
    on_dem = dem is not None
    inputs = [releases, model_file] + ([deposits, dem] if on_dem else [])
    holdout = holdout_releases is not None
    if holdout:
        inputs += [holdout_releases, holdout_deposits]
    with OutputSet(inputs=inputs) as outputs:
        outputs.plan(output, argument="-o")
        if json_file is not None:
            outputs.plan(json_file, argument="--json")
        if report is not None:
            outputs.plan(report / "holdout.png", argument="--report")
        base = read_model(model_file, outputs=outputs)
        if on_dem:
            grid = read_dem(dem)
            calibration = path_runs(
                read_release_deposit(releases, deposits), grid, base,
                section=section, min_runs=3,
            )  # fmt: skip
        else:
            table = ImpactTable.read(releases).derive()
            calibration = section_runs(observations_from_impact_table(table), base)
        held = (
            path_runs(
                read_release_deposit(holdout_releases, holdout_deposits),
                grid,
                base,
                section="descent",
            )  # fmt: skip
            if holdout
            else None
        )
        names = free or default_free(base)
        result = fit_paths(
            calibration, base, names, rocks=rocks, seed=seed, bootstrap=bootstrap,
            progress=lambda line: typer.echo(line, err=True), screen=screen,
            bounds=box,
        )  # fmt: skip
        fitted = dict(zip(result.names, map(float, result.values), strict=True))
        summary = result.to_dict()
        summary["section"] = section if on_dem else "the model's own profile"
        if held is not None:
            typer.echo("scoring the held-out runs", err=True)
            validation = validate(held, calibration, fitted, rocks=rocks, seed=seed)
            summary["holdout"] = validation["forecasts"]
            summary["holdout_path_ids"] = validation["path_ids"]
            if report is not None:
                from fieldkit.viz.holdout_figure import write_holdout_figure

                write_holdout_figure(
                    report / "holdout.png", validation, outputs=outputs
                )
        provenance = {**base.provenance, "fit_paths": summary}
        write_model(
            replace(result.model, provenance=provenance), output, outputs=outputs
        )
        if json_file is not None:
            write_json(json_file, summary, outputs)
        outputs.commit()
    for p in summary["parameters"]:
        lo, hi = p["interval90"]
        flag = "" if p["pinned"] else "  [not pinned down by these runs]"
        typer.echo(
            f"{p['name']}: {p['value']:.4g} ± {p['stderr']:.2g} "
            f"(90 % {lo:.4g} to {hi:.4g}; start {p['start']:.4g}){flag}"
        )
    if result.kinds == ["runout_m"]:
        typer.echo(
            f"mean CRPS of the {summary['n_runs']} calibration runs: "
            f"{summary['objective_start']:.2f} -> {summary['objective_optimum']:.2f} m"
        )
    else:
        for kind in result.kinds:
            typer.echo(
                f"{kind} ({result.kind_counts[kind]} observed): mean CRPS "
                f"{result.kind_start[kind]:.3f} -> {result.kind_optimum[kind]:.3f}"
            )
    for name, h in summary.get("holdout", {}).items():
        typer.echo(
            f"held out ({h['n_runs']} runs), {name}: mean CRPS "
            f"{h['mean_crps']:.2f} m, 50 % / 90 % coverage {h['coverage_50']:.0%} / "
            f"{h['coverage_90']:.0%}, median |error| {h['median_abs_error']:.1f} m, "
            f"mean runout {h['mean_predicted']:.1f} vs observed "
            f"{h['mean_observed']:.1f} m"
        )
    typer.echo(f"calibrated model -> {output}")
