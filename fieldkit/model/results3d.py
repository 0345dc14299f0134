"""What a designer reads from a 3-D simulation: deposits, rasters, analysis lines.

Everything here is computed in numpy from a 3-D result (the contract of
:func:`fieldkit.model.simulate3d.simulate3d`): the final positions and states of
the rocks and their sampled paths (flat arrays ``path`` with ``path_offsets``),
so it is deterministic and independent of how the kernel was threaded.

* **Deposits**: one row per rock (rock, release, x_m, y_m, z_m, state).
* **Rasters** on the DEM's grid (row 0 south, as :class:`~fieldkit.model.terrain.
  Terrain`): ``passing_count`` (rocks whose path enters the cell), ``max_ke_j``
  (largest translational kinetic energy in the cell), ``max_height_m`` (largest
  bounce height of the centre above the ground) and ``deposit_density_per_m2``
  (rocks stopped in the cell / (rocks x cell area): integrates to the stopped
  fraction). A path is followed between its samples as straight pieces cut at most
  a quarter cell long (values interpolated linearly), so a rock crossing a cell's
  corner between two samples is still counted.
* **Impacts** (:func:`impact_table3d`): one ImpactTable row per impact, the 2-D
  rows' conventions in each impact's plane of incidence (below).
* **Analysis lines** (barrier polylines in plan): a rock passes a line when a
  piece of its path crosses it; it is counted once, at its first crossing, with its
  speed, translational kinetic energy and bounce height interpolated there. The
  passing fraction and the p50/p95/p99 of each quantity carry Monte Carlo standard
  errors (:mod:`fieldkit.model.statistics`).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from fieldkit.errors import ArgumentError
from fieldkit.impact_table import ImpactTable
from fieldkit.model.results import (
    EXITED_DOWNSLOPE,
    EXITED_UPSLOPE,
    MAX_IMPACTS,
    STOPPED,
)
from fieldkit.model.statistics import distribution, fraction_se
from fieldkit.model.terrain import Terrain

#: Final states of a 3-D rock (the 2-D codes) -> the name written to deposits.csv.
STATE3D_NAMES = {
    STOPPED: "stopped",
    EXITED_DOWNSLOPE: "left_dem",
    EXITED_UPSLOPE: "left_dem",
    MAX_IMPACTS: "capped",
}
#: Percentiles reported at an analysis line.
LINE_PERCENTILES = (50, 95, 99)
#: Quantities read at an analysis line: path field -> summary key.
LINE_QUANTITIES = {"speed_mps": "speed_mps", "ke_j": "ke_j", "height_m": "height_m"}
#: Raster outputs -> (file name, description).
RASTERS = {
    "passing_count": "rocks whose path enters the cell",
    "max_ke_j": "largest translational kinetic energy in the cell [J]",
    "max_height_m": "largest bounce height above the ground in the cell [m]",
    "deposit_density_per_m2": "rocks stopped in the cell / (rocks x cell area) [1/m2]",
}
#: Longest straight piece a path is cut into for the rasters, in cells.
PIECE_CELLS = 0.25
#: Points of cut paths the rasters handle at a time (blocks of whole rocks).
CHUNK_POINTS = 2_000_000


def simulator3d():
    """The 3-D kernel's entry point: the one place the outputs reach it.

    Returns
    -------
    callable
        :func:`fieldkit.model.simulate3d.simulate3d` -- ``(model, rocks, rng, *,
        sample_m=None, record_impacts=False, on_impact_rows=None) -> Result3D``.

    Raises
    ------
    ArgumentError
        The 3-D kernel is not part of this build.
    """
    try:
        from fieldkit.model.simulate3d import simulate3d
    except ImportError:
        raise ArgumentError(
            "this build has no 3-D simulator (fieldkit.model.simulate3d); the model "
            "file describes a DEM"
        ) from None
    return simulate3d


def state_names(state: np.ndarray) -> list[str]:
    """``stopped``, ``left_dem`` or ``capped`` for each state code."""
    return [STATE3D_NAMES[int(s)] for s in np.asarray(state)]


def deposits_frame(result) -> pd.DataFrame:
    """One row per rock: ``rock, release, x_m, y_m, z_m, state``."""
    xyz = np.asarray(result.deposit_xyz, float)
    return pd.DataFrame(
        {
            "rock": np.arange(len(xyz), dtype=np.int64),
            "release": np.asarray(result.release_index, np.int64),
            "x_m": xyz[:, 0],
            "y_m": xyz[:, 1],
            "z_m": xyz[:, 2],
            "state": state_names(result.state),
        }
    )


#: ImpactTable columns a 3-D impact row leaves empty -> why (said with the table).
IMPACT3D_EMPTY = {
    "theta0_deg, theta0_source": "no restitution angle is assumed: the rebound is "
    "simulated",
    "flight_time_s, flight_length_m, hmax_vertical_m, hmax_normal_m": "the 3-D "
    "kernel does not measure the flight leaving an impact",
}
#: What a 3-D impact row's section-frame columns mean, in one sentence.
IMPACT3D_FRAME = (
    "3-D impact rows: x_m, y_m, z_m the contact in the DEM's coordinates; N (normal_x,"
    " normal_y, normal_z) the surface normal the impact used (tilted by "
    "slope_roughness), T (tangent_*) in the plane of incidence along the incoming "
    "tangential velocity; each row's section plane is its plane of incidence: "
    "vi_x/vf_x along the plane's horizontal line in the direction of travel, "
    "vi_z/vf_z along its steepest upward direction (vertical when the plane is), "
    "slope_deg the angle of N from that direction (the dip when the rock travels "
    "down the fall line), dip_deg the surface's own dip; vin, vit, vfn, vft, "
    "theta_i/f, e_n, e_t and the energies as in 2-D"
)


def impact_table3d(rows: dict[str, np.ndarray], material_names) -> ImpactTable:
    """The ImpactTable (derived) of 3-D impact rows of consecutive rocks.

    Each impact is planar: the incoming velocity ``vin N + vit T`` and the rebound
    ``vfn N + vft T`` lie in the plane of incidence spanned by ``N`` and ``T``
    (:mod:`fieldkit.model.kernel3d`). That plane is the row's section plane, with
    ``X`` its horizontal line along the travel and ``Z`` its steepest upward
    direction (the projection of the vertical: ``Z ∝ n_z N + t_z T``,
    ``X ∝ n_z T - t_z N``), so ``slope_deg = atan2(-t_z, n_z)`` and the
    section-frame velocities ``vi_x = vit cos(psi) + vin sin(psi)``, ``vi_z = vin
    cos(psi) - vit sin(psi)`` (and ``vf_*`` alike) give back, through
    :meth:`ImpactTable.derive`, the kernel's ``vin, vit, vfn, vft`` -- hence its
    ``e_n, e_t`` and angles -- to rounding. Speeds and energies are the 3-D ones
    (the whole velocity lies in the plane); ``z_m`` is the contact's elevation, so
    the energy heads are the 3-D ones too.

    Parameters
    ----------
    rows
        :attr:`fieldkit.model.simulate3d.Result3D.impact_rows` (or one chunk of
        them): whole rocks, each rock's impacts in order.
    material_names
        The model's material names, in the order ``material_index`` counts them.

    Returns
    -------
    ImpactTable
        ``path_id`` the rock's index in the run, ``point`` its impact number from
        1; ``t_s`` the time since its release; ``material``, body, spins;
        ``tree_strike`` whether the rock struck a tree since its previous impact
        (``tree_impacts``);
        :data:`IMPACT3D_EMPTY` columns NaN; extension columns ``y_m``,
        ``normal_x/y/z``, ``tangent_x/y/z``, ``dip_deg``.

    Examples
    --------
    A drop of 5 m on a plane dipping 30 deg towards +x: ``vi = sqrt(2 g 5)``,
    ``vin = -vi cos 30``, ``vit = vi sin 30``.

    >>> vi, b = math.sqrt(2 * 9.81 * 5), math.radians(30)
    >>> one = lambda v: np.array([float(v)])
    >>> rows = {"rock": np.array([0]), "t_s": one(1.0), "x_m": one(0),
    ...     "y_m": one(0), "z_m": one(0),
    ...     "material_index": np.array([0]), "vin_mps": one(-vi * math.cos(b)),
    ...     "vit_mps": one(vi * math.sin(b)), "vfn_mps": one(0.3 * vi * math.cos(b)),
    ...     "vft_mps": one(0.8 * vi * math.sin(b)), "omega_i_radps": one(0),
    ...     "omega_f_radps": one(0), "normal_x": one(math.sin(b)), "normal_y": one(0),
    ...     "normal_z": one(math.cos(b)), "tangent_x": one(math.cos(b)),
    ...     "tangent_y": one(0), "tangent_z": one(-math.sin(b)), "mass_kg": one(100),
    ...     "radius_m": one(0.2), "gyration_m": one(0.126), "tree_strike": one(0)}
    >>> f = impact_table3d(rows, ["rock"]).frame
    >>> [round(float(f.loc[0, c]), 6) for c in ("slope_deg", "vi_x_mps", "e_n", "e_t")]
    [30.0, 0.0, 0.3, 0.8]
    """
    r = {k: np.asarray(v) for k, v in rows.items()}
    rock = r["rock"].astype(np.int64)
    first = np.ones(rock.size, bool)
    first[1:] = rock[1:] != rock[:-1]
    start = np.maximum.accumulate(np.where(first, np.arange(rock.size), 0))
    number = np.arange(rock.size) - start + 1
    nz, tz = r["normal_z"].astype(float), r["tangent_z"].astype(float)
    norm = np.hypot(nz, tz)
    cos_psi, sin_psi = nz / norm, -tz / norm
    vin, vit, vfn, vft = (
        r[k].astype(float) for k in ("vin_mps", "vit_mps", "vfn_mps", "vft_mps")
    )
    names = np.asarray(list(material_names), dtype=object)
    frame = pd.DataFrame(
        {
            "path_id": rock.astype(str),
            "point": number.astype(str),
            "t_s": r["t_s"],
            "x_m": r["x_m"],
            "y_m": r["y_m"],
            "z_m": r["z_m"],
            "slope_deg": np.degrees(np.arctan2(sin_psi, cos_psi)),
            "material": names[r["material_index"].astype(np.int64)],
            "mass_kg": r["mass_kg"],
            "radius_m": r["radius_m"],
            "gyration_m": r["gyration_m"],
            "vi_x_mps": vit * cos_psi + vin * sin_psi,
            "vi_z_mps": vin * cos_psi - vit * sin_psi,
            "vf_x_mps": vft * cos_psi + vfn * sin_psi,
            "vf_z_mps": vfn * cos_psi - vft * sin_psi,
            "omega_i_radps": r["omega_i_radps"],
            "omega_f_radps": r["omega_f_radps"],
            "tree_strike": np.asarray(r["tree_strike"], float) > 0.5,
            **{k: r[k] for k in ("normal_x", "normal_y", "normal_z", "tangent_x",
                                 "tangent_y", "tangent_z")},  # fmt: skip
            "dip_deg": np.degrees(np.arccos(np.clip(nz, -1.0, 1.0))),
        }
    )
    return ImpactTable(frame, source="simulation").derive()


def _path_fields(result) -> dict[str, np.ndarray]:
    path = result.path
    names = ("x_m", "y_m", "z_m", "speed_mps", "ke_j", "re_j", "height_m")
    return {k: np.asarray(path[k], float) for k in names}


def _segments(result) -> tuple[np.ndarray, np.ndarray]:
    """``(start, rock)``: index of the first sample of every path piece (samples
    i, i + 1 of one rock) and its rock."""
    offsets = np.asarray(result.path_offsets, np.int64)
    counts = np.diff(offsets)
    rock_of_sample = np.repeat(np.arange(counts.size), counts)
    start = np.arange(max(int(offsets[-1]) - 1, 0), dtype=np.int64)
    start = start[rock_of_sample[start] == rock_of_sample[start + 1]]
    return start, rock_of_sample[start]


def cells_of(terrain: Terrain, x_m, y_m) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(row, col, inside)`` of the cells holding the points (row 0 south); a
    point off the grid has ``inside`` False (its row, col are then meaningless).

    Examples
    --------
    >>> t = Terrain(100.0, 200.0, 5.0, np.zeros((2, 3)))
    >>> [a.tolist() for a in cells_of(t, np.array([101.0, 114.9, 99.0]),
    ...                               np.array([209.0, 200.0, 201.0]))]
    [[1, 0, 0], [0, 2, -1], [True, True, False]]
    """
    col = np.floor((np.asarray(x_m, float) - terrain.x0_m) / terrain.cell_m)
    row = np.floor((np.asarray(y_m, float) - terrain.y0_m) / terrain.cell_m)
    ny, nx = terrain.shape
    inside = (col >= 0) & (col < nx) & (row >= 0) & (row < ny)
    return row.astype(np.int64), col.astype(np.int64), inside


