"""`fieldkit simulate`: Monte Carlo rock falls on a slope profile (thesis ch. 7)."""

from __future__ import annotations

import secrets
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from fieldkit.cli.common import note, one_line_errors, warn
from fieldkit.cli.design import parse_measured
from fieldkit.cli.engine_options import (
    ENGINE_FLAGS,
    Retries,
    Scheduler,
    Timeout,
    WorkerMemory,
    Workers,
)
from fieldkit.errors import ArgumentError
from fieldkit.outputs import OutputSet, write_json

FLAGS = {
    "rocks": "--rocks",
    "seed": "--seed",
    "impacts_path": "--impacts",
    "measured": "--measured",
    "analysis_x_m": "--at",
    "trajectories": "--trajectories",
    "envelope_dx_m": "--envelope-dx",
    **ENGINE_FLAGS,
}

def _fmt(d: dict, key: str, unit: str = "") -> str:
    from fieldkit.model.results import readable

    v, se = d.get(key), d.get("se", {}).get(key)
    if v is None:
        return "-"
    if d.get("lower_bound", {}).get(key):  # uses censored values: at least v
        return f"≥ {readable(v, 4)}{unit}"
    return readable(v, 4) + (f" ± {readable(se, 2)}" if se is not None else "") + unit


def _runout_values(r: dict, censored: dict) -> str:
    """The runout statistics, each lower bound as "≥": a run of them at the
    profile's end said once, "p50, p90, p95, p99, max ≥ 700 m (end of profile;
    71 % of rocks left it)"."""
    from fieldkit.model.results import censored_words

    keys = ("mean", "p50", "p90", "p95", "p99", "max")
    end = censored.get("end_x_m")
    at_end = [
        k for k in keys
        if k != "mean" and r.get("lower_bound", {}).get(k) and r.get(k) == end
    ]  # fmt: skip
    parts = [f"{k} {_fmt(r, k)}" for k in keys if k not in at_end]
    if at_end:
        parts.append(
            f"{', '.join(at_end)} ≥ {end:g} m ({censored_words(censored['fraction'])})"
        )
    return ", ".join(parts)


def engine_given(workers, scheduler, worker_memory, timeout, retries):
    """The engine spec when a run is sent to Dask (--workers >= 1, --scheduler or
    Dask's configured scheduler), else None (this process, as without Dask)."""
    from fieldkit.cli.engine_options import engine_spec
    from fieldkit.parallel.engine import configured_scheduler

    spec = engine_spec(workers, scheduler, worker_memory, timeout, retries)
    if workers == 0 or not (workers or scheduler or configured_scheduler()):
        if worker_memory is not None:
            raise ArgumentError("--worker-memory needs --workers N or --scheduler")
        return None
    return spec


