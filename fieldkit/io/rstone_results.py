"""r.stone's result grids read back as a fieldkit result.

``fieldkit export --to rstone`` writes, beside the rasters, ``run_rstone.sh`` (it
exports r.stone's ``counter``, ``maxvel`` and ``maxdz`` grids as ESRI ASCII
``counter.asc``, ``maxvel.asc``, ``maxdz.asc``) and ``fieldkit_export.json``, the
record of the grid: its geometry, the source cells and the trajectories started in
each, the DEM offset, the body's mass, and for the model's section extruded the
chainage of each column. :func:`read_rstone_results` reads the four;
:func:`along_path` turns them into the quantities of ``fieldkit simulate``:

* distance: the chainage of each column on an extruded section; on a DEM, the
  plan distance of a cell's centre from the nearest source cell's centre, in bins
  of one cell;
* ``trajectories``: r.stone's counter summed over the column (the bin): the
  trajectories with a path point there (``MarkPath`` in r.stone's ``stone.c``
  counts a trajectory once in each cell of its path points, which ``Filter``
  keeps about 5 m apart: a trajectory can skip a cell);
* ``survival``: the fraction of the traced trajectories that reach the distance,
  the largest count at that distance or beyond over the trajectories traced (a
  trajectory that reaches a farther cell passed every nearer one, counted or
  not);
* ``max_speed_mps``, ``max_energy_kj`` (translational, ``m v² / 2`` with the
  record's mass: r.stone's block is a point) and ``max_height_m``: the largest over
  the column (the bin) of ``maxvel`` and ``maxdz``, which r.stone writes in whole
  m/s and whole metres, truncated (``MarkVelo``, ``MarkQuota``).

The runout percentile q (:func:`runout_percentiles`) is the farthest distance that
a fraction ``1 - q`` of the trajectories reaches: good to about one cell.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from fieldkit.errors import InputFileError
from fieldkit.io.dem import read_dem, same_origin_and_cell

#: The record of the grid, written by the export.
RECORD = "fieldkit_export.json"

#: r.stone's output grids, as ``run_rstone.sh`` writes them.
GRIDS = ("counter", "maxvel", "maxdz")

#: Runout percentiles reported, as ``fieldkit simulate``'s summary.
PERCENTILES = (50, 90, 95, 99)


@dataclass(frozen=True)
class RstoneResults:
    """r.stone's grids and the export's record of them.

    Attributes
    ----------
    record
        ``fieldkit_export.json`` as read.
    counter
        Trajectories through each cell (0 where r.stone wrote none).
    maxvel_mps, maxdz_m
        Largest speed [m/s] and height above the ground [m] (NaN where none).
    x_m, y_m
        Cell-centre coordinates of the columns and rows (row 0 north).
    """

    record: dict
    counter: np.ndarray
    maxvel_mps: np.ndarray
    maxdz_m: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray

    @property
    def cellsize_m(self) -> float:
        return float(self.record["grid"]["cellsize_m"])

    @property
    def stated(self) -> int:
        """Trajectories the export started (the record's sum over source cells)."""
        return int(sum(s["trajectories"] for s in self.record["sources"]))

    @property
    def traced(self) -> int:
        """Trajectories r.stone traced, as far as the counter shows: each source
        cell's count, at most the trajectories it started (every trajectory's
        first path point is its source cell's centre; a count above that is
        other cells' trajectories passing through), summed over the source cells.
        Equal to :attr:`stated` when every source cell started all its stones (a
        stone r.stone never starts, e.g. on the grid's edge row, leaves its cell
        short unless others pass through it)."""
        return int(
            sum(
                min(self.counter[s["row"], s["col"]], s["trajectories"])
                for s in self.record["sources"]
            )
        )

    @property
    def on_sources(self) -> int:
        """The counter summed over the source cells (own and passing trajectories)."""
        return int(
            sum(self.counter[s["row"], s["col"]] for s in self.record["sources"])
        )

    def edge_counts(self) -> dict[str, int]:
        """Counter summed over the grid's outer rows and columns: trajectories
        that reached the edge, where r.stone stops them (an upper bound: one
        trajectory may cross several edge cells)."""
        c = self.counter
        return {
            "north": int(c[0].sum()),
            "south": int(c[-1].sum()),
            "west": int(c[:, 0].sum()),
            "east": int(c[:, -1].sum()),
        }


def _record(folder: Path) -> dict:
    path = folder / RECORD
    if not path.is_file():
        raise InputFileError(
            f"missing: {folder} holds no {RECORD} (the record `fieldkit export --to "
            "rstone` writes beside the rasters)",
            source=path,
        )
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputFileError(f"not JSON ({exc})", source=path) from None
    need = {"grid": dict, "sources": list, "extruded": bool, "mass_kg": (int, float)}
    for key, kind in need.items():
        if not isinstance(record, dict) or not isinstance(record.get(key), kind):
            raise InputFileError(
                f"{key}: missing or of the wrong type (not a record written by "
                "`fieldkit export --to rstone`)",
                source=path,
            )
    for key in ("ncols", "nrows", "x_left_m", "y_top_m", "cellsize_m"):
        value = record["grid"].get(key)
        if not isinstance(value, (int, float)) or not math.isfinite(value):
            raise InputFileError(f"grid.{key}: missing or not a number", source=path)
    if record["extruded"] and len(record.get("chainage_m") or []) != int(
        record["grid"]["ncols"]
    ):
        raise InputFileError(
            "chainage_m: an extruded section needs one chainage per column",
            source=path,
        )
    for i, s in enumerate(record["sources"]):
        ok = isinstance(s, dict) and all(
            isinstance(s.get(k), int) for k in ("row", "col", "trajectories")
        )
        if not ok or not (
            0 <= s["row"] < record["grid"]["nrows"]
            and 0 <= s["col"] < record["grid"]["ncols"]
        ):
            raise InputFileError(
                "row, col and trajectories must be whole numbers inside the grid",
                source=path,
                where=f"sources[{i}]",
            )
    if not record["sources"]:
        raise InputFileError("sources: no source cell", source=path)
    return record


def read_rstone_results(folder: str | Path) -> RstoneResults:
    """Read ``counter.asc``, ``maxvel.asc``, ``maxdz.asc`` and the export's
    record from ``folder`` (module docstring).

    Raises
    ------
    InputFileError
        A missing or malformed file (one line naming it), or a grid whose size,
        corner or cell differs from the record's.
    """
    folder = Path(folder)
    record = _record(folder)
    g = record["grid"]
    grids = {}
    for name in GRIDS:
        path = folder / f"{name}.asc"
        if not path.is_file():
            raise InputFileError(
                f"missing: r.stone's {name} grid (run_rstone.sh writes it with "
                "r.out.gdal format=AAIGrid)",
                source=path,
            )
        grid = read_dem(path)
        left = grid.x_left_m
        top = grid.y_top_m
        cell = g["cellsize_m"]
        same = grid.shape == (int(g["nrows"]), int(g["ncols"])) and (
            same_origin_and_cell((left, top, grid.dx_m, grid.dy_m),
                                 (g["x_left_m"], g["y_top_m"], cell, cell))
        )  # fmt: skip
        if not same:
            raise InputFileError(
                f"{grid.shape[1]} x {grid.shape[0]} cells of {grid.dx_m:g} m from "
                f"({left:.10g}, {top:.10g}); the export's grid ({RECORD}) is "
                f"{g['ncols']} x {g['nrows']} cells of {g['cellsize_m']:g} m from "
                f"({g['x_left_m']:.10g}, {g['y_top_m']:.10g}): not r.stone's result "
                "on these files",
                source=path,
            )
        values = grid.values
        if np.nanmin(values, initial=0.0) < 0:
            raise InputFileError(
                f"negative values in r.stone's {name} grid (counts, speeds and "
                "heights are >= 0)",
                source=path,
            )
        grids[name] = (grid, values)
    counter_grid, counter = grids["counter"]
    return RstoneResults(
        record,
        np.nan_to_num(counter, nan=0.0),
        grids["maxvel"][1],
        grids["maxdz"][1],
        counter_grid.x_m,
        counter_grid.y_m,
    )


def _distance_m(results: RstoneResults) -> tuple[np.ndarray, str]:
    """Each cell's distance along the path and what it is."""
    shape = results.counter.shape
    if results.record["extruded"]:
        chainage = np.asarray(results.record["chainage_m"], float)
        return np.tile(chainage, (shape[0], 1)), "chainage along the section [m]"
    xx, yy = np.meshgrid(results.x_m, results.y_m)
    best = np.full(shape, np.inf)
    for s in results.record["sources"]:
        x0, y0 = results.x_m[s["col"]], results.y_m[s["row"]]
        best = np.minimum(best, np.hypot(xx - x0, yy - y0))
    return best, "plan distance from the nearest source cell [m]"


def along_path(results: RstoneResults) -> tuple[pd.DataFrame, str]:
    """The result along the path: one row per column (extruded section) or per
    one-cell distance bin (DEM), module docstring; and what the distance is.
    """
    distance, what = _distance_m(results)
    cell = results.cellsize_m
    if results.record["extruded"]:
        keys = distance[0]
        index = np.tile(np.arange(keys.size), (distance.shape[0], 1))
    else:
        index = np.floor(distance / cell + 0.5).astype(int)
        keys = np.arange(index.max() + 1) * cell
    n = keys.size
    counts = np.bincount(index.ravel(), results.counter.ravel(), minlength=n)
    speed = np.full(n, np.nan)
    height = np.full(n, np.nan)
    np.fmax.at(speed, index.ravel(), results.maxvel_mps.ravel())
    np.fmax.at(height, index.ravel(), results.maxdz_m.ravel())
    traced = max(results.stated, 1)
    envelope = np.maximum.accumulate(counts[::-1])[::-1]
    mass = float(results.record["mass_kg"])
    table = pd.DataFrame(
        {
            "distance_m": keys,
            "trajectories": counts.astype(int),
            "survival": np.minimum(envelope / traced, 1.0),
            "max_speed_mps": speed,
            "max_energy_kj": 0.5 * mass * speed**2 / 1000.0,
            "max_height_m": height,
        }
    )
    return table, what


def runout_percentiles(table: pd.DataFrame) -> dict[str, float]:
    """``pQ``: the farthest distance a fraction ``1 - Q/100`` of the trajectories
    reaches (``max``: the farthest reached), from :func:`along_path`'s table.

    Examples
    --------
    >>> t = pd.DataFrame({"distance_m": [0.0, 5, 10, 15],
    ...                   "survival": [1.0, 0.8, 0.4, 0.02]})
    >>> runout_percentiles(t)
    {'p50': 5.0, 'p90': 10.0, 'p95': 10.0, 'p99': 15.0, 'max': 15.0}
    """
    d = table["distance_m"].to_numpy(float)
    s = table["survival"].to_numpy(float)
    out = {}
    for q in PERCENTILES:
        reached = np.flatnonzero(s >= 1.0 - q / 100.0 - 1e-12)
        out[f"p{q}"] = float(d[reached.max()]) if reached.size else float("nan")
    out["max"] = float(d[np.flatnonzero(s > 0).max()]) if (s > 0).any() else math.nan
    return out
