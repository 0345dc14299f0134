"""The corridor figures: design values against chainage, and the plan.

``chainage.png`` -- three panels on one chainage axis, as a barrier designer reads
them: the p95 and p99 kinetic energy at the alignment with their Monte Carlo SE
bands and the ETAG 027 class limits (MEL) as horizontal lines; the p95 and p99
bounce heights with SE bands; the passing fraction with its SE band.
``plan.png`` -- the hillshade with the alignment, its stations coloured by the
p99 energy, and (2-D) each station's section.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from fieldkit.corridor.table import ETAG027_MEL_KJ
from fieldkit.outputs import OutputSet
from fieldkit.viz.figure_files import save_png
from fieldkit.viz.terrain_figure import hillshade


def _band(ax, c, frame, key: str, se: str, color: str, label: str, scale=1.0) -> None:
    v = frame[key].to_numpy(float) * scale
    s = frame[se].to_numpy(float) * scale
    ax.plot(c, v, "o-", color=color, ms=3, lw=1.2, label=label)
    ax.fill_between(c, v - s, v + s, color=color, alpha=0.25, lw=0)


def write_chainage_figure(
    path: str | os.PathLike[str], frame, *, title: str, outputs: OutputSet | None = None
) -> Path:
    """Write ``chainage.png`` (module docstring) from the corridor table."""
    fig = Figure(figsize=(9.0, 8.5), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    c = frame["chainage_m"].to_numpy(float)
    ax = axes[0]
    _band(ax, c, frame, "energy_p95_kj", "energy_p95_se_kj", "tab:orange", "p95")
    _band(ax, c, frame, "energy_p99_kj", "energy_p99_se_kj", "tab:red", "p99")
    top = np.nanmax(frame[["energy_p99_kj", "energy_max_kj"]].to_numpy(float),
                    initial=0.0)  # fmt: skip
    shown = [(k, mel) for k, mel in ETAG027_MEL_KJ.items() if mel <= 1.6 * top + 1e-9]
    shown = shown or [(0, ETAG027_MEL_KJ[0])]
    for k, mel in shown:
        ax.axhline(mel, color="0.4", lw=0.8, ls="--")
        ax.annotate(f"class {k}: {mel:g} kJ", (c[0], mel), xytext=(2, 2),
                    textcoords="offset points", fontsize=7, color="0.3")  # fmt: skip
    ax.set_ylim(0, max(1.15 * top, 1.1 * shown[-1][1]))
    ax.set_ylabel("kinetic energy at the alignment (kJ)")
    ax.set_title(title, fontsize=10)
    ax.legend(loc="upper right", fontsize=8, title="band: ±1 Monte Carlo SE",
              title_fontsize=7)  # fmt: skip
    ax = axes[1]
    _band(ax, c, frame, "height_p95_m", "height_p95_se_m", "tab:cyan", "p95")
    _band(ax, c, frame, "height_p99_m", "height_p99_se_m", "tab:blue", "p99")
    ax.set_ylim(bottom=0)
    ax.set_ylabel("bounce height (m)")
    ax.legend(loc="upper right", fontsize=8)
    ax = axes[2]
    _band(ax, c, frame, "passing_fraction", "passing_fraction_se", "tab:green",
          "passing fraction")  # fmt: skip
    ax.set_ylim(bottom=0)
    ax.set_ylabel("rocks crossing")
    ax.set_xlabel("chainage along the alignment (m)")
    for a in axes:
        a.grid(True, alpha=0.3)
    return save_png(fig, path, outputs=outputs)


def write_plan_figure(
    path: str | os.PathLike[str],
    terrain,
    scan,
    *,
    outputs: OutputSet | None = None,
) -> Path:
    """Write ``plan.png`` (module docstring) of a :class:`~fieldkit.corridor.scan.
    CorridorScan` on its DEM (a :class:`~fieldkit.model.terrain.Terrain`)."""
    ny, nx = terrain.shape
    extent = (terrain.x0_m, terrain.x0_m + nx * terrain.cell_m,
              terrain.y0_m, terrain.y0_m + ny * terrain.cell_m)  # fmt: skip
    fig = Figure(figsize=(7.5, 7.5 * ny / max(nx, 1) + 0.8), layout="constrained")
    ax = fig.add_subplot()
    ax.imshow(hillshade(terrain), cmap="gray", origin="lower", extent=extent,
              vmin=0, vmax=1)  # fmt: skip
    st = scan.stations
    if scan.sections is not None:
        for i, s in enumerate(scan.sections):
            sign = 1 if s.side == "left" else -1
            n = sign * st.normal_xy[i]
            a = st.xy_m[i] + s.alignment_x_m * n
            b = st.xy_m[i] - s.beyond_m * n
            ax.plot([a[0], b[0]], [a[1], b[1]], "-", color="tab:blue", lw=0.6,
                    alpha=0.6, label="section" if i == 0 else None)  # fmt: skip
    for p in scan.paths[:40]:
        ax.plot(p[:, 0], p[:, 1], "-", color="tab:purple", lw=0.5, alpha=0.5)
    xy = st.alignment_xy
    ax.plot(xy[:, 0], xy[:, 1], "-", color="k", lw=1.5, label="alignment")
    energy = scan.frame["energy_p99_kj"].to_numpy(float)
    points = ax.scatter(st.xy_m[:, 0], st.xy_m[:, 1], c=energy, cmap="inferno_r",
                        s=30, edgecolors="k", linewidths=0.5, zorder=3)  # fmt: skip
    fig.colorbar(points, ax=ax, shrink=0.7, label="p99 energy at the station (kJ)")
    ax.set_xlim(extent[0], extent[1])
    ax.set_ylim(extent[2], extent[3])
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"corridor scan ({scan.dimension}-D): stations and sample paths",
                 fontsize=10)  # fmt: skip
    ax.legend(loc="upper right", fontsize=8)
    return save_png(fig, path, outputs=outputs)
