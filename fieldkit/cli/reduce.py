"""`fieldkit reduce`: a field survey -> an ImpactTable, a summary and figures."""

from __future__ import annotations

import math
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
    with_flags,
)
from fieldkit.cli.progress import step
from fieldkit.errors import ArgumentError
from fieldkit.impact_table import table_format
from fieldkit.outputs import OutputSet

#: Body values `reduce` needs: none (columns it cannot fill stay NaN).
BODY_NEEDS: tuple[str, ...] = ()

#: Preset ``[reduce]`` keys -> the options they stand for.
PRESET_FLAGS = {
    "theta0_deg": "--theta0",
    "mass_kg": "--mass",
    "radius_m": "--radius",
    "gyration_m": "--gyration",
    "path_id": "--path-id",
}

FIGURE_NAMES = (
    "section.png",
    "en_theta.png",
    "et_impacts.png",
    "energy_partition.png",
    "energy_head.png",
)


@one_line_errors
def reduce(
    impacts: Annotated[
        Path | None,
        typer.Option(
            "--impacts",
            help="Impact points in order of travel: GPX waypoints, or CSV of "
            "x,z (section) / lat,lon,elev / easting,northing,elevation.",
        ),
    ] = None,
    fieldbook: Annotated[
        Path | None,
        typer.Option(
            "--fieldbook",
            help="Rangefinder field book CSV (point, station, "
            "instrument_height_m, target_height_m, TruPulse $PLTIT,HV sentence).",
        ),
    ] = None,
    stations: Annotated[
        Path | None,
        typer.Option("--stations", help="GPS stations of the field book (GPX or CSV)."),
    ] = None,
    trees: Annotated[
        Path | None,
        typer.Option(
            "--trees",
            help="Tree strikes CSV (after_impact, horizontal_distance_m, "
            "strike_height_m): each fixes its flight exactly (three-point solve).",
        ),
    ] = None,
    theta0: Annotated[
        float | None,
        typer.Option(
            "--theta0",
            help="Restitution angle to the ground (degrees) assumed for flights "
            "no tree defines (thesis: 32.6 at Tornado Mountain).",
        ),
    ] = None,
    mass: MassOpt = None,
    radius: RadiusOpt = None,
    gyration: GyrationOpt = None,
    shape: ShapeOpt = None,
    dimensions: DimensionsOpt = None,
    unit_weight: UnitWeightOpt = None,
    units: Annotated[
        str | None,
        typer.Option(
            "--units",
            help="Length unit of CSV columns without a unit in their names: m or ft "
            "(none assumed: such a column is an error without --units; x_m, "
            "'elev (ft)' carry their own; GPX <ele> is metres).",
        ),
    ] = None,
    path_id: Annotated[
        str | None,
        typer.Option(
            "--path-id", help="Rock / path identifier (default: the input file name)."
        ),
    ] = None,
    epsg: Annotated[
        int | None,
        typer.Option(
            "--epsg",
            help="EPSG code of easting/northing columns in a CSV (e.g. 32611).",
        ),
    ] = None,
    gpx_points: Annotated[
        str,
        typer.Option(
            "--gpx-points",
            help="Which GPX points are the impacts: waypoints, route, track or auto.",
        ),
    ] = "waypoints",
    gpx_track: Annotated[
        str | None,
        typer.Option(
            "--gpx-track",
            help="With --gpx-points track or route: the track (or route) to reduce, "
            "by name or number (1 = first), when the GPX has several.",
        ),
    ] = None,
    lenient_checksum: Annotated[
        bool,
        typer.Option(
            "--lenient-checksum",
            help="Accept TruPulse sentences whose checksum does not match.",
        ),
    ] = False,
    friction: Annotated[
        float,
        typer.Option(
            "--friction",
            help="Contact friction mu for the theoretical impact energy "
            "(dke_theory_j; default 0.68, thesis §5.3 / example 6B).",
        ),
    ] = 0.68,
    declination: Annotated[
        float | None,
        typer.Option(
            "--declination",
            help="Magnetic declination (degrees, east positive) added to magnetic "
            "field-book azimuths. Required (0 included) unless the field book's "
            "azimuth_reference column says the azimuths are true.",
        ),
    ] = None,
    position_sigma: Annotated[
        float | None,
        typer.Option(
            "--position-sigma",
            help="Standard uncertainty (m) of each surveyed point (GPS or "
            "rangefinder), in plan and in height, relative to its neighbours "
            "(default 0.5: averaged handheld GNSS under open sky or a rangefinder; "
            "2-5 under forest canopy).",
        ),
    ] = None,
    height_sigma: Annotated[
        float | None,
        typer.Option(
            "--height-sigma",
            help="Standard uncertainty (m) of each tree-strike height (default "
            "0.25: where on the scar the rock's centre passed).",
        ),
    ] = None,
    preset: Annotated[
        Path | None,
        typer.Option(
            "--preset",
            help="A survey preset (TOML, e.g. surveys/tornado_mountain/"
            "boulder_a_preset.toml): its [reduce] values (theta0_deg, mass_kg, "
            "radius_m, gyration_m, path_id) for the options not given; the output "
            "names each value taken from it.",
        ),
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option("-o", "--out", help="Output table: .csv, .parquet or .xlsx."),
    ] = None,
    figures: Annotated[
        Path | None,
        typer.Option(
            "--figures",
            help="Folder for PNG figures: section, theta_i-e_N, e_T, "
            "energy partition, energy head.",
        ),
    ] = None,
) -> None:
    """Reduce a rockfall survey to a per-impact table (thesis §2, §3, §7.1).

    Each flight between two impacts is a parabola (eq. 3.5): fixed exactly by
    a tree strike (three-point solve), else by the restitution angle --theta0.
    Velocities, N/T components on the chord slope, e_N, e_T, energies (KE, RE
    with omega = v/r, energy head) and flight heights go to one row per impact,
    with quality flags (qa_flags) and standard uncertainties (e_n_sd, e_t_sd,
    vi_sd_mps, vf_sd_mps, vin/vit/vfn/vft_sd_mps, theta_i_sd_deg) propagated by
    Monte Carlo from --position-sigma (default 0.5 m in plan and in height per
    point) and --height-sigma (default 0.25 m per tree strike); the summary
    states the model and how many e_n are known to better than 0.1. The table
    records that model (x_sd_m, z_sd_m, strike_height_sd_m) and the correlation
    of each impact's arrival and rebound errors (vin_vfn_corr, vit_vft_corr).

    A flight no ballistic path makes (under --theta0 the next point lies above
    the launch line; a tree strike no parabola reaches) is kept unsolved: its
    reason in flight_unsolved, the velocities at its two ends NaN (not impacts
    for fit and diagnose), a warning line, and the rest of the path reduced.

    Example (thesis Table 2-4, Tornado Mountain boulder A, whose preset holds
    --theta0 32.6 --mass 3750 --radius 0.725 --gyration 0.46 --path-id boulder_a;
    from the repository root):

        fieldkit reduce --impacts surveys/tornado_mountain/boulder_a_impacts.gpx \\
          --trees surveys/tornado_mountain/boulder_a_trees.csv \\
          --preset surveys/tornado_mountain/boulder_a_preset.toml \\
          -o out/boulder_a.csv --figures out/figures
    """
    from fieldkit.reduce.pipeline import ReduceOptions, reduce_path
    from fieldkit.reduce.summary import format_summary, summarize
    from fieldkit.survey import Survey

    from_preset: list[str] = []
    overridden: list[str] = []
    if preset is not None:
        from fieldkit.io.preset import read_preset

        given = read_preset(preset).reduce
        if shape is not None or dimensions is not None:
            given.pop("gyration_m", None)  # the shape gives k
        current = {"theta0_deg": theta0, "mass_kg": mass, "radius_m": radius,
                   "gyration_m": gyration, "path_id": path_id}  # fmt: skip
        for key, value in given.items():
            if current[key] is None:
                current[key] = value
                from_preset.append(f"{PRESET_FLAGS[key]} {value}")
            else:
                overridden.append(f"{PRESET_FLAGS[key]} {current[key]}")
        theta0, mass, radius = (current[k] for k in ("theta0_deg", "mass_kg",
                                                     "radius_m"))  # fmt: skip
        gyration, path_id = current["gyration_m"], current["path_id"]

    if (impacts is None) == (fieldbook is None):
        raise ArgumentError(
            "give either --impacts FILE or --fieldbook FILE --stations FILE",
            source="--impacts" if impacts else "--fieldbook",
        )
    if fieldbook is not None and stations is None:
        raise ArgumentError(
            "--fieldbook needs --stations (the GPS stations file)", source="--stations"
        )
    if stations is not None and fieldbook is None:
        raise ArgumentError("--stations goes with --fieldbook", source="--stations")
    if gpx_track is not None and impacts is None:
        raise ArgumentError(
            "--gpx-track goes with --impacts FILE.gpx", source="--gpx-track"
        )
    if declination is not None and fieldbook is None:
        raise ArgumentError(
            "--declination goes with --fieldbook (GPX and CSV positions have no "
            "azimuths)",
            source="--declination",
        )
    if units is not None and units not in ("m", "ft"):
        raise ArgumentError(f"must be m or ft (got {units!r})", source="--units")
    if theta0 is not None and not (math.isfinite(theta0) and 0.0 < theta0 < 180.0):
        raise ArgumentError(
            f"must be between 0 and 180 degrees (got {theta0:g})", source="--theta0"
        )
    from fieldkit.reduce.uncertainty import (
        DEFAULT_ELEVATION_SIGMA_M,
        DEFAULT_POSITION_SIGMA_M,
        DEFAULT_STRIKE_HEIGHT_SIGMA_M,
        PositionError,
    )

    error_model = PositionError(
        position_sigma_m=(
            DEFAULT_POSITION_SIGMA_M if position_sigma is None else position_sigma
        ),
        elevation_sigma_m=(
            DEFAULT_ELEVATION_SIGMA_M if position_sigma is None else position_sigma
        ),
        strike_height_sigma_m=(
            DEFAULT_STRIKE_HEIGHT_SIGMA_M if height_sigma is None else height_sigma
        ),
    )
    if height_sigma is not None and trees is None:
        raise ArgumentError(
            "--height-sigma goes with --trees (it is the error of tree-strike heights)",
            source="--height-sigma",
        )
    body = body_from_options(
        mass, radius, gyration, shape, dimensions, unit_weight
    ).require(*BODY_NEEDS, source="fieldkit reduce")
    if out is None and figures is None:
        note("no -o/--out or --figures given; printing the summary only")
    if out is not None:
        table_format(out)  # CSV for /dev/null or a FIFO, else by its extension
    outputs = OutputSet(inputs=[impacts, fieldbook, stations, trees, preset])
    outputs.confine(figures)
    if out is not None:
        outputs.plan(out, argument="-o")
    for name in FIGURE_NAMES if figures is not None else ():
        outputs.plan(figures / name, argument="--figures")

    if impacts is not None:
        from fieldkit.io.impacts import read_impacts

        points = read_impacts(
            impacts,
            units=units,
            epsg=epsg,
            gpx_points=gpx_points,
            gpx_track=gpx_track,
        )
        name = impacts.stem
    else:
        from fieldkit.io.fieldbook import read_fieldbook

        points = read_fieldbook(
            fieldbook,
            stations,
            declination_deg=declination,
            lenient=lenient_checksum,
            units=units,
            epsg=epsg,
        )
        name = fieldbook.stem
    tree_set = None
    if trees is not None:
        from fieldkit.io.trees import read_trees

        tree_set = read_trees(trees, points, units=units)
    options = ReduceOptions(
        path_id=path_id or name,
        theta0_deg=theta0,
        body=body,
        friction=friction,
        position_error=error_model,
    )
    survey = Survey(points, tree_set)
    # seconds for a surveyed path (Monte Carlo uncertainty): shown on a terminal
    with step(f"reducing {len(points.frame)} points", announce=False):
        reduction = reduce_path(survey, options)
    table = reduction.table

    if out is not None:
        table.write(out, outputs=outputs)
    if figures is not None:
        from fieldkit.viz.energy_figure import write_energy_figures
        from fieldkit.viz.restitution_figure import write_restitution_figures
        from fieldkit.viz.section_figure import write_section_figure

        paths = [figures / name for name in FIGURE_NAMES]
        write_section_figure(table, paths[0], survey=survey, outputs=outputs)
        write_restitution_figures(table, paths[1], paths[2], outputs=outputs)
        write_energy_figures(table, paths[3], paths[4], outputs=outputs)
    written = outputs.commit()
    if preset is not None:
        note(
            f"from the preset {preset}: {', '.join(from_preset) or 'nothing'}"
            + (f"; from the command line instead: {', '.join(overridden)}"
               if overridden else "")
        )  # fmt: skip
    typer.echo(f"body: {body.description}")
    print_body_notes(body)
    for text in (*points.notes, *(tree_set.notes if tree_set else ())):
        note(text)
    summary = summarize(table, reduction.uncertainty)
    typer.echo(with_flags(format_summary(summary)))
    for path in written:
        rows = f" ({len(table)} rows)" if out is not None and path == out else ""
        typer.echo(f"wrote {path}{rows}")
