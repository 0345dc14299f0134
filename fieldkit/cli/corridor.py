"""`fieldkit corridor`: design energies, bounce heights and passing fractions every
few metres along a road, railway or barrier line (:mod:`fieldkit.corridor.scan`),
its units of work run through the Dask engine (:mod:`fieldkit.parallel.engine`)."""

from __future__ import annotations

import secrets
from pathlib import Path
from typing import Annotated

import typer

from fieldkit.cli.common import FLAGS, note, one_line_errors, warn
from fieldkit.cli.engine_options import (
    ENGINE_FLAGS,
    Retries,
    Scheduler,
    Timeout,
    WorkerMemory,
    Workers,
    engine_spec,
)
from fieldkit.errors import ArgumentError

CORRIDOR_FLAGS = {
    **FLAGS,
    **ENGINE_FLAGS,
    "spacing_m": "--spacing",
    "rocks": "--rocks",
    "upslope_m": "--upslope",
    "beyond_m": "--beyond",
    "release_band_m": "--release-band",
    "material_ranges": "--materials",
    "ranges": "--materials",
    "step_m": "--step",
    "seed": "--seed",
}


def class_runs(frame) -> list[str]:
    """Stretches of consecutive stations with the same ETAG 027 class at p99, as
    lines ``chainage a-b m: class k`` (``no p99`` where too few rocks crossed)."""
    import pandas as pd

    c = frame["chainage_m"].to_numpy(float)
    cls = [None if pd.isna(v) else int(v) for v in frame["etag027_class_p99"]]
    out, start = [], 0
    for i in range(1, len(cls) + 1):
        if i == len(cls) or cls[i] != cls[start]:
            k = cls[start]
            what = "no p99 (fewer than 20 rocks crossed)" if k is None else f"class {k}"
            out.append(f"  chainage {c[start]:7.1f}-{c[i - 1]:7.1f} m: {what}")
            start = i
    return out


