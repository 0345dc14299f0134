"""Digital elevation models: an ESRI ASCII grid or a GeoTIFF -> :class:`DemGrid`.

Two formats, chosen by the file's first bytes (a TIFF signature) or, failing that, read
as ESRI ASCII:

* **ESRI ASCII grid** (``.asc``), read natively. A header of ``key value`` lines, any
  case, in any order: ``ncols``, ``nrows``, ``xllcorner`` or ``xllcenter``,
  ``yllcorner`` or ``yllcenter``, ``cellsize`` (or ``dx`` and ``dy``, as GDAL writes
  non-square cells) and the optional ``NODATA_value`` (the ESRI default -9999 when
  absent, stated in :attr:`DemGrid.notes`). Then ``nrows`` rows of ``ncols`` numbers,
  the first row the northern one. Read strictly: a missing or repeated key, a
  non-integer count, a cell size <= 0, text in a number, an infinite value or a row
  of the wrong length is a one-line error naming the file and the line. A ``.prj``
  beside the file gives :attr:`DemGrid.crs` (its text as written).
* **GeoTIFF**, through rasterio (GDAL): band 1 of a single-band, north-up raster
  (no rotation terms); masked cells and the nodata value become NaN; the CRS as
  rasterio writes it (``EPSG:2056``) or None.

Elevations are in metres, as the coordinates (a projected grid: a DEM in degrees is
refused, the slope of a section needs lengths in one unit).

Interpolation (:meth:`DemGrid.elevation`) is bilinear between the four cell centres
around a point, so it is defined on the rectangle of cell centres -- half a cell
inside the grid's outer edge. A point outside it, or whose interpolation uses a
nodata cell, is an error naming the point.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from functools import cached_property
from os import PathLike
from pathlib import Path

import numpy as np

from fieldkit.errors import InputFileError
from fieldkit.io.csv_table import check_readable, decode_text

#: ESRI's NODATA_value when a header gives none.
ESRI_DEFAULT_NODATA = -9999.0

#: Header keys of an ESRI ASCII grid (lower case) -> what they are.
_ESRI_KEYS = {
    "ncols": "number of columns",
    "nrows": "number of rows",
    "xllcorner": "x of the lower-left corner",
    "xllcenter": "x of the lower-left cell centre",
    "yllcorner": "y of the lower-left corner",
    "yllcenter": "y of the lower-left cell centre",
    "cellsize": "cell size",
    "dx": "cell width",
    "dy": "cell height",
    "nodata_value": "nodata value",
}

_TIFF_SIGNATURES = (b"II*\x00", b"MM\x00*", b"II+\x00", b"MM\x00+")

#: Status codes of :meth:`DemGrid.sample`.
INSIDE, OUTSIDE, NODATA = 0, 1, 2


#: Points per side of the square grid a block's footprint is sampled on (clipped to
#: a disc): :func:`footprint_offsets`.
FOOTPRINT_SAMPLES = 9


def footprint_offsets(radius_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Plan offsets [m] of the DEM points a ground plane is fitted to: a square grid
    of :data:`FOOTPRINT_SAMPLES` x :data:`FOOTPRINT_SAMPLES` points over
    ``[-r, r]^2`` kept inside the disc of radius ``r`` (the block's footprint).

    Examples
    --------
    >>> dx, dy = footprint_offsets(2.0)
    >>> dx.size, float(np.hypot(dx, dy).max())
    (49, 2.0)
    """
    s = np.linspace(-1.0, 1.0, FOOTPRINT_SAMPLES)
    de, dn = np.meshgrid(s, s)
    inside = de**2 + dn**2 <= 1.0 + 1e-12
    return radius_m * de[inside], radius_m * dn[inside]


