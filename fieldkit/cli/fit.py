"""`fieldkit fit`: fit a model's impact laws to an ImpactTable."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Annotated

import typer

from fieldkit.cli.common import one_line_errors
from fieldkit.cli.design import (
    DEFAULT_DESIGN_ROCKS,
    AtOpt,
    DesignRocksOpt,
    MeasuredOpt,
)
from fieldkit.cli.material_options import MaterialOpt, PresetOpt, mapped_table
from fieldkit.cli.progress import report_written, step
from fieldkit.cli.suspect_options import (
    SUSPECT_FLAGS,
    AssumedOpt,
    FlaggedOpt,
    LeaveOutOpt,
    suspect_lines,
    suspect_markdown,
    suspect_policy,
    suspect_record,
)
from fieldkit.errors import ArgumentError, FieldkitError
from fieldkit.outputs import OutputSet, write_text

FLAGS = {
    "output": "-o",
    "model": "--model",
    "report_dir": "--report",
    "report": "--report",
    "releases": "--paths",
    "deposits": "--deposits",
    "dem": "--dem",
    "json_file": "--json",
    "holdout_releases": "--holdout-paths",
    "holdout_deposits": "--holdout-deposits",
    "bound": "--bound",
    "bounds": "--bound",
    "screen": "--screen",
    "rocks": "--rocks",
    "seed": "--seed",
    "bootstrap": "--bootstrap",
    "free": "--free",
    "section": "--section",
    "material": "--material",
    "preset": "--preset",
    "profile_points": "--profile-points",
    "max_realised_e_n": "--max-realised-en",
    "analysis_x_m": "--at",
    "at": "--at",
    "measured": "--measured",
    "design_rocks": "--design-rocks",
    "tracked_extent": "--tracked-extent",
    "holdout_seeds": "--holdout-seeds",
    "virtual_campaigns": "--virtual-campaigns",
    **SUSPECT_FLAGS,
}

#: Path-fit settings left unset on the command line take these values.
PATH_DEFAULTS = {"rocks": 200, "seed": 0, "bootstrap": 20, "screen": 16,
                 "section": "descent", "profile_points": 5}  # fmt: skip
#: Options of the path fit only: refused by an impact fit, never silently ignored.
PATH_ONLY = ("json_file", "holdout_releases", "holdout_deposits", "free", "rocks",
             "seed", "bootstrap", "screen", "bound", "section",
             "profile_points")  # fmt: skip


def impact_report_markdown(
    result, *, table_file: Path, model_file: Path, mapping: list[str],
    design: list[str] = (),
) -> str:  # fmt: skip
    """report.md of an impact fit: the design quantities (``design``, first), the
    verdict, each parameter in words with its unit, its flags, and the residual
    figure."""
    from fieldkit.cli.fit_paths import parameter_words

    lines = [
        "# Impact fit",
        "",
        *design,
        f"Table: `{table_file}`; base model: `{model_file}`.",
        "",
        *[f"* {m}" for m in mapping],
        *([""] if mapping else []),
        f"{'Converged' if result.success else 'FAILED'}: {result.stop_words()}. "
        f"{result.ndata} rebound values (normal and tangential rebound velocity, "
        f"rebound spin where measured) from {result.n_impacts} impacts, "
        f"{result.nparams} parameters.",
        "",
        f"**Goodness of fit:** {result.verdict()}.",
        "",
        f"Weights: {result.weighting_words()}. Standard errors from the fit's "
        "Jacobian, scaled by √(reduced chi2). AIC "
        f"{result.aic:.6g}, BIC {result.bic:.6g} (compare models fitted to the same "
        "table: lower is better).",
        "",
        "## Fitted parameters",
        "",
        "| parameter | start | fitted | standard error | flags |",
        "|---|---|---|---|---|",
    ]
    for name, v, se, s0, flags in zip(
        result.names, result.values, result.stderr, result.start, result.flags(),
        strict=True,
    ):  # fmt: skip
        lines.append(
            f"| {parameter_words(name)} | {s0:.6g} | {v:.6g} | {se:.2g} "
            f"| {'; '.join(flags) or 'none'} |"
        )
    lines += _profile_markdown(result)
    if result.notes:
        lines += ["", "## Notes", ""] + [f"* {n}" for n in result.notes]
    lines += [
        "",
        "## Residuals",
        "",
        "Observed minus predicted rebound at each impact, against the impact angle "
        "and speed: a trend is physics the model misses.",
        "",
        "![residuals](residuals.png)",
    ]
    return "\n".join(lines) + "\n"


def _profile_markdown(result) -> list[str]:
    """report.md's profile-likelihood section: each parameter's profile interval
    beside the Jacobian's, the threshold, the cost, the one-path statement."""
    from fieldkit.cli.fit_paths import parameter_words

    prof = result.profile
    if not prof:
        return []
    lines = [
        "",
        "## Profile-likelihood intervals",
        "",
        "Each parameter fixed at values around its fit, the others refitted by the "
        "same weighted least squares; a value is in the 90 % interval while the "
        "rise of chi2 over its minimum, divided by the reduced chi2, stays below "
        f"F(0.90; 1, {prof['dof']}) = {prof['threshold']:.4g}. The Jacobian's "
        f"interval beside it is the fitted value ± {prof['t_quantile']:.4g} standard "
        "errors (the same t); the two agree where the model is linear in its "
        f"parameters. {prof['evaluations']} refits, {prof['wall_s']:.2f} s.",
        "",
    ]
    if prof.get("one_path"):
        lines += [f"**Lower bounds.** {prof['one_path'][0].upper()}"
                  f"{prof['one_path'][1:]}.", ""]  # fmt: skip
    lines += [
        "| parameter | fitted | profile 90 % | Jacobian 90 % | upper / lower "
        "half-width |",
        "|---|---|---|---|---|",
    ]

    def num(x):
        return "open" if x is None else f"{x:.4g}"

    for q in prof["parameters"]:
        (lo, hi), (jlo, jhi) = q["interval90"], q["jacobian90"]
        ends = [num(v) + (" (open)" if o else "") for v, o in
                zip((lo, hi), q["open"], strict=True)]  # fmt: skip
        lines.append(
            f"| {parameter_words(q['name'])} | {q['value']:.6g} | {ends[0]} to "
            f"{ends[1]} | {num(jlo)} to {num(jhi)} | {num(q['asymmetry'])} |"
        )
    return lines


