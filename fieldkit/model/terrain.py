"""The ground of a 3-D model: a DEM as a regular grid, row 0 south.

:class:`Terrain` is the contract between the 3-D model file
(:mod:`fieldkit.model.model3d`), the 3-D kernel and the 3-D outputs
(:mod:`fieldkit.model.results3d`): ``x0_m, y0_m`` is the lower-left corner of the
lower-left cell, cells are square (``cell_m``), ``z[row, col]`` is the elevation of
the cell centre ``(x0_m + (col + 0.5) cell_m, y0_m + (row + 0.5) cell_m)``, row 0
the southern row (y increases with the row index), NaN = nodata. The surface is the
bilinear interpolation between cell centres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fieldkit.errors import InputFileError
from fieldkit.io.dem import DemGrid


@dataclass(frozen=True)
class Terrain:
    """A DEM surface (module docstring).

    Attributes
    ----------
    x0_m, y0_m
        Lower-left corner of the lower-left cell [m], in the DEM's CRS.
    cell_m
        Cell size [m] (square cells).
    z
        ``(ny, nx)`` float64 elevations [m] of the cell centres, row 0 south; NaN =
        nodata.
    crs
        The DEM's coordinate reference system (WKT or ``EPSG:...``), or None.
    """

    x0_m: float
    y0_m: float
    cell_m: float
    z: np.ndarray
    crs: str | None = None

    @property
    def shape(self) -> tuple[int, int]:
        """``(ny, nx)``."""
        return self.z.shape  # type: ignore[return-value]

    def centres(self) -> tuple[np.ndarray, np.ndarray]:
        """``(x_m, y_m)``: the column and row centres [m], both increasing."""
        ny, nx = self.shape
        return (
            self.x0_m + self.cell_m * (np.arange(nx) + 0.5),
            self.y0_m + self.cell_m * (np.arange(ny) + 0.5),
        )

    def cell_index(self, x_m: np.ndarray, y_m: np.ndarray) -> tuple[np.ndarray, ...]:
        """``(row, col, inside)`` of the cells holding the points (row 0 south).

        Examples
        --------
        >>> t = Terrain(100.0, 200.0, 5.0, np.zeros((2, 3)))
        >>> [a.tolist() for a in t.cell_index(np.array([101.0, 114.9, 99.0]),
        ...                                   np.array([209.0, 200.0, 201.0]))]
        [[1, 0, 0], [0, 2, -1], [True, True, False]]
        """
        col = np.floor((np.asarray(x_m, float) - self.x0_m) / self.cell_m)
        row = np.floor((np.asarray(y_m, float) - self.y0_m) / self.cell_m)
        ny, nx = self.shape
        inside = (col >= 0) & (col < nx) & (row >= 0) & (row < ny)
        return row.astype(np.int64), col.astype(np.int64), inside

    def ground_m(self, x_m: np.ndarray, y_m: np.ndarray) -> np.ndarray:
        """Bilinear elevation [m] between cell centres; NaN outside the rectangle
        of cell centres or where a nodata cell is used."""
        xc, yc = self.centres()
        x = np.asarray(x_m, float)
        y = np.asarray(y_m, float)
        fx = (x - xc[0]) / self.cell_m
        fy = (y - yc[0]) / self.cell_m
        ny, nx = self.shape
        ok = (fx >= 0) & (fx <= nx - 1) & (fy >= 0) & (fy <= ny - 1)
        i = np.clip(np.floor(fx), 0, max(nx - 2, 0)).astype(np.int64)
        j = np.clip(np.floor(fy), 0, max(ny - 2, 0)).astype(np.int64)
        u = np.where(ok, fx - i, 0.0)
        v = np.where(ok, fy - j, 0.0)
        z = self.z
        out = (
            z[j, i] * (1 - u) * (1 - v)
            + z[j, i + 1] * u * (1 - v)
            + z[j + 1, i] * (1 - u) * v
            + z[j + 1, i + 1] * u * v
        )
        return np.where(ok, out, np.nan)


def terrain_from_dem(grid: DemGrid) -> Terrain:
    """The :class:`Terrain` of a DEM read by :func:`fieldkit.io.dem.read_dem`.

    Raises
    ------
    InputFileError
        The cells are not square (naming the DEM).
    """
    dx, dy = grid.dx_m, grid.dy_m
    if not np.isclose(dx, dy, rtol=1e-9, atol=0.0):
        raise InputFileError(
            f"cells are {dx:g} x {dy:g} m; the 3-D model needs square cells "
            "(resample it: gdalwarp -tr)",
            source=grid.source,
        )
    return Terrain(
        x0_m=float(grid.x_m[0] - dx / 2),
        y0_m=float(grid.y_m[-1] - dy / 2),
        cell_m=float(dx),
        z=np.ascontiguousarray(np.flipud(grid.values), dtype=np.float64),
        crs=grid.crs,
    )
