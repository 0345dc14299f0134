"""`fieldkit diagnose`: where the model fails and which effect is missing."""

from __future__ import annotations

import contextlib
import secrets
from collections.abc import Callable, Iterator
from dataclasses import replace
from pathlib import Path
from typing import Annotated

import typer

from fieldkit.cli.common import note, one_line_errors
from fieldkit.cli.design import (
    DEFAULT_DESIGN_ROCKS,
    AtOpt,
    DesignRocksOpt,
    MeasuredOpt,
)
from fieldkit.cli.engine_options import Scheduler, Timeout
from fieldkit.cli.material_options import MaterialOpt, PresetOpt, mapped_table
from fieldkit.cli.progress import report_written, step
from fieldkit.errors import ArgumentError
from fieldkit.outputs import OutputSet, write_json, write_text

FLAGS = {
    "json_file": "--json",
    "report_dir": "--report",
    "rrd": "--rrd",
    "model": "--model",
    "output": "-o",
    "folds": "--folds",
    "seed": "--seed",
    "material": "--material",
    "preset": "--preset",
    "sensitivity": "--sensitivity",
    "null": "--null",
    "power": "--power",
    "null_quantile": "--null-quantile",
    "workers": "--workers",
    "scheduler": "--scheduler",
    "timeout_s": "--timeout",
    "input_files": "TABLE_OR_TRACK",
    "at": "--at",
    "measured": "--measured",
    "design_rocks": "--design-rocks",
}
#: Most characters of a CSV's first line read to tell a track from a table.
MAX_HEADER_CHARS = 1 << 20
#: Largest fold seed (numpy's generators take any integer >= 0; 64 bits are plenty).
MAX_SEED = 2**64 - 1


def _is_track(path: Path) -> bool:
    from fieldkit.track import is_track_header

    if path.suffix.lower() != ".csv":
        return False
    with open(path, encoding="utf-8", errors="replace") as handle:
        header = handle.readline(MAX_HEADER_CHARS)
    cells = [c.strip() for c in header.split(",")]
    return is_track_header(cells) and "vi_x_mps" not in cells


def _summary(diagnosis) -> list[str]:
    """What the command prints: the verdict in words, one line per candidate."""
    from fieldkit.diagnose import labels
    from fieldkit.diagnose.report import (
        alternative_meaning,
        baseline_label,
        dependence_sentence,
        rankings,
        rule_head,
    )
    from fieldkit.diagnose.survey_loop import loop_lines

    d = diagnosis
    unit = labels.unit(d.metric)
    lines = [
        f"held out: {d.groups}",
        f"baseline, {baseline_label(d)}: {labels.metric_words(d.metric)} "
        f"{d.baseline.cv_rmse:.4g} {unit}",
        f"rule: a candidate is recommended (*) when {rule_head(d)}",
        "candidates, best first: held-out RMS error, gain ± its standard error",
    ]
    for c in d.candidates:
        mark = "*" if c.meaningful else " "
        lines.append(
            f" {mark} {c.effect:<30} {c.cv_rmse:.4g} {unit}  gain "
            f"{c.improvement:+.1%} ± {c.improvement_se:.1%}"
        )
    for name, why in d.skipped.items():
        lines.append(f"   {name:<30} not tested: {why}")
    rounds = rankings(d)
    for i, s in enumerate(d.steps):
        lines.append(
            f"step {i + 1}: add {s.added}: {s.cv_rmse_before:.4g} -> "
            f"{s.cv_rmse:.4g} {unit} ({1 - s.cv_rmse / s.cv_rmse_before:.1%} lower)"
        )
        if i + 1 < len(rounds):
            lines.append(
                f"  then, against the model after step {i + 1}: "
                + "; ".join(
                    f"{'* ' if c.meaningful else ''}{c.effect} gain "
                    f"{c.improvement:+.1%} ± {c.improvement_se:.1%}"
                    for c in rounds[i + 1]
                )
            )
    lines += [f"confounded: {a}" for a in d.advice]
    lines.append(f"recommended: {d.recommended or 'nothing'}; stopped: {d.stopped}")
    lines += loop_lines(d.null, d.power)
    if len(d.accepted) > 1:
        lines.append(f"accepted: {', '.join(d.accepted)}")
    meaning = alternative_meaning(d)
    if meaning:
        lines.append(meaning)
    lines += [f"sensitivity: {v.sentence()}" for v in d.sensitivity]
    lines += [
        f"residuals still: {dependence_sentence(x)}"
        for x in sorted(d.dependence_after, key=lambda x: x.p_value)
        if x.significant
    ]
    return lines


