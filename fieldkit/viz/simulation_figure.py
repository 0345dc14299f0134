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
import textwrap
from collections.abc import Sequence
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.figure import Figure

from fieldkit.measured import Measured  # noqa: F401 (its old home; figures draw it)
from fieldkit.model.results import SimulationResult
from fieldkit.model.statistics import PERCENTILES
from fieldkit.outputs import OutputSet
from fieldkit.viz.figure_files import new_figure, save_png
from fieldkit.viz.marks import outside_legend

_MATERIAL_COLOURS = ("#b89b72", "#8c8c8c", "#7fa36b", "#c9b458", "#9c6f5a", "#6b8fa3")
_PERCENTILE_STYLES = {50: "-", 90: "--", 95: "-.", 99: ":"}
_MEASURED_COLOUR = "red"
_TRAJECTORY_COLOURS = matplotlib.colormaps["tab10"]


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
            alpha=0.35,
            lw=0,
            label=f"material: {name}" if new else None,
        )
    ax.plot(x, z, color="black", lw=0.8, zorder=3, label="ground surface (profile)")


#: Largest section height drawn at true scale [in]; a flatter section is exaggerated.
_SECTION_MAX_IN = 4.5
_SECTION_MIN_IN = 2.2
_FIGURE_WIDTH_IN = 10.0


def _exaggeration(x_span_m: float, z_span_m: float) -> tuple[float, float]:
    """Vertical exaggeration (1 = true scale) and the section's height in inches
    for an axes about 8.6 in wide: true scale unless that is flatter than
    :data:`_SECTION_MIN_IN` or taller than :data:`_SECTION_MAX_IN`."""
    width_in = _FIGURE_WIDTH_IN - 1.8  # less the labels
    true_in = width_in * z_span_m / max(x_span_m, 1e-9)
    if true_in < _SECTION_MIN_IN:
        exaggeration = _SECTION_MIN_IN / max(true_in, 1e-9)
        exaggeration = float(np.ceil(exaggeration * 2) / 2)  # 1.5, 2, 2.5 ...
        return exaggeration, true_in * exaggeration
    return 1.0, min(true_in, _SECTION_MAX_IN)


def trajectories_figure(
    result: SimulationResult, *, count: int | None = None
) -> Figure:
    """The section with the first ``count`` trajectories and the analysis points
    (Figs. 7.12, 7.15), at true scale (or a stated vertical exaggeration for a flat
    section) and fitted to the section; below it the same trajectories as the
    height of the rock's centre above the ground, where a rolling rock and a
    flying one can be told apart."""
    profile = result.model.profile
    px, pz = np.asarray(profile.x_m, float), np.asarray(profile.z_m, float)
    paths = result.trajectories[: count if count is not None else None]
    z_top = max([pz.max()] + [float(np.nanmax(p[:, 1])) for p in paths if p.size])
    z_span = z_top - pz.min()
    _, section_in = _exaggeration(px.max() - px.min(), 1.1 * z_span)
    fig = Figure(figsize=(_FIGURE_WIDTH_IN, section_in + 3.6), layout="constrained")
    top, low = fig.subplots(
        2, 1, sharex=True, height_ratios=[section_in, 2.0], squeeze=True
    )
    for ax in (top, low):
        ax.grid(True, alpha=0.3)
    _draw_section(top, profile)
    colours = [_TRAJECTORY_COLOURS(i % 10) for i in range(len(paths))]
    ground = getattr(profile, "ground_z", None)
    for i, (path, colour) in enumerate(zip(paths, colours, strict=True)):
        label = (
            f"trajectories of the rock's centre ({len(paths)} of {result.rocks:,} "
            "rocks, one colour each)"
            if i == 0
            else None
        )
        top.plot(path[:, 0], path[:, 1], color=colour, lw=0.9, zorder=4, label=label)
        if ground is not None:
            above = path[:, 1] - np.asarray(ground(path[:, 0]), float)
            low.plot(path[:, 0], above, color=colour, lw=0.9)
    where = ", ".join(f"{p.x_m:g}" for p in result.analysis)
    for i, point in enumerate(result.analysis):
        for ax in (top, low):
            ax.axvline(
                point.x_m,
                color="tab:blue",
                lw=1.2,
                ls="--",
                zorder=5,
                label=f"analysis points (x = {where} m: speeds and energies read there)"
                if i == 0 and ax is top
                else None,
            )
    bottom = pz.min() - 0.05 * z_span
    top.set_xlim(px.min(), px.max())
    top.set_ylim(bottom, z_top + 0.05 * z_span)
    top.set_ylabel("elevation z (m)\nscale")
    top.set_title(
        f"Simulated trajectories: the first {len(paths)} of {result.rocks:,} rocks "
        f"(seed {result.seed})"
    )
    low.axhline(0.0, color="black", lw=0.8)
    low.set_ylim(bottom=0.0)
    low.set_xlabel("horizontal distance x (m)")
    low.set_ylabel("centre above\nthe ground (m)")
    outside_legend(top, below=True, ncols=2)
    top.set_ylabel(f"elevation z (m)\n{_scale_words(top)}")
    return fig


