"""Tree strikes: scars on trees hit by the rock in flight between two impacts.

Two CSV layouts (aliases accepted, see the ``*_ALIASES`` tuples):

1. Measured along the section::

       after_impact, horizontal_distance_m, strike_height_m [, species, dbh_mm,
       ground_z_m | ground_elev_m, tree]

   ``horizontal_distance_m`` is the plan distance from the ``after_impact`` point toward
   the next impact.

2. Tree coordinates plus strike height: ``lat, lon`` (impacts must have latitude and
   longitude), ``x, y`` on the impacts' local grid (impacts read as a local x, y, z
   grid), or section ``x_m`` (``x``), with ``strike_height_m`` and optionally
   ``after_impact``. A lat/lon or grid tree is projected in plan onto the line between
   the two impacts (along-line distance); its offset from the line is kept in
   ``offset_m``. Without ``after_impact`` the flight whose plan line passes nearest
   the tree (among those it lies between) is chosen and a note says so. With impacts
   on a local grid, a tree ``x`` without ``y`` is refused: grid x is not section x.

``strike_height_m`` is the height of the scar above the ground at the tree. The ground
elevation at the tree (``ground_z_m``) is NaN unless the file gives it; the reduction
then interpolates it on the line between the two impacts.

``units`` (``"m"``/``"ft"``) gives the unit of distances, strike heights and ground
elevations without a unit in their column names (without it such a column is an
error); ``dbh`` is read from ``dbh_mm``, ``dbh_cm`` or ``dbh_in`` (``dbh``: mm).

Strike heights above :data:`MAX_STRIKE_HEIGHT_M` (taller than any tree) and ground
elevations beyond the sane range of :mod:`fieldkit.io.point_sets` are refused, naming
the row.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from os import PathLike

import numpy as np
import pandas as pd

from fieldkit.errors import InputFileError
from fieldkit.io import geodesy
from fieldkit.io.csv_table import Column, CsvTable, length_factor, read_csv_table
from fieldkit.io.point_sets import LOCAL_GRID, MAX_ELEVATION_M, check_coordinates
from fieldkit.io.points_csv import LAT_ALIASES, LON_ALIASES
from fieldkit.survey import TREE_COLUMNS, PointSet, TreeStrikes

#: Highest strike accepted [m]: the tallest measured tree (a coast redwood) is 116 m.
MAX_STRIKE_HEIGHT_M = 120.0

AFTER_IMPACT_ALIASES = ("after_impact", "after", "from_impact", "impact", "after_point")
DISTANCE_ALIASES = (
    "horizontal_distance",
    "distance",
    "distance_from_impact",
    "hd",
    "dx",
)
STRIKE_HEIGHT_ALIASES = ("strike_height", "scar_height", "height", "impact_height")
GROUND_ALIASES = ("ground_z", "ground_elev", "ground_elevation", "ground")
SPECIES_ALIASES = ("species", "tree_species")
TREE_ALIASES = ("tree", "tree_id", "name", "id")
SECTION_X_ALIASES = ("x", "x_section", "chainage")
GRID_Y_ALIASES = ("y",)
DBH_UNITS = {"mm": 1.0, "cm": 10.0, "in": 25.4}


def _dbh_column(table: CsvTable) -> tuple[Column | None, float]:
    column = table.find(("dbh", "dbh_in", "dbh_cm", "dbh_mm"), "the dbh")
    if column is None:
        return None, 1.0
    if column.name != "dbh":
        return column, DBH_UNITS[column.name[4:]]
    unit = column.unit or "mm"
    if unit not in DBH_UNITS:
        raise InputFileError(
            f"column '{column.header.strip()}': dbh unit must be mm, cm or in",
            source=table.source,
            where="row 1",
        )
    return column, DBH_UNITS[unit]


def read_trees(
    path: str | PathLike[str], impacts: PointSet, *, units: str | None = None
) -> TreeStrikes:
    """Read tree strikes and tie each to the flight it interrupted.

    Parameters
    ----------
    path
        Tree CSV (layouts in the module docstring).
    impacts
        The impacts of the same path (from :func:`fieldkit.io.impacts.read_impacts`).
    units
        ``"m"`` or ``"ft"`` for lengths without units in their column names (None:
        such a column is an error).

    Raises
    ------
    InputFileError
        Unknown ``after_impact`` (names the row and the impact), the last impact (no
        flight follows), a distance outside the flight (0 < d < flight length), a
        negative strike height, text in a number, missing columns.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from fieldkit.io.point_sets import point_set_from_section
    >>> impacts = point_set_from_section(["A", "B"], [0.0, 12.0], [100.0, 90.0],
    ...                                  source="impacts.csv")
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "trees.csv"
    >>> _ = f.write_text("after_impact,horizontal_distance_m,strike_height_m\\n"
    ...                  "A,5,2.5\\n")
    >>> read_trees(f, impacts).frame[["after_impact", "horizontal_distance_m"]].values
    array([['A', 5.0]], dtype=object)
    """
    table = read_csv_table(path)
    source = table.source
    names = impacts.names
    index_of = {name: i for i, name in enumerate(names)}
    x_impacts = impacts.frame["x_m"].to_numpy(float)

    after_column = table.find(AFTER_IMPACT_ALIASES)
    distance_column = table.find(DISTANCE_ALIASES)
    height_column = table.find(STRIKE_HEIGHT_ALIASES)
    lat_column, lon_column = table.find(LAT_ALIASES), table.find(LON_ALIASES)
    x_column = table.find(SECTION_X_ALIASES)
    y_column = table.find(GRID_Y_ALIASES)
    grid = impacts.crs == LOCAL_GRID
    ground_column = table.find(GROUND_ALIASES)
    species_column = table.find(SPECIES_ALIASES)
    tree_column = table.find(TREE_ALIASES)
    dbh_column, dbh_factor = _dbh_column(table)
    have = table.header_text()
    if height_column is None:
        raise InputFileError(
            f"tree strikes need a strike_height_m column (have: {have})",
            source=source,
            where="row 1",
        )
    if distance_column is not None:
        mode = "distance"
        if after_column is None:
            raise InputFileError(
                "a horizontal_distance_m column needs an after_impact column",
                source=source,
                where="row 1",
            )
    elif lat_column is not None and lon_column is not None:
        mode = "geographic"
        if not impacts.frame["lat_deg"].notna().all():
            raise InputFileError(
                f"trees are given by latitude/longitude but the impacts "
                f"({impacts.source}) have only section coordinates",
                source=source,
                where="row 1",
            )
    elif x_column is not None and grid:
        if y_column is None or x_column.name != "x":
            raise InputFileError(
                f"the impacts ({impacts.source}) are on a local x, y grid: give each "
                "tree's grid x and y, or after_impact + horizontal_distance_m "
                f"(have: {have})",
                source=source,
                where="row 1",
            )
        mode = "grid"
    elif x_column is not None:
        mode = "section"
    else:
        raise InputFileError(
            "tree strikes need after_impact + horizontal_distance_m, or lat/lon, or "
            f"x_m (have: {have})",
            source=source,
            where="row 1",
        )
    height_factor = length_factor(table, height_column, units)
    ground_factor = (
        length_factor(table, ground_column, units) if ground_column is not None else 1.0
    )

    records, notes = [], []
    for number, row in table.rows:
        where = f"row {number}"
        after = table.cell(row, after_column) if after_column is not None else ""
        if after and after not in index_of:
            raise InputFileError(
                f"tree strike after impact '{after}', which is not an impact in "
                f"{impacts.source}",
                source=source,
                where=where,
            )
        if after and index_of[after] == len(names) - 1:
            raise InputFileError(
                f"impact '{after}' is the last impact: no flight follows it",
                source=source,
                where=where,
            )
        offset = math.nan
        if mode == "distance":
            factor = length_factor(table, distance_column, units)
            distance = table.number(number, row, distance_column) * factor
        elif mode == "grid":
            tree_x = table.number(number, row, x_column) * length_factor(
                table, x_column, units
            )
            tree_y = table.number(number, row, y_column) * length_factor(
                table, y_column, units
            )
            after, distance, offset, note = _place_on_grid(
                impacts, after, tree_x, tree_y, source, where
            )
            if note:
                notes.append(note)
        elif mode == "section":
            x_tree = table.number(number, row, x_column) * length_factor(
                table, x_column, units
            )
            if not after:
                inside = np.flatnonzero(
                    (x_impacts[:-1] < x_tree) & (x_tree < x_impacts[1:])
                )
                if inside.size == 0:
                    raise InputFileError(
                        f"tree at x = {x_tree:g} m is not between two impacts "
                        f"(x from {x_impacts[0]:g} to {x_impacts[-1]:g} m)",
                        source=source,
                        where=where,
                    )
                after = names[int(inside[0])]
            distance = x_tree - x_impacts[index_of[after]]
        else:
            lat = table.number(number, row, lat_column)
            lon = table.number(number, row, lon_column)
            after, distance, offset, note = _place_geographic(
                impacts, after, lat, lon, source, where
            )
            if note:
                notes.append(note)
        i = index_of[after]
        length = x_impacts[i + 1] - x_impacts[i]
        if not 0.0 < distance < length:
            raise InputFileError(
                f"horizontal distance {distance:.6g} m is outside the flight from "
                f"'{after}' to '{names[i + 1]}' (must be between 0 and "
                f"{length:.3f} m)",
                source=source,
                where=where,
            )
        height = table.number(number, row, height_column) * height_factor
        if height < 0:
            raise InputFileError(
                f"strike height {height:g} m is negative", source=source, where=where
            )
        if height > MAX_STRIKE_HEIGHT_M:
            raise InputFileError(
                f"strike height {height:g} m is above {MAX_STRIKE_HEIGHT_M:g} m, "
                "taller than any tree (a typo or the wrong unit?)",
                source=source,
                where=where,
            )
        ground = (
            table.number(number, row, ground_column, required=False) * ground_factor
            if ground_column is not None
            else math.nan
        )
        if math.isfinite(ground):
            check_coordinates(
                [ground],
                "ground elevation",
                MAX_ELEVATION_M,
                source=source,
                wheres=[where],
            )
        species = table.cell(row, species_column) if species_column else ""
        dbh = (
            table.number(number, row, dbh_column, required=False) * dbh_factor
            if dbh_column is not None
            else math.nan
        )
        if dbh < 0:
            raise InputFileError(
                f"dbh {dbh:g} mm is negative", source=source, where=where
            )
        tree = (table.cell(row, tree_column) if tree_column else "") or where
        records.append(
            (
                after,
                distance,
                height,
                ground,
                species or None,
                dbh,
                tree,
                number,
                offset,
            )
        )
    frame = pd.DataFrame.from_records(records, columns=TREE_COLUMNS)
    for column in ("after_impact", "tree", "species"):
        frame[column] = pd.Series(list(frame[column]), dtype="str")
    return TreeStrikes(frame=frame, source=source, notes=tuple(notes))


def _place_geographic(
    impacts: PointSet, after: str, lat: float, lon: float, source: str, where: str
) -> tuple[str, float, float, str]:
    """(after_impact, along-line distance, offset, note) of a lat/lon tree."""
    lats = impacts.frame["lat_deg"].to_numpy(float)
    lons = impacts.frame["lon_deg"].to_numpy(float)

    def project(i: int) -> tuple[float, float, float]:
        along, across, length = geodesy.along_and_across(
            lats[i], lons[i], lats[i + 1], lons[i + 1], [lat], [lon]
        )
        return float(along[0]), float(across[0]), float(length)

    return _nearest_flight(
        impacts, after, project, f"{lat:.7f}, {lon:.7f}", source, where
    )


def _place_on_grid(
    impacts: PointSet, after: str, x: float, y: float, source: str, where: str
) -> tuple[str, float, float, str]:
    """(after_impact, along-line distance, offset, note) of a tree on the local grid."""
    gx = impacts.frame["easting_m"].to_numpy(float)
    gy = impacts.frame["northing_m"].to_numpy(float)

    def project(i: int) -> tuple[float, float, float] | None:
        dx, dy = gx[i + 1] - gx[i], gy[i + 1] - gy[i]
        length = math.hypot(dx, dy)
        if length == 0.0:
            return None
        along = ((x - gx[i]) * dx + (y - gy[i]) * dy) / length
        across = ((x - gx[i]) * dy - (y - gy[i]) * dx) / length  # right of the line
        return along, across, length

    return _nearest_flight(
        impacts, after, project, f"x = {x:g}, y = {y:g}", source, where
    )


def _nearest_flight(
    impacts: PointSet,
    after: str,
    project: Callable[[int], tuple[float, float, float] | None],
    position: str,
    source: str,
    where: str,
) -> tuple[str, float, float, str]:
    """The flight a tree stands on, in plan: ``after`` if given, else the flight whose
    plan line passes nearest among those the tree lies between. ``project(i)`` gives
    the tree's ``(along, across, length)`` on the plan line of flight ``i`` (None for a
    line of zero length)."""
    names = impacts.names
    candidates = [names.index(after)] if after else range(len(names) - 1)
    best = None
    for i in candidates:
        placed = project(i)
        if placed is None:
            continue
        along, across, length = placed
        if after or 0.0 < along < length:
            if best is None or abs(across) < abs(best[2]):
                best = (i, along, across)
    if best is None:
        raise InputFileError(
            f"tree at {position} is not between any two successive impacts "
            "in plan; give after_impact",
            source=source,
            where=where,
        )
    i, along, across = best
    note = ""
    if not after:
        note = (
            f"{where}: no after_impact given; tree placed on the flight "
            f"'{names[i]}' → '{names[i + 1]}' ({abs(across):.1f} m from its plan line)"
        )
    return names[i], along, across, note
