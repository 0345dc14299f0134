"""Instrument stations for rangefinder shots: GPS positions from a GPX or a CSV.

* GPX: each waypoint is a station, its ``<name>`` the station id; ``<ele>`` required for
  any station a shot uses.
* CSV: ``station, lat, lon, elev_m`` (aliases: ``name``/``id``/``point`` for the id,
  the latitude/longitude/elevation aliases of :mod:`fieldkit.io.points_csv`).
"""

from __future__ import annotations

from os import PathLike

import numpy as np
import pandas as pd

from fieldkit.errors import InputFileError
from fieldkit.io.csv_table import check_readable, length_factor, read_csv_table
from fieldkit.io.gpx import GPX_HEIGHT_REFERENCE, read_gpx_waypoints
from fieldkit.io.point_sets import check_unique_points
from fieldkit.io.points_csv import ELEVATION_ALIASES, LAT_ALIASES, LON_ALIASES
from fieldkit.survey import Stations

STATION_ALIASES = ("station", "station_id", "stn", "name", "id", "point", "point_id")


def read_stations(path: str | PathLike[str], *, units: str | None = None) -> Stations:
    """Read stations from a GPX (waypoints) or CSV file (by content, then extension).

    ``units`` (``"m"``/``"ft"``) applies to a CSV elevation column without a unit in
    its name; such a column without ``units`` is an error (GPX ``<ele>`` is metres).
    """
    file = check_readable(path)
    with file.open("rb") as handle:
        head = handle.read(512).lstrip(b"\xef\xbb\xbf \t\r\n")
    source = str(path)
    if head.startswith(b"<") or file.suffix.lower() == ".gpx":
        table = read_gpx_waypoints(path)
        names = [str(n) for n in table["point"]]
        check_unique_points(
            names, [f"waypoint {i}" for i in range(1, len(names) + 1)], source
        )
        frame = pd.DataFrame(
            {
                "station": pd.Series(names, dtype="str"),
                "lat_deg": table["lat_deg"].to_numpy(float),
                "lon_deg": table["lon_deg"].to_numpy(float),
                "elev_m": table["elev_m"].to_numpy(float),
            }
        )
        return Stations(frame, source, GPX_HEIGHT_REFERENCE)
    table = read_csv_table(path)
    wanted = table.require(
        {
            "station": STATION_ALIASES,
            "lat": LAT_ALIASES,
            "lon": LON_ALIASES,
            "elev": ELEVATION_ALIASES,
        },
        "stations CSV needs columns station, lat, lon, elev_m",
    )
    names, lats, lons, elevs, wheres = [], [], [], [], []
    elev_factor = length_factor(table, wanted["elev"], units)
    for number, row in table.rows:
        name = table.cell(row, wanted["station"])
        if not name:
            raise InputFileError(
                "station id is empty", source=source, where=f"row {number}"
            )
        lat = table.number(number, row, wanted["lat"])
        lon = table.number(number, row, wanted["lon"])
        if not (-90.0 <= lat <= 90.0 and -180.0 <= lon <= 180.0):
            raise InputFileError(
                f"station '{name}': latitude/longitude {lat:g}, {lon:g} out of range",
                source=source,
                where=f"row {number}",
            )
        names.append(name)
        lats.append(lat)
        lons.append(lon)
        elevs.append(table.number(number, row, wanted["elev"]) * elev_factor)
        wheres.append(f"row {number}")
    check_unique_points(names, wheres, source)
    frame = pd.DataFrame(
        {
            "station": pd.Series(names, dtype="str"),
            "lat_deg": np.asarray(lats, dtype=float),
            "lon_deg": np.asarray(lons, dtype=float),
            "elev_m": np.asarray(elevs, dtype=float),
        }
    )
    reference = (
        f"column '{wanted['elev'].header.strip()}' of {source} as given; "
        "no geoid conversion"
    )
    return Stations(frame, source, reference)
