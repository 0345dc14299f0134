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


#: Fastest capture rate accepted [frames/s]: beyond the fastest scientific cameras
#: (about 1e7 frames/s); a larger number is a typo or a unit mix-up.
MAX_FPS = 1e7
#: Plausible image scales [m/px]: a microscope's 0.1 um/px to a satellite's 1 km/px;
#: a scale outside is a unit mistake and breaks the tracking arithmetic.
MIN_METRES_PER_PIXEL = 1e-7
MAX_METRES_PER_PIXEL = 1e3
#: Slowest frame rate accepted [frames/s] (a frame every ~17 minutes: time-lapse).
MIN_FPS = 1e-3
#: Shortest time step between track rows [s]: a tenth of a frame at MAX_FPS.
MIN_TIME_STEP_S = 0.1 / MAX_FPS
#: Largest time a track may hold [s] (a day): beyond it the times are in another
#: unit or the export is broken.
MAX_TRACK_TIME_S = 86_400.0
#: Largest coordinate a track may hold [m] (100 km): beyond it the length unit or
#: the scale is wrong.
MAX_TRACK_COORDINATE_M = 1e5


def check_increasing_times(t: np.ndarray, row_numbers: np.ndarray, source: str):
    """Raise naming the first row whose time is not after the previous time
    (backwards or repeated)."""
    ok = np.isfinite(t)
    steps = np.diff(t[ok])
    if np.any(steps <= 0):
        j = int(np.flatnonzero(steps <= 0)[0])
        before, this = t[ok][j], t[ok][j + 1]
        how = "repeats" if this == before else "goes back from"
        raise InputFileError(
            f"times are not increasing: {this:.9g} s {how} {before:.9g} s of the "
            "row before",
            source=source,
            where=f"row {row_numbers[ok][j + 1]}",
        )


def check_time_steps(t: np.ndarray, row_numbers: np.ndarray, source: str):
    """Raise naming the first row less than :data:`MIN_TIME_STEP_S` after the row
    before (faster than any camera: times in a wrong unit)."""
    ok = np.isfinite(t)
    steps = np.diff(t[ok])
    if np.any(steps < MIN_TIME_STEP_S):
        j = int(np.flatnonzero(steps < MIN_TIME_STEP_S)[0])
        raise InputFileError(
            f"time step {steps[j]:.3g} s from the row before is shorter than "
            f"{MIN_TIME_STEP_S:g} s (faster than any camera: a wrong time unit or "
            "frame rate?)",
            source=source,
            where=f"row {row_numbers[ok][j + 1]}",
        )


def check_track_values(
    t: np.ndarray,
    x: np.ndarray,
    z: np.ndarray,
    row_numbers: np.ndarray,
    source: str,
) -> None:
    """Raise :class:`InputFileError` naming the first bad row of a track in SI units.

    Every row needs a finite time within +/- :data:`MAX_TRACK_TIME_S`; coordinates
    may be missing (NaN: body not found) but not infinite nor beyond +/-
    :data:`MAX_TRACK_COORDINATE_M`; times must increase
    (:func:`check_increasing_times`).
    """
    row_numbers = np.asarray(row_numbers)
    checks = (
        (~np.isfinite(t), "t_s", "time is missing or not finite"),
        (np.abs(t) > MAX_TRACK_TIME_S, "t_s", f"beyond {MAX_TRACK_TIME_S:g} s"),
        (np.isinf(x), "x_m", "not finite"),
        (np.isinf(z), "z_m", "not finite"),
        (
            np.abs(x) > MAX_TRACK_COORDINATE_M,
            "x_m",
            f"beyond {MAX_TRACK_COORDINATE_M:g} m",
        ),
        (
            np.abs(z) > MAX_TRACK_COORDINATE_M,
            "z_m",
            f"beyond {MAX_TRACK_COORDINATE_M:g} m",
        ),
    )
    first = None
    for bad, column, what in checks:
        with np.errstate(invalid="ignore"):
            hits = np.flatnonzero(bad)
        if len(hits) and (first is None or hits[0] < first[0]):
            first = (int(hits[0]), column, what)
    if first is not None:
        i, column, what = first
        value = {"t_s": t, "x_m": x, "z_m": z}[column][i]
        hint = "" if "finite" in what else " (a wrong unit or scale?)"
        raise InputFileError(
            f"{column} {value:.6g}: {what}{hint}",
            source=source,
            where=f"row {row_numbers[i]}",
        )
    check_increasing_times(t, row_numbers, source)
    check_time_steps(t, row_numbers, source)


def check_frame_rate(value: float, name: str) -> float:
    """``value`` as a frame rate in (0, :data:`MAX_FPS`] frames/s, else
    :class:`ArgumentError` naming the argument ``name``."""
    if not (np.isfinite(value) and MIN_FPS <= value <= MAX_FPS):
        raise ArgumentError(
            f"{name} must be a positive frame rate of at most {MAX_FPS:g} frames/s "
            f"(and at least {MIN_FPS:g}), got {value:g}",
            source=name,
        )
    return float(value)


@dataclass(frozen=True)
class LengthScale:
    """How file coordinates become metres."""

    unit: str
    metres_per_pixel: float | None = None
    y_down: bool = False

    def metres_per_unit(self, source: object) -> float:
        if self.unit == PIXELS:
            if self.metres_per_pixel is None:
                raise ArgumentError(
                    "coordinates are in pixels: give the scale in metres per pixel "
                    "(`metres_per_pixel`, e.g. ball diameter in m / diameter in px)",
                    source=str(source),
                )
            if not (
                np.isfinite(self.metres_per_pixel)
                and MIN_METRES_PER_PIXEL
                <= self.metres_per_pixel
                <= MAX_METRES_PER_PIXEL
            ):
                raise ArgumentError(
                    f"metres_per_pixel must lie between {MIN_METRES_PER_PIXEL:g} and "
                    f"{MAX_METRES_PER_PIXEL:g} m/px, got {self.metres_per_pixel:g}",
                    source="metres_per_pixel",
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
    row_numbers: np.ndarray | None = None,
) -> Track:
    """A Track in metres (z up) from file columns; rows without time are dropped.

    With ``row_numbers`` (the file row of each value) the result is checked by
    :func:`check_track_values`, naming the file row at fault.
    """
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
    if row_numbers is not None:
        check_track_values(
            frame["t_s"].to_numpy(float),
            frame["x_m"].to_numpy(float),
            frame["z_m"].to_numpy(float),
            np.asarray(row_numbers)[keep],
            source,
        )
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
    return check_frame_rate(file_fps, "file_fps") / check_frame_rate(fps, "fps")
