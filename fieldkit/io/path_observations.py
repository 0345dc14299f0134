"""Path observations in: a release/deposit CSV pair, or an ImpactTable.

:func:`read_release_deposit` reads two CSV files matched by run id, as the Tschamut
2014 data set gives them (``tests/data/tschamut2014/``)::

    releases: trajectory_id, x_m, y_m, z_m [, ground_z_m, vx_mps, vy_mps, vz_mps,
              block_id, mass_kg, radius_m, source, ...]
    deposits: trajectory_id, x_m, y_m, z_m [, ground_z_m, release_x_m, release_y_m,
              release_z_m, observed_runout_m, block_id, mass_kg, radius_m, ...]

Any other column is ignored. ``path_id`` (or ``id``) may stand for ``trajectory_id``;
lengths may carry any unit of :data:`fieldkit.io.csv_table.LENGTH_UNITS` in their
names (``x_ft``), and a length column without one is an error. Both files go through
:func:`fieldkit.io.csv_table.read_csv_table` (strict cells, numbered rows).

Every problem is one line naming the file, the row and the run:

* a required column missing (named, with the header);
* text, ``nan`` or ``inf`` in a number (the row and the column);
* a run id twice in a file, or in one file only (the ids named);
* a deposit higher than its release (upslope: both elevations);
* a deposit file whose ``release_x_m/y_m/z_m`` or ``mass_kg``/``radius_m``
  disagree with the release file (by more than 1 cm / 1 g / 1 mm).

:func:`observations_from_impact_table` turns an ImpactTable (surveyed impacts from
``reduce``) into section-coordinate observations: release = the first impact of each
path, deposit = the last, and every impact an along-path observation.
"""

from __future__ import annotations

import math
from os import PathLike

import numpy as np
import pandas as pd

from fieldkit.errors import InputFileError
from fieldkit.impact_table import ImpactTable, flight_value_markers
from fieldkit.io.csv_table import CsvTable, length_factor, read_csv_table
from fieldkit.path_observations import PathObservations

ID_ALIASES = ("trajectory_id", "path_id", "id")
_XYZ = {"x": ("x",), "y": ("y",), "z": ("z",)}
_RELEASE_OPTIONAL = {
    "ground_z": ("ground_z",),
    "vx": ("vx_mps",),
    "vy": ("vy_mps",),
    "vz": ("vz_mps",),
    "mass": ("mass_kg",),
    "radius": ("radius",),
    "gyration": ("gyration",),
    "group": ("block_id", "group", "block"),
    "source": ("source",),
}
_DEPOSIT_OPTIONAL = {
    "ground_z": ("ground_z",),
    "release_x": ("release_x",),
    "release_y": ("release_y",),
    "release_z": ("release_z",),
    "runout": ("observed_runout",),
    "mass": ("mass_kg",),
    "radius": ("radius",),
}
_LENGTHS = {"x", "y", "z", "ground_z", "radius", "gyration", "release_x",
            "release_y", "release_z", "runout"}  # fmt: skip
#: Agreement required between the two files: position [m], mass [kg], radius [m].
POSITION_TOLERANCE_M = 0.01
MASS_TOLERANCE_KG = 1e-3
RADIUS_TOLERANCE_M = 1e-3


def _read(path, optional: dict, what: str) -> tuple[CsvTable, list[dict]]:
    """Rows of one file as dicts of numbers (SI) plus ``id``, ``row``, text fields."""
    table = read_csv_table(path)
    aliases = {"id": ID_ALIASES, **_XYZ}
    columns = table.require(aliases, f"{what} CSV needs columns trajectory_id, x_m, "
                            "y_m, z_m")  # fmt: skip
    for key, names in optional.items():
        column = table.find(names, key)
        if column is not None:
            columns[key] = column
    factors = {
        key: length_factor(table, column, None)
        for key, column in columns.items()
        if key in _LENGTHS
    }
    rows, seen = [], {}
    for number, cells in table.rows:
        path_id = table.cell(cells, columns["id"])
        if not path_id:
            raise InputFileError(
                f"column '{columns['id'].header.strip()}' is empty",
                source=table.source,
                where=f"row {number}",
            )
        if path_id in seen:
            raise InputFileError(
                f"run {path_id} appears twice (rows {seen[path_id]} and {number})",
                source=table.source,
                where=f"row {number}",
            )
        seen[path_id] = number
        record: dict = {"id": path_id, "row": number}
        for key, column in columns.items():
            if key == "id":
                continue
            if key in ("group", "source"):
                record[key] = table.cell(cells, column)
                continue
            value = table.number(number, cells, column, required=key in _XYZ,
                                 where=f"row {number} ({path_id})")  # fmt: skip
            record[key] = value * factors.get(key, 1.0)
        rows.append(record)
    return table, rows


