"""Section of a reduced path: impacts, flights, trees and velocity vectors (Fig. 2.8).

Left: the whole section at true scale -- ground line through the impact points, each
flight's parabola (solid where a tree strike fixed it, dashed where the restitution
angle was assumed; a flight with no ballistic solution as its dotted grey chord), broken
trees as down arrows, impact numbers, the restitution velocity at each impact with its
scale ("10 m/s"), impacts with quality flags ringed; the legend sits outside the axes.
Right: the detail the thesis draws as an inset -- one impact with its impact and
restitution velocity vectors, their N and T components on the local ground, and e_N,
e_T.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from fieldkit.impact_table import ImpactTable, unsolved_sides
from fieldkit.outputs import OutputSet
from fieldkit.physics.flight import flight_samples
from fieldkit.physics.local_axes import to_section
from fieldkit.survey import Survey
from fieldkit.viz.figure_files import save_png
from fieldkit.viz.marks import (
    impact_count_text,
    impact_rows,
    mark_flagged,
    nice_speed,
    outside_legend,
    qa_column,
    velocity_key,
)

TREE_COLOUR = "#2e7d32"
FLIGHT_COLOUR = "#1f4e9c"
IMPACT_COLOUR = "#b22222"
UNSOLVED_COLOUR = "#7f7f7f"


def flight_paths(table: ImpactTable, n_samples: int = 40) -> list[tuple]:
    """``(x, z, source)`` samples of each flight's parabola (eqs. 3.1, 3.2).

    Sampled by :func:`fieldkit.physics.flight.flight_samples` from the table's launch
    state (``x_m``, ``z_m``, ``vf_x_mps``, ``vf_z_mps``) and ``flight_time_s``.
    """
    f = table.frame
    out = []
    for row in f.itertuples(index=False):
        if not np.isfinite(row.flight_time_s):
            continue
        s = flight_samples(
            row.x_m, row.z_m, row.vf_x_mps, row.vf_z_mps, row.flight_time_s, n_samples
        )
        out.append((s.x_m, s.z_m, str(row.theta0_source)))
    return out


def unsolved_chords(table: ImpactTable) -> list[tuple[np.ndarray, np.ndarray]]:
    """``(x, z)`` of the straight chord of each flight the reduction could not solve
    (``flight_unsolved``): its end points are known, its parabola is not, so the
    figure draws the chord (dotted) instead of a path."""
    f = table.frame
    _, leaves = unsolved_sides(f)
    x, z = f["x_m"].to_numpy(float), f["z_m"].to_numpy(float)
    return [
        (x[i : i + 2], z[i : i + 2]) for i in np.flatnonzero(leaves) if i + 1 < len(f)
    ]


def detail_row(table: ImpactTable) -> int | None:
    """Index of the impact to draw in detail: of the impacts whose restitution a tree
    fixed, the one with the steepest restitution (thesis: #A26, θ0 = 62°); else the
    impact with the largest theta_f."""
    f = table.frame
    ok = np.isfinite(f["e_n"].to_numpy(float)) & np.isfinite(
        f["theta_f_deg"].to_numpy(float)
    )
    if not ok.any():
        return None
    theta_f = np.where(ok, f["theta_f_deg"].to_numpy(float), -np.inf)
    tree = (f["theta0_source"] == "tree").fillna(False).to_numpy(bool) & ok
    if tree.any():
        theta_f = np.where(tree, theta_f, -np.inf)
    return int(np.argmax(theta_f))


def _trees_xy(
    table: ImpactTable, survey: Survey | None
) -> list[tuple[float, float, float]]:
    """(x, ground z, strike z) of each tree strike (ground interpolated if missing)."""
    if survey is None:
        return []
    f = table.frame
    x = f["x_m"].to_numpy(float)
    index = {name: i for i, name in enumerate(f["point"].astype(str))}
    return [
        (float(x[index[key]]) + tree.distance_m, tree.ground_z_m, tree.z_m)
        for key, tree in survey.trees_by_launch().items()
    ]


def plot_section(table: ImpactTable, survey: Survey | None = None) -> Figure:
    """Draw the section figure and return it (see the module docstring)."""
    f = table.frame
    fig = Figure(figsize=(13.0, 6.2), layout="constrained")
    grid = fig.add_gridspec(1, 2, width_ratios=[2.1, 1.0])
    ax = fig.add_subplot(grid[0, 0])
    detail = fig.add_subplot(grid[0, 1])
    x, z = f["x_m"].to_numpy(float), f["z_m"].to_numpy(float)

    ax.fill_between(x, z, z.min() - 0.05 * np.ptp(z), color="#d9c7a7", alpha=0.6, lw=0)
    ax.plot(x, z, color="#6b4f2a", lw=1.0, label="ground (chords between impacts)")
    for xs, zs, source in flight_paths(table):
        style = "-" if source in ("tree", "given", "video") else "--"
        ax.plot(xs, zs, style, color=FLIGHT_COLOUR, lw=0.9)
    ax.plot([], [], "-", color=FLIGHT_COLOUR, label="flight fixed by a tree strike")
    ax.plot([], [], "--", color=FLIGHT_COLOUR, label="flight with assumed θ0")
    chords = unsolved_chords(table)
    for xs, zs in chords:
        ax.plot(xs, zs, ":", color=UNSOLVED_COLOUR, lw=2.2, zorder=4)  # over ground
    if chords:
        ax.plot(
            [], [], ":", color=UNSOLVED_COLOUR, lw=2.2,
            label="unsolved flight (no ballistic solution): chord",
        )  # fmt: skip
    ax.plot(
        x,
        z,
        "o",
        ms=3.5,
        color=IMPACT_COLOUR,
        label="impact point (survey name)",
        zorder=5,
    )
    vfx, vfz = f["vf_x_mps"].to_numpy(float), f["vf_z_mps"].to_numpy(float)
    ok = np.isfinite(vfx) & np.isfinite(vfz)
    if ok.any():
        top = float(np.nanmax(np.hypot(vfx[ok], vfz[ok])))
        arrows = ax.quiver(
            x[ok],
            z[ok],
            vfx[ok],
            vfz[ok],
            angles="xy",
            scale_units="xy",
            scale=top / (0.05 * np.ptp(x)),
            width=0.0022,
            color=FLIGHT_COLOUR,
            alpha=0.8,
            zorder=6,
            label="restitution velocity $v_f$ (∝ speed)",
        )
    impacts = impact_rows(f)  # the release and stop points carry no impact flags
    mark_flagged(ax, x[impacts], z[impacts], qa_column(f[impacts]))
    step = max(1, len(f) // 15)
    for i, row in enumerate(f.itertuples(index=False)):
        if i % step == 0 or i == len(f) - 1:
            ax.annotate(
                str(row.point),
                (row.x_m, row.z_m),
                textcoords="offset points",
                xytext=(4, 5),
                fontsize=7,
                color=IMPACT_COLOUR,
            )
    tree_xy = _trees_xy(table, survey)
    if tree_xy:
        span = np.ptp(z) * 0.035
        for xt, zg, zs in tree_xy:
            ax.annotate(
                "",
                xy=(xt, zs),
                xytext=(xt, zs + span),
                arrowprops={"arrowstyle": "->", "color": TREE_COLOUR, "lw": 1.2},
            )
            ax.plot([xt, xt], [zg, zs], color=TREE_COLOUR, lw=1.5)
        ax.plot([], [], color=TREE_COLOUR, lw=1.5, label="broken tree (strike ↓)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x, horizontal distance along the path [m]")
    ax.set_ylabel("z, elevation [m]")
    ax.set_title(
        f"{', '.join(table.paths())}: mapped impact points and trajectories\n"
        f"{impact_count_text(f)}"
    )
    ax.grid(True, alpha=0.3)
    outside_legend(ax, below=True)
    if ok.any():  # after the limits are set: the key goes where nothing is drawn
        drawn = [(x, z), *((xs, zs) for xs, zs, _ in flight_paths(table))]
        drawn.append((x[ok] + vfx[ok] / arrows.scale, z[ok] + vfz[ok] / arrows.scale))
        velocity_key(
            ax,
            arrows,
            top,
            np.concatenate([d[0] for d in drawn]),
            np.concatenate([d[1] for d in drawn]),
        )

    i = detail_row(table)
    if i is not None:
        _draw_detail(detail, f.iloc[i], f, i)
    else:
        detail.set_axis_off()
    return fig


def _draw_detail(ax: Axes, row, f, i: int) -> None:
    """Inset: impact ``row`` with v_i, v_f and their N/T components."""
    tangent = np.array(to_section(1.0, 0.0, row.slope_deg))  # local T and N axes
    normal = np.array(to_section(0.0, 1.0, row.slope_deg))
    p = np.array([row.x_m, row.z_m])
    vi = np.array([row.vi_x_mps, row.vi_z_mps])
    vf = np.array([row.vf_x_mps, row.vf_z_mps])
    scale = 1.0 / max(row.vi_mps, row.vf_mps)  # longest vector = 1 unit
    ground = np.array([p - 1.4 * tangent, p + 1.4 * tangent])
    ax.fill(
        [*ground[:, 0], ground[1, 0], ground[0, 0]],
        [*ground[:, 1], ground[1, 1] - 0.5, ground[0, 1] - 0.5],
        color="#d9c7a7",
        alpha=0.6,
        lw=0,
    )
    ax.plot(ground[:, 0], ground[:, 1], color="#6b4f2a", lw=1.5)

    def arrow(start, vec, colour, style="-", width=2.0):
        ax.annotate(
            "",
            xy=start + vec,
            xytext=start,
            arrowprops={
                "arrowstyle": "-|>",
                "color": colour,
                "lw": width,
                "linestyle": style,
                "shrinkA": 0,
                "shrinkB": 0,
            },
        )

    vi_s, vf_s = vi * scale, vf * scale
    arrow(p - vi_s, vi_s, IMPACT_COLOUR)
    arrow(p, vf_s, FLIGHT_COLOUR)
    comps = (
        (p - vi_s, float(row.vit_mps) * scale * tangent, IMPACT_COLOUR),
        (
            p - float(row.vin_mps) * scale * normal,
            float(row.vin_mps) * scale * normal,
            IMPACT_COLOUR,
        ),
        (p, float(row.vft_mps) * scale * tangent, FLIGHT_COLOUR),
        (p, float(row.vfn_mps) * scale * normal, FLIGHT_COLOUR),
    )
    for start, vec, colour in comps:
        arrow(start, vec, colour, style=(0, (3, 2)), width=1.0)
    key = nice_speed(max(row.vi_mps, row.vf_mps))  # the scale of these arrows
    key_start = p + np.array([0.15, -1.45])
    arrow(key_start, np.array([key * scale, 0.0]), "0.25", width=1.5)
    ax.text(
        *(key_start + np.array([key * scale / 2, 0.06])),
        f"{key:g} m/s",
        fontsize=8,
        ha="center",
        va="bottom",
        color="0.25",
    )
    ax.text(
        *(p - vi_s + 0.08 * normal),
        f"$v_i$ = {row.vi_mps:.1f} m/s\n$\\theta_i$ = {row.theta_i_deg:.0f}°",
        color=IMPACT_COLOUR,
        fontsize=9,
        ha="right",
        va="bottom",
    )
    ax.text(
        *(p + vf_s + 0.06 * tangent),
        f"$v_f$ = {row.vf_mps:.1f} m/s\n$\\theta_f$ = {row.theta_f_deg:.0f}°",
        color=FLIGHT_COLOUR,
        fontsize=9,
        ha="left",
        va="center",
    )
    ax.text(
        0.03,
        0.04,
        f"$v_{{iN}}$ = {row.vin_mps:.1f}, $v_{{iT}}$ = {row.vit_mps:.1f} m/s\n"
        f"$v_{{fN}}$ = {row.vfn_mps:.1f}, $v_{{fT}}$ = {row.vft_mps:.1f} m/s\n"
        f"$e_N$ = {row.e_n:.2f}, $e_T$ = {row.e_t:.2f}\n"
        f"ψ = {row.slope_deg:.1f}° ({row.theta0_source} θ0)",
        transform=ax.transAxes,
        fontsize=9,
        va="bottom",
        bbox={"boxstyle": "round", "fc": "white", "ec": "0.7"},
    )
    ax.set_aspect("equal")
    ax.set_xlim(p[0] - 1.7, p[0] + 1.7)
    ax.set_ylim(p[1] - 1.6, p[1] + 1.3)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(f"velocities at impact {row.point} (arrows ∝ speed)")


def write_section_figure(
    table: ImpactTable,
    path: str | os.PathLike[str],
    survey: Survey | None = None,
    *,
    outputs: OutputSet | None = None,
) -> Path:
    """Draw :func:`plot_section` and save it as a PNG (into ``outputs`` if given)."""
    return save_png(plot_section(table, survey=survey), path, outputs=outputs)
