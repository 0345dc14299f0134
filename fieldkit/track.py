"""The Track: a body's position (and marker angle) against time, in world metres.

Every video tracker and track importer (OSP Tracker, Kinovea) returns a :class:`Track`;
flight segmentation and impact analysis read it. World axes: ``x`` horizontal along the
direction of travel, ``z`` up (ARCHITECTURE §2).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from fieldkit.errors import InputFileError

#: Columns every Track frame holds, in order. NaN where unknown.
TRACK_COLUMNS: tuple[str, ...] = (
    "frame",  # source frame index (int); -1 for imports without frames
    "t_s",  # time [s]
    "x_m",  # centre, horizontal [m]
    "z_m",  # centre, vertical, up [m]
    "angle_rad",  # marker angle (unwrapped) [rad], NaN when no marker
    "omega_radps",  # angular velocity [rad/s], NaN when no marker
)


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
