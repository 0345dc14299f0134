"""The area a survey could see, applied to forecasts as it was to the observations.

An observed 'deposit' is often the **last tracked position**, not a rest position:
Tschamut 2014's deposits are the last sample of the laser-scan tracks
(``tests/data/tschamut2014/observed_deposition.csv``, column ``source``), and a block
that leaves the scanned area is last seen where it left. Six of the 80 deposits
lie within 1.5 m of one line (y = 133.0-134.5 m), the southern edge of the ground
points the terrain proxy was built from -- rocks seen leaving, not rocks at rest.

A forecast scored against such observations has to be observed the same way:
every simulated rock is **censored at its first exit from the tracked extent** --
its deposit is the exit point if it leaves, its rest point otherwise
(the observation operator). Without it a rock that ran on past the edge is
scored where it stopped, tens of metres beyond anything the survey could record,
and a model is penalised for physics the data cannot show.

* 3-D model: the DEM clipped to the extent (:func:`clip_model`); a rock leaving
  it ends as 'left the DEM' at its exit point, which the plan fit already scores
  (:mod:`fieldkit.fit.plan_fit`). The clipped surface spans the centres inside the
  extent, so it ends up to half a cell inside it: :func:`clip_model` returns that
  rectangle, and the other forecasts are censored on it, so all are observed alike.
  A rolling rock's exit point is its last position on the surface, within one slide
  step (:data:`fieldkit.model.kernel3d.SLIDE_STEP_CELLS` of a cell) of the edge; a
  flying rock's is where its path leaves it.
* A path in plan (a 2-D model's section, a climatology's straight
  release-to-deposit segment): :func:`censor_chainage`, :func:`censor_segments`.

The extent is an assumption about the survey; a report using it says so and
shows the scores without it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from fieldkit.errors import ArgumentError
from fieldkit.fit.plan_scores import plan_climatology
from fieldkit.model.model3d import Model3D


@dataclass(frozen=True)
class Extent:
    """An axis-aligned rectangle in plan [m]: ``x_min < x_max``, ``y_min < y_max``.

    Examples
    --------
    >>> Extent(0.0, 0.0, 10.0, 5.0).contains(np.array([[1.0, 1.0], [11.0, 1.0]]))
    array([ True, False])
    """

    x_min: float
    y_min: float
    x_max: float
    y_max: float

    def __post_init__(self) -> None:
        v = (self.x_min, self.y_min, self.x_max, self.y_max)
        if not all(math.isfinite(float(a)) for a in v):
            raise ArgumentError(f"extent {v}: not finite", source="extent")
        if not (self.x_min < self.x_max and self.y_min < self.y_max):
            raise ArgumentError(
                f"extent x {self.x_min:g}..{self.x_max:g}, y {self.y_min:g}.."
                f"{self.y_max:g}: needs x_min < x_max and y_min < y_max",
                source="extent",
            )

    def contains(self, xy: np.ndarray) -> np.ndarray:
        """Whether each point (..., 2) lies inside or on the edge."""
        p = np.asarray(xy, float)
        return (
            (p[..., 0] >= self.x_min)
            & (p[..., 0] <= self.x_max)
            & (p[..., 1] >= self.y_min)
            & (p[..., 1] <= self.y_max)
        )

    def describe(self) -> str:
        return f"x {self.x_min:g}..{self.x_max:g} m, y {self.y_min:g}..{self.y_max:g} m"


def parse_extent(text: str, source: str = "extent") -> Extent:
    """``"x_min,y_min,x_max,y_max"`` [m] -> :class:`Extent`.

    Examples
    --------
    >>> parse_extent("10,130,135,270").describe()
    'x 10..135 m, y 130..270 m'
    """
    parts = [p.strip() for p in str(text).split(",")]
    try:
        values = [float(p) for p in parts]
    except ValueError:
        values = []
    if len(values) != 4:
        raise ArgumentError(
            f"{text!r}: give four numbers x_min,y_min,x_max,y_max in metres",
            source=source,
        )
    try:
        return Extent(*values)
    except ArgumentError as err:
        raise ArgumentError(err.message, source=source) from None


def clip_model(model: Model3D, extent: Extent) -> tuple[Model3D, Extent]:
    """``model`` with its DEM clipped to ``extent`` (cells whose centre lies outside
    become nodata), and the rectangle its surface then spans -- the extent every
    forecast is censored on.

    Raises
    ------
    ArgumentError
        No cell centre lies inside the extent.
    """
    t = model.terrain
    ny, nx = t.shape
    xc = t.x0_m + t.cell_m * (np.arange(nx) + 0.5)
    yc = t.y0_m + t.cell_m * (np.arange(ny) + 0.5)
    inside_x = np.count_nonzero((xc >= extent.x_min) & (xc <= extent.x_max))
    inside_y = np.count_nonzero((yc >= extent.y_min) & (yc <= extent.y_max))
    if inside_x < 2 or inside_y < 2:
        raise ArgumentError(
            f"extent {extent.describe()} holds fewer than 2 x 2 of the DEM's cell "
            "centres",
            source="extent",
        )
    clipped = t.clipped(extent.x_min, extent.y_min, extent.x_max, extent.y_max)
    return replace(model, terrain=clipped), Extent(*clipped.surface_extent())


def _exit_fraction(p0: np.ndarray, p1: np.ndarray, extent: Extent) -> np.ndarray:
    """Per segment p0 -> p1 (both (m, 2), p0 inside), the fraction t in [0, 1] at
    which it first leaves the extent; ``inf`` where it stays inside."""
    d = p1 - p0
    t = np.full(len(p0), np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        for axis, lo, hi in ((0, extent.x_min, extent.x_max),
                             (1, extent.y_min, extent.y_max)):  # fmt: skip
            below = p1[:, axis] < lo
            above = p1[:, axis] > hi
            t = np.where(below, np.minimum(t, (lo - p0[:, axis]) / d[:, axis]), t)
            t = np.where(above, np.minimum(t, (hi - p0[:, axis]) / d[:, axis]), t)
    return np.clip(t, 0.0, np.inf)


def censor_segments(
    start_xy: np.ndarray, end_xy: np.ndarray, extent: Extent
) -> tuple[np.ndarray, np.ndarray]:
    """Straight paths from ``start_xy`` (2,) to each of ``end_xy`` (m, 2), each
    cut at its first exit from the extent: the censored end points and which
    were cut.

    Raises
    ------
    ArgumentError
        ``start_xy`` lies outside the extent.

    Examples
    --------
    >>> pts, cut = censor_segments(np.array([5.0, 5.0]),
    ...                            np.array([[5.0, 8.0], [5.0, -5.0]]),
    ...                            Extent(0.0, 0.0, 10.0, 10.0))
    >>> pts.tolist(), cut.tolist()
    ([[5.0, 8.0], [5.0, 0.0]], [False, True])
    """
    s = np.asarray(start_xy, float)[:2]
    e = np.asarray(end_xy, float)[:, :2]
    if not extent.contains(s):
        raise ArgumentError(
            f"start ({s[0]:g}, {s[1]:g}) lies outside the extent {extent.describe()}",
            source="extent",
        )
    p0 = np.broadcast_to(s, e.shape)
    t = _exit_fraction(p0, e, extent)
    cut = np.isfinite(t)
    out = e.copy()
    out[cut] = p0[cut] + t[cut, None] * (e[cut] - p0[cut])
    return out, cut


def exit_chainage(plan_x_m: np.ndarray, plan_y_m: np.ndarray,
                  extent: Extent) -> float:  # fmt: skip
    """The chainage (plan distance from the first vertex) at which a polyline
    first leaves the extent; ``inf`` if it stays inside.

    Raises
    ------
    ArgumentError
        The first vertex lies outside the extent.

    Examples
    --------
    >>> exit_chainage(np.array([1.0, 4.0, 4.0]), np.array([1.0, 1.0, -9.0]),
    ...               Extent(0.0, 0.0, 10.0, 10.0))
    4.0
    """
    p = np.column_stack([np.asarray(plan_x_m, float), np.asarray(plan_y_m, float)])
    if not extent.contains(p[0]):
        raise ArgumentError(
            f"the path starts at ({p[0, 0]:g}, {p[0, 1]:g}), outside the extent "
            f"{extent.describe()}",
            source="extent",
        )
    seg = np.hypot(*np.diff(p, axis=0).T)
    t = _exit_fraction(p[:-1], p[1:], extent)
    # a segment's exit counts only if its start is inside (the first one whose
    # end is outside is the first exit: every earlier end is inside)
    first = np.flatnonzero(np.isfinite(t))
    if first.size == 0:
        return math.inf
    i = int(first[0])
    return float(np.sum(seg[:i]) + t[i] * seg[i])


def censor_chainage(
    chainage_m: np.ndarray, exit_at_m: float
) -> tuple[np.ndarray, np.ndarray]:
    """Stops along a path at ``chainage_m`` censored at the path's exit chainage:
    ``min(c, exit)`` and which were cut (a stop upslope of the start, c < 0, is
    kept)."""
    c = np.asarray(chainage_m, float)
    cut = c > exit_at_m
    return np.where(cut, exit_at_m, c), cut


def censor_straight_ensembles(
    release_xy: np.ndarray, ensembles: np.ndarray, extent: Extent
) -> tuple[list[np.ndarray], float]:
    """Deposit ensembles (runs, m, 2) reached along straight lines from each run's
    release (a climatology's release-to-deposit vectors), each member cut at its
    first exit from the extent; and the share of members cut."""
    out, cut, total = [], 0, 0
    for r, e in zip(np.asarray(release_xy, float), ensembles, strict=True):
        c, was_cut = censor_segments(r, e, extent)
        out.append(c)
        cut += int(was_cut.sum())
        total += was_cut.size
    return out, (cut / total if total else math.nan)


def censored_climatology(
    calibration_release_xy: np.ndarray,
    calibration_deposit_xy: np.ndarray,
    release_xy: np.ndarray,
    extent: Extent | None,
) -> tuple[np.ndarray, float]:
    """The climatology in plan (:func:`fieldkit.fit.plan_scores.plan_climatology`),
    each member cut at its first exit from ``extent`` along its straight vector
    (:func:`censor_straight_ensembles`; None: not cut), and the share of members
    cut (0.0 without an extent).

    Returns
    -------
    tuple
        (runs, n, 2) deposit ensembles and the share cut.
    """
    ens = plan_climatology(calibration_release_xy, calibration_deposit_xy, release_xy)
    if extent is None:
        return ens, 0.0
    cut, share = censor_straight_ensembles(release_xy, ens, extent)
    return np.stack(cut), share
