"""`fieldkit simulate`: Monte Carlo rock falls on a slope profile (thesis ch. 7)."""

from __future__ import annotations

import math
import secrets
import sys
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from fieldkit.cli.common import note, one_line_errors
from fieldkit.errors import ArgumentError
from fieldkit.outputs import OutputSet, write_json

#: Rows an XLSX sheet holds (the header takes one).
XLSX_MAX_ROWS = 1_048_576 - 1

FLAGS = {
    "rocks": "--rocks",
    "seed": "--seed",
    "impacts_path": "--impacts",
    "measured": "--measured",
    "analysis_x_m": "--at",
    "trajectories": "--trajectories",
    "envelope_dx_m": "--envelope-dx",
}

_MEASURED_KEYS = {"x": "x_m", "speed": "speed_mps", "ke": "ke_j", "height": "height_m"}


def parse_measured(text: str):
    """``x=610,speed=18,ke=600e3[,height=1.5]`` -> a Measured (x required).

    Examples
    --------
    >>> parse_measured("x=610,speed=18,ke=600e3")
    Measured(x_m=610.0, speed_mps=18.0, ke_j=600000.0, height_m=None)
    """
    from fieldkit.viz.simulation_figure import Measured

    values: dict[str, float] = {}
    for part in text.split(","):
        key, sep, value = part.partition("=")
        key = key.strip().lower()
        if not sep or key not in _MEASURED_KEYS:
            raise ArgumentError(
                f"{part.strip()!r} in {text!r}: expected key=value with key one of "
                f"{', '.join(_MEASURED_KEYS)}",
                source="measured",
            )
        try:
            number = float(value)
        except ValueError:
            number = math.nan
        if not math.isfinite(number):
            raise ArgumentError(
                f"{key}={value!r} is not a finite number", source="measured"
            )
        values[_MEASURED_KEYS[key]] = number
    if "x_m" not in values:
        raise ArgumentError(f"{text!r} lacks x=<position m>", source="measured")
    return Measured(**values)


def _fmt(d: dict, key: str, unit: str = "") -> str:
    v, se = d.get(key), d.get("se", {}).get(key)
    if v is None:
        return "-"
    return f"{v:.4g}" + (f" ± {se:.2g}" if se is not None else "") + unit


