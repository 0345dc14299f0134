"""PathObservations: observed rock-fall runs, one row per run, for path-level fitting.

A data type beside :class:`~fieldkit.survey.Survey`, :class:`~fieldkit.track.Track`
and :class:`~fieldkit.impact_table.ImpactTable`: what a designer sees of a rock fall
without measuring restitution -- where each rock was released, where it stopped,
the block, and optionally what was measured along its path (impact positions,
flight heights, speeds). The path-level fit (:mod:`fieldkit.fit.path_sections`)
turns every run into a 2-D section model.

Two tables, SI units, the unit in every column name:

* ``runs`` -- one row per run, the columns of :data:`RUN_COLUMNS` (required ones
  must be present and finite; optional ones may be NaN = not observed);
* ``along`` -- optional observations along the paths, one row per observed point,
  the columns of :data:`ALONG_COLUMNS` (``path_id`` must name a run); extra value
  columns (e.g. ``hmax_normal_m``, ``vi_mps``) are kept.

Coordinates (:attr:`PathObservations.coordinates`):

* ``"plan"`` -- x, y in a map grid (that of the DEM the sections are cut from), z
  the elevation [m];
* ``"section"`` -- already along one 2-D section (an ImpactTable): x is the
  horizontal distance along the section, y is 0.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from fieldkit.errors import ArgumentError, InputFileError

#: Per-run columns: name -> (required, meaning). NaN in an optional column: unknown.
RUN_COLUMNS: dict[str, tuple[bool, str]] = {
    "path_id": (True, "run identifier (e.g. Tschamut trajectory_id)"),
    "release_x_m": (True, "release point x [m]"),
    "release_y_m": (True, "release point y [m] (0 in section coordinates)"),
    "release_z_m": (True, "release elevation of the block centre [m]"),
    "release_ground_z_m": (False, "ground elevation under the release [m]"),
    "release_vx_mps": (False, "release velocity, x [m/s]"),
    "release_vy_mps": (False, "release velocity, y [m/s]"),
    "release_vz_mps": (False, "release velocity, z (up) [m/s]"),
    "deposit_x_m": (False, "deposit (stop) point x [m]"),
    "deposit_y_m": (False, "deposit point y [m]"),
    "deposit_z_m": (False, "deposit elevation of the block centre [m]"),
    "deposit_ground_z_m": (False, "ground elevation under the deposit [m]"),
    "mass_kg": (False, "block mass [kg]"),
    "radius_m": (False, "block contact radius [m]"),
    "gyration_m": (False, "block radius of gyration [m]"),
    "reported_runout_m": (False, "runout as the source reports it [m]"),
    "group": (False, "label to report by (e.g. the block id)"),
    "source": (False, "where the run's numbers come from"),
}
#: String columns of ``runs`` (the rest are floats).
TEXT_COLUMNS = ("path_id", "group", "source")

#: Along-path columns: name -> (required, meaning).
ALONG_COLUMNS: dict[str, tuple[bool, str]] = {
    "path_id": (True, "the run the point belongs to"),
    "point": (True, "point identifier (e.g. the impact)"),
    "x_m": (True, "x of the point [m]"),
    "y_m": (True, "y of the point [m] (0 in section coordinates)"),
    "z_m": (True, "elevation of the point [m]"),
}

COORDINATES = ("plan", "section")


@dataclass(frozen=True)
class PathObservations:
    """Observed runs (see the module docstring for the columns).

    Parameters
    ----------
    runs
        One row per run: :data:`RUN_COLUMNS` (optional ones added as NaN or "").
    along
        Observations along the paths (:data:`ALONG_COLUMNS` plus value columns), or
        None.
    coordinates
        ``"plan"`` or ``"section"``.
    source
        Where the runs came from (a file name, for messages).

    Examples
    --------
    >>> obs = PathObservations(pd.DataFrame({"path_id": ["a", "b"],
    ...     "release_x_m": [0.0, 1.0], "release_y_m": [0.0, 0.0],
    ...     "release_z_m": [10.0, 10.0], "deposit_x_m": [30.0, 40.0],
    ...     "deposit_y_m": [40.0, 0.0], "deposit_z_m": [0.0, 0.0]}))
    >>> obs.path_ids(), obs.straight_runout_m().tolist()
    (['a', 'b'], [50.0, 39.0])
    >>> len(obs.subset(["b"]))
    1
    """

    runs: pd.DataFrame
    along: pd.DataFrame | None = None
    coordinates: str = "plan"
    source: str = ""

    def __post_init__(self) -> None:
        if self.coordinates not in COORDINATES:
            raise ArgumentError(
                f"coordinates must be one of {', '.join(COORDINATES)} (got "
                f"{self.coordinates!r})",
                source="coordinates",
            )
        object.__setattr__(self, "runs", _normal_runs(self.runs, self.source))
        if self.along is not None:
            along = _normal_along(self.along, self.source)
            unknown = sorted(set(along["path_id"]) - set(self.runs["path_id"]))
            if unknown:
                raise InputFileError(
                    f"along-path observations name runs that are not in the runs: "
                    f"{', '.join(unknown[:5])}",
                    source=self.source,
                )
            object.__setattr__(self, "along", along)

    def __len__(self) -> int:
        return len(self.runs)

    def __repr__(self) -> str:
        along = "" if self.along is None else f", {len(self.along)} along-path points"
        return f"PathObservations({len(self)} runs{along}, {self.coordinates})"

    def path_ids(self) -> list[str]:
        """The run ids, in order."""
        return self.runs["path_id"].tolist()

    def row(self, path_id: str) -> pd.Series:
        """The run ``path_id`` (an unknown id is an error naming it)."""
        match = self.runs.index[self.runs["path_id"] == path_id]
        if len(match) == 0:
            raise ArgumentError(
                f"no run {path_id!r} (have {len(self)}: "
                f"{', '.join(self.path_ids()[:5])}{', ...' if len(self) > 5 else ''})",
                source="path_id",
            )
        return self.runs.loc[match[0]]

    def along_path(self, path_id: str) -> pd.DataFrame:
        """The along-path observations of run ``path_id`` (empty if none)."""
        self.row(path_id)
        if self.along is None:
            return pd.DataFrame(columns=list(ALONG_COLUMNS))
        return self.along[self.along["path_id"] == path_id].reset_index(drop=True)

    def subset(self, ids: Iterable[str]) -> PathObservations:
        """The runs ``ids`` (in that order) with their along-path observations."""
        ids = list(ids)
        for path_id in ids:
            self.row(path_id)
        runs = self.runs.set_index("path_id", drop=False).loc[ids]
        along = None
        if self.along is not None:
            along = self.along[self.along["path_id"].isin(ids)]
        return PathObservations(
            runs.reset_index(drop=True), along, self.coordinates, self.source
        )

    def straight_runout_m(self) -> np.ndarray:
        """Horizontal straight-line distance release -> deposit of every run [m]
        (NaN without a deposit)."""
        r = self.runs
        return np.hypot(
            r["deposit_x_m"].to_numpy(float) - r["release_x_m"].to_numpy(float),
            r["deposit_y_m"].to_numpy(float) - r["release_y_m"].to_numpy(float),
        )


def _normal_runs(frame: pd.DataFrame, source: str) -> pd.DataFrame:
    missing = [k for k, (req, _) in RUN_COLUMNS.items() if req and k not in frame]
    if missing:
        raise InputFileError(
            f"runs lack required column(s) {', '.join(missing)}", source=source
        )
    out = frame.copy().reset_index(drop=True)
    for name in RUN_COLUMNS:
        if name not in out:
            out[name] = "" if name in TEXT_COLUMNS else math.nan
    for name in RUN_COLUMNS:
        if name in TEXT_COLUMNS:
            out[name] = out[name].fillna("").astype(str)
        else:
            out[name] = pd.to_numeric(out[name], errors="coerce").astype(float)
    if len(out) == 0:
        raise InputFileError("no runs", source=source)
    duplicated = out["path_id"][out["path_id"].duplicated()].tolist()
    if duplicated:
        raise InputFileError(
            f"path id {duplicated[0]} appears more than once", source=source
        )
    for name, (required, _) in RUN_COLUMNS.items():
        if name in TEXT_COLUMNS:
            continue
        values = out[name].to_numpy(float)
        bad = ~np.isfinite(values) if required else np.isinf(values)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise InputFileError(
                f"{name} is not a finite number ({values[i]})",
                source=source,
                where=str(out["path_id"].iloc[i]),
            )
    for name in ("mass_kg", "radius_m", "gyration_m"):
        values = out[name].to_numpy(float)
        bad = values <= 0
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise InputFileError(
                f"{name} must be > 0 (got {values[i]:g})",
                source=source,
                where=str(out["path_id"].iloc[i]),
            )
    extra = [c for c in out.columns if c not in RUN_COLUMNS]
    return out[list(RUN_COLUMNS) + extra]


def _normal_along(frame: pd.DataFrame, source: str) -> pd.DataFrame:
    missing = [k for k in ALONG_COLUMNS if k not in frame]
    if missing:
        raise InputFileError(
            f"along-path observations lack column(s) {', '.join(missing)}",
            source=source,
        )
    out = frame.copy().reset_index(drop=True)
    out["path_id"] = out["path_id"].astype(str)
    out["point"] = out["point"].astype(str)
    for name in ("x_m", "y_m", "z_m"):
        out[name] = pd.to_numeric(out[name], errors="coerce").astype(float)
        bad = ~np.isfinite(out[name].to_numpy(float))
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise InputFileError(
                f"{name} of point {out['point'].iloc[i]} is not a finite number",
                source=source,
                where=str(out["path_id"].iloc[i]),
            )
    extra = [c for c in out.columns if c not in ALONG_COLUMNS]
    return out[list(ALONG_COLUMNS) + extra]
