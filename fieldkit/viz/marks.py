"""What every figure draws the same way: legends, quality flags, velocity scales.

* :func:`outside_legend` -- the legend beside the axes, never over the data or the
  labels annotated on it (``loc="best"`` only avoids data, not annotations);
* :func:`qa_flagged` / :func:`mark_flagged` -- impacts whose ``qa_flags`` column
  (docs/architecture.md §3: ``;``-separated flags) is not empty get an open red ring
  and a "quality flag" legend entry;
* :func:`velocity_key` -- the scale of a quiver of velocity arrows ("10 m/s"), in the
  corner of the axes with the fewest data points (:func:`free_corner`).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.legend import Legend
from matplotlib.quiver import Quiver, QuiverKey

QA_COLOUR = "red"
QA_LABEL = "quality flag"


def outside_legend(ax: Axes, *, below: bool = False, **kwargs) -> Legend | None:
    """Legend outside the axes: to the right of ``ax``, or (``below``) a figure legend
    under all axes. None when nothing is labelled.

    The figure's constrained layout makes room for it.
    """
    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return None
    if below:
        options = dict(loc="outside lower center", ncols=3, fontsize=8)
        options.update(kwargs)
        return ax.figure.legend(handles, labels, **options)
    options = dict(
        loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, fontsize=8
    )
    options.update(kwargs)
    return ax.legend(**options)


def qa_flagged(frame: pd.DataFrame) -> np.ndarray:
    """Rows with at least one quality flag (``qa_flags`` not empty); all False when the
    table has no ``qa_flags`` column.

    Examples
    --------
    >>> qa_flagged(pd.DataFrame({"qa_flags": ["", "e_t > 1", None, " ; "]})).tolist()
    [False, True, False, False]
    """
    if "qa_flags" not in frame.columns:
        return np.zeros(len(frame), bool)
    return np.array(
        [
            isinstance(v, str) and any(part.strip() for part in v.split(";"))
            for v in frame["qa_flags"]
        ],
        dtype=bool,
    )


def mark_flagged(ax: Axes, x, y, flagged) -> None:
    """Open red rings around the flagged points, with one "quality flag" legend entry.

    Draws nothing when no point is flagged.
    """
    flagged = np.asarray(flagged, bool)
    x, y = np.asarray(x, float)[flagged], np.asarray(y, float)[flagged]
    if not flagged.any():
        return
    ax.scatter(
        x,
        y,
        s=150,
        facecolors="none",
        edgecolors=QA_COLOUR,
        linewidths=1.5,
        zorder=7,
        label=f"{QA_LABEL} ({int(flagged.sum())})",
    )


def nice_speed(largest_mps: float) -> float:
    """A round speed (1, 2 or 5 x 10^k m/s) no larger than ``largest_mps``.

    Examples
    --------
    >>> [nice_speed(v) for v in (0.37, 1.0, 3.9, 22.0, 78.0)]
    [0.2, 1.0, 2.0, 20.0, 50.0]
    """
    if not (math.isfinite(largest_mps) and largest_mps > 0):
        return 1.0
    power = 10.0 ** math.floor(math.log10(largest_mps))
    for step in (5.0, 2.0, 1.0):
        if step * power <= largest_mps * (1 + 1e-12):
            return step * power
    return power


#: Corners of the axes (axes coordinates of the box a key needs), in order of
#: preference when several are equally free.
CORNERS = ("upper right", "upper left", "lower right", "lower left")
KEY_BOX = (0.24, 0.1)  # width, height of the key's box [axes fraction]


def free_corner(ax: Axes, x, y) -> str:
    """The corner of ``ax`` whose key-sized box holds the fewest of the points
    ``(x, y)`` (data coordinates), after the axes' limits and aspect are settled."""
    ax.apply_aspect()
    xy = np.column_stack([np.asarray(x, float).ravel(), np.asarray(y, float).ravel()])
    xy = xy[np.isfinite(xy).all(axis=1)]
    pts = ax.transAxes.inverted().transform(ax.transData.transform(xy))
    w, h = KEY_BOX

    def count(corner: str) -> int:
        right, upper = corner.endswith("right"), corner.startswith("upper")
        in_x = pts[:, 0] >= 1 - w if right else pts[:, 0] <= w
        in_y = pts[:, 1] >= 1 - h if upper else pts[:, 1] <= h
        return int((in_x & in_y).sum())

    return min(CORNERS, key=count)  # min keeps the first of equal counts


def velocity_key(ax: Axes, quiver: Quiver, largest_mps: float, x, y) -> QuiverKey:
    """A key arrow of a round speed for ``quiver`` (at the scale of its arrows), in the
    corner of the axes freest of the points ``(x, y)`` (what the axes draw)."""
    speed = nice_speed(largest_mps)
    corner = free_corner(ax, x, y)
    w, h = KEY_BOX
    right, upper = corner.endswith("right"), corner.startswith("upper")
    return ax.quiverkey(
        quiver,
        1 - 0.3 * w if right else 0.7 * w,
        1 - 0.6 * h if upper else 0.4 * h,
        speed,
        f"{speed:g} m/s",
        labelpos="N",
        coordinates="axes",
        color="0.15",
        fontproperties={"size": 8},
    )
