"""The 3-D model file: a ``terrain`` block (a DEM) instead of a ``profile``.

One model-file format (docs/architecture.md §7): :func:`fieldkit.model.model_file.
read_model` (with ``terrain=True``) returns a :class:`~fieldkit.model.model3d.Model3D`
when the file has a ``terrain`` block::

    {"terrain": {"dem": "terrain.asc",
                 "materials": "meadow",
                 "releases": "release_points.csv"},
     "materials": {"meadow": {"e_n": 1.0, "e_t": 0.62, "friction_deg": 19.29}},
     "body": {"mass_kg": 69.0, "radius_m": 0.176667},
     "seeder": {"vx_mps": 0.0, "vy_mps": 0.0, "vz_mps": 0.0},
     "effects": {}, "core": {},
     "analysis_lines": [{"name": "road", "xy_m": [[0, 150], [120, 150]]}]}

``terrain`` fields (file names relative to the model file):

* ``dem`` (required): an ESRI ASCII grid or a GeoTIFF (:func:`fieldkit.io.dem.
  read_dem`), square cells; its CRS (the ``.prj`` beside an ESRI grid, the
  GeoTIFF's own) is kept and written into every raster output.
* ``materials`` (required): one material name for the whole DEM; or a raster on the
  DEM's grid (same size, origin and cell) whose cell value k is the k-th material of
  ``"materials"`` counted from 0; or a list of polygons ``{"material": name,
  "polygon": [[x, y], ...]}`` -- a cell belongs to the last polygon holding its
  centre, and one item ``{"material": name}`` without a polygon names the material
  of every other cell (without it, a valid DEM cell outside every polygon is an
  error).
* ``releases`` (required): a release CSV (:func:`fieldkit.io.releases.
  read_releases`: ``x_m, y_m`` and an optional ``count``); or a list ``[[x, y],
  ...]``; or a raster on the DEM's grid of rocks per cell (cells > 0 release that
  many rocks at their centre). A release lies where the ground is defined (inside
  the rectangle of cell centres, no nodata cell around it); its z is the ground.

Optional top-level fields beside ``materials``, ``body``, ``effects`` and ``core``
(read as in 2-D): ``seeder`` (``height_m`` above the ground, ``vx_mps, vy_mps,
vz_mps, omega_radps``, their ``*_sd_*`` spreads and ``mass_sd_kg``; all 0 when
absent, i.e. rocks start at rest on the ground), ``trees`` (lists
``x_m, y_m, diameter_m, height_m``: stems in plan, trunk diameter and tree height;
struck with ``tree_impacts`` on, whose ``hit_probability`` is 1 in 3-D --
:func:`fieldkit.model.simulate3d.tree_hit_probability`), ``analysis_lines``
(barrier polylines ``{"name": ..., "xy_m": [[x, y], ...]}``) and ``provenance``.
Every problem is one line naming the model file (or the file it reads) and the
field.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fieldkit.errors import InputFileError
from fieldkit.io.dem import DemGrid, read_dem, same_origin_and_cell
from fieldkit.io.releases import cells_inside, read_releases
from fieldkit.model.materials import Material, check_number
from fieldkit.model.model3d import (
    WHY_HIT_PROBABILITY_1,
    Model3D,
    Seeder3D,
    Trees3D,
)
from fieldkit.model.model_blocks import (
    BODY_BOUNDS,
    SEEDER_BOUNDS,
    TREE_BOUNDS,
    number_lists,
    read_body,
    read_core,
    read_effects,
)
from fieldkit.model.model_blocks import object_field as _object
from fieldkit.model.model_blocks import refuse_unknown as _unknown
from fieldkit.model.terrain import Terrain

#: Top-level fields of a 3-D model file.
MODEL3D_FIELDS = frozenset(
    {"terrain", "materials", "body", "seeder", "effects", "core", "trees",
     "analysis_lines", "provenance"}
)  # fmt: skip
#: Fields of the ``terrain`` block.
TERRAIN_FIELDS = frozenset({"dem", "materials", "releases"})
#: Seeder fields of a 3-D model -> unit kind (:data:`SEEDER_BOUNDS`; "kg": the
#: body's mass bound).
SEEDER3D_FIELDS = {
    "height_m": "m", "vx_mps": "mps", "vy_mps": "mps", "vz_mps": "mps",
    "omega_radps": "radps", "height_sd_m": "m", "vx_sd_mps": "mps",
    "vy_sd_mps": "mps", "vz_sd_mps": "mps", "omega_sd_radps": "radps",
    "mass_sd_kg": "kg",
}  # fmt: skip
_UNITS = {"m": "m", "mps": "m/s", "radps": "rad/s", "kg": "kg"}
#: Most analysis lines a model file may name (as analysis points in 2-D).
MAX_ANALYSIS_LINES = 100
#: Most points an analysis line may have.
MAX_LINE_VERTICES = 10_000


@dataclass(frozen=True)
class AnalysisLine:
    """A barrier polyline in plan: ``xy_m`` ``(n, 2)`` [m], ``name`` ('' if none)."""

    xy_m: np.ndarray
    name: str = ""

    def label(self, index: int) -> str:
        """The line's name, or ``line <index + 1>``."""
        return self.name or f"line {index + 1}"