def _ids_text(ids: list[str]) -> str:
    shown = ", ".join(ids[:8])
    return shown + (f" and {len(ids) - 8} more" if len(ids) > 8 else "")


def read_release_deposit(
    releases: str | PathLike[str], deposits: str | PathLike[str]
) -> PathObservations:
    """Read a release CSV and a deposit CSV, matched by run id (module docstring).

    Parameters
    ----------
    releases
        One row per run: where it was released (block centre), optional velocity
        and block.
    deposits
        One row per run: where it stopped.

    Returns
    -------
    PathObservations
        In plan coordinates, runs in the order of the release file; ``source`` the
        release file. The deposit file's ``observed_runout_m`` is kept as
        ``reported_runout_m``; ``block_id`` becomes ``group``.

    Raises
    ------
    InputFileError
        One line naming the file, the row and the run (module docstring).

    Examples
    --------
    >>> from pathlib import Path
    >>> folder = Path("tests/data/tschamut2014/calibration_split")
    >>> obs = read_release_deposit(folder / "calibration_release_points.csv",
    ...                            folder / "calibration_observed_deposition.csv")
    >>> len(obs), obs.path_ids()[0], round(float(obs.straight_runout_m()[0]), 2)
    (18, 'v020', 110.23)
    """
    rel_table, rel = _read(releases, _RELEASE_OPTIONAL, "release")
    dep_table, dep = _read(deposits, _DEPOSIT_OPTIONAL, "deposit")
    rel_ids = [r["id"] for r in rel]
    dep_by_id = {d["id"]: d for d in dep}
    only_rel = [i for i in rel_ids if i not in dep_by_id]
    only_dep = [d["id"] for d in dep if d["id"] not in set(rel_ids)]
    if only_rel:
        raise InputFileError(
            f"run(s) {_ids_text(only_rel)} have no deposit in {dep_table.source}",
            source=rel_table.source,
        )
    if only_dep:
        raise InputFileError(
            f"run(s) {_ids_text(only_dep)} have no release in {rel_table.source}",
            source=dep_table.source,
        )
    records = []
    for r in rel:
        d = dep_by_id[r["id"]]
        where = f"row {d['row']} ({r['id']})"
        for key, tol, unit in (
            ("release_x", POSITION_TOLERANCE_M, "m"),
            ("release_y", POSITION_TOLERANCE_M, "m"),
            ("release_z", POSITION_TOLERANCE_M, "m"),
            ("mass", MASS_TOLERANCE_KG, "kg"),
            ("radius", RADIUS_TOLERANCE_M, "m"),
        ):
            mine = d.get(key, math.nan)
            theirs = r.get(key[8:] if key.startswith("release_") else key, math.nan)
            if np.isfinite(mine) and np.isfinite(theirs) and abs(mine - theirs) > tol:
                raise InputFileError(
                    f"{key} {mine:g} {unit} disagrees with the release file "
                    f"({theirs:g} {unit} in {rel_table.source}, row {r['row']})",
                    source=dep_table.source,
                    where=where,
                )
        if d["z"] > r["z"]:
            raise InputFileError(
                f"the deposit (z = {d['z']:.2f} m) is higher than its release "
                f"(z = {r['z']:.2f} m in {rel_table.source}): upslope",
                source=dep_table.source,
                where=where,
            )
        mass = r.get("mass", d.get("mass", math.nan))
        radius = r.get("radius", d.get("radius", math.nan))
        records.append(
            {
                "path_id": r["id"],
                "release_x_m": r["x"],
                "release_y_m": r["y"],
                "release_z_m": r["z"],
                "release_ground_z_m": r.get("ground_z", math.nan),
                "release_vx_mps": r.get("vx", math.nan),
                "release_vy_mps": r.get("vy", math.nan),
                "release_vz_mps": r.get("vz", math.nan),
                "deposit_x_m": d["x"],
                "deposit_y_m": d["y"],
                "deposit_z_m": d["z"],
                "deposit_ground_z_m": d.get("ground_z", math.nan),
                "mass_kg": mass,
                "radius_m": radius,
                "gyration_m": r.get("gyration", math.nan),
                "reported_runout_m": d.get("runout", math.nan),
                "group": r.get("group", ""),
                "source": r.get("source", ""),
            }
        )
    for record in records:
        for key in ("mass_kg", "radius_m", "gyration_m"):
            if record[key] <= 0:
                raise InputFileError(
                    f"{key} must be > 0 (got {record[key]:g})",
                    source=rel_table.source,
                    where=f"run {record['path_id']}",
                )
    return PathObservations(
        pd.DataFrame.from_records(records), None, "plan", rel_table.source
    )


