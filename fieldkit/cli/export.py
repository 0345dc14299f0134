"""`fieldkit export`: a (calibrated) model file -> another simulator's input files.

Glue only: read the model (and the DEM of a grid target), build the export
(:mod:`fieldkit.export`), write the target's files and its README.md into the
output folder all or nothing.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from fieldkit.cli.common import one_line_errors, parse_point
from fieldkit.cli.progress import report_written, step
from fieldkit.errors import ArgumentError
from fieldkit.io.dem import MAX_DEM_CELLS
from fieldkit.outputs import OutputSet, write_file

FLAGS = {
    "to": "--to",
    "output": "-o",
    "dem": "--dem",
    "release_xy": "--release",
    "releases": "--releases",
    "cellsize_m": "--cellsize",
    "rows": "--rows",
    "model_file": "MODEL",
}


def _refuse_full_folder(folder: Path, force: bool) -> None:
    if folder.exists() and not folder.is_dir():
        raise ArgumentError(f"{folder} exists and is not a folder", source="output")
    if folder.is_dir() and any(folder.iterdir()) and not force:
        raise ArgumentError(
            f"{folder} exists and is not empty (give --force to write into it; files "
            "of the same names are replaced, others left alone; a symbolic link "
            "there is refused, never followed out of the folder)",
            source="output",
        )


@one_line_errors(flags=FLAGS)
def export(
    model_file: Annotated[
        Path, typer.Argument(help="The model file to export (e.g. from fit).")
    ],
    to: Annotated[
        str,
        typer.Option(
            "--to", help="Target: rocfall, crsp, rockyfor3d, ramms, rstone or json."
        ),
    ],
    output: Annotated[Path, typer.Option("-o", help="Output folder.")],
    dem: Annotated[
        Path | None,
        typer.Option(
            "--dem", help="Grid targets: the site's DEM (ESRI ASCII, GeoTIFF)."
        ),
    ] = None,
    release: Annotated[
        str | None,
        typer.Option("--release", help="With --dem: the release point X,Y."),
    ] = None,
    releases: Annotated[
        Path | None,
        typer.Option(
            "--releases",
            help="With --dem, instead of --release: a CSV of release points and/or "
            "polygons in the DEM's coordinates. Columns x, y with their unit "
            "(x_m, y_m) and optionally polygon: rows with a polygon name are that "
            "polygon's vertices in order (the cells whose centre lies inside it "
            "release rocks); rows without one are points (the cell holding each "
            "point releases rocks). A release off the DEM or on nodata is refused, "
            "naming its rows.",
        ),
    ] = None,
    extrude: Annotated[
        bool,
        typer.Option(
            "--extrude",
            help="Grid targets without a DEM: the model's 2-D section extruded "
            "across (--rows cells of --cellsize m).",
        ),
    ] = False,
    cellsize: Annotated[
        float | None,
        typer.Option(
            "--cellsize",
            help="With --extrude: cell size in metres, > 0 (default the profile "
            "length / 500, at least 0.5 m; rstone: a whole number, default 5 m or "
            "the length / 500 rounded up); the grid may have at most "
            f"{MAX_DEM_CELLS:,} cells, as a DEM.",
        ),
    ] = None,
    rows: Annotated[
        int | None,
        typer.Option(
            "--rows",
            help="With --extrude: cells across, 2 or more (default 5; rstone: 61, "
            "one release cell in the middle row; rows x columns at most "
            f"{MAX_DEM_CELLS:,} cells, as a DEM).",
        ),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", help="Write into a folder that is not empty.")
    ] = False,
) -> None:
    """Export a model to another simulator's input files, with a README.md.

    Each target's folder holds its files and a README.md: what was mapped to what,
    what could not be mapped and why, the units converted, and the mismatch left
    where a class or category had to be chosen. Grid targets (rockyfor3d, ramms,
    rstone) are written on a DEM (--dem with --release, or --releases for many
    release cells) or on the model's own section extruded across (--extrude).

    Example (from the repository root):

        fieldkit export surveys/tornado_mountain/model_rocfall_table_7_1.json \\
          --to rocfall -o out/rocfall
        fieldkit export examples/tschamut/model_base.json --to rockyfor3d \\
          --dem tests/data/tschamut2014/terrain.asc \\
          --releases tests/data/tschamut2014/release_points.csv -o out/r3d
    """
    from fieldkit.export.site import site_from_dem
    from fieldkit.export.targets import target
    from fieldkit.io.dem import read_dem
    from fieldkit.io.releases import read_releases
    from fieldkit.model.model_file import read_model

    chosen = target(to)
    if not chosen.grid and (dem is not None or extrude):
        raise ArgumentError(
            f"{chosen.name} is not a grid target: it takes no DEM", source="dem"
        )
    if chosen.grid and (dem is None) == (not extrude):
        raise ArgumentError(
            f"{chosen.name} writes grids: give a DEM (with the release point) or "
            "extrude the model's section, one of the two",
            source="dem",
        )
    if release is not None and dem is None:
        raise ArgumentError("the release point goes with a DEM", source="release_xy")
    if releases is not None and dem is None:
        raise ArgumentError("the release file goes with a DEM", source="releases")
    if release is not None and releases is not None:
        raise ArgumentError(
            "give the release point or a release file, not both", source="releases"
        )
    _refuse_full_folder(output, force)
    inputs = [model_file] + [p for p in (dem, releases) if p is not None]
    with OutputSet(inputs=inputs) as outputs:
        outputs.confine(output)
        model = read_model(model_file, outputs=outputs)
        site = None
        with step(f"exporting to {chosen.name}", announce=False):
            if dem is not None:
                point = (
                    parse_point(release, "--release") if release is not None else None
                )
                site = site_from_dem(
                    model,
                    read_dem(dem),
                    point,
                    releases=read_releases(releases) if releases else None,
                )
            elif extrude:
                given = {"cellsize_m": cellsize, "rows": rows}
                site = chosen.extrude(
                    model, **{k: v for k, v in given.items() if v is not None}
                )
            result = chosen.export(model, site)
        files = dict(result.files)
        if site is not None and not any(n.startswith("site:") for n in result.notes):
            result.notes.insert(0, f"grid: {site.description}")
        files["README.md"] = result.readme(str(model_file))
        for name in files:
            outputs.plan(output / name, argument="-o")
        for name, content in files.items():
            write_file(output / name, _writer(content), outputs)
        with step(f"writing {len(files)} files", announce=False):
            written = outputs.commit()
    report_written(written)
    typer.echo(
        f"{chosen.name}: {len(files)} files -> {output}/ "
        f"({len(result.mapped)} quantities mapped, {len(result.unmapped)} not "
        f"mappable, {len(result.mismatches)} mismatches stated in README.md)"
    )
    for what, why in result.unmapped:
        typer.echo(f"  not mapped: {what}: {why}")


def _writer(content: str | bytes):
    def write(tmp: Path) -> None:
        if isinstance(content, bytes):
            tmp.write_bytes(content)
        else:
            tmp.write_text(content, encoding="utf-8")

    return write
