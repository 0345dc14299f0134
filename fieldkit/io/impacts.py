"""Impact points from a GPX or CSV file: the one reader of an impacts file.

:func:`read_impacts` detects the format (content first, then extension) and hands
over to :func:`read_gpx_impacts` or :func:`fieldkit.io.points_csv.read_points_csv`.
"""

from __future__ import annotations

from collections.abc import Sequence
from os import PathLike
from pathlib import Path

import numpy as np
import pandas as pd

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io.csv_table import check_readable
from fieldkit.io.gpx import GPX_HEIGHT_REFERENCE, read_gpx_waypoints
from fieldkit.io.point_sets import check_unique_points, point_set_from_geographic
from fieldkit.io.points_csv import read_points_csv
from fieldkit.survey import PointSet


def read_gpx_impacts(
    path: str | PathLike[str],
    *,
    units: str | None = None,
    epsg: int | str | None = None,
    gpx_points: str = "waypoints",
    gpx_track: str | None = None,
) -> PointSet:
    """Impact points from GPX waypoints (or the points of one route or track if asked).

    Every point needs an ``<ele>``; names must be unique. A waypoint ``<type>`` becomes
    the ``material`` column. ``<ele>`` is metres by the
    GPX standard, so ``units="ft"`` does not apply (a note says so). Several tracks or
    routes are several paths: ``gpx_track`` picks one (name or number), else it is an
    error (:mod:`fieldkit.io.gpx`, "One track, one path").
    """
    source = str(path)
    table = read_gpx_waypoints(path, points=gpx_points, track=gpx_track)
    kind = {"waypoints": "waypoint"}.get(gpx_points, "point")
    wheres = [f"{kind} {i}" for i in range(1, len(table) + 1)]
    for i, row in enumerate(table.itertuples(index=False)):
        if not np.isfinite(row.elev_m):
            raise InputFileError(
                f"{kind} '{row.point}' has no elevation (<ele>)",
                source=source,
                where=wheres[i],
            )
    names = [str(n) for n in table["point"]]
    check_unique_points(names, wheres, source)
    notes = []
    if units not in (None, "m"):
        notes.append(f"units {units} ignored: GPX <ele> is in metres by definition")
    extra: dict[str, Sequence] = {}
    if table["time"].notna().any():
        extra["time"] = table["time"]
    if table["type"].notna().any():
        extra["material"] = [None if pd.isna(t) else str(t) for t in table["type"]]
        notes.append("GPX <type> read as the slope material")
    return point_set_from_geographic(
        names,
        table["lat_deg"],
        table["lon_deg"],
        table["elev_m"],
        source=source,
        height_reference=GPX_HEIGHT_REFERENCE,
        epsg=epsg,
        notes=notes,
        extra=extra or None,
        wheres=wheres,
    )


def read_impacts(
    path: str | PathLike[str],
    *,
    units: str | None = None,
    epsg: int | str | None = None,
    gpx_points: str = "waypoints",
    gpx_track: str | None = None,
) -> PointSet:
    """Read impact points from a GPX or CSV file.

    The format comes from the content (a file starting with ``<`` is GPX) and then the
    extension (``.gpx``; ``.csv``, ``.txt``, ``.tsv``); anything else is tried as GPX
    and as CSV, and the error says what each attempt found.

    Parameters
    ----------
    path
        GPX waypoints, or CSV with ``x, z`` (section), ``lat, lon, elev`` or
        ``easting, northing, elevation`` (+ ``epsg``); see
        :func:`fieldkit.io.points_csv.read_points_csv`.
    units
        ``"m"`` or ``"ft"`` for lengths in a CSV without units in its column names
        (None: such a column is an error; GPX ``<ele>`` is metres and needs none).
    epsg
        Projected CRS of easting/northing columns, or the CRS wanted for
        ``easting_m``/``northing_m`` of geographic input (default: UTM zone).
    gpx_points
        ``"waypoints"``, ``"route"``, ``"track"`` or ``"auto"`` (GPX only).
    gpx_track
        Which track or route of a GPX with several (its name or number, 1 = first).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "impacts.csv"
    >>> _ = f.write_text("point,x_m,z_m\\nA1,0,100\\nA2,10.5,92\\n")
    >>> read_impacts(f).frame[["point", "x_m", "z_m"]].to_dict("list")
    {'point': ['A1', 'A2'], 'x_m': [0.0, 10.5], 'z_m': [100.0, 92.0]}
    """
    file = check_readable(path)
    with file.open("rb") as handle:
        head = handle.read(512).lstrip(b"\xef\xbb\xbf \t\r\n")
    suffix = Path(path).suffix.lower()
    if head.startswith(b"<") or suffix == ".gpx":
        return read_gpx_impacts(
            path, units=units, epsg=epsg, gpx_points=gpx_points, gpx_track=gpx_track
        )
    if gpx_track is not None:
        raise ArgumentError(
            f"`gpx_track` picks a track of a GPX file; {path} is not GPX",
            source="gpx_track",
        )
    if suffix in (".csv", ".txt", ".tsv"):
        return read_points_csv(path, units=units, epsg=epsg)
    try:
        return read_points_csv(path, units=units, epsg=epsg)
    except InputFileError as csv_error:
        raise InputFileError(
            "not a recognised points file: tried GPX (it does not start with XML) and "
            f"CSV ({csv_error.message})",
            source=path,
        ) from None