def terrain_from_dem(grid: DemGrid) -> Terrain:
    """The :class:`~fieldkit.model.terrain.Terrain` of a DEM read by
    :func:`fieldkit.io.dem.read_dem` (flipped to row 0 south).

    Raises
    ------
    InputFileError
        The cells are not square (naming the DEM).
    """
    if not grid.square:  # the header's sizes, not differences of coordinates
        raise InputFileError(
            f"cells are {grid.dx_m:g} x {grid.dy_m:g} m; the 3-D model needs square "
            "cells (resample it: gdalwarp -tr)",
            source=grid.source,
        )
    return Terrain(
        x0_m=grid.x_left_m,
        y0_m=grid.y_bottom_m,
        cell_m=grid.dx_m,
        z=np.flipud(grid.values),
        crs=grid.crs,
    )


def cell_centres(terrain: Terrain) -> tuple[np.ndarray, np.ndarray]:
    """``(x_m, y_m)``: the column and the row centres [m], both increasing.

    Examples
    --------
    >>> [a.tolist() for a in cell_centres(Terrain(10.0, 20.0, 5.0, np.zeros((2, 3))))]
    [[12.5, 17.5, 22.5], [22.5, 27.5]]
    """
    ny, nx = terrain.shape
    return (
        terrain.x0_m + terrain.cell_m * (np.arange(nx) + 0.5),
        terrain.y0_m + terrain.cell_m * (np.arange(ny) + 0.5),
    )