def _paths(options: dict) -> None:
    from fieldkit.cli.fit_paths import fit_paths_command

    on_dem = options["deposits"] is not None or options["dem"] is not None
    for name in ("releases", "deposits", "dem") if on_dem else ("releases",):
        if options[name] is None:
            raise ArgumentError(
                "a path fit on a DEM needs --paths, --deposits and --dem", source=name
            )
    if not on_dem and options["holdout_releases"] is not None:
        raise ArgumentError(
            "held-out runs need a DEM (--deposits and --dem): a surveyed path "
            "is fitted on the model's own profile",
            source="holdout_releases",
        )
    if (options["holdout_releases"] is None) != (options["holdout_deposits"] is None):
        raise ArgumentError(
            "--holdout-paths and --holdout-deposits go together",
            source="holdout_releases",
        )
    if options["table_file"] is not None:
        raise ArgumentError(
            "give either an ImpactTable or --paths, not both", source="table_file"
        )
    fit_paths_command(
        releases=options["releases"],
        deposits=options["deposits"],
        dem=options["dem"],
        model_file=options["model_file"],
        output=options["output"],
        json_file=options["json_file"],
        report=options["report"],
        holdout_releases=options["holdout_releases"],
        holdout_deposits=options["holdout_deposits"],
        free=options["free"],
        rocks=PATH_DEFAULTS["rocks"] if options["rocks"] is None else options["rocks"],
        seed=PATH_DEFAULTS["seed"] if options["seed"] is None else options["seed"],
        bootstrap=(
            PATH_DEFAULTS["bootstrap"]
            if options["bootstrap"] is None
            else options["bootstrap"]
        ),
        section=options["section"] or PATH_DEFAULTS["section"],
        screen=(
            PATH_DEFAULTS["screen"] if options["screen"] is None else options["screen"]
        ),
        bounds=options["bound"],
        material=options["material"],
        preset=options["preset"],
        profile_points=(
            PATH_DEFAULTS["profile_points"]
            if options["profile_points"] is None
            else options["profile_points"]
        ),
        max_realised_e_n=options["max_realised_e_n"],
        at=options["at"],
        measured=options["measured"],
        design_rocks=options["design_rocks"],
        suspect=suspect_policy(options["flagged"], options["assumed_theta0"]),
        leave_out=options["leave_out"],
    )


