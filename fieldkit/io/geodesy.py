"""Geodesy for field surveys: geodesic distances, UTM zones and projected coordinates.

Everything goes through pyproj (PROJ and GeographicLib underneath):

* distances and azimuths on the WGS 84 ellipsoid with ``pyproj.Geod(ellps="WGS84")``
  (``inv`` and ``fwd``), accurate to a few nanometres;
* projections with ``Transformer.from_crs(..., always_xy=True)`` so that coordinates are
  always (longitude, latitude) or (easting, northing) in that order;
* the UTM zone of a site from ``pyproj.database.query_utm_crs_info``.

The section coordinate ``x`` is the cumulative *geodesic* plan distance between
successive points, not a distance measured on the UTM grid: the grid scale factor
(0.9996 on the central meridian to about 1.0004 at a zone edge) would bias a 600 m
path by up to 0.25 m.

Heights are never converted here (no geoid grids are available): they are carried as
given and labelled by the readers.

A CRS given by the user must fit the points: :func:`check_area_of_use` refuses points
farther than :data:`AREA_OF_USE_MARGIN_DEG` outside the CRS's EPSG area of use
(``pyproj.CRS.area_of_use``), e.g. EPSG:32755 (UTM 55S, Australia) for a site in
Canada, naming the CRS, its area and the first point outside.
:func:`to_projected` applies it whenever a CRS is given.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

import numpy as np
import pyproj
from numpy.typing import ArrayLike, NDArray
from pyproj.aoi import AreaOfInterest
from pyproj.database import query_utm_crs_info

from fieldkit.errors import ArgumentError

#: The WGS 84 ellipsoid used for every geodesic computation.
GEOD = pyproj.Geod(ellps="WGS84")

#: Geographic WGS 84, the CRS of GPX files and GNSS latitude/longitude columns.
WGS84_GEOGRAPHIC = "EPSG:4326"

#: How far outside a CRS's area of use a point may lie [deg]. EPSG areas are the
#: official extents (a UTM zone is a 6° band), but a site straddling a zone edge is
#: often kept in one zone, where the projection is still accurate (scale error
#: ~1e-4 one degree past the edge at mid-latitudes); a wrong zone or hemisphere is
#: many degrees off.
AREA_OF_USE_MARGIN_DEG = 1.0


def _latitude_text(lat: float) -> str:
    return f"{abs(lat):.5f}°{'N' if lat >= 0 else 'S'}"


def _longitude_text(lon: float) -> str:
    return f"{abs(lon):.5f}°{'E' if lon >= 0 else 'W'}"


def check_area_of_use(
    crs: pyproj.CRS,
    lat_deg: ArrayLike,
    lon_deg: ArrayLike,
    *,
    names: Sequence[str] | None = None,
    source: str | None = None,
) -> None:
    """Raise if a point lies outside the area of use of ``crs`` (beyond the margin).

    Parameters
    ----------
    crs
        The CRS the user chose (its ``area_of_use``; a CRS without one passes).
    lat_deg, lon_deg
        WGS 84 positions of the points [deg].
    names, source
        Point names and their file, for the message.

    Raises
    ------
    ArgumentError
        ``source="epsg"``, naming the CRS, its area (bounds and name) and the first
        point outside it.

    Examples
    --------
    >>> check_area_of_use(pyproj.CRS.from_epsg(32611), [49.97], [-114.68])
    >>> check_area_of_use(pyproj.CRS.from_epsg(32755), [49.97], [-114.68],
    ...                   names=["A"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fieldkit.errors.ArgumentError: epsg: EPSG:32755 (WGS 84 / UTM zone 55S) is for...
    """
    area = crs.area_of_use
    if area is None:
        return
    west, south, east, north = area.bounds
    lat = np.atleast_1d(np.asarray(lat_deg, dtype=float))
    lon = np.atleast_1d(np.asarray(lon_deg, dtype=float))
    m = AREA_OF_USE_MARGIN_DEG
    inside = (lat >= south - m) & (lat <= north + m)
    if east - west >= 360.0 - 2 * m:
        pass  # the whole circle of longitude
    elif west <= east:
        inside &= (lon >= west - m) & (lon <= east + m)
    else:  # the area crosses the antimeridian
        inside &= (lon >= west - m) | (lon <= east + m)
    outside = np.flatnonzero(~inside)
    if outside.size == 0:
        return
    i = int(outside[0])
    name = names[i] if names is not None else str(i + 1)
    where = f" of {source}" if source else ""
    text = area.name if len(area.name) <= 90 else area.name[:87].rstrip() + "..."

    def lon_text(value: float) -> str:
        return f"{abs(value):g}°{'E' if value >= 0 else 'W'}"

    def lat_text(value: float) -> str:
        return f"{abs(value):g}°{'N' if value >= 0 else 'S'}"

    raise ArgumentError(
        f"{crs_label(crs)} ({crs.name}) is for {lon_text(west)} to {lon_text(east)}, "
        f"{lat_text(south)} to {lat_text(north)} ({text}); point {name}{where} at "
        f"{_latitude_text(float(lat[i]))}, {_longitude_text(float(lon[i]))} lies "
        f"outside it ({outside.size} of {lat.size} points do): give the EPSG code of "
        "the zone the points are in",
        source="epsg",
    )


def geodesic_inverse(
    lat1_deg: ArrayLike, lon1_deg: ArrayLike, lat2_deg: ArrayLike, lon2_deg: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Geodesic between two points on the WGS 84 ellipsoid.

    Parameters
    ----------
    lat1_deg, lon1_deg, lat2_deg, lon2_deg
        Latitude and longitude of the two points [deg].

    Returns
    -------
    distance_m, forward_azimuth_deg, back_azimuth_deg
        Length of the geodesic [m]; azimuth at point 1 towards point 2 and at point 2
        towards point 1, clockwise from north in [0, 360) [deg].

    Examples
    --------
    >>> d, az, back = geodesic_inverse(0.0, 0.0, 0.0, 1.0)
    >>> round(float(d), 3), round(float(az), 6)
    (111319.491, 90.0)
    """
    lat1, lon1, lat2, lon2 = (
        np.array(a, dtype=float)
        for a in np.broadcast_arrays(lat1_deg, lon1_deg, lat2_deg, lon2_deg)
    )
    forward, back, distance = GEOD.inv(lon1, lat1, lon2, lat2)
    return (
        np.asarray(distance, dtype=float),
        np.mod(np.asarray(forward, dtype=float), 360.0),
        np.mod(np.asarray(back, dtype=float), 360.0),
    )


def section_from_geographic(
    lat_deg: ArrayLike, lon_deg: ArrayLike
) -> NDArray[np.float64]:
    """Section ``x``: cumulative geodesic plan distance along a sequence of points.

    Parameters
    ----------
    lat_deg, lon_deg
        Latitudes and longitudes of the points in order along the path [deg].

    Returns
    -------
    x_m
        0 at the first point, then the running sum of the geodesic distances between
        successive points [m] (docs/architecture.md §2).

    Examples
    --------
    >>> section_from_geographic([0.0, 0.0, 0.0], [0.0, 0.001, 0.002]).round(4)
    array([  0.    , 111.3195, 222.639 ])
    """
    lat = np.atleast_1d(np.asarray(lat_deg, dtype=float))
    lon = np.atleast_1d(np.asarray(lon_deg, dtype=float))
    if lat.shape != lon.shape:
        raise ArgumentError("latitude and longitude arrays differ in length")
    if lat.size == 0:
        return np.zeros(0)
    if lat.size == 1:
        return np.zeros(1)
    steps, _, _ = geodesic_inverse(lat[:-1], lon[:-1], lat[1:], lon[1:])
    return np.concatenate([[0.0], np.cumsum(np.atleast_1d(steps))])


def destination(
    lat_deg: ArrayLike,
    lon_deg: ArrayLike,
    azimuth_deg: ArrayLike,
    distance_m: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Point reached along a geodesic from a start point (direct problem).

    Parameters
    ----------
    lat_deg, lon_deg
        Start point [deg].
    azimuth_deg
        Geodesic azimuth at the start, clockwise from true north [deg].
    distance_m
        Length along the ellipsoid [m].

    Returns
    -------
    lat_deg, lon_deg
        The end point [deg].

    Examples
    --------
    >>> lat, lon = destination(49.0, -117.0, 0.0, 100.0)
    >>> round(float(lat - 49.0), 7), round(float(lon), 9)
    (0.0008992, -117.0)
    """
    lat, lon, azimuth, distance = (
        np.array(a, dtype=float)
        for a in np.broadcast_arrays(lat_deg, lon_deg, azimuth_deg, distance_m)
    )
    lon2, lat2, _ = GEOD.fwd(lon, lat, azimuth, distance)
    return np.asarray(lat2, dtype=float), np.asarray(lon2, dtype=float)


def utm_crs_for(lat_deg: ArrayLike, lon_deg: ArrayLike) -> pyproj.CRS:
    """WGS 84 / UTM CRS for a site, chosen from the point nearest its centre.

    Uses ``pyproj.database.query_utm_crs_info`` at the mean position of the points,
    with the Norway (32V) and Svalbard (31X-37X) zone exceptions applied on top (the
    EPSG areas of use are plain 6° bands).

    Examples
    --------
    >>> utm_crs_for([49.5], [-117.5]).to_epsg()
    32611
    >>> utm_crs_for([-37.95], [144.42]).to_epsg()
    32755
    """
    lat = np.asarray(lat_deg, dtype=float).ravel()
    lon = np.asarray(lon_deg, dtype=float).ravel()
    if lat.size == 0 or not (np.all(np.isfinite(lat)) and np.all(np.isfinite(lon))):
        raise ArgumentError("a UTM zone needs finite latitudes and longitudes")
    centre_lat = float(np.mean(lat))
    # Mean longitude on the circle, so that sites across the antimeridian work.
    centre_lon = math.degrees(
        math.atan2(np.mean(np.sin(np.radians(lon))), np.mean(np.cos(np.radians(lon))))
    )
    if not -80.0 <= centre_lat <= 84.0:
        raise ArgumentError(
            f"latitude {centre_lat:.4f} is outside the UTM system (80°S to 84°N); "
            "give a projected EPSG code"
        )
    return _utm_crs(round(centre_lat, 6), round(centre_lon, 6))


@functools.lru_cache(maxsize=64)
def _utm_crs(lat: float, lon: float) -> pyproj.CRS:
    infos = query_utm_crs_info(
        datum_name="WGS 84",
        area_of_interest=AreaOfInterest(
            west_lon_degree=lon,
            south_lat_degree=lat,
            east_lon_degree=lon,
            north_lat_degree=lat,
        ),
    )
    if not infos:  # pragma: no cover - every valid lat/lon has a zone
        raise ArgumentError(f"no UTM zone found for latitude {lat}, longitude {lon}")
    zone = _utm_zone_number(lat, lon)
    standard = str((32600 if lat >= 0 else 32700) + zone)
    codes = [info.code for info in infos]
    if standard in codes or _is_exception_zone(lat, lon):
        return pyproj.CRS.from_epsg(int(standard))
    return pyproj.CRS.from_epsg(int(codes[0]))  # pragma: no cover - defensive


def _is_exception_zone(lat: float, lon: float) -> bool:
    return (56.0 <= lat < 64.0 and 3.0 <= lon < 12.0) or (
        72.0 <= lat < 84.0 and 0.0 <= lon < 42.0
    )


def _utm_zone_number(lat: float, lon: float) -> int:
    """UTM zone with the Norway (32V) and Svalbard (31X-37X) exceptions."""
    if 56.0 <= lat < 64.0 and 3.0 <= lon < 12.0:
        return 32
    if 72.0 <= lat < 84.0 and 0.0 <= lon < 42.0:
        return 31 if lon < 9.0 else 33 if lon < 21.0 else 35 if lon < 33.0 else 37
    return int((lon + 180.0) // 6.0) % 60 + 1


def projected_crs(epsg: int | str) -> pyproj.CRS:
    """A projected CRS from an EPSG code (``32611``, ``"32611"`` or ``"EPSG:32611"``).

    Raises :class:`ArgumentError` for unknown codes and for geographic CRSs.
    """
    text = str(epsg).strip()
    code = text if ":" in text else f"EPSG:{text}"
    try:
        crs = pyproj.CRS.from_user_input(code)
    except pyproj.exceptions.CRSError:
        raise ArgumentError(f"unknown CRS '{epsg}'", source="epsg") from None
    if not crs.is_projected:
        raise ArgumentError(
            f"{code} ({crs.name}) is not a projected CRS with easting/northing",
            source="epsg",
        )
    return crs


def crs_label(crs: pyproj.CRS) -> str:
    """``"EPSG:32611"`` when the CRS has an EPSG code, else its name."""
    code = crs.to_epsg()
    return f"EPSG:{code}" if code is not None else crs.name


def metres_per_crs_unit(crs: pyproj.CRS) -> float:
    """Length of one easting/northing unit of a projected CRS in metres."""
    return float(crs.axis_info[0].unit_conversion_factor)


@functools.lru_cache(maxsize=64)
def _transformer(source: str, target: str) -> pyproj.Transformer:
    return pyproj.Transformer.from_crs(source, target, always_xy=True)


def to_projected(
    lat_deg: ArrayLike,
    lon_deg: ArrayLike,
    crs: pyproj.CRS | int | str | None = None,
    *,
    names: Sequence[str] | None = None,
    source: str | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64], pyproj.CRS]:
    """Easting and northing of WGS 84 latitudes/longitudes in a projected CRS.

    Parameters
    ----------
    lat_deg, lon_deg
        WGS 84 coordinates [deg].
    crs
        Target projected CRS (pyproj CRS or EPSG code); ``None`` picks the UTM zone of
        the points with :func:`utm_crs_for`. A given CRS must contain the points
        (:func:`check_area_of_use`).
    names, source
        Point names and file, for the area-of-use message.

    Returns
    -------
    easting, northing, crs
        Coordinates in the CRS's own unit (metres for UTM) and the CRS used.

    Examples
    --------
    >>> e, n, crs = to_projected([0.0], [-117.0])
    >>> crs.to_epsg(), round(float(e[0]), 3), round(float(n[0]), 3)
    (32611, 500000.0, 0.0)
    """
    lat = np.asarray(lat_deg, dtype=float)
    lon = np.asarray(lon_deg, dtype=float)
    if crs is None:
        target = utm_crs_for(lat, lon)
    else:
        target = _as_projected(crs)
        check_area_of_use(target, lat, lon, names=names, source=source)
    transformer = _transformer(WGS84_GEOGRAPHIC, target.to_wkt())
    easting, northing = transformer.transform(lon, lat)
    return np.asarray(easting, dtype=float), np.asarray(northing, dtype=float), target


def to_utm(
    lat_deg: ArrayLike, lon_deg: ArrayLike, epsg: int | str | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64], str]:
    """UTM easting and northing [m] and the CRS label (zone chosen unless given).

    Examples
    --------
    >>> e, n, label = to_utm([49.0], [-117.0])
    >>> label, round(float(e[0]), 3)
    ('EPSG:32611', 500000.0)
    """
    easting, northing, crs = to_projected(lat_deg, lon_deg, epsg)
    return easting, northing, crs_label(crs)


def from_projected(
    easting: ArrayLike, northing: ArrayLike, crs: pyproj.CRS | int | str
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """WGS 84 latitude and longitude [deg] of projected coordinates.

    ``easting`` and ``northing`` are in the CRS's own unit.

    Examples
    --------
    >>> lat, lon = from_projected([500000.0], [0.0], 32611)
    >>> round(float(lat[0]), 9), round(float(lon[0]), 9)
    (0.0, -117.0)
    """
    source = _as_projected(crs)
    transformer = _transformer(source.to_wkt(), WGS84_GEOGRAPHIC)
    lon, lat = transformer.transform(
        np.asarray(easting, dtype=float), np.asarray(northing, dtype=float)
    )
    return np.asarray(lat, dtype=float), np.asarray(lon, dtype=float)


def _as_projected(crs: pyproj.CRS | int | str) -> pyproj.CRS:
    if isinstance(crs, pyproj.CRS):
        if not crs.is_projected:
            raise ArgumentError(f"{crs.name} is not a projected CRS", source="epsg")
        return crs
    return projected_crs(crs)


def along_and_across(
    lat_start: float,
    lon_start: float,
    lat_end: float,
    lon_end: float,
    lat_deg: ArrayLike,
    lon_deg: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64], float]:
    """Project points onto the plan line from a start to an end point.

    Uses the geodesic distance ``d`` and azimuth ``a`` from the start to each point and
    the azimuth ``b`` of the line: along = d·cos(a - b), across = d·sin(a - b)
    (positive to the right of the line). Over rockfall distances (< 1 km) this local
    projection differs from a rigorous one by well under a millimetre.

    Returns
    -------
    along_m, across_m, length_m
        Distance along the line from the start, offset from the line, and the length
        of the line (geodesic) [m].
    """
    length, line_azimuth, _ = geodesic_inverse(lat_start, lon_start, lat_end, lon_end)
    lat = np.asarray(lat_deg, dtype=float)
    lon = np.asarray(lon_deg, dtype=float)
    distance, azimuth, _ = geodesic_inverse(
        np.full_like(lat, lat_start), np.full_like(lon, lon_start), lat, lon
    )
    angle = np.radians(azimuth - line_azimuth)
    return distance * np.cos(angle), distance * np.sin(angle), float(length)
