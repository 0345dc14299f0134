"""`fieldkit profile`: a slope section cut from a DEM, for the simulator.

Along a plan polyline (``--from`` then each ``--to``) or, with ``--from`` alone, down
the line of steepest descent from a release point
(:mod:`fieldkit.model.dem_profile`); materials by chainage ranges. A CSV of section
vertices (``x, z[, material]``, metres or feet) is read instead of a DEM when the
input ends in ``.csv``: checked, converted to metres, materials (re)assigned. Writes a
profile CSV (``x_m`` chainage, ``z_m``, ``plan_x_m``, ``plan_y_m``, ``material`` of the
segment starting at the vertex) that :func:`fieldkit.io.profile_csv.read_profile_csv`
reads back.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer

from fieldkit.cli.common import note, one_line_errors, parse_point
from fieldkit.cli.progress import report_written
from fieldkit.cli.progress import step as progress_step
from fieldkit.errors import ArgumentError
from fieldkit.io.dem import DemGrid, read_dem
from fieldkit.io.profile_csv import read_profile_csv
from fieldkit.model.dem_profile import (
    DEFAULT_MATERIAL,
    Section,
    descent_steps,
    parse_material_ranges,
    profile_along_polyline,
    section_from_vertices,
    steepest_descent_line,
)
from fieldkit.outputs import OutputSet, csv_text, write_text

#: Steepest descent takes about 1 ms a vertex: announce a line that may pass 5 s.
_ANNOUNCE_VERTICES = 5_000

#: Columns of the profile CSV, in order.
COLUMNS = ("x_m", "z_m", "plan_x_m", "plan_y_m", "material")


def profile_csv_text(section: Section) -> str:
    """The profile CSV (module docstring): the last row's material is empty."""
    rows = [list(COLUMNS)]
    materials = (*section.material, "")
    for c, z, x, y, m in zip(
        section.chainage_m, section.z_m, section.plan_x_m, section.plan_y_m, materials,
        strict=True,
    ):  # fmt: skip
        plan = [f"{x:.4f}", f"{y:.4f}"] if math.isfinite(x) else ["", ""]
        rows.append([f"{c:.4f}", f"{z:.4f}", *plan, m])
    return csv_text(rows)  # quoted and formula-escaped by the csv module


def _describe_grid(grid: DemGrid) -> str:
    nrows, ncols = grid.shape
    size = (
        f"{grid.dx_m:g} m"
        if grid.square
        else f"{grid.dx_m:g} x {grid.dy_m:g} m"
    )
    crs = grid.crs.splitlines()[0][:60] if grid.crs else "not given"
    return f"DEM {grid.source}: {nrows} rows x {ncols} columns of {size}; CRS {crs}"


def _ending(section: Section) -> str:
    x, y, z = section.plan_x_m[-1], section.plan_y_m[-1], section.z_m[-1]
    plan = f"({x:.2f}, {y:.2f}), " if math.isfinite(x) else ""
    where = f"at {plan}z {z:.2f} m"
    reasons = {
        "local minimum": "a local minimum (no step lowers z)",
        "flat area": "a flat area",
        "grid edge": "reached the grid edge",
        "nodata": "reached nodata cells",
        "maximum length": "reached --max-length",
        "vertex limit": f"reached the limit of {len(section.chainage_m):,} vertices (a "
        "longer --step or a --max-length ends it sooner)",
        "end of polyline": "the last --to point",
        "end of the CSV": "the last row of the CSV",
    }
    return f"{reasons.get(section.ending, section.ending)} {where}"


def _cut(
    grid: DemGrid,
    start: str,
    to: list[str],
    step: float | None,
    max_length: float | None,
) -> tuple[Section, list[str]]:
    """The section of a DEM, and lines saying how it was cut."""
    start_xy = parse_point(start, "--from")
    vertices = [start_xy, *(parse_point(t, "--to") for t in to)]
    lines = [_describe_grid(grid)]
    spacing = grid.cellsize_m / 2 if step is None else step
    step_text = f"step {spacing:g} m" + (
        " (default: half the cell size)" if step is None else ""
    )
    if len(vertices) > 1:
        if max_length is not None:
            raise ArgumentError("--max-length applies to steepest descent (no --to)")
        section = profile_along_polyline(grid, vertices, spacing)
        lines.append(f"polyline through {len(vertices)} points; {step_text}")
    else:
        steps = descent_steps(grid, spacing, max_length)[2]  # checked before work
        description = "following the line of steepest descent"
        with progress_step(
            description, announce=steps > _ANNOUNCE_VERTICES
        ) as advance:
            section = steepest_descent_line(
                grid, start_xy, spacing, max_length_m=max_length, progress=advance
            )
        lines.append(
            f"steepest descent from ({start_xy[0]:g}, {start_xy[1]:g}), z "
            f"{section.z_m[0]:.2f} m; {step_text}"
        )
    return section, lines