def footprint_plane(
    dx_m: np.ndarray, dy_m: np.ndarray, z_m: np.ndarray
) -> tuple[float, float, float, float]:
    """Least-squares plane ``z = a + b dx + c dy`` through DEM heights sampled at
    plan offsets (:func:`footprint_offsets`) about a point: ``(a, b, c, rms)``,
    ``a`` the plane's height at the point, ``(b, c)`` its gradient, ``rms`` the
    misfit of the heights [m]. Over a disc inside one bilinear cell the twist term
    is orthogonal to the plane, so ``(b, c)`` is the surface's gradient at the point.

    Examples
    --------
    >>> dx, dy = footprint_offsets(1.0)
    >>> a, b, c, rms = footprint_plane(dx, dy, 3 - 0.5 * dx + dx * dy)
    >>> [round(v, 9) + 0.0 for v in (a, b, c)], rms > 0  # the twist is misfit
    ([3.0, -0.5, 0.0], True)
    """
    design = np.column_stack([np.ones_like(dx_m), dx_m, dy_m])
    coef, *_ = np.linalg.lstsq(design, z_m, rcond=None)
    res = z_m - design @ coef
    a, b, c = (float(v) for v in coef)
    return a, b, c, float(np.sqrt(np.mean(res * res)))


def header_number_text(value: float) -> str:
    """A header number (corner, cell size) as the shortest text that reads back
    as the same float: ``%g`` would write 2780000.025 as ``2.78e+06``.

    Examples
    --------
    >>> [header_number_text(v) for v in (5.0, 2780000.025, 0.05)]
    ['5', '2780000.025', '0.05']
    """
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


def coordinate_tolerance_m(*coords_m: float) -> float:
    """A few rounding errors of the largest coordinate [m]: how far two
    computations of one point may differ (4.7e-10 m is one at 2.8e6 m, LV95).

    Examples
    --------
    >>> coordinate_tolerance_m(2_780_000.0, 1_185_000.0) < 1e-8
    True
    """
    return 16.0 * math.ulp(max((abs(c) for c in coords_m), default=1.0) or 1.0)


def same_origin_and_cell(
    a: tuple[float, ...], b: tuple[float, ...], rel_cell: float = 1e-9
) -> bool:
    """Whether two grids' ``(x0, y0, cell_x[, cell_y])`` agree: cell sizes to
    ``rel_cell``, origins within 1e-6 of a cell plus
    :func:`coordinate_tolerance_m` of their magnitude.

    Examples
    --------
    >>> same_origin_and_cell((2780000.0, 1185000.0, 0.05),
    ...                      (2780000.0 + 1e-9, 1185000.0, 0.05 * (1 + 1e-12)))
    True
    >>> same_origin_and_cell((0.0, 0.0, 0.05), (0.05, 0.0, 0.05))
    False
    """
    cells = list(zip(a[2:], b[2:], strict=True))
    if not all(math.isclose(p, q, rel_tol=rel_cell) for p, q in cells):
        return False
    cell = min(a[2:])
    return all(
        abs(p - q) <= 1e-6 * cell + coordinate_tolerance_m(p, q)
        for p, q in zip(a[:2], b[:2], strict=True)
    )


