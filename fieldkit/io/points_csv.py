"""Points from a CSV: section coordinates, latitude/longitude, or easting/northing.

Three layouts, recognised from the header (first match wins):

1. ``lat, lon, elev`` — WGS 84 degrees and an elevation (GNSS apps: Emlid Flow, Bad Elf,
   Trimble exports). ``x_m`` is the cumulative geodesic distance.
2. ``easting, northing, elevation`` with an EPSG code (``epsg=``) — the
   coordinates are converted to latitude/longitude with pyproj and treated as in 1.
   ``x, y`` columns count as easting/northing when an EPSG code is given.
3. ``x, y, z`` without an EPSG code — a local plan grid (site coordinates from a
   total station or a CAD drawing): section ``x_m`` is the cumulative plan distance
   ``sqrt(dx² + dy²)`` between successive points, so a path that turns, or runs along
   y, keeps its true length; the grid coordinates go to ``easting_m``/``northing_m``.
4. ``x, z`` — section coordinates directly (``x`` increasing in the direction of
   travel).

Column names are matched once, here, after lower-casing and dropping units written as
``_m``/``_ft`` suffixes or in brackets (``Altitude (ft)``); see the ``*_ALIASES``
tuples. A point-name column is optional (rows are then named 1, 2, 3 …).

Units: a unit in a column name wins; otherwise ``units`` (``"m"`` or ``"ft"``,
international feet of 0.3048 m) says what elevations and section coordinates are in.
Such a column with no unit in its name and no ``units`` is an error: metres are never
assumed. Eastings/northings are in the unit of their CRS (``units`` may still say
feet on a metre grid; a CRS in US survey feet is read in those regardless).
Latitude and longitude are never scaled.
"""

from __future__ import annotations

from os import PathLike

import numpy as np
import pandas as pd

from fieldkit.errors import InputFileError
from fieldkit.io import geodesy
from fieldkit.io.csv_table import Column, CsvTable, length_factor, read_csv_table
from fieldkit.io.point_sets import (
    check_unique_points,
    point_set_from_geographic,
    point_set_from_local_grid,
    point_set_from_section,
)
from fieldkit.survey import PointSet

NAME_ALIASES = (
    "point",
    "point_name",
    "name",
    "id",
    "point_id",
    "pt",
    "label",
    "impact",
)
LAT_ALIASES = ("lat", "latitude")
LON_ALIASES = ("lon", "long", "lng", "longitude")
ELEVATION_ALIASES = (
    "elev",
    "elevation",
    "ele",
    "z",
    "height",
    "alt",
    "altitude",
    "orthometric_height",
)
ELLIPSOIDAL_ALIASES = (
    "ellipsoidal_height",
    "ellipsoid_height",
    "height_ellipsoidal",
    "hae",
)
EASTING_ALIASES = ("easting", "east", "e")
NORTHING_ALIASES = ("northing", "north", "n")
SECTION_X_ALIASES = ("x", "chainage", "distance", "horizontal_distance")
GRID_X_ALIASES = ("x",)
GRID_Y_ALIASES = ("y",)
MATERIAL_ALIASES = ("material", "surface", "terrain", "slope_material")
SLOPE_ALIASES = ("slope", "slope_angle", "psi", "ground_slope")
THETA0_ALIASES = ("theta0", "theta_0", "restitution_angle")
TIME_ALIASES = ("time", "timestamp", "datetime", "date_time", "utc_time")


def _require_numbers(
    table: CsvTable, column: Column, factor: float = 1.0
) -> np.ndarray:
    return np.array(
        [table.number(n, row, column) * factor for n, row in table.rows], dtype=float
    )


def _check_range(
    table: CsvTable, column: Column, values: np.ndarray, low: float, high: float
) -> None:
    for (number, _), value in zip(table.rows, values, strict=True):
        if not low <= value <= high:
            raise InputFileError(
                f"column '{column.header.strip()}': {value:g} is outside "
                f"[{low:g}, {high:g}]",
                source=table.source,
                where=f"row {number}",
            )


