"""Building a :class:`~fieldkit.survey.PointSet` from what a reader found.

Every point reader (GPX, CSV, rangefinder field book) ends here: geographic points get
their section ``x_m`` as the cumulative geodesic plan distance and projected
coordinates; points on a local x, y grid the cumulative plan distance
``sqrt(dx² + dy²)``; section points are checked to run in the order of travel.

Coordinates must be sane before any physics sees them (:func:`check_coordinates`):
plan coordinates (section ``x``, local ``x``/``y``) within
:data:`MAX_PLAN_COORDINATE_M` = 10,000 km and elevations within
:data:`MAX_ELEVATION_M` = 11,000 m of zero. Beyond that a value is a typo, a unit
mix-up or an overflow waiting to happen (``1e308`` is a finite number, but its square
is not), and the error names the file and the row or point.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from fieldkit.errors import InputFileError
from fieldkit.io import geodesy
from fieldkit.survey import OPTIONAL_COLUMNS, PointSet

#: Largest plan coordinate accepted [m]: a quarter meridian. A fall path, or a local
#: grid coordinate, beyond it is a typo.
MAX_PLAN_COORDINATE_M = 1.0e7
#: Largest elevation magnitude accepted [m]: deeper than the deepest ocean trench
#: (10,935 m) and higher than the highest summit (8,849 m). A height in feet read as
#: metres stays inside only below 3,350 m.
MAX_ELEVATION_M = 11_000.0
#: What a PointSet's ``crs`` says for points on a local x, y grid.
LOCAL_GRID = "local grid"


def check_coordinates(
    values: Sequence[float] | np.ndarray,
    what: str,
    limit: float,
    *,
    source: str,
    wheres: Sequence[str],
) -> None:
    """Raise naming the first row/point whose ``what`` is not finite or beyond ±limit.

    Examples
    --------
    >>> check_coordinates([0.0, 1e308], "x", MAX_PLAN_COORDINATE_M, source="a.csv",
    ...                   wheres=["row 2", "row 3"])
    Traceback (most recent call last):
    ...
    fieldkit.errors.InputFileError: a.csv: row 3: x 1e+308 m is beyond ±1e+07 m (...)
    """
    array = np.asarray(values, dtype=float)
    bad = np.flatnonzero(~(np.abs(array) <= limit))  # NaN and inf fail too
    if bad.size:
        i = int(bad[0])
        raise InputFileError(
            f"{what} {array[i]:g} m is beyond ±{limit:g} m (a typo or the wrong unit?)",
            source=source,
            where=wheres[i],
        )


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
    wheres: Sequence[str] | None = None,
) -> PointSet:
    """Build a PointSet from WGS 84 positions and elevations.

    ``x_m`` is the cumulative geodesic distance
    (:func:`geodesy.section_from_geographic`);
    easting/northing are in ``epsg`` (which must contain the points,
    :func:`geodesy.check_area_of_use`) or, by default, the UTM zone of the points.
    ``wheres`` (e.g. ``"row 7"``) name the points in errors.
    """
    lat = np.asarray(lat_deg, dtype=float)
    lon = np.asarray(lon_deg, dtype=float)
    wheres = list(wheres) if wheres is not None else [f"point {n}" for n in names]
    check_coordinates(
        elev_m, "elevation", MAX_ELEVATION_M, source=source, wheres=wheres
    )
    x = geodesy.section_from_geographic(lat, lon)
    easting, northing, crs = geodesy.to_projected(
        lat, lon, epsg, names=[str(n) for n in names], source=source
    )
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
    check_coordinates(x, "x", MAX_PLAN_COORDINATE_M, source=source, wheres=wheres)
    check_coordinates(z_m, "z", MAX_ELEVATION_M, source=source, wheres=wheres)
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


def point_set_from_local_grid(
    names: Sequence[str],
    x_m: Sequence[float],
    y_m: Sequence[float],
    z_m: Sequence[float],
    *,
    source: str,
    wheres: Sequence[str] | None = None,
    height_reference: str = "z as given in the file",
    notes: Sequence[str] = (),
    extra: dict[str, Sequence] | None = None,
) -> PointSet:
    """Build a PointSet from points on a local plan grid (x, y) with elevations z.

    Section ``x_m`` is the cumulative plan distance ``sum sqrt(dx² + dy²)`` between
    successive points (docs/architecture.md §2), not the grid ``x``; the grid
    coordinates are kept in ``easting_m``/``northing_m`` with ``crs``
    :data:`LOCAL_GRID`.

    Examples
    --------
    >>> ps = point_set_from_local_grid(["A", "B", "C"], [0.0, 3.0, 3.0],
    ...                                [0.0, 4.0, 10.0], [9.0, 5.0, 1.0],
    ...                                source="grid.csv")
    >>> ps.frame["x_m"].tolist(), ps.crs
    ([0.0, 5.0, 11.0], 'local grid')
    """
    gx = np.asarray(x_m, dtype=float)
    gy = np.asarray(y_m, dtype=float)
    wheres = list(wheres) if wheres is not None else [f"point {n}" for n in names]
    check_coordinates(gx, "x", MAX_PLAN_COORDINATE_M, source=source, wheres=wheres)
    check_coordinates(gy, "y", MAX_PLAN_COORDINATE_M, source=source, wheres=wheres)
    check_coordinates(z_m, "z", MAX_ELEVATION_M, source=source, wheres=wheres)
    steps = np.hypot(np.diff(gx), np.diff(gy))
    notes = list(notes)
    notes.append(
        "x, y, z read as a local plan grid (no EPSG code): section x is the "
        "cumulative plan distance sqrt(dx² + dy²) between successive points"
    )
    for i in np.flatnonzero(steps < 1e-3):
        notes.append(
            f"points '{names[i]}' and '{names[i + 1]}' are at the same plan position"
        )
    frame = pd.DataFrame(
        {
            "point": pd.Series([str(n) for n in names], dtype="str"),
            "x_m": np.concatenate([[0.0], np.cumsum(steps)]) if len(gx) else gx,
            "z_m": np.asarray(z_m, dtype=float),
            "lat_deg": np.nan,
            "lon_deg": np.nan,
            "easting_m": gx,
            "northing_m": gy,
        }
    )
    return PointSet(
        frame=_optional(frame, extra),
        source=source,
        crs=LOCAL_GRID,
        height_reference=height_reference,
        notes=tuple(notes),
    )
