"""Rangefinder field book: TruPulse shots from GPS stations to impact points.

Field book CSV columns (aliases accepted, see the ``*_ALIASES`` tuples)::

    point, station, instrument_height_m, target_height_m, sentence

``sentence`` is the ``$PLTIT,HV,…*cs`` line the TruPulse sent (checksum verified unless
``lenient``), quoted, or unquoted as the last column. Optional ``material`` and
``slope_deg`` columns are carried through.
Stations come from a GPX (waypoint name = station id) or a CSV (see
:mod:`fieldkit.io.stations`).

North reference of the azimuths
    A TruPulse 360 sends magnetic azimuths unless its declination was set in the
    instrument, and the ``$PLTIT,HV`` sentence does not say which. So the field book
    says it, in an ``azimuth_reference`` column (aliases ``azimuth_ref``,
    ``north_reference``): ``true`` (the instrument's declination was set,
    or the azimuths were corrected before they were written) or ``magnetic``, per
    row. A row whose azimuth is magnetic -- or unstated, because the column is absent
    or the cell empty -- needs ``declination_deg`` (0 must be given explicitly: a
    silent 0 swings every shot by the local declination, 14° at Tornado Mountain);
    the declination is added to those rows only. Given for a book whose azimuths are
    all true, it is not applied and a note says so.

Geometry of each shot
    true azimuth = magnetic azimuth + declination (east positive);
    target (lat, lon) = geodesic destination from the station along the true azimuth
    by the horizontal distance HD (``pyproj.Geod.fwd``);
    vertical difference = SD·sin(INC), or HD·tan(INC) when the sentence has no SD;
    target elevation = station elevation + instrument height + vertical difference
    - target height.

Points come out in field-book order (the order along the fall path), with section
``x`` = cumulative geodesic distance between successive targets.
"""

from __future__ import annotations

import math
from os import PathLike

import numpy as np

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io import geodesy
from fieldkit.io.csv_table import CsvTable, length_factor, read_csv_table
from fieldkit.io.point_sets import check_unique_points, point_set_from_geographic
from fieldkit.io.points_csv import (
    MATERIAL_ALIASES,
    NAME_ALIASES,
    SLOPE_ALIASES,
    check_angles,
)
from fieldkit.io.stations import read_stations
from fieldkit.io.trupulse import parse_trupulse
from fieldkit.survey import PointSet

STATION_COLUMN_ALIASES = ("station", "station_id", "stn", "from", "setup")
INSTRUMENT_HEIGHT_ALIASES = (
    "instrument_height",
    "ih",
    "hi",
    "height_of_instrument",
    "instrument_h",
)
TARGET_HEIGHT_ALIASES = ("target_height", "th", "ht", "rod_height", "target_h")
SENTENCE_ALIASES = ("sentence", "trupulse", "nmea", "message", "raw")
AZIMUTH_REFERENCE_ALIASES = ("azimuth_reference", "azimuth_ref", "north_reference")
#: Words an ``azimuth_reference`` cell may hold, and what they mean.
AZIMUTH_REFERENCES = {"true": "true", "magnetic": "magnetic", "mag": "magnetic"}


def _azimuth_references(table: CsvTable) -> list[str | None]:
    """Per row: ``"true"``, ``"magnetic"`` or None (not stated)."""
    column = table.find(AZIMUTH_REFERENCE_ALIASES)
    if column is None:
        return [None] * len(table.rows)
    out: list[str | None] = []
    for number, row in table.rows:
        text = table.cell(row, column).lower()
        if text and text not in AZIMUTH_REFERENCES:
            raise InputFileError(
                f"column '{column.header.strip()}': '{table.cell(row, column)}' is not "
                "true or magnetic",
                source=table.source,
                where=f"row {number}",
            )
        out.append(AZIMUTH_REFERENCES.get(text))
    return out


