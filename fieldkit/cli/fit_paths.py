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


#: Scored kinds in words with units (report and console).
KIND_WORDS = {
    "runout_m": "runout along the section (m)",
    "flight_height_m": "normal flight height between impacts (m)",
    "impact_spacing_m": "horizontal spacing of consecutive impacts (m)",
    "speed_mps": "speed at the observed impacts (m/s)",
}
#: ``--section`` values in words.
SECTION_WORDS = {
    "descent": "each run's steepest descent from its release on the DEM",
    "release-deposit": "the straight line from each run's release to its deposit "
    "on the DEM",
}


def plural(count: int, noun: str) -> str:
    """``1 run``, ``2 runs``.

    Examples
    --------
    >>> plural(1, "run"), plural(18, "run")
    ('1 run', '18 runs')
    """
    return f"{count} {noun}{'' if count == 1 else 's'}"


def parameter_words(name: str) -> str:
    """A fitted parameter in words with its unit (``materials.colluvium.e_n`` ->
    ``colluvium: normal restitution e_n``; units where it has one).

    Examples
    --------
    >>> parameter_words("materials.meadow.friction_deg")
    'meadow: friction angle (deg)'
    >>> parameter_words("velocity_scaled_restitution.k_mps")[-5:]
    '(m/s)'
    >>> parameter_words("core.drag_dt_s")
    'simulator setting drag_dt_s (s)'
    """
    from fieldkit.diagnose.labels import parameter
    from fieldkit.model.model_file import CORE_DEFAULTS

    parts = name.split(".")
    if parts[0] == "core" and len(parts) == 2 and parts[1] in CORE_DEFAULTS:
        return f"simulator setting {parts[1]} ({CORE_DEFAULTS[parts[1]][3]})"
    words, unit = parameter(name)
    if words == name:
        return name
    if unit in ("", "-") or words.endswith(f"({unit})"):
        return words
    return f"{words} ({unit})"


def _value(p: dict) -> str:
    """``value ± SE (90 % lo to hi; start s)``, without ± when there is no SE."""
    lo, hi = p["interval90"]
    if p["stderr"] is None:
        if p.get("range_resolved", True):
            span = f"; the runs cannot tell it from {lo:.4g} to {hi:.4g}"
        else:
            span = (
                f"; no range resolved: the values the runs cannot tell from it span "
                f"less than the slice resolves, {p['slice_resolution']:.2g}"
            )
        return f"{p['value']:.4g} (no standard error{span}; start {p['start']:.4g})"
    bound = ", a lower bound" if p.get("stderr_is_lower_bound") else ""
    span = (
        f"90 % {lo:.4g} to {hi:.4g}" if p.get("range_resolved", True)
        else f"no 90 % range resolved: narrower than {p['slice_resolution']:.2g}"
    )  # fmt: skip
    return (
        f"{p['value']:.4g} ± {p['stderr']:.2g}{bound} ({span}; start {p['start']:.4g})"
    )


def _flag(p: dict) -> str:
    """The console's verdict on a parameter (empty when pinned down)."""
    if p["pinned"] is None:
        return "  [no evidence that these runs pin it down]"
    return "" if p["pinned"] else "  [not pinned down by these runs]"


def uncertainty_lines(summary: dict) -> list[str]:
    """What ± and the range mean, said where they are printed (before the values)."""
    boot, n_runs = summary["bootstrap_size"], summary["n_runs"]
    if boot < MIN_BOOTSTRAP_SE:
        return ([ONE_PATH] if n_runs == 1 else []) + [
            f"no standard errors or correlations: --bootstrap {boot} is fewer than "
            f"the {MIN_BOOTSTRAP_SE} resamples a standard error needs; the range is "
            "the values the runs cannot tell from the optimum (the objective's slice)"
        ]
    t, dof = summary["t_quantile"], summary["t_dof"]
    lines = [
        f"± is the standard error (SD of {boot} bootstrap refits); 90 % is ± "
        f"{t:.2f} standard errors (Student's t with {plural(dof, 'degree')} of "
        "freedom), widened to the objective's slice where that is wider"
    ]
    if n_runs == 1:
        lines.insert(0, ONE_PATH)
    return lines