def model3d_from_dict(
    data: dict, *, source: str = "", base_dir: str | os.PathLike[str] | None = None
) -> Model3D:
    """Validate a parsed 3-D model file (module docstring); one-line errors.

    Parameters
    ----------
    data
        The parsed JSON object, with a ``terrain`` block.
    source
        The model file, for messages.
    base_dir
        Where relative file names are looked up (the model file's folder; None: the
        working directory).

    Returns
    -------
    Model3D
    """
    _unknown(data, set(MODEL3D_FIELDS), "", source)
    for key in ("terrain", "materials", "body"):
        if key not in data:
            raise InputFileError("missing", source=source, where=key)
    block = _object(data["terrain"], "terrain", source)
    _unknown(block, set(TERRAIN_FIELDS), "terrain", source)
    for key in ("dem", "materials", "releases"):
        if key not in block:
            raise InputFileError("missing", source=source, where=f"terrain.{key}")
    read: list[str] = []
    base = Path(base_dir) if base_dir is not None else Path()
    dem_path = _file(block["dem"], base, source, "terrain.dem")
    grid = read_dem(dem_path)
    read.append(str(dem_path))
    terrain = terrain_from_dem(grid)
    mats = _object(data["materials"], "materials", source)
    if not mats:
        raise InputFileError("no material defined", source=source, where="materials")
    materials = {
        name: Material.from_dict(name, value, source=source)
        for name, value in mats.items()
    }
    material_index = _material_index(
        block["materials"], terrain, list(materials), base, source, read
    )
    releases, weights = _releases(block["releases"], terrain, base, source, read)
    body = read_body(_object(data["body"], "body", source), source)
    seeder = _seeder3d(_object(data.get("seeder", {}), "seeder", source), source)
    effects = read_effects(data, source)
    core = read_core(data, source)
    trees = None
    if "trees" in data:
        trees = _trees3d(_object(data["trees"], "trees", source), source)
    if "tree_impacts" in effects and trees is None:
        raise InputFileError(
            "tree_impacts is on but the model has no trees", source=source,
            where="trees",
        )  # fmt: skip
    if "tree_impacts" in effects:
        effects["tree_impacts"] = _tree_effect3d(data, effects["tree_impacts"], source)
    lines = tuple(
        analysis_lines_from(data.get("analysis_lines", []), source, "analysis_lines")
    )
    for i, line in enumerate(lines):
        check_line_on_dem(line.xy_m, terrain, source=source,
                          where=f"analysis_lines[{i}].xy_m")  # fmt: skip
    provenance = data.get("provenance", {})
    return Model3D(
        terrain=terrain,
        materials=materials,
        material_index=material_index,
        body=body,
        releases=releases,
        release_weights=weights,
        seeder=seeder,
        effects=effects,
        core=core,
        trees=trees,
        analysis_lines=lines,
        crs=terrain.crs,
        provenance=dict(provenance) if isinstance(provenance, dict) else {},
        source=source,
        source_files=tuple(read),
    )


def _file(value: object, base: Path, source: str, where: str) -> Path:
    """A file named in the model file, relative to its folder; must exist."""
    if not isinstance(value, str) or not value.strip():
        raise InputFileError("must be a file name", source=source, where=where)
    path = Path(value)
    path = path if path.is_absolute() else base / path
    if not path.is_file():
        raise InputFileError(f"file not found: {path}", source=source, where=where)
    return path


def _grid_like(path: Path, terrain: Terrain, source: str, where: str) -> np.ndarray:
    """A raster on the DEM's grid (same size, origin, cell), row 0 south."""
    other = terrain_from_dem(read_dem(path))
    same = other.shape == terrain.shape and same_origin_and_cell(
        (other.x0_m, other.y0_m, other.cell_m),
        (terrain.x0_m, terrain.y0_m, terrain.cell_m),
    )
    if not same:
        ny, nx = other.shape
        raise InputFileError(
            f"{path.name} is not on the DEM's grid: {ny} x {nx} cells of "
            f"{other.cell_m:g} m from ({other.x0_m:.10g}, {other.y0_m:.10g}), the DEM "
            f"has {terrain.shape[0]} x {terrain.shape[1]} of {terrain.cell_m:g} m from "
            f"({terrain.x0_m:.10g}, {terrain.y0_m:.10g})",
            source=source,
            where=where,
        )
    return other.z


