"""`fieldkit import-results`: a target program's output grids -> a fieldkit result.

Glue only: r.stone's counter, maxvel and maxdz grids and the export's record of the
grid (:mod:`fieldkit.io.rstone_results`) read into the runout distribution and the
largest speed, energy and height along the path, written as CSV and JSON.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from fieldkit.cli.common import one_line_errors, warn
from fieldkit.cli.progress import report_written
from fieldkit.errors import ArgumentError
from fieldkit.outputs import OutputSet, write_json, write_text

FLAGS = {"source": "--from", "output": "-o", "folder": "FOLDER"}

#: What the command writes into ``-o``.
TABLE, SUMMARY, FIGURE = "along.csv", "summary.json", "along.png"


@one_line_errors(flags=FLAGS)
def import_results(
    folder: Annotated[
        Path,
        typer.Argument(
            help="The folder `fieldkit export --to rstone` wrote, after run_rstone.sh "
            "(counter.asc, maxvel.asc, maxdz.asc, fieldkit_export.json)."
        ),
    ],
    source: Annotated[str, typer.Option("--from", help="The program: rstone.")],
    output: Annotated[
        Path, typer.Option("-o", help=f"Output folder ({TABLE}, {SUMMARY}, {FIGURE}).")
    ],
) -> None:
    """Read r.stone's result grids back as a fieldkit result.

    Writes the runout distribution (survival of the traced trajectories against
    the chainage of an extruded section, or the plan distance from the release on
    a DEM), and the largest speed, energy and height above the ground along it:
    along.csv (one row per column or one-cell distance bin) and summary.json
    (runout percentiles, trajectories stated and traced, trajectories that reached
    the grid's edge).

    Example (from the repository root): the bundled grids of a real r.stone run
    (GRASS 8.2.1) on the Tornado Mountain export,

        fieldkit import-results examples/rstone_tornado --from rstone \\
          -o out/rstone_results

    made with (the last two lines in a shell with GRASS GIS and r.stone):

        fieldkit export surveys/tornado_mountain/model_path_calibrated.json \\
          --to rstone --extrude -o out/rstone
        grass -c XY /tmp/grassdb/xy -e
        grass /tmp/grassdb/xy/PERMANENT --exec bash out/rstone/run_rstone.sh
    """
    from fieldkit.io.rstone_results import (
        GRIDS,
        RECORD,
        along_path,
        read_rstone_results,
        runout_percentiles,
    )
    from fieldkit.viz.figure_files import save_png
    from fieldkit.viz.rstone_figure import rstone_along_figure

    if source != "rstone":
        raise ArgumentError(
            f"unknown program {source!r} (known: rstone)", source="source"
        )
    if not folder.is_dir():
        raise ArgumentError(f"{folder} is not a folder", source="folder")
    inputs = [folder / RECORD, *(folder / f"{g}.asc" for g in GRIDS)]
    with OutputSet(inputs=[p for p in inputs if p.exists()]) as outputs:
        outputs.confine(output)
        results = read_rstone_results(folder)
        table, distance = along_path(results)
        runout = runout_percentiles(table)
        edges = results.edge_counts()
        extruded = results.record["extruded"]
        sides = ("north", "south") if extruded else tuple(edges)
        summary = {
            "program": "rstone",
            "folder": str(folder),
            "distance": distance,
            "trajectories_stated": results.stated,
            "trajectories_traced": results.traced,
            "counter_on_source_cells": results.on_sources,
            "runout_m": runout,
            "edge_counts": edges,
            "left_the_grid": {s: edges[s] for s in sides},
            "max_speed_mps": float(table["max_speed_mps"].max()),
            "max_energy_kj": float(table["max_energy_kj"].max()),
            "max_height_m": float(table["max_height_m"].max()),
            "mass_kg": float(results.record["mass_kg"]),
            "cellsize_m": results.cellsize_m,
            "notes": [
                "survival at a distance: the largest counter sum at that distance "
                "or beyond over the trajectories traced (a trajectory can skip a "
                "cell: r.stone keeps path points about 5 m apart)",
                "runout pQ: the farthest distance that a fraction 1 - Q/100 of the "
                "trajectories reaches; good to about one cell",
                "max_speed_mps and max_height_m: r.stone's maxvel and maxdz, whole "
                "m/s and whole metres, truncated; max_energy_kj = m v^2 / 2 "
                "(translational: r.stone's block is a point)",
            ],
        }
        for name in (TABLE, SUMMARY, FIGURE):
            outputs.plan(output / name, argument="-o")
        write_text(output / TABLE, table.to_csv(index=False), outputs)
        write_json(output / SUMMARY, summary, outputs)
        save_png(
            rstone_along_figure(
                table,
                distance,
                f"r.stone: {results.traced} trajectories "
                f"(runout p50 {runout['p50']:g} m, p95 {runout['p95']:g} m)",
            ),
            output / FIGURE,
            outputs=outputs,
        )
        written = outputs.commit()
    if results.traced != results.stated:
        warn(
            f"r.stone traced {results.traced} of the {results.stated} trajectories "
            f"the export started ({RECORD})"
        )
    left = {s: n for s, n in summary["left_the_grid"].items() if n}
    if left:
        warn(
            "trajectories reached the grid's edge, where r.stone stops them (not a "
            "runout): " + ", ".join(f"{s} {n}" for s, n in left.items())
        )
    report_written(written)
    typer.echo(
        f"rstone: {results.traced} trajectories traced; runout p50 "
        f"{runout['p50']:g} m, p95 {runout['p95']:g} m ({distance})"
    )
