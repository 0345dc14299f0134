"""`fieldkit view`: a rerun recording (.rrd) of an ImpactTable or a track."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer

from fieldkit.cli.common import (
    DimensionsOpt,
    GyrationOpt,
    MassOpt,
    RadiusOpt,
    ShapeOpt,
    UnitWeightOpt,
    body_from_options,
    note,
    one_line_errors,
    print_body_notes,
    warn,
)
from fieldkit.cli.progress import report_written, step
from fieldkit.cli.track import print_flight_gravity
from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.impact_table import ImpactTable
from fieldkit.io.track_files import detect_format, read_track
from fieldkit.outputs import OutputSet

#: Body values `view` needs to analyse a track (an ImpactTable carries its own).
TRACK_BODY_NEEDS = ("radius_m",)


class InputFormat(StrEnum):
    auto = "auto"
    impacts = "impacts"
    track = "track"
    tracker = "tracker"
    kinovea = "kinovea"


@one_line_errors
def view(
    input_file: Annotated[
        Path,
        typer.Argument(
            metavar="INPUT",
            help="An ImpactTable (CSV, Parquet, XLSX), a fieldkit track CSV "
            "(t_s, x_m, z_m, ...), an OSP Tracker data export or a Kinovea CSV.",
        ),
    ],
    out: Annotated[
        Path, typer.Option("-o", "--out", help="Recording to write (.rrd).")
    ],
    input_format: Annotated[
        InputFormat,
        typer.Option(
            "--format", help="What INPUT is; auto detects it from its header."
        ),
    ] = InputFormat.auto,
    radius: RadiusOpt = None,
    surface_angle: Annotated[
        float | None,
        typer.Option(
            "--surface-angle",
            help="Dip of the impact surface (deg), positive descending in the "
            "direction of travel; estimated from the impacts when omitted.",
        ),
    ] = None,
    mass: MassOpt = None,
    gyration: GyrationOpt = None,
    shape: ShapeOpt = None,
    dimensions: DimensionsOpt = None,
    unit_weight: UnitWeightOpt = None,
    unit: Annotated[
        str | None,
        typer.Option(
            "--unit",
            help="Length unit of a Tracker/Kinovea export: m, cm, mm, in, ft or px "
            "(Tracker default m; Kinovea: from its header when given).",
        ),
    ] = None,
    metres_per_pixel: Annotated[
        float | None,
        typer.Option("--metres-per-pixel", help="Scale for --unit px (m/px)."),
    ] = None,
    y_down: Annotated[
        bool,
        typer.Option("--y-down", help="Kinovea y grows downward (image coordinates)."),
    ] = False,
    fps: Annotated[
        float | None,
        typer.Option("--fps", help="True capture rate, frames/s (with --file-fps)."),
    ] = None,
    file_fps: Annotated[
        float | None,
        typer.Option(
            "--file-fps",
            help="Rate the export's times were computed with (e.g. a 30 fps playback "
            "rate); times are rescaled by file-fps/fps.",
        ),
    ] = None,
    figures: Annotated[
        Path | None,
        typer.Option("--figures", help="Also write PNG figures of a track into DIR."),
    ] = None,
) -> None:
    """Write a rerun recording of an impact table or a track, for the rerun viewer.

    An ImpactTable becomes a section view of every path (one row of the
    `path` timeline each): impact points labelled with e_n and e_t, impact and
    restitution velocity arrows, slope ticks, and e_n, e_t and speeds against
    the impact order (the `impact` timeline). A track (fieldkit's track.csv, or an OSP
    Tracker or Kinovea export) is first analysed like `fieldkit track` does:
    flights found and fitted (each flight's fitted g +/- standard error printed,
    warned beyond 3 standard errors from 9.81), impacts and net contacts (each
    counted once, with its energy efficiency); the recording shows the track,
    the fitted flights, velocity vectors, speed, spin and residuals. A track
    needs --radius (or --shape).

    Examples (from the repository root): an ImpactTable, the true track of
    the rendered net clip, an OSP Tracker export in centimetres:

        fieldkit reduce --impacts surveys/tornado_mountain/boulder_a_impacts.gpx \\
          --trees surveys/tornado_mountain/boulder_a_trees.csv \\
          --preset surveys/tornado_mountain/boulder_a_preset.toml \\
          -o out/boulder_a.csv
        fieldkit view out/boulder_a.csv -o out/boulder_a.rrd

        fieldkit view video/net.truth.csv --radius 0.0375 --mass 0.14 \\
          --gyration 0.02372 -o out/net.rrd --figures out/net

        fieldkit view tests/io/data/osp_tracker_multi_comma_cm.csv \\
          --format tracker --unit cm --radius 0.0375 -o out/ball.rrd

    Then open a recording with `rerun out/boulder_a.rrd`.
    """
    outputs = OutputSet(inputs=[input_file])
    outputs.confine(figures)
    outputs.plan(out, argument="-o")
    if out.suffix.lower() != ".rrd":
        raise ArgumentError(
            f"output must be a .rrd file, got {out.name!r}", source="-o"
        )
    body = body_from_options(mass, radius, gyration, shape, dimensions, unit_weight)
    fmt = input_format.value
    if fmt == "auto":
        fmt = detect_format(input_file)
    from fieldkit.viz import rerun_log

    if fmt == "impacts":
        table = ImpactTable.read(input_file)
        if len(table) == 0:
            raise InputFileError("table has no rows", source=input_file)
        paths = len(table.paths())
        from fieldkit.viz.marks import impact_count_text

        with step(f"recording {len(table):,} table rows of {paths:,} path(s)"):
            table = table.derive()
            rerun_log.write_impact_recording(out, table, outputs=outputs)
            written = outputs.commit()
        typer.echo(
            f"{impact_count_text(table.frame)}, {paths:,} path(s): the section shows "
            "every path "
            "(one row of the path timeline each), e_n, e_t and speeds against the "
            "impact timeline (table row)"
        )
        report_written(written)
        return
    if figures is not None:
        from fieldkit.viz.track_figure import TRACK_FIGURE_NAMES, write_track_figures

        for name in TRACK_FIGURE_NAMES:
            outputs.plan(figures / name, argument="--figures")
    track = read_track(
        input_file,
        fmt,
        unit=unit,
        metres_per_pixel=metres_per_pixel,
        y_down=y_down,
        fps=fps,
        file_fps=file_fps,
    )
    if body.missing(*TRACK_BODY_NEEDS):
        raise ArgumentError(
            "a track needs the body radius to analyse its impacts (or `shape`)",
            source="radius_m",
        )
    from fieldkit.tracking.flights.pipeline import analyse_track

    analysis = analyse_track(
        track,
        radius_m=body.radius_m,
        surface_angle_deg=surface_angle,
        mass_kg=body.mass_kg,
        gyration_m=body.gyration_m,
        path_id=input_file.stem,
    )
    for text in track.meta.get("notes", ()):
        note(text)
    for message in analysis.warnings:
        warn(message)
    print_body_notes(body)
    rerun_log.write_recording(out, analysis, outputs=outputs)
    if figures is not None:
        write_track_figures(figures, analysis, outputs=outputs)
    with step(
        "writing the recording and figures", announce=len(analysis.track) > 20_000
    ):
        written = outputs.commit()
    typer.echo(f"{len(analysis.track)} samples, {analysis.counts_text()}")
    print_flight_gravity(analysis.flights)
    for contact in analysis.contacts:
        typer.echo(f"  {contact.summary()}")
    for line in analysis.net_rows_text():
        typer.echo(f"  {line}")
    report_written(written)