def _material_index(
    value: object,
    terrain: Terrain,
    names: list[str],
    base: Path,
    source: str,
    read: list[str],
) -> np.ndarray:
    """``terrain.materials``: a name, a raster of indices or a list of polygons."""
    where = "terrain.materials"
    valid = np.isfinite(terrain.z)
    index = np.full(terrain.shape, -1, np.int64)
    if isinstance(value, str) and value in names:
        index[valid] = names.index(value)
        return index
    if isinstance(value, str):
        if not value.lower().endswith((".tif", ".tiff", ".asc")):
            raise InputFileError(
                f'{value!r} is neither a material of "materials" '
                f"({', '.join(names)}) nor a raster (.tif, .asc)",
                source=source,
                where=where,
            )
        path = _file(value, base, source, where)
        codes = _grid_like(path, terrain, source, where)
        read.append(str(path))
        bad = valid & ~(
            np.isfinite(codes) & (codes == np.round(codes))
            & (codes >= 0) & (codes < len(names))
        )  # fmt: skip
        if bad.any():
            row, col = (int(a[0]) for a in np.nonzero(bad))
            xc, yc = cell_centres(terrain)
            raise InputFileError(
                f"{path.name}: the cell at x = {xc[col]:.10g}, y = {yc[row]:.10g} m "
                f"holds {codes[row, col]:g}; a cell holds the index of a material of "
                f'"materials", 0 to {len(names) - 1} ({", ".join(names)})',
                source=source,
                where=where,
            )
        index[valid] = codes[valid].astype(np.int64)
        return index
    if not isinstance(value, list) or not value:
        raise InputFileError(
            'must be a material name, a raster file or a list of {"material": ..., '
            '"polygon": [[x, y], ...]}',
            source=source,
            where=where,
        )
    xc, yc = cell_centres(terrain)
    gx, gy = np.meshgrid(xc, yc)
    rest = -1
    for i, item in enumerate(value):
        at = f"{where}[{i}]"
        item = _object(item, at, source)
        _unknown(item, {"material", "polygon"}, at, source)
        name = item.get("material")
        if name not in names:
            raise InputFileError(
                f"names material {name!r}, not defined in materials "
                f"(defined: {', '.join(names)})",
                source=source,
                where=f"{at}.material",
            )
        if "polygon" not in item:
            if rest >= 0:
                raise InputFileError(
                    "a second item without a polygon (only one names the material "
                    "of every other cell)",
                    source=source,
                    where=at,
                )
            rest = names.index(name)
            continue
        xy = _xy_list(item["polygon"], source, f"{at}.polygon", minimum=3)
        index[cells_inside(xy, gx, gy)] = names.index(name)
    missing = valid & (index < 0)
    if missing.any():
        if rest < 0:
            row, col = (int(a[0]) for a in np.nonzero(missing))
            raise InputFileError(
                f"{int(missing.sum())} DEM cells lie outside every polygon (e.g. the "
                f"cell at x = {xc[col]:.10g}, y = {yc[row]:.10g} m); add an item "
                '{"material": name} without a polygon for every other cell',
                source=source,
                where=where,
            )
        index[missing] = rest
    index[~valid] = -1
    return index


def _releases(
    value: object, terrain: Terrain, base: Path, source: str, read: list[str]
) -> tuple[np.ndarray, np.ndarray]:
    """``terrain.releases`` -> ``(n, 3)`` points on the ground and ``(n,)`` counts."""
    where = "terrain.releases"
    origin = source
    rows: list[str]
    if isinstance(value, str):
        path = _file(value, base, source, where)
        read.append(str(path))
        if value.lower().endswith((".tif", ".tiff", ".asc")):
            counts = _grid_like(path, terrain, source, where)
            cells = np.isfinite(counts) & (counts > 0)
            if np.any(cells & (counts != np.round(counts))):
                raise InputFileError(
                    f"{path.name}: a release cell holds a count of rocks, a whole "
                    "number",
                    source=source,
                    where=where,
                )
            xc, yc = cell_centres(terrain)
            row, col = np.nonzero(cells)
            xy = np.column_stack([xc[col], yc[row]])
            weights = counts[row, col].astype(np.int64)
            rows = [f"the cell at x = {x:g}, y = {y:g} m" for x, y in xy]
            origin = str(path)
        else:
            releases = read_releases(path)
            if releases.polygons:
                raise InputFileError(
                    f"{path.name} gives release polygons; a 3-D model releases from "
                    "points (x_m, y_m[, count]) or a raster of release cells",
                    source=source,
                    where=where,
                )
            xy = releases.points_m
            weights = releases.point_counts
            rows = [f"row {r}" for r in releases.point_rows]
            origin = str(path)
    else:
        xy = _xy_list(value, source, where, minimum=1)
        weights = np.ones(len(xy), np.int64)
        rows = [f"{where}[{i}]" for i in range(len(xy))]
    if len(xy) == 0:
        raise InputFileError("no release point", source=source, where=where)
    z = terrain.heights(xy[:, 0], xy[:, 1])
    off = ~np.isfinite(z)
    if off.any():
        i = int(np.flatnonzero(off)[0])
        raise InputFileError(
            f"release ({xy[i, 0]:g}, {xy[i, 1]:g}) is off the DEM's ground (outside "
            "its cell centres or next to a nodata cell)",
            source=origin,
            where=rows[i],
        )
    return np.column_stack([xy, z]), np.asarray(weights, np.int64)


