"""Alignment files: the plan line of a road, railway or barrier, in order.

One CSV (any separator :mod:`fieldkit.io.csv_table` reads) with plan coordinates in
the DEM's coordinate system: ``x``, ``y`` (also ``easting``, ``northing``), a length
unit in the name (``x_m, y_m``); other columns are ignored. Rows are the vertices
in chainage order (chainage 0 at the first row); a vertex repeating the one before
is refused, naming its row (the header is row 1).

Examples
--------
>>> import tempfile, pathlib
>>> f = pathlib.Path(tempfile.mkdtemp()) / "line.csv"
>>> _ = f.write_text("x_m,y_m\\n0,0\\n30,40\\n")
>>> read_alignment(f).tolist()
[[0.0, 0.0], [30.0, 40.0]]
"""

from __future__ import annotations

from os import PathLike

import numpy as np

from fieldkit.errors import InputFileError
from fieldkit.io.csv_table import length_factor, read_csv_table

X_ALIASES = ("x", "easting")
Y_ALIASES = ("y", "northing")


def read_alignment(path: str | PathLike[str]) -> np.ndarray:
    """The alignment's vertices ``(n, 2)`` [m], n >= 2 (module docstring).

    Raises
    ------
    InputFileError
        No x/y column, a length without a unit, a value that is not a finite
        number, fewer than two vertices, or a vertex repeating the one before.
    """
    table = read_csv_table(path)
    found = table.require(
        {"x": X_ALIASES, "y": Y_ALIASES},
        "an alignment file needs plan coordinates in columns x, y (e.g. x_m, y_m)",
    )
    for column in found.values():
        if column.unit is None:
            header = column.header.strip()
            raise InputFileError(
                f"column '{header}' has no length unit: name it in the header "
                f"('{header}_m', '{header}_ft'), in the DEM's coordinate system",
                source=table.source,
                where="row 1",
            )
    factors = {k: length_factor(table, c, None) for k, c in found.items()}
    xy, rows = [], []
    for number, row in table.rows:
        x = table.number(number, row, found["x"]) * factors["x"]
        y = table.number(number, row, found["y"]) * factors["y"]
        if not (np.isfinite(x) and np.isfinite(y)):
            raise InputFileError(
                "x and y must be finite numbers",
                source=table.source,
                where=f"row {number}",
            )
        if xy and (x, y) == xy[-1]:
            raise InputFileError(
                f"vertex ({x:g}, {y:g}) repeats the one before (row {rows[-1]})",
                source=table.source,
                where=f"row {number}",
            )
        xy.append((x, y))
        rows.append(number)
    if len(xy) < 2:
        raise InputFileError(
            f"an alignment needs at least 2 vertices (got {len(xy)})",
            source=table.source,
        )
    return np.array(xy, float)
