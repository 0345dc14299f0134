"""r.stone's result read back along the path (``fieldkit import-results``): the
fraction of trajectories passing each distance, and the largest energy and height
above the ground r.stone recorded there -- the runout and the design values a
barrier is placed and sized from (thesis Figs. 7.10, 7.13 show them for the thesis's
own simulator)."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure


def rstone_along_figure(table: pd.DataFrame, distance: str, title: str) -> Figure:
    """Three panels over ``table`` (:func:`fieldkit.io.rstone_results.along_path`):
    survival, max energy [kJ], max height [m] against the distance.

    Parameters
    ----------
    table
        ``distance_m``, ``survival``, ``max_energy_kj``, ``max_height_m``.
    distance
        What the distance is (chainage along an extruded section, or plan distance
        from the release), for the x label.
    title
        The figure's title.
    """
    fig = Figure(figsize=(8.0, 8.0), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    x = table["distance_m"].to_numpy(float)
    panels = (
        ("survival", "fraction of trajectories\npassing", None),
        ("max_energy_kj", "largest kinetic\nenergy [kJ]", None),
        ("max_height_m", "largest height above\nthe ground [m]", None),
    )
    for ax, (column, label, _) in zip(axes, panels, strict=True):
        y = table[column].to_numpy(float)
        ok = np.isfinite(y)
        ax.step(x[ok], y[ok], where="mid", color="C0")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[0].set_ylim(-0.02, 1.02)
    for q, style in ((0.5, "--"), (0.05, ":")):
        axes[0].axhline(q, color="0.4", lw=0.8, ls=style)
        axes[0].annotate(
            f"{100 * (1 - q):.0f} % stopped",
            (x[0] if x.size else 0.0, q),
            xytext=(2, 2),
            textcoords="offset points",
            fontsize=8,
            color="0.3",
        )
    axes[-1].set_xlabel(distance)
    axes[0].set_title(title)
    return fig