def read_points_csv(
    path: str | PathLike[str],
    *,
    units: str | None = None,
    epsg: int | str | None = None,
) -> PointSet:
    """Read a points CSV into a :class:`PointSet` (layouts in the module docstring).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "p.csv"
    >>> _ = f.write_text("Name,Latitude,Longitude,Elevation (m)\\nA,49,-117,1500\\n"
    ...                  "B,49.0009,-117,1450\\n")
    >>> ps = read_points_csv(f)
    >>> ps.crs, round(float(ps.frame.x_m.iloc[1]), 2)
    ('EPSG:32611', 100.09)
    """
    table = read_csv_table(path)
    source = table.source
    name_column = table.find(NAME_ALIASES)
    wheres = [f"row {number}" for number, _ in table.rows]
    if name_column is not None:
        names = []
        for number, row in table.rows:
            name = table.cell(row, name_column)
            if not name:
                raise InputFileError(
                    f"column '{name_column.header.strip()}' (point name) is empty",
                    source=source,
                    where=f"row {number}",
                )
            names.append(name)
    else:
        names = [str(i) for i in range(1, len(table.rows) + 1)]
    check_unique_points(names, wheres, source)
    extra = _optional_columns(table, units)
    notes = list(extra.pop("_notes", []))
    labelled = [c.header.strip() for c in table.columns if c.unit in ("m", "mm", "cm")]
    if units not in (None, "m") and labelled:
        notes.append(
            f"units {units} not applied to {', '.join(labelled)}: the column names "
            "say metres"
        )
    if name_column is None:
        notes.append("no point-name column; points are named 1, 2, 3 … in file order")

    lat_column, lon_column = table.find(LAT_ALIASES), table.find(LON_ALIASES)
    easting_column = table.find(EASTING_ALIASES)
    northing_column = table.find(NORTHING_ALIASES)
    if easting_column is None and northing_column is None and epsg is not None:
        easting_column, northing_column = table.find(("x",)), table.find(("y",))
    x_column = table.find(SECTION_X_ALIASES)

    if lat_column is not None and lon_column is not None:
        lat = _require_numbers(table, lat_column)
        lon = _require_numbers(table, lon_column)
        _check_range(table, lat_column, lat, -90.0, 90.0)
        _check_range(table, lon_column, lon, -180.0, 180.0)
        return _geographic_points(table, units, names, lat, lon, epsg, notes, extra)
    if easting_column is not None and northing_column is not None:
        if epsg is None:
            raise InputFileError(
                f"easting/northing columns ('{easting_column.header.strip()}', "
                f"'{northing_column.header.strip()}') need the EPSG code of their "
                "projection (`epsg`, e.g. 32611 for WGS 84 / UTM zone 11N)",
                source=source,
            )
        crs = geodesy.projected_crs(epsg)
        native = geodesy.metres_per_crs_unit(crs)
        if native == 1.0:  # a metre grid: unlabelled columns are in its metres
            e_factor = length_factor(table, easting_column, units or "m")
            n_factor = length_factor(table, northing_column, units or "m")
        else:
            e_factor = n_factor = 1.0  # values are in the CRS's own unit
            notes.append(
                f"easting/northing read in {crs.axis_info[0].unit_name}, the unit of "
                f"{geodesy.crs_label(crs)}"
            )
        easting = _require_numbers(table, easting_column, e_factor)
        northing = _require_numbers(table, northing_column, n_factor)
        lat, lon = geodesy.from_projected(easting, northing, crs)
        bad = np.flatnonzero(~(np.isfinite(lat) & np.isfinite(lon)))
        if bad.size:
            raise InputFileError(
                f"easting/northing {easting[bad[0]]:g}, {northing[bad[0]]:g} cannot be "
                f"converted from {geodesy.crs_label(crs)}",
                source=source,
                where=wheres[int(bad[0])],
            )
        return _geographic_points(table, units, names, lat, lon, crs, notes, extra)
    grid_x, grid_y = table.find(GRID_X_ALIASES), table.find(GRID_Y_ALIASES)
    if grid_x is not None and grid_y is not None:
        z_column = table.find(ELEVATION_ALIASES)
        if z_column is None:
            raise InputFileError(
                f"local grid columns '{grid_x.header.strip()}', "
                f"'{grid_y.header.strip()}' found but no elevation column (one of: "
                f"{', '.join(ELEVATION_ALIASES)})",
                source=source,
                where="row 1",
            )
        return point_set_from_local_grid(
            names,
            _require_numbers(table, grid_x, length_factor(table, grid_x, units)),
            _require_numbers(table, grid_y, length_factor(table, grid_y, units)),
            _require_numbers(table, z_column, length_factor(table, z_column, units)),
            source=source,
            wheres=wheres,
            height_reference=f"column '{z_column.header.strip()}' as given",
            notes=notes,
            extra=extra,
        )
    if x_column is not None:
        z_column = table.find(ELEVATION_ALIASES)
        if z_column is None:
            raise InputFileError(
                f"section column '{x_column.header.strip()}' found but no elevation "
                f"column (one of: {', '.join(ELEVATION_ALIASES)})",
                source=source,
            )
        x = _require_numbers(table, x_column, length_factor(table, x_column, units))
        z = _require_numbers(table, z_column, length_factor(table, z_column, units))
        if epsg is not None:
            notes.append("`epsg` ignored: the file has section coordinates (x, z)")
        return point_set_from_section(
            names,
            x,
            z,
            source=source,
            wheres=wheres,
            height_reference=f"column '{z_column.header.strip()}' as given",
            notes=notes,
            extra=extra,
        )
    raise InputFileError(
        f"no coordinate columns found (have: {table.header_text()}); need lat, lon, "
        "elev or easting, northing, elevation (+ `epsg`) or x, z",
        source=source,
        where="row 1",
    )


