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
from fieldkit.io.csv_table import plan_columns, read_csv_table


def read_alignment(path: str | PathLike[str]) -> np.ndarray:
    """The alignment's vertices ``(n, 2)`` [m], n >= 2 (module docstring).

    Raises
    ------
    InputFileError
        No x/y column, a length without a unit, a value that is not a finite
        number, fewer than two vertices, or a vertex repeating the one before.
    """
    table = read_csv_table(path)
    found, factors = plan_columns(table, "an alignment file")
    xy, rows = [], []
    for number, row in table.rows:
        # table.number refuses empty cells, text and non-finite numbers
        x = table.number(number, row, found["x"]) * factors["x"]
        y = table.number(number, row, found["y"]) * factors["y"]
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