def rasters(result, terrain: Terrain) -> dict[str, np.ndarray]:
    """The four rasters of the module docstring, each ``terrain.shape``, row 0 south.

    Cells no rock entered hold 0 (counts) or NaN (maxima). The paths are cut into
    pieces in blocks of whole rocks (at most about :data:`CHUNK_POINTS` points at a
    time), so memory stays bounded whatever the number of rocks.
    """
    ny, nx = terrain.shape
    cells = ny * nx
    f = _path_fields(result)
    start, rock = _segments(result)
    length = np.hypot(f["x_m"][start + 1] - f["x_m"][start],
                      f["y_m"][start + 1] - f["y_m"][start])  # fmt: skip
    pieces = np.maximum(np.ceil(length / (PIECE_CELLS * terrain.cell_m)), 1)
    pieces = pieces.astype(np.int64)
    offsets = np.asarray(result.path_offsets, np.int64)
    lone = np.flatnonzero(np.diff(offsets) == 1)  # rocks of one sample
    n_rocks = offsets.size - 1
    per_rock = np.bincount(rock, pieces + 1, minlength=n_rocks) + np.bincount(
        lone, minlength=n_rocks
    )
    block = np.cumsum(per_rock) // CHUNK_POINTS
    edges = np.concatenate([[0], np.flatnonzero(np.diff(block)) + 1, [n_rocks]])
    passing = np.zeros(cells, np.int64)
    maxima = {key: np.full(cells, -np.inf) for key in ("ke_j", "height_m")}
    for r0, r1 in zip(edges[:-1], edges[1:], strict=True):
        s0, s1 = np.searchsorted(rock, [r0, r1])
        l0, l1 = np.searchsorted(lone, [r0, r1])
        a, k = start[s0:s1], pieces[s0:s1]
        # points at t = 0, 1/k, ..., 1 along every piece (shared ends repeated)
        seg = np.repeat(np.arange(a.size), k + 1)
        first = np.repeat(np.cumsum(k + 1) - (k + 1), k + 1)
        t = (np.arange(seg.size) - first) / np.repeat(k, k + 1)
        ia = np.concatenate([a[seg], offsets[lone[l0:l1]]])
        ib = np.concatenate([a[seg] + 1, offsets[lone[l0:l1]]])
        t = np.concatenate([t, np.zeros(l1 - l0)])
        owner = np.concatenate([rock[s0:s1][seg], lone[l0:l1]])

        def lerp(key: str, ia=ia, ib=ib, t=t) -> np.ndarray:
            va, vb = f[key][ia], f[key][ib]
            out = np.where(t == 1, vb, va + t * (vb - va))
            return np.where(t == 0, va, out)  # a NaN neighbour spoils no sample

        row, col, inside = cells_of(terrain, lerp("x_m"), lerp("y_m"))
        cell = row[inside] * nx + col[inside]
        pairs = np.unique(owner[inside] * cells + cell)
        passing += np.bincount(pairs % cells, minlength=cells)
        for key, grid in maxima.items():
            np.fmax.at(grid, cell, lerp(key)[inside])  # NaN samples ignored
    out: dict[str, np.ndarray] = {"passing_count": passing.reshape(ny, nx)}
    for name, key in (("max_ke_j", "ke_j"), ("max_height_m", "height_m")):
        grid = maxima[key]
        grid[~np.isfinite(grid)] = np.nan
        out[name] = grid.reshape(ny, nx)
    count = deposit_counts(result, terrain)
    rocks = max(int(result.rocks), 1)
    out["deposit_density_per_m2"] = count / (rocks * terrain.cell_m**2)
    return out