@one_line_errors(flags=FLAGS)
def simulate(
    model_file: Annotated[
        Path,
        typer.Argument(
            metavar="MODEL.json",
            help="The model file: a profile (§5) or a terrain block (a DEM, 3-D).",
        ),
    ],
    rocks: Annotated[
        int, typer.Option("--rocks", help="Number of rocks (1 to 10,000,000).")
    ] = 1000,
    seed: Annotated[
        int | None,
        typer.Option(
            "--seed", help="Random seed >= 0 (drawn and printed when omitted)."
        ),
    ] = None,
    impacts: Annotated[
        Path | None,
        typer.Option(
            "--impacts",
            help="Write every impact as an ImpactTable (.csv, .parquet; .xlsx up "
            "to 1,048,575 rows), path_id = rock, streamed to disk in chunks. 3-D: "
            "x_m, y_m, z_m the contact in the DEM's coordinates, each row's section "
            "plane its plane of incidence (docs/terrain-model.md).",
        ),
    ] = None,
    summary: Annotated[
        Path | None, typer.Option("--summary", help="Write summary.json.")
    ] = None,
    at: Annotated[
        list[float] | None,
        typer.Option(
            "--at",
            help="Analysis point x (m), within the profile; repeatable (up to 100). "
            "Default: the model file's analysis_points (stated when used).",
        ),
    ] = None,
    trajectories: Annotated[
        int,
        typer.Option(
            "--trajectories",
            help="Keep the paths of the first K rocks (0 to 1,000); 3-D: the "
            "paths --rrd draws (at most 200).",
        ),
    ] = 20,
    figures: Annotated[
        Path | None, typer.Option("--figures", help="Write PNG figures into DIR.")
    ] = None,
    rrd: Annotated[
        Path | None, typer.Option("--rrd", help="Write a rerun recording (.rrd).")
    ] = None,
    measured: Annotated[
        list[str] | None,
        typer.Option(
            "--measured",
            help="A measured value at an --at point, e.g. "
            "x=610,speed=18,ke=600e3[,total=690e3][,height=1.5] (ke translational, "
            "total translational + rotational, J; each key once; speed 0-100 m/s, "
            "ke 0-5e10 J, total 0-1e11 J, height 0-510 m): its "
            "percentile among the simulated rocks crossing x is printed, written to "
            "summary.json and drawn on the figures; repeatable.",
        ),
    ] = None,
    envelope_dx: Annotated[
        float | None,
        typer.Option(
            "--envelope-dx",
            help="Bin width of the bounce-height envelope (m). With --figures and "
            "none given: the profile's x extent / 200, rounded up to 1, 2 or 5 x "
            "10^k m (stated when used).",
        ),
    ] = None,
    deposits: Annotated[
        Path | None,
        typer.Option(
            "--deposits",
            help="3-D: write every rock's final position (rock, release, x_m, y_m, "
            "z_m, state) as CSV.",
        ),
    ] = None,
    rasters: Annotated[
        Path | None,
        typer.Option(
            "--rasters",
            help="3-D: write GeoTIFFs on the DEM's grid and CRS into DIR: "
            "passing_count, max_ke_j, max_height_m, deposit_density_per_m2.",
        ),
    ] = None,
    line: Annotated[
        list[str] | None,
        typer.Option(
            "--line",
            help="3-D: an analysis line (a barrier) x1,y1,x2,y2[,...] in the DEM's "
            "coordinates (m): passing fraction and speed, KE, bounce height "
            "percentiles of the rocks crossing it; repeatable. Default: the model "
            "file's analysis_lines (stated when used).",
        ),
    ] = None,
    observed: Annotated[
        Path | None,
        typer.Option(
            "--observed",
            help="3-D: observed deposits (CSV with x_m, y_m) drawn on map.png and "
            "in the recording.",
        ),
    ] = None,
    workers: Workers = None,
    scheduler: Scheduler = None,
    worker_memory: WorkerMemory = None,
    timeout: Timeout = 10.0,
    retries: Retries = 2,
) -> None:
    """Simulate rock falls down a slope profile and say what a designer reads.

    Every rock is released by the model's seeder and followed through exact
    parabolic flights, impacts (material restitution and the effects the model
    switches on) and sliding until it stops or leaves the profile. Printed:
    the runout distribution, the stopped fraction and, at each analysis point
    (--at, else the model file's analysis_points), the fraction of rocks passing
    and percentiles of speed, energy and bounce height -- each with its Monte
    Carlo standard error, so you can see
    whether --rocks was enough -- and the percentile of each --measured value
    (a value above or below every crossing rock has none: "above all N simulated
    rocks", with their maximum).

    A rock that leaves the profile at its lower end ran out at least that far: a
    runout statistic that uses such rocks is a lower bound, printed "≥ 700 m (end
    of profile; 71 % of rocks left it)" and flagged in summary.json
    (runout_x_m.lower_bound); extend the profile to measure it.

    Rocks still moving after the model's core.max_impacts impacts (capped) are
    their own final state: never counted as stopped or run out, left out of the
    runout statistics (summary.json brackets what counting them would give), with
    a warning saying how many. The first run after an install compiles the
    simulator once ("compiling the simulator, first run only"); compile and
    simulation times are reported apart (compile_s, wall_s in summary.json).

    A model file with a terrain block (a DEM, 3-D) runs the 3-D simulator on
    the DEM from its release points. Printed: final states, the release-to-deposit
    distance and, at each analysis line (--line, else the model file's
    analysis_lines), the passing fraction and p50/p95/p99 of speed, kinetic energy
    and bounce height with their Monte Carlo SEs; --deposits, --rasters (GeoTIFF in
    the DEM's CRS), --figures (map.png) and --rrd write the rest; --impacts writes
    every impact as an ImpactTable row, in the plane of incidence of the impact
    (N the surface normal, T along the incoming tangential velocity; what each
    column means in 3-D and which stay empty is printed). --at, --measured and
    --envelope-dx are for profile models; --deposits, --rasters, --line and
    --observed for terrain models.

    A terrain model's hazard map runs in tiles of release cells through Dask with
    --workers N (local processes), --scheduler ADDRESS (a running cluster) or
    Dask's configured scheduler; the rocks' random numbers are drawn once here, so
    the maps and numbers are those of the run in this process with the same seed.

    Example (from the repository root; thesis §7.5.4, Tornado Mountain with
    the RocFall inputs of Table 7-1):

        fieldkit simulate surveys/tornado_mountain/model_rocfall_table_7_1.json \\
          --rocks 2000 --seed 1 --at 610 --measured x=610,speed=18,ke=600e3 \\
          --summary out/summary.json --figures out/sim

    Example, 3-D (Tschamut 2014: the DEM, the 80 runs' release points, a line
    across the slope below them):

        fieldkit simulate examples/tschamut/model_3d.json --rocks 800 --seed 1 \\
          --line 0,180,120,180 \\
          --observed tests/data/tschamut2014/observed_deposition.csv \\
          --summary out3d/summary.json --deposits out3d/deposits.csv \\
          --impacts out3d/impacts.csv --rasters out3d/rasters \\
          --figures out3d/figures --rrd out3d/sim.rrd
    """
    import fieldkit.model.kernel as kernel
    from fieldkit.cli.progress import report_written, step
    from fieldkit.cli.simulate3d import (
        PROFILE_ONLY,
        TERRAIN_ONLY,
        refuse_options,
        simulate_terrain,
    )
    from fieldkit.io.impact_stream import ImpactTableOutput, check_impacts_target
    from fieldkit.model.model3d import Model3D
    from fieldkit.model.model_file import read_model
    from fieldkit.model.simulate import (
        check_run,
        default_envelope_dx_m,
        warm_kernel,
    )
    from fieldkit.model.simulate import simulate as run

    if seed is not None and not 0 <= seed < 2**64:
        raise ArgumentError(
            f"seed must be from 0 to 2**64 - 1 (got {seed})", source="seed"
        )
    points = [parse_measured(text) for text in (measured or [])]
    if impacts is not None:
        check_impacts_target(impacts, "impacts_path")
    if rrd is not None and rrd.suffix.lower() != ".rrd":
        raise ArgumentError(f"must be a .rrd file, got {rrd.name!r}", source="--rrd")

    with OutputSet(inputs=[model_file]) as outputs:
        outputs.confine(figures)
        if summary is not None:
            outputs.plan(summary, argument="--summary")
        if rrd is not None:
            outputs.plan(rrd, argument="--rrd")
        model = read_model(model_file, outputs=outputs, terrain=True)
        given = {"impacts": impacts, "at": at, "measured": measured,
                 "envelope_dx": envelope_dx, "deposits": deposits,
                 "rasters": rasters, "line": line, "observed": observed}  # fmt: skip
        if isinstance(model, Model3D):
            refuse_options(given, PROFILE_ONLY, "is for a profile model; "
                           f"{model_file.name} describes a DEM (terrain)")  # fmt: skip
            simulate_terrain(
                model, outputs, rocks=rocks, seed=seed, summary=summary,
                deposits=deposits, rasters=rasters, lines=line, observed=observed,
                figures=figures, rrd=rrd, trajectories=trajectories, impacts=impacts,
                engine=engine_given(workers, scheduler, worker_memory, timeout,
                                    retries),
            )  # fmt: skip
            return
        if workers is not None or scheduler is not None or worker_memory is not None:
            raise ArgumentError(
                "--workers, --scheduler and --worker-memory run a terrain (3-D) "
                f"model's tiles; {model_file.name} describes a profile, which runs "
                "in this process on every core"
            )
        refuse_options(given, TERRAIN_ONLY, "is for a terrain (3-D) model; "
                       f"{model_file.name} describes a profile")  # fmt: skip
        analysis_x = [float(x) for x in (at or [])]
        from_model = not at and bool(model.analysis_points)
        if from_model:
            analysis_x = [p.x_m for p in model.analysis_points]
        if figures is not None:
            from fieldkit.viz.simulation_figure import point_figure_names

            for name in point_figure_names(analysis_x):
                outputs.plan(figures / name, argument="--figures")
        x_range = (float(model.profile.x_m[0]), float(model.profile.x_m[-1]))
        default_dx = envelope_dx is None and figures is not None
        if default_dx:
            envelope_dx = default_envelope_dx_m(x_range[1] - x_range[0])
        check_run(rocks, x_range, analysis_x, envelope_dx, trajectories)
        _check_measured(points, analysis_x)
        if from_model:  # said once the inputs are known good (errors are one line)
            note(
                "--at not given: analysis points from the model file, "
                + ", ".join(
                    f"x = {p.x_m:g} m" + (f" ({p.name})" if p.name else "")
                    for p in model.analysis_points
                )
            )
        if default_dx:
            note(
                f"--envelope-dx not given: the bounce-height envelope (envelope.png) "
                f"uses {envelope_dx:g} m bins (profile x {x_range[0]:g} to "
                f"{x_range[1]:g} m); pass --envelope-dx to choose"
            )
        if seed is None:
            seed = secrets.randbits(32)
            note(f"`seed` not given: used {seed}; pass --seed {seed} to reproduce")
        rng = np.random.default_rng(seed)

        compile_s = 0.0
        if not kernel.kernel_ready():
            with step("compiling the simulator, first run only"):
                compile_s = warm_kernel()
        elif not kernel.kernel_loaded():
            warm_kernel()  # load from the cache (< 1 s), off the clock

        kept: list = []  # impacts of the trajectory rocks, for the recording
        writer = None
        if impacts is not None:
            writer = ImpactTableOutput(impacts, outputs, argument="--impacts")

        def on_chunk(table) -> None:  # chunks arrive derived (model.simulate)
            if writer is not None:
                writer.write(table)
            if rrd is not None and trajectories:
                ids = table.frame["path_id"].astype(int)
                if (ids < trajectories).any():
                    kept.append(table.frame[ids < trajectories])

        doing = f"simulating {rocks:,} rocks"
        if impacts is not None:
            doing += f", recording their impacts for {impacts}"
        try:
            with step(doing, total=rocks) as advance:
                result = run(
                    model,
                    rocks,
                    rng,
                    analysis_x_m=analysis_x,
                    trajectories=trajectories,
                    record_impacts=impacts is not None or rrd is not None,
                    on_impact_chunk=on_chunk,
                    progress=advance,
                    envelope_dx_m=envelope_dx,
                )
        finally:
            if writer is not None:
                writer.close()
        result.seed = seed
        result.compile_s = compile_s
        if writer is not None:
            writer.finish()  # an XLSX table is written whole here
        stats = result.summary()
        stats["measured"] = _measured_percentiles(result, points)
        if summary is not None:
            write_json(summary, stats, outputs)
        if figures is not None:
            from fieldkit.viz.simulation_figure import write_simulation_figures

            with step(f"drawing the figures into {figures}"):
                write_simulation_figures(
                    figures, result, measured=points, outputs=outputs
                )
        if rrd is not None:
            import pandas as pd

            from fieldkit.impact_table import ImpactTable
            from fieldkit.viz.rerun_log import write_simulation_recording

            some = ImpactTable(pd.concat(kept, ignore_index=True)) if kept else None
            write_simulation_recording(rrd, result, some, outputs=outputs)
        to_xlsx = impacts is not None and impacts.suffix.lower() == ".xlsx"
        with step("writing the outputs", announce=rrd is not None or to_xlsx):
            written = outputs.commit()
    _print_summary(stats, model)
    report_written(written)