def observations_from_impact_table(table: ImpactTable) -> PathObservations:
    """Section-coordinate observations from an ImpactTable (surveyed impacts).

    Release = the first impact of each path, deposit = its last (x along the
    section, y = 0); mass and radius from the first row where given; every impact
    an along-path observation with ``x_m``, ``z_m`` and, where the table has them,
    ``hmax_normal_m`` and ``vi_mps``, each with what it rests on
    (:func:`fieldkit.impact_table.flight_value_markers`: ``<value>_flags``, the
    flag bit code of the impacts its flight joins, and ``<value>_theta0_assumed``).

    Raises
    ------
    InputFileError
        A path whose last impact is higher than its first (upslope), naming the
        table and the path.

    Examples
    --------
    >>> t = ImpactTable(pd.DataFrame({"path_id": ["A", "A"], "point": ["1", "2"],
    ...     "x_m": [0.0, 8.0], "z_m": [10.0, 4.0], "slope_deg": [30.0, 30.0],
    ...     "vi_x_mps": [3.0, 4.0], "vi_z_mps": [-4.0, -5.0], "vf_x_mps": [3.0, 3.0],
    ...     "vf_z_mps": [2.0, 1.0]})).derive()
    >>> obs = observations_from_impact_table(t)
    >>> run = obs.row("A")
    >>> [float(run[k]) for k in ("release_x_m", "deposit_x_m", "deposit_z_m")]
    [0.0, 8.0, 4.0]
    >>> obs.along_path("A")["vi_mps"].tolist()
    [5.0, 6.4031242374328485]
    """
    frame = table.frame
    derived = table.derive().frame  # its qa_flags, whatever the table carried
    source = table.source or "ImpactTable"
    records, along = [], []
    for path_id in table.paths():
        rows = frame[frame["path_id"] == path_id]
        first, last = rows.iloc[0], rows.iloc[-1]
        if float(last["z_m"]) > float(first["z_m"]):
            raise InputFileError(
                f"the last impact (z = {float(last['z_m']):.2f} m) is higher than "
                f"the first (z = {float(first['z_m']):.2f} m): upslope",
                source=source,
                where=f"path {path_id}",
            )
        records.append(
            {
                "path_id": str(path_id),
                "release_x_m": float(first["x_m"]),
                "release_y_m": 0.0,
                "release_z_m": float(first["z_m"]),
                "deposit_x_m": float(last["x_m"]),
                "deposit_y_m": 0.0,
                "deposit_z_m": float(last["z_m"]),
                "mass_kg": float(first["mass_kg"]),
                "radius_m": float(first["radius_m"]),
                "gyration_m": float(first["gyration_m"]),
                "source": source,
            }
        )
        points = pd.DataFrame(
            {
                "path_id": str(path_id),
                "point": rows["point"].astype(str).to_numpy(),
                "x_m": rows["x_m"].to_numpy(float),
                "y_m": 0.0,
                "z_m": rows["z_m"].to_numpy(float),
            }
        )
        markers = flight_value_markers(derived[derived["path_id"] == path_id])
        for name in ("hmax_normal_m", "vi_mps"):
            values = rows[name].to_numpy(dtype=float, na_value=np.nan)
            if np.isfinite(values).any():
                points[name] = values
        for name in ("hmax_normal_m", "vi_mps"):
            if name in points:  # what the value rests on (fieldkit.fit.suspect)
                points[f"{name}_flags"] = markers[f"{name}_flags"]
                points[f"{name}_theta0_assumed"] = markers[f"{name}_theta0_assumed"]
        along.append(points)
    return PathObservations(
        pd.DataFrame.from_records(records),
        pd.concat(along, ignore_index=True),
        "section",
        source,
    )
