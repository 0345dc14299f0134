"""Kinovea CSV exports -> Track.

Kinovea (kinovea.org) exports trajectories as CSV from its kinematics dialogs and,
since 0.9.6, as "raw CSV" (``ExporterCSV`` in Kinovea.ScreenManager):

* one header row: ``"Time"`` then two columns per tracked point, named
  ``"<object>/<point>/X"`` and ``"<object>/<point>/Y"`` (kinematics dialogs write
  names such as ``"Trajectory 1 X (m)"``: an axis letter and an optional unit);
* every cell quoted; the list separator is a comma, or a semicolon where the
  locale's decimal mark is a comma (``"1,25";"0,5"``); empty cells where a point
  was not tracked;
* the time in the first column, in milliseconds when the header says ``(ms)``.

Coordinates are in the unit of the user's calibration (the raw export does not name
it: pass ``unit``), or in pixels when the clip was not calibrated (``unit="px"`` and
``metres_per_pixel``). Kinovea's calibrated axes have y up; give ``y_down=True``
for image coordinates (y down). A header unit in parentheses overrides ``unit``.

Format source: Kinovea reference manual, "Exporting data and measurements"
(kinovea.readthedocs.io), and ``ExporterCSV.Export`` in the Kinovea source.
"""

from __future__ import annotations

import os
import re

import numpy as np

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io.csv_table import (
    detect_delimiter,
    numbered_lines,
    read_text,
    split_row,
    unit_name,
)
from fieldkit.io.tracking_export import (
    LengthScale,
    build_track,
    check_increasing_times,
    read_number_columns,
    time_factor,
)
from fieldkit.track import Track

_COORD = re.compile(
    r"^(?P<name>.*?)[\s/_\-:]*\b(?P<axis>[XxYy])\b\s*(?:\((?P<unit>[^)]*)\))?\s*$"
)
_TIME = re.compile(r"^\s*(time|t)\b\s*(?:\((?P<unit>[^)]*)\))?", re.IGNORECASE)


def read_kinovea(
    path: str | os.PathLike[str],
    *,
    point: str | None = None,
    unit: str | None = None,
    metres_per_pixel: float | None = None,
    y_down: bool = False,
    time_unit: str = "auto",
    fps: float | None = None,
    file_fps: float | None = None,
) -> Track:
    """Read a Kinovea CSV export into a :class:`Track` (metres, seconds, z up).

    Parameters
    ----------
    path
        The exported CSV file.
    point
        Which tracked point (a substring of its column name, e.g. ``"ball"``); default
        the first X/Y pair.
    unit
        Length unit of the coordinates when the header does not give one: ``m``,
        ``cm``, ``mm``, ``in``, ``ft`` or ``px`` (with ``metres_per_pixel``).
    metres_per_pixel
        Scale for pixel coordinates [m/px].
    y_down
        The y coordinate grows downward (image coordinates).
    time_unit
        ``"s"``, ``"ms"`` or ``"auto"``: the header's unit if any, else milliseconds
        when the median time step is 0.2 or more (every camera between 5 and 5000
        frames/s is then read right), else seconds.
    fps, file_fps
        True capture rate and the rate the export's times used (give both to correct a
        high-speed clip timed at its playback rate).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "k.csv"
    >>> _ = p.write_text('"Time";"Ball/Centre/X";"Ball/Centre/Y"\\n'
    ...                  '"0";"1,5";"2"\\n"33,33";"1,6";"1,9"\\n')
    >>> tr = read_kinovea(p, unit="m")
    >>> tr.t.round(5).tolist(), tr.x.tolist()
    ([0.0, 0.03333], [1.5, 1.6])
    """
    src = str(path)
    lines = numbered_lines(read_text(path))
    delim = detect_delimiter(lines[0][1], default=" ")
    header = [h.strip() for h in split_row(lines[0][1], delim)]
    tm = _TIME.match(header[0]) if header else None
    if tm is None:
        raise InputFileError(
            f"first column {header[0] if header else ''!r} is not the time",
            source=src,
            where=f"row {lines[0][0]}",
        )
    pairs = _coordinate_pairs(header)
    if not pairs:
        raise InputFileError(
            "no X and Y coordinate columns in the header",
            source=src,
            where=f"row {lines[0][0]}",
        )
    if point is None:
        name = next(iter(pairs))
    else:
        found = [n for n in pairs if point.lower() in n.lower()]
        if not found:
            raise InputFileError(
                f"no point matching {point!r}; the file holds {', '.join(pairs)}",
                source=src,
            )
        name = found[0]
    (x_col, x_unit), (y_col, _) = pairs[name]["x"], pairs[name]["y"]
    length_unit = unit_name(x_unit) or unit
    if length_unit is None:
        raise ArgumentError(
            "the export does not name its length unit: give it (`unit` m|cm|mm|px)",
            source=src,
        )
    row_numbers, data = read_number_columns(
        lines[1:], delim, header, (0, x_col, y_col), src
    )
    t = data[:, 0] * _seconds_per_time_unit(
        time_unit, tm.group("unit"), data[:, 0], src
    )
    check_increasing_times(t, row_numbers, src)
    ok = np.isfinite(t)
    tracked = ok & np.isfinite(data[:, 1]) & np.isfinite(data[:, 2])
    return build_track(
        np.where(tracked, t, np.nan),
        data[:, 1],
        data[:, 2],
        scale=LengthScale(length_unit, metres_per_pixel, y_down=y_down),
        source=src,
        time_factor=time_factor(file_fps, fps, src),
        fps=fps,
        row_numbers=row_numbers,
        meta={
            "format": "kinovea",
            "point": name,
            "unit": length_unit,
            "delimiter": delim,
        },
    )


def _coordinate_pairs(
    header: list[str],
) -> dict[str, dict[str, tuple[int, str | None]]]:
    pairs: dict[str, dict[str, tuple[int, str | None]]] = {}
    for j, h in enumerate(header[1:], start=1):
        m = _COORD.match(h)
        if m is None:
            continue
        name = m.group("name").strip() or "point"
        pairs.setdefault(name, {})[m.group("axis").lower()] = (j, m.group("unit"))
    return {n: p for n, p in pairs.items() if "x" in p and "y" in p}


def _seconds_per_time_unit(time_unit: str, header_unit: str | None, t, src) -> float:
    unit = time_unit
    if unit == "auto":
        if header_unit:
            unit = header_unit.strip().lower()
        else:
            steps = np.diff(t[np.isfinite(t)])
            unit = "ms" if len(steps) and np.median(steps) >= 0.2 else "s"
    factors = {"s": 1.0, "ms": 1e-3}
    if unit not in factors:
        raise ArgumentError(f"time unit {unit!r} is not s or ms", source=src)
    return factors[unit]