def _scale_words(ax) -> str:
    """The drawn vertical exaggeration of ``ax`` (after layout): "true scale" within
    5 %, else "vertical exaggeration 2.3x"."""
    ax.figure.draw_without_rendering()
    box = ax.get_window_extent()
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    ratio = (box.height / abs(y1 - y0)) / (box.width / abs(x1 - x0))
    if abs(ratio - 1.0) <= 0.05:
        return "true scale"
    return f"vertical exaggeration {ratio:.1f}x"


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
    outside_legend(ax, below=True, ncols=2)
    return fig


def point_histograms_figure(
    result: SimulationResult, index: int, *, measured: Measured | None = None
) -> Figure:
    """Speed, translational KE and total energy at analysis point ``index``.

    Percentiles are marked; a measured speed is drawn on the speed panel and a
    measured (translational) kinetic energy on the translational KE panel -- like
    with like -- each with its percentile among the simulated rocks (or, beyond
    every one of them, "above all N simulated rocks";
    :func:`fieldkit.model.statistics.rank_of`). The total energy (translational +
    rotational) is what a barrier must absorb. Each panel's legend sits under it,
    off the bars.
    """
    from fieldkit.model.results import rank_words, readable
    from fieldkit.model.statistics import rank_of

    point = result.analysis[index]
    crossed = np.asarray(point.crossed, bool)
    fig = Figure(figsize=(15.0, 6.0), layout="constrained")
    grid = fig.subplots(2, 3, height_ratios=[3.0, 1.0])
    axes, keys = grid[0], grid[1]
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
            None if measured is None else measured.total_j,
            "measured total energy",
        ),
    )
    for ax, key, (values, label, unit, scale, meas, meas_label) in zip(
        axes, keys, panels, strict=True
    ):
        ax.grid(True, alpha=0.3)
        values = values[np.isfinite(values)]
        if values.size:
            ax.hist(
                values,
                bins=min(50, max(10, values.size // 20)),
                color="0.6",
                label=f"simulated rocks crossing this x ({values.size:,})",
            )
            for q in PERCENTILES:
                v = float(np.percentile(values, q))
                ax.axvline(
                    v,
                    color="tab:blue",
                    ls=_PERCENTILE_STYLES[q],
                    label=f"{q}th percentile = {readable(v)} {unit}",
                )
        if meas is not None:
            rank = rank_of(values, meas * scale)
            ax.axvline(
                meas * scale,
                color=_MEASURED_COLOUR,
                lw=2.0,
                label=f"{meas_label} = {meas * scale:.4g} {unit}: "
                + rank_words(rank, 1.0, unit, decimals=0),
            )
        ax.set_xlabel(label)
        ax.set_ylabel("number of rocks")
        key.axis("off")
        handles, labels = ax.get_legend_handles_labels()
        if handles:  # under the panel, wrapped to its width, off the layout
            labels = [textwrap.fill(text, 60) for text in labels]
            key.legend(
                handles, labels, loc="upper center", fontsize=8, frameon=False
            ).set_in_layout(False)
    fig.suptitle(
        f"x = {point.x_m:g} m: {int(crossed.sum()):,} of {result.rocks:,} rocks passed "
        "(values at their first crossing)"
    )
    return fig


def _ordinal_list(qs: Sequence[int]) -> str:
    """``[90, 95]`` -> "90th, 95th percentiles"; ``[50]`` -> "50th percentile"."""
    words = ", ".join(f"{q}th" for q in qs)
    return f"{words} percentile{'s' if len(qs) > 1 else ''}"


def runout_figure(result: SimulationResult) -> Figure:
    """Where the rocks ended, by final state: stopped on the profile, left it at
    either end, or still moving at the impact limit (capped, drawn apart: where
    they were when the simulation stopped following them, not a runout).

    Rocks that left the profile at its lower end have no runout on it: their bar
    stands beyond the profile's end (its count written on it when it would dwarf
    the rest). A runout percentile that uses them is only a lower bound: no line
    but a "≥" mark at the end, said once in the legend with the fraction that left.
    """
    from fieldkit.model.results import (
        EXITED_DOWNSLOPE,
        EXITED_UPSLOPE,
        MAX_IMPACTS,
        STOPPED,
        censored_words,
    )
    from fieldkit.model.statistics import distribution

    fig, ax = new_figure(9.0, 5.2)
    x = np.asarray(result.runout_x_m, float)
    state = np.asarray(result.state)
    ok = np.isfinite(x)
    px = np.asarray(result.model.profile.x_m, float)
    x_start, x_end = float(px.min()), float(px.max())
    on = ok & ((state == STOPPED) | (state == MAX_IMPACTS))
    span = x[on] if on.any() else np.array([x_start, x_end])
    edges = np.histogram_bin_edges(
        span, bins=min(60, max(10, int(on.sum()) // 20)), range=(span.min(), x_end)
    )
    width = float(edges[1] - edges[0])
    groups = [
        (STOPPED, "stopped on the profile ({n:,} rocks)", "0.45"),
        (
            MAX_IMPACTS,
            "capped ({n:,} rocks): still moving at the impact limit, "
            "core.max_impacts; where they were, not a runout (left out of the "
            "percentiles)",
            "tab:red",
        ),
    ]
    data, labels, colours = [], [], []
    for code, label, colour in groups:
        sel = ok & (state == code)
        if sel.any():
            data.append(x[sel])
            labels.append(label.format(n=int(sel.sum())))
            colours.append(colour)
    tallest = 0.0
    if data:
        counts = ax.hist(data, bins=edges, stacked=True, color=colours, label=labels)[0]
        tallest = float(np.max(counts))
    # rocks that left the profile: a bar beyond the end they left by
    off = []
    for code, at, side, colour in (
        (EXITED_DOWNSLOPE, x_end + 2 * width, "lower", "tab:green"),
        (EXITED_UPSLOPE, x_start - 2 * width, "upper", "tab:purple"),
    ):
        n = int((ok & (state == code)).sum())
        if n:
            off.append((at, n, colour))
            ax.bar(at, n, width=2 * width, color=colour, hatch="//", edgecolor="white",
                   label=f"left the profile at its {side} end ({n:,} rocks, drawn "
                   "beyond it: their runout is not on the profile)")  # fmt: skip
    top = max(tallest, 1.0) * 1.25
    if any(n > 2.5 * max(tallest, 1.0) for _, n, _ in off):
        ax.set_ylim(0.0, top)  # the others stay readable; the count is written
        for at, n, _ in off:
            if n > top:
                ax.text(at, top * 0.95, f"{n:,}\n↑", ha="center", va="top",
                        fontsize=9, fontweight="bold",
                        bbox={"facecolor": "white", "edgecolor": "none"})  # fmt: skip
    ax.axvline(x_end, color="black", lw=1.0, ls=(0, (1, 1)),
               label=f"lower end of the profile, x = {x_end:g} m")  # fmt: skip
    ended = ok & (state != MAX_IMPACTS)
    if ended.any():
        left = state == EXITED_DOWNSLOPE
        d = distribution(x[ended], at_least=left[ended])
        bounds: dict[float, list[int]] = {}
        for q in PERCENTILES:
            v = float(d[f"p{q}"])
            if d["lower_bound"][f"p{q}"]:
                bounds.setdefault(v, []).append(q)
                continue
            ax.axvline(v, color="tab:blue", ls=_PERCENTILE_STYLES[q],
                       label=f"runout {q}th percentile = {v:.4g} m")  # fmt: skip
        fraction = int(left[ended].sum()) / int(ended.sum())
        for v, qs in bounds.items():
            ax.plot([v], [0.5], marker=">", ms=10, color="tab:blue", ls="",
                    transform=ax.get_xaxis_transform(), zorder=6,
                    label=f"runout {_ordinal_list(qs)} ≥ {v:.4g} m "
                    f"({censored_words(fraction)})")  # fmt: skip
    ax.set_xlabel("x where the rock ended, horizontal distance (m)")
    ax.set_ylabel("number of rocks")
    ax.set_title(f"Runout: where {result.rocks:,} rocks ended, by final state")
    outside_legend(ax, below=True, ncols=1)
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
