"""A slope profile from a CSV of section vertices: ``x, z[, material]``.

One row per vertex, in order down the section::

    x_m,z_m,material
    0,100,rock
    12,80,talus
    40,62,

``x`` (aliases: chainage, distance, station) is the horizontal distance along the
section, strictly increasing; ``z`` (elevation, elev, height) the ground elevation.
``material`` names the material of the segment that *starts* at the row's vertex, so
the last row's cell names no segment (it may be empty; a name there is not used).
Without a material column, :attr:`ProfileVertices.material` is None.

Units as every reader here (:func:`fieldkit.io.csv_table.length_factor`): a unit in
the column name (``x_m``, ``Elevation (ft)``) wins, else ``units`` (``"m"`` or
``"ft"``); a length column with neither is an error. The plan coordinates
``plan_x_m``, ``plan_y_m`` that ``fieldkit profile`` writes are read when both are
filled in on every row; other columns are ignored.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from os import PathLike

import numpy as np

from fieldkit.errors import InputFileError
from fieldkit.io.csv_table import length_factor, read_csv_table

#: Largest chainage [m]: 100 km, beyond any slope section.
MAX_CHAINAGE_M = 100_000.0

#: Largest elevation size [m]: the Earth's surface lies between -10,994 m (the
#: Challenger Deep) and 8,849 m (Everest).
MAX_ELEVATION_M = 11_000.0

#: Shortest segment [m]: the profile CSV is written to 0.1 mm, and a surveyed
#: section has no vertices a millimetre apart (RocFall's export needs as much).
MIN_SEGMENT_M = 1e-3

X_ALIASES = ("x", "chainage", "distance", "station")
Z_ALIASES = ("z", "elevation", "elev", "height", "ground_z")
MATERIAL_ALIASES = ("material", "materials", "surface")


def check_profile_vertices(
    x_m: np.ndarray,
    z_m: np.ndarray,
    *,
    source: str,
    where: Callable[[str, int], str],
) -> None:
    """Refuse vertices no slope section has, naming the first (one check for every
    profile: this CSV, a model file's vertex lists, a RocFall slope).

    A chainage beyond :data:`MAX_CHAINAGE_M`, an elevation beyond
    :data:`MAX_ELEVATION_M`, or a vertex closer than :data:`MIN_SEGMENT_M` after
    the one before it (vertices out of order are left to the caller, which names
    them in its own terms). ``where(axis, i)`` names vertex ``i``'s ``axis`` (``"x"``
    or ``"z"``) for the message, e.g. ``"row 7: column 'z_m'"`` or
    ``"profile.z_m[5]"``. The values are finite (each reader checks that first).

    Examples
    --------
    >>> check_profile_vertices(
    ...     np.array([0.0, 10.0]), np.array([100.0, 1e12]), source="m.json",
    ...     where=lambda axis, i: f"profile.{axis}_m[{i}]")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fieldkit.errors.InputFileError: m.json: profile.z_m[1]: 1e+12 m is not an ...
    """
    for axis, values, limit, what in (
        ("x", x_m, MAX_CHAINAGE_M, "a chainage (100 km, beyond any slope section)"),
        ("z", z_m, MAX_ELEVATION_M, "an elevation on Earth (-10,994 to 8,849 m)"),
    ):
        beyond = np.flatnonzero(np.abs(values) > limit)
        if beyond.size:
            i = int(beyond[0])
            raise InputFileError(
                f"{values[i]:g} m is not {what}: at most {limit:,.0f} m in size",
                source=source,
                where=where(axis, i),
            )
    steps = np.diff(x_m)
    short = np.flatnonzero((steps > 0) & (steps < MIN_SEGMENT_M))
    if short.size:
        i = int(short[0])
        raise InputFileError(
            f"vertices {steps[i]:.3g} m apart; segments must be at least "
            f"{MIN_SEGMENT_M * 1e3:g} mm long (no surveyed section has vertices "
            "closer; the profile CSV is written to 0.1 mm)",
            source=source,
            where=where("x", i + 1),
        )


@dataclass(frozen=True)
class ProfileVertices:
    """Profile vertices read from a CSV, in metres.

    Attributes
    ----------
    x_m, z_m
        ``(n,)`` section vertices [m], x strictly increasing, n >= 2.
    material
        ``(n-1,)`` material of each segment, or None without a material column.
    source
        The file.
    plan_x_m, plan_y_m
        ``(n,)`` plan coordinates of the vertices [m], or None.
    """

    x_m: np.ndarray
    z_m: np.ndarray
    material: tuple[str, ...] | None
    source: str
    plan_x_m: np.ndarray | None = None
    plan_y_m: np.ndarray | None = None


def read_profile_csv(
    path: str | PathLike[str], units: str | None = None
) -> ProfileVertices:
    """Read profile vertices (format in the module docstring).

    Raises
    ------
    InputFileError
        Missing x or z column, text or non-finite numbers, fewer than two vertices,
        x not strictly increasing (names the row), a material cell left empty above
        the last row.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "profile.csv"
    >>> _ = f.write_text("x_ft,z_ft,material\\n0,100,rock\\n10,90,\\n")
    >>> p = read_profile_csv(f)
    >>> p.x_m.round(4).tolist(), p.z_m.round(4).tolist(), p.material
    ([0.0, 3.048], [30.48, 27.432], ('rock',))
    """
    table = read_csv_table(path)
    source = table.source
    columns = table.require(
        {"x": X_ALIASES, "z": Z_ALIASES}, "a profile CSV needs columns x, z"
    )
    x_column, z_column = columns["x"], columns["z"]
    x_factor = length_factor(table, x_column, units)
    z_factor = length_factor(table, z_column, units)
    material_column = table.find(MATERIAL_ALIASES, "the material")
    rows = table.rows
    if len(rows) < 2:
        raise InputFileError(
            f"a profile needs at least 2 vertices (got {len(rows)})",
            source=source,
            where=f"row {rows[0][0]}",
        )
    x = np.array([table.number(n, row, x_column) for n, row in rows]) * x_factor
    z = np.array([table.number(n, row, z_column) for n, row in rows]) * z_factor
    headers = {"x": x_column.header.strip(), "z": z_column.header.strip()}
    check_profile_vertices(
        x, z, source=source,
        where=lambda axis, i: f"row {rows[i][0]}: column '{headers[axis]}'",
    )  # fmt: skip
    steps = np.diff(x)
    if (steps <= 0).any():
        i = int(np.flatnonzero(steps <= 0)[0])
        header = x_column.header.strip()
        raise InputFileError(
            f"column '{header}' must increase down the section: "
            f"{table.cell(rows[i + 1][1], x_column)} after "
            f"{table.cell(rows[i][1], x_column)}",
            source=source,
            where=f"row {rows[i + 1][0]}",
        )
    material = None
    if material_column is not None:
        names = [table.cell(row, material_column) for _, row in rows[:-1]]
        for (number, _), name in zip(rows[:-1], names, strict=True):
            if not name:
                raise InputFileError(
                    f"column '{material_column.header.strip()}' is empty: every "
                    "vertex but the last starts a segment, which needs a material",
                    source=source,
                    where=f"row {number}",
                )
        material = tuple(names)
    plan = [table.find((name,)) for name in ("plan_x", "plan_y")]
    plan_xy: list[np.ndarray | None] = [None, None]
    if all(plan) and all(table.cell(row, c) for _, row in rows for c in plan):
        plan_xy = [
            np.array([table.number(n, row, c) for n, row in rows])
            * length_factor(table, c, units)
            for c in plan
        ]
    return ProfileVertices(
        x_m=x, z_m=z, material=material, source=source, plan_x_m=plan_xy[0],
        plan_y_m=plan_xy[1],
    )  # fmt: skip
