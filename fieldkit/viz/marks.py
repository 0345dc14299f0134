"""What every figure draws the same way: legends, quality flags, velocity scales.

* :func:`outside_legend` -- the legend beside the axes, never over the data or the
  labels annotated on it (``loc="best"`` only avoids data, not annotations);
* :func:`qa_flagged` / :func:`mark_flagged` -- impacts with a quality flag
  (``qa_flags``, docs/architecture.md §3: ``;``-separated) that sets them apart get an
  open red ring and a "quality flag" legend entry naming the flags; a method flag
  (slope from the chord, spin estimated) or a flag every impact carries marks no
  impact and is said once, in one legend line (:func:`flag_summary`);
* :func:`velocity_key` -- the scale of a quiver of velocity arrows ("10 m/s"), in the
  corner of the axes with the fewest data points (:func:`free_corner`).
"""

from __future__ import annotations

import math
import textwrap
from dataclasses import dataclass

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.legend import Legend
from matplotlib.patches import Rectangle
from matplotlib.quiver import Quiver, QuiverKey

from fieldkit.impact_table import (
    METHOD_QA_FLAGS,
    QA_FLAG_LABELS,
    flight_sides,
    unsolved_sides,
)

QA_COLOUR = "red"
QA_LABEL = "quality flag"
#: Legend line for flags not ringed (method flags, flags on every row).
SHARED_LABEL = "not ringed, said once"


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


def _flag_names(qa_flags) -> list[list[str]]:
    """Each row's flags (``;``-separated ``qa_flags`` values; None / NaN = none)."""
    return [
        [part.strip() for part in v.split(";") if part.strip()]
        if isinstance(v, str)
        else []
        for v in qa_flags
    ]


@dataclass(frozen=True)
class FlagSummary:
    """Which quality flags set rows apart, and which are said once.

    Attributes
    ----------
    apart
        Per row, the flags that set it apart from the other rows: every flag except
        a method flag (:data:`fieldkit.impact_table.METHOD_QA_FLAGS`) and a flag
        carried by every row.
    shared
        Flags not ringed (method flags and flags on every row) -> rows carrying them.
    rows
        Number of rows.
    """

    apart: list[list[str]]
    shared: dict[str, int]
    rows: int

    @property
    def ringed(self) -> np.ndarray:
        """True for rows with a flag that sets them apart."""
        return np.array([bool(names) for names in self.apart], dtype=bool)


def flag_summary(qa_flags) -> FlagSummary:
    """Split the ``qa_flags`` values of a set of rows into flags that set a row apart
    and flags said once (see :class:`FlagSummary`).

    Examples
    --------
    >>> s = flag_summary(["spin_estimated;e_t_above_1", "spin_estimated", None])
    >>> s.apart, s.shared
    ([['e_t_above_1'], [], []], {'spin_estimated': 2})
    >>> flag_summary(["e_t > 1", "e_t > 1"]).shared  # on every row: said once
    {'e_t > 1': 2}
    """
    names = _flag_names(qa_flags)
    counts: dict[str, int] = {}
    for row in names:
        for name in dict.fromkeys(row):
            counts[name] = counts.get(name, 0) + 1
    everywhere = {name for name, n in counts.items() if n == len(names) > 1}
    shared = {
        name: n
        for name, n in counts.items()
        if name in METHOD_QA_FLAGS or name in everywhere
    }
    apart = [[name for name in row if name not in shared] for row in names]
    return FlagSummary(apart=apart, shared=shared, rows=len(names))


def impact_rows(frame: pd.DataFrame) -> np.ndarray:
    """Rows of an ImpactTable frame that record an impact: a restitution coefficient
    (``e_n`` or ``e_t``) is known, so the body arrived and left there. A reduced
    path's first row (the release) and last row (where the body stopped) are points
    of the path, not impacts; ``fieldkit reduce`` counts impacts the same way. Every
    row counts when the table has neither column.

    Examples
    --------
    >>> f = pd.DataFrame({"e_n": [np.nan, 0.3, 0.4, np.nan], "e_t": np.nan})
    >>> impact_rows(f).tolist()
    [False, True, True, False]
    """
    known = np.zeros(len(frame), bool)
    columns = [c for c in ("e_n", "e_t") if c in frame.columns]
    if not columns:
        return ~known
    for c in columns:
        known |= np.isfinite(pd.to_numeric(frame[c], errors="coerce").to_numpy(float))
    return known