def _check_measured(points, analysis_x: list[float]) -> None:
    """A measured speed or energy is compared at an analysis point: its x must be
    one of the ``--at`` points (a height alone is drawn on the envelope)."""
    for m in points:
        compared = any(v is not None for v in (m.speed_mps, m.ke_j, m.total_j))
        if compared and not any(np.isclose(m.x_m, x) for x in analysis_x):
            raise ArgumentError(
                f"x={m.x_m:g} is not an analysis point "
                f"({', '.join(f'--at {x:g}' for x in analysis_x) or 'no --at given'}); "
                f"its speed and energy are compared with the rocks crossing it: add "
                f"--at {m.x_m:g}",
                source="measured",
            )


#: Measured quantities -> (AnalysisPoint array, label, scale, unit).
_MEASURED_QUANTITIES = {
    "speed_mps": ("speed_mps", "speed", 1.0, "m/s"),
    "ke_j": ("ke_j", "translational KE", 1e-3, "kJ"),
    "total_j": ("total_j", "total energy KE+RE", 1e-3, "kJ"),
    "height_m": ("height_m", "bounce height", 1.0, "m"),
}


def _measured_percentiles(result, points) -> list[dict]:
    """Each measured value's percentile among the rocks crossing its point."""
    out = []
    for m in points:
        index = next(
            (i for i, p in enumerate(result.analysis) if np.isclose(p.x_m, m.x_m)),
            None,
        )
        if index is None:
            continue
        entry: dict = {"x_m": float(m.x_m)}
        for key, (quantity, *_rest) in _MEASURED_QUANTITIES.items():
            value = getattr(m, key)
            if value is not None:
                entry[key] = result.percentile_of(index, quantity, value)
        entry["over"] = (
            "rocks crossing x_m (first crossing); percentile = percent of them with a "
            "smaller value (ties half), percentile_se binomial; a value above (below) "
            "every crossing rock has no percentile (null) but beyond = above (below) "
            "and the simulated_max (simulated_min) it exceeds; ke_j is translational "
            "(1/2 m v^2), as measured"
        )
        out.append(entry)
    return out