def deposit_counts(result, terrain: Terrain) -> np.ndarray:
    """Rocks stopped in each cell (int, ``terrain.shape``, row 0 south)."""
    ny, nx = terrain.shape
    xyz = np.asarray(result.deposit_xyz, float)
    stopped = np.asarray(result.state) == STOPPED
    row, col, inside = cells_of(terrain, xyz[stopped, 0], xyz[stopped, 1])
    count = np.bincount(row[inside] * nx + col[inside], minlength=ny * nx)
    return count.reshape(ny, nx)


def write_geotiff(path, values: np.ndarray, terrain: Terrain) -> None:
    """Write one raster (row 0 south, as ``terrain.z``) as a north-up GeoTIFF with
    the DEM's transform and CRS (none when the DEM has none); NaN = nodata."""
    import rasterio
    from rasterio.crs import CRS
    from rasterio.transform import Affine

    ny, nx = terrain.shape
    top = terrain.y0_m + ny * terrain.cell_m
    transform = Affine(terrain.cell_m, 0.0, terrain.x0_m, 0.0, -terrain.cell_m, top)
    crs = CRS.from_user_input(terrain.crs) if terrain.crs else None
    data = np.flipud(np.asarray(values))
    integer = np.issubdtype(data.dtype, np.integer)
    profile = {
        "driver": "GTiff",
        "height": ny,
        "width": nx,
        "count": 1,
        "dtype": "int32" if integer else "float64",
        "crs": crs,
        "transform": transform,
        "nodata": None if integer else np.nan,
    }
    with rasterio.open(path, "w", **profile) as dst:
        dst.write(data.astype(profile["dtype"]), 1)


