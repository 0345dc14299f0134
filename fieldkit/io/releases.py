"""Release files: where rocks start on a DEM -- points, or polygons of cells.

One CSV (any separator :mod:`fieldkit.io.csv_table` reads), plan coordinates in
the DEM's coordinate system:

* ``x``, ``y`` (required, a length unit in the name: ``x_m, y_m``; the Tschamut
  ``release_points.csv`` has them, other columns are ignored);
* ``polygon`` (optional; also ``polygon_id``): rows with a polygon name are the
  vertices, in order, of that polygon (at least 3, not repeating the first at the
  end -- a repeated closing vertex is dropped); the cells whose centre lies inside
  it are release cells (even-odd rule, :func:`cells_inside`). Rows with the cell
  empty, or a file without the column, are release points: the cell holding each
  point is a release cell;
* ``count`` (optional; also ``rocks``): how many rocks start at a release point, a
  whole number >= 1 (empty or no column: 1).

Rows are file line numbers (the header is row 1), so every message names the row
a user can find in a spreadsheet.
"""

from __future__ import annotations

from dataclasses import dataclass
from os import PathLike

import numpy as np

from fieldkit.errors import InputFileError
from fieldkit.io.csv_table import plan_columns, read_csv_table

POLYGON_ALIASES = ("polygon", "polygon_id")
COUNT_ALIASES = ("count", "rocks")
#: Most rocks one release point may start (a count beyond is a typing error).
MAX_POINT_COUNT = 10_000_000


@dataclass(frozen=True)
class ReleasePolygon:
    """A release polygon: its name, vertices ``(n, 2)`` [m] in order, file rows."""

    name: str
    xy_m: np.ndarray
    rows: tuple[int, ...]

    def rows_text(self) -> str:
        """``"rows 2-5"``: where the polygon is in its file."""
        return f"rows {self.rows[0]}-{self.rows[-1]}"


@dataclass(frozen=True)
class Releases:
    """The release points and polygons of a release file.

    Attributes
    ----------
    points_m
        ``(n, 2)`` plan x, y [m] of the release points.
    point_rows
        The file row of each point.
    polygons
        The release polygons, in file order.
    source
        The file.
    point_counts
        ``(n,)`` rocks started at each point (the ``count`` column; 1 without it).
    """

    points_m: np.ndarray
    point_rows: tuple[int, ...]
    polygons: tuple[ReleasePolygon, ...]
    source: str
    point_counts: np.ndarray | None = None

    def summary(self) -> str:
        """``"80 points"``, ``"1 polygon (5 vertices)"``, or both."""
        parts = []
        n = len(self.point_rows)
        if n:
            parts.append(f"{n} point" + ("" if n == 1 else "s"))
        for p in self.polygons:
            parts.append(f"polygon {p.name} ({len(p.xy_m)} vertices)")
        return ", ".join(parts)


def read_releases(path: str | PathLike[str]) -> Releases:
    """Read a release file (module docstring).

    Raises
    ------
    InputFileError
        No ``x``/``y`` column, a length without a unit, a value that is not a
        number, or a polygon of fewer than 3 distinct vertices (naming its rows).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "r.csv"
    >>> _ = f.write_text("x_m,y_m,polygon\\n0,0,A\\n10,0,A\\n10,10,A\\n5,5,\\n")
    >>> r = read_releases(f)
    >>> r.points_m.tolist(), r.point_rows, r.polygons[0].rows, r.summary()
    ([[5.0, 5.0]], (5,), (2, 3, 4), '1 point, polygon A (3 vertices)')
    """
    table = read_csv_table(path)
    found, factors = plan_columns(table, "a release file")
    polygon = table.find(POLYGON_ALIASES, "polygon")
    count = table.find(COUNT_ALIASES, "count")
    points, point_rows, counts = [], [], []
    vertices: dict[str, list[tuple[float, float, int]]] = {}
    for number, row in table.rows:
        x = table.number(number, row, found["x"]) * factors["x"]
        y = table.number(number, row, found["y"]) * factors["y"]
        name = table.cell(row, polygon) if polygon is not None else ""
        if name:
            vertices.setdefault(name, []).append((x, y, number))
        else:
            points.append((x, y))
            point_rows.append(number)
            counts.append(_count(table, number, row, count))
    polygons = []
    for name, vs in vertices.items():
        rows = tuple(v[2] for v in vs)
        xy = np.array([(v[0], v[1]) for v in vs], float)
        if len(xy) > 3 and np.array_equal(xy[0], xy[-1]):
            xy = xy[:-1]  # the closing vertex written again
        if len(np.unique(xy, axis=0)) < 3:
            raise InputFileError(
                f"polygon {name} has {len(np.unique(xy, axis=0))} distinct vertices; "
                "a release polygon needs at least 3",
                source=table.source,
                where=f"rows {rows[0]}-{rows[-1]}",
            )
        polygons.append(ReleasePolygon(name, xy, rows))
    return Releases(
        np.array(points, float).reshape(-1, 2),
        tuple(point_rows),
        tuple(polygons),
        table.source,
        np.array(counts, np.int64),
    )


def _count(table, number: int, row: tuple[str, ...], column) -> int:
    """The ``count`` of a release point: a whole number in [1, 10 million]."""
    if column is None or table.cell(row, column) == "":
        return 1
    value = table.number(number, row, column)
    if value != int(value) or not 1 <= value <= MAX_POINT_COUNT:
        raise InputFileError(
            f"column '{column.header.strip()}': a count is a whole number from 1 to "
            f"{MAX_POINT_COUNT:,} (got {value:g})",
            source=table.source,
            where=f"row {number}",
        )
    return int(value)


def cells_inside(
    vertices_m: np.ndarray, x_m: np.ndarray, y_m: np.ndarray
) -> np.ndarray:
    """Which points ``(x_m, y_m)`` lie inside the polygon (even-odd rule).

    A point exactly on an edge counts by the half-open rule of the crossing test
    (the lower and left edges in, the upper and right out, for an axis-aligned
    rectangle), so two polygons that share an edge never both claim a cell.

    Examples
    --------
    >>> square = np.array([[0, 0], [10, 0], [10, 10], [0, 10]], float)
    >>> cells_inside(square, np.array([5, 15, 0, 10]), np.array([5, 5, 5, 5])).tolist()
    [True, False, True, False]
    """
    x = np.asarray(x_m, float)
    y = np.asarray(y_m, float)
    inside = np.zeros(np.broadcast(x, y).shape, bool)
    xs, ys = vertices_m[:, 0], vertices_m[:, 1]
    for i in range(len(xs)):
        x1, y1 = xs[i - 1], ys[i - 1]
        x2, y2 = xs[i], ys[i]
        if y1 == y2:
            continue
        spans = (y1 > y) != (y2 > y)
        x_cross = x1 + (y - y1) * (x2 - x1) / (y2 - y1)
        inside ^= spans & (x < x_cross)
    return inside
