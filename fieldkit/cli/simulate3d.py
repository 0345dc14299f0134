"""`fieldkit simulate` on a 3-D model file (a ``terrain`` block): the run and its
outputs. Called by :mod:`fieldkit.cli.simulate` when the model file describes a
DEM; not a command of its own."""

from __future__ import annotations

import secrets
from pathlib import Path

import numpy as np
import typer

from fieldkit.cli.common import note, warn
from fieldkit.errors import ArgumentError
from fieldkit.outputs import OutputSet, write_file, write_json

#: Options of `fieldkit simulate` that read a profile (2-D) model only.
PROFILE_ONLY = {
    "at": "--at",
    "measured": "--measured",
    "envelope_dx": "--envelope-dx",
}
#: Options of `fieldkit simulate` that read a terrain (3-D) model only.
TERRAIN_ONLY = {
    "deposits": "--deposits",
    "rasters": "--rasters",
    "line": "--line",
    "observed": "--observed",
}
#: Most rocks one run follows (as in 2-D).
MAX_ROCKS = 10_000_000


def refuse_options(given: dict[str, object], which: dict[str, str], why: str) -> None:
    """Refuse every option of ``which`` that was given (not None / empty)."""
    for key, flag in which.items():
        if given.get(key):
            raise ArgumentError(f"{flag} {why}", source=flag)


def parse_line(text: str) -> np.ndarray:
    """``--line x1,y1,x2,y2[,...]`` -> ``(n, 2)`` vertices [m]; one-line errors."""
    from fieldkit.model.terrain_file import line_vertices

    try:
        values = [float(v) for v in text.replace(";", ",").split(",")]
    except ValueError:
        values = []
    if len(values) < 4 or len(values) % 2:
        raise ArgumentError(
            f"'{text}' is not x1,y1,x2,y2[,...] (an even number, at least 4, of "
            "coordinates in metres in the DEM's coordinate system)",
            source="--line",
        )
    xy = np.array(values, float).reshape(-1, 2)
    return line_vertices(xy.tolist(), "--line", text)