def line_crossings(result, xy_m: np.ndarray) -> dict[str, np.ndarray]:
    """Each rock's first crossing of a polyline.

    Parameters
    ----------
    result
        A 3-D result (module docstring).
    xy_m
        ``(n, 2)`` polyline vertices [m].

    Returns
    -------
    dict
        ``rock`` (the crossing rocks, ascending) and, at each one's first crossing
        along its path, ``x_m, y_m, speed_mps, ke_j, re_j, height_m`` (linear
        between the two samples around it; ``re_j`` the rotational energy).
    """
    f = _path_fields(result)
    start, rock = _segments(result)
    px, py = f["x_m"][start], f["y_m"][start]
    qx, qy = f["x_m"][start + 1], f["y_m"][start + 1]
    best_t = np.full(start.size, np.inf)  # path parameter of the first crossing
    for (ax, ay), (bx, by) in zip(xy_m[:-1], xy_m[1:], strict=True):
        rx, ry = qx - px, qy - py
        sx, sy = bx - ax, by - ay
        den = rx * sy - ry * sx
        with np.errstate(divide="ignore", invalid="ignore"):
            t = ((ax - px) * sy - (ay - py) * sx) / den
            u = ((ax - px) * ry - (ay - py) * rx) / den
        # half-open on the path piece: a crossing exactly at a sample counts once
        hit = (den != 0) & (t >= 0) & (t < 1) & (u >= 0) & (u <= 1)
        best_t = np.where(hit & (t < best_t), t, best_t)
    hit = np.isfinite(best_t)
    seg, t = np.flatnonzero(hit), best_t[hit]
    # first crossing per rock: segments are in path order within a rock
    rocks_hit = rock[seg]
    keep = np.unique(rocks_hit, return_index=True)[1]
    seg, t = seg[keep], t[keep]
    a = start[seg]
    out = {"rock": rock[seg].astype(np.int64)}
    for key in ("x_m", "y_m", "speed_mps", "ke_j", "re_j", "height_m"):
        out[key] = f[key][a] + t * (f[key][a + 1] - f[key][a])
    return out


