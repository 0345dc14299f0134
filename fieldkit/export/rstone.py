"""r.stone (GRASS GIS): the calibrated model as the add-on's input rasters.

r.stone is the GRASS GIS add-on implementing STONE (Guzzetti et al. 2002): a point
block falls, bounces and rolls over the triangles of a DEM. Besides the DEM it reads
four rasters of the DEM's geometry:

* ``sources``: whole numbers; a value n > 0 starts n trajectories in the cell, -1
  stops rocks there, 0 and null have no effect;
* ``nrest``, ``trest``: the normal and tangential coefficients of restitution in
  whole percent, 0-100. At a bounce r.stone multiplies the normal and tangential
  velocity components by ``nrest/100`` and ``trest/100`` (``Bounce`` in
  ``points.c``): velocity ratios, as fieldkit's e_n and e_t (eqs. 4.6, 4.7), though
  STONE calls them energy restitution. A cell with nrest 0 stops the rock ("fallen
  into water");
* ``friction``: the rolling friction coefficient ``tan(beta)``, a real number read
  as thousandths (``(long)(value * 1000)``, ``stone.c``). While rolling, r.stone
  decelerates the block by ``g sin(beta)`` in the plane of the triangle (``Roll``).

The files are ESRI ASCII grids (:func:`~fieldkit.export.ascii_grid.ascii_grid_text`)
imported by GDAL's driver (``r.in.gdal``): one format that GIS tools, Rockyfor3D and
:func:`fieldkit.io.dem.read_dem` all read. The translation:

* ``nrest = 100 e_n``, ``trest = 100 e_t``, rounded half up (:func:`percent`); a
  coefficient above 1 is refused (r.stone accepts 0-100 and clips every draw to 1);
* ``friction = tan(friction_deg)``: beta = phi. fieldkit's sliding phase (eq. 7.3)
  decelerates by ``g cos(psi) tan(phi)`` on a slope ``psi``, r.stone by
  ``g sin(phi)``: both balance gravity on the same slope ``psi = phi``; on flatter
  ground r.stone brakes less (by ``cos(phi)`` on the flat). Above 45 deg (tan > 1)
  it is refused, since r.stone clips every friction draw to 1;
* ``sources``: ``rocks`` trajectories shared over the site's release cells (at
  least 1 per cell);
* the DEM: r.stone treats a cell whose elevation is <= 0 as no ground
  (``pivIsValid`` in ``utils.c``), so a DEM reaching 0 is raised by whole metres to
  a lowest elevation of at least 1 m (a datum shift: only differences matter to
  the kinematics), stated in the README;
* the spreads: r.stone draws each coefficient from a Gaussian whose SD is
  ``2 * range / 100`` (``GetRandVElas`` etc., ``stone.c``), ``range`` being one
  whole number per run (``vrest_stoch_range``...), so the calibrated SD maps to
  ``range = 50 SD`` (:func:`stoch_range`), the largest over the materials.

Sources
-------
* r.stone manual (grass.osgeo.org/grass-devel/manuals/addons/r.stone.html; OSGeo
  grass-addons ``src/raster/r.stone/r.stone.md``) and source, read in this session:
  ``main.c`` (options and their defaults), ``stone.c`` (``ReadInputRasters``:
  DEM and friction as thousandths, nrest/trest as whole numbers; ``GetRandVElas``,
  ``GetRandHElas``, ``GetRandFrict``: /100, /1000, Gaussian SD ``2 range / 100``,
  draws clipped to [0, 1]), ``points.c`` (``Bounce``, ``Roll``), ``utils.c``
  (``pivIsValid``), ``fixed_parameters.c`` (5 m flight and roll steps; rolling
  when a bounce is shorter than 3 m and slower than 5 m/s; stochastic runs on).
* Guzzetti, F., Crosta, G., Detti, R., Agliardi, F. (2002). STONE: a computer
  program for the three-dimensional simulation of rock-falls. Computers &
  Geosciences 28(9), 1079-1093.
"""

from __future__ import annotations

import json
import math
import shlex
from dataclasses import replace

import numpy as np

from fieldkit.errors import ArgumentError
from fieldkit.export.ascii_grid import ascii_grid_text
from fieldkit.export.fitted import with_error
from fieldkit.export.lumped import (
    Behaviour,
    Coefficient,
    closest_behaviour,
    fit_coefficients,
    not_a_law,
    search_line,
    with_coefficients,
)
from fieldkit.export.result import Export, Mapped
from fieldkit.export.rstone_law import RstoneLaw
from fieldkit.export.site import (
    ExportSite,
    checked_site,
    ground_cells,
    pad_site,
    site_from_section,
)
from fieldkit.export.translation import translation_error
from fieldkit.io.dem import DemGrid
from fieldkit.model.materials import Material
from fieldkit.model.model_file import Model

TARGET = "rstone"
#: The program's name in the effects' export metadata (:data:`~fieldkit.model.
#: effects.spec.EXPORT_TARGETS`).
PROGRAM = "r.stone"
TITLE = "r.stone (GRASS GIS)"

#: Trajectories in all, as ``fieldkit simulate``'s default ensemble.
DEFAULT_ROCKS = 1000

#: r.stone's defaults for what fieldkit does not calibrate (main.c).
DEFAULT_ANGLE_RANGE = 0
DEFAULT_START_VEL_MPS = 1.0

#: The smallest e_n written: r.stone takes nrest 0 for water, a stop
#: (points.c Bounce), not a rebound law.
NREST_MIN = 0.01

#: r.stone's flight and roll step [m] (fixed_parameters.c): not above the cell size.
STEP_M = 5.0

#: Elevations r.stone takes as ground: above 0 m, at most 9999 m (stone.c NewPlane).
MAX_ELEVATION_M = 9999.0

#: Standard gravity [m/s²], fieldkit's kernel's: the seeder's fall to the ground
#: r.stone starts on happens in fieldkit's world (r.stone's own G, 9.805 m/s² in
#: stone.h, is :data:`fieldkit.export.rstone_law.G_MPS2`).
G_MPS2 = 9.81

#: Cells every release cell keeps from the grid's edge: r.stone never starts a
#: stone whose first triangle needs a cell beyond the edge (``NewPlane`` in
#: ``stone.c`` fails on the north row and east column, ``TrackPoints`` in
#: ``points.c`` then skips every stone of the cell).
EDGE_CELLS = 1

#: The extruded strip for r.stone: rows across (an odd number: the one release
#: cell in the middle row). Measured with the real r.stone (GRASS 8.2.1) on
#: Tornado Mountain's Table 7-1 model, 5 m cells, ang_stoch_range 10, 1000
#: trajectories: the counter grid's rows reached lie 14 rows (70 m) either side of
#: the release row at most; 61 rows (±150 m) hold twice that.
DEFAULT_ROWS = 61

#: The record of the grid written beside the rasters, read by ``import-results``.
RECORD = "fieldkit_export.json"

#: The script the README's recipe runs inside a GRASS session.
SCRIPT = "run_rstone.sh"

#: r.stone's output grids as the script exports them (ESRI ASCII, whole numbers).
OUTPUT_GRIDS = ("counter", "maxvel", "maxdz")


def material_grids(per_material, grid: DemGrid) -> dict[str, str]:
    """r.stone's three material rasters as ESRI ASCII text: ``nrest.asc`` and
    ``trest.asc`` (whole percent) and ``friction.asc`` (tan of the friction angle,
    3 decimals); ``per_material(f)`` maps ``f(material)`` onto the grid (NaN where
    no ground)."""
    return {
        "nrest.asc": ascii_grid_text(
            per_material(lambda m: percent(m.e_n)), grid, integer=True
        ),
        "trest.asc": ascii_grid_text(
            per_material(lambda m: percent(m.e_t)), grid, integer=True
        ),
        "friction.asc": ascii_grid_text(
            per_material(lambda m: math.tan(math.radians(m.friction_deg))),
            grid,
            decimals=3,
        ),
    }