def read_fieldbook(
    path: str | PathLike[str],
    stations_path: str | PathLike[str],
    *,
    declination_deg: float | None = None,
    lenient: bool = False,
    units: str | None = None,
    epsg: int | str | None = None,
) -> PointSet:
    """Positions of rangefinder targets from a field book and station coordinates.

    Parameters
    ----------
    path
        Field book CSV.
    stations_path
        Stations GPX or CSV.
    declination_deg
        Magnetic declination added to the magnetic (or unstated) azimuths, east
        positive [deg]. Required unless the book's ``azimuth_reference`` column says
        every azimuth is true (module docstring); 0 must be given, never assumed.
    lenient
        Accept TruPulse sentences with a wrong or missing checksum (noted).
    units
        ``"m"``/``"ft"`` for height columns without a unit in their names (and for a
        stations CSV elevation); None: such a column is an error. The sentences carry
        their own units.
    epsg
        CRS for ``easting_m``/``northing_m`` (default: UTM zone of the targets).

    Returns
    -------
    PointSet
        One row per shot, ``crs`` the projected CRS, heights as the stations give them.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from fieldkit.io.trupulse import format_trupulse_hv
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "st.csv").write_text("station,lat,lon,elev_m\\nS1,49,-117,1500")
    >>> shot = format_trupulse_hv(100.0, 0.0, -10.0, 100.0 / math.cos(math.radians(10)))
    >>> _ = (folder / "fb.csv").write_text(
    ...     "point,station,instrument_height_m,target_height_m,sentence\\n"
    ...     f"A1,S1,1.5,0,{shot}\\n")
    >>> ps = read_fieldbook(folder / "fb.csv", folder / "st.csv", declination_deg=0)
    >>> round(float(ps.frame.lat_deg[0]) - 49, 6), round(float(ps.frame.z_m[0]), 2)
    (0.000899, 1483.87)
    """
    if declination_deg is not None and (
        not math.isfinite(declination_deg) or abs(declination_deg) > 180.0
    ):
        raise ArgumentError(
            f"declination {declination_deg} is not in [-180, 180] degrees",
            source="declination_deg",
        )
    table = read_csv_table(path, open_last=SENTENCE_ALIASES)
    source = table.source
    columns = table.require(
        {
            "point": NAME_ALIASES,
            "station": STATION_COLUMN_ALIASES,
            "instrument_height_m": INSTRUMENT_HEIGHT_ALIASES,
            "target_height_m": TARGET_HEIGHT_ALIASES,
            "sentence": SENTENCE_ALIASES,
        },
        "field book needs columns point, station, instrument_height_m, "
        "target_height_m, sentence",
    )
    references = _azimuth_references(table)
    magnetic = [ref != "true" for ref in references]
    if declination_deg is None and any(magnetic):
        first = magnetic.index(True)
        said = (
            "its azimuth is magnetic (azimuth_reference)"
            if references[first] == "magnetic"
            else "the book does not say whether its azimuths are true or magnetic (no "
            "azimuth_reference)"
        )
        raise ArgumentError(
            f"{said}: give the magnetic declination `declination_deg` (degrees, east "
            "positive; 0 only where it is 0), or mark true azimuths with "
            "azimuth_reference true",
            source=source,
            where=f"row {table.rows[first][0]}",
        )
    stations = read_stations(stations_path, units=units)
    ih_factor = length_factor(table, columns["instrument_height_m"], units)
    th_factor = length_factor(table, columns["target_height_m"], units)
    material_column = table.find(MATERIAL_ALIASES)
    slope_column = table.find(SLOPE_ALIASES)

    names, wheres, lats, lons, elevs = [], [], [], [], []
    materials, slopes, notes = [], [], []
    zero_azimuths = 0
    for index, (number, row) in enumerate(table.rows):
        where = f"row {number}"
        name = table.cell(row, columns["point"])
        if not name:
            raise InputFileError("point name is empty", source=source, where=where)
        where_point = f"row {number} (point {name})"
        station_id = table.cell(row, columns["station"])
        station = stations.lookup(station_id)
        if station is None:
            known = ", ".join(stations.frame["station"].astype(str).head(12))
            raise InputFileError(
                f"station '{station_id}' is not in {stations.source} (stations there: "
                f"{known})",
                source=source,
                where=where_point,
            )
        if not math.isfinite(float(station["elev_m"])):
            raise InputFileError(
                f"station '{station_id}' has no elevation in {stations.source}",
                source=source,
                where=where_point,
            )
        ih = table.number(number, row, columns["instrument_height_m"], where=where)
        th = table.number(number, row, columns["target_height_m"], where=where)
        ih *= ih_factor
        th *= th_factor
        if ih < 0 or th < 0:
            raise InputFileError(
                f"instrument and target heights must not be negative (got {ih:g} m "
                f"and {th:g} m)",
                source=source,
                where=where_point,
            )
        try:
            text = table.cell(row, columns["sentence"])
            shot = parse_trupulse(text, lenient=lenient)
        except InputFileError as error:
            raise InputFileError(
                error.message, source=source, where=where_point
            ) from None
        if shot.kind != "HV":
            raise InputFileError(
                f"{shot.kind} sentence gives no target position; shoot an HV "
                "(horizontal vector) to each point",
                source=source,
                where=where_point,
            )
        if not math.isfinite(shot.horizontal_distance_m):
            raise InputFileError(
                "inclination-only shot (no distance) cannot place a point",
                source=source,
                where=where_point,
            )
        if not shot.checksum_ok:
            notes.append(f"{where_point}: TruPulse checksum wrong, accepted (lenient)")
        if shot.azimuth_deg == 0.0:
            zero_azimuths += 1
        if math.isfinite(shot.slope_distance_m):
            rise = shot.slope_distance_m * math.sin(math.radians(shot.inclination_deg))
        else:
            rise = shot.horizontal_distance_m * math.tan(
                math.radians(shot.inclination_deg)
            )
        correction = declination_deg if magnetic[index] else 0.0
        azimuth = (shot.azimuth_deg + (correction or 0.0)) % 360.0
        lat, lon = geodesy.destination(
            float(station["lat_deg"]),
            float(station["lon_deg"]),
            azimuth,
            shot.horizontal_distance_m,
        )
        names.append(name)
        wheres.append(where)
        lats.append(float(lat))
        lons.append(float(lon))
        elevs.append(float(station["elev_m"]) + ih + rise - th)
        if material_column is not None:
            materials.append(table.cell(row, material_column) or None)
        if slope_column is not None:
            slopes.append(table.number(number, row, slope_column, required=False))
    check_unique_points(names, wheres, source)
    if zero_azimuths == len(names) and len(names) > 1:
        notes.append(
            "every azimuth is 0.00: a TruPulse 200 has no compass, so all targets "
            "were placed due north of their stations"
        )
    if declination_deg is not None and any(magnetic):
        which = (
            "every azimuth" if all(magnetic) else f"{sum(magnetic)} magnetic azimuths"
        )
        notes.append(f"declination {declination_deg:+g}° added to {which}")
    if declination_deg is not None and not all(magnetic):
        which = "every azimuth is" if not any(magnetic) else "some azimuths are"
        notes.append(
            f"the field book says {which} true: declination not applied to those"
        )
    extra: dict[str, list] = {}
    if material_column is not None:
        extra["material"] = materials
    if slope_column is not None:
        check_angles(table, slope_column, slopes, -90.0, 90.0, "a ground dip")
        extra["slope_deg"] = slopes
    reference = (
        f"station heights ({stations.height_reference}) + instrument height + "
        "SD·sin(INC) - target height"
    )
    return point_set_from_geographic(
        names,
        np.asarray(lats),
        np.asarray(lons),
        np.asarray(elevs),
        source=source,
        height_reference=reference,
        epsg=epsg,
        notes=notes,
        extra=extra or None,
        wheres=[f"{w} (point {n})" for w, n in zip(wheres, names, strict=True)],
    )