@dataclass(frozen=True)
class DemGrid:
    """A regular elevation grid, north up.

    The geometry is the file's own header (ESRI ``cellsize``/``dx``/``dy`` and
    ``xllcorner``/``xllcenter``...) or GeoTIFF transform (``a``, ``-e``, ``c``,
    ``f``), kept as given: the cell centres :attr:`x_m`, :attr:`y_m` are computed
    from it, never the other way round. Differences of centres near 2.8e6 m (a
    national grid) are off by ~1e-9 m, which is 2e-8 of a 5 cm cell.

    Attributes
    ----------
    values
        ``(nrows, ncols)`` elevations [m]; row 0 is the northern row; NaN = nodata.
    x_left_m
        x of the western edge of the grid (of column 0's cells) [m].
    y_top_m
        y of the northern edge of the grid (of row 0's cells) [m].
    dx_m
        Column spacing (cell width) [m], > 0, as the header gives it.
    dy_m
        Row spacing (cell height) [m], > 0, as the header gives it.
    crs
        The coordinate reference system as the file gives it, or None.
    source
        The file it was read from.
    notes
        What reading assumed (e.g. the ESRI default nodata value).
    """

    values: np.ndarray
    x_left_m: float
    y_top_m: float
    dx_m: float
    dy_m: float
    crs: str | None = None
    source: str = ""
    notes: tuple[str, ...] = field(default=())

    @classmethod
    def from_corner(
        cls,
        values: np.ndarray,
        *,
        x_left_m: float,
        y_top_m: float,
        cellsize_m: float,
        cellsize_y_m: float | None = None,
        crs: str | None = None,
        source: str = "",
        notes: tuple[str, ...] = (),
    ) -> DemGrid:
        """A grid from its values and the upper-left corner of its upper-left cell.

        Examples
        --------
        >>> g = DemGrid.from_corner(np.zeros((2, 3)), x_left_m=0, y_top_m=10,
        ...                         cellsize_m=5)
        >>> g.x_m.tolist(), g.y_m.tolist(), g.cellsize_m
        ([2.5, 7.5, 12.5], [7.5, 2.5], 5.0)
        """
        dy = cellsize_m if cellsize_y_m is None else cellsize_y_m
        return cls(
            np.asarray(values, dtype=float),
            float(x_left_m),
            float(y_top_m),
            float(cellsize_m),
            float(dy),
            crs=crs,
            source=source,
            notes=notes,
        )

    @cached_property
    def x_m(self) -> np.ndarray:
        """``(ncols,)`` x of the column centres [m], increasing."""
        return self.x_left_m + self.dx_m * (np.arange(self.shape[1]) + 0.5)

    @cached_property
    def y_m(self) -> np.ndarray:
        """``(nrows,)`` y of the row centres [m], decreasing (row 0 north)."""
        return self.y_top_m - self.dy_m * (np.arange(self.shape[0]) + 0.5)

    @property
    def shape(self) -> tuple[int, int]:
        """``(nrows, ncols)``."""
        return self.values.shape  # type: ignore[return-value]

    @property
    def y_bottom_m(self) -> float:
        """y of the southern edge of the grid [m]."""
        return self.y_top_m - self.shape[0] * self.dy_m

    @property
    def cellsize_m(self) -> float:
        """The cell size [m]: the smaller of the column and row spacings."""
        return min(self.dx_m, self.dy_m)

    @property
    def square(self) -> bool:
        """Whether the cells are square: the header's two sizes agree to 1e-9
        (a file writes one ``cellsize``, or ``dx``/``dy`` as decimals that may
        round differently in the last digit)."""
        return math.isclose(self.dx_m, self.dy_m, rel_tol=1e-9)

    def same_geometry(self, other: DemGrid) -> bool:
        """Whether ``other`` lies on this grid: same shape and cell sizes (to
        1e-9), origins within 1e-6 of a cell (and within a few rounding errors of
        the coordinates' magnitude, so a 5 cm grid at 2.8e6 m compares)."""
        return self.shape == other.shape and same_origin_and_cell(
            (self.x_left_m, self.y_top_m, self.dx_m, self.dy_m),
            (other.x_left_m, other.y_top_m, other.dx_m, other.dy_m),
        )

    def extent_text(self) -> str:
        """Where interpolation is defined, for messages: the cell-centre rectangle."""
        return (
            f"cell centres span x {self.x_m[0]:.10g}..{self.x_m[-1]:.10g} m, "
            f"y {self.y_m[-1]:.10g}..{self.y_m[0]:.10g} m"
        )

    def sample(
        self, x_m: np.ndarray, y_m: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Bilinear elevation and gradient at points, without raising.

        Returns
        -------
        z_m, dzdx, dzdy, status
            Elevation [m], gradient (dimensionless, of the bilinear surface in the
            cell holding the point; on a cell edge the mean over the cells meeting
            there) and per point :data:`INSIDE`, :data:`OUTSIDE`
            (off the cell-centre rectangle) or :data:`NODATA` (a cell the
            interpolation uses is nodata); z and gradient are NaN unless INSIDE.
        """
        x = np.atleast_1d(np.asarray(x_m, dtype=float))
        y = np.atleast_1d(np.asarray(y_m, dtype=float))
        nrows, ncols = self.shape
        col = (x - self.x_m[0]) / self.dx_m
        row = (self.y_m[0] - y) / self.dy_m
        # a point on the grid's edge, computed another way, may be a few rounding
        # errors of its coordinate off: at 2.8e6 m that is ~1e-8 of a 5 cm cell
        tol_c = 1e-9 + coordinate_tolerance_m(self.x_left_m) / self.dx_m
        tol_r = 1e-9 + coordinate_tolerance_m(self.y_top_m) / self.dy_m
        # ... and so may a point on a line of cell centres: snapped onto it, so it
        # does not lean on the next row or column (which may be nodata)
        col = np.where(np.abs(col - np.round(col)) <= tol_c, np.round(col), col)
        row = np.where(np.abs(row - np.round(row)) <= tol_r, np.round(row), row)
        inside = (
            np.isfinite(col)
            & np.isfinite(row)
            & (col >= -tol_c)
            & (col <= ncols - 1 + tol_c)
            & (row >= -tol_r)
            & (row <= nrows - 1 + tol_r)
        )
        col = np.clip(np.where(inside, col, 0.0), 0.0, ncols - 1)
        row = np.clip(np.where(inside, row, 0.0), 0.0, nrows - 1)
        c0 = np.minimum(np.floor(col).astype(int), ncols - 2)
        r0 = np.minimum(np.floor(row).astype(int), nrows - 2)
        fc, fr = col - c0, row - r0
        z00 = self.values[r0, c0]  # north-west corner of the cell
        z01 = self.values[r0, c0 + 1]
        z10 = self.values[r0 + 1, c0]
        z11 = self.values[r0 + 1, c0 + 1]
        weights = ((1 - fr) * (1 - fc), (1 - fr) * fc, fr * (1 - fc), fr * fc)
        corners = (z00, z01, z10, z11)
        # a nodata corner counts only where it carries weight (a point on a node
        # next to a nodata cell is fine)
        used_nan = np.zeros(x.shape, bool)
        for w, z in zip(weights, corners, strict=True):
            used_nan |= (w > 0) & np.isnan(z)
        z = sum(np.where(w > 0, w * np.nan_to_num(c), 0.0) for w, c in zip(
            weights, corners, strict=True))  # fmt: skip
        dzdx, dzdy = self._gradient(r0, c0, fr, fc)
        status = np.where(inside, np.where(used_nan, NODATA, INSIDE), OUTSIDE)
        bad = status != INSIDE
        z = np.where(bad, np.nan, z)
        dzdx = np.where(bad, np.nan, dzdx)
        dzdy = np.where(bad, np.nan, dzdy)
        return z, dzdx, dzdy, status

    def _gradient(self, r0, c0, fr, fc) -> tuple[np.ndarray, np.ndarray]:
        """Gradient of the bilinear surface; on a cell edge, the mean over the cells
        meeting there that have data (the surface has a kink along cell edges: the
        mean keeps a line running along an edge from being pulled to one side)."""
        nrows, ncols = self.shape
        sum_x = np.zeros(np.shape(fr))
        sum_y = np.zeros(np.shape(fr))
        count = np.zeros(np.shape(fr))
        for dr in (0, -1):
            for dc in (0, -1):
                use = np.ones(np.shape(fr), bool)
                if dr:
                    use &= (fr == 0) & (r0 > 0)
                if dc:
                    use &= (fc == 0) & (c0 > 0)
                if not use.any():
                    continue
                r, c = np.where(use, r0 + dr, r0), np.where(use, c0 + dc, c0)
                gr, gc = np.where(use & (dr != 0), 1.0, fr), np.where(
                    use & (dc != 0), 1.0, fc)  # fmt: skip
                z00, z01 = self.values[r, c], self.values[r, c + 1]
                z10, z11 = self.values[r + 1, c], self.values[r + 1, c + 1]
                gx = ((1 - gr) * (z01 - z00) + gr * (z11 - z10)) / self.dx_m
                gy = -((1 - gc) * (z10 - z00) + gc * (z11 - z01)) / self.dy_m
                ok = use & np.isfinite(gx) & np.isfinite(gy)
                sum_x += np.where(ok, gx, 0.0)
                sum_y += np.where(ok, gy, 0.0)
                count += ok
        with np.errstate(invalid="ignore", divide="ignore"):
            return sum_x / count, sum_y / count

    def elevation(self, x_m, y_m) -> np.ndarray:
        """Bilinear elevation [m] at plan points ``(x_m, y_m)``.

        Raises
        ------
        InputFileError
            Naming the file and the first point outside the cell-centre rectangle
            or whose interpolation needs a nodata cell.

        Examples
        --------
        >>> g = DemGrid.from_corner([[10.0, 20.0], [0.0, 10.0]], x_left_m=0,
        ...                         y_top_m=2, cellsize_m=1)
        >>> g.elevation([0.5, 1.0], [1.5, 1.0]).tolist()
        [10.0, 10.0]
        """
        z, _, _, status = self.sample(x_m, y_m)
        self.check(np.atleast_1d(x_m), np.atleast_1d(y_m), status)
        return z

    def check(self, x_m: np.ndarray, y_m: np.ndarray, status: np.ndarray) -> None:
        """Raise naming the first point whose ``status`` is not :data:`INSIDE`."""
        bad = np.flatnonzero(status != INSIDE)
        if bad.size:
            i = int(bad[0])
            raise InputFileError(
                self.problem_at(float(x_m[i]), float(y_m[i]), int(status[i])),
                source=self.source,
                where=f"point (x, y) = ({x_m[i]:.2f}, {y_m[i]:.2f})",
            )

    def problem_at(self, x_m: float, y_m: float, status: int) -> str:
        """Why a point has no elevation: off the grid, or nodata (row, column)."""
        if status == OUTSIDE:
            return f"outside the grid ({self.extent_text()})"
        row = (self.y_m[0] - y_m) / self.dy_m
        col = (x_m - self.x_m[0]) / self.dx_m
        corners = [
            (r, c)
            for r in sorted({math.floor(row), math.ceil(row)})
            for c in sorted({math.floor(col), math.ceil(col)})
            if 0 <= r < self.shape[0] and 0 <= c < self.shape[1]
        ]
        r, c = next(
            ((r, c) for r, c in corners if np.isnan(self.values[r, c])), corners[0]
        )
        return f"nodata in the grid at row {r + 1}, column {c + 1}: no elevation there"


def read_dem(path: str | PathLike[str]) -> DemGrid:
    """Read an ESRI ASCII grid or a GeoTIFF (see the module docstring).

    Raises
    ------
    InputFileError
        A missing, empty or malformed file (one line naming the file and, for ESRI
        ASCII, the line), a grid of fewer than 2 x 2 cells, a rotated GeoTIFF, more
        than one band, or no valid elevation at all.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "dem.asc"
    >>> _ = f.write_text("ncols 3\\nnrows 2\\nxllcorner -35\\nyllcorner 85\\n"
    ...                  "cellsize 5\\nNODATA_value -9999\\n1 2 3\\n4 -9999 6\\n")
    >>> grid = read_dem(f)
    >>> grid.shape, grid.cellsize_m, grid.x_m.tolist(), grid.y_m.tolist()
    ((2, 3), 5.0, [-32.5, -27.5, -22.5], [92.5, 87.5])
    >>> grid.values.tolist()
    [[1.0, 2.0, 3.0], [4.0, nan, 6.0]]
    """
    file = check_readable(path)
    with file.open("rb") as handle:
        head = handle.read(4)
    grid = _read_geotiff(file) if head in _TIFF_SIGNATURES else _read_esri_ascii(file)
    if not np.isfinite(grid.values).any():
        raise InputFileError("every cell is nodata", source=str(path))
    return grid


def _header_number(text: str, key: str, source: str, line: int) -> float:
    try:
        value = float(text)
    except ValueError:
        raise InputFileError(
            f"header {key} '{text}' is not a number",
            source=source,
            where=f"line {line}",
        ) from None
    if not math.isfinite(value):
        raise InputFileError(
            f"header {key} '{text}' is not a finite number",
            source=source,
            where=f"line {line}",
        )
    return value


#: Most cells a DEM may have: 50 million (a 7 km square at 1 m) is 400 MB as
#: floats, and a rockfall section needs a slope, not a region. A compressed
#: GeoTIFF declaring more (a few kB on disk) would otherwise exhaust memory.
MAX_DEM_CELLS = 50_000_000


def check_cell_count(nrows: int, ncols: int, source: str) -> None:
    """Refuse a grid of more than :data:`MAX_DEM_CELLS` cells, before reading it."""
    if nrows * ncols > MAX_DEM_CELLS:
        raise InputFileError(
            f"grid of {nrows:,} x {ncols:,} cells, more than the limit of "
            f"{MAX_DEM_CELLS:,} (400 MB of elevations): crop it to the slope "
            "(gdal_translate -projwin) or coarsen it (gdalwarp -tr)",
            source=source,
        )


def _read_esri_ascii(file: Path) -> DemGrid:
    """An ESRI ASCII grid, strictly (module docstring)."""
    source = str(file)
    text = decode_text(file.read_bytes(), source, "ESRI ASCII grid")
    lines = text.splitlines()
    header: dict[str, tuple[float, int]] = {}
    number = 0
    for number, raw in enumerate(lines, 1):
        parts = raw.split()
        if not parts:
            continue
        key = parts[0].lower()
        if key not in _ESRI_KEYS:
            try:
                float(parts[0])
            except ValueError:
                raise InputFileError(
                    f"unknown header key '{parts[0]}' (an ESRI ASCII grid has "
                    "ncols, nrows, xllcorner|xllcenter, yllcorner|yllcenter, "
                    "cellsize, NODATA_value)",
                    source=source,
                    where=f"line {number}",
                ) from None
            break  # the first data line
        if len(parts) != 2:
            raise InputFileError(
                f"header line needs 'key value', got {len(parts)} fields",
                source=source,
                where=f"line {number}",
            )
        if key in header:
            raise InputFileError(
                f"header key {key} appears twice", source=source, where=f"line {number}"
            )
        header[key] = (_header_number(parts[1], key, source, number), number)
    else:
        number += 1
    first_data = number

    def need(*keys: str) -> tuple[str, float, int]:
        found = [k for k in keys if k in header]
        if len(found) != 1:
            what = " or ".join(keys)
            problem = "missing" if not found else f"given twice ({', '.join(found)})"
            raise InputFileError(
                f"header {what} {problem}", source=source, where=f"line {first_data}"
            )
        return found[0], *header[found[0]]

    counts = {}
    for key in ("ncols", "nrows"):
        _, value, line = need(key)
        if value != int(value) or value < 2:
            raise InputFileError(
                f"header {key} must be a whole number >= 2 (got {value:g})",
                source=source,
                where=f"line {line}",
            )
        counts[key] = int(value)
    check_cell_count(counts["nrows"], counts["ncols"], source)
    if "cellsize" in header:
        if "dx" in header or "dy" in header:
            need("cellsize", "dx")  # raises: given twice
        _, dx, line = need("cellsize")
        dy = dx
        dy_line = line
    else:
        _, dx, line = need("dx")
        _, dy, dy_line = need("dy")
    for value, at in ((dx, line), (dy, dy_line)):
        if value <= 0:
            raise InputFileError(
                f"header cell size must be > 0 (got {value:g})",
                source=source,
                where=f"line {at}",
            )
    x_key, x_ll, _ = need("xllcorner", "xllcenter")
    y_key, y_ll, _ = need("yllcorner", "yllcenter")
    notes: tuple[str, ...] = ()
    if "nodata_value" in header:
        nodata = header["nodata_value"][0]
    else:
        nodata = ESRI_DEFAULT_NODATA
        notes = (f"no NODATA_value in the header: the ESRI default {nodata:g} is used",)

    ncols, nrows = counts["ncols"], counts["nrows"]
    rows: list[np.ndarray] = []
    for number in range(first_data, len(lines) + 1):
        parts = lines[number - 1].split()
        if not parts:
            continue
        if len(rows) == nrows:
            raise InputFileError(
                f"more than nrows = {nrows} rows of values",
                source=source,
                where=f"line {number}",
            )
        if len(parts) != ncols:
            raise InputFileError(
                f"{len(parts)} values in a row of ncols = {ncols}",
                source=source,
                where=f"line {number}",
            )
        try:
            values = np.array(parts, dtype=float)
        except ValueError:
            bad = next(p for p in parts if not _is_number(p))
            raise InputFileError(
                f"value '{bad}' is not a number", source=source, where=f"line {number}"
            ) from None
        if np.isinf(values).any():
            bad = parts[int(np.flatnonzero(np.isinf(values))[0])]
            raise InputFileError(
                f"value '{bad}' is not a finite number",
                source=source,
                where=f"line {number}",
            )
        rows.append(values)
    if len(rows) != nrows:
        raise InputFileError(
            f"{len(rows)} rows of values for nrows = {nrows}",
            source=source,
            where=f"line {len(lines)}",
        )
    values = np.vstack(rows)
    values[values == nodata] = np.nan
    x_left = x_ll if x_key == "xllcorner" else x_ll - dx / 2
    y_bottom = y_ll if y_key == "yllcorner" else y_ll - dy / 2
    prj = file.with_suffix(".prj")
    crs = (prj.read_text(errors="replace").strip() or None) if prj.is_file() else None
    return DemGrid(
        values,
        x_left_m=x_left,
        y_top_m=y_bottom + nrows * dy,
        dx_m=dx,
        dy_m=dy,
        crs=crs,
        source=source,
        notes=notes,
    )


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _read_geotiff(file: Path) -> DemGrid:
    """Band 1 of a single-band north-up GeoTIFF, through rasterio."""
    source = str(file)
    try:
        import rasterio
        from rasterio.errors import NotGeoreferencedWarning, RasterioError
    except ImportError:  # pragma: no cover - rasterio is a dependency
        raise InputFileError(
            "reading a GeoTIFF needs rasterio (pip install rasterio); or convert it "
            "to an ESRI ASCII grid (gdal_translate -of AAIGrid)",
            source=source,
        ) from None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NotGeoreferencedWarning)
            src = rasterio.open(file)
        with src:
            if src.transform.is_identity and src.crs is None:
                raise InputFileError(
                    "not georeferenced (no geotransform): a plain TIFF image, not a "
                    "GeoTIFF DEM",
                    source=source,
                )
            if src.count != 1:
                raise InputFileError(
                    f"has {src.count} bands; a DEM has one (elevation)", source=source
                )
            t = src.transform
            if t.b != 0 or t.d != 0 or t.a <= 0 or t.e >= 0:
                raise InputFileError(
                    "not a north-up grid (rotated or flipped geotransform "
                    f"{tuple(t)[:6]}); warp it north-up first (gdalwarp)",
                    source=source,
                )
            if src.crs is not None and src.crs.is_geographic:
                raise InputFileError(
                    f"coordinates are degrees ({src.crs}); a section needs a projected "
                    "grid in metres: reproject it (gdalwarp -t_srs EPSG:...)",
                    source=source,
                )
            check_cell_count(src.height, src.width, source)
            band = src.read(1, masked=True).astype(float)
            values = band.filled(np.nan)
            crs = src.crs.to_string() if src.crs is not None else None
    except RasterioError as exc:
        raise InputFileError(
            f"not a readable GeoTIFF ({' '.join(str(exc).split())})", source=source
        ) from None
    if values.shape[0] < 2 or values.shape[1] < 2:
        raise InputFileError(
            f"grid of {values.shape[0]} x {values.shape[1]} cells; bilinear "
            "interpolation needs at least 2 x 2",
            source=source,
        )
    values[~np.isfinite(values)] = np.nan
    return DemGrid(
        values,
        x_left_m=float(t.c),
        y_top_m=float(t.f),
        dx_m=float(t.a),
        dy_m=float(-t.e),
        crs=crs,
        source=source,
    )