def percent(value: float) -> int:
    """A coefficient as whole percent, rounded half up.

    Examples
    --------
    >>> percent(0.625), percent(0.285), percent(0.754), percent(1.0)
    (63, 29, 75, 100)
    """
    return math.floor(100.0 * value + 0.5 + 1e-9)


def stoch_range(sd: float) -> int:
    """r.stone's whole-number range whose Gaussian SD ``2 range / 100`` is ``sd``.

    Examples
    --------
    >>> stoch_range(0.04), stoch_range(0.0), stoch_range(0.05)
    (2, 0, 3)
    """
    return math.floor(50.0 * sd + 0.5 + 1e-9)


def friction_sd_tan(friction_deg: float, sd_deg: float) -> float:
    """SD of ``tan(phi)`` for an SD of ``phi`` [deg] (first order: sec² phi sd).

    Examples
    --------
    >>> round(friction_sd_tan(0.0, 2.0), 5)
    0.03491
    """
    return math.radians(sd_deg) / math.cos(math.radians(friction_deg)) ** 2


def dem_offset_m(elevations: np.ndarray) -> float:
    """Whole metres to add so the lowest elevation is at least 1 m (0 if it is > 0).

    Examples
    --------
    >>> dem_offset_m(np.array([-7.14, 20.0])), dem_offset_m(np.array([0.0, 5.0]))
    (9.0, 1.0)
    >>> dem_offset_m(np.array([0.5, np.nan]))
    0.0
    """
    lowest = float(np.nanmin(elevations))
    return 0.0 if lowest > 0 else float(math.ceil(1.0 - lowest))


def section_site(
    model: Model, *, cellsize_m: float | None = None, rows: int | None = None
) -> ExportSite:
    """The model's section extruded for r.stone: whole-metre cells, one release cell.

    r.stone stores the cell size as a C ``short`` (``typeGeometry.cell`` in
    ``stone.h``, set from the region in ``ReadInputRasters``, ``stone.c``): a
    1.5 m grid runs as 1 m. So the cell is a whole number of metres, by default
    the profile length / 500 rounded up and at least r.stone's 5 m flight and
    roll step (:data:`STEP_M`); ``rows`` across (default :data:`DEFAULT_ROWS`, a
    strip measured to hold the lateral spread of r.stone's launch angles); the
    one release cell is the seeder's column in the middle row, so every
    trajectory starts on the section's centre line.

    Raises
    ------
    ArgumentError
        ``cellsize_m`` not a whole number of metres >= 1, ``rows`` not a whole
        number >= 3 (or what :func:`~fieldkit.export.site.site_from_section`
        refuses).

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 100], "z_m": [60, 0],
    ...   "material": "rock"}, "materials": {"rock": {"e_n": 0.3, "e_t": 0.8,
    ...   "friction_deg": 25}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 61}})
    >>> s = section_site(m)
    >>> s.grid.cellsize_m, s.grid.shape, np.argwhere(s.release).tolist()
    (5.0, (61, 20), [[30, 0]])
    """
    if cellsize_m is None:
        length = float(model.profile.x_m[-1] - model.profile.x_m[0])
        cellsize_m = max(STEP_M, float(math.ceil(length / 500.0)))
    cell = float(cellsize_m)
    if not (math.isfinite(cell) and cell >= 1 and cell == math.floor(cell)):
        raise ArgumentError(
            f"cellsize_m must be a whole number of metres >= 1 for r.stone (got "
            f"{cell:g}): r.stone stores the cell size as a whole number (a C short), "
            f"so {cell:g} m would run as {max(0, math.floor(cell)):g} m; give e.g. "
            f"{max(math.ceil(cell), 1):g} (default {STEP_M:g}, r.stone's step)",
            source="cellsize_m",
        )
    rows = DEFAULT_ROWS if rows is None else rows
    if isinstance(rows, bool) or not isinstance(rows, int) or rows < 3:
        raise ArgumentError(
            f"rows must be a whole number >= 3 for r.stone (got {rows})", source="rows"
        )
    site = site_from_section(model, cellsize_m=cell, rows=rows)
    release = np.zeros_like(site.release)
    middle = rows // 2
    release[middle] = site.release[middle]
    column = int(np.flatnonzero(release[middle])[0])
    return ExportSite(
        site.grid,
        site.material,
        release,
        f"the model's 2-D section extruded to {rows} rows of {site.grid.shape[1]} "
        f"cells of {cell:g} m (x = chainage, y across, the same ground in every "
        f"row); one release cell, row {middle + 1} (the middle), at chainage "
        f"{site.grid.x_m[column]:.10g} m",
    )


