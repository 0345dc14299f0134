"""Coordinates exported by tracking programs -> Track: columns, units, time base.

Shared by the OSP Tracker and Kinovea readers; the text itself (decoding, separator,
locale decimals, row numbers) is read by :mod:`fieldkit.io.csv_table`. Coordinates
arrive in metres, centimetres, millimetres, inches, feet or pixels; pixels need a
scale. Times may have been computed at a playback rate instead of the capture rate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io.csv_table import (
    LENGTH_UNITS,
    check_cell_count,
    parse_number,
    split_row,
)
from fieldkit.track import Track

#: Metres per unit for the length units tracking programs export.
METRES_PER_UNIT: dict[str, float] = {**LENGTH_UNITS, "in": 0.0254}
#: The unit name for pixels (needs ``metres_per_pixel``).
PIXELS = "px"


def read_number_columns(
    rows: list[tuple[int, str]],
    delimiter: str,
    header: list[str],
    columns: tuple[int, ...],
    source: str,
) -> tuple[np.ndarray, np.ndarray]:
    """Row numbers and the numbers in ``columns`` of the numbered data ``rows``.

    Cells missing at the end of a row are NaN (a value not tracked). Raises
    :class:`InputFileError` naming the row for a cell that is not a finite number,
    for more cells than ``header`` columns (:func:`check_cell_count`: decimal commas
    with a comma separator), and for no rows at all.
    """
    row_numbers, data = [], []
    for row_number, line in rows:
        where = f"row {row_number}"
        cells = check_cell_count(
            split_row(line, delimiter),
            header,
            delimiter,
            source=source,
            where=where,
            allow_short=True,
        )
        values = []
        for c in columns:
            cell = cells[c] if c < len(cells) else ""
            try:
                value = parse_number(cell, delimiter)
            except ValueError:
                raise InputFileError(
                    f"column {header[c]!r}: {cell.strip()!r} is not a number",
                    source=source,
                    where=where,
                ) from None
            if np.isinf(value):
                raise InputFileError(
                    f"column {header[c]!r}: {cell.strip()!r} is not a finite number",
                    source=source,
                    where=where,
                )
            values.append(value)
        row_numbers.append(row_number)
        data.append(values)
    if not data:
        raise InputFileError("no data rows after the header", source=source)
    return np.array(row_numbers, int), np.array(data, float)


def check_increasing_times(t: np.ndarray, row_numbers: np.ndarray, source: str):
    """Raise naming the first row whose time is not after the previous time."""
    ok = np.isfinite(t)
    steps = np.diff(t[ok])
    if np.any(steps <= 0):
        j = int(np.flatnonzero(steps <= 0)[0])
        raise InputFileError(
            "times are not increasing",
            source=source,
            where=f"row {row_numbers[ok][j + 1]}",
        )


@dataclass(frozen=True)
class LengthScale:
    """How file coordinates become metres."""

    unit: str
    metres_per_pixel: float | None = None
    y_down: bool = False

    def metres_per_unit(self, source: object) -> float:
        if self.unit == PIXELS:
            if self.metres_per_pixel is None or not self.metres_per_pixel > 0:
                raise ArgumentError(
                    "coordinates are in pixels: give the scale in metres per pixel "
                    "(`metres_per_pixel`, e.g. ball diameter in m / diameter in px)",
                    source=str(source),
                )
            return float(self.metres_per_pixel)
        if self.unit not in METRES_PER_UNIT:
            raise ArgumentError(
                f"unknown length unit {self.unit!r}; use one of "
                f"{', '.join([*METRES_PER_UNIT, PIXELS])}",
                source=str(source),
            )
        return METRES_PER_UNIT[self.unit]


def build_track(
    t: np.ndarray,
    x: np.ndarray,
    y: np.ndarray,
    *,
    scale: LengthScale,
    source: str,
    time_factor: float = 1.0,
    frames: np.ndarray | None = None,
    fps: float | None = None,
    meta: dict | None = None,
) -> Track:
    """A Track in metres (z up) from file columns; rows without time are dropped."""
    k = scale.metres_per_unit(source)
    sign = -1.0 if scale.y_down else 1.0
    keep = np.isfinite(t)
    frame = pd.DataFrame(
        {
            "frame": frames[keep] if frames is not None else np.arange(keep.sum()),
            "t_s": t[keep] * time_factor,
            "x_m": x[keep] * k,
            "z_m": sign * y[keep] * k,
        }
    )
    if len(frame) == 0:
        raise InputFileError("no data rows", source=source)
    return Track(frame, source=source, fps=fps, meta=dict(meta or {}))


def time_factor(file_fps: float | None, fps: float | None, source: object) -> float:
    """Factor turning file times into true times when the file used a playback rate.

    A clip filmed at ``fps`` (e.g. 1205) but timed at ``file_fps`` (e.g. the 30 frames/s
    stored in the video) has times ``fps / file_fps`` too long.
    """
    if file_fps is None and fps is None:
        return 1.0
    if file_fps is None or fps is None:
        raise ArgumentError(
            "give both the rate the file's times used (`file_fps`) and the capture "
            "rate (`fps`) to correct the time base",
            source=str(source),
        )
    if not (file_fps > 0 and fps > 0):
        raise ArgumentError("frame rates must be > 0", source=str(source))
    return file_fps / fps