def _geographic_points(table: CsvTable, units, names, lat, lon, epsg, notes, extra):
    """Points at ``lat``/``lon`` with the table's elevations."""
    elev, reference = _elevations(table, units)
    return point_set_from_geographic(
        names,
        lat,
        lon,
        elev,
        source=table.source,
        height_reference=reference,
        epsg=epsg,
        notes=notes,
        extra=extra,
        wheres=[f"row {number}" for number, _ in table.rows],
    )


def _elevations(table: CsvTable, units: str) -> tuple[np.ndarray, str]:
    column = table.find(ELEVATION_ALIASES)
    reference = (
        "as given (height above sea level per the receiver; no geoid conversion)"
    )
    if column is None:
        column = table.find(ELLIPSOIDAL_ALIASES)
        reference = "ellipsoidal height (WGS 84) as given; no geoid conversion"
    if column is None:
        raise InputFileError(
            f"no elevation column (one of: {', '.join(ELEVATION_ALIASES)})",
            source=table.source,
            where="row 1",
        )
    values = _require_numbers(table, column, length_factor(table, column, units))
    return values, f"column '{column.header.strip()}' {reference}"


def check_angles(
    table: CsvTable,
    column: Column,
    values: list[float],
    low: float,
    high: float,
    what: str,
) -> None:
    """Angles strictly inside (low, high) [deg] (empty cells pass); one reader's
    rule for every surveyed angle column (points CSV, field book)."""
    for (number, _), value in zip(table.rows, values, strict=True):
        if not np.isnan(value) and not low < value < high:
            raise InputFileError(
                f"column '{column.header.strip()}': {value:g}° is not {what} "
                f"(must be between {low:g} and {high:g} degrees)",
                source=table.source,
                where=f"row {number}",
            )


def _optional_columns(table: CsvTable, units: str) -> dict[str, object]:
    extra: dict[str, object] = {"_notes": []}
    material = table.find(MATERIAL_ALIASES)
    if material is not None:
        extra["material"] = [table.cell(row, material) or None for _, row in table.rows]
    slope = table.find(SLOPE_ALIASES)
    if slope is not None:
        values = [table.number(n, row, slope, required=False) for n, row in table.rows]
        check_angles(table, slope, values, -90.0, 90.0, "a ground dip")
        extra["slope_deg"] = values
    theta0 = table.find(THETA0_ALIASES)
    if theta0 is not None:
        values = [table.number(n, row, theta0, required=False) for n, row in table.rows]
        check_angles(table, theta0, values, 0.0, 180.0, "a restitution angle")
        extra["theta0_deg"] = values
    time = table.find(TIME_ALIASES)
    if time is not None:
        texts = [table.cell(row, time) or None for _, row in table.rows]
        try:
            extra["time"] = pd.Series(pd.to_datetime(texts, utc=True, format="ISO8601"))
        except (ValueError, TypeError):
            example = next((t for t in texts if t), "")
            extra["_notes"].append(  # type: ignore[union-attr]
                f"column '{time.header.strip()}' is not ISO 8601 (e.g. '{example}'); "
                "times left out"
            )
    return extra