def impact_count_text(frame: pd.DataFrame) -> str:
    """``48 impacts (plus the release point and the stop point)``: the impacts
    (:func:`impact_rows`) and, apart, the other rows -- a release point (no impact
    velocity), a stop point (no restitution velocity), the ends of a flight the
    reduction could not solve (``flight_unsolved``), other rows.

    Examples
    --------
    >>> nan = np.nan
    >>> f = pd.DataFrame({"e_n": [nan, 0.3, nan], "e_t": nan,
    ...                   "vi_x_mps": [nan, 1.0, 1.0], "vf_x_mps": [1.0, 1.0, nan]})
    >>> impact_count_text(f)
    '1 impact (plus the release point and the stop point)'
    """
    impacts = impact_rows(frame)
    n = int(impacts.sum())
    text = f"{n:,} impact{'' if n == 1 else 's'}"
    others = ~impacts
    arrives, leaves = flight_sides(frame)
    arrives_unsolved, leaves_unsolved = unsolved_sides(frame)
    unsolved = others & (arrives_unsolved | leaves_unsolved)
    others = others & ~unsolved
    release = others & ~arrives
    stop = others & arrives & ~leaves
    rest = others & arrives & leaves
    parts = []
    for mask, one, many in (
        (release, "the release point", "release points"),
        (stop, "the stop point", "stop points"),
        (
            unsolved,
            "one end of an unsolved flight",
            "ends of unsolved flights",
        ),
        (rest, "one other row without an impact", "other rows without an impact"),
    ):
        k = int(mask.sum())
        if k:
            parts.append(one if k == 1 else f"{k:,} {many}")
    if parts:
        text += f" (plus {' and '.join(parts)})"
    return text


def qa_flagged(frame: pd.DataFrame) -> np.ndarray:
    """Rows with a quality flag that sets them apart (:func:`flag_summary`); all
    False when the table has no ``qa_flags`` column.

    Examples
    --------
    >>> qa_flagged(pd.DataFrame({"qa_flags": ["", "e_t > 1", None, " ; "]})).tolist()
    [False, True, False, False]
    >>> qa_flagged(pd.DataFrame({"qa_flags": ["spin_estimated", "spin_estimated"]}))
    array([False, False])
    """
    if "qa_flags" not in frame.columns:
        return np.zeros(len(frame), bool)
    return flag_summary(frame["qa_flags"].tolist()).ringed


def qa_column(frame: pd.DataFrame) -> list | None:
    """The ``qa_flags`` values of ``frame`` for :func:`mark_flagged`; None without
    the column."""
    return frame["qa_flags"].tolist() if "qa_flags" in frame.columns else None


def flag_words(name: str) -> str:
    """A flag in words for a legend (:data:`fieldkit.impact_table.QA_FLAG_LABELS`;
    a producer's own flag as written)."""
    return QA_FLAG_LABELS.get(name, name)


def mark_flagged(ax: Axes, x, y, qa_flags, where=None) -> None:
    """Open red rings around the rows whose quality flags set them apart, with one
    legend entry naming those flags and how many rows carry each; flags every row
    shares (and method flags, :data:`fieldkit.impact_table.METHOD_QA_FLAGS`) get one
    legend line instead of a ring on every point.

    Parameters
    ----------
    ax
        Axes to draw on.
    x, y
        Position of each row's mark (data coordinates).
    qa_flags
        Each row's ``qa_flags`` value (``;``-separated; None / NaN = none), or None
        when the table has no such column (nothing drawn).
    where
        Rows that may be ringed (e.g. those drawn at all); default every row with
        finite ``x`` and ``y``.
    """
    if qa_flags is None:
        return
    summary = flag_summary(list(qa_flags))
    x, y = np.asarray(x, float), np.asarray(y, float)
    drawn = np.isfinite(x) & np.isfinite(y)
    if where is not None:
        drawn &= np.asarray(where, bool)
    ringed = summary.ringed & drawn
    if ringed.any():
        counts: dict[str, int] = {}
        for names, on in zip(summary.apart, ringed, strict=True):
            for name in names if on else ():
                counts[name] = counts.get(name, 0) + 1
        listed = ", ".join(f"{flag_words(k)} ({v})" for k, v in counts.items())
        ax.scatter(
            x[ringed],
            y[ringed],
            s=150,
            facecolors="none",
            edgecolors=QA_COLOUR,
            linewidths=1.5,
            zorder=7,
            label=textwrap.fill(f"{QA_LABEL} on {int(ringed.sum())}: {listed}", 48),
        )
    if summary.shared:
        listed = ", ".join(
            f"{flag_words(k)} ({v} of {summary.rows})"
            for k, v in summary.shared.items()
        )
        ax.plot(
            [],
            [],
            " ",
            label=textwrap.fill(f"{SHARED_LABEL}: {listed}", 48),
            gid="qa-shared",
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
    corner of the axes freest of the points ``(x, y)`` (what the axes draw), on a
    white box so that what the axes show beneath it (an image: a scale cross, a
    texture) does not hide it."""
    speed = nice_speed(largest_mps)
    corner = free_corner(ax, x, y)
    w, h = KEY_BOX
    right, upper = corner.endswith("right"), corner.startswith("upper")
    ax.add_patch(
        Rectangle(
            (1 - w if right else 0.0, 1 - h if upper else 0.0),
            w,
            h,
            transform=ax.transAxes,
            facecolor="white",
            edgecolor="0.6",
            linewidth=0.5,
            zorder=9,
            gid="velocity-key-box",
        )
    )
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
        zorder=10,
    )
