"""`fieldkit fit`: fit a model's impact laws to an ImpactTable."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Annotated

import typer

from fieldkit.cli.common import one_line_errors
from fieldkit.outputs import OutputSet, write_text

FLAGS = {"output": "-o", "model": "--model", "report_dir": "--report"}


@one_line_errors(flags=FLAGS)
def fit(
    table_file: Annotated[
        Path,
        typer.Argument(
            metavar="TABLE", help="The ImpactTable (.csv, .parquet, .xlsx)."
        ),
    ],
    model_file: Annotated[
        Path, typer.Option("--model", help="The base model file (§5).")
    ],
    output: Annotated[
        Path, typer.Option("-o", help="The calibrated model file to write.")
    ],
    report: Annotated[
        Path | None,
        typer.Option(
            "--report", help="Write report.md and residuals.png into this folder."
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
    bound, not identifiable, or unchanged.

    Example (from the repository root):

        fieldkit synth surveys/tornado_mountain/model_rocfall_table_7_1.json \\
          --paths 20 --seed 1 \\
          --effects angle_dependent_restitution=b=1.2 -o out/synth.csv

        fieldkit fit out/synth.csv \\
          --model surveys/tornado_mountain/model_rocfall_table_7_1.json \\
          -o out/calibrated.json --report out/fit
    """
    from fieldkit.fit.impact_fit import fit_impacts
    from fieldkit.impact_table import ImpactTable
    from fieldkit.model.model_file import read_model, write_model

    with OutputSet(inputs=[table_file, model_file]) as outputs:
        outputs.plan(output, argument="-o")
        if report is not None:
            outputs.plan(report / "report.md", argument="--report")
            outputs.plan(report / "residuals.png", argument="--report")
        model = read_model(model_file)
        table = ImpactTable.read(table_file)
        result, calibrated = fit_impacts(table, model)
        provenance = {
            **calibrated.provenance,
            "fit": result.provenance(str(table_file)),
        }
        write_model(replace(calibrated, provenance=provenance), output, outputs=outputs)
        text = result.report()
        if report is not None:
            from fieldkit.viz.fit_figure import write_residual_figure

            derived = table.derive()
            write_text(
                report / "report.md",
                f"# Impact fit\n\ntable: `{table_file}`, base model: `{model_file}`\n\n"
                f"```\n{text}\n```\n\n![residuals](residuals.png)\n",
                outputs,
            )
            write_residual_figure(
                report / "residuals.png",
                result,
                derived.column("theta_i_deg"),
                derived.column("vi_mps"),
                outputs=outputs,
            )
        outputs.commit()
    typer.echo(text)
    typer.echo(f"calibrated model -> {output}")