def _plan(options: dict) -> None:
    """A fit of a terrain (3-D) model to deposits in plan (cli/fit_plan.py)."""
    from fieldkit.cli.fit_plan import fit_plan_command

    if options["deposits"] is None:
        raise ArgumentError(
            "a fit of a terrain (3-D) model needs --paths and --deposits",
            source="deposits",
        )
    if options["table_file"] is not None:
        raise ArgumentError(
            "give either an ImpactTable or --paths, not both", source="table_file"
        )
    fit_plan_command(
        model_file=options["model_file"],
        releases=options["releases"],
        deposits=options["deposits"],
        output=options["output"],
        json_file=options["json_file"],
        holdout_releases=options["holdout_releases"],
        holdout_deposits=options["holdout_deposits"],
        free=options["free"],
        bounds=options["bound"],
        rocks=options["rocks"],
        seed=options["seed"],
        screen=options["screen"],
        given=options,
        tracked_extent=options["tracked_extent"],
        holdout_seeds=options["holdout_seeds"],
        virtual_campaigns=options["virtual_campaigns"],
    )


@one_line_errors(flags=FLAGS)
def fit(
    model_file: Annotated[
        Path, typer.Option("--model", help="The base model file (§5).")
    ],
    output: Annotated[
        Path, typer.Option("-o", help="The calibrated model file to write.")
    ],
    table_file: Annotated[
        Path | None,
        typer.Argument(
            metavar="[TABLE]",
            help="The ImpactTable (.csv, .parquet, .xlsx); omit with --paths.",
        ),
    ] = None,
    report: Annotated[
        Path | None,
        typer.Option(
            "--report",
            help="Write report.md into this folder, with residuals.png (impacts) or, "
            "with held-out runs, holdout.png (paths).",
        ),
    ] = None,
    releases: Annotated[
        Path | None,
        typer.Option("--paths", help="Path fit: release points CSV (one run a row)."),
    ] = None,
    deposits: Annotated[
        Path | None,
        typer.Option("--deposits", help="Path fit: deposit points CSV (same ids)."),
    ] = None,
    dem: Annotated[
        Path | None,
        typer.Option("--dem", help="Path fit: the DEM (ESRI ASCII grid, GeoTIFF)."),
    ] = None,
    json_file: Annotated[
        Path | None,
        typer.Option("--json", help="Path fit: write the fit and hold-out scores."),
    ] = None,
    holdout_releases: Annotated[
        Path | None,
        typer.Option("--holdout-paths", help="Path fit: held-out release points."),
    ] = None,
    holdout_deposits: Annotated[
        Path | None,
        typer.Option("--holdout-deposits", help="Path fit: held-out deposits."),
    ] = None,
    free: Annotated[
        list[str] | None,
        typer.Option(
            "--free",
            help="Path fit: a parameter to fit (repeatable; default e_n, e_t and "
            "friction_deg of every material).",
        ),
    ] = None,
    rocks: Annotated[
        int | None,
        typer.Option(
            "--rocks",
            help="Path fit: rocks per run and evaluation (1 to 20,000; default 200).",
        ),
    ] = None,
    seed: Annotated[
        int | None,
        typer.Option(
            "--seed",
            help="Path fit: seed of the common random numbers (0 to 2^32-1; "
            "default 0).",
        ),
    ] = None,
    bootstrap: Annotated[
        int | None,
        typer.Option(
            "--bootstrap",
            help="Path fit: bootstrap resamples of runs (0 to 1,000; default 20; "
            "fewer than 10 give no standard errors or correlations).",
        ),
    ] = None,
    screen: Annotated[
        int | None,
        typer.Option(
            "--screen",
            help="Path fit: Sobol points screened for a better start (0: none; at "
            "most 4,096; default 16).",
        ),
    ] = None,
    bound: Annotated[
        list[str] | None,
        typer.Option(
            "--bound",
            help="Path fit: search bounds NAME=LO,HI of a free parameter (repeatable).",
        ),
    ] = None,
    material: MaterialOpt = None,
    preset: PresetOpt = None,
    profile_points: Annotated[
        int | None,
        typer.Option(
            "--profile-points",
            help="Path fit: values across each bound range at which the objective "
            "is profiled (the other parameters re-optimised; 0: no profile; default "
            "5); the profile's threshold includes the objective's spread over 5 "
            "other seeds.",
        ),
    ] = None,
    section: Annotated[
        str | None,
        typer.Option(
            "--section",
            help="Path fit: 'descent' (steepest descent from each release, the "
            "default) or 'release-deposit' (honest for calibration only).",
        ),
    ] = None,
    max_realised_e_n: Annotated[
        float | None,
        typer.Option(
            "--max-realised-en",
            help="Constrain the fit to realised e_n = -vfn/vin <= VALUE: at every "
            "observed impact (impact fit; a penalty residual per impact) or on at "
            "most 1 % of each material's simulated impacts (path fit; a penalty). "
            "Default: no constraint.",
        ),
    ] = None,
    at: AtOpt = None,
    measured: MeasuredOpt = None,
    design_rocks: DesignRocksOpt = DEFAULT_DESIGN_ROCKS,
    flagged: FlaggedOpt = "keep",
    assumed_theta0: AssumedOpt = "keep",
    leave_out: LeaveOutOpt = True,
    tracked_extent: Annotated[
        str | None,
        typer.Option(
            "--tracked-extent",
            help="3-D fit: XMIN,YMIN,XMAX,YMAX [m], the area the survey tracked "
            "the blocks in: every simulated rock ends at its first exit from it, as "
            "an observed last tracked position does (and so do the climatology's "
            "vectors). Default: none, rocks scored where they stop or leave the DEM.",
        ),
    ] = None,
    holdout_seeds: Annotated[
        int | None,
        typer.Option(
            "--holdout-seeds",
            help="3-D fit: fits (seeds --seed, --seed + 1, ...) the held-out "
            "comparison averages over (1 to 20; default 3).",
        ),
    ] = None,
    virtual_campaigns: Annotated[
        int | None,
        typer.Option(
            "--virtual-campaigns",
            help="3-D fit with held-out runs: virtual campaigns drawn from the "
            "calibrated model, which measure how often a perfect forecast would "
            "beat the climatology by 2 paired SEs on a held-out set of this size "
            "(0 = off, 2 to 10,000; default 200).",
        ),
    ] = None,
) -> None:
    """Fit restitution and effect parameters to measured impacts (weighted LSQ).

    Each impact's rebound (vfn, vft, and omega_f where measured) is predicted from
    its measured impact velocity with the model's impact laws (material means and
    the active impact-stage effects, the simulator's own physics) and the
    parameters are fitted by weighted least squares: per-material e_n, e_t and the
    active impact effects' parameters. Weights 1/sd from the table's *_sd columns
    (which ones is printed), else unit weights. The calibrated model keeps the
    base model's format, with the fitted values and provenance.fit (values,
    standard errors, correlations, AIC/BIC). The report flags parameters at a
    bound, not identifiable, or unchanged. A table too small for standard errors
    worth the name is refused: at least 2 impacts per fitted material and 3
    residual degrees of freedom (data - parameters).

    Example (from the repository root):

        fieldkit synth surveys/tornado_mountain/model_rocfall_table_7_1.json \\
          --paths 20 --seed 1 \\
          --effects angle_dependent_restitution=b=1.2 -o out/synth.csv

        fieldkit fit out/synth.csv \\
          --model surveys/tornado_mountain/model_rocfall_table_7_1.json \\
          -o out/calibrated.json --report out/fit

    With --paths, --deposits and --dem it calibrates the simulator on observed
    runs instead: each run's section is the steepest descent from its release on
    the DEM; the free parameters are fitted to the observed runouts by the mean
    CRPS of simulated ensembles (common random numbers), with bootstrap
    uncertainty over runs; held-out runs, when given, are scored for the
    calibrated model, the starting model and the climatology (the calibration
    runs' observed runouts). The README shows it on the Tschamut 2014 runs.
    With a terrain (3-D) model file, --paths and --deposits (no --dem: the
    model's own DEM) calibrate the 3-D model in plan: each run simulated from
    its own release with its own block, objective the mean fair energy score of
    the deposits (fieldkit.fit.plan_fit; --rocks per run, default 60, --seed,
    --screen, --free, default e_n, e_t, friction_deg of every material,
    --bound); held-out runs are scored (fair energy score, fair distance CRPS)
    for the calibrated model, the start and the climatology with paired
    differences +- SE over runs, over --holdout-seeds fits (default 3);
    --tracked-extent censors every forecast at the surveyed area's edge. What
    such a test can show at all is measured beside it: --virtual-campaigns
    campaigns drawn from the calibrated model give the share in which a perfect
    forecast beats the climatology by 2 paired SEs, and where every block has 5
    runs, the climatology of the run's own block against the pooled one
    (repeated 5-fold over all runs) bounds what knowing the block is worth. The
    calibrated file is the base file with the fitted values and provenance.fit;
    its terrain block's file names are made relative to the calibrated file's
    folder.
    With --paths alone, the file is an ImpactTable from reduce and each path is
    fitted on the model's own profile: its runout, flight heights, impact spacing
    and speeds at the impacts.

    Both fits print first what a designer reads: at the analysis points (--at,
    else the model file's analysis_points) the start and the calibrated model
    are simulated on one held-out random stream (--design-rocks rocks each) and
    their passing fraction and p50/p95/p99/max of speed, translational and
    total energy and bounce height (each with its Monte Carlo SE) are set
    beside the values measured there (--measured, the preset's measured entries);
    a line says when a model is unconservative (a measured value above its p99,
    above every rock, or no rock reaching the point). Written under "design" of
    the JSON and at the top of report.md.
    """
    from fieldkit.fit.impact_fit import check_realised_limit

    check_realised_limit(max_realised_e_n)
    from fieldkit.cli.fit_plan import is_terrain_model

    if releases is not None and is_terrain_model(model_file):
        _plan(locals())
        return
    for name in ("tracked_extent", "holdout_seeds", "virtual_campaigns"):
        if locals()[name] is not None:
            raise ArgumentError(
                "for a fit of a terrain (3-D) model only (a model file with a "
                "terrain block, with --paths and --deposits)",
                source=name,
            )
    if releases is not None or deposits is not None or dem is not None:
        _paths(locals())
        return
    if table_file is None:
        raise ArgumentError(
            "give an ImpactTable, or --paths, --deposits and --dem for a path fit",
            source="table_file",
        )
    options = locals()
    given = [name for name in PATH_ONLY if options[name] not in (None, [])]
    if given:
        also = ", ".join(FLAGS[name] for name in given[1:])
        raise ArgumentError(
            "for a path fit (--paths) only; an impact fit has no such setting"
            + (f" (nor {also})" if also else ""),
            source=given[0],
        )
    from fieldkit.cli.design import (
        check_design_rocks,
        design_for_fit,
        design_markdown,
        design_points,
        measured_values,
        print_design,
    )
    from fieldkit.fit.impact_fit import fit_impacts
    from fieldkit.fit.leave_out import impact_leave_outs, leave_out_models
    from fieldkit.impact_table import ImpactTable
    from fieldkit.model.model_file import read_model, write_model

    check_design_rocks(design_rocks)
    design_measured = measured_values(measured, preset)
    policy = suspect_policy(flagged, assumed_theta0)

    with OutputSet(inputs=[table_file, model_file, preset]) as outputs:
        outputs.confine(report)
        outputs.plan(output, argument="-o")
        if report is not None:
            outputs.plan(report / "report.md", argument="--report")
            outputs.plan(report / "residuals.png", argument="--report")
        model = read_model(model_file, outputs=outputs)
        design_points(model, at, design_measured)  # refused before the fit
        table = ImpactTable.read(table_file)
        mapping = mapped_table(table, model, material, preset)
        # a weighted least squares of a few parameters: short, shown on a terminal
        with step(f"fitting {model_file.name} to {table_file}", announce=False):
            result, calibrated = fit_impacts(
                mapping.table, model, policy, max_realised_e_n=max_realised_e_n
            )
        text = result.report()
        if not result.success:
            raise FieldkitError(
                f"the fit did not converge ({result.stop_words()}): no calibrated "
                "model written",
                source=str(table_file),
            )
        leave_outs = None
        if leave_out:
            leave_outs = impact_leave_outs(
                mapping.table, model, result, calibrated, policy
            )
        counts = {"impacts": result.suspect}
        suspect = suspect_lines(
            policy, counts, "impacts", leave_outs,
            how="weighted least squares from the calibrated values"
            + ("; without the --max-realised-en constraint"
               if max_realised_e_n is not None else ""),
        )  # fmt: skip
        # the impact fit has no seed of its own: the design stream's is the path
        # fit's default, stated in the design table; the leave-out refits' models
        # are set beside the start and the calibrated model
        design, said = design_for_fit(
            {"start": model, "calibrated": calibrated,
             **leave_out_models(leave_outs or [])},
            at=at, measured=design_measured, rocks=design_rocks,
            seed=PATH_DEFAULTS["seed"],
        )  # fmt: skip
        fit_record = result.provenance(str(table_file))
        fit_record["material_map"] = mapping.provenance()
        plausibility = _impact_plausibility(
            result, calibrated, mapping.table, max_realised_e_n
        )
        fit_record["plausibility"] = plausibility.to_dict()
        fit_record["design"] = design.to_dict()
        fit_record["suspect"] = suspect_record(
            policy, counts, leave_outs or [], suspect
        )
        provenance = {**calibrated.provenance, "fit": fit_record}
        write_model(replace(calibrated, provenance=provenance), output, outputs=outputs)
        if report is not None:
            from fieldkit.cli.fit_paths import parameter_words
            from fieldkit.viz.fit_figure import write_residual_figure

            derived = mapping.table.derive()
            write_text(
                report / "report.md",
                impact_report_markdown(
                    result, table_file=table_file, model_file=model_file,
                    mapping=mapping.notes, design=design_markdown(design, said),
                )
                + plausibility.markdown()
                + suspect_markdown(fit_record["suspect"], {}, parameter_words),
                outputs,
            )  # fmt: skip
            write_residual_figure(
                report / "residuals.png",
                result,
                derived.column("theta_i_deg"),
                derived.column("vi_mps"),
                outputs=outputs,
            )
        written = outputs.commit()
    print_design(design, said)
    typer.echo(text)
    for line in plausibility.lines():
        typer.echo(line)
    typer.echo("\n".join(suspect))
    report_written(written)


def _impact_plausibility(result, calibrated, table, limit):
    """The impact fit's plausibility report (the calibrated model simulated on its
    own stream, the fitted law at the observed impacts, bounds, constraint)."""
    from fieldkit.fit.plausibility import (
        PLAUSIBILITY_ROCKS,
        impact_fit_plausibility,
    )

    with step(f"simulating {PLAUSIBILITY_ROCKS:,} rocks of the calibrated model "
              "for its realised restitution"):  # fmt: skip
        return impact_fit_plausibility(
            result, calibrated, table, max_realised_e_n=limit
        )
