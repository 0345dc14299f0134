"""`fieldkit track3d`: 3-D trajectory samples on a DEM -> ImpactTable."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import numpy as np
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
from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.impact_table import table_format
from fieldkit.outputs import OutputSet

#: Default contact tolerance [m]: how far beyond its radius from the DEM's ground
#: plane the centre may be at an impact (DEM and fit error).
DEFAULT_TOLERANCE_M = 0.1


@one_line_errors(flags={"tolerance_m": "--tolerance", "footprint_m": "--footprint",
                        "noise_sd_m": "--noise-sd",
                        "drag_per_m": "--air-drag"})  # fmt: skip
def track3d(
    trajectories: Annotated[
        Path,
        typer.Argument(
            help="CSV of samples: path_id (or trajectory/run/id), t_s, x_m, y_m, z_m "
            "(the block's centre in the DEM's coordinates), optional omega_radps or "
            "omega_x_radps, omega_y_radps, omega_z_radps.",
            show_default=False,
        ),
    ],
    dem: Annotated[
        Path | None,
        typer.Option("--dem", help="DEM (ESRI ASCII grid or GeoTIFF, square cells)."),
    ] = None,
    radius: RadiusOpt = None,
    mass: MassOpt = None,
    gyration: GyrationOpt = None,
    shape: ShapeOpt = None,
    dimensions: DimensionsOpt = None,
    unit_weight: UnitWeightOpt = None,
    tolerance: Annotated[
        float,
        typer.Option(
            "--tolerance",
            help="Contact tolerance (m): at an impact the centre lies within radius + "
            "this of the DEM's ground plane, and two flights meet within this.",
        ),
    ] = DEFAULT_TOLERANCE_M,
    footprint: Annotated[
        float | None,
        typer.Option(
            "--footprint",
            help="Radius (m) of the disc of DEM the ground plane at a contact is "
            "fitted over (default: the block's radius).",
        ),
    ] = None,
    noise_sd: Annotated[
        float | None,
        typer.Option(
            "--noise-sd",
            help="SD of the position noise per coordinate (m); default: estimated "
            "from each trajectory (stated).",
        ),
    ] = None,
    air_drag: Annotated[
        float,
        typer.Option(
            "--air-drag",
            help="Quadratic air drag of the flights, k = rho C_d A / (2 m) in 1/m "
            "(dv/dt = -g z - k |v| v); default 0: ballistic (stated).",
        ),
    ] = 0.0,
    material: Annotated[
        str | None,
        typer.Option(
            "--material",
            help="Slope material label of every impact (fit and diagnose group "
            "impacts by it; default: empty, stated).",
        ),
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option("-o", "--out", help="ImpactTable: .csv, .parquet or .xlsx."),
    ] = None,
) -> None:
    """Reduce 3-D trajectories (x, y, z, t at 100-200 Hz) on a DEM to an ImpactTable.

    Flights are ballistic fits with g = 9.81 m/s^2 fixed (no air drag unless
    --air-drag gives its parameter). Two
    consecutive flights meeting within --tolerance, with the centre within
    radius + --tolerance of the ground plane fitted to the DEM over the
    block's footprint, are an impact; a join anywhere else is reported as a
    misfit, never as an impact. Rows follow the 3-D simulator's convention
    (N the ground's normal, T in the plane of incidence; docs/terrain-model.md),
    with chainage_m, lateral_deg, contact_duration_s and contact_height_m.

    Example (from the repository root; the first line writes 8 simulated rocks
    sampled at 200 Hz with 2 cm noise, the DEM and the truth):

        python examples/track3d/make_runs.py out/track3d
        fieldkit track3d out/track3d/trajectories.csv \\
          --dem out/track3d/valley.asc --radius 0.2 --mass 100 \\
          --material ground -o out/track3d/impacts.csv
    """
    from fieldkit.io.dem import read_dem
    from fieldkit.model.terrain_file import terrain_from_dem
    from fieldkit.tracking.trajectory3d.impacts import (
        Body3D,
        impact_rows,
        reduce_trajectory,
    )
    from fieldkit.tracking.trajectory3d.samples import read_trajectories

    if dem is None:
        raise ArgumentError("a DEM is required (the ground at every contact)",
                            source="--dem")  # fmt: skip
    if not air_drag >= 0:
        raise ArgumentError(f"drag_per_m must be >= 0 1/m (got {air_drag:g})",
                            source="drag_per_m")  # fmt: skip
    for value, name in ((tolerance, "tolerance_m"), (footprint, "footprint_m"),
                        (noise_sd, "noise_sd_m")):  # fmt: skip
        if value is not None and not (math.isfinite(value) and value >= 0):
            raise ArgumentError(f"{name} must be a length >= 0 m (got {value:g})",
                                source=name)  # fmt: skip
    if footprint is not None and footprint <= 0:
        raise ArgumentError(f"footprint_m must be > 0 m (got {footprint:g})",
                            source="footprint_m")  # fmt: skip
    body = body_from_options(mass, radius, gyration, shape, dimensions, unit_weight)
    body.require("radius_m", source="fieldkit track3d")
    if out is not None:
        table_format(out)
    outputs = OutputSet(inputs=[trajectories, dem])
    if out is not None:
        outputs.plan(out, argument="-o")
    else:
        note("no -o given; printing the summary only")
    runs = read_trajectories(trajectories)
    terrain = terrain_from_dem(read_dem(dem))
    for run in runs:
        over = np.isfinite(terrain.heights(run.xyz_m[:, 0], run.xyz_m[:, 1]))
        if not over.any():
            x0, y0, x1, y1 = terrain.surface_extent()
            raise InputFileError(
                f"trajectory {run.path_id}: no sample lies over the DEM's surface "
                f"(x {x0:.10g}..{x1:.10g}, y {y0:.10g}..{y1:.10g} m; the first "
                f"sample is at x {run.xyz_m[0, 0]:.10g}, y {run.xyz_m[0, 1]:.10g}): "
                "are the trajectory and the DEM in the same coordinates?",
                source=str(trajectories),
                where=f"row {run.rows[0]}",
            )
    print_body_notes(body)
    nan = float("nan")
    gyration_m = body.gyration_m
    if gyration_m is None:
        gyration_m = math.sqrt(0.4) * body.radius_m
        note(f"no --gyration, --shape or --dimensions: gyration_m {gyration_m:.4g} m, "
             "a solid sphere's (k = sqrt(2/5) r), as a model file's default")
    b3 = Body3D(
        body.radius_m,
        body.mass_kg if body.mass_kg is not None else nan,
        gyration_m,
    )
    foot = body.radius_m if footprint is None else footprint
    if air_drag > 0:
        note(f"flights: g = 9.81 m/s^2 fixed and quadratic air drag k = "
             f"{air_drag:g} 1/m (--air-drag)")  # fmt: skip
    else:
        note("flights: ballistic fits with g = 9.81 m/s^2 fixed, no air drag "
             "(--air-drag 0, the default)")  # fmt: skip
    note(
        f"ground at each contact: a plane fitted to the DEM over a disc of radius "
        f"{foot:g} m{' (the block radius)' if footprint is None else ''} "
        "(surface_footprint_m); an impact needs the centre within radius + "
        f"tolerance = {body.radius_m + tolerance:g} m of it"
        + (" (--tolerance default)" if tolerance == DEFAULT_TOLERANCE_M else "")
    )
    reductions = []
    with step(f"reducing {len(runs)} trajectories", announce=len(runs) > 20):
        for run in runs:
            reductions.append((
                reduce_trajectory(run, terrain, b3, tolerance_m=tolerance,
                                  footprint_m=foot, noise_sd_m=noise_sd,
                                  drag_per_m=air_drag),
                run,
            ))  # fmt: skip
    table = impact_rows(reductions, b3, foot, material)
    if material is None:
        note("no --material: the material column is empty (give --material NAME "
             "to fit or diagnose the table)")
    for red, _ in reductions:
        noise = (f"noise SD {1e3 * red.noise_sd_m:.1f} mm "
                 f"({'estimated' if red.noise_estimated else 'given'})")  # fmt: skip
        typer.echo(
            f"{red.path_id}: {red.samples} samples at {1 / red.interval_s:.0f} Hz, "
            f"{noise}; {len(red.flights)} flights, {len(red.impacts)} impacts, "
            f"{len(red.misfits)} misfits"
        )
        for m in red.misfits:
            warn(f"{red.path_id}: {m.reason}")
    if any(run.omega_radps is None and run.omega_vector_radps is None
           for _, run in reductions):  # fmt: skip
        note("no omega_radps or omega_x/y/z_radps columns: omega_i/omega_f empty "
             "(omega_source none)")
    elif any(run.omega_vector_radps is not None for _, run in reductions):
        note("spin: the angular velocity's component about N x T at each impact, "
             "omega = -w . (N x T) (rolling toward travel negative)")
    f = table.frame
    resolved = int(f["contact_duration_s"].notna().sum()) if len(f) else 0
    note(
        f"contact_duration_s: {resolved} of {len(f)} impacts resolved by the "
        "sampling; empty where the two flights meet within one sampling interval"
    )
    typer.echo(f"{len(f)} impacts from {len(runs)} trajectories")
    if out is not None:
        table.write(out, outputs=outputs)
        report_written(outputs.commit())
