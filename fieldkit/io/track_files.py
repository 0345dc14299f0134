"""Which kind of file is this, and a Track from any track file.

:func:`detect_format` tells an ImpactTable, a fieldkit track CSV, an OSP Tracker
export and a Kinovea CSV apart by their first lines; :func:`read_track` reads any of
the three track kinds into a :class:`~fieldkit.track.Track`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fieldkit.errors import InputFileError
from fieldkit.impact_table import REQUIRED_COLUMNS
from fieldkit.io.csv_table import (
    detect_delimiter,
    numbered_lines,
    read_text,
    split_row,
)
from fieldkit.io.kinovea import read_kinovea
from fieldkit.io.osp_tracker import read_osp_tracker
from fieldkit.io.tracking_export import (
    check_frame_rate,
    check_track_values,
    time_factor,
)
from fieldkit.track import Track, is_track_header

#: What :func:`detect_format` can answer.
FORMATS = ("impacts", "track", "tracker", "kinovea")


def detect_format(path: Path) -> str:
    """``impacts``, ``track``, ``tracker`` or ``kinovea`` from a file's first lines."""
    if path.suffix.lower() in (".parquet", ".xlsx"):
        return "impacts"
    lines = [ln for ln in read_text(path, kind="input").splitlines()[:3] if ln.strip()]
    first = lines[0].strip()
    delimiter = detect_delimiter(first, default=" ")
    cells = [c.strip().strip('"') for c in split_row(first, delimiter)]
    if first.lower().startswith("#multi"):
        return "tracker"
    if set(REQUIRED_COLUMNS) <= set(cells):
        return "impacts"
    if is_track_header(cells):
        return "track"
    if (
        cells
        and cells[0].lower().startswith("time")
        and any("x" in c.lower() for c in cells[1:])
    ):
        return "kinovea"
    if len(lines) > 1:
        second = lines[1]
        delimiter = detect_delimiter(second, default=" ")
        names = {c.strip() for c in split_row(second, delimiter)}
        if "t" in names and names & {"x", "y"}:  # a missing axis is reported later
            return "tracker"
    raise InputFileError(
        "cannot tell what this file is (ImpactTable, track CSV, Tracker or Kinovea "
        "export); give `input_format`",
        source=path,
        where="row 1",
    )


def read_track(
    path: Path,
    fmt: str,
    *,
    unit: str | None = None,
    metres_per_pixel: float | None = None,
    y_down: bool | None = None,
    fps: float | None = None,
    file_fps: float | None = None,
) -> Track:
    """A Track from a fieldkit track CSV (``fmt="track"``), an OSP Tracker export
    (``"tracker"``) or a Kinovea CSV (``"kinovea"``).

    ``fps``/``file_fps`` correct times that a file wrote at a playback rate
    (:func:`fieldkit.io.tracking_export.time_factor`).
    """
    if fmt == "tracker":
        track = read_osp_tracker(
            path,
            unit=unit or "m",
            metres_per_pixel=metres_per_pixel,
            fps=fps,
            file_fps=file_fps,
        )
        if unit is None:  # the export does not say: state Tracker's default
            track.meta.setdefault("notes", []).append(
                "Tracker export read in metres (Tracker's default length unit; the "
                "file does not say): give `unit` if its calibration used another"
            )
        return track
    if fmt == "kinovea":
        return read_kinovea(
            path,
            unit=unit,
            metres_per_pixel=metres_per_pixel,
            y_down=y_down,
            fps=fps,
            file_fps=file_fps,
        )
    if fps is not None and file_fps is None:
        check_frame_rate(fps, "fps")
    track = Track.read(path, fps=fps)
    if fps is not None or file_fps is not None:
        track.frame["t_s"] = track.frame["t_s"] * time_factor(file_fps, fps, path)
    # Track.read keeps every data row: they are the file's non-blank lines after the
    # header, as pandas reads them
    rows = [n for n, _ in numbered_lines(read_text(path, kind="input"))[1:]]
    if len(rows) == len(track):
        check_track_values(track.t, track.x, track.z, np.array(rows), str(path))
    else:  # a quoted cell over several lines: no exact row numbers
        check_track_values(
            track.t, track.x, track.z, np.arange(2, len(track) + 2), str(path)
        )
    return track
