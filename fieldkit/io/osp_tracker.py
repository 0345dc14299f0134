"""Open Source Physics Tracker data exports -> Track.

Tracker (physlets.org/tracker, "File > Export > Data File") writes delimited text:

* line 1: the track name (e.g. ``mass A``);
* line 2: the column names, ``t`` first, then ``x``, ``y`` and whatever else the
  user selected (``v_{x}``, ``theta``, ``step``, ``frame`` ...);
* one row per step, numbers in the user's locale (``1,245986911E1`` on a French or
  German system), separated by tab (default), comma, semicolon or space as chosen in
  the export dialog. Missing values are empty cells.

With several tracks selected, Tracker 6 writes a ``#multi:`` line, then a line with
each track name above its first column, then the column names (``t x y x y ...``).

Tracker's world coordinates have y up and are in whatever unit the user calibrated
(the file does not say): metres by default here, ``unit="cm"`` etc. otherwise, and
``unit="px"`` with ``metres_per_pixel`` for an uncalibrated clip. ``t`` is in seconds
at the clip's frame rate; for a high-speed clip timed at its playback rate give both
``file_fps`` (the rate Tracker used) and ``fps`` (the true capture rate).

Format source: Tracker help ("Exporting data", "Data tracks": delimited text with an
optional first-line track name), and the Brock University Tracker notes showing the
``cm_A / t x y`` and ``#multi:`` layouts.
"""

from __future__ import annotations

import os

from fieldkit.errors import InputFileError
from fieldkit.io.csv_table import detect_delimiter, numbered_lines, read_text, split_row
from fieldkit.io.tracking_export import (
    LengthScale,
    build_track,
    check_increasing_times,
    read_number_columns,
    time_factor,
)
from fieldkit.track import Track


def read_osp_tracker(
    path: str | os.PathLike[str],
    *,
    track_name: str | None = None,
    unit: str = "m",
    metres_per_pixel: float | None = None,
    fps: float | None = None,
    file_fps: float | None = None,
) -> Track:
    """Read a Tracker data export into a :class:`Track` (metres, seconds, z up).

    Parameters
    ----------
    path
        The exported text file (``.txt``, ``.csv``, ``.tsv``).
    track_name
        Which track of a ``#multi:`` export (default: the first).
    unit
        Length unit of the export: ``m`` (default), ``cm``, ``mm``, ``in``, ``ft`` or
        ``px`` (then ``metres_per_pixel`` is required).
    metres_per_pixel
        Scale for pixel coordinates [m/px].
    fps, file_fps
        True capture rate and the rate Tracker's ``t`` was computed with; give both to
        correct a clip timed at its playback rate.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "ball.txt"
    >>> _ = p.write_text("ball\\nt\\tx\\ty\\n0,0\\t1,5\\t2,0\\n0,1\\t1,6\\t1,95\\n")
    >>> tr = read_osp_tracker(p)
    >>> tr.meta["track_name"], tr.x.tolist(), tr.z.tolist()
    ('ball', [1.5, 1.6], [2.0, 1.95])
    """
    src = str(path)
    numbered = numbered_lines(read_text(path, kind="Tracker data"))
    lines = [line for _, line in numbered]
    i = 0
    names_line = None
    if lines[0].strip().lower().startswith("#multi"):
        names_line, i = lines[1] if len(lines) > 1 else "", 2
        name = None
    elif _is_header(lines[0]):
        name = ""
    else:
        name, i = lines[0].strip(), 1
    if i >= len(lines) or not _is_header(lines[i]):
        row = numbered[i][0] if i < len(lines) else numbered[-1][0] + 1
        raise InputFileError(
            "no column header with 't' found (expected the track name, then 't  x  y')",
            source=src,
            where=f"row {row}",
        )
    header_line = lines[i]
    delim = detect_delimiter(header_line, default=" ")
    header = [h.strip() for h in split_row(header_line, delim)]
    for axis in ("x", "y"):
        if axis not in header:
            raise InputFileError(
                f"the {axis} column is missing (columns found: {', '.join(header)}); "
                "export t, x and y from Tracker",
                source=src,
                where=f"row {numbered[i][0]}",
            )
    t_col = header.index("t")
    x_col, y_col = _xy_columns(header, names_line, delim, track_name, src)
    if names_line is not None:
        name = _track_names(names_line, delim).get(x_col, "")
    row_numbers, data = read_number_columns(
        numbered[i + 1 :], delim, header, (t_col, x_col, y_col), src
    )
    check_increasing_times(data[:, 0], row_numbers, src)
    return build_track(
        data[:, 0],
        data[:, 1],
        data[:, 2],
        scale=LengthScale(unit, metres_per_pixel, y_down=False),
        source=src,
        time_factor=time_factor(file_fps, fps, src),
        fps=fps,
        row_numbers=row_numbers,
        meta={
            "format": "osp-tracker",
            "track_name": name,
            "unit": unit,
            "delimiter": delim,
        },
    )


def _is_header(line: str) -> bool:
    """A column-name line: ``t`` with ``x`` or ``y`` (a missing one is reported)."""
    delim = detect_delimiter(line, default=" ")
    cells = [c.strip().strip('"') for c in split_row(line, delim)]
    return "t" in cells and ("x" in cells or "y" in cells)


def _track_names(names_line: str, delim: str) -> dict[int, str]:
    """Column index -> track name from a ``#multi:`` names line."""
    cells = split_row(names_line, delim)
    return {j: c.strip() for j, c in enumerate(cells) if c.strip()}


def _xy_columns(header, names_line, delim, track_name, src) -> tuple[int, int]:
    xs = [j for j, h in enumerate(header) if h == "x"]
    if names_line is None:
        if track_name is not None:
            pass  # single-track file: the name is informational
        return xs[0], header.index("y", xs[0])
    names = _track_names(names_line, delim)
    # each track's name sits above its first column; its x is the first x at or after
    starts = sorted(names)
    wanted = track_name if track_name is not None else names[starts[0]]
    if wanted not in names.values():
        raise InputFileError(
            f"no track named {wanted!r}; the file holds {', '.join(names.values())}",
            source=src,
        )
    start = next(j for j in starts if names[j] == wanted)
    stop = next((j for j in starts if j > start), len(header))
    x_col = next((j for j in xs if start <= j < stop), None)
    if x_col is None or "y" not in header[x_col:stop]:
        raise InputFileError(f"track {wanted!r} has no x and y columns", source=src)
    return x_col, header.index("y", x_col)
