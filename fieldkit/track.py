"""The Track: a body's position (and marker angle) against time, in world metres.

One of the three data types of fieldkit (docs/architecture.md §1), beside
:class:`~fieldkit.survey.Survey` and :class:`~fieldkit.impact_table.ImpactTable`.
Every video tracker and track importer (OSP Tracker, Kinovea) returns a :class:`Track`;
flight segmentation and impact analysis read it. World axes: ``x`` horizontal along the
direction of travel, ``z`` up (docs/architecture.md §2).

fieldkit's own track file is a CSV of :data:`TRACK_COLUMNS` (plus any extra columns,
e.g. ``flight``, ``u_px``) written by :meth:`Track.write` and read by
:meth:`Track.read`; :func:`is_track_header` recognises it.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from fieldkit.errors import InputFileError
from fieldkit.outputs import OutputSet, write_file

#: Columns every Track frame holds, in order. NaN where unknown.
TRACK_COLUMNS: tuple[str, ...] = (
    "frame",  # source frame index (int); -1 for imports without frames
    "t_s",  # time [s]
    "x_m",  # centre, horizontal [m]
    "z_m",  # centre, vertical, up [m]
    "angle_rad",  # marker angle (unwrapped) [rad], NaN when no marker
    "omega_radps",  # angular velocity [rad/s], NaN when no marker
)
#: Columns a file must have to be read as a fieldkit track.
TRACK_FILE_REQUIRED: tuple[str, ...] = ("t_s", "x_m", "z_m")


def is_track_header(cells: Iterable[str]) -> bool:
    """True when a header row names the columns of a fieldkit track file.

    Examples
    --------
    >>> is_track_header(["frame", "t_s", "x_m", "z_m"]), is_track_header(["t", "x"])
    (True, False)
    """
    return set(TRACK_FILE_REQUIRED) <= {c.strip() for c in cells}


@dataclass
class Track:
    """Positions of one body through time.

    Parameters
    ----------
    frame
        A DataFrame with at least :data:`TRACK_COLUMNS`; extra columns (``u_px``,
        ``v_px``, ``radius_px``, ``flight``, ``residual_m``, ...) are kept.
    source
        File the track came from.
    fps
        Capture rate [frames/s] where known.
    meta
        Free-form provenance (calibration, detector settings, warnings).
    """

    frame: pd.DataFrame
    source: str = ""
    fps: float | None = None
    meta: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        missing = [c for c in TRACK_COLUMNS if c not in self.frame.columns]
        for c in missing:
            if c in ("frame",):
                self.frame[c] = -1
            elif c in ("t_s", "x_m", "z_m"):
                raise InputFileError(
                    f"track lacks column {c}", source=self.source or None
                )
            else:
                self.frame[c] = np.nan
        extras = [c for c in self.frame.columns if c not in TRACK_COLUMNS]
        self.frame = self.frame[list(TRACK_COLUMNS) + extras].reset_index(drop=True)

    def __len__(self) -> int:
        return len(self.frame)

    @property
    def t(self) -> np.ndarray:
        return self.frame["t_s"].to_numpy(float)

    @property
    def x(self) -> np.ndarray:
        return self.frame["x_m"].to_numpy(float)

    @property
    def z(self) -> np.ndarray:
        return self.frame["z_m"].to_numpy(float)

    # ------------------------------------------------------------------ files
    @classmethod
    def read(cls, path: str | os.PathLike[str], *, fps: float | None = None) -> Track:
        """Read a fieldkit track CSV (written by :meth:`write`).

        Raises
        ------
        InputFileError
            Unreadable file, a missing ``t_s``/``x_m``/``z_m`` column, or text in a
            number (naming the row).
        """
        try:
            frame = pd.read_csv(path)
        except (ValueError, OSError, pd.errors.ParserError) as exc:
            raise InputFileError(f"cannot read CSV: {exc}", source=path) from None
        for col in TRACK_FILE_REQUIRED:
            if col not in frame:
                raise InputFileError(
                    f"track lacks column {col}", source=path, where="row 1"
                )
            values = pd.to_numeric(frame[col], errors="coerce")
            bad = frame[col].notna() & values.isna()
            if bad.any():
                row = int(bad.to_numpy().nonzero()[0][0]) + 2
                raise InputFileError(
                    f"column {col}: {frame[col][bad].iloc[0]!r} is not a number",
                    source=path,
                    where=f"row {row}",
                )
            frame[col] = values
        return cls(frame, source=str(path), fps=fps)

    def write(
        self, path: str | os.PathLike[str], *, outputs: OutputSet | None = None
    ) -> Path:
        """Write the track as CSV (9 significant digits).

        Into ``outputs`` (written when the set commits) or, without one, at once
        (:func:`fieldkit.outputs.write_file`). A track file holds numbers for
        programs, not text for spreadsheets, so no cell is quoted.
        """
        frame = self.frame
        return write_file(
            path,
            lambda tmp: frame.to_csv(tmp, index=False, float_format="%.9g"),
            outputs,
        )