def whole_metre_site(site: ExportSite) -> tuple[ExportSite, str]:
    """``site`` on cells of a whole number of metres, and what was done ("" if
    nothing): a site whose cell is not whole is resampled (bilinear) to the next
    whole metre above its cell, over the same extent.

    r.stone stores the cell size as a whole number (:func:`section_site`).
    Elevations are the bilinear surface of the old grid at the new cell centres
    (cells whose interpolation touches nodata have none); materials and release
    cells take the old cell under the new centre.

    Examples
    --------
    >>> g = DemGrid.from_corner(np.arange(30.0).reshape(3, 10) * 1.0,
    ...     x_left_m=0, y_top_m=7.5, cellsize_m=2.5)
    >>> release = np.zeros((3, 10), bool); release[1, 1] = True
    >>> s = ExportSite(g, np.full((3, 10), "rock", object), release, "test")
    >>> w, how = whole_metre_site(s)
    >>> w.grid.cellsize_m, w.grid.shape, np.argwhere(w.release).tolist()
    (3.0, (2, 8), [[1, 1]])
    >>> how.split(":")[0]
    'cells of 2.5 m resampled (bilinear) to 3 m'
    """
    g = site.grid
    cell = g.cellsize_m
    if cell == math.floor(cell) and cell >= 1:
        return site, ""
    new = float(max(1, math.ceil(cell)))
    width = g.shape[1] * g.dx_m
    height = g.shape[0] * g.dy_m
    ncols, nrows = int(width // new), int(height // new)
    if ncols < 2 or nrows < 2:
        raise ArgumentError(
            f"the grid of {g.shape[1]} x {g.shape[0]} cells of {cell:g} m is too small "
            f"to resample to r.stone's whole-metre cells of {new:g} m",
            source="site",
        )
    left = g.x_left_m
    top = g.y_top_m
    x = left + new * (np.arange(ncols) + 0.5)
    y = top - new * (np.arange(nrows) + 0.5)
    xx, yy = np.meshgrid(x, y)
    z, _, _, _ = g.sample(xx.ravel(), yy.ravel())
    col = np.clip(np.floor((xx - left) / g.dx_m).astype(int), 0, g.shape[1] - 1)
    row = np.clip(np.floor((top - yy) / g.dy_m).astype(int), 0, g.shape[0] - 1)
    grid = DemGrid.from_corner(
        z.reshape(nrows, ncols),
        x_left_m=left,
        y_top_m=top,
        cellsize_m=new,
        crs=g.crs,
        source=g.source,
        notes=g.notes,
    )
    release = np.zeros((nrows, ncols), bool)
    for r, c in np.argwhere(site.release):  # every release cell keeps one
        rr = min(nrows - 1, int((g.y_top_m - g.y_m[r]) // new))
        cc = min(ncols - 1, int((g.x_m[c] - left) // new))
        release[rr, cc] = True
    how = (
        f"cells of {cell:g} m resampled (bilinear) to {new:g} m: r.stone stores the "
        "cell size as a whole number of metres (a C short), so it would run the "
        f"grid as {math.floor(cell):g} m cells"
    )
    return (
        ExportSite(
            grid,
            site.material[row, col],
            release,
            f"{site.description}; {how}",
        ),
        how,
    )


def extruded_chainage_m(model: Model, site: ExportSite) -> np.ndarray | None:
    """The chainage of each column when ``site`` is ``model``'s section extruded
    (every row the profile's elevation at the column centres: x is the chainage),
    else None."""
    g = site.grid
    x = np.asarray(model.profile.x_m, float)
    if g.x_m[0] < x[0] or g.x_m[-1] > x[-1]:
        # padded columns continue the edge: the section's own columns are inside
        inside = (g.x_m >= x[0]) & (g.x_m <= x[-1])
    else:
        inside = np.ones(g.shape[1], bool)
    z = np.interp(g.x_m, x, model.profile.z_m)
    values = g.values
    if not np.isfinite(values).all():
        return None
    same_rows = np.allclose(values, values[0:1], atol=1e-9)
    on_profile = np.allclose(values[0, inside], z[inside], atol=1e-6)
    return g.x_m.copy() if same_rows and on_profile else None


def fall_height_m(model: Model, site: ExportSite) -> float:
    """How far the seeder lies above the ground r.stone starts from [m], >= 0.

    On an extruded section, the seeder's height above the mean elevation of the
    release cells (r.stone starts a stone at its cell's centre, on the ground);
    on a DEM, the seeder's height above the model's own profile at its chainage
    (the release point is the user's, on ground).
    """
    s = model.seeder
    if extruded_chainage_m(model, site) is not None:
        ground = float(np.mean(site.grid.values[site.release]))
    else:
        ground = float(np.interp(s.x_m, model.profile.x_m, model.profile.z_m))
    return max(0.0, s.z_m - ground)


def start_speed_mps(model: Model, height_m: float) -> float:
    """r.stone's start speed keeping the seeder's fall height: the speed at the
    ground, ``sqrt(vx² + vz² + 2 g h)`` (energy conserved over the fall).

    Examples
    --------
    >>> from types import SimpleNamespace as N
    >>> round(start_speed_mps(N(seeder=N(vx_mps=3.0, vz_mps=0.0)), 10.6), 3)
    14.73
    """
    s = model.seeder
    return math.sqrt(s.vx_mps**2 + s.vz_mps**2 + 2.0 * G_MPS2 * height_m)


def friction_read(tan_written: float) -> float:
    """The friction r.stone uses for a written ``tan(beta)``: GDAL hands the
    3-decimal value over as a 32-bit float, r.stone keeps ``(long)(value * 1000)``
    thousandths (``ReadRasterToLongMatrix``, ``stone.c``).

    Examples
    --------
    >>> friction_read(0.35), friction_read(0.05)
    (0.349, 0.05)
    """
    value = float(np.float32(round(tan_written, 3))) * 1000.0
    return math.floor(value + 1e-12) / 1000.0 if value >= 0 else 0.0


def cell_centres_m(
    model: Model, cellsize_m: float | None = None, origin_m: float | None = None
) -> np.ndarray:
    """Chainages of the cell centres along ``model``'s section: the vertices of
    r.stone's planes seen in section.

    As :func:`section_site` lays its columns (cells of ``cellsize_m``, default
    :func:`section_site`'s), or, with ``origin_m``, one centre there (where
    r.stone starts a rock: a release cell's centre) and the others every cell
    either side of it within the profile.

    Examples
    --------
    >>> from types import SimpleNamespace as N
    >>> m = N(profile=N(x_m=[0.0, 21.0]))
    >>> cell_centres_m(m, 5.0).tolist(), cell_centres_m(m, 5.0, 0.0).tolist()
    ([2.5, 7.5, 12.5, 17.5], [0.0, 5.0, 10.0, 15.0, 20.0])
    """
    x = np.asarray(model.profile.x_m, float)
    length = float(x[-1] - x[0])
    if cellsize_m is None:
        cellsize_m = max(STEP_M, float(math.ceil(length / 500.0)))
    cell = float(cellsize_m)
    if origin_m is not None:
        first = math.ceil((x[0] - origin_m) / cell - 1e-9)
        last = math.floor((x[-1] - origin_m) / cell + 1e-9)
        return origin_m + cell * np.arange(first, max(last, first + 1) + 1)
    ncols = max(2, math.floor(length / cell))
    return x[0] + cell * (np.arange(ncols) + 0.5)


def emulated_model(
    model: Model,
    options: dict[str, float],
    release_x_m: float,
    names: list[str] | None = None,
    *,
    chainage_m: np.ndarray | None = None,
    cell_id: np.ndarray | None = None,
) -> RstoneLaw:
    """fieldkit's emulation of r.stone's law with the values written for ``model``:
    r.stone's own kernel ported along the section
    (:class:`~fieldkit.export.rstone_law.RstoneLaw`, what is ported and what not:
    :mod:`fieldkit.export.rstone_law`).

    The section's vertices are the cell centres at ``chainage_m`` (default
    :func:`cell_centres_m`), their ground ``model``'s profile there (continued
    flat beyond its ends, as padded columns); each cell the values written for
    the material of the profile segment under its centre: nrest and trest in
    whole percent (:func:`percent`), ``tan(beta)`` as r.stone reads it
    (:func:`friction_read`); the spread ranges, ``start_vel`` and ``stop_vel``
    of ``options``; the rocks start on the ground at ``release_x_m``; energies
    with the body's mass. ``cell_id``: the DEM cell of each vertex when the
    vertices are not cell centres (:func:`tin_section`). ``names`` is accepted
    for the callers' symmetry: every material of ``model`` is taken as written.
    """
    del names
    x = np.asarray(model.profile.x_m, float)
    vertices = (
        cell_centres_m(model) if chainage_m is None else np.asarray(chainage_m, float)
    )
    z = np.interp(vertices, x, model.profile.z_m)
    segment = np.clip(np.searchsorted(x, vertices, side="right") - 1, 0, x.size - 2)
    material = np.asarray(model.profile.material, dtype=object)[segment]
    table = {
        name: (
            percent(m.e_n),
            percent(m.e_t),
            friction_read(math.tan(math.radians(m.friction_deg))),
        )
        for name, m in model.materials.items()
    }
    values = np.array([table[name] for name in material], float)
    return RstoneLaw(
        x_m=vertices,
        z_m=z,
        nrest_pct=values[:, 0].astype(np.int64),
        trest_pct=values[:, 1].astype(np.int64),
        friction_tan=values[:, 2],
        vrest_stoch_range=int(options["vrest_stoch_range"]),
        hrest_stoch_range=int(options["hrest_stoch_range"]),
        frict_stoch_range=int(options["frict_stoch_range"]),
        start_vel_mps=float(options["start_vel"]),
        stop_vel_mps=float(options["stop_vel"]),
        release_x_m=float(release_x_m),
        mass_kg=float(model.body.mass_kg),
        cell_id=cell_id,
    )


#: Plan spacing [m] of the points of a section through r.stone's triangles
#: (:func:`tin_section`): the triangles' edges are crossed within it.
TIN_STEP_M = 0.5


def tin_section(
    grid: DemGrid, plan_x_m: np.ndarray, plan_y_m: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The ground of r.stone's triangles under plan points, and each point's cell.

    r.stone's surface (``NewPlane``, ``stone.c``) is two triangles per square
    of four cell centres: type 1 with its right angle at the south-west centre
    (below the diagonal from the south-east to the north-west centre), type 2 at
    the north-east one; each plane through its three centres' elevations.

    Returns
    -------
    z_m, cell_id
        The elevation on that surface, and the id (``row * ncols + col``) of the
        cell whose centre is nearest (the cell r.stone reads values from).

    Examples
    --------
    >>> g = DemGrid.from_corner(np.array([[4.0, 0.0], [0.0, 0.0]]), x_left_m=0,
    ...     y_top_m=2, cellsize_m=1)
    >>> z, cell = tin_section(g, np.array([0.5, 1.0, 1.25]), np.array([1.5, 1.0, 1.25]))
    >>> z.tolist(), cell.tolist()
    ([4.0, 2.0, 1.0], [0, 3, 1])
    """
    x0, y0, cell = float(grid.x_m[0]), float(grid.y_m[0]), float(grid.cellsize_m)
    rows, cols = grid.shape
    px, py = np.asarray(plan_x_m, float), np.asarray(plan_y_m, float)
    col = np.clip(np.floor((px - x0) / cell).astype(int), 0, cols - 2)
    south = np.clip(np.floor((y0 - py) / cell).astype(int) + 1, 1, rows - 1)
    north = south - 1
    u = (px - grid.x_m[col]) / cell
    v = (py - grid.y_m[south]) / cell
    z = grid.values
    sw, se = z[south, col], z[south, col + 1]
    nw, ne = z[north, col], z[north, col + 1]
    first = sw + u * (se - sw) + v * (nw - sw)
    second = ne + (1 - u) * (nw - ne) + (1 - v) * (se - ne)
    nearest_col = np.clip(np.floor((px - x0) / cell + 0.5).astype(int), 0, cols - 1)
    nearest_row = np.clip(np.floor((y0 - py) / cell + 0.5).astype(int), 0, rows - 1)
    return np.where(v <= 1 - u, first, second), nearest_row * cols + nearest_col


def emulated_runouts(
    model: Model, record: dict, grid: DemGrid | None = None, *, seed: int = 0
) -> tuple[np.ndarray, np.ndarray]:
    """fieldkit's emulation of an r.stone run: the runout of each trajectory the
    export's ``record`` (:data:`RECORD`) starts, and whether it left its section
    at the lower end (a censored runout).

    The values written (``record["written"]``, ``record["options"]``) under
    r.stone's law (:func:`emulated_model`). On an extruded section: the columns'
    chainages (``record["chainage_m"]``) as the vertices of ``model``'s own
    section, the rocks launched at the release column's chainage. On a DEM
    (``grid``): for each source cell, the steepest-descent section from its
    centre (:func:`~fieldkit.model.dem_profile.steepest_descent_line`, half-cell
    steps) continued straight to the grid's edge where it ends in a pit or a
    flat, as ``fieldkit fit-paths`` cuts Tschamut's runs
    (:func:`~fieldkit.fit.path_sections.extend_to_edge`), its ground the section
    through r.stone's triangles (:func:`tin_section`, points every
    :data:`TIN_STEP_M` of plan chainage, each with its cell's values and
    friction draw), its trajectories launched at chainage 0; a
    runout is then the plan distance of the rock's stop on that line from the
    nearest source cell's centre, as ``import-results`` measures r.stone's
    (:mod:`fieldkit.io.rstone_results`). A rock that reaches its section's end
    leaves it (its runout is censored).

    Raises
    ------
    ArgumentError
        A DEM record without ``grid``.
    """

    from fieldkit.fit.path_sections import extend_to_edge
    from fieldkit.model.dem_profile import steepest_descent_line
    from fieldkit.model.profile import Profile
    from fieldkit.model.results import EXITED_DOWNSLOPE

    materials = dict(model.materials)
    for name, values in record["written"].items():
        materials[name] = replace(materials[name], **values)
    written = replace(model, materials=materials)
    options = record["options"]
    names = list(record["written"])
    rng = np.random.default_rng(seed)
    if record["extruded"]:
        x = float(np.mean([s["x_m"] for s in record["sources"]]))
        emulated = emulated_model(
            written, options, x, names, chainage_m=np.asarray(record["chainage_m"])
        )
        result = emulated.simulate(int(record["trajectories"]), rng)
        runout = np.asarray(result.runout_x_m, float)
        return runout, np.asarray(result.state) == EXITED_DOWNSLOPE
    if grid is None:
        raise ArgumentError("a DEM record needs its DEM to emulate", source="grid")
    runouts, ends = [], []
    sx = np.array([s["x_m"] for s in record["sources"]])
    sy = np.array([s["y_m"] for s in record["sources"]])

    def from_sources(line, chainage: np.ndarray) -> np.ndarray:
        px = np.interp(chainage, line.chainage_m, line.plan_x_m)
        py = np.interp(chainage, line.chainage_m, line.plan_y_m)
        return np.hypot(px[:, None] - sx, py[:, None] - sy).min(axis=1)

    cell = grid.cellsize_m
    for s in record["sources"]:
        line = extend_to_edge(
            grid, steepest_descent_line(grid, (s["x_m"], s["y_m"]), cell / 2), cell / 2
        )
        vertices = np.append(np.arange(0.0, line.length_m, TIN_STEP_M), line.length_m)
        if vertices[-1] - vertices[-2] < 1e-6:
            vertices = vertices[:-1]
        z, cells = tin_section(
            grid,
            np.interp(vertices, line.chainage_m, line.plan_x_m),
            np.interp(vertices, line.chainage_m, line.plan_y_m),
        )
        profile = Profile.from_arrays(vertices, z, [names[0]] * (z.size - 1))
        emulated = emulated_model(
            replace(written, profile=profile),
            options,
            0.0,
            names,
            chainage_m=vertices,
            cell_id=cells,
        )
        result = emulated.simulate(int(s["trajectories"]), rng)
        runouts.append(from_sources(line, np.asarray(result.runout_x_m, float)))
        ends.append(np.asarray(result.state) == EXITED_DOWNSLOPE)
    return np.concatenate(runouts), np.concatenate(ends)


def constant_pair(model: Model, name: str) -> bool:
    """Whether ``name``'s calibrated law is r.stone's: a constant pair in [0, 1],
    no effect, no roughness (the values are then written as calibrated)."""
    m = model.materials[name]
    return (
        not model.effects
        and m.roughness_m == 0
        and m.roughness_deg_sd == 0
        and 0 <= m.e_n <= 1
        and 0 <= m.e_t <= 1
    )


def rstone_pairs(
    model: Model,
    names: list[str],
    release_x_m: float,
    height_m: float,
    *,
    chainage_m: np.ndarray | None = None,
) -> tuple[Model, list[str], list[str], Behaviour | None]:
    """``model`` with each material's e_n, e_t (and their SDs) the in-range
    constant pair closest under r.stone's law, and what was done.

    Materials whose calibrated law is already r.stone's (:func:`constant_pair`,
    all of them) keep their values. Otherwise every material takes the pair in
    [0, 1] (e_n at least :data:`NREST_MIN`) minimising the squared rebound
    error over its impacts in the calibrated model's own simulation
    (:func:`fieldkit.export.lumped.fit_coefficients` with ``f = 1``); from there
    :func:`fieldkit.export.lumped.closest_behaviour` searches the pairs whose
    emulation under r.stone's law (:func:`emulated_model`, vertices at
    ``chainage_m``) behaves closest to the
    calibrated model (runout, design energy and bounce height), written only if
    they also do so on an independent stream, in whole percent. Each written
    value is shown with the impacts' own spread around it (not the fit's
    standard error); r.stone's random draws keep the calibrated SDs, since that
    spread is mostly the calibrated law's systematic change with impact speed,
    not scatter; roughness goes (r.stone has none). A material no simulated
    rock touched is said loudly (:func:`~fieldkit.export.lumped.fit_coefficients`).

    Returns
    -------
    model, mismatches, unconfirmed, search
    """

    if all(constant_pair(model, n) for n in names):
        return model, [], [], None
    ranges = ((NREST_MIN, 1.0), (0.0, 1.0))
    coefficients, loud = fit_coefficients(model, "r.stone", np.ones_like, *ranges)

    def written(values: dict[str, tuple[Coefficient, Coefficient]]) -> Model:
        # The draw SDs stay the calibrated e_n_sd, e_t_sd: the impacts' spread
        # around a constant pair is mostly the law's systematic change with impact
        # speed or angle, which a random draw would turn into noise (the README
        # shows it beside each written value).
        out = with_coefficients(model, values)
        materials = {
            name: replace(m, roughness_m=0.0, roughness_deg_sd=0.0)
            for name, m in out.materials.items()
        }
        return replace(out, materials=materials)

    def emulate(values: dict[str, tuple[Coefficient, Coefficient]]) -> RstoneLaw:
        w = written(values)
        return emulated_model(
            w, _options(w, names, height_m), release_x_m, names, chainage_m=chainage_m
        )

    coefficients, search = closest_behaviour(
        model, coefficients, emulate, np.ones_like, *ranges,
        precision=lambda v: percent(v) / 100,
    )  # fmt: skip
    laws = ", ".join(model.effects) or "no effect"
    lines = [
        f"{name}: r.stone's law is a constant pair; the calibrated e_n "
        f"{model.materials[name].e_n:.4g}, e_t {model.materials[name].e_t:.4g} with "
        f"{laws} (roughness {model.materials[name].roughness_deg_sd:g} deg) are "
        f"written as e_n {rn.text()}, e_t {rt.text()}"
        + "".join(
            f"; {c.name.rsplit('.', 1)[1]}: the least-squares value {c.unclipped:.3f} "
            "under r.stone's law lies outside its range and was clipped to "
            f"{min(max(c.unclipped, lo), hi):g}"
            for c, (lo, hi) in zip((rn, rt), ranges, strict=True)
            if c.clipped and c.n
        )
        + "".join(f"; {w}" for w in (not_a_law(e, TARGET) for e in model.effects) if w)
        for name, (rn, rt) in coefficients.items()
        if name in names
    ]
    return (
        written(coefficients),
        [*lines, *loud, *search_line(search, TARGET)],
        list(loud),
        search,
    )


def _check(model: Model, names: list[str]) -> None:
    """Refuse coefficients r.stone cannot take (one line naming the value)."""
    for name in names:
        m = model.materials[name]
        for key in ("e_n", "e_t"):
            value = getattr(m, key)
            if value > 1.0:
                raise ArgumentError(
                    f"materials.{name}.{key} = {value:g}: r.stone accepts restitution "
                    "0-100 % (0-1) and clips every draw to 1",
                    source="model",
                )
        if m.friction_deg > 45.0:
            raise ArgumentError(
                f"materials.{name}.friction_deg = {m.friction_deg:g}: r.stone clips "
                "its rolling friction tan(beta) to 1 (beta <= 45 deg)",
                source="model",
            )


def export_rstone(
    model: Model, site: ExportSite | None = None, *, rocks: int = DEFAULT_ROCKS
) -> Export:
    """r.stone's input rasters for ``model`` on ``site`` (module docstring), the
    script that runs them (:data:`SCRIPT`) and the record of the grid
    (:data:`RECORD`) that ``fieldkit import-results --from rstone`` reads.

    Parameters
    ----------
    model
        The calibrated model.
    site
        The grid (required: a grid target); :func:`section_site` extrudes the
        model's section as r.stone needs it. A grid whose cell is not a whole
        number of metres is resampled (:func:`whole_metre_site`), one whose
        release cells touch the edge padded (:data:`EDGE_CELLS`), both stated.
    rocks
        Trajectories in all, shared over the release cells (at least 1 a cell).

    Raises
    ------
    ArgumentError
        No site, no release cell on ground, ``rocks`` < 1, a restitution above 1, a
        friction angle above 45 deg, or a DEM whose relief exceeds 9998 m.
    """
    site = checked_site(site, TARGET)
    if isinstance(rocks, bool) or not isinstance(rocks, int) or rocks < 1:
        raise ArgumentError(
            f"rocks must be a whole number >= 1 (got {rocks})", source="rocks"
        )
    site, resampled = whole_metre_site(site)
    site = pad_site(site, EDGE_CELLS)
    calibrated = model
    grid = site.grid
    ground = ground_cells(site)
    source = site.release & ground
    present = [n for n in model.materials if (site.material[ground] == n).any()]
    chainage = extruded_chainage_m(model, site)
    release_x = (
        float(np.mean(grid.x_m[np.nonzero(source)[1]]))
        if chainage is not None
        else model.seeder.x_m
    )
    height = fall_height_m(model, site)
    vertices = (
        chainage
        if chainage is not None
        else cell_centres_m(model, grid.cellsize_m, release_x)
    )
    model, fitted, open_, _ = rstone_pairs(
        model, present, release_x, height, chainage_m=vertices
    )
    _check(model, present)
    offset = dem_offset_m(grid.values[ground])
    dem = np.where(ground, grid.values + offset, np.nan)
    if np.nanmax(dem) > MAX_ELEVATION_M:
        raise ArgumentError(
            f"the DEM reaches {np.nanmax(dem):.6g} m after a shift of {offset:g} m: "
            f"r.stone takes elevations in (0, {MAX_ELEVATION_M:g}] m as ground",
            source="site",
        )
    n_source = int(source.sum())
    per_cell = max(1, round(rocks / n_source))
    options = _options(model, present, height)

    def per_material(value) -> np.ndarray:
        out = np.full(grid.shape, np.nan)
        for name in present:
            out[ground & (site.material == name)] = value(model.materials[name])
        return out

    files: dict[str, str | bytes] = {
        "dem.asc": ascii_grid_text(dem, grid, decimals=3),
        "sources.asc": ascii_grid_text(
            np.where(ground, np.where(source, per_cell, 0), np.nan), grid, integer=True
        ),
        **material_grids(per_material, grid),
        SCRIPT: run_script(options),
    }
    files[RECORD] = record_text(
        model, site, source, per_cell, offset, chainage, options
    )
    traced = per_cell * n_source
    emulated = emulated_model(model, options, release_x, present, chainage_m=vertices)
    translation = translation_error(calibrated, emulated)
    return Export(
        TARGET,
        TITLE,
        files,
        mapped=_mapped(model, site, present, offset, per_cell, options),
        unmapped=_unmapped(calibrated, present),
        units=[
            "nrest, trest: e_n and e_t x 100, whole percent (rounded half up)",
            "friction: tan(friction_deg), dimensionless, 3 decimals (r.stone reads "
            "thousandths)",
            f"dem: metres (fieldkit's SI), raised by {offset:g} m"
            if offset
            else "dem: metres (fieldkit's SI), as given",
            f"cell size: {grid.cellsize_m:g} m, a whole number (r.stone stores it "
            "as a C short)",
            "sources: numbers of trajectories; start_vel, stop_vel in m/s",
            "results (counter, maxvel, maxdz): trajectories through a cell, the "
            "largest speed in whole m/s and the largest height above the ground in "
            "whole m, both truncated (stone.c MarkVelo, MarkQuota)",
        ],
        mismatches=[
            *fitted,
            *([resampled] if resampled else []),
            *_mismatches(model, present, offset, options),
        ],
        notes=_notes(site, traced, n_source, per_cell, chainage is not None),
        how_to_use=_how_to_use(options, traced),
        translation=[
            *translation.lines(),
            "",
            emulation_text(release_x, grid.cellsize_m),
        ],
        sources=SOURCES,
        unconfirmed=[*UNCONFIRMED, *open_],
    )


def emulation_text(release_x_m: float, cellsize_m: float) -> str:
    """What fieldkit's emulation of r.stone's law is (the README's translation
    section): :func:`emulated_model`, :mod:`fieldkit.export.rstone_law`."""
    return (
        "The emulation of r.stone's law is a 2-D port of r.stone's own kernel "
        "(fieldkit.export.rstone_law, from points.c TrackPoints, Parab, Bounce, "
        "Roll and stone.c) along the section, its vertices the cell centres "
        f"({cellsize_m:g} m apart), each segment one of r.stone's planes seen in "
        "section; each cell the values written (nrest, trest in whole percent, "
        "tan(beta) in thousandths as r.stone reads them). Ported: the launch "
        f"(horizontal at start_vel from the ground at chainage {release_x_m:.1f} m, "
        "towards the lower neighbour); flight as a parabola under r.stone's g = "
        "9.805 m/s² to the ground; at a landing, rolling when the bounce was "
        "shorter than 3 m and slower than 5 m/s (both), else a bounce: normal "
        "velocity x -nrest, tangential x trest, each drawn per bounce (Gaussian SD "
        "2 range / 100, clipped to [0, 1]), a stop below stop_vel; rolling with the "
        "velocity in the plane, decelerated by g sin(beta) against the motion, "
        "tan(beta) drawn for each cell entered, 5 m steps with r.stone's 'stop "
        "between two steps', flight again where a step ends more than 0.01 m above "
        "the next plane (a convex break), a stop below stop_vel. Not ported: the "
        "3-D geometry of r.stone's two triangles per cell (lateral components of "
        "velocity and gravity), the lateral spread of the launch angle "
        f"(ang_stoch_range, written as {DEFAULT_ANGLE_RANGE}), the 5 m flight steps "
        "(the parabola's landing is exact), and r.stone's output sampling (its grids "
        "are marked at path points 5 m apart). Energies use the model's mass "
        "(r.stone has none), with no rotation."
    )


def rstone_arguments(options: dict[str, float], angle_range: int) -> str:
    """r.stone's scalar arguments from ``options`` (:func:`_options`): the uniform
    stochastic functions, ``angle_range`` as ``ang_stoch_range``, the three
    spread ranges, ``start_vel`` and ``stop_vel``."""
    o = options
    return " ".join(
        f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
        for k, v in (
            ("stoch_funct", 0),
            ("stoch_funct_ang", 0),
            ("ang_stoch_range", int(angle_range)),
            ("vrest_stoch_range", int(o["vrest_stoch_range"])),
            ("hrest_stoch_range", int(o["hrest_stoch_range"])),
            ("frict_stoch_range", int(o["frict_stoch_range"])),
            ("start_vel", round(float(o["start_vel"]), 3)),
            ("stop_vel", float(o["stop_vel"])),
        )
    )


def run_script(options: dict[str, float]) -> str:
    """The bash script run inside a GRASS session (:func:`_how_to_use`): import
    the five grids, set the region to the DEM, run r.stone with ``options``, write
    its three result grids as ESRI ASCII beside the inputs."""
    args = rstone_arguments(options, DEFAULT_ANGLE_RANGE)
    rasters = " ".join(f"{n}={n}" for n in ("dem", "sources", "nrest", "trest",
                                            "friction"))  # fmt: skip
    outputs = " ".join(f"{n}={n}" for n in OUTPUT_GRIDS)
    return f"""#!/usr/bin/env bash
# r.stone on the files beside this script, written by fieldkit export --to rstone.
# Run it inside a GRASS GIS session (8.2), e.g. in a new XY project:
#   grass -c XY /tmp/grassdb/xy -e
#   grass /tmp/grassdb/xy/PERMANENT --exec bash {shlex.quote(SCRIPT)}
# It writes counter.asc, maxvel.asc and maxdz.asc here (ESRI ASCII, nodata -1)
# for `fieldkit import-results --from rstone`.
set -euo pipefail
cd "$(dirname "$0")"
for name in dem sources nrest trest friction; do
    r.in.gdal -o --overwrite --quiet input="$name.asc" output="$name"
done
g.region raster=dem
r.stone --overwrite {rasters} \\
    {args} \\
    {outputs}
for name in {" ".join(OUTPUT_GRIDS)}; do
    r.out.gdal -c -m --overwrite --quiet input="$name" output="$name.asc" \\
        format=AAIGrid type=Int32 nodata=-1
done
"""


def record_text(model, site, source, per_cell, offset, chainage, options) -> str:
    """The JSON record of the grid (:data:`RECORD`) that ``import-results`` reads:
    the grid's geometry, the source cells and their trajectories, the DEM offset,
    the body's mass, and the chainage of each column for an extruded section."""
    g = site.grid
    cells = [
        {
            "row": int(r),
            "col": int(c),
            "x_m": float(g.x_m[c]),
            "y_m": float(g.y_m[r]),
            "trajectories": int(per_cell),
        }
        for r, c in np.argwhere(source)
    ]
    record = {
        "target": TARGET,
        "grid": {
            "ncols": int(g.shape[1]),
            "nrows": int(g.shape[0]),
            "x_left_m": g.x_left_m,
            "y_top_m": g.y_top_m,
            "cellsize_m": float(g.cellsize_m),
        },
        "dem_offset_m": float(offset),
        "sources": cells,
        "trajectories": int(per_cell * len(cells)),
        "extruded": chainage is not None,
        "chainage_m": None if chainage is None else [float(v) for v in chainage],
        "mass_kg": float(model.body.mass_kg),
        "start_vel_mps": float(options["start_vel"]),
        "fall_height_m": float(options["fall_height_m"]),
        "model": model.source,
        "options": {k: float(v) for k, v in options.items()},
        "written": {
            name: {
                "e_n": float(m.e_n),
                "e_t": float(m.e_t),
                "friction_deg": float(m.friction_deg),
            }
            for name, m in model.materials.items()
            if (site.material == name).any()
        },
    }
    return json.dumps(record, indent=1) + "\n"


def _ranges(m: Material) -> dict[str, int]:
    """r.stone's spread ranges for one material (:func:`stoch_range`)."""
    return {
        "vrest_stoch_range": stoch_range(m.e_n_sd),
        "hrest_stoch_range": stoch_range(m.e_t_sd),
        "frict_stoch_range": stoch_range(
            friction_sd_tan(m.friction_deg, m.friction_deg_sd)
        ),
    }


def _options(model: Model, names: list[str], height_m: float) -> dict[str, float]:
    """The r.stone options fieldkit can set (one value per run), and the fall
    height the start speed keeps (:func:`start_speed_mps`)."""
    ranges = [_ranges(model.materials[n]) for n in names]
    speed = start_speed_mps(model, height_m)
    out: dict[str, float] = {k: max(r[k] for r in ranges) for k in ranges[0]}
    out["start_vel"] = round(speed, 3) if speed > 0 else DEFAULT_START_VEL_MPS
    out["stop_vel"] = model.core["stop_speed_mps"]
    out["fall_height_m"] = height_m
    return out


def _how_to_use(options: dict[str, float], traced: int) -> str:
    return f"""\
With GRASS GIS 8.2 and the add-on installed (`g.extension r.stone`, or built from
its source), make a new XY project and run `{SCRIPT}` (written here) inside it:

    grass -c XY ~/grassdata/rstone -e
    grass ~/grassdata/rstone/PERMANENT --exec bash {SCRIPT}

(`grass -c dem.asc ...` gives a 0 x 0 region on GRASS 8.2.1: use an XY project.)
The script imports the five ESRI ASCII grids through GDAL (`r.in.gdal -o`), sets
the region to the DEM, runs r.stone with the values derived from the model (see
the tables below):

    r.stone dem=dem sources=sources nrest=nrest trest=trest friction=friction \\
        stoch_funct=0 stoch_funct_ang=0 ang_stoch_range={DEFAULT_ANGLE_RANGE} \\
        vrest_stoch_range={options["vrest_stoch_range"]} \\
        hrest_stoch_range={options["hrest_stoch_range"]} \\
        frict_stoch_range={options["frict_stoch_range"]} \\
        start_vel={options["start_vel"]:g} stop_vel={options["stop_vel"]:g} \\
        counter=counter maxvel=maxvel maxdz=maxdz

and writes `counter.asc`, `maxvel.asc`, `maxdz.asc` beside the inputs (`r.out.gdal
format=AAIGrid`). r.stone traces {traced} trajectories; `counter` counts the
trajectories through each cell. Read the results back with

    fieldkit import-results --from rstone . -o rstone_results

for the runout distribution and the largest speed, energy and height along the
section (or by distance from the release on a DEM)."""


def _mapped(model, site, present, offset, per_cell, options) -> list[Mapped]:
    n_source = int((site.release & ground_cells(site)).sum())
    shift = f"; raised by {offset:g} m (r.stone needs elevations > 0)" if offset else ""
    out = [
        Mapped(
            "site terrain (DEM or extruded profile)",
            f"dem.asc [m]{shift}",
            site.description,
        ),
        Mapped(
            "seeder (where rocks start)",
            f"sources.asc = {per_cell} in {n_source} release "
            + ("cell" if n_source == 1 else "cells")
            + ", 0 elsewhere",
            f"{per_cell * n_source} trajectories in all",
        ),
    ]
    for name in present:
        m = model.materials[name]
        for key, raster in (("e_n", "nrest"), ("e_t", "trest")):
            value = getattr(m, key)
            out.append(
                Mapped(
                    with_error(model, f"materials.{name}.{key}", value),
                    f"{raster}.asc = {percent(value)} %",
                    "x 100, rounded half up; r.stone multiplies the "
                    + ("normal" if key == "e_n" else "tangential")
                    + " velocity by it at a bounce",
                )
            )
        tan_phi = math.tan(math.radians(m.friction_deg))
        out.append(
            Mapped(
                with_error(model, f"materials.{name}.friction_deg", m.friction_deg),
                f"friction.asc = tan(beta) = {tan_phi:.3f}",
                "beta = phi: rolling balances gravity on the slope phi in both",
            )
        )
    s = model.seeder
    out += [
        Mapped(
            "materials: e_n_sd, e_t_sd, friction_deg_sd (largest over the materials)",
            f"vrest_stoch_range = {options['vrest_stoch_range']}, hrest_stoch_range ="
            f" {options['hrest_stoch_range']}, frict_stoch_range = "
            f"{options['frict_stoch_range']} (stoch_funct = 0, Gaussian)",
            "range = 50 SD: r.stone's Gaussian SD is 2 range / 100 (friction SD in "
            "tan units: sec² phi x SD)",
        ),
        Mapped(
            f"seeder speed hypot(vx, vz) = {math.hypot(s.vx_mps, s.vz_mps):g} m/s, "
            f"{options['fall_height_m']:.3g} m above the ground r.stone starts on",
            f"start_vel = {options['start_vel']:g} m/s",
            "the speed at the ground, sqrt(vx² + vz² + 2 g h) with g = 9.81 m/s²: "
            "r.stone starts a stone on its cell's ground, launched horizontally "
            "towards the steepest neighbour (points.c TrackPoints), so the fall "
            "height is kept as speed (energy conserved) rather than as a raised "
            "cell, which would tilt the triangles around it"
            + (
                ""
                if options["start_vel"] != DEFAULT_START_VEL_MPS
                or start_speed_mps(model, options["fall_height_m"]) > 0
                else f"; the seeder is at rest on the ground, so r.stone's default "
                f"{DEFAULT_START_VEL_MPS:g} m/s (it needs a speed > 0)"
            ),
        ),
        Mapped(
            f"core.stop_speed_mps = {model.core['stop_speed_mps']:g} m/s",
            f"stop_vel = {options['stop_vel']:g} m/s",
            "r.stone stops a rock slower than this (its default is 3 m/s)",
        ),
    ]
    return out


def _unmapped(model: Model, present: list[str]) -> list[tuple[str, str]]:
    b, s = model.body, model.seeder
    out = [
        (
            f"body (mass {b.mass_kg:g} kg, radius {b.radius_m:g} m, gyration "
            f"{b.gyration_m:g} m)",
            "r.stone's block is a point (lumped mass): neither mass nor size enters "
            "its kinematics",
        ),
        (
            f"seeder direction and spreads (vx {s.vx_mps:g}, vz {s.vz_mps:g} m/s; SDs"
            f" {s.vx_sd_mps:g}, {s.vz_sd_mps:g} m/s)",
            "r.stone launches horizontally towards the steepest neighbour cell, the "
            "angle drawn with ang_stoch_range; only the speed is mapped (start_vel)",
        ),
        (
            f"lateral spread (ang_stoch_range = {DEFAULT_ANGLE_RANGE}, not r.stone's "
            "default 10)",
            "fieldkit's model is a 2-D section: it calibrates no spread across it, so "
            "none is written; r.stone's default 10 would add one nobody calibrated "
            "(on the Tschamut release area it moves r.stone's runout p95 from 90 m "
            "to 115 m, p50 unchanged at 70 m): set ang_stoch_range in run_rstone.sh "
            "if your site's spread is known",
        ),
    ]
    rough = [
        n
        for n in present
        if model.materials[n].roughness_m > 0 or model.materials[n].roughness_deg_sd > 0
    ]
    if rough:
        out.append(
            (
                "slope roughness ("
                + ", ".join(_roughness_text(n, model.materials[n]) for n in rough)
                + ")",
                "r.stone has no roughness input (its ground is the DEM's triangles): "
                "what it does to the rebounds is folded into the fitted constant "
                "pair (see the mismatches)",
            )
        )
    out += effect_lines(model)
    if model.trees is not None:
        out.append(("trees", "r.stone has no trees"))
    out.append(
        (
            f"core.slide_vn_mps = {model.core['slide_vn_mps']:g} m/s, max_impacts, "
            "drag_dt_s",
            "r.stone switches from flying to rolling when a bounce is shorter than "
            "3 m and slower than 5 m/s, both (DIST_FLY_ROLL, VEL_FLY_ROLL in "
            "fixed_parameters.c; the test in TrackPoints, points.c), constants "
            "compiled into it",
        )
    )
    return out


def effect_lines(model: Model) -> list[tuple[str, str]]:
    """Every registered effect (:data:`fieldkit.model.effects.registry.EFFECTS`),
    active in ``model`` or not, and what r.stone does with it."""
    from fieldkit.model.effects import registry

    out = []
    for spec in registry.EFFECTS:
        active = spec.name in model.effects
        state = "active in the model" if active else "not in the model"
        reason = not_a_law(spec.name, PROGRAM)
        if reason:
            why = reason
        else:
            why = spec.export(PROGRAM).how
            if spec.name == "slope_roughness":
                # the random dip is not an input, but it is in the impacts the
                # constant pair is fitted to
                why += (
                    "; its rebounds are folded into the in-range constant pair "
                    "fitted to the calibrated model's own impacts"
                )
        out.append((f"effect {spec.name} ({state})", why))
    return out


def _roughness_text(name: str, m: Material) -> str:
    return (
        f"{name}: roughness_m {m.roughness_m:g} m, roughness_deg_sd "
        f"{m.roughness_deg_sd:g} deg"
    )


def _mismatches(model, present, offset, options) -> list[str]:
    out = []
    for name in present:
        m = model.materials[name]
        for key, raster, opt in (
            ("e_n", "nrest", "vrest_stoch_range"),
            ("e_t", "trest", "hrest_stoch_range"),
        ):
            value = getattr(m, key)
            p = percent(value)
            out.append(
                f"{name}: {key} = {value:.4g} -> {raster} {p} % "
                f"({p / 100 - value:+.4f})"
            )
            sd = 2 * options[opt] / 100
            if sd > 0 and (p / 100 + 2 * sd > 1 or p / 100 - 2 * sd < 0):
                out.append(
                    f"{name}: {raster} {p} % with a draw SD of {sd:.2f}: r.stone clips "
                    "draws to [0, 1], so the mean it uses is pulled "
                    + ("down" if p / 100 + 2 * sd > 1 else "up")
                )
            if p == 0 and key == "e_n":
                out.append(
                    f"{name}: nrest 0 % makes r.stone stop every rock that bounces "
                    "there (it takes 0 for water)"
                )
        phi = math.radians(m.friction_deg)
        out.append(
            f"{name}: friction tan({m.friction_deg:g} deg) = {math.tan(phi):.4f} -> "
            "read by r.stone as thousandths rounded down (up to 0.001 less); on "
            f"the flat it brakes by g sin(phi), fieldkit by g tan(phi): a rolling "
            f"run-out {1 / math.cos(phi):.3f} x fieldkit's, equal at a slope of "
            f"{m.friction_deg:g} deg"
        )
    sds = {
        opt: sorted({_ranges(model.materials[n])[opt] for n in present})
        for opt in ("vrest_stoch_range", "hrest_stoch_range", "frict_stoch_range")
    }
    for opt, values in sds.items():
        if len(values) > 1:
            out.append(
                f"{opt}: the materials need {', '.join(map(str, values))}; r.stone "
                f"takes one per run: {options[opt]} (the largest) is used"
            )
    if offset:
        out.append(
            f"dem: every elevation raised by {offset:g} m (r.stone takes a cell at "
            "<= 0 m as no ground); subtract it from elevations read off the results"
        )
    return out


#: The documents r.stone's rules come from (README "Sources").
SOURCES = [
    "OSGeo/grass-addons src/raster/r.stone/main.c (main): the options, their "
    "defaults (ang_stoch_range 10, start_vel 1, stop_vel 3) and types",
    "OSGeo/grass-addons src/raster/r.stone/stone.h (typeGeometry): the cell size "
    "and the grid's rows and columns are C shorts (whole metres, at most 32767)",
    "OSGeo/grass-addons src/raster/r.stone/stone.c (ReadInputRasters: DEM and "
    "friction read as thousandths, nrest/trest as whole numbers, the cell from the "
    "region; NewPlane: a triangle needing a cell beyond the grid or above 9999 m "
    "stops the stone; GetRandAngle, GetRandVElas, GetRandHElas, GetRandFrict: "
    "Gaussian SD 2 range / 100, draws clipped to [0, 1]; MarkPath, MarkVelo, "
    "MarkQuota: the counter, maxvel and maxdz grids, speeds and heights in whole "
    "units)",
    "OSGeo/grass-addons src/raster/r.stone/points.c (TrackPoints: a stone starts "
    "at its cell's centre on the ground, horizontally towards the steepest of the "
    "8 neighbours, and rolls when a bounce is shorter than 3 m and slower than "
    "5 m/s; Bounce: nrest/trest multiply the normal and tangential velocity; "
    "Roll: deceleration g sin(atan(friction)))",
    "OSGeo/grass-addons src/raster/r.stone/utils.c (pivIsValid: a cell at <= 0 m "
    "is no ground)",
    "OSGeo/grass-addons src/raster/r.stone/fixed_parameters.c (DIST_FLY_ROLL "
    "3 m, VEL_FLY_ROLL 5 m/s, FLY_INT_TAB and ROLL_INT_TAB 5 m, STOCH_FLAG 1)",
    "r.stone manual (grass.osgeo.org/grass-devel/manuals/addons/r.stone.html)",
    "Guzzetti, Crosta, Detti, Agliardi (2002), STONE: a computer program for the "
    "three-dimensional simulation of rock-falls, Computers & Geosciences 28(9), "
    "1079-1093",
]

#: What the sources leave open (README "Unconfirmed").
UNCONFIRMED = [
    "r.stone seeds its random numbers with the constant 1 (random2.c Init_RNG "
    "with STOCH_FLAG): every run of the same files gives the same trajectories; "
    "its Monte Carlo error is that of one sample of the traced trajectories",
    "the counter grid counts a trajectory in the cells of its path points kept "
    "5 m apart (stone.c Filter, OUTPUT_TAB): a trajectory can skip a cell, so "
    "runouts read from it are good to about one cell either way",
    "the lateral spread of the launch angle is written as 0 (ang_stoch_range): "
    "fieldkit's model is a 2-D section and calibrates none; what a site's real "
    "spread is stays open",
    "the translation error is fieldkit's emulation of r.stone's law (a 2-D port "
    "of its kernel along the section, fieldkit.export.rstone_law), not r.stone: "
    "the 3-D triangles, the launch-angle spread and the 5 m flight steps are not "
    "ported. Checked in r.stone 8.2.1 (tests/export/test_rstone_real.py): on "
    "Tornado Mountain's path-calibrated model extruded (1000 trajectories, all "
    "stopping on the section) r.stone's runout p50/p95 are 607.5/617.5 m against "
    "the emulation's 609.3 ± 0.1/617.3 ± 0.9 m; on a Tschamut release area (14 "
    "cells, 994 trajectories, the emulation on the section through r.stone's "
    "triangles along each cell's steepest descent) 70.0/90.0 m against "
    "72.7 ± 0.4/88.8 ± 1.3 m: both within 2 sqrt(2) SE plus one cell",
    "r.stone ends some trajectories as 'Track overflow' without writing their last "
    "path segment to the grids (points.c TrackPoints, case 0: Parab 'confused' "
    "after 5 steps outside the triangle, or 100000 path points): 239 of 994 on the "
    "Tschamut area, so its counter grid may end those paths early",
]


def _notes(
    site: ExportSite, traced: int, n_source: int, per_cell: int, extruded: bool
) -> list[str]:
    out = [
        f"site: {site.description}",
        f"trajectories traced: {traced} = {n_source} source "
        + ("cell" if n_source == 1 else "cells")
        + f" x {per_cell} (sources.asc, after padding; every source cell lies >= "
        f"{EDGE_CELLS} cell inside the grid, since r.stone never starts a stone on "
        "its edge row or column)",
        "format: the r.stone manual (grass.osgeo.org, manuals/addons/r.stone.html) "
        "and its source in OSGeo/grass-addons src/raster/r.stone (main.c, stone.c, "
        "points.c, utils.c, fixed_parameters.c); STONE: Guzzetti et al. (2002), "
        "Computers & Geosciences 28(9), 1079-1093.",
        "the manual describes the coefficient spread as 'limited by +/- 10 %'; the "
        "source draws a Gaussian of SD 2 range / 100 and clips it to [0, 1]: the "
        "ranges here follow the source.",
        "rasters as ESRI ASCII grids for r.in.gdal (GDAL's AAIGrid driver): integer "
        "grids become CELL maps, the DEM and friction floating-point maps.",
    ]
    if extruded:
        out.append(
            f"strip: {site.grid.shape[0]} rows across "
            f"(±{site.grid.shape[0] // 2 * site.grid.cellsize_m:g} m from the "
            "release row). Measured with r.stone 8.2.1 on Tornado Mountain (5 m "
            "cells, ang_stoch_range 10, r.stone's default, 1000 trajectories): no "
            "trajectory passed 14 rows (70 m) from the release row; with the "
            "ang_stoch_range 0 written here the spread is smaller still. A "
            "trajectory reaching the strip's "
            "side stops there (stone.c NewPlane): that is not a runout; "
            "`fieldkit import-results` reports how many did"
        )
    if site.grid.cellsize_m < STEP_M:
        out.append(
            f"cells of {site.grid.cellsize_m:g} m are smaller than r.stone's {STEP_M:g}"
            " m flight and roll steps, which its source says should not exceed the "
            "cell: resample the DEM to >= 5 m cells or expect coarse paths"
        )
    return out
