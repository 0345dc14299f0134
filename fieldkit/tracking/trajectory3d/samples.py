"""A CSV of 3-D trajectory samples -> :class:`Trajectory3D` per trajectory.

Columns (any order, names as :func:`fieldkit.io.csv_table.normalise_name` reads
them): a trajectory id (``path_id``, ``trajectory``, ``run`` or ``id``; optional,
one trajectory when absent), ``t_s``, ``x_m``, ``y_m``, ``z_m`` (the block's centre
in the DEM's coordinates), optional ``omega_radps`` (spin about the axis across the
direction of travel, the ImpactTable's sign: rolling toward travel is negative) or
``omega_x_radps, omega_y_radps, omega_z_radps`` (the angular velocity vector in the
DEM's axes; at each impact its component about ``N x T`` gives the spin, sign as
the ImpactTable's: ``omega = -w . (N x T)``).
Read strictly: a missing column, text in a number, an infinite value, an empty
required cell or a time that does not increase within a trajectory is a one-line
error naming the file, the row and the column.
"""

from __future__ import annotations

from dataclasses import dataclass
from os import PathLike

import numpy as np

from fieldkit.errors import InputFileError
from fieldkit.io.csv_table import read_csv_table

#: Column aliases (normalised names, units split off) of the trajectory CSV.
ID_NAMES = ("path_id", "trajectory", "run", "id")
REQUIRED = {"t_s": ("t",), "x_m": ("x",), "y_m": ("y",), "z_m": ("z",)}
OMEGA_NAMES = ("omega", "omega_radps")
OMEGA_VECTOR_NAMES = ("omega_x_radps", "omega_y_radps", "omega_z_radps")
#: Fewest samples a trajectory needs (two flights of the shortest length).
MIN_SAMPLES = 12


@dataclass(frozen=True)
class Trajectory3D:
    """One trajectory's samples.

    Attributes
    ----------
    path_id
        The trajectory's identifier.
    t_s
        Sample times [s], strictly increasing.
    xyz_m
        ``(n, 3)`` centre positions in the DEM's coordinates [m].
    omega_radps
        Spin per sample [rad/s], or None when the file has none.
    rows
        The file row of every sample (for messages).
    omega_vector_radps
        ``(n, 3)`` angular velocity vectors in the DEM's axes [rad/s], or None.
    """

    path_id: str
    t_s: np.ndarray
    xyz_m: np.ndarray
    omega_radps: np.ndarray | None
    rows: np.ndarray
    omega_vector_radps: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.t_s)

    @property
    def interval_s(self) -> float:
        """Median sampling interval [s]."""
        return float(np.median(np.diff(self.t_s)))


def read_trajectories(path: str | PathLike[str]) -> list[Trajectory3D]:
    """Read every trajectory of a samples CSV, in the order first seen.

    Raises
    ------
    InputFileError
        A column missing, a bad cell, times not increasing within a trajectory, or a
        trajectory with fewer than :data:`MIN_SAMPLES` samples (naming file, row,
        column).
    """
    table = read_csv_table(path)
    source = table.source
    for key, unit in (("t_s", "s"), ("x_m", "m"), ("y_m", "m"), ("z_m", "m")):
        col = table.find(REQUIRED[key] + (key,), key)
        if col is not None and col.unit not in (None, unit):
            raise InputFileError(
                f"column '{col.header.strip()}' is in {col.unit}; give {key} in "
                f"{unit}",
                source=source,
                where="row 1",
            )
    cols = table.require(
        {k: v + (k,) for k, v in REQUIRED.items()},
        "a 3-D trajectory CSV needs columns t_s, x_m, y_m, z_m",
    )
    id_col = table.find(ID_NAMES, "the trajectory id")
    omega_col = table.find(OMEGA_NAMES, "the spin")
    vec_cols = [table.find((name,), name) for name in OMEGA_VECTOR_NAMES]
    if any(c is not None for c in vec_cols):
        missing = [n for n, c in zip(OMEGA_VECTOR_NAMES, vec_cols, strict=True)
                   if c is None]  # fmt: skip
        if missing:
            raise InputFileError(
                f"the spin vector needs {', '.join(OMEGA_VECTOR_NAMES)}; missing "
                f"{', '.join(missing)}",
                source=source,
                where="row 1",
            )
        if omega_col is not None:
            raise InputFileError(
                f"columns '{omega_col.header.strip()}' and omega_x/y/z_radps both give "
                "the spin; keep one",
                source=source,
                where="row 1",
            )
    else:
        vec_cols = []
    ids: list[str] = []
    values: list[list[float]] = []
    rows: list[int] = []
    for number, row in table.rows:
        ids.append(table.cell(row, id_col) if id_col is not None else "1")
        if id_col is not None and ids[-1] == "":
            raise InputFileError(
                f"column '{id_col.header.strip()}' is empty",
                source=source,
                where=f"row {number}",
            )
        values.append(
            [table.number(number, row, cols[k]) for k in ("t_s", "x_m", "y_m", "z_m")]
            + [
                table.number(number, row, omega_col, required=False)
                if omega_col is not None
                else np.nan
            ]
            + [table.number(number, row, c, required=False) for c in vec_cols]
        )
        rows.append(number)
    data = np.array(values, float)
    ids_a = np.array(ids, dtype=object)
    rows_a = np.array(rows, np.int64)
    out = []
    for pid in dict.fromkeys(ids):
        sel = ids_a == pid
        t = data[sel, 0]
        r = rows_a[sel]
        bad = np.flatnonzero(np.diff(t) <= 0)
        if bad.size:
            i = int(bad[0]) + 1
            raise InputFileError(
                f"column 't_s': {t[i]:g} s does not follow {t[i - 1]:g} s of row "
                f"{r[i - 1]} (times must increase within trajectory {pid})",
                source=source,
                where=f"row {r[i]}",
            )
        if t.size < MIN_SAMPLES:
            raise InputFileError(
                f"trajectory {pid} has {t.size} samples; at least {MIN_SAMPLES} are "
                "needed (two flights)",
                source=source,
                where=f"row {r[0]}",
            )
        omega = data[sel, 4] if omega_col is not None else None
        vec = data[sel, 5:8].copy() if vec_cols else None
        out.append(Trajectory3D(str(pid), t, data[sel, 1:4].copy(), omega, r, vec))
    return out
