"""Delimited text as tracking programs write it: any separator, locale decimals, units.

Shared by the OSP Tracker and Kinovea readers. Programs write numbers in the user's
locale: ``1.25`` or ``1,25`` (and ``1.2E-3`` or ``1,2E-3``). With a tab or semicolon
separator a comma can only be a decimal mark; with a comma separator it cannot be.
Coordinates arrive in metres, centimetres, millimetres or pixels; pixels need a scale.
"""

from __future__ import annotations

import csv
import io
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.tracking.track import Track

#: Metres per unit for the length units tracking programs export.
METRES_PER_UNIT: dict[str, float] = {
    "m": 1.0,
    "cm": 0.01,
    "mm": 0.001,
    "in": 0.0254,
    "ft": 0.3048,
}
#: The unit name for pixels (needs ``metres_per_pixel``).
PIXELS = "px"


def read_lines(path: str | os.PathLike[str]) -> list[str]:
    """The file's lines (UTF-8, else Latin-1), BOM removed; errors name the file."""
    p = Path(path)
    if not p.is_file():
        raise InputFileError("file not found", source=p)
    raw = p.read_bytes()
    if not raw.strip():
        raise InputFileError("file is empty", source=p)
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    return text.splitlines()


def detect_delimiter(header: str) -> str:
    """Tab, semicolon or comma, whichever the header line uses (else whitespace)."""
    for delim in ("\t", ";", ","):
        if delim in header:
            return delim
    return " "


def split_row(line: str, delimiter: str) -> list[str]:
    """Cells of one line, honouring double quotes (RFC 4180)."""
    if delimiter == " ":
        return line.split()
    return next(csv.reader(io.StringIO(line), delimiter=delimiter))


def parse_number(cell: str, delimiter: str) -> float:
    """A number in either locale; empty cells are NaN. Raises ValueError otherwise.

    Examples
    --------
    >>> parse_number("1,25E-3", "\\t"), parse_number("", ";"), parse_number("-0.5", ",")
    (0.00125, nan, -0.5)
    """
    text = cell.strip().strip('"').replace("\u2212", "-")
    if not text:
        return float("nan")
    if delimiter != "," and "," in text:
        if "." in text:  # thousands separators: 1.234,5
            text = text.replace(".", "")
        text = text.replace(",", ".")
    value = float(text)
    return value


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
                    "(--metres-per-pixel, e.g. ball diameter in m / diameter in px)",
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
            "give both the rate the file's times used (--file-fps) and the capture "
            "rate (--fps) to correct the time base",
            source=str(source),
        )
    if not (file_fps > 0 and fps > 0):
        raise ArgumentError("frame rates must be > 0", source=str(source))
    return file_fps / fps