def simulate_terrain(
    model,
    outputs: OutputSet,
    *,
    rocks: int,
    seed: int | None,
    summary: Path | None,
    deposits: Path | None,
    rasters: Path | None,
    lines: list[str] | None,
    observed: Path | None,
    figures: Path | None,
    rrd: Path | None,
    trajectories: int,
    impacts: Path | None = None,
    engine=None,
) -> None:
    """Run a 3-D model and write what was asked (:mod:`fieldkit.model.results3d`).

    ``impacts``: every impact as an ImpactTable row
    (:func:`fieldkit.model.results3d.impact_table3d`), streamed chunk by chunk; the
    3-D meaning of its columns and the columns left empty are stated on stderr.
    ``engine``: an :class:`~fieldkit.parallel.engine.EngineSpec` to run the rocks
    in tiles through Dask (:mod:`fieldkit.model.hazard_tiles`), or None.
    """
    from fieldkit.cli.progress import report_written, step
    from fieldkit.io.impact_stream import ImpactTableOutput
    from fieldkit.io.releases import read_releases
    from fieldkit.model.results import STOPPED
    from fieldkit.model.results3d import (
        IMPACT3D_EMPTY,
        IMPACT3D_FRAME,
        RASTERS,
        deposits_frame,
        impact_table3d,
        simulator3d,
        summary3d,
        write_geotiff,
    )
    from fieldkit.model.results3d import rasters as make_rasters
    from fieldkit.model.simulate import MAX_TRAJECTORIES
    from fieldkit.model.terrain_file import AnalysisLine, check_line_on_dem

    if not 1 <= rocks <= MAX_ROCKS:
        raise ArgumentError(
            f"must be from 1 to {MAX_ROCKS:,} (got {rocks})", source="--rocks"
        )
    if not 0 <= trajectories <= MAX_TRAJECTORIES:
        raise ArgumentError(
            f"must be from 0 to {MAX_TRAJECTORIES:,} (got {trajectories})",
            source="--trajectories",
        )
    if engine is not None and impacts is not None:
        raise ArgumentError(
            "--impacts streams every impact from this process; run it without "
            "--workers/--scheduler (the tiles return maps and numbers, not impacts)"
        )
    analysis = []
    for text in lines or []:
        xy = parse_line(text)
        check_line_on_dem(xy, model.terrain, source="--line", where=text)
        analysis.append(AnalysisLine(xy))
    from_model = not analysis and bool(model.analysis_lines)
    if from_model:
        analysis = list(model.analysis_lines)
    observed_xy = None
    if observed is not None:
        outputs.add_inputs([observed])
        points = read_releases(observed)
        if points.polygons:
            raise ArgumentError(
                "gives polygons; observed deposits are points (x_m, y_m)",
                source=str(observed),
            )
        observed_xy = points.points_m
    if deposits is not None:
        outputs.plan(deposits, argument="--deposits")
    outputs.confine(rasters)
    if rasters is not None:
        for name in RASTERS:
            outputs.plan(rasters / f"{name}.tif", argument="--rasters")
    if figures is not None:
        outputs.plan(figures / "map.png", argument="--figures")
    if from_model:
        note(
            "--line not given: analysis lines from the model file, "
            + ", ".join(ln.label(i) for i, ln in enumerate(analysis))
        )
    if seed is None:
        seed = secrets.randbits(32)
        note(f"`seed` not given: used {seed}; pass --seed {seed} to reproduce")
    rng = np.random.default_rng(seed)
    run = simulator3d()
    doing = f"simulating {rocks:,} rocks on the DEM"
    recording = {}
    writer = None
    tiled = None
    if engine is not None:
        from fieldkit.model.hazard_tiles import simulate3d_tiled
        from fieldkit.parallel.engine import Engine

        with Engine(engine, notify=note) as dask_engine:
            dask_engine.start()
            with step(doing + " in tiles of release cells", total=1) as advance:
                tiled = simulate3d_tiled(
                    model, rocks, rng, dask_engine,
                    lines=[ln.xy_m for ln in analysis], paths=trajectories,
                    progress=advance,
                )  # fmt: skip
        result = tiled.result
        note(
            f"{tiled.units} units in {tiled.tiles} tile(s) of 32 x 32 release cells "
            f"(at most 5,000 rocks a unit; a unit's sampled paths held at most "
            f"{tiled.largest_unit_path_bytes / 2**20:.1f} MiB on its worker); the "
            "rocks' random numbers drawn once here, so the results are those of the "
            "run in this process with this seed"
        )
        for line in dask_engine.retried:
            warn(line)
    if tiled is None and impacts is not None:
        writer = ImpactTableOutput(impacts, outputs, argument="--impacts")
        names = list(model.materials)
        recording = {
            "record_impacts": True,
            "on_impact_rows": lambda rows: writer.write(impact_table3d(rows, names)),
        }
        doing += f", recording their impacts for {impacts}"
    try:
        if tiled is None:
            with step(doing):
                result = run(model, rocks, rng, **recording)
    finally:
        if writer is not None:
            writer.close()
    if writer is not None:
        writer.finish()  # an XLSX table is written whole here
        note(f"--impacts: {IMPACT3D_FRAME}")
        note(
            "--impacts: columns left empty in 3-D rows: "
            + "; ".join(f"{cols} ({why})" for cols, why in IMPACT3D_EMPTY.items())
        )
    result.seed = seed
    for text in getattr(result, "notes", None) or []:
        note(text)  # what the simulator assumed (a default that changes a result)
    stats = summary3d(result, model, analysis,
                      None if tiled is None else tiled.crossings)  # fmt: skip
    if tiled is not None:
        stats["engine"] = dask_engine.describe()
    if summary is not None:
        write_json(summary, stats, outputs)
    if deposits is not None:
        frame = deposits_frame(result)
        write_file(deposits, lambda tmp: frame.to_csv(tmp, index=False), outputs)
    grids = None if tiled is None else tiled.rasters
    if grids is None and (rasters is not None or figures is not None):
        grids = make_rasters(result, model.terrain)
    if rasters is not None:
        for name in RASTERS:
            write_file(
                rasters / f"{name}.tif",
                lambda tmp, name=name: write_geotiff(tmp, grids[name], model.terrain),
                outputs,
            )
    if figures is not None:
        from fieldkit.viz.terrain_figure import write_terrain_map

        write_terrain_map(
            figures / "map.png",
            model.terrain,
            grids["deposit_density_per_m2"],
            releases=model.releases,
            deposits=np.asarray(result.deposit_xyz, float)[
                np.asarray(result.state) == STOPPED
            ],
            observed=observed_xy,
            lines=[(ln.label(i), ln.xy_m) for i, ln in enumerate(analysis)],
            outputs=outputs,
        )
    if rrd is not None:
        from fieldkit.viz.terrain_recording import write_terrain_recording

        write_terrain_recording(rrd, model.terrain, result, observed=observed_xy,
                                paths=trajectories, outputs=outputs)  # fmt: skip
    to_xlsx = impacts is not None and impacts.suffix.lower() == ".xlsx"
    with step("writing the outputs", announce=rrd is not None or to_xlsx):
        written = outputs.commit()
    print_summary3d(stats, model)
    report_written(written)


