"""`fieldkit fit --paths`: calibrate the simulator on observed runs (issue 11).

Glue only: read the observations, the DEM and the base model, build each run's
section (:func:`fieldkit.fit.path_sections.path_runs`), fit
(:func:`fieldkit.fit.path_fit.fit_paths`), score the held-out runs
(:func:`fieldkit.fit.path_validation.validate`) and write the outputs.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import typer

from fieldkit.errors import ArgumentError
from fieldkit.fit.path_fit import MIN_BOOTSTRAP_SE
from fieldkit.outputs import OutputSet, write_json, write_text


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
        if not (math.isfinite(lo) and math.isfinite(hi)):
            raise ArgumentError(
                f"{item!r}: LO and HI must be finite numbers", source="bound"
            )
        if not (name and lo < hi):
            raise ArgumentError(
                f"{item!r}: expected NAME=LO,HI with LO < HI", source="bound"
            )
        out[name.strip()] = (lo, hi)
    return out


def _value(p: dict) -> str:
    """``value ± SE (90 % lo to hi; start s)``, without ± when there is no SE."""
    lo, hi = p["interval90"]
    if p["stderr"] is None:
        span = f"; the runs cannot tell it from {lo:.4g} to {hi:.4g}" if hi > lo else ""
        return f"{p['value']:.4g} (no standard error{span}; start {p['start']:.4g})"
    return (
        f"{p['value']:.4g} ± {p['stderr']:.2g} (90 % {lo:.4g} to {hi:.4g}; "
        f"start {p['start']:.4g})"
    )


def _kind_lines(result, summary: dict) -> list[str]:
    """The CRPS before -> after lines, one per scored kind."""
    if result.kinds == ["runout_m"]:
        return [
            f"mean CRPS of the {summary['n_runs']} calibration runs: "
            f"{summary['objective_start']:.2f} -> {summary['objective_optimum']:.2f} m"
        ]
    return [
        f"{kind} ({result.kind_counts[kind]} observed): mean CRPS "
        f"{result.kind_start[kind]:.3f} -> {result.kind_optimum[kind]:.3f}"
        for kind in result.kinds
    ]


def _holdout_lines(summary: dict) -> list[str]:
    return [
        f"held out ({h['n_runs']} runs), {name}: mean CRPS "
        f"{h['mean_crps']:.2f} m, 50 % / 90 % coverage {h['coverage_50']:.0%} / "
        f"{h['coverage_90']:.0%}, median |error| {h['median_abs_error']:.1f} m, "
        f"mean runout {h['mean_predicted']:.1f} vs observed "
        f"{h['mean_observed']:.1f} m"
        for name, h in summary.get("holdout", {}).items()
    ]


def report_markdown(
    summary: dict, result, *, inputs: list[str], model_file: Path, mapping: list[str]
) -> str:
    """report.md of a path fit: what was fitted, values, CRPS per kind, figures."""
    from fieldkit.fit.path_fit import MIN_BOOTSTRAP_SE

    lines = [
        "# Path fit",
        "",
        f"observations: {', '.join(f'`{p}`' for p in inputs)}; base model: "
        f"`{model_file}`; sections: {summary['section']}",
        "",
        f"{summary['n_runs']} run(s), {summary['rocks']} rocks per run and "
        f"evaluation, seed {summary['seed']}, {summary['n_evaluations']} "
        f"evaluations; objective: {summary['objective']}.",
        "",
    ]
    lines += [f"* {m}" for m in mapping] + ([""] if mapping else [])
    boot = summary["bootstrap_size"]
    se = (
        f"± is the standard error: the SD of {boot} bootstrap refits"
        if boot >= MIN_BOOTSTRAP_SE
        else f"no standard errors: {boot} bootstrap resamples are fewer than "
        f"{MIN_BOOTSTRAP_SE}; the range is the values the runs cannot tell from the "
        "optimum (the objective's slice)"
    )
    interval = "90 % interval" if boot >= MIN_BOOTSTRAP_SE else "runs cannot tell apart"
    lines += [
        "## Fitted parameters",
        "",
        f"{se}.",
        "",
        f"| parameter | start | fitted | standard error | {interval} | bounds "
        "| pinned down |",
        "|---|---|---|---|---|---|---|",
    ]
    for p in summary["parameters"]:
        lo, hi = p["interval90"]
        err = "—" if p["stderr"] is None else f"{p['stderr']:.2g}"
        lines.append(
            f"| `{p['name']}` | {p['start']:.4g} | {p['value']:.4g} | {err} "
            f"| {lo:.4g} to {hi:.4g} | {p['bounds'][0]:g} to {p['bounds'][1]:g} "
            f"| {'yes' if p['pinned'] else 'no'} |"
        )
    lines += [
        "",
        "## Mean CRPS, start -> calibrated",
        "",
        "| observed | count | start | calibrated |",
        "|---|---|---|---|",
    ]
    for k in summary["kinds"]:
        lines.append(
            f"| {k['kind']} | {k['observations']} | {k['crps_start']:.4g} "
            f"| {k['crps_optimum']:.4g} |"
        )
    if summary.get("holdout"):
        lines += ["", "## Held-out runs", ""]
        lines += [f"* {x}" for x in _holdout_lines(summary)]
        lines += ["", "![held-out runouts](holdout.png)"]
    if summary["notes"]:
        lines += ["", "## Notes", ""] + [f"* {n}" for n in summary["notes"]]
    return "\n".join(lines) + "\n"


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
    material: list[str] | None = None,
    preset: Path | None = None,
) -> None:
    """Run the path-level fit (see the command's help)."""
    from fieldkit.cli.common import note
    from fieldkit.cli.material_options import mapped_table
    from fieldkit.cli.progress import report_written, step
    from fieldkit.fit.material_map import profile_disagreements
    from fieldkit.fit.path_fit import check_settings, fit_paths
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

    check_settings(rocks=rocks, seed=seed, bootstrap=bootstrap, screen=screen)
    box = parse_bounds(bounds)
    on_dem = dem is not None
    if on_dem and (material or preset is not None):
        raise ArgumentError(
            "material mappings apply to an ImpactTable (--paths with a table from "
            "reduce); runs on a DEM take their materials from the model",
            source="material",
        )
    inputs = [releases, model_file] + ([deposits, dem] if on_dem else [])
    holdout = holdout_releases is not None
    if holdout:
        inputs += [holdout_releases, holdout_deposits]
    with OutputSet(inputs=[*inputs, preset]) as outputs:
        outputs.confine(report)
        # plan exactly what will be written, before any long step
        outputs.plan(output, argument="-o")
        if json_file is not None:
            outputs.plan(json_file, argument="--json")
        if report is not None:
            outputs.plan(report / "report.md", argument="--report")
            if holdout:
                outputs.plan(report / "holdout.png", argument="--report")
        base = read_model(model_file, outputs=outputs)
        mapping = []
        material_map: dict[str, str] = {}
        material_check = None
        if on_dem:
            grid = read_dem(dem)
            with step(f"cutting the sections of {releases.name} from {dem.name}"):
                calibration = path_runs(
                    read_release_deposit(releases, deposits), grid, base,
                    section=section, min_runs=3,
                )  # fmt: skip
        else:
            table = ImpactTable.read(releases)
            mapped = mapped_table(table, base, material, preset, required=False)
            mapping, material_map = mapped.notes, mapped.provenance()
            calibration = section_runs(
                observations_from_impact_table(mapped.table.derive()), base
            )
            profile = base.profile
            compared, differ = profile_disagreements(
                mapped.table, profile.x_m, profile.material
            )
            check = (
                f"the table's materials (as mapped) agree with the model's profile at "
                f"{compared - len(differ)} of {compared} surveyed points"
                + (f"; they differ at {'; '.join(differ[:3])}" if differ else "")
                + (f" and {len(differ) - 3} more" if len(differ) > 3 else "")
                + (" (the fit uses the profile's)" if differ else "")
            )
            note(check)
            mapping = [*mapping, check]
            material_check = {"points_compared": compared, "differences": differ}
        held = None
        if holdout:
            with step("cutting the held-out sections"):
                held = path_runs(
                    read_release_deposit(holdout_releases, holdout_deposits),
                    grid, base, section="descent",
                )  # fmt: skip
        names = free or default_free(base)
        result = fit_paths(
            calibration, base, names, rocks=rocks, seed=seed, bootstrap=bootstrap,
            progress=lambda line: typer.echo(line, err=True), screen=screen,
            bounds=box, step=step,
        )  # fmt: skip
        fitted = dict(zip(result.names, map(float, result.values), strict=True))
        summary = result.to_dict()
        summary["section"] = section if on_dem else "the model's own profile"
        summary["material_map"] = material_map
        if material_check is not None:
            summary["material_check"] = material_check
        if held is not None:
            with step(f"scoring {len(held)} held-out runs ({rocks} rocks each)"):
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
        if report is not None:
            text = report_markdown(
                summary, result, inputs=[str(p) for p in inputs if p != model_file],
                model_file=model_file, mapping=mapping,
            )  # fmt: skip
            write_text(report / "report.md", text, outputs)
        written = outputs.commit()
    for p in summary["parameters"]:
        flag = "" if p["pinned"] else "  [not pinned down by these runs]"
        typer.echo(f"{p['name']}: {_value(p)}{flag}")
    if result.bootstrap.shape[0] < MIN_BOOTSTRAP_SE:
        typer.echo(
            f"no standard errors or correlations: --bootstrap {bootstrap} is fewer "
            f"than the {MIN_BOOTSTRAP_SE} resamples a standard error needs"
        )
    for line in _kind_lines(result, summary) + _holdout_lines(summary):
        typer.echo(line)
    report_written(written)