@one_line_errors(flags=CORRIDOR_FLAGS)
def corridor(
    dem: Annotated[Path, typer.Argument(help="The DEM (ESRI ASCII grid or GeoTIFF).")],
    alignment: Annotated[
        Path,
        typer.Option(
            "--alignment",
            help="CSV of the alignment's vertices in order "
            "(columns x_m, y_m, in the DEM's coordinates).",
        ),
    ],  # fmt: skip
    model: Annotated[
        Path,
        typer.Option(
            "--model",
            help="Model file: a profile (2-D) model -- each "
            "station gets its own section -- or a terrain (3-D) model on "
            "this DEM.",
        ),
    ],  # fmt: skip
    out: Annotated[
        Path, typer.Option("-o", "--output", help="The corridor table (CSV).")
    ],
    spacing: Annotated[
        float,
        typer.Option("--spacing", help="Station spacing along the alignment (m)."),
    ] = 10.0,
    rocks: Annotated[
        int,
        typer.Option("--rocks", help="Rocks per station (2-D) or in all (3-D)."),
    ] = 10_000,
    seed: Annotated[int | None, typer.Option("--seed", help="Random seed.")] = None,
    figures: Annotated[
        Path | None,
        typer.Option("--figures", help="Folder for chainage.png and plan.png."),
    ] = None,
    rrd: Annotated[
        Path | None, typer.Option("--rrd", help="Write a rerun scene (.rrd).")
    ] = None,
    summary: Annotated[
        Path | None,
        typer.Option(
            "--summary",
            help="Write the settings, notes and where the work ran as JSON.",
        ),
    ] = None,  # fmt: skip
    upslope: Annotated[
        float,
        typer.Option(
            "--upslope",
            help="2-D: section length above the alignment (m); rocks start at its top.",
            rich_help_panel="2-D sections",
        ),
    ] = 150.0,  # fmt: skip
    beyond: Annotated[
        float,
        typer.Option(
            "--beyond",
            help="2-D: section length below the alignment (m).",
            rich_help_panel="2-D sections",
        ),
    ] = 20.0,  # fmt: skip
    release_band: Annotated[
        float,
        typer.Option(
            "--release-band",
            help="2-D: rocks start along the top this-many "
            "m of each section (0: at its top).",
            rich_help_panel="2-D sections",
        ),
    ] = 0.0,  # fmt: skip
    materials: Annotated[
        str | None,
        typer.Option(
            "--materials",
            help="2-D: material of each chainage range from "
            'the section\'s top, e.g. "0-60:rock,60-:talus" (default: the '
            "model's only material).",
            rich_help_panel="2-D sections",
        ),
    ] = None,  # fmt: skip
    step: Annotated[
        float | None,
        typer.Option(
            "--step",
            help="2-D: section vertex spacing (m) (default: half a DEM cell).",
            rich_help_panel="2-D sections",
        ),
    ] = None,  # fmt: skip
    workers: Workers = None,
    scheduler: Scheduler = None,
    worker_memory: WorkerMemory = None,
    timeout: Timeout = 10.0,
    retries: Retries = 2,
) -> None:
    r"""Scan a corridor: design energy, bounce height and passing fraction per station.

    Stations every --spacing m along the alignment. With a profile (2-D) model each
    station gets a DEM section across the alignment (--upslope m on the higher
    side, --beyond m below) with --rocks rocks from its top; with a terrain (3-D)
    model --rocks rocks from the model's releases are counted where they first
    cross the alignment. Per station: the passing fraction, p95/p99 of the kinetic
    energy and bounce height with their Monte Carlo SEs, and the ETAG 027 class
    covering the p99 energy. The stations (2-D) or units of 2,000 rocks (3-D) run
    on a local Dask cluster, a running scheduler (--scheduler) or in this process
    (--workers 0); each has its own seed, so the numbers do not depend on where.

    Example (Tschamut 2014: an alignment across the slope foot, 2-D sections):

        fieldkit corridor tests/data/tschamut2014/terrain.asc \
          --alignment examples/tschamut/alignment.csv \
          --model examples/tschamut/model_base.json --upslope 80 \
          --rocks 2000 --seed 1 -o out/corridor.csv --figures out/corridor

    The same line with the 3-D model on two local workers:

        fieldkit corridor tests/data/tschamut2014/terrain.asc \
          --alignment examples/tschamut/alignment.csv \
          --model examples/tschamut/model_3d.json --rocks 20000 --seed 1 \
          --workers 2 -o out/corridor3d.csv --rrd out/corridor3d.rrd
    """
    from fieldkit.cli.progress import report_written
    from fieldkit.cli.progress import step as progress_step
    from fieldkit.corridor.scan import (
        TINY_ROCKS,
        UNIT_ROCKS_3D,
        check_rocks,
        check_same_dem,
        scan2d,
        scan3d,
    )
    from fieldkit.corridor.sections import SectionSetup, check_base_model
    from fieldkit.corridor.stations import check_on_dem, stations_along
    from fieldkit.io.alignment import read_alignment
    from fieldkit.io.dem import read_dem
    from fieldkit.model.dem_profile import parse_material_ranges
    from fieldkit.model.model_file import read_model
    from fieldkit.model.terrain_file import terrain_from_dem
    from fieldkit.outputs import OutputSet, write_file, write_json
    from fieldkit.parallel.engine import Engine

    spec = engine_spec(workers, scheduler, worker_memory, timeout, retries)
    check_rocks(rocks)
    if seed is not None and not 0 <= seed <= 2**64 - 1:
        raise ArgumentError(f"seed must be an integer from 0 to 2**64 - 1 (got {seed})",
                            source="seed")  # fmt: skip
    outputs = OutputSet(inputs=[dem, alignment, model])
    outputs.plan(out, argument="-o")
    outputs.confine(figures)
    if figures is not None:
        for name in ("chainage.png", "plan.png"):
            outputs.plan(figures / name, argument="--figures")
    if rrd is not None:
        outputs.plan(rrd, argument="--rrd")
    if summary is not None:
        outputs.plan(summary, argument="--summary")
    setup = SectionSetup(upslope, beyond, release_band, materials, step).check()
    if materials is not None:
        parse_material_ranges(materials)
    xy = read_alignment(alignment)
    stations = stations_along(xy, spacing)  # spacing checked before the DEM is read
    grid = read_dem(dem)
    the_model = read_model(model, outputs=outputs, terrain=True)
    three_d = not hasattr(the_model, "profile")
    if three_d:
        given = {
            "--upslope": upslope != 150.0,
            "--beyond": beyond != 20.0,
            "--release-band": release_band != 0.0,
            "--materials": materials is not None,
            "--step": step is not None,
        }
        for flag, on in given.items():  # fmt: skip
            if on:
                raise ArgumentError(f"{flag} cuts 2-D sections; {model} is a terrain "
                                    "(3-D) model")  # fmt: skip
    if three_d:
        check_same_dem(the_model, grid)
    check_on_dem(stations, grid)
    if not three_d:
        check_base_model(the_model, setup)
    if seed is None:
        seed = secrets.randbits(32)
        note(f"`seed` not given: used {seed}; pass --seed {seed} to reproduce")
    with Engine(spec, notify=note) as engine:
        n = len(stations)
        engine.start(tiny=rocks * (1 if three_d else n) <= TINY_ROCKS)
        what = (f"{rocks:,} rocks from the model's releases across {n} stations"
                if three_d else f"{n} stations x {rocks:,} rocks")  # fmt: skip
        units = -(-rocks // UNIT_ROCKS_3D) if three_d else n
        with progress_step(f"corridor scan: {what}", total=units) as advance:
            if three_d:
                scan = scan3d(the_model, grid, xy, spacing, rocks, seed, engine,
                              progress=advance)  # fmt: skip
            else:
                scan = scan2d(grid, xy, spacing, the_model, rocks, seed, engine,
                              setup=setup, progress=advance)  # fmt: skip
    for text in scan.notes:
        note(text)
    for line in engine.retried:
        warn(line)
    frame = scan.frame
    # 10 digits: a station's x in a national grid (2780001.234 m, LV95) to the mm
    write_file(out, lambda tmp: frame.to_csv(tmp, index=False, float_format="%.10g"),
               outputs)  # fmt: skip
    if summary is not None:
        write_json(summary, scan.summary(), outputs)
    terrain = terrain_from_dem(grid) if (figures or rrd) else None
    if figures is not None:
        from fieldkit.viz.corridor_figure import (
            write_chainage_figure,
            write_plan_figure,
        )

        title = (
            f"corridor scan ({scan.dimension}-D), {scan.rocks:,} rocks "
            f"{'per station' if scan.dimension == 2 else 'in all'}, seed {seed}"
        )
        write_chainage_figure(figures / "chainage.png", frame, title=title,
                              outputs=outputs)  # fmt: skip
        write_plan_figure(figures / "plan.png", terrain, scan, outputs=outputs)
    if rrd is not None:
        from fieldkit.viz.corridor_recording import write_corridor_recording

        write_corridor_recording(rrd, terrain, scan, outputs=outputs)
    written = outputs.commit()
    echo = typer.echo
    echo(
        f"{len(scan.stations)} stations over {scan.stations.length_m:.1f} m; "
        f"{scan.impacts:,} impacts in {scan.units} units, {scan.wall_s:.1f} s "
        f"(seed {seed}); ran on {scan.engine['where']}"
    )
    s = scan.summary()["largest_p99_energy"]
    if s is not None:
        echo(
            f"largest p99 energy: {s['energy_p99_kj']:.4g} ± "
            f"{s['energy_p99_se_kj']:.2g}"
            f" kJ at station {s['station']} (chainage {s['chainage_m']:.1f} m)"
        )
    echo("ETAG 027 class covering the p99 energy (before design-code factors):")
    for line in class_runs(frame):
        echo(line)
    echo("± = Monte Carlo standard error (percentiles: order-statistic interval)")
    report_written(written)
