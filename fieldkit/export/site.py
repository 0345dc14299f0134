"""The site a grid target is written on: a DEM, or the model's section extruded.

Grid simulators (Rockyfor3D, r.stone, RAMMS) need a terrain and, cell by cell, the
ground material and where rocks start. fieldkit's model is a 2-D section, so a site
is either

* a DEM the user gives (:func:`site_from_dem`): every cell takes the model's one
  material (a model with several has no plan map of them -- refused, naming them),
  and rocks start in the cell of a release point the user gives, or in the cells
  of a release file's points and polygons (:mod:`fieldkit.io.releases`); or
* the section extruded across (:func:`site_from_section`): columns along the chainage
  (x = chainage), a few rows across with the same ground, each cell the material of
  the segment under its centre, rocks starting in the cells of the seeder's
  chainage. The README of the export states which.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.io.dem import MAX_DEM_CELLS, DemGrid
from fieldkit.io.releases import Releases, cells_inside
from fieldkit.model.model_file import Model


@dataclass(frozen=True)
class ExportSite:
    """Terrain, materials and release cells of a grid export.

    Attributes
    ----------
    grid
        Elevations (NaN = nodata), row 0 north.
    material
        ``(nrows, ncols)`` material name of each cell ("" where there is no ground).
    release
        ``(nrows, ncols)`` bool: the cells rocks start from.
    description
        One line for the README: where the grid came from.
    """

    grid: DemGrid
    material: np.ndarray
    release: np.ndarray
    description: str


def site_from_dem(
    model: Model,
    grid: DemGrid,
    release_xy: tuple[float, float] | None = None,
    *,
    releases: Releases | None = None,
) -> ExportSite:
    """A site on the user's DEM (module docstring).

    Rocks start in the cell holding the release point ``release_xy``, or in the
    cells of ``releases`` (:func:`fieldkit.io.releases.read_releases`): the cell
    holding each of its points and every cell whose centre lies inside one of its
    polygons. Give one of the two.

    Raises
    ------
    ArgumentError
        A model with several materials; no release, or both; ``release_xy`` off
        the DEM or on a nodata cell.
    InputFileError
        A release of ``releases`` off the DEM or on nodata (every such row named,
        in one line), or a polygon holding no cell centre.

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 20], "z_m": [10, 0],
    ...   "material": "talus"}, "materials": {"talus": {"e_n": 0.3, "e_t": 0.8,
    ...   "friction_deg": 30}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 11}})
    >>> g = DemGrid.from_corner(np.zeros((3, 4)), x_left_m=0, y_top_m=15,
    ...                         cellsize_m=5)
    >>> np.argwhere(site_from_dem(m, g, (19.9, 0.1)).release).tolist()
    [[2, 3]]
    """
    if len(model.materials) != 1:
        raise ArgumentError(
            f"the model has {len(model.materials)} materials "
            f"({', '.join(model.materials)}) and no plan map of them: export it on "
            "its own section (`extrude`) or give a one-material model",
            source="dem",
        )
    if (release_xy is None) == (releases is None):
        raise ArgumentError(
            "a DEM site needs the release point (x, y) in the DEM's grid, or a "
            "file of `releases`, one of the two: the model's seeder is a chainage "
            "on its own profile",
            source="release_xy",
        )
    name = next(iter(model.materials))
    valid = np.isfinite(grid.values)
    material = np.where(valid, name, "").astype(object)
    release = np.zeros(grid.shape, bool)
    if release_xy is not None:
        x, y = (float(v) for v in release_xy)
        row, col, problem = _cell_of(grid, x, y)
        if problem:
            raise ArgumentError(
                f"the release ({x:g}, {y:g}) has no ground in the DEM "
                f"{grid.source}: {problem}",
                source="release_xy",
            )
        release[row, col] = True
        where = f"release cell at ({grid.x_m[col]:.10g}, {grid.y_m[row]:.10g})"
    else:
        release = release_cells(grid, releases)
        where = (
            f"{int(release.sum())} release cells from {releases.source} "
            f"({releases.summary()})"
        )
    return ExportSite(
        grid,
        material,
        release,
        f"the DEM {grid.source} ({grid.shape[1]} x {grid.shape[0]} cells of "
        f"{grid.cellsize_m:g} m); material {name} everywhere; {where}",
    )


def _cell_of(grid: DemGrid, x: float, y: float) -> tuple[int, int, str]:
    """``(row, column, "")`` of the cell holding ``(x, y)``, or a problem text: off
    the grid (its extent given) or on a nodata cell (1-based row and column)."""
    col = math.floor((x - grid.x_left_m) / grid.dx_m)
    row = math.floor((grid.y_top_m - y) / grid.dy_m)
    nrows, ncols = grid.shape
    if not (0 <= row < nrows and 0 <= col < ncols):
        x0, y0 = grid.x_left_m, grid.y_bottom_m
        return (
            -1,
            -1,
            f"outside the grid (x {x0:.10g}..{x0 + ncols * grid.dx_m:.10g} m, "
            f"y {y0:.10g}..{y0 + nrows * grid.dy_m:.10g} m)",
        )
    if not np.isfinite(grid.values[row, col]):
        return row, col, f"a nodata cell (grid row {row + 1}, column {col + 1})"
    return row, col, ""


#: Bad releases listed in full in one error line; more are counted.
MAX_LISTED = 10


def release_cells(grid: DemGrid, releases: Releases) -> np.ndarray:
    """``(nrows, ncols)`` bool: the cells of ``releases`` on ``grid``.

    Raises
    ------
    InputFileError
        Naming, in one line, every point (row) off the grid or on a nodata cell,
        every polygon with a vertex off the grid (its rows) or a nodata cell whose
        centre is inside it, and a polygon that holds no cell centre.
    """
    release = np.zeros(grid.shape, bool)
    bad: list[tuple[str, str]] = []
    for (x, y), number in zip(releases.points_m, releases.point_rows, strict=True):
        row, col, problem = _cell_of(grid, float(x), float(y))
        if problem:
            bad.append((f"row {number}", f"({x:g}, {y:g}) {problem}"))
        else:
            release[row, col] = True
    xx, yy = np.meshgrid(grid.x_m, grid.y_m)
    for polygon in releases.polygons:
        outside = [
            (number, problem)
            for (x, y), number in zip(polygon.xy_m, polygon.rows, strict=True)
            if (problem := _cell_of(grid, float(x), float(y))[2]).startswith("outside")
        ]
        if outside:
            bad.append(
                (
                    ", ".join(f"row {n}" for n, _ in outside),
                    f"polygon {polygon.name}: vertex {outside[0][1]}",
                )
            )
            continue
        inside = cells_inside(polygon.xy_m, xx, yy)
        if not inside.any():
            bad.append(
                (
                    polygon.rows_text(),
                    f"polygon {polygon.name} holds no cell centre of the DEM "
                    f"(cells of {grid.cellsize_m:g} m): draw it larger, or give "
                    "its cells as points",
                )
            )
            continue
        nodata = np.argwhere(inside & ~np.isfinite(grid.values))
        if nodata.size:
            cells = ", ".join(f"({r + 1}, {c + 1})" for r, c in nodata[:MAX_LISTED])
            extra = len(nodata) - MAX_LISTED
            more = f" and {extra} more" if extra > 0 else ""
            bad.append(
                (
                    polygon.rows_text(),
                    f"polygon {polygon.name} covers {len(nodata)} nodata cells "
                    f"(grid row, column): {cells}{more}",
                )
            )
            continue
        release |= inside
    if bad:
        more = len(bad) - MAX_LISTED
        raise InputFileError(
            f"{len(bad)} release"
            + ("" if len(bad) == 1 else "s")
            + f" with no cell on ground in the DEM {grid.source}: "
            + "; ".join(f"{where}: {what}" for where, what in bad[:MAX_LISTED])
            + (f"; and {more} more" if more > 0 else ""),
            source=releases.source,
        )
    return release


def site_from_section(
    model: Model, *, cellsize_m: float | None = None, rows: int = 5
) -> ExportSite:
    """The model's section extruded to ``rows`` cells across (module docstring).

    Cells of ``cellsize_m`` (default: the profile length / 500, rounded to 0.5 m,
    at least 0.5 m); column centres from the profile's first x; rows centred on
    y = 0; every cell of a column has the profile's elevation at its centre.
    The grid may have at most :data:`fieldkit.io.dem.MAX_DEM_CELLS` cells, the
    limit of a DEM read as input: more is refused before anything is allocated.

    Raises
    ------
    ArgumentError
        ``cellsize_m`` not > 0, ``rows`` not a whole number >= 2, or a grid of
        more than :data:`~fieldkit.io.dem.MAX_DEM_CELLS` cells (naming ``rows``
        when even two columns are too many, else ``cellsize_m``).

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 10, 20], "z_m": [10, 0, -1],
    ...   "material": ["rock", "talus"]}, "materials": {"rock": {"e_n": 0.3,
    ...   "e_t": 0.8, "friction_deg": 25}, "talus": {"e_n": 0.3, "e_t": 0.8,
    ...   "friction_deg": 30}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 11}})
    >>> s = site_from_section(m, cellsize_m=5, rows=3)
    >>> s.grid.values[1].tolist(), s.material[1].tolist()
    ([7.5, 2.5, -0.25, -0.75], ['rock', 'rock', 'talus', 'talus'])
    >>> s.release.sum(), s.grid.y_m.tolist()
    (np.int64(3), [5.0, 0.0, -5.0])
    """
    x = np.asarray(model.profile.x_m, float)
    length = float(x[-1] - x[0])
    if cellsize_m is None:
        cellsize_m = max(0.5, round(length / 500.0 / 0.5) * 0.5)
    cell = float(cellsize_m)
    if not (math.isfinite(cell) and cell > 0):
        raise ArgumentError(
            f"cellsize_m must be > 0 (got {cell:g})", source="cellsize_m"
        )
    if not (isinstance(rows, int) and rows >= 2):
        raise ArgumentError(
            f"rows must be a whole number >= 2 (got {rows})", source="rows"
        )
    ratio = length / cell  # a float: tiny cells overflow an int, subnormal ones to inf
    columns = max(2.0, math.floor(ratio)) if math.isfinite(ratio) else math.inf
    _check_cell_count(rows, columns, length, cell)
    ncols = int(columns)
    centres = x[0] + cell * (np.arange(ncols) + 0.5)
    z = np.interp(centres, x, model.profile.z_m)
    segment = np.clip(np.searchsorted(x, centres, side="right") - 1, 0, x.size - 2)
    names = np.asarray(model.profile.material, dtype=object)[segment]
    grid = DemGrid.from_corner(
        np.tile(z, (rows, 1)),
        x_left_m=float(x[0]),
        y_top_m=0.5 * rows * cell,
        cellsize_m=cell,
        source=f"{model.source or 'model'} (section extruded)",
    )
    release = np.zeros(grid.shape, bool)
    seed_col = int(np.clip(np.floor((model.seeder.x_m - x[0]) / cell), 0, ncols - 1))
    release[:, seed_col] = True
    return ExportSite(
        grid,
        np.tile(names, (rows, 1)),
        release,
        f"the model's 2-D section extruded to {rows} rows of {ncols} cells of "
        f"{cell:g} m (x = chainage, y across, the same ground in every row); "
        f"release cells in the column at chainage {centres[seed_col]:.10g} m",
    )


def _check_cell_count(rows: int, ncols: float, length_m: float, cell_m: float) -> None:
    """Refuse an extruded grid of more than :data:`MAX_DEM_CELLS` cells (the DEM
    limit), naming ``rows`` if even two columns are too many, else ``cellsize_m``."""
    if rows * ncols <= MAX_DEM_CELLS:
        return

    def count(n: float) -> str:
        return f"{n:,.0f}" if n < 1e12 else f"{n:.3g}"

    what = (
        f"an extruded grid of {rows:,} rows x {count(ncols)} columns "
        f"({length_m:g} m / {cell_m:g} m) is {count(rows * ncols)} cells, more than "
        f"the limit of {MAX_DEM_CELLS:,} (a DEM's)"
    )
    if 2 * rows > MAX_DEM_CELLS:
        raise ArgumentError(
            f"rows must be <= {MAX_DEM_CELLS // 2:,}: {what}", source="rows"
        )
    smallest = length_m * rows / MAX_DEM_CELLS
    raise ArgumentError(
        f"cellsize_m too small: {what}; with {rows:,} `rows` give cells of at "
        f"least {smallest:.3g} m, or fewer `rows`",
        source="cellsize_m",
    )


def ground_cells(site: ExportSite) -> np.ndarray:
    """Cells with ground: a finite elevation and a material."""
    return np.isfinite(site.grid.values) & (site.material != "")


def checked_site(site: ExportSite | None, target: str) -> ExportSite:
    """``site``, checked for a grid target: given, square cells, a release cell on
    ground.

    Raises
    ------
    ArgumentError
        What is missing, naming ``target``.
    """
    if site is None:
        raise ArgumentError(
            f"{target} needs a grid site: a DEM or the section extruded", source="site"
        )
    if not site.grid.square:
        raise ArgumentError(
            f"{target} needs square cells (got {site.grid.dx_m:g} x "
            f"{site.grid.dy_m:g} m)",
            source="site",
        )
    if not (site.release & ground_cells(site)).any():
        raise ArgumentError("the site has no release cell on ground", source="site")
    return site


def pad_site(site: ExportSite, cells: int) -> ExportSite:
    """``site`` with ``cells`` cells added on every side that has a release cell
    closer than ``cells`` to it, so that every release cell lies at least ``cells``
    cells inside the grid (a target that ignores its outer rows or columns, or
    never starts a stone on its edge row, then starts them all).

    The added cells continue the outermost row or column's elevation and material
    (a flat continuation of the edge: it adds no relief a rock could gain speed
    on); none is a release cell. A site whose release cells are all far enough
    inside is returned as it is. The description says what was added.

    Raises
    ------
    ArgumentError
        ``cells`` not a whole number >= 0, or a padded grid of more than
        :data:`~fieldkit.io.dem.MAX_DEM_CELLS` cells.

    Examples
    --------
    >>> g = DemGrid.from_corner(np.arange(12.0).reshape(3, 4), x_left_m=0,
    ...                         y_top_m=15, cellsize_m=5)
    >>> release = np.zeros((3, 4), bool); release[1, 0] = True
    >>> s = ExportSite(g, np.full((3, 4), "rock", object), release, "test")
    >>> p = pad_site(s, 2)
    >>> p.grid.shape, p.grid.x_m[:3].tolist(), float(p.grid.y_m[0])
    ((5, 6), [-7.5, -2.5, 2.5], 17.5)
    >>> np.argwhere(p.release).tolist(), p.grid.values[2, :3].tolist()
    ([[2, 2]], [4.0, 4.0, 4.0])
    >>> pad_site(p, 2) is p
    True
    """
    if isinstance(cells, bool) or not isinstance(cells, int) or cells < 0:
        raise ArgumentError(
            f"cells must be a whole number >= 0 (got {cells})", source="cells"
        )
    rows, cols = np.nonzero(site.release)
    nrows, ncols = site.grid.shape
    if rows.size == 0:
        return site
    top = max(0, cells - int(rows.min()))
    bottom = max(0, cells - (nrows - 1 - int(rows.max())))
    left = max(0, cells - int(cols.min()))
    right = max(0, cells - (ncols - 1 - int(cols.max())))
    if not (top or bottom or left or right):
        return site
    shape = (nrows + top + bottom, ncols + left + right)
    if shape[0] * shape[1] > MAX_DEM_CELLS:
        raise ArgumentError(
            f"padding the grid by {cells} cells gives {shape[0]} x {shape[1]} cells, "
            f"more than the limit of {MAX_DEM_CELLS:,}",
            source="site",
        )
    widths = ((top, bottom), (left, right))
    values = np.pad(site.grid.values, widths, mode="edge")
    material = np.pad(site.material, widths, mode="edge")
    release = np.pad(site.release, widths, mode="constant", constant_values=False)
    g = site.grid
    grid = DemGrid.from_corner(
        values,
        x_left_m=float(g.x_left_m - left * g.dx_m),
        y_top_m=float(g.y_top_m + top * g.dy_m),
        cellsize_m=g.dx_m,
        cellsize_y_m=g.dy_m,
        crs=g.crs,
        source=g.source,
        notes=g.notes,
    )
    sides = ", ".join(
        f"{n} {name}"
        for n, name in (
            (top, "north"),
            (bottom, "south"),
            (left, "west"),
            (right, "east"),
        )
        if n
    )
    return ExportSite(
        grid,
        material,
        release,
        f"{site.description}; padded by {sides} (cells continuing the edge's "
        f"elevation and ground) so every release cell lies >= {cells} cells inside "
        "the grid",
    )
