"""The ground of a 3-D model: a DEM on a regular grid, bilinear between cell centres.

:class:`Terrain` holds the grid as the 3-D kernel reads it: ``z[row, col]`` with row 0
the SOUTHERN row (``y`` grows with the row index; an ESRI ASCII grid, whose first row
is the northern one, is flipped when read), ``x0_m, y0_m`` the lower-left corner of
the lower-left cell and ``cell_m`` the cell size. The value of a cell belongs to its
centre ``(x0_m + (col + 1/2) cell_m, y0_m + (row + 1/2) cell_m)``; the surface is the
bilinear interpolation between the four centres around a point, so it is defined
from the first to the last centre (half a cell inside the grid's outer edge). NaN is
nodata: a point whose four centres include one is off the surface.

:func:`surface_at` (compiled) gives the height and its gradient at a point,
:func:`height` and :func:`normal` the height and the upward unit normal
``(-dz/dx, -dz/dy, 1) / |...|``.
"""

from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import dataclass

import numpy as np
from numba import njit

from fieldkit.errors import ArgumentError

#: The grid as the compiled code takes it: ``z`` (ny, nx) float64, row 0 south;
#: ``xc0``, ``yc0`` the centre of cell (0, 0); ``cell`` the cell size [m].
Grid = namedtuple("Grid", ("z", "xc0", "yc0", "cell"))


@dataclass(frozen=True)
class Terrain:
    """A DEM (see the module docstring).

    Parameters
    ----------
    x0_m, y0_m
        Lower-left corner of the lower-left cell [m].
    cell_m
        Cell size [m], > 0.
    z
        Elevations [m], float64 (ny, nx), row 0 = south; NaN = nodata; at least 2 x 2.
    crs
        Coordinate reference system (WKT) or None.

    Examples
    --------
    >>> t = Terrain(0.0, 0.0, 1.0, np.array([[0.0, 1.0], [2.0, 3.0]]))
    >>> t.height(1.0, 1.0)  # the mean of the four centres
    1.5
    >>> [round(c, 4) for c in t.normal(1.0, 1.0)]
    [-0.4082, -0.8165, 0.4082]
    """

    x0_m: float
    y0_m: float
    cell_m: float
    z: np.ndarray
    crs: str | None = None

    def __post_init__(self) -> None:
        z = np.ascontiguousarray(self.z, dtype=np.float64)
        if z.ndim != 2 or z.shape[0] < 2 or z.shape[1] < 2:
            raise ArgumentError(
                f"z must be a 2-D grid of at least 2 x 2 cells (got shape {z.shape})",
                source="z",
            )
        if not (math.isfinite(self.cell_m) and self.cell_m > 0):
            raise ArgumentError(
                f"cell_m must be a finite size > 0 m (got {self.cell_m})",
                source="cell_m",
            )
        if not (math.isfinite(self.x0_m) and math.isfinite(self.y0_m)):
            raise ArgumentError("x0_m and y0_m must be finite", source="x0_m")
        if np.isinf(z).any():
            raise ArgumentError("z holds an infinite elevation", source="z")
        object.__setattr__(self, "z", z)

    @property
    def shape(self) -> tuple[int, int]:
        """``(ny, nx)``: rows (south to north) and columns (west to east)."""
        return self.z.shape

    def grid(self) -> Grid:
        """The grid as the compiled code takes it (:data:`Grid`)."""
        half = 0.5 * self.cell_m
        return Grid(
            self.z, float(self.x0_m + half), float(self.y0_m + half), float(self.cell_m)
        )

    def cell_index(self, x_m, y_m) -> tuple[np.ndarray, np.ndarray]:
        """``(row, col)`` of the cell holding each point (clipped to the grid)."""
        ny, nx = self.shape
        col = np.floor((np.asarray(x_m, float) - self.x0_m) / self.cell_m)
        row = np.floor((np.asarray(y_m, float) - self.y0_m) / self.cell_m)
        return (
            np.clip(row, 0, ny - 1).astype(np.int64),
            np.clip(col, 0, nx - 1).astype(np.int64),
        )

    def height(self, x_m: float, y_m: float) -> float:
        """Surface height at ``(x_m, y_m)``; NaN off the surface."""
        return float(height(self.grid(), float(x_m), float(y_m)))

    def heights(self, x_m, y_m) -> np.ndarray:
        """Surface heights at arrays of points; NaN off the surface."""
        x = np.asarray(x_m, float)
        y = np.asarray(y_m, float)
        bx, by = np.broadcast_arrays(x, y)
        out = np.empty(bx.size)
        _heights(self.grid(), np.ascontiguousarray(bx).reshape(-1),
                 np.ascontiguousarray(by).reshape(-1), out)  # fmt: skip
        return out.reshape(bx.shape)

    def clipped(self, x_min: float, y_min: float, x_max: float,
                y_max: float) -> Terrain:  # fmt: skip
        """The DEM with every cell whose centre lies outside the rectangle set to
        nodata: a rock ends where it leaves what is kept (the kernel's 'left the
        DEM'). The surface of the result spans the kept centres, so it ends up to
        half a cell inside the rectangle (:meth:`surface_extent`).

        Examples
        --------
        >>> t = Terrain(0.0, 0.0, 1.0, np.zeros((4, 4))).clipped(0.0, 0.0, 2.9, 9.0)
        >>> t.surface_extent()
        (0.5, 0.5, 2.5, 3.5)
        """
        ny, nx = self.shape
        xc = self.x0_m + self.cell_m * (np.arange(nx) + 0.5)
        yc = self.y0_m + self.cell_m * (np.arange(ny) + 0.5)
        out = ~((yc >= y_min) & (yc <= y_max))[:, None] | ~(
            (xc >= x_min) & (xc <= x_max)
        )[None, :]
        z = self.z.copy()
        z[out] = np.nan
        return Terrain(self.x0_m, self.y0_m, self.cell_m, z, self.crs)

    def surface_extent(self) -> tuple[float, float, float, float]:
        """``(x_min, y_min, x_max, y_max)`` of the centres holding data: the
        rectangle the surface spans (nodata holes inside it are not excluded)."""
        rows, cols = np.nonzero(np.isfinite(self.z))
        if rows.size == 0:
            raise ArgumentError("the DEM holds no data", source="z")
        half = 0.5 * self.cell_m
        return (
            float(self.x0_m + half + self.cell_m * cols.min()),
            float(self.y0_m + half + self.cell_m * rows.min()),
            float(self.x0_m + half + self.cell_m * cols.max()),
            float(self.y0_m + half + self.cell_m * rows.max()),
        )

    def normal(self, x_m: float, y_m: float) -> tuple[float, float, float]:
        """Upward unit normal at ``(x_m, y_m)``; NaNs off the surface."""
        nx, ny, nz = normal(self.grid(), float(x_m), float(y_m))
        return float(nx), float(ny), float(nz)


