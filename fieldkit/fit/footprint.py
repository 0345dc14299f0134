"""What a passing-count raster says about one run, in plan.

Some simulators write no deposits, only rasters: r.stone's ``counter`` holds how
many trajectories passed through each cell (:mod:`fieldkit.export.rstone3d`).
From such a raster, with the run's release point and its observed deposit, this
module reads what can be compared honestly with the observation and, computed the
same way from fieldkit's own ``passing_count``
(:func:`fieldkit.model.results3d.rasters`), with another model:

* ``reach_m``: the plan distance from the release point to the centre of the
  farthest cell any trajectory passed (a maximum runout of the ensemble, good to
  about a cell; it grows with the number of trajectories, so compare equal
  ensembles);
* ``passage_mean_m``: the count-weighted mean distance of the passed cells from
  the release (where the ensemble's trajectories spend their cells);
* ``deposit_passed``: whether a trajectory passed the observed deposit's cell;
* ``miss_m``: 0 when it did, else the plan distance from the observed deposit to
  the nearest passed cell's centre;
* ``observed_m``: the observed release-to-deposit distance, for ``reach_m``.

A raster holds no deposit: energy scores and CRPS of deposits are not defined
from it, and nothing here pretends otherwise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fieldkit.errors import ArgumentError


@dataclass(frozen=True)
class Footprint:
    """One run's passing-count raster against its observation (module docstring)."""

    reach_m: float
    passage_mean_m: float
    deposit_passed: bool
    miss_m: float
    observed_m: float


def footprint(
    count: np.ndarray,
    x_m: np.ndarray,
    y_m: np.ndarray,
    release_xy,
    deposit_xy,
) -> Footprint:
    """The :class:`Footprint` of a passing-count raster.

    Parameters
    ----------
    count
        (rows, cols) trajectories through each cell; NaN or 0 = none passed.
    x_m, y_m
        (cols,), (rows,) the cell centres' coordinates (either orientation).
    release_xy, deposit_xy
        The run's release point and observed deposit (x, y) [m].

    Raises
    ------
    ArgumentError
        Shapes that do not match, or no cell passed at all.

    Examples
    --------
    >>> c = np.array([[0, 0, 0, 0], [5, 5, 3, 1]])     # row 1 passed eastwards
    >>> f = footprint(c, np.array([0.0, 5, 10, 15]), np.array([5.0, 0]),
    ...               (0.0, 0.0), (12.0, 0.0))
    >>> f.reach_m, round(f.passage_mean_m, 3), f.deposit_passed, f.miss_m
    (15.0, 5.0, True, 0.0)
    >>> footprint(c, np.array([0.0, 5, 10, 15]), np.array([5.0, 0]),
    ...           (0.0, 0.0), (15.0, 3.0)).miss_m
    3.0
    """
    c = np.nan_to_num(np.asarray(count, float))
    x, y = np.asarray(x_m, float), np.asarray(y_m, float)
    if c.ndim != 2 or c.shape != (y.size, x.size):
        raise ArgumentError(
            f"count {c.shape} does not match {y.size} rows x {x.size} columns",
            source="count",
        )
    passed = c > 0
    if not passed.any():
        raise ArgumentError("no cell was passed", source="count")
    rows, cols = np.nonzero(passed)
    px, py = x[cols], y[rows]
    rx, ry = float(release_xy[0]), float(release_xy[1])
    dx, dy = float(deposit_xy[0]), float(deposit_xy[1])
    distance = np.hypot(px - rx, py - ry)
    weight = c[rows, cols]
    col = int(np.argmin(np.abs(x - dx)))
    row = int(np.argmin(np.abs(y - dy)))
    half_x = abs(x[1] - x[0]) / 2 if x.size > 1 else math.inf
    half_y = abs(y[1] - y[0]) / 2 if y.size > 1 else math.inf
    inside = abs(x[col] - dx) <= half_x and abs(y[row] - dy) <= half_y
    hit = bool(inside and passed[row, col])
    return Footprint(
        reach_m=float(distance.max()),
        passage_mean_m=float(np.sum(weight * distance) / np.sum(weight)),
        deposit_passed=hit,
        miss_m=0.0 if hit else float(np.hypot(px - dx, py - dy).min()),
        observed_m=float(math.hypot(dx - rx, dy - ry)),
    )
