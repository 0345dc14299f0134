"""Stations along an alignment: chainage, plan position and the local directions.

A station sits every ``spacing_m`` of chainage (horizontal distance along the
alignment from its first vertex), from 0 to the last whole step; the alignment's
end is a station too when it falls more than a tenth of a step past the last one.
Each station has the unit tangent of the leg it lies on (a vertex belongs to the
leg leaving it) and the unit normal to its left, ``(-t_y, t_x)``. In the 3-D scan a
station stands for the stretch of alignment closer to it than to its neighbours.

Examples
--------
>>> s = stations_along(np.array([[0.0, 0.0], [25.0, 0.0]]), 10.0)
>>> s.chainage_m.tolist(), s.normal_xy[0].tolist()
([0.0, 10.0, 20.0, 25.0], [-0.0, 1.0])
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io.dem import INSIDE, DemGrid

#: Most stations one scan makes (a spacing typed in mm instead of m).
MAX_STATIONS = 100_000


@dataclass(frozen=True)
class Stations:
    """Stations along an alignment (module docstring).

    Attributes
    ----------
    chainage_m
        ``(n,)`` chainage of each station [m], increasing.
    xy_m
        ``(n, 2)`` plan position [m].
    tangent_xy, normal_xy
        ``(n, 2)`` unit tangent (direction of rising chainage) and left normal.
    edges_m
        ``(n + 1,)`` chainage where each station's stretch begins and ends [m]
        (midway between stations; 0 and the alignment's length at the ends).
    alignment_xy
        ``(k, 2)`` the alignment's vertices [m].
    """

    chainage_m: np.ndarray
    xy_m: np.ndarray
    tangent_xy: np.ndarray
    normal_xy: np.ndarray
    edges_m: np.ndarray
    alignment_xy: np.ndarray

    def __len__(self) -> int:
        return int(self.chainage_m.size)

    @property
    def length_m(self) -> float:
        """The alignment's length in plan [m]."""
        return float(self.edges_m[-1])


def vertex_chainage(xy: np.ndarray) -> np.ndarray:
    """Chainage of each vertex of a polyline [m]."""
    return np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xy, axis=0).T))])


def stations_along(alignment_xy: np.ndarray, spacing_m: float) -> Stations:
    """The stations every ``spacing_m`` along the alignment (module docstring).

    Raises
    ------
    ArgumentError
        ``spacing_m`` not > 0, or more than :data:`MAX_STATIONS` stations.
    """
    xy = np.asarray(alignment_xy, float).reshape(-1, 2)
    if not (isinstance(spacing_m, int | float) and math.isfinite(spacing_m)
            and spacing_m > 0):  # fmt: skip
        raise ArgumentError(
            f"spacing_m must be a distance > 0 m (got {spacing_m})", source="spacing_m"
        )
    if len(xy) < 2:
        raise ArgumentError(
            f"alignment_xy needs at least 2 vertices (got {len(xy)})",
            source="alignment_xy",
        )
    at = vertex_chainage(xy)
    if (np.diff(at) <= 0).any():
        i = int(np.flatnonzero(np.diff(at) <= 0)[0])
        raise ArgumentError(
            f"alignment_xy vertices {i + 1} and {i + 2} are the same point",
            source="alignment_xy",
        )
    length = float(at[-1])
    count = math.floor(length / spacing_m + 1e-9) + 1
    if count > MAX_STATIONS:
        raise ArgumentError(
            f"spacing_m {spacing_m:g} m makes {count:,} stations on {length:.0f} m of "
            f"alignment (at most {MAX_STATIONS:,})",
            source="spacing_m",
        )
    chainage = spacing_m * np.arange(count)
    if length - chainage[-1] > 0.1 * spacing_m:
        chainage = np.append(chainage, length)
    leg = np.clip(np.searchsorted(at, chainage, side="right") - 1, 0, len(xy) - 2)
    t = (chainage - at[leg]) / (at[leg + 1] - at[leg])
    points = xy[leg] + t[:, None] * (xy[leg + 1] - xy[leg])
    tangent = (xy[leg + 1] - xy[leg]) / (at[leg + 1] - at[leg])[:, None]
    normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])
    edges = np.concatenate([[0.0], 0.5 * (chainage[1:] + chainage[:-1]), [length]])
    return Stations(chainage, points, tangent, normal, edges, xy)


def check_on_dem(stations: Stations, grid: DemGrid) -> None:
    """Refuse an alignment that leaves the DEM or crosses nodata, naming the first
    point (sampled every half cell) and its chainage.

    Raises
    ------
    InputFileError
        Naming the DEM file, the point and its chainage.
    """
    xy = stations.alignment_xy
    at = vertex_chainage(xy)
    step = 0.5 * grid.cellsize_m
    s = np.union1d(np.arange(0.0, at[-1], step), at)
    x = np.interp(s, at, xy[:, 0])
    y = np.interp(s, at, xy[:, 1])
    _, _, _, status = grid.sample(x, y)
    bad = np.flatnonzero(status != INSIDE)
    if bad.size:
        i = int(bad[0])
        raise InputFileError(
            f"the alignment at chainage {s[i]:.1f} m, (x, y) = ({x[i]:.2f}, "
            f"{y[i]:.2f}), is not on the DEM: "
            + grid.problem_at(float(x[i]), float(y[i]), int(status[i])),
            source=grid.source,
        )


def chainage_of(stations: Stations, x_m: np.ndarray, y_m: np.ndarray) -> np.ndarray:
    """Chainage of plan points lying on (or next to) the alignment: that of the
    nearest point on the polyline [m]."""
    xy = stations.alignment_xy
    at = vertex_chainage(xy)
    p = np.column_stack([np.asarray(x_m, float), np.asarray(y_m, float)])
    best = np.full(len(p), np.inf)
    out = np.zeros(len(p))
    for k in range(len(xy) - 1):
        a, d = xy[k], xy[k + 1] - xy[k]
        length2 = float(d @ d)
        t = np.clip(((p - a) @ d) / length2, 0.0, 1.0)
        dist = np.hypot(*(a + t[:, None] * d - p).T)
        closer = dist < best
        best = np.where(closer, dist, best)
        out = np.where(closer, at[k] + t * math.sqrt(length2), out)
    return out