@contextlib.contextmanager
def _step_once_checked(description: str) -> Iterator[Callable[[str], None]]:
    """A progress callback for the library that starts :func:`step` at its first
    call: the library calls it once the input has passed every check, so bad input
    is refused in one line before any progress is shown."""
    with contextlib.ExitStack() as stack:
        started = False

        def progress(_message: str) -> None:
            nonlocal started
            if not started:
                started = True
                stack.enter_context(step(description))

        yield progress


@contextlib.contextmanager
def _bar_once_checked(description: str) -> Iterator[Callable[[int, int], None]]:
    """:func:`_step_once_checked` with a bar: ``advance(done, total)`` starts the
    step at its first call (after the table has passed every check)."""
    with contextlib.ExitStack() as stack:
        bar = None

        def advance(done: int, total: int) -> None:
            nonlocal bar
            if bar is None:
                bar = stack.enter_context(step(description, total=total))
            bar(done, total)

        yield advance


def _sensitivity(
    table, base, seed: int, folds: int, wanted: bool | None, floor: float | None = None
) -> list:
    """The verdict under each variant of the table (``wanted`` None: only for a
    reduced survey), diagnosed with the same fold seed and folds, and with the
    observed table's null threshold ``floor`` as the least gain when there is one."""
    import numpy as np

    from fieldkit.diagnose.impacts import diagnose_impacts
    from fieldkit.diagnose.sensitivity import is_surveyed, sensitivity, variants

    if wanted is False or (wanted is None and not is_surveyed(table)):
        return []
    names = variants(table)
    if not names:
        return []

    def again(variant_table, variant_model):
        return diagnose_impacts(
            variant_table, variant_model, rng=np.random.default_rng(seed),
            folds=folds, gain_floor=floor if floor is not None else 0.0,
        )  # fmt: skip

    with step(f"sensitivity of the verdict: diagnosing {', '.join(names)}"):
        return sensitivity(table, base, again)


def _read_tables(paths: list[Path]):
    """The ImpactTables of ``paths`` as one (each path_id in one file only)."""
    import pandas as pd

    from fieldkit.impact_table import ImpactTable

    tables = [ImpactTable.read(p) for p in paths]
    if len(tables) == 1:
        return tables[0]
    seen: dict[str, Path] = {}
    for path, table in zip(paths, tables, strict=True):
        for pid in table.paths():
            if pid in seen:
                raise ArgumentError(
                    f"path {pid!r} is in {seen[pid]} and in {path}: give each path "
                    "once (reduce them with distinct --path-id)",
                    source="input_files",
                )
            seen[pid] = path
    frame = pd.concat([t.frame for t in tables], ignore_index=True)
    return ImpactTable(frame, source=" + ".join(str(p) for p in paths))


def _write_report(report_dir: Path, diagnosis, inputs, outputs: OutputSet) -> str:
    from fieldkit.diagnose.report import markdown
    from fieldkit.viz.diagnose_figure import write_diagnosis_figures

    text = markdown(diagnosis, title=inputs[0], inputs=inputs)
    write_text(report_dir / "report.md", text, outputs)
    write_diagnosis_figures(report_dir, diagnosis, outputs=outputs)
    return text