def line_summary(result, xy_m: np.ndarray, name: str, crossing=None) -> dict:
    """The analysis-line entry of summary.json: passing count and fraction with its
    SE, and p50/p95/p99 (with SEs) of speed, KE and bounce height of the crossing
    rocks at their first crossing (``crossing``: :func:`line_crossings` already
    made, e.g. merged from the tiles of a run)."""
    if crossing is None:
        crossing = line_crossings(result, xy_m)
    rocks = int(result.rocks)
    passing = int(crossing["rock"].size)
    fraction, se = fraction_se(passing, rocks)
    entry: dict = {
        "name": name,
        "xy_m": np.asarray(xy_m, float).tolist(),
        "passing": passing,
        "passing_fraction": fraction,
        "passing_fraction_se": se,
    }
    for key, out_key in LINE_QUANTITIES.items():
        entry[out_key] = distribution(crossing[key], LINE_PERCENTILES)
    return entry


def summary3d(result, model, lines: list, crossings: list | None = None) -> dict:
    """summary.json of a 3-D run: rocks, impacts, wall_s, seed, final states, the
    stopped fraction, release-to-deposit distance in plan, the analysis lines
    (``lines``: :class:`~fieldkit.model.terrain_file.AnalysisLine`) and, with
    ``tree_impacts`` on, ``tree_strikes`` (total, rocks that struck one, stems)."""
    state = np.asarray(result.state)
    names = state_names(state)
    final = {k: names.count(k) for k in ("stopped", "left_dem", "capped")}
    rocks = int(result.rocks)
    stopped = state == STOPPED
    fraction, se = fraction_se(int(stopped.sum()), rocks)
    releases = np.asarray(model.releases, float)[np.asarray(result.release_index)]
    xyz = np.asarray(result.deposit_xyz, float)
    distance = np.hypot(xyz[:, 0] - releases[:, 0], xyz[:, 1] - releases[:, 1])
    out = {
        "dimension": 3,
        "rocks": rocks,
        "impacts": int(result.impacts),
        "wall_s": float(result.wall_s),
        "seed": result.seed,
        "final_state": final,
        "stopped_fraction": fraction,
        "stopped_fraction_se": se,
        "deposits": {
            "distance_m": distribution(np.where(stopped, distance, math.nan)),
            "over": "stopped rocks; distance in plan from the release point",
        },
        "lines": [
            line_summary(result, ln.xy_m, ln.label(i),
                         None if crossings is None else crossings[i])
            for i, ln in enumerate(lines)
        ],  # fmt: skip
    }
    if "tree_impacts" in (model.effects or {}):
        strikes = np.asarray(result.tree_strikes_per_rock)
        out["tree_strikes"] = {
            "total": int(strikes.sum()),
            "rocks_struck": int((strikes > 0).sum()),
            "stems": int(len(model.trees.x_m)),
            "over": "every rock; a strike: the centre within d/2 + r of a stem, "
            "below its top",
        }
    return out