#: Said with the intervals of a fit to one surveyed path (issue 20).
ONE_PATH = (
    "one surveyed path: resampling its points is a lower bound on the uncertainty of "
    "a site's parameters (another boulder, another path); its observed values are "
    "not independent, so every standard error, 90 % range and profile interval "
    "below is a lower bound (more paths give honest ones)"
)


def profile_lines(summary: dict) -> list[str]:
    """The profile intervals beside the bootstrap's, with the seed spread and the
    profile's cost (none when the fit made no profile)."""
    prof = summary.get("profile")
    if not prof:
        return []
    sd = prof["optimum_seed_sd"]
    noise = (
        f"objective at the optimum {prof['objective_optimum']:.4g}, SD over "
        f"{prof['seeds']} other seeds {sd:.2g} "
        f"({100 * sd / prof['objective_optimum']:.1f} % of it: Monte Carlo noise)"
        if sd is not None and prof["objective_optimum"] > 0
        else "no seed spread (--profile-points with fewer than 2 seeds)"
    )
    lines = [
        f"profile ({prof['points']} values across each bound range, the other "
        "parameters re-optimised; a value is compatible when its excess over the "
        "optimum is below 1.645 × √(SE over observations² + SD over "
        f"{prof['seeds']} seeds²)): {noise}; cost {prof['evaluations']} evaluations, "
        f"{prof['wall_s']:.1f} s"
    ]
    params = {p["name"]: p for p in summary["parameters"]}
    for q, (slo, shi) in zip(prof["parameters"], summary["slice_compatible"],
                             strict=True):  # fmt: skip
        lo, hi = q["interval90"]
        p = params[q["name"]]
        boot = (
            f"90 % interval (bootstrap) {p['interval90'][0]:.4g} to "
            f"{p['interval90'][1]:.4g}"
            if p["stderr"] is not None
            else "no bootstrap interval"
        )
        lines.append(
            f"  {q['name']}: profile {lo:.4g} to {hi:.4g}; {boot}; slice {slo:.4g} "
            f"to {shi:.4g}; widest: {q['widest']}"
        )
    return lines


def _kind_lines(result, summary: dict) -> list[str]:
    """The CRPS before -> after lines, one per scored kind."""
    if result.kinds == ["runout_m"]:
        return [
            f"mean CRPS of the {plural(summary['n_runs'], 'calibration run')}: "
            f"{summary['objective_start']:.2f} -> {summary['objective_optimum']:.2f} m"
        ]
    return [
        f"{kind} ({result.kind_counts[kind]} observed): mean CRPS "
        f"{result.kind_start[kind]:.3f} -> {result.kind_optimum[kind]:.3f}"
        for kind in result.kinds
    ]


def _holdout_lines(summary: dict) -> list[str]:
    lines = [
        f"held out ({plural(h['n_runs'], 'run')}), {name}: mean CRPS "
        f"{h['mean_crps']:.2f} m, 50 % / 90 % coverage {h['coverage_50']:.0%} / "
        f"{h['coverage_90']:.0%}, median |error| {h['median_abs_error']:.1f} m, "
        f"mean runout {h['mean_predicted']:.1f} vs observed "
        f"{h['mean_observed']:.1f} m"
        for name, h in summary.get("holdout", {}).items()
    ]
    from fieldkit.fit.path_validation import RELEASE_STOP_M

    what = {
        "left_section": "rocks left the section (runout censored at its end)",
        "stopped_at_release": f"rocks stopped within {RELEASE_STOP_M:g} m of the "
        "release",
    }
    for name, marks in summary.get("holdout_censoring", {}).items():
        for key, runs in marks.items():
            if runs:
                listed = ", ".join(f"{pid} {share:.0%}" for pid, share in runs.items())
                lines.append(f"held out, {name}: {what[key]}: {listed}")
    return lines


