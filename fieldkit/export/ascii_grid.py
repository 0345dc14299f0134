"""ESRI ASCII grids as text: the format Rockyfor3D reads and GIS tools exchange.

Header ``ncols nrows xllcorner yllcorner cellsize NODATA_value`` (lower-left corner of
the lower-left cell), then ``nrows`` lines north to south. :func:`fieldkit.io.dem.
read_dem` reads the result back (the round-trip tests do).
"""

from __future__ import annotations

import numpy as np

from fieldkit.io.dem import DemGrid, header_number_text


def ascii_grid_text(
    values: np.ndarray,
    grid: DemGrid,
    *,
    nodata: float = -9999,
    integer: bool = False,
    decimals: int = 3,
) -> str:
    """An ESRI ASCII grid of ``values`` on the cells of ``grid``.

    Parameters
    ----------
    values
        ``(nrows, ncols)``, row 0 north (as :class:`DemGrid`); NaN -> ``nodata``.
    grid
        The grid whose geometry the file takes (square cells).
    nodata
        The NODATA_value written.
    integer
        Write whole numbers (codes, counts, percentages).
    decimals
        Decimals of a float grid.

    Examples
    --------
    >>> g = DemGrid.from_corner(np.zeros((2, 3)), x_left_m=100, y_top_m=20,
    ...                         cellsize_m=5)
    >>> print(ascii_grid_text(np.array([[1, 2, np.nan], [4, 5, 6]]), g,
    ...                       integer=True))
    ncols 3
    nrows 2
    xllcorner 100
    yllcorner 10
    cellsize 5
    NODATA_value -9999
    1 2 -9999
    4 5 6
    <BLANKLINE>
    """
    v = np.asarray(values, float)
    if v.shape != grid.shape:
        raise ValueError(f"values {v.shape} do not match the grid {grid.shape}")
    if not grid.square:
        raise ValueError("an ESRI ASCII grid needs square cells")
    header = [  # the grid's own header numbers, each written to read back exactly
        f"ncols {v.shape[1]}",
        f"nrows {v.shape[0]}",
        f"xllcorner {header_number_text(grid.x_left_m)}",
        f"yllcorner {header_number_text(grid.y_bottom_m)}",
        f"cellsize {header_number_text(grid.dx_m)}",
        f"NODATA_value {nodata:g}",
    ]
    out = np.where(np.isfinite(v), v, nodata)
    if integer:
        rows = [" ".join(str(int(round(c))) for c in row) for row in out]
    else:
        rows = [
            " ".join(
                f"{c:.{decimals}f}".rstrip("0").rstrip(".") if c != nodata else f"{c:g}"
                for c in row
            )
            for row in out
        ]
    return "\n".join(header + rows) + "\n"