@njit(cache=True)
def surface_at(g, x, y):
    """``(h, dh/dx, dh/dy)`` of the bilinear surface at ``(x, y)``.

    ``h`` is NaN off the surface (outside the centres or beside nodata). On a
    patch edge the patch to the south-west of it is used (lower index), except at
    the last centre row/column.
    """
    ny, nx = g.z.shape
    fx = (x - g.xc0) / g.cell
    fy = (y - g.yc0) / g.cell
    if not (0.0 <= fx <= nx - 1.0 and 0.0 <= fy <= ny - 1.0):
        return math.nan, 0.0, 0.0
    i = min(int(fx), nx - 2)
    j = min(int(fy), ny - 2)
    u = fx - i
    v = fy - j
    z00 = g.z[j, i]
    z10 = g.z[j, i + 1]
    z01 = g.z[j + 1, i]
    z11 = g.z[j + 1, i + 1]
    h = z00 * (1 - u) * (1 - v) + z10 * u * (1 - v) + z01 * (1 - u) * v + z11 * u * v
    dhdx = ((z10 - z00) * (1.0 - v) + (z11 - z01) * v) / g.cell
    dhdy = ((z01 - z00) * (1.0 - u) + (z11 - z10) * u) / g.cell
    return h, dhdx, dhdy


@njit(cache=True)
def height(g, x, y):
    """Surface height at ``(x, y)``; NaN off the surface."""
    return surface_at(g, x, y)[0]


@njit(cache=True)
def normal(g, x, y):
    """Upward unit normal ``(nx, ny, nz)`` at ``(x, y)``; NaNs off the surface."""
    h, gx, gy = surface_at(g, x, y)
    if h != h:
        return math.nan, math.nan, math.nan
    inv = 1.0 / math.sqrt(gx * gx + gy * gy + 1.0)
    return -gx * inv, -gy * inv, inv


@njit(cache=True)
def _heights(g, x, y, out):
    for k in range(out.size):
        out[k] = surface_at(g, x[k], y[k])[0]
