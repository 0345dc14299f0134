"""A section cut from a DEM: the plan line on the grid, and the section at true scale.

Left: the DEM (elevations in colour, with contours) with the plan line and its
start. Right: elevation against chainage, equal scales, each material its own colour.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from fieldkit.io.dem import DemGrid
from fieldkit.model.dem_profile import Section
from fieldkit.outputs import OutputSet
from fieldkit.viz.figure_files import new_figure, save_png

LINE_COLOUR = "#b22222"


#: How each :attr:`~fieldkit.model.dem_profile.Section.ending` reads in a title.
ENDING_TEXT = {
    "local minimum": "the steepest descent stopped at a local minimum",
    "flat area": "the steepest descent stopped on a flat area",
    "grid edge": "the line stopped at the edge of the DEM",
    "nodata": "the line stopped at nodata cells",
    "maximum length": "the line stopped at its maximum length",
    "vertex limit": "the line stopped at the vertex limit",
    "end of polyline": "along the polyline to its last point",
    "end of the CSV": "as read, to the CSV's last row",
}


def ending_text(ending: str) -> str:
    """How a section ended, in words (:data:`ENDING_TEXT`; an unknown value as
    given).

    Examples
    --------
    >>> ending_text("local minimum")
    'the steepest descent stopped at a local minimum'
    """
    return ENDING_TEXT.get(ending, ending)


def save_profile_figure(
    grid: DemGrid | None,
    section: Section,
    path: str | os.PathLike[str],
    *,
    title: str = "",
    outputs: OutputSet | None = None,
) -> Path:
    """Draw the plan line and the section (module docstring) and save it as PNG.

    Without a ``grid`` (a section read from a CSV) only the section is drawn.
    """
    if grid is None:
        fig, ax_section = new_figure(9.0, 5.0)
    else:
        fig, ax_plan = new_figure(12.0, 5.0)
        ax_plan.remove()
        ax_plan, ax_section = fig.subplots(1, 2, width_ratios=(1, 1.6))
        _draw_plan(fig, ax_plan, grid, section)
    _draw_section(ax_section, section, title)
    return save_png(fig, path, outputs=outputs)


def _draw_plan(fig, ax_plan, grid: DemGrid, section: Section) -> None:
    ncols = grid.shape[1]
    extent = (
        grid.x_left_m,
        grid.x_left_m + ncols * grid.dx_m,
        grid.y_bottom_m,
        grid.y_top_m,
    )
    image = ax_plan.imshow(
        np.ma.masked_invalid(grid.values), extent=extent, cmap="terrain", origin="upper"
    )
    fig.colorbar(image, ax=ax_plan, label="elevation [m]", shrink=0.8)
    if np.isfinite(grid.values).sum() > 3:
        ax_plan.contour(grid.x_m, grid.y_m, grid.values, colors="k", linewidths=0.4,
                        alpha=0.5)  # fmt: skip
    ax_plan.plot(section.plan_x_m, section.plan_y_m, color=LINE_COLOUR, lw=1.5,
                 label="section line")  # fmt: skip
    ax_plan.plot(section.plan_x_m[0], section.plan_y_m[0], "o", color=LINE_COLOUR,
                 label="start")  # fmt: skip
    ax_plan.set_xlabel("x, easting in the DEM's coordinates [m]")
    ax_plan.set_ylabel("y, northing in the DEM's coordinates [m]")
    ax_plan.set_aspect("equal")
    ax_plan.legend(loc="best", fontsize=8)
    ax_plan.set_title(Path(grid.source).name or "DEM", fontsize=10)


def _draw_section(ax_section, section: Section, title: str) -> None:
    materials = np.array(section.material)
    for i, name in enumerate(dict.fromkeys(section.material)):
        for j in np.flatnonzero(materials == name):
            ax_section.plot(
                section.chainage_m[j : j + 2], section.z_m[j : j + 2],
                color=f"C{i}", lw=2, label=name if j == np.flatnonzero(
                    materials == name)[0] else None,
            )  # fmt: skip
    ax_section.set_xlabel("chainage, horizontal distance along the line [m]")
    ax_section.set_ylabel("z, elevation [m]")
    ax_section.set_aspect("equal", adjustable="datalim")
    ax_section.grid(True, alpha=0.3)
    ax_section.legend(title="material", fontsize=8, loc="upper right")
    ending = ending_text(section.ending)
    ax_section.set_title(title or f"section: {ending}", fontsize=10)