@one_line_errors(flags=FLAGS)
def simulate(
    model_file: Annotated[
        Path, typer.Argument(metavar="MODEL.json", help="The model file (§5).")
    ],
    rocks: Annotated[int, typer.Option("--rocks", help="Number of rocks.")] = 1000,
    seed: Annotated[
        int | None,
        typer.Option("--seed", help="Random seed (drawn and printed when omitted)."),
    ] = None,
    impacts: Annotated[
        Path | None,
        typer.Option(
            "--impacts",
            help="Write every impact as an ImpactTable (.csv, .parquet; .xlsx up "
            "to 1,048,575 rows), path_id = rock, streamed to disk in chunks.",
        ),
    ] = None,
    summary: Annotated[
        Path | None, typer.Option("--summary", help="Write summary.json.")
    ] = None,
    at: Annotated[
        list[float] | None,
        typer.Option("--at", help="Analysis point x (m); repeatable."),
    ] = None,
    trajectories: Annotated[
        int,
        typer.Option("--trajectories", help="Keep the paths of the first K rocks."),
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
            help="A measured value drawn on the figures, e.g. "
            "x=610,speed=18,ke=600e3[,height=1.5]; repeatable.",
        ),
    ] = None,
    envelope_dx: Annotated[
        float | None,
        typer.Option(
            "--envelope-dx", help="Bin width of the bounce-height envelope (m)."
        ),
    ] = None,
) -> None:
    """Simulate rock falls down a slope profile and say what a designer reads.

    Every rock is released by the model's seeder and followed through exact
    parabolic flights, impacts (material restitution and the effects the model
    switches on) and sliding until it stops or leaves the profile. Printed:
    the runout distribution, the stopped fraction and, at each analysis point
    (--at), the fraction of rocks passing and percentiles of speed, energy and
    bounce height -- each with its Monte Carlo standard error, so you can see
    whether --rocks was enough.

    Example (from the repository root; thesis §7.5.4, Tornado Mountain with
    the RocFall inputs of Table 7-1):

        fieldkit simulate surveys/tornado_mountain/model_rocfall_table_7_1.json \\
          --rocks 2000 --seed 1 --at 610 --measured x=610,speed=18,ke=600e3 \\
          --summary out/summary.json --figures out/sim
    """
    from fieldkit.io.impact_stream import (
        ImpactStreamWriter,
        stream_format,
    )
    from fieldkit.model.model_file import read_model
    from fieldkit.model.simulate import simulate as run

    if rocks < 1:
        raise ArgumentError(f"rocks must be >= 1 (got {rocks})", source="rocks")
    if trajectories < 0:
        raise ArgumentError("trajectories must be >= 0", source="trajectories")
    if envelope_dx is not None and not envelope_dx > 0:
        raise ArgumentError("envelope_dx_m must be > 0", source="envelope_dx_m")
    analysis_x = [float(x) for x in (at or [])]
    points = [parse_measured(text) for text in (measured or [])]
    to_xlsx = impacts is not None and impacts.suffix.lower() == ".xlsx"
    if impacts is not None and not to_xlsx:
        stream_format(impacts, "impacts_path")

    with OutputSet(inputs=[model_file]) as outputs:
        if summary is not None:
            outputs.plan(summary, argument="--summary")
        if rrd is not None:
            if rrd.suffix.lower() != ".rrd":
                raise ArgumentError(
                    f"must be a .rrd file, got {rrd.name!r}", source="--rrd"
                )
            outputs.plan(rrd, argument="--rrd")
        if figures is not None:
            from fieldkit.viz.simulation_figure import point_figure_names

            for name in point_figure_names(analysis_x):
                outputs.plan(figures / name, argument="--figures")
        model = read_model(model_file, outputs=outputs)
        if seed is None:
            seed = secrets.randbits(32)
            note(f"`seed` not given: used {seed}; pass --seed {seed} to reproduce")
        rng = np.random.default_rng(seed)

        kept: list = []  # impacts of the trajectory rocks, for the recording
        writer = None
        if impacts is not None and not to_xlsx:
            tmp = outputs.stream(impacts, argument="--impacts")
            writer = ImpactStreamWriter(tmp, stream_format(impacts))

        def on_chunk(table) -> None:  # chunks arrive derived (model.simulate)
            writer.write(table)
            if rrd is not None and trajectories:
                ids = table.frame["path_id"].astype(int)
                if (ids < trajectories).any():
                    kept.append(table.frame[ids < trajectories])

        progress, finish = _progress(rocks)
        try:
            result = run(
                model,
                rocks,
                rng,
                analysis_x_m=analysis_x,
                trajectories=trajectories,
                record_impacts=impacts is not None or rrd is not None,
                on_impact_chunk=on_chunk if writer is not None else None,
                progress=progress,
                envelope_dx_m=envelope_dx,
            )
        finally:
            finish()
            if writer is not None:
                writer.close()
        result.seed = seed
        recorded = None
        if result.impact_table is not None:
            recorded = result.impact_table
            if recorded.frame["vi_mps"].isna().all():
                recorded = recorded.derive()
        if to_xlsx:
            if len(recorded) > XLSX_MAX_ROWS:
                raise ArgumentError(
                    f"{len(recorded):,} impacts do not fit an XLSX sheet "
                    f"({XLSX_MAX_ROWS:,} rows); write .csv or .parquet",
                    source="--impacts",
                )
            recorded.write(impacts, outputs=outputs)
        stats = result.summary()
        if summary is not None:
            write_json(summary, stats, outputs)
        if figures is not None:
            from fieldkit.viz.simulation_figure import write_simulation_figures

            write_simulation_figures(figures, result, measured=points, outputs=outputs)
        if rrd is not None:
            import pandas as pd

            from fieldkit.impact_table import ImpactTable
            from fieldkit.viz.rerun_log import write_simulation_recording

            some = None
            if kept:
                some = ImpactTable(pd.concat(kept, ignore_index=True))
            elif recorded is not None:
                ids = recorded.frame["path_id"].astype(int)
                some = ImpactTable(recorded.frame[ids < trajectories])
            write_simulation_recording(rrd, result, some, outputs=outputs)
        outputs.commit()
    _print_summary(stats, model)


def _progress(total: int):
    """A rich progress bar on a terminal's stderr; else nothing."""
    if not sys.stderr.isatty():
        return None, lambda: None
    from rich.console import Console
    from rich.progress import Progress

    bar = Progress(console=Console(stderr=True), transient=True)
    task = bar.add_task("simulating", total=total)
    bar.start()

    def update(done: int, of: int) -> None:
        bar.update(task, completed=done, total=of)

    return update, bar.stop


def _print_summary(s: dict, model) -> None:
    echo = typer.echo
    echo(
        f"{s['rocks']} rocks, {s['impacts']} impacts in {s['wall_s']:.2f} s "
        f"(seed {s['seed']})"
    )
    r = s["runout_x_m"]
    echo(
        "runout x (m): "
        + ", ".join(
            f"{k} {_fmt(r, k)}" for k in ("mean", "p50", "p90", "p95", "p99", "max")
        )
    )
    echo(
        f"stopped on the profile: {s['stopped_fraction']:.3f} "
        f"± {s['stopped_fraction_se']:.2g}; final states: "
        + ", ".join(f"{k} {v}" for k, v in s["final_state"].items() if v)
    )
    for p in s["analysis_points"]:
        echo(
            f"x = {p['x_m']:g} m: passing {p['passing_fraction']:.3f} "
            f"± {p['passing_fraction_se']:.2g} ({p['passing']} rocks)"
        )
        for key, label, scale, unit in (
            ("speed_mps", "speed", 1.0, " m/s"),
            ("total_j", "total E", 1e-3, " kJ"),
            ("ke_j", "KE", 1e-3, " kJ"),
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