@one_line_errors
def profile(
    dem: Annotated[
        Path,
        typer.Argument(
            metavar="DEM",
            help="Elevation grid: ESRI ASCII grid (.asc) or GeoTIFF, projected "
            "coordinates in metres; or a CSV of section vertices x,z[,material] "
            "(.csv).",
        ),
    ],
    out: Annotated[Path, typer.Option("-o", "--out", help="Profile CSV to write.")],
    start: Annotated[
        str | None,
        typer.Option(
            "--from",
            metavar="X,Y",
            help="Start of the section X,Y in the DEM's coordinates (m): the release "
            "point (required with a DEM).",
        ),
    ] = None,
    to: Annotated[
        list[str] | None,
        typer.Option(
            "--to",
            metavar="X,Y",
            help="Next plan vertex X,Y (m), repeatable: the section follows the "
            "polyline --from, --to, --to ... Without it: the line of steepest "
            "descent from --from.",
        ),
    ] = None,
    step: Annotated[
        float | None,
        typer.Option(
            "--step",
            help="Spacing of the section's vertices along the line (m) (default: "
            "half the cell size; steepest descent allows at most that).",
        ),
    ] = None,
    max_length: Annotated[
        float | None,
        typer.Option(
            "--max-length",
            help="Steepest descent: stop after this plan length (m) (default: the "
            "grid's width plus height).",
        ),
    ] = None,
    materials: Annotated[
        str | None,
        typer.Option(
            "--materials",
            help='Material of each chainage range (m), e.g. "0-40:rock,40-:talus" '
            "(no gaps or overlaps; the last may be open). Default: every segment "
            f"'{DEFAULT_MATERIAL}'.",
        ),
    ] = None,
    units: Annotated[
        str | None,
        typer.Option(
            "--units",
            help="CSV input: m or ft for x and z columns without a unit in their "
            "names.",
        ),
    ] = None,
    figure: Annotated[
        Path | None,
        typer.Option("--figure", help="Write the plan line and the section as PNG."),
    ] = None,
) -> None:
    r"""Cut a slope section from a DEM: along a line, or steepest descent.

    Chainage x_m is the horizontal distance along the plan line; z_m the
    bilinear elevation of the grid. A polyline that leaves the grid or crosses
    nodata is an error; a steepest-descent line stops at a local minimum, a flat
    area, the grid edge or nodata, and says which.

    Example (Tschamut 2014: steepest descent from the release point of run v020,
    rock for the first 40 m, talus beyond):

        fieldkit profile tests/data/tschamut2014/terrain.asc \
          --from 30.602,235.28 --materials "0-40:rock,40-:talus" \
          -o out/profile.csv --figure out/profile.png

    Along a straight line from the release point to where v020 stopped:

        fieldkit profile tests/data/tschamut2014/terrain.asc \
          --from 30.602,235.28 --to 102.22,151.49 --step 1 \
          -o out/profile_line.csv

    A section from a CSV of vertices x, z (here the one just written; a field
    CSV in feet takes --units ft), with its materials:

        fieldkit profile out/profile_line.csv --materials "0-60:rock,60-:talus" \
          -o out/profile_field.csv
    """
    outputs = OutputSet(inputs=[dem])
    outputs.plan(out, argument="-o")
    if figure is not None:
        outputs.plan(figure, argument="--figure")
    if materials is not None:
        parse_material_ranges(materials)  # before any work
    grid: DemGrid | None = None
    vertices_csv = None
    if dem.suffix.lower() == ".csv":
        for given, flag in ((start, "--from"), (to, "--to"), (step, "--step"),
                            (max_length, "--max-length")):  # fmt: skip
            if given:
                raise ArgumentError(f"{flag} applies to a DEM, not a profile CSV")
        vertices_csv = read_profile_csv(dem, units)
        section = section_from_vertices(
            vertices_csv.x_m, vertices_csv.z_m, vertices_csv.material,
            plan_x_m=vertices_csv.plan_x_m, plan_y_m=vertices_csv.plan_y_m,
            source=vertices_csv.source,
        )  # fmt: skip
        lines = [f"profile CSV {dem}: {len(section.chainage_m)} vertices"]
    else:
        if units is not None:
            raise ArgumentError("--units applies to a profile CSV; a DEM is in metres")
        if start is None:
            raise ArgumentError("a DEM needs --from X,Y (the start of the section)")
        grid = read_dem(dem)
        section, lines = _cut(grid, start, to or [], step, max_length)
    if materials is not None:
        section = section.with_materials(materials)
        spans = []
        for name in dict.fromkeys(section.material):
            seg = [i for i, m in enumerate(section.material) if m == name]
            spans.append(
                f"{name} {section.chainage_m[seg[0]]:.1f}-"
                f"{section.chainage_m[seg[-1] + 1]:.1f} m"
            )
        material_text = "materials: " + ", ".join(spans)
    elif vertices_csv is not None and vertices_csv.material is not None:
        material_text = "materials: from the CSV"
    else:
        material_text = (
            f"materials: every segment '{DEFAULT_MATERIAL}' (no --materials given)"
        )
    lines.append(
        f"section: {len(section.chainage_m)} vertices, {section.length_m:.1f} m long, "
        f"drop {section.drop_m:.1f} m; ended: {_ending(section)}"
    )
    lines.append(material_text)
    write_text(out, profile_csv_text(section), outputs)
    if figure is not None:
        from fieldkit.viz.profile_figure import save_profile_figure

        save_profile_figure(grid, section, figure, outputs=outputs)
    typer.echo("\n".join(lines))
    for text in grid.notes if grid is not None else ():
        note(text)
    report_written(outputs.commit())