def report_markdown(
    summary: dict, result, *, inputs: list[str], model_file: Path, mapping: list[str],
    design: list[str] = (),
) -> str:  # fmt: skip
    """report.md of a path fit: the design quantities (``design``, first), what was
    fitted, values, CRPS per kind, figures."""
    n_runs = summary["n_runs"]
    objective = (
        "mean CRPS of the observed runouts (m)"
        if result.kinds == ["runout_m"]
        else "the sum over what was observed of its mean CRPS divided by its value "
        f"at the start ({len(result.kinds)} at the start)"
    )
    lines = [
        "# Path fit",
        "",
        *design,
        f"Observations: {', '.join(f'`{p}`' for p in inputs)}; base model: "
        f"`{model_file}`; sections: "
        f"{SECTION_WORDS.get(summary['section'], summary['section'])}.",
        "",
        f"{plural(n_runs, 'run')}, {summary['rocks']} simulated rocks per run and "
        f"evaluation, seed {summary['seed']}, "
        f"{plural(summary['n_evaluations'], 'evaluation')} of the objective: "
        f"{objective}. The CRPS (continuous ranked probability score) is the mean "
        "absolute error of a distribution of simulated values against the observed "
        "one, in the observed value's unit; smaller is better.",
        "",
    ]
    lines += [f"* {m}" for m in mapping] + ([""] if mapping else [])
    boot = summary["bootstrap_size"]
    lower_bound = n_runs == 1 and boot >= MIN_BOOTSTRAP_SE
    if boot >= MIN_BOOTSTRAP_SE:
        t, dof = summary["t_quantile"], summary["t_dof"]
        explain = [
            f"± is the standard error: the SD of the fitted values over {boot} "
            "bootstrap refits.",
            "",
            f"The 90 % interval is the fitted value ±{t:.1f} SE: Student's t (95 % "
            f"quantile) with {plural(dof, 'degree')} of freedom "
            f"(±{t:.1f} SE with {dof}, ±1.76 with 14, ±1.645 with many), because a "
            "standard error from few resampled units is itself uncertain. Where the "
            "objective's slice cannot tell values further out from the optimum, the "
            "interval is widened to them.",
        ]
        if lower_bound:
            explain += [
                "",
                "**Lower bounds.** One surveyed path: the bootstrap resamples its "
                "own observed values (flight heights, impact spacings, speeds), "
                "which are not independent of each other, so every standard error "
                "and 90 % interval below understates the uncertainty. Several "
                "surveyed paths give honest ones.",
            ]
        interval = "90 % interval"
    else:
        explain = [
            f"No standard errors: {boot} bootstrap resamples are fewer than the "
            f"{MIN_BOOTSTRAP_SE} a standard error needs. The range is the values the "
            "runs cannot tell from the optimum (the objective sliced across each "
            "parameter's bounds, the others at the optimum); where none is resolved "
            "that is no evidence either way."
        ]
        interval = "values the runs cannot tell from the optimum"
    se_head = "standard error (a lower bound)" if lower_bound else "standard error"
    lines += [
        "## Fitted parameters",
        "",
        *explain,
        "",
        f"| parameter | start | fitted | {se_head} | {interval} | search bounds "
        "| pinned down by the runs |",
        "|---|---|---|---|---|---|---|",
    ]
    pinned_words = {
        True: "yes, on a lower-bound interval" if lower_bound else "yes",
        False: "no",
        None: "no evidence (no range resolved)",
    }
    for p in summary["parameters"]:
        lo, hi = p["interval90"]
        err = "none" if p["stderr"] is None else f"{p['stderr']:.2g}"
        if lower_bound and p["stderr"] is not None:
            err = f"at least {err}"
        resolved = p.get("range_resolved", True)
        span = (
            f"{lo:.4g} to {hi:.4g}" if resolved
            else f"none resolved (narrower than {p['slice_resolution']:.2g})"
        )  # fmt: skip
        if lower_bound and resolved:
            span = f"at least {span}"
        lines.append(
            f"| {parameter_words(p['name'])} | {p['start']:.4g} | {p['value']:.4g} "
            f"| {err} | {span} | {p['bounds'][0]:g} to {p['bounds'][1]:g} "
            f"| {pinned_words[p['pinned']]} |"
        )
    lines += _profile_markdown(summary, lower_bound=n_runs == 1)
    lines += [
        "",
        "## Mean CRPS, starting model → calibrated",
        "",
        "| observed | count | starting model | calibrated |",
        "|---|---|---|---|",
    ]
    for k in summary["kinds"]:
        lines.append(
            f"| {KIND_WORDS.get(k['kind'], k['kind'])} | {k['observations']} "
            f"| {k['crps_start']:.4g} | {k['crps_optimum']:.4g} |"
        )
    if summary.get("holdout"):
        lines += ["", "## Held-out runs", ""]
        lines += [f"* {x}" for x in _holdout_lines(summary)]
        lines += ["", "![held-out runouts](holdout.png)"]
    # the suspect-data notes are said in words under "Suspect data"
    notes = [n for n in summary["notes"] if not n.startswith("suspect data:")]
    if notes:
        lines += ["", "## Notes", ""] + [
            f"* {_in_words(n, summary['parameters'])}" for n in notes
        ]
    return "\n".join(lines) + "\n"


