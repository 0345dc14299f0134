"""The map of a 3-D simulation: hillshade, deposit density, releases, observed
deposits and analysis lines, in the DEM's coordinates."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from fieldkit.model.terrain import Terrain
from fieldkit.outputs import OutputSet
from fieldkit.viz.figure_files import new_figure, save_png

#: Sun of the hillshade: azimuth and altitude [deg] (the GIS default, from the NW).
SUN_AZIMUTH_DEG, SUN_ALTITUDE_DEG = 315.0, 45.0


def hillshade(terrain: Terrain) -> np.ndarray:
    """Hillshade in [0, 1] of ``terrain.z`` (row 0 south), NaN on nodata.

    Examples
    --------
    >>> flat = Terrain(0.0, 0.0, 5.0, np.zeros((3, 3)))
    >>> float(np.round(hillshade(flat)[1, 1], 4))  # sin(45 deg)
    0.7071
    """
    dz_dy, dz_dx = np.gradient(terrain.z, terrain.cell_m)
    slope = np.arctan(np.hypot(dz_dx, dz_dy))
    aspect = np.arctan2(-dz_dx, -dz_dy)  # direction of steepest descent, from north
    az, alt = np.radians(SUN_AZIMUTH_DEG), np.radians(SUN_ALTITUDE_DEG)
    shade = np.sin(alt) * np.cos(slope) + np.cos(alt) * np.sin(slope) * np.cos(
        az - aspect
    )
    return np.clip(shade, 0.0, 1.0)


def write_terrain_map(
    path: str | os.PathLike[str],
    terrain: Terrain,
    density_per_m2: np.ndarray,
    *,
    releases: np.ndarray,
    deposits: np.ndarray,
    observed: np.ndarray | None = None,
    lines: list[tuple[str, np.ndarray]] = (),
    outputs: OutputSet | None = None,
) -> Path:
    """Write ``map.png``.

    Parameters
    ----------
    path
        The PNG.
    terrain
        The DEM.
    density_per_m2
        Deposit density raster (row 0 south), drawn over the hillshade where > 0.
    releases
        ``(n, 2+)`` release points [m].
    deposits
        ``(n, 2+)`` where simulated rocks stopped [m] (drawn small).
    observed
        ``(m, 2)`` observed deposits [m], or None.
    lines
        ``(name, (k, 2) vertices)`` of the analysis lines.
    outputs
        Written when the set commits (else at once).
    """
    ny, nx = terrain.shape
    extent = (
        terrain.x0_m,
        terrain.x0_m + nx * terrain.cell_m,
        terrain.y0_m,
        terrain.y0_m + ny * terrain.cell_m,
    )
    fig, ax = new_figure(7.0, 7.0 * ny / max(nx, 1) + 0.8)
    ax.grid(False)
    ax.imshow(hillshade(terrain), cmap="gray", origin="lower", extent=extent,
              vmin=0, vmax=1)  # fmt: skip
    shown = np.where(density_per_m2 > 0, density_per_m2, np.nan)
    if np.isfinite(shown).any():
        image = ax.imshow(shown, cmap="magma_r", origin="lower", extent=extent,
                          alpha=0.75)  # fmt: skip
        fig.colorbar(image, ax=ax, shrink=0.7,
                     label="simulated deposits per rock per m²")  # fmt: skip
    ax.plot(deposits[:, 0], deposits[:, 1], ".", ms=2, color="tab:orange",
            label="simulated stop")  # fmt: skip
    ax.plot(releases[:, 0], releases[:, 1], "^", color="tab:green", ms=4,
            label="release")  # fmt: skip
    if observed is not None and len(observed):
        ax.plot(observed[:, 0], observed[:, 1], "o", mfc="none", color="tab:blue",
                ms=5, label="observed deposit")  # fmt: skip
    for name, xy in lines:
        ax.plot(xy[:, 0], xy[:, 1], "-", color="tab:red", lw=2)
        ax.annotate(name, xy[0], color="tab:red", fontsize=8)
    ax.set_xlim(extent[0], extent[1])
    ax.set_ylim(extent[2], extent[3])
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("3-D simulation: hillshade, deposit density")
    ax.legend(loc="upper right", fontsize=8)
    return save_png(fig, path, outputs=outputs)
