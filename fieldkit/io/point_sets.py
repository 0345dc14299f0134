"""Building a :class:`~fieldkit.survey.PointSet` from what a reader found.

Every point reader (GPX, CSV, rangefinder field book) ends here: geographic points get
their section ``x_m`` as the cumulative geodesic plan distance and projected
coordinates; section points are checked to run in the order of travel.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from fieldkit.errors import InputFileError
from fieldkit.io import geodesy
from fieldkit.survey import OPTIONAL_COLUMNS, PointSet


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