def _stat(d: dict, key: str, scale: float = 1.0) -> str:
    value, se = d.get(key), d.get("se", {}).get(key)
    if value is None:
        return f"{key} -"
    text = f"{key} {value * scale:.4g}"
    return text + (f" ± {se * scale:.2g}" if se is not None else "")


def print_summary3d(s: dict, model) -> None:
    """What a designer reads of a 3-D run, on stdout."""
    echo = typer.echo
    echo(
        f"{s['rocks']} rocks, {s['impacts']} impacts in {s['wall_s']:.2f} s of "
        f"simulation (seed {s['seed']})"
    )
    sd, weights = model.seeder, int(model.release_weights.sum())
    echo(
        f"released from {len(model.releases)} points (weights {weights} in all)"
        f" at v = ({sd.vx_mps:g}, {sd.vy_mps:g}, {sd.vz_mps:g}) m/s, SD "
        f"({sd.vx_sd_mps:g}, {sd.vy_sd_mps:g}, {sd.vz_sd_mps:g}) m/s, spin "
        f"{sd.omega_radps:g} ± {sd.omega_sd_radps:g} rad/s (the model's seeder; all 0 "
        "when it has none)"
    )
    final = s["final_state"]
    echo(
        f"stopped on the DEM: {s['stopped_fraction']:.3f} ± "
        f"{s['stopped_fraction_se']:.2g}; final states: stopped {final['stopped']}, "
        f"left the DEM {final['left_dem']}, capped {final['capped']}"
    )
    if final["capped"]:
        warn(
            f"{final['capped']} of {s['rocks']} rocks were still moving after "
            f"{int(model.core.get('max_impacts', 0))} impacts (the model's "
            "core.max_impacts): they are neither stopped nor left the DEM; raise "
            '"core": {"max_impacts": ...} in the model file to follow them'
        )
    if "tree_strikes" in s:
        t = s["tree_strikes"]
        echo(
            f"tree strikes: {t['total']} (by {t['rocks_struck']} of {s['rocks']} "
            f"rocks; {t['stems']} stems in the model)"
        )
    d = s["deposits"]["distance_m"]
    echo(
        "release -> deposit distance in plan (m, stopped rocks): "
        + ", ".join(_stat(d, k) for k in ("p50", "p90", "p95", "max"))
    )
    for line in s["lines"]:
        echo(
            f"{line['name']}: passing {line['passing_fraction']:.3f} ± "
            f"{line['passing_fraction_se']:.2g} ({line['passing']} rocks)"
        )
        for key, label, scale, unit in (
            ("speed_mps", "speed", 1.0, " m/s"),
            ("ke_j", "KE", 1e-3, " kJ (translational, 1/2 m v^2)"),
            ("height_m", "bounce h", 1.0, " m"),
        ):
            echo(
                f"  {label:9s}"
                + "  ".join(_stat(line[key], k, scale) for k in ("p50", "p95", "p99"))
                + unit
            )
    echo("± = Monte Carlo standard error (percentiles: order-statistic interval)")
    effects = model.effects or {}
    echo("effects: " + (", ".join(effects) if effects else "none (base model)"))