def _profile_markdown(summary: dict, *, lower_bound: bool) -> list[str]:
    """report.md's profile section: each parameter's profile interval beside its 90 %
    interval and slice, the objective's seed spread, the cost."""
    prof = summary.get("profile")
    if not prof:
        return []
    sd = prof["optimum_seed_sd"]
    lines = [
        "",
        "## Profile intervals",
        "",
        f"Each parameter set to {prof['points']} values across its search bounds "
        "(ends refined by bisection), the others re-optimised each time; a value is "
        "compatible with the data when the objective's excess over the optimum is "
        "below 1.645 × √(SE over the observations² + SD over "
        f"{prof['seeds']} other seeds²): the threshold includes the run-to-run "
        "(Monte Carlo) spread of the objective, not only which values were observed.",
        "",
    ]
    if sd is not None:
        lines += [
            f"Objective at the optimum: {prof['objective_optimum']:.4g}; its SD over "
            f"{prof['seeds']} other seeds (new rocks): {sd:.2g}.",
            "",
        ]
    if lower_bound:
        lines += [
            "One surveyed path: resampling its points is a lower bound on the "
            "uncertainty of a site's parameters (another boulder, another path); "
            "these intervals are lower bounds too.",
            "",
        ]
    lines += [
        "| parameter | fitted | profile interval | 90 % interval | slice | widest |",
        "|---|---|---|---|---|---|",
    ]
    for p, q, (slo, shi) in zip(summary["parameters"], prof["parameters"],
                                summary["slice_compatible"], strict=True):  # fmt: skip
        lo, hi = q["interval90"]
        blo, bhi = p["interval90"]
        lines.append(
            f"| {parameter_words(p['name'])} | {p['value']:.4g} | {lo:.4g} to "
            f"{hi:.4g} | {blo:.4g} to {bhi:.4g} | {slo:.4g} to {shi:.4g} "
            f"| {q['widest']} |"
        )
    lines += [
        "",
        f"Cost of the profile: {prof['evaluations']} evaluations of the objective, "
        f"{prof['wall_s']:.1f} s (`--profile-points 0` turns it off).",
    ]
    return lines