def _print_summary(s: dict, model) -> None:
    from fieldkit.model.results import rank_words

    echo = typer.echo
    compiled = (
        f"; compiling the simulator took {s['compile_s']:.2f} s (first run only)"
        if s.get("compile_s")
        else ""
    )
    echo(
        f"{s['rocks']} rocks, {s['impacts']} impacts in {s['wall_s']:.2f} s of "
        f"simulation (seed {s['seed']}){compiled}"
    )
    r = s["runout_x_m"]
    capped = s["capped"]
    over = (
        f" (over the {r['n']} rocks that stopped or left; {capped['rocks']} capped "
        "left out)"
        if capped["rocks"]
        else ""
    )
    echo(f"runout x (m){over}: {_runout_values(r, s['runout_censored'])}")
    if any(r.get("lower_bound", {}).values()):
        censored = s["runout_censored"]
        echo(
            f"  ≥: a lower bound, the statistic uses the {censored['rocks']:,} rocks "
            f"that left the profile at its lower end (x = {censored['end_x_m']:g} m), "
            "whose runout is at least that; extend the profile to place it"
        )
    echo(
        f"stopped on the profile: {s['stopped_fraction']:.3f} "
        f"± {s['stopped_fraction_se']:.2g}; final states: "
        + ", ".join(f"{k} {v}" for k, v in s["final_state"].items() if v)
    )
    if capped["rocks"]:
        lo, hi = s["runout_bounds_x_m"]["lower"], s["runout_bounds_x_m"]["upper"]

        def p95(d: dict) -> str:
            return ("≥ " if d["lower_bound"]["p95"] else "") + f"{d['p95']:.4g} m"

        if lo["p95"] == hi["p95"]:
            bound = (
                "counting them anywhere from where they were to the profile's end "
                f"leaves the runout p95 at {p95(lo)}"
            )
        else:
            bound = (
                f"counting them, the runout p95 lies between {p95(lo)} (where "
                f"they were) and {p95(hi)} (the profile's end)"
            )
        warn(
            f"{capped['fraction']:.1%} of the rocks "
            f"({capped['rocks']} of {s['rocks']}) "
            f"were still moving after {capped['max_impacts']} impacts (the model's "
            "core.max_impacts), where the simulation stopped following them: they "
            f"are neither stopped nor run out and are left out of the runout "
            f'statistics; {bound}. Raise "core": {{"max_impacts": ...}} in the '
            "model file (up to 1e6) to follow them to the end."
        )
    for p in s["analysis_points"]:
        echo(
            f"x = {p['x_m']:g} m: passing {p['passing_fraction']:.3f} "
            f"± {p['passing_fraction_se']:.2g} ({p['passing']} rocks)"
        )
        for key, label, scale, unit in (
            ("speed_mps", "speed", 1.0, " m/s"),
            ("total_j", "KE+RE", 1e-3, " kJ (total: translational + rotational)"),
            ("ke_j", "KE", 1e-3, " kJ (translational, 1/2 m v^2)"),
            ("bounce_height_m", "bounce h", 1.0, " m"),
        ):
            d = _scaled(p[key], scale)
            echo(
                f"  {label:9s}"
                + "  ".join(
                    f"{k} {_fmt(d, k)}" for k in ("p50", "p90", "p95", "p99", "max")
                )
                + unit
            )
    for m in s.get("measured", []):
        parts = []
        for key, (_q, label, scale, unit) in _MEASURED_QUANTITIES.items():
            d = m.get(key)
            if d is None:
                continue
            words = rank_words(d, scale, unit)
            sep = " = " if d["percentile"] is not None else ": "
            parts.append(f"{label} {d['measured'] * scale:.4g} {unit}{sep}{words}")
        if parts:
            echo(
                f"measured at x = {m['x_m']:g} m, among the simulated rocks crossing "
                "it: " + "; ".join(parts)
            )
    echo(
        "± = Monte Carlo standard error (percentiles: order-statistic interval; "
        "max: exact bootstrap)"
    )
    core = getattr(model, "core", {}) or {}
    if core:
        echo(
            "core settings: "
            + ", ".join(
                f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                for k, v in core.items()
            )
        )
    effects = getattr(model, "effects", {}) or {}
    echo("effects: " + (", ".join(effects) if effects else "none (base model)"))


def _scaled(d: dict, scale: float) -> dict:
    out = {
        k: (v * scale if isinstance(v, float) else v) for k, v in d.items() if k != "se"
    }
    out["se"] = {k: (v * scale if v is not None else None) for k, v in d["se"].items()}
    return out
