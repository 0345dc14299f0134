"""Figures of a simulation, as thesis ch. 7 draws them (Figs. 7.4-7.16).

* :func:`trajectories_figure` -- the section (ground filled, coloured by material),
  the first trajectories and the analysis points as vertical lines (Figs. 7.4, 7.7,
  7.9, 7.12, 7.15);
* :func:`envelope_figure` -- the bounce-height envelope along the profile: p50, p95
  and max of the rocks' maximum centre height above the ground in each x bin, with a
  measured height as a line when given (Figs. 7.10, 7.13);
* :func:`point_histograms_figure` -- speed, translational and total kinetic energy
  of the rocks crossing an analysis point, with p50/p90/p95/p99 marked and a
  measured value drawn on the distribution of the same quantity, with its
  percentile (Figs. 7.6, 7.8, 7.11, 7.14, 7.16);
* :func:`runout_figure` -- where the rocks ended, by final state (capped rocks
  apart).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from fieldkit.model.results import SimulationResult
from fieldkit.model.statistics import PERCENTILES
from fieldkit.outputs import OutputSet
from fieldkit.viz.figure_files import new_figure, save_png
from fieldkit.viz.marks import outside_legend

_MATERIAL_COLOURS = ("#b89b72", "#8c8c8c", "#7fa36b", "#c9b458", "#9c6f5a", "#6b8fa3")
_PERCENTILE_STYLES = {50: "-", 90: "--", 95: "-.", 99: ":"}
_MEASURED_COLOUR = "red"


@dataclass(frozen=True)
class Measured:
    """A measured value at an analysis point, drawn on its distribution (Fig. 7.14).

    Any of speed, kinetic energy and bounce height may be given.
    """

    x_m: float
    speed_mps: float | None = None
    ke_j: float | None = None
    height_m: float | None = None


def _draw_section(ax, profile) -> None:
    x, z = np.asarray(profile.x_m, float), np.asarray(profile.z_m, float)
    bottom = z.min() - 0.1 * max(z.max() - z.min(), 1.0)
    colours: dict[str, str] = {}
    for j, name in enumerate(profile.material):
        new = name not in colours
        if new:
            colours[name] = _MATERIAL_COLOURS[len(colours) % len(_MATERIAL_COLOURS)]
        ax.fill_between(
            x[j : j + 2],
            z[j : j + 2],
            bottom,
            color=colours[name],
            alpha=0.6,
            lw=0,
            label=f"material: {name}" if new else None,
        )
    ax.plot(x, z, color="0.2", lw=1.2, label="ground surface (profile vertices)")


def trajectories_figure(
    result: SimulationResult, *, count: int | None = None
) -> Figure:
    """The section with the first ``count`` trajectories and the analysis points."""
    fig, ax = new_figure(9.0, 5.0)
    _draw_section(ax, result.model.profile)
    paths = result.trajectories[: count if count is not None else None]
    for i, path in enumerate(paths):
        ax.plot(
            path[:, 0],
            path[:, 1],
            color="tab:red",
            lw=0.6,
            alpha=0.7,
            label=f"trajectories ({len(paths)} of {result.rocks} rocks)"
            if i == 0
            else None,
        )
    for i, point in enumerate(result.analysis):
        ax.axvline(
            point.x_m,
            color="tab:blue",
            lw=1.0,
            label="analysis points (vertical lines where speeds and energies are read)"
            if i == 0
            else None,
        )
    ax.set_xlabel("x, horizontal distance (m)")
    ax.set_ylabel("z, elevation (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(f"Simulated trajectories ({result.rocks} rocks, seed {result.seed})")
    outside_legend(ax)
    return fig


def envelope_figure(
    result: SimulationResult, *, measured: Sequence[Measured] = ()
) -> Figure:
    """Bounce-height envelope along x: p50, p95, max per bin (Figs. 7.10, 7.13)."""
    fig, ax = new_figure(9.0, 4.5)
    env = result.envelope()
    x = env["x_m"]
    width = float(np.diff(result.envelope_x_m[:2])[0]) if x.size else float("nan")
    over = f"of each rock's highest point in {width:g} m bins"
    ax.plot(x, env["max"], color="tab:red", label=f"maximum {over}")
    ax.plot(x, env["p95"], color="tab:orange", ls="--", label=f"95th percentile {over}")
    ax.plot(x, env["p50"], color="tab:blue", label=f"median {over}")
    for i, m in enumerate(v for v in measured if v.height_m is not None):
        ax.plot(
            [m.x_m],
            [m.height_m],
            "o",
            color=_MEASURED_COLOUR,
            label="measured mean bounce height, at its x" if i == 0 else None,
        )
        ax.axhline(
            m.height_m,
            color=_MEASURED_COLOUR,
            lw=0.8,
            ls=":",
            label="measured mean bounce height, level" if i == 0 else None,
        )
    ax.set_xlabel("x, horizontal distance (m)")
    ax.set_ylabel("bounce height: centre above the ground, vertical (m)")
    ax.set_title("Bounce-height envelope (over the rocks reaching each x bin)")
    if not x.size:
        ax.text(
            0.5,
            0.5,
            "no envelope computed (no bin width given)",
            transform=ax.transAxes,
            ha="center",
        )
    ax.set_ylim(bottom=0.0)
    outside_legend(ax)
    return fig


def _measured_percentile(values: np.ndarray, measured: float) -> float:
    """Percent of ``values`` below ``measured`` (ties half), as summary.json."""
    below = (values < measured).sum() + 0.5 * (values == measured).sum()
    return 100.0 * float(below) / values.size


def point_histograms_figure(
    result: SimulationResult, index: int, *, measured: Measured | None = None
) -> Figure:
    """Speed, translational KE and total energy at analysis point ``index``.

    Percentiles are marked; a measured speed is drawn on the speed panel and a
    measured (translational) kinetic energy on the translational KE panel -- like
    with like -- each with its percentile among the simulated rocks. The total
    energy (translational + rotational) is what a barrier must absorb.
    """
    point = result.analysis[index]
    crossed = np.asarray(point.crossed, bool)
    fig = Figure(figsize=(14.0, 4.4), layout="constrained")
    axes = fig.subplots(1, 3)
    panels = (
        (
            np.asarray(point.speed_mps, float)[crossed],
            "speed of the centre (m/s)",
            "m/s",
            1.0,
            None if measured is None else measured.speed_mps,
            "measured speed",
        ),
        (
            np.asarray(point.ke_j, float)[crossed] / 1e3,
            "translational kinetic energy, 1/2 m v² (kJ)",
            "kJ",
            1e-3,
            None if measured is None else measured.ke_j,
            "measured translational KE",
        ),
        (
            np.asarray(point.total_j, float)[crossed] / 1e3,
            "total kinetic energy, translational + rotational (kJ)",
            "kJ",
            1e-3,
            None,
            "",
        ),
    )
    for ax, (values, label, unit, scale, meas, meas_label) in zip(
        axes, panels, strict=True
    ):
        ax.grid(True, alpha=0.3)
        values = values[np.isfinite(values)]
        if values.size:
            ax.hist(
                values,
                bins=min(50, max(10, values.size // 20)),
                color="0.6",
                label="simulated rocks crossing this x",
            )
            for q in PERCENTILES:
                v = float(np.percentile(values, q))
                ax.axvline(
                    v,
                    color="tab:blue",
                    ls=_PERCENTILE_STYLES[q],
                    label=f"{q}th percentile = {v:.3g} {unit}",
                )
        if meas is not None:
            rank = (
                f", percentile {_measured_percentile(values, meas * scale):.0f}"
                if values.size
                else ""
            )
            ax.axvline(
                meas * scale,
                color=_MEASURED_COLOUR,
                lw=2.0,
                label=f"{meas_label} = {meas * scale:.3g} {unit}{rank}",
            )
        ax.set_xlabel(label)
        ax.set_ylabel("number of rocks")
        ax.legend(fontsize=7, loc="upper right")
    fig.suptitle(
        f"x = {point.x_m:g} m: {int(crossed.sum())} of {result.rocks} rocks passed "
        "(values at their first crossing)"
    )
    return fig


def runout_figure(result: SimulationResult) -> Figure:
    """Where the rocks ended, by final state: stopped on the profile, left it at
    either end, or still moving at the impact limit (capped, drawn apart: where
    they were when the simulation stopped following them, not a runout)."""
    from fieldkit.model.results import (
        EXITED_DOWNSLOPE,
        EXITED_UPSLOPE,
        MAX_IMPACTS,
        STOPPED,
    )

    fig, ax = new_figure(8.0, 4.0)
    x = np.asarray(result.runout_x_m, float)
    state = np.asarray(result.state)
    ok = np.isfinite(x)
    bins = np.histogram_bin_edges(x[ok], bins=min(60, max(10, int(ok.sum()) // 20)))
    groups = [
        (STOPPED, "stopped on the profile", "0.55"),
        (EXITED_DOWNSLOPE, "left the profile at its lower end", "tab:green"),
        (EXITED_UPSLOPE, "left the profile at its upper end", "tab:purple"),
        (
            MAX_IMPACTS,
            "capped: still moving at the impact limit, core.max_impacts (where "
            "they were; not a runout)",
            "tab:red",
        ),
    ]
    data, labels, colours = [], [], []
    for code, label, colour in groups:
        sel = ok & (state == code)
        if sel.any():
            data.append(x[sel])
            labels.append(f"{label} ({int(sel.sum())} rocks)")
            colours.append(colour)
    if data:
        ax.hist(data, bins=bins, stacked=True, color=colours, label=labels)
    ended = ok & (state != MAX_IMPACTS)
    if ended.any():
        for q in PERCENTILES:
            v = float(np.percentile(x[ended], q))
            ax.axvline(
                v,
                color="tab:blue",
                ls=_PERCENTILE_STYLES[q],
                label=f"runout {q}th percentile = {v:.4g} m (capped rocks left out)",
            )
    ax.set_xlabel("x where the rock ended, horizontal distance (m)")
    ax.set_ylabel("number of rocks")
    ax.set_title("Runout distribution, by final state")
    outside_legend(ax)
    return fig


def simulation_figure_names(result: SimulationResult) -> list[str]:
    """The PNG names :func:`write_simulation_figures` writes (to plan them early)."""
    names = ["trajectories.png", "envelope.png", "runout.png"]
    names += [f"point_{i + 1}_x{p.x_m:g}.png" for i, p in enumerate(result.analysis)]
    return names


def point_figure_names(analysis_x_m: Sequence[float]) -> list[str]:
    """Names of the figures for these analysis points, before a result exists."""
    base = ["trajectories.png", "envelope.png", "runout.png"]
    return base + [f"point_{i + 1}_x{x:g}.png" for i, x in enumerate(analysis_x_m)]


def write_simulation_figures(
    folder: str | os.PathLike[str],
    result: SimulationResult,
    *,
    measured: Sequence[Measured] = (),
    outputs: OutputSet | None = None,
) -> list[Path]:
    """Write every figure of a simulation into ``folder`` (names as
    :func:`simulation_figure_names`)."""
    folder = Path(folder)
    names = simulation_figure_names(result)
    figures = [
        trajectories_figure(result),
        envelope_figure(result, measured=measured),
        runout_figure(result),
    ]
    for i, point in enumerate(result.analysis):
        near = [m for m in measured if np.isclose(m.x_m, point.x_m)]
        figures.append(
            point_histograms_figure(result, i, measured=near[0] if near else None)
        )
    return [
        save_png(fig, folder / name, outputs=outputs)
        for fig, name in zip(figures, names, strict=True)
    ]