def _in_words(text: str, parameters: list[dict]) -> str:
    """``text`` with each fitted parameter's name in words (the fit's notes name
    them as the model file does; the report reads in words)."""
    for p in sorted(parameters, key=lambda p: -len(p["name"])):
        text = text.replace(p["name"], parameter_words(p["name"]))
    return text


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
    profile_points: int = 5,
    max_realised_e_n: float | None = None,
    at: list[float] | None = None,
    measured: list[str] | None = None,
    design_rocks: int | None = None,
    suspect=None,
    leave_out: bool = True,
) -> None:
    """Run the path-level fit (see the command's help)."""
    from fieldkit.cli.common import note
    from fieldkit.cli.design import (
        DEFAULT_DESIGN_ROCKS,
        check_design_rocks,
        design_for_fit,
        design_markdown,
        design_points,
        measured_values,
        print_design,
    )
    from fieldkit.cli.material_options import mapped_table
    from fieldkit.cli.progress import report_written, step
    from fieldkit.fit.leave_out import leave_out_models
    from fieldkit.fit.material_map import profile_disagreements
    from fieldkit.fit.path_fit import check_settings, fit_paths
    from fieldkit.fit.path_runs import section_runs
    from fieldkit.fit.path_sections import path_runs
    from fieldkit.fit.path_validation import censoring, validate
    from fieldkit.impact_table import ImpactTable
    from fieldkit.io.dem import read_dem
    from fieldkit.io.path_observations import (
        observations_from_impact_table,
        read_release_deposit,
    )
    from fieldkit.model.model_file import read_model, write_model

    check_settings(rocks=rocks, seed=seed, bootstrap=bootstrap, screen=screen,
                   profile_points=profile_points)  # fmt: skip
    if design_rocks is None:
        design_rocks = DEFAULT_DESIGN_ROCKS
    check_design_rocks(design_rocks)
    design_measured = measured_values(measured, preset)
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
        design_points(base, at, design_measured)  # refused before the fit
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
            bounds=box, step=step, profile_points=profile_points,
            max_realised_e_n=max_realised_e_n, suspect=suspect,
        )  # fmt: skip
        suspect_summary, suspect_text, leave_outs = _suspect(
            calibration, result, leave_out
        )
        fitted = dict(zip(result.names, map(float, result.values), strict=True))
        summary = result.to_dict()
        summary["section"] = section if on_dem else "the model's own profile"
        summary["material_map"] = material_map
        plausibility = _path_plausibility(result, calibration, seed, step)
        summary["plausibility"] = plausibility.to_dict()
        if material_check is not None:
            summary["material_check"] = material_check
        summary["suspect"] = suspect_summary
        if held is not None:
            with step(f"scoring {len(held)} held-out runs ({rocks} rocks each)"):
                validation = validate(held, calibration, fitted, rocks=rocks, seed=seed)
            summary["holdout"] = validation["forecasts"]
            summary["holdout_path_ids"] = validation["path_ids"]
            summary["holdout_section_end_m"] = validation["section_end_m"]
            summary["holdout_censoring"] = censoring(validation)
            if report is not None:
                from fieldkit.viz.holdout_figure import write_holdout_figure

                write_holdout_figure(
                    report / "holdout.png", validation, outputs=outputs
                )
        # the leave-out refits' models beside the start and the calibrated model
        design, said = design_for_fit(
            {"start": base, "calibrated": result.model,
             **leave_out_models(leave_outs)},
            at=at, measured=design_measured, rocks=design_rocks, seed=seed,
        )  # fmt: skip
        summary["design"] = design.to_dict()
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
                design=design_markdown(design, said),
            )  # fmt: skip
            text += plausibility.markdown()
            from fieldkit.cli.suspect_options import suspect_markdown

            text += suspect_markdown(suspect_summary, KIND_WORDS, parameter_words)
            write_text(report / "report.md", text, outputs)
        written = outputs.commit()
    print_design(design, said)
    for line in uncertainty_lines(summary):
        typer.echo(line)
    for p in summary["parameters"]:
        typer.echo(f"{p['name']}: {_value(p)}{_flag(p)}")
    for line in profile_lines(summary):
        typer.echo(line)
    for line in _kind_lines(result, summary) + _holdout_lines(summary):
        typer.echo(line)
    for line in plausibility.lines():
        typer.echo(line)
    for line in suspect_text:
        typer.echo(line)
    report_written(written)


def _path_plausibility(result, runs, seed: int, step):
    """The path fit's plausibility report: the calibrated model simulated on the
    calibration runs' sections (its own stream), bounds, the constraint."""
    from fieldkit.fit.plausibility import PLAUSIBILITY_ROCKS, path_fit_plausibility

    with step(f"simulating {PLAUSIBILITY_ROCKS:,} rocks of the calibrated model "
              "for its realised restitution"):  # fmt: skip
        return path_fit_plausibility(result, runs, seed=seed)


def _suspect(runs, result, leave_out: bool) -> tuple[dict, list[str], list]:
    """The path fit's JSON ``suspect`` entry, its lines and the leave-out refits
    (:class:`~fieldkit.fit.leave_out.LeaveOut`, their models by
    :func:`~fieldkit.fit.leave_out.leave_out_models`), run here unless
    ``leave_out`` is False (or nothing is suspect)."""
    from fieldkit.cli.progress import step
    from fieldkit.cli.suspect_options import suspect_lines, suspect_record
    from fieldkit.fit.leave_out import path_leave_outs

    leave_outs = None
    if leave_out and result.suspect:
        leave_outs = path_leave_outs(runs, result, step=step)
    how = (
        "one search each from the calibrated values, same rocks and seed, about "
        f"{max(150, 60 * len(result.names))} evaluations"
        + ("; without the realised-e_n constraint"
           if result.max_realised_e_n is not None else "")
    )  # fmt: skip
    policy, counts = result.suspect_policy, result.suspect
    lines = suspect_lines(policy, counts, "observed values", leave_outs, how=how)
    leave_outs = leave_outs or []
    return suspect_record(policy, counts, leave_outs, lines), lines, leave_outs
