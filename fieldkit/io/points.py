"""Surveyed points along a fall path: the common result of every point reader.

:class:`PointSet` is what :func:`read_impacts` (GPX or CSV), the rangefinder field book
reader and the generators hand to the survey reduction: one row per point in file
order, which is the order along the fall path, with section coordinates
(``x_m`` = cumulative plan distance, ``z_m`` = elevation) and, when known, geographic
and projected coordinates.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path

import numpy as np
import pandas as pd

from fieldkit.errors import InputFileError
from fieldkit.io import geodesy
from fieldkit.io.csv_table import check_readable

#: Columns every PointSet frame has, in this order.
POINT_COLUMNS = ("point", "x_m", "z_m", "lat_deg", "lon_deg", "easting_m", "northing_m")
#: Columns a PointSet frame may add when the source has them.
OPTIONAL_COLUMNS = ("material", "slope_deg", "theta0_deg", "time")

GPX_HEIGHT_REFERENCE = (
    "GPX <ele> as given (usually above sea level); no geoid conversion"
)


@dataclass(frozen=True)
class PointSet:
    """Points along one fall path, in order of travel.

    Attributes
    ----------
    frame
        One row per point: ``point`` (str), ``x_m``, ``z_m`` (section coordinates
        [m]), ``lat_deg``, ``lon_deg`` (WGS 84), ``easting_m``, ``northing_m`` (in
        ``crs``; NaN where unknown), optionally ``material``, ``slope_deg`` (surveyed
        ground dip, positive descending toward +x [deg]) and ``time`` (UTC).
    source
        The file the points came from.
    crs
        ``"section"`` when only section coordinates are known, else the CRS of
        ``easting_m``/``northing_m``, e.g. ``"EPSG:32611"``.
    height_reference
        What ``z_m`` is measured from, in words (heights are never converted).
    notes
        Things the reader decided or noticed that a user should know.
    """

    frame: pd.DataFrame
    source: str
    crs: str = "section"
    height_reference: str = "as given"
    notes: tuple[str, ...] = field(default_factory=tuple)

    def __len__(self) -> int:
        return len(self.frame)

    @property
    def names(self) -> list[str]:
        """Point names in order."""
        return [str(name) for name in self.frame["point"]]


def check_unique_points(
    names: Sequence[str], wheres: Sequence[str], source: str
) -> None:
    """Raise naming the point and both places if a point name occurs twice.

    Examples
    --------
    >>> check_unique_points(["A", "B"], ["row 2", "row 3"], "a.csv")
    """
    first: dict[str, str] = {}
    for name, where in zip(names, wheres, strict=True):
        if name in first:
            raise InputFileError(
                f"point '{name}' appears twice ({first[name]} and {where})",
                source=source,
                where=f"point {name}",
            )
        first[name] = where


def _optional(frame: pd.DataFrame, extra: dict[str, Sequence] | None) -> pd.DataFrame:
    for column in OPTIONAL_COLUMNS:
        if not extra or column not in extra:
            continue
        values = extra[column]
        if column == "material":
            frame[column] = pd.Series(list(values), dtype="str", index=frame.index)
        elif column in ("slope_deg", "theta0_deg"):
            frame[column] = np.asarray(list(values), dtype=float)
        else:
            frame[column] = pd.Series(values).to_numpy()
    return frame


def point_set_from_geographic(
    names: Sequence[str],
    lat_deg: Sequence[float],
    lon_deg: Sequence[float],
    elev_m: Sequence[float],
    *,
    source: str,
    height_reference: str,
    epsg: int | str | None = None,
    notes: Sequence[str] = (),
    extra: dict[str, Sequence] | None = None,
) -> PointSet:
    """Build a PointSet from WGS 84 positions and elevations.

    ``x_m`` is the cumulative geodesic distance
    (:func:`geodesy.section_from_geographic`);
    easting/northing are in ``epsg`` or, by default, the UTM zone of the points.
    """
    lat = np.asarray(lat_deg, dtype=float)
    lon = np.asarray(lon_deg, dtype=float)
    x = geodesy.section_from_geographic(lat, lon)
    easting, northing, crs = geodesy.to_projected(lat, lon, epsg)
    factor = geodesy.metres_per_crs_unit(crs)
    notes = list(notes)
    steps = np.diff(x)
    for i in np.flatnonzero(steps < 1e-3):
        notes.append(
            f"points '{names[i]}' and '{names[i + 1]}' are at the same plan position"
        )
    frame = pd.DataFrame(
        {
            "point": pd.Series([str(n) for n in names], dtype="str"),
            "x_m": x,
            "z_m": np.asarray(elev_m, dtype=float),
            "lat_deg": lat,
            "lon_deg": lon,
            "easting_m": easting * factor,
            "northing_m": northing * factor,
        }
    )
    if factor != 1.0:
        notes.append(
            f"{geodesy.crs_label(crs)} is in {crs.axis_info[0].unit_name}; "
            "easting_m/northing_m are converted to metres on that grid"
        )
    return PointSet(
        frame=_optional(frame, extra),
        source=source,
        crs=geodesy.crs_label(crs),
        height_reference=height_reference,
        notes=tuple(notes),
    )


def point_set_from_section(
    names: Sequence[str],
    x_m: Sequence[float],
    z_m: Sequence[float],
    *,
    source: str,
    wheres: Sequence[str] | None = None,
    height_reference: str = "z as given in the file",
    notes: Sequence[str] = (),
    extra: dict[str, Sequence] | None = None,
) -> PointSet:
    """Build a PointSet from section coordinates; ``x`` must not decrease."""
    x = np.asarray(x_m, dtype=float)
    wheres = list(wheres) if wheres is not None else [f"point {n}" for n in names]
    notes = list(notes)
    for i in range(1, len(x)):
        if x[i] < x[i - 1]:
            raise InputFileError(
                f"x goes backwards ({x[i]:g} m after {x[i - 1]:g} m at "
                f"{wheres[i - 1]}); points must be in order of travel with x "
                "increasing",
                source=source,
                where=wheres[i],
            )
        if x[i] == x[i - 1]:
            notes.append(f"points '{names[i - 1]}' and '{names[i]}' have the same x")
    frame = pd.DataFrame(
        {
            "point": pd.Series([str(n) for n in names], dtype="str"),
            "x_m": x,
            "z_m": np.asarray(z_m, dtype=float),
            "lat_deg": np.nan,
            "lon_deg": np.nan,
            "easting_m": np.nan,
            "northing_m": np.nan,
        }
    )
    return PointSet(
        frame=_optional(frame, extra),
        source=source,
        crs="section",
        height_reference=height_reference,
        notes=tuple(notes),
    )


def read_gpx_impacts(
    path: str | PathLike[str],
    *,
    units: str = "m",
    epsg: int | str | None = None,
    gpx_points: str = "waypoints",
) -> PointSet:
    """Impact points from GPX waypoints (or route/track points if asked).

    Every point needs an ``<ele>``; names must be unique. A waypoint ``<type>`` becomes
    the ``material`` column. ``<ele>`` is metres by the
    GPX standard, so ``units="ft"`` does not apply (a note says so).
    """
    from fieldkit.io.gpx import read_gpx_waypoints

    source = str(path)
    table = read_gpx_waypoints(path, points=gpx_points)
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
    if units != "m":
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
    )


def read_impacts(
    path: str | PathLike[str],
    *,
    units: str = "m",
    epsg: int | str | None = None,
    gpx_points: str = "waypoints",
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
        ``"m"`` or ``"ft"`` for lengths in a CSV without units in its column names.
    epsg
        Projected CRS of easting/northing columns, or the CRS wanted for
        ``easting_m``/``northing_m`` of geographic input (default: UTM zone).
    gpx_points
        ``"waypoints"``, ``"route"``, ``"track"`` or ``"auto"`` (GPX only).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "impacts.csv"
    >>> _ = f.write_text("point,x_m,z_m\\nA1,0,100\\nA2,10.5,92\\n")
    >>> read_impacts(f).frame[["point", "x_m", "z_m"]].to_dict("list")
    {'point': ['A1', 'A2'], 'x_m': [0.0, 10.5], 'z_m': [100.0, 92.0]}
    """
    from fieldkit.io.points_csv import read_points_csv

    file = check_readable(path)
    with file.open("rb") as handle:
        head = handle.read(512).lstrip(b"\xef\xbb\xbf \t\r\n")
    suffix = Path(path).suffix.lower()
    if head.startswith(b"<") or suffix == ".gpx":
        return read_gpx_impacts(path, units=units, epsg=epsg, gpx_points=gpx_points)
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