def _xy_list(value: object, source: str, where: str, *, minimum: int) -> np.ndarray:
    """A list of ``[x, y]`` pairs [m] of at least ``minimum`` points."""
    try:
        if isinstance(value, str) or not isinstance(value, list):
            raise TypeError(where)
        xy = np.array(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        xy = None
    if xy is None or xy.ndim != 2 or xy.shape[1] != 2 or len(xy) < minimum:
        raise InputFileError(
            f"must be a list of at least {minimum} [x, y] pairs", source=source,
            where=where,
        )  # fmt: skip
    if not np.all(np.isfinite(xy)):
        raise InputFileError("not all finite", source=source, where=where)
    return xy


def _seeder3d(data: dict, source: str) -> Seeder3D:
    """The 3-D seeder: start height above the ground, velocity, spin and their SDs,
    the mass SD; bounded as in 2-D (heights and speeds may not be negative where
    they are sizes)."""
    _unknown(data, set(SEEDER3D_FIELDS), "seeder", source)
    values = {}
    for key, kind in SEEDER3D_FIELDS.items():
        bound = BODY_BOUNDS["mass_kg"][1] if kind == "kg" else SEEDER_BOUNDS[kind]
        size = "_sd_" in key or key == "height_m"
        values[key] = check_number(
            data.get(key, 0.0), 0.0 if size else -bound, bound, source=source,
            where=f"seeder.{key}", unit=_UNITS[kind],
        )  # fmt: skip
    return Seeder3D(**values)


def _tree_effect3d(data: dict, params: dict, source: str) -> dict:
    """``tree_impacts`` of a 3-D model: ``hit_probability`` 1 (the strike is
    geometric; :func:`fieldkit.model.simulate3d.tree_hit_probability`), given as 1
    or left out (2-D's default, 0.5, is not taken)."""

    given = data["effects"]["tree_impacts"]
    params = dict(params)
    if "hit_probability" not in given:
        params["hit_probability"] = 1.0
    elif params["hit_probability"] != 1.0:
        raise InputFileError(
            f"is {params['hit_probability']:g}; {WHY_HIT_PROBABILITY_1} (or left out)",
            source=source,
            where="effects.tree_impacts.hit_probability",
        )
    return params


def _trees3d(data: dict, source: str) -> Trees3D:
    """Tree stems in plan: lists ``x_m, y_m, diameter_m, height_m`` of one length."""
    keys = ("x_m", "y_m", "diameter_m", "height_m")
    _unknown(data, set(keys), "trees", source)
    arrays = number_lists(data, keys, "trees", source)
    for key in keys[1:]:
        if arrays[key].size != arrays["x_m"].size:
            raise InputFileError(
                f"has {arrays[key].size} values, trees.x_m has {arrays['x_m'].size}",
                source=source,
                where=f"trees.{key}",
            )
    d = arrays["diameter_m"]
    if np.any(d <= 0) or np.any(d > TREE_BOUNDS["diameter_m"]):
        raise InputFileError(
            f"must be in (0, {TREE_BOUNDS['diameter_m']:g}] m", source=source,
            where="trees.diameter_m",
        )  # fmt: skip
    h = arrays["height_m"]
    if np.any(h <= 0) or np.any(h > TREE_BOUNDS["height_m"]):
        raise InputFileError(
            f"must be in (0, {TREE_BOUNDS['height_m']:g}] m", source=source,
            where="trees.height_m",
        )  # fmt: skip
    return Trees3D(**arrays)


def analysis_lines_from(data: object, source: str, where: str) -> list[AnalysisLine]:
    """The ``analysis_lines`` block: ``[{"name": ..., "xy_m": [[x, y], ...]}]``."""
    if not isinstance(data, list):
        raise InputFileError(
            'must be a list of {"name": ..., "xy_m": [[x, y], ...]} objects',
            source=source,
            where=where,
        )
    if len(data) > MAX_ANALYSIS_LINES:
        raise InputFileError(
            f"at most {MAX_ANALYSIS_LINES} lines (got {len(data)})",
            source=source,
            where=where,
        )
    out = []
    for i, item in enumerate(data):
        at = f"{where}[{i}]"
        item = _object(item, at, source)
        _unknown(item, {"name", "xy_m"}, at, source)
        if "xy_m" not in item:
            raise InputFileError("missing", source=source, where=f"{at}.xy_m")
        name = item.get("name", "")
        if not isinstance(name, str):
            raise InputFileError("must be text", source=source, where=f"{at}.name")
        out.append(AnalysisLine(line_vertices(item["xy_m"], source, f"{at}.xy_m"),
                                name.strip()))  # fmt: skip
    return out


def check_line_on_dem(
    xy_m: np.ndarray, terrain: Terrain, *, source: str, where: str
) -> None:
    """Refuse a polyline that never enters the DEM's rectangle (no rock can cross
    it there: a line in another coordinate system, or a typing error). A line
    partly outside is accepted.

    Raises
    ------
    InputFileError
        Every segment misses the rectangle (naming ``source`` and ``where``).
    """
    ny, nx = terrain.shape
    x0, y0 = terrain.x0_m, terrain.y0_m
    x1, y1 = x0 + nx * terrain.cell_m, y0 + ny * terrain.cell_m
    for (ax, ay), (bx, by) in zip(xy_m[:-1], xy_m[1:], strict=True):
        # Liang-Barsky: does the segment meet the rectangle?
        lo, hi = 0.0, 1.0
        for p, q in ((-(bx - ax), ax - x0), (bx - ax, x1 - ax),
                     (-(by - ay), ay - y0), (by - ay, y1 - ay)):  # fmt: skip
            if p == 0:
                if q < 0:
                    lo, hi = 1.0, 0.0
            elif p < 0:
                lo = max(lo, q / p)
            else:
                hi = min(hi, q / p)
        if lo <= hi:
            return
    raise InputFileError(
        f"the line never enters the DEM (x {x0:.10g} to {x1:.10g} m, y {y0:.10g} to "
        f"{y1:.10g} m): check its coordinates are in the DEM's system",
        source=source,
        where=where,
    )


def line_vertices(value: object, source: str, where: str) -> np.ndarray:
    """A polyline's vertices ``(n, 2)``: 2 to :data:`MAX_LINE_VERTICES` points,
    consecutive points distinct."""
    xy = _xy_list(value, source, where, minimum=2)
    if len(xy) > MAX_LINE_VERTICES:
        raise InputFileError(
            f"at most {MAX_LINE_VERTICES} points (got {len(xy)})", source=source,
            where=where,
        )  # fmt: skip
    if np.any(np.all(np.diff(xy, axis=0) == 0, axis=1)):
        raise InputFileError(
            "two consecutive points are the same", source=source, where=where
        )
    return xy
