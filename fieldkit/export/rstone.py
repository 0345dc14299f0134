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
  (``pivIsValid``), ``fixed_parameters.c`` (5 m flight and roll steps, rolling below
  5 m/s or after bounces shorter than 3 m, stochastic runs on).
* Guzzetti, F., Crosta, G., Detti, R., Agliardi, F. (2002). STONE: a computer
  program for the three-dimensional simulation of rock-falls. Computers &
  Geosciences 28(9), 1079-1093.
"""

from __future__ import annotations

import math

import numpy as np

from fieldkit.errors import ArgumentError
from fieldkit.export.ascii_grid import ascii_grid_text
from fieldkit.export.fitted import with_error
from fieldkit.export.lumped import lumped_equivalent
from fieldkit.export.result import Export, Mapped
from fieldkit.export.site import ExportSite, checked_site, ground_cells
from fieldkit.model.materials import Material
from fieldkit.model.model_file import Model

TARGET = "rstone"
TITLE = "r.stone (GRASS GIS)"

#: Trajectories in all, as ``fieldkit simulate``'s default ensemble.
DEFAULT_ROCKS = 1000

#: r.stone's defaults for what fieldkit does not calibrate (main.c).
DEFAULT_ANGLE_RANGE = 10
DEFAULT_START_VEL_MPS = 1.0

#: r.stone's flight and roll step [m] (fixed_parameters.c): not above the cell size.
STEP_M = 5.0

#: Elevations r.stone takes as ground: above 0 m, at most 9999 m (stone.c NewPlane).
MAX_ELEVATION_M = 9999.0


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
    """r.stone's input rasters for ``model`` on ``site`` (module docstring).

    Parameters
    ----------
    model
        The calibrated model.
    site
        The grid (required: a grid target).
    rocks
        Trajectories in all, shared over the release cells (at least 1 a cell).

    Raises
    ------
    ArgumentError
        No site, no release cell on ground, ``rocks`` < 1, a restitution above 1, a
        friction angle above 45 deg, or a DEM whose relief exceeds 9998 m.
    """
    site = checked_site(site, TARGET)
    model, lumped = lumped_equivalent(model, TARGET)
    if isinstance(rocks, bool) or not isinstance(rocks, int) or rocks < 1:
        raise ArgumentError(
            f"rocks must be a whole number >= 1 (got {rocks})", source="rocks"
        )
    grid = site.grid
    ground = ground_cells(site)
    source = site.release & ground
    present = [n for n in model.materials if (site.material[ground] == n).any()]
    _check(model, present)
    offset = dem_offset_m(grid.values[ground])
    dem = np.where(ground, grid.values + offset, np.nan)
    if np.nanmax(dem) > MAX_ELEVATION_M:
        raise ArgumentError(
            f"the DEM reaches {np.nanmax(dem):.6g} m after a shift of {offset:g} m: "
            f"r.stone takes elevations in (0, {MAX_ELEVATION_M:g}] m as ground",
            source="site",
        )
    per_cell = max(1, round(rocks / int(source.sum())))

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
    options = _options(model, present)
    return Export(
        TARGET,
        TITLE,
        files,
        mapped=_mapped(model, site, present, offset, per_cell, options),
        unmapped=_unmapped(model, present),
        units=[
            "nrest, trest: e_n and e_t x 100, whole percent (rounded half up)",
            "friction: tan(friction_deg), dimensionless, 3 decimals (r.stone reads "
            "thousandths)",
            f"dem: metres (fieldkit's SI), raised by {offset:g} m"
            if offset
            else "dem: metres (fieldkit's SI), as given",
            "sources: numbers of trajectories; start_vel, stop_vel in m/s",
        ],
        mismatches=[*lumped, *_mismatches(model, present, offset, options)],
        notes=_notes(site),
        how_to_use=_how_to_use(options),
    )


def _ranges(m: Material) -> dict[str, int]:
    """r.stone's spread ranges for one material (:func:`stoch_range`)."""
    return {
        "vrest_stoch_range": stoch_range(m.e_n_sd),
        "hrest_stoch_range": stoch_range(m.e_t_sd),
        "frict_stoch_range": stoch_range(
            friction_sd_tan(m.friction_deg, m.friction_deg_sd)
        ),
    }