@one_line_errors(flags=FLAGS)
def diagnose(
    input_files: Annotated[
        list[Path],
        typer.Argument(
            metavar="TABLE_OR_TRACK...",
            help="An ImpactTable (.csv, .parquet, .xlsx) or a track CSV "
            "(t_s, x_m, z_m); several ImpactTables (e.g. one reduced path each) are "
            "diagnosed together, each path_id once.",
        ),
    ],
    json_file: Annotated[
        Path | None,
        typer.Option("--json", help="Write the diagnosis JSON (architecture §4)."),
    ] = None,
    report_dir: Annotated[
        Path | None,
        typer.Option("--report", help="Write report.md and the residual PNGs here."),
    ] = None,
    rrd: Annotated[
        Path | None, typer.Option("--rrd", help="Write a rerun recording (.rrd).")
    ] = None,
    model: Annotated[
        Path | None,
        typer.Option(
            "--model",
            help="Base model file (§5); default: constant e_n, e_t per material.",
        ),
    ] = None,
    output: Annotated[
        Path | None,
        typer.Option(
            "-o", help="Write the model with the accepted effects (needs --model)."
        ),
    ] = None,
    folds: Annotated[
        int,
        typer.Option(
            "--folds",
            help="Cross-validation folds, 2 to 100 (fewer when there are fewer "
            "paths, blocks or flights).",
            min=2,
        ),
    ] = 5,
    seed: Annotated[
        int | None,
        typer.Option(
            "--seed",
            help="Seed of the fold split, 0 to 2^64-1 (drawn and printed when "
            "omitted).",
        ),
    ] = None,
    radius: Annotated[
        float | None,
        typer.Option(
            "--radius",
            help="Track only: body radius (m); default: the track file's "
            "body_radius_m (written by `fieldkit track`).",
        ),
    ] = None,
    mass: Annotated[
        float | None,
        typer.Option(
            "--mass",
            help="Track only: body mass (kg); default: the track file's "
            "body_mass_kg, else a 2650 kg/m3 sphere of --radius.",
        ),
    ] = None,  # fmt: skip
    material: MaterialOpt = None,
    preset: PresetOpt = None,
    null: Annotated[
        int | None,
        typer.Option(
            "--null",
            help="Null campaigns simulated through the survey and the reduction "
            "for a reduced survey (default 99; 0 = none, the plain rule only); on "
            "a table with impact-velocity errors (vin_sd_mps, vit_sd_mps) null "
            "tables of its fitted baseline with those errors (default none); 19 "
            "is the least for a 5 % test.",
        ),
    ] = None,
    power: Annotated[
        int,
        typer.Option(
            "--power",
            help="Campaigns per candidate, simulated with it at its fitted size, "
            "for the power this survey gives it (0 = none).",
        ),
    ] = 40,
    null_quantile: Annotated[
        float,
        typer.Option(
            "--null-quantile",
            help="The quantile of the null gains a recommended gain must exceed.",
        ),
    ] = 0.95,
    workers: Annotated[
        int | None,
        typer.Option(
            "--workers",
            help="Local Dask worker processes for the null and power campaigns "
            "(default: every core; 1: this process).",
        ),
    ] = None,
    scheduler: Scheduler = None,
    timeout: Timeout = 10.0,
    sensitivity: Annotated[
        bool | None,
        typer.Option(
            "--sensitivity/--no-sensitivity",
            help="Diagnose again with the assumed launch angles theta0 -10 and +10 "
            "deg and with the materials grouped into one, and show each verdict "
            "(default: on for a reduced survey, a table with assumed launch angles).",
        ),
    ] = None,
    at: AtOpt = None,
    measured: MeasuredOpt = None,
    design_rocks: DesignRocksOpt = DEFAULT_DESIGN_ROCKS,
) -> None:
    """Compare model and measurements; rank the missing effects; add them stepwise.

    The baseline (constant e_n, e_t per material, or --model) is scored by its
    held-out error: k-fold cross-validation over paths (or blocks of consecutive
    impacts on a single-path survey). Residuals are tested against every feature
    the table carries; a residual depends on a feature when its Holm-adjusted p
    <= 0.01. Each candidate effect the data can inform is added, refitted and
    scored on the held-out data; one is
    recommended only when it lowers the held-out error by more than 1 % and by
    more than 2 standard errors of that gain (jackknife over the held-out
    groups). Two candidates that both pass, neither of which lowers the other's
    error by more than 1 % and 1 standard error, are reported as confounded and
    neither is added. Accepted effects are added stepwise. A track CSV is
    diagnosed at flight level, on the positions of its flights: air_drag is
    recommended when it lowers the held-out error by more than 1 % and by more
    than 2 standard errors of that gain. The body (--radius, --mass) is read
    from the track file when `fieldkit track` wrote it. Its x and z residuals
    are tested against the time from mid-flight and the speed (4 tests; a
    residual depends on a feature when its Holm-adjusted p <= 0.05). The
    dependence tests only describe the residuals: no recommendation rests on
    them. With -o (a calibration), the
    base and the written model are first set side by side at the analysis points
    (--at, else the model file's analysis_points) beside the values measured
    there (--measured, the preset's), as fit does.

    Example (from the repository root):

        fieldkit synth surveys/tornado_mountain/model_rocfall_table_7_1.json \\
          --paths 25 --seed 7 --effects angle_dependent_restitution=b=1.03 \\
          -o out/hidden.csv

        fieldkit diagnose out/hidden.csv --seed 1 --json out/diagnosis.json \\
          --report out/diagnosis --rrd out/diagnosis.rrd
    """
    import numpy as np

    from fieldkit.diagnose.groups import check_folds
    from fieldkit.io.csv_table import check_readable

    if seed is not None and not 0 <= seed <= MAX_SEED:
        raise ArgumentError(
            f"seed must be between 0 and 2^64 - 1 (got {seed})", source="seed"
        )
    check_folds(folds)
    from fieldkit.diagnose.survey_loop import check_loop_options

    check_loop_options(null, power, null_quantile, workers)
    for path in input_files:
        check_readable(path)
    input_file = input_files[0]
    from fieldkit.cli.design import check_design_rocks, measured_values

    if (at or measured) and output is None:
        raise ArgumentError(
            "--at and --measured set the design quantities of the model diagnose "
            "writes: give -o (and --model)",
            source="at" if at else "measured",
        )
    check_design_rocks(design_rocks)
    design_measured = measured_values(measured, preset) if output else []
    if output is not None and model is None:
        raise ArgumentError(
            "-o needs --model (the base model supplies profile, body and seeder)",
            source="output",
        )
    inputs = [*input_files] + ([model] if model is not None else [])
    with OutputSet(inputs=[*inputs, preset]) as outputs:
        outputs.confine(report_dir)
        if json_file is not None:
            outputs.plan(json_file, argument="--json")
        if report_dir is not None:
            outputs.plan(report_dir / "report.md", argument="--report")
        if rrd is not None:
            outputs.plan(rrd, argument="--rrd")
        if output is not None:
            outputs.plan(output, argument="-o")
        if seed is None:
            seed = secrets.randbits(32)
            note(f"`seed` not given: used {seed}; pass --seed {seed} to reproduce")
        rng = np.random.default_rng(seed)
        if _is_track(input_file):
            if len(input_files) > 1:
                raise ArgumentError(
                    "a track is diagnosed on its own: give one track CSV",
                    source="input_files",
                )
            if null or null_quantile != 0.95:
                raise ArgumentError(
                    "--null and --null-quantile apply to reduced surveys only",
                    source="null",
                )
            if model is not None or output is not None or material or preset:
                raise ArgumentError(
                    "a track is diagnosed at flight level: --model, -o, --material "
                    "and --preset apply to ImpactTables only",
                    source="model",
                )
            if sensitivity:
                raise ArgumentError(
                    "--sensitivity applies to ImpactTables only (a track has no "
                    "assumed launch angles or materials)",
                    source="sensitivity",
                )
            from fieldkit.cli.diagnose_track import diagnose_track_file, track_body
            from fieldkit.diagnose.flights import check_body

            radius, mass, body_notes = track_body(
                input_file, radius_m=radius, mass_kg=mass
            )
            check_body(radius, mass)

            with _step_once_checked(
                f"diagnosing the flights of {input_file}: fitting air drag by "
                f"{folds}-fold cross-validation"
            ) as progress:
                diagnosis = diagnose_track_file(
                    input_file, radius_m=radius, mass_kg=mass, rng=rng, folds=folds,
                    progress=progress,
                )  # fmt: skip
            # stated once the track has passed every check (an error stays alone)
            for line in body_notes:
                note(line)
            diagnosis.notes[0:0] = body_notes
        else:
            if radius is not None or mass is not None:
                raise ArgumentError(
                    "--radius and --mass apply to a track only (an ImpactTable "
                    "gives the body on every row)"
                )
            from fieldkit.diagnose.impacts import diagnose_impacts, impact_count
            from fieldkit.diagnose.survey_loop import DEFAULT_NULL, diagnose_surveyed
            from fieldkit.model.model_file import read_model

            base = read_model(model, outputs=outputs) if model is not None else None
            if output is not None:
                from fieldkit.cli.design import design_points

                design_points(base, at, design_measured)  # refused before the work
            from fieldkit.diagnose.sensitivity import is_surveyed

            joined = _read_tables(input_files)
            mapping = mapped_table(joined, base, material, preset)
            table = mapping.table
            surveyed = is_surveyed(table)
            size = (DEFAULT_NULL if surveyed else 0) if null is None else null
            in_table = size and not surveyed
            if in_table and not {"vin_sd_mps", "vit_sd_mps"} <= set(table.frame):
                raise ArgumentError(
                    "--null needs a reduced survey (a table with assumed launch "
                    "angles: campaigns through the survey and the reduction) or "
                    "a table that gives its impact velocities' errors (vin_sd_mps, "
                    "vit_sd_mps: null tables with those errors)",
                    source="null",
                )
            floor = None
            if in_table:
                from fieldkit.diagnose.table_null import diagnose_with_table_null

                with _bar_once_checked(
                    f"diagnosing {impact_count(table)} against {size} null tables "
                    "of its fitted baseline with its own errors"
                ) as advance:
                    diagnosis = diagnose_with_table_null(
                        table, base, seed=seed, folds=folds, size=size,
                        quantile=null_quantile, progress=advance,
                    )  # fmt: skip
                floor = (diagnosis.null or {}).get("threshold")
            elif size:
                with _bar_once_checked(
                    f"diagnosing {impact_count(table)} with its null and power: "
                    f"{size} effect-free campaigns and {power} per candidate, each "
                    "simulated, surveyed, reduced and diagnosed"
                ) as advance:
                    from fieldkit.diagnose.survey_loop import engine_spec_of
                    from fieldkit.parallel.engine import Engine

                    spec = engine_spec_of(workers)
                    if scheduler is not None:
                        spec = replace(spec, scheduler=scheduler)
                    spec = replace(spec, timeout_s=timeout).check()
                    with Engine(spec, notify=note) as engine:
                        engine.start(tiny=size + power < 4)
                        diagnosis = diagnose_surveyed(
                            table, base, seed=seed, folds=folds, null_size=size,
                            power_size=power, quantile=null_quantile,
                            workers=engine, loop_progress=advance,
                        )  # fmt: skip
                floor = (diagnosis.null or {}).get("threshold")
            else:
                with _step_once_checked(
                    f"diagnosing {impact_count(table)}: scoring the baseline and "
                    f"each candidate effect by {folds}-fold cross-validation"
                ) as progress:
                    diagnosis = diagnose_impacts(
                        table, base, rng=rng, folds=folds, progress=progress
                    )
            if surveyed and not size:
                diagnosis.notes.append(
                    "no null campaigns (--null 0): the verdict is the plain rule's, "
                    "which on a reduced survey cannot tell physics from artefacts of "
                    "the assumed launch angles and the survey error"
                )
            diagnosis.notes.extend(mapping.notes)
            diagnosis.sensitivity = _sensitivity(
                table, base, seed, folds, sensitivity, floor
            )
            if sensitivity is None and not diagnosis.sensitivity:
                diagnosis.notes.append(
                    "sensitivity of the verdict not run: no launch angle of this "
                    "table was assumed (--sensitivity runs it on any table)"
                )
        diagnosis.notes.append(f"fold seed {seed}")
        design = None
        if output is not None:
            from fieldkit.cli.design import design_for_fit

            design, said = design_for_fit(
                {"start": base, "calibrated": diagnosis.arrays["after_model"]},
                at=at, measured=design_measured, rocks=design_rocks, seed=seed,
            )  # fmt: skip
        if json_file is not None:
            data = diagnosis.to_json()
            if design is not None:
                data["design"] = design.to_dict()
            write_json(json_file, data, outputs)
        text = None
        if report_dir is not None:
            with step(f"writing the report and its figures to {report_dir}"):
                text = _write_report(report_dir, diagnosis,
                                     [str(p) for p in inputs], outputs)  # fmt: skip
        if rrd is not None:
            from fieldkit.diagnose.report import markdown
            from fieldkit.viz.diagnose_recording import write_diagnosis_recording

            text = text or markdown(
                diagnosis, title=str(input_file), inputs=[str(p) for p in inputs]
            )
            with step(f"writing the recording {rrd}", announce=False):
                write_diagnosis_recording(rrd, diagnosis, text, outputs=outputs)
        if output is not None:

            from fieldkit.model.model_file import write_model

            after = diagnosis.arrays["after_model"]
            provenance = {
                **after.provenance,
                "diagnose": {
                    "table": ", ".join(str(p) for p in input_files),
                    "material_map": mapping.provenance(),
                    "added": [s.added for s in diagnosis.steps],
                    "cv_rmse_mps": diagnosis.after.cv_rmse,
                    "params_sd": diagnosis.after.params_sd,
                    "design": design.to_dict(),
                },
            }
            write_model(replace(after, provenance=provenance), output, outputs=outputs)
        written = outputs.commit()
    if design is not None:
        from fieldkit.cli.design import print_design

        print_design(design, said)
    for line in _summary(diagnosis):
        typer.echo(line)
    report_written(written)