def _options(model: Model, names: list[str]) -> dict[str, float]:
    """The r.stone options fieldkit can set (one value per run)."""
    ranges = [_ranges(model.materials[n]) for n in names]
    speed = math.hypot(model.seeder.vx_mps, model.seeder.vz_mps)
    out: dict[str, float] = {k: max(r[k] for r in ranges) for k in ranges[0]}
    out["start_vel"] = round(speed, 3) if speed > 0 else DEFAULT_START_VEL_MPS
    out["stop_vel"] = model.core["stop_speed_mps"]
    return out


def _how_to_use(options: dict[str, float]) -> str:
    o = options
    return f"""\
In a GRASS GIS project with the DEM's coordinate system (or an XY project, e.g.
`grass -c dem.asc ~/grassdata/site`), with the add-on installed (`g.extension
r.stone`), import the five ESRI ASCII grids through GDAL (`-o`: take the project's
coordinate system) and run r.stone on the DEM's region:

    r.in.gdal -o input=dem.asc output=dem
    r.in.gdal -o input=sources.asc output=sources
    r.in.gdal -o input=nrest.asc output=nrest
    r.in.gdal -o input=trest.asc output=trest
    r.in.gdal -o input=friction.asc output=friction
    g.region raster=dem
    r.stone dem=dem sources=sources nrest=nrest trest=trest friction=friction \\
        stoch_funct=0 stoch_funct_ang=0 ang_stoch_range={DEFAULT_ANGLE_RANGE} \\
        vrest_stoch_range={o["vrest_stoch_range"]} \\
        hrest_stoch_range={o["hrest_stoch_range"]} \\
        frict_stoch_range={o["frict_stoch_range"]} \\
        start_vel={o["start_vel"]:g} stop_vel={o["stop_vel"]:g} \\
        counter=counter maxvel=maxvel maxdz=maxdz

`counter` counts the trajectories through each cell. The ranges, start_vel and
stop_vel are the values derived from the model (see the tables below)."""


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
            f"seeder speed hypot(vx, vz) = {math.hypot(s.vx_mps, s.vz_mps):g} m/s",
            f"start_vel = {options['start_vel']:g} m/s",
            "the launch speed"
            + (
                ""
                if math.hypot(s.vx_mps, s.vz_mps) > 0
                else f"; the seeder is at rest, so r.stone's default "
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
            f"lateral spread (ang_stoch_range = {DEFAULT_ANGLE_RANGE}, r.stone's "
            "default)",
            "fieldkit's model is a 2-D section: it calibrates no spread across it",
        ),
    ]
    rough = [
        n
        for n in present
        if model.materials[n].roughness_m > 0 or model.materials[n].roughness_deg_sd > 0
    ]
    if rough or "slope_roughness" in model.effects:
        out.append(
            (
                "slope roughness ("
                + (
                    ", ".join(_roughness_text(n, model.materials[n]) for n in rough)
                    or "none in the materials"
                )
                + ")",
                "r.stone has no roughness input: its ground is the DEM's triangles",
            )
        )
    for name in model.effects:
        if name != "slope_roughness":
            out.append((f"effect {name}", "r.stone has no such process or parameter"))
    if model.trees is not None:
        out.append(("trees", "r.stone has no trees"))
    out.append(
        (
            f"core.slide_vn_mps = {model.core['slide_vn_mps']:g} m/s, max_impacts, "
            "drag_dt_s",
            "r.stone switches to rolling after bounces shorter than 3 m or below "
            "5 m/s, constants compiled into it (fixed_parameters.c)",
        )
    )
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


def _notes(site: ExportSite) -> list[str]:
    out = [
        f"site: {site.description}",
        "format: the r.stone manual (grass.osgeo.org, manuals/addons/r.stone.html) "
        "and its source in OSGeo/grass-addons src/raster/r.stone (main.c, stone.c, "
        "points.c, utils.c, fixed_parameters.c); STONE: Guzzetti et al. (2002), "
        "Computers & Geosciences 28(9), 1079-1093.",
        "the manual describes the coefficient spread as 'limited by +/- 10 %'; the "
        "source draws a Gaussian of SD 2 range / 100 and clips it to [0, 1]: the "
        "ranges here follow the source.",
        "rasters as ESRI ASCII grids for r.in.gdal (GDAL's AAIGrid driver): integer "
        "grids become CELL maps, the DEM and friction floating-point maps.",
        "no r.stone run was made with these files: they follow the documented format.",
    ]
    if site.grid.cellsize_m < STEP_M:
        out.append(
            f"cells of {site.grid.cellsize_m:g} m are smaller than r.stone's {STEP_M:g}"
            " m flight and roll steps, which its source says should not exceed the "
            "cell: resample the DEM to >= 5 m cells or expect coarse paths"
        )
    return out
