"""Rockyfor3D (ecorisQ): the calibrated model as its ESRI ASCII input grids.

Rockyfor3D reads a folder of ESRI ASCII grids that all share the header of
``dem.asc`` (Dorren 2016, §2.1):

* ``dem.asc``: elevations [m];
* ``rockdensity.asc``: the density of the block [kg/m³] in the source cells, 0
  elsewhere (a cell with a density > 0 is a source cell);
* ``d1.asc``, ``d2.asc``, ``d3.asc``: the block's height, width and length [m] in the
  source cells, 0 elsewhere;
* ``blshape.asc``: 0 no block, 1 rectangular, 2 ellipsoidal, 3 spherical, 4 disc;
* ``rg70.asc``, ``rg20.asc``, ``rg10.asc``: the height [m] of the obstacles a block
  meets in 70, 20 and 10 % of its rebounds (the ground's roughness);
* ``soiltype.asc``: 0-7, the class that fixes the range of the normal coefficient of
  restitution Rn (:data:`SOIL_TYPES`).

The translation:

* **soiltype**: the calibrated e_n (eq. 4.6) goes to the class whose mean Rn is
  nearest (:func:`nearest_soil_type`; a tie goes to the higher Rn, the livelier
  rebounds: the conservative side for a hazard map). The README lists the class
  means and the mismatch ``|e_n - class mean|`` of every material.
* **rg70/rg20/rg10**: fieldkit's roughness is a random local dip ``delta ~ N(0,
  sigma)`` at each impact (``slope_roughness``, eq. 7.4: ``sigma`` from
  ``roughness_m`` and ``roughness_deg_sd``). Read back through eq. 7.4, a dip
  ``delta`` is an asperity of height ``h = r tan|delta|`` within a block radius
  ``r``; the heights met in the lowest 70 %, the next 20 % and the top 10 % of
  impacts are represented by the medians of those bands: the 35th, 80th and 95th
  percentiles of the half-normal ``|delta|`` (:func:`obstacle_heights`). Without
  ``slope_roughness`` the ground is smooth in fieldkit: 0 m.
* **block**: fieldkit's body is a sphere of its contact radius ``r``, so ``d1 = d2
  = d3 = 2 r``, ``blshape`` 3, and ``rockdensity = mass / (pi/6 (2r)^3)`` so the
  sphere Rockyfor3D builds has the model's mass (:func:`sphere_block`).
* **not written**: Rockyfor3D computes its tangential coefficient Rt from the
  obstacle heights and the block size (Dorren 2016, §3.3), so the calibrated e_t is
  not an input; nor are the friction angle, the SDs, the release velocity or the
  effects other than ``slope_roughness`` (the README lists them).

Sources
-------
* Dorren, L.K.A. (2016). Rockyfor3D (v5.2) revealed - Transparent description of the
  complete 3D rockfall model. ecorisQ paper (www.ecorisq.org), 32 p.: the input
  grids (§2.1), the soil types and their Rn (Table 1), the rebound (§3.3).
* Nicolet, P. (NGU, 2021). PimpMyRockyfor, ``CreateFeatureClass.py``
  (github.com/pierrick-nicolet/PimpMyRockyfor): the grid names and units
  (rockdensity kg/m³; d1 height, d2 width, d3 length [m]; rg70/rg20/rg10 [m]) and
  the blshape (0-4) and soiltype (0-7) code lists, read in this session.

The Rn ranges of :data:`SOIL_TYPES` are those of Table 1 as recalled: the stored
copies of the manual found while writing this module showed its contents, not the
table, so the README says to check them against the manual of the Rockyfor3D
version used (v6.0 has been released since v5.2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from statistics import NormalDist

import numpy as np

from fieldkit.errors import ArgumentError
from fieldkit.export.ascii_grid import ascii_grid_text
from fieldkit.export.fitted import with_error
from fieldkit.export.lumped import lumped_equivalent
from fieldkit.export.result import Export, Mapped
from fieldkit.export.site import ExportSite, checked_site, ground_cells
from fieldkit.model.effects.slope_roughness import dip_sd_rad
from fieldkit.model.materials import Material
from fieldkit.model.model_file import Body, Model
from fieldkit.physics.bodies import sphere_density_kg_m3

TARGET = "rockyfor3d"
TITLE = "Rockyfor3D (ecorisQ)"


@dataclass(frozen=True)
class SoilType:
    """A Rockyfor3D soil type: code, description and its Rn range and mean."""

    code: int
    description: str
    rn_min: float
    rn_max: float
    rn_mean: float

    def label(self) -> str:
        """``"6 (bedrock)"``."""
        return f"{self.code} ({self.description})"


#: Rockyfor3D soil types (Dorren 2016, Table 1): Rn range and mean per class.
SOIL_TYPES: tuple[SoilType, ...] = (
    SoilType(0, "river, swamp, or material a rock penetrates completely", 0, 0, 0),
    SoilType(1, "fine soil material, depth > ~100 cm", 0.21, 0.25, 0.23),
    SoilType(
        2, "fine soil material, depth < ~100 cm, or sand/gravel mix", 0.25, 0.31, 0.28
    ),
    SoilType(
        3,
        "scree < ~10 cm, or medium compact soil with small rock fragments, "
        "or forest road",
        0.30,
        0.36,
        0.33,
    ),
    SoilType(
        4,
        "talus slope > ~10 cm, or compact soil with large rock fragments",
        0.34,
        0.42,
        0.38,
    ),
    SoilType(5, "bedrock with thin weathered material or soil cover", 0.39, 0.47, 0.43),
    SoilType(6, "bedrock", 0.48, 0.58, 0.53),
    SoilType(7, "asphalt road", 0.32, 0.38, 0.35),
)

#: Obstacle-height grids -> the quantile of |delta| that represents their band.
RG_QUANTILES: tuple[tuple[str, float], ...] = (
    ("rg70", 0.35),
    ("rg20", 0.80),
    ("rg10", 0.95),
)

#: Largest dip a roughness may reach (at the rg10 quantile) and still be a height.
MAX_DIP_DEG = 89.0


def nearest_soil_type(e_n: float) -> SoilType:
    """The soil type whose mean Rn is nearest ``e_n``; a tie goes to the higher Rn.

    Distances equal to 1e-9 are ties (0.255 lies halfway between 0.23 and 0.28).

    Examples
    --------
    >>> nearest_soil_type(0.75).code, nearest_soil_type(0.255).code
    (6, 2)
    >>> nearest_soil_type(0.34).label()
    '7 (asphalt road)'
    """
    return min(SOIL_TYPES, key=lambda s: (round(abs(e_n - s.rn_mean), 9), -s.rn_mean))


def obstacle_heights(
    dip_sd_deg: float, radius_m: float, *, name: str = "material"
) -> dict[str, float]:
    """Heights [m] of the obstacles met in 70, 20 and 10 % of impacts.

    ``h = radius_m * tan(|delta|_q)`` at the quantiles ``q`` of
    :data:`RG_QUANTILES`, with ``|delta|`` half-normal of scale ``dip_sd_deg``
    (module docstring).

    Raises
    ------
    ArgumentError
        A dip SD so large that the rg10 dip reaches :data:`MAX_DIP_DEG`.

    Examples
    --------
    >>> {k: round(v, 4) for k, v in obstacle_heights(10.0, 1.0).items()}
    {'rg70': 0.0794, 'rg20': 0.2275, 'rg10': 0.3561}
    """
    out = {}
    for key, q in RG_QUANTILES:
        dip = dip_sd_deg * NormalDist().inv_cdf(0.5 + 0.5 * q)
        if dip >= MAX_DIP_DEG:
            raise ArgumentError(
                f"materials.{name}: a dip SD of {dip_sd_deg:.3g} deg (slope_roughness) "
                f"makes the {key} dip {dip:.3g} deg; Rockyfor3D's obstacle heights "
                f"need dips below {MAX_DIP_DEG:g} deg",
                source="model",
            )
        out[key] = radius_m * math.tan(math.radians(dip))
    return out


def sphere_block(body: Body) -> tuple[float, int]:
    """``(diameter [m], density [kg/m³])`` of the sphere that stands for the body.

    Diameter ``2 r``; density ``mass / (pi/6 d^3)`` rounded to a whole number.

    Raises
    ------
    ArgumentError
        A density that rounds to 0 (Rockyfor3D would see no source cell).

    Examples
    --------
    >>> sphere_block(Body(mass_kg=3750.0, radius_m=0.725, gyration_m=0.46))
    (1.45, 2349)
    """
    diameter = 2.0 * body.radius_m
    density = round(sphere_density_kg_m3(body.mass_kg, body.radius_m))
    if density < 1:
        raise ArgumentError(
            f"body: mass_kg {body.mass_kg:g} in a sphere of radius_m "
            f"{body.radius_m:g} is a density below 1 kg/m3; Rockyfor3D's rockdensity "
            "must be > 0 in a source cell",
            source="model",
        )
    return diameter, density


def _dip_sd_deg(model: Model, material: Material) -> float:
    """fieldkit's SD of the local dip [deg] for the body (0 without the effect)."""
    if "slope_roughness" not in model.effects:
        return 0.0
    scale = model.effects["slope_roughness"].get("scale", 1.0)
    sd = dip_sd_rad(
        material.roughness_m, material.roughness_deg_sd, model.body.radius_m, scale
    )
    return math.degrees(sd)


def export_rockyfor3d(model: Model, site: ExportSite | None = None) -> Export:
    """Rockyfor3D's input grids for ``model`` on ``site`` (module docstring).

    Raises
    ------
    ArgumentError
        No site (a grid target), a site without a release cell on ground, a body
        or a roughness Rockyfor3D cannot take (:func:`sphere_block`,
        :func:`obstacle_heights`).
    """
    site = checked_site(site, TARGET)
    model, lumped = lumped_equivalent(model, TARGET)
    grid = site.grid
    ground = ground_cells(site)
    source = site.release & ground
    present = [n for n in model.materials if (site.material[ground] == n).any()]
    soil = {n: nearest_soil_type(model.materials[n].e_n) for n in present}
    dip = {n: _dip_sd_deg(model, model.materials[n]) for n in present}
    rg = {n: obstacle_heights(dip[n], model.body.radius_m, name=n) for n in present}
    diameter, density = sphere_block(model.body)

    def per_material(value) -> np.ndarray:
        out = np.full(grid.shape, np.nan)
        for name in present:
            out[ground & (site.material == name)] = value(name)
        return out

    def on_source(value: float) -> np.ndarray:
        return np.where(ground, np.where(source, value, 0.0), np.nan)

    block = ascii_grid_text(on_source(diameter), grid, decimals=3)
    files: dict[str, str | bytes] = {
        "dem.asc": ascii_grid_text(np.where(ground, grid.values, np.nan), grid),
        "rockdensity.asc": ascii_grid_text(on_source(density), grid, integer=True),
        "d1.asc": block,
        "d2.asc": block,
        "d3.asc": block,
        "blshape.asc": ascii_grid_text(on_source(3), grid, integer=True),
        "soiltype.asc": ascii_grid_text(
            per_material(lambda n: soil[n].code), grid, integer=True
        ),
    }
    for key, _ in RG_QUANTILES:
        files[f"{key}.asc"] = ascii_grid_text(
            per_material(lambda n, k=key: rg[n][k]), grid, decimals=3
        )
    return Export(
        TARGET,
        TITLE,
        files,
        mapped=_mapped(model, site, present, soil, dip, rg, diameter, density),
        unmapped=_unmapped(model, present),
        units=[
            "lengths in metres as Rockyfor3D reads them (DEM, d1-d3, rg70/rg20/rg10;"
            " fieldkit's SI unchanged)",
            "rockdensity in kg/m³, whole numbers",
            "soiltype (0-7) and blshape (0-4) are codes; NODATA_value -9999 where "
            "the site has no ground",
        ],
        mismatches=[*lumped, *_mismatches(model, present, soil, diameter, density)],
        notes=_notes(model, site, present),
        how_to_use=HOW_TO_USE,
    )


HOW_TO_USE = """\
Put the ten `.asc` files in one folder: they share the header of `dem.asc`
(Rockyfor3D needs every grid on the same cells) and choose that folder as the input
of a Rockyfor3D simulation (Dorren 2016, §2.6). The number of simulations per source
cell, any variation of the block volume and an additional initial fall height are
settings of the run (§2.5), not grids: set them there. No forest or net grids are
written, so the run is without forest and nets."""


def _mapped(model, site, present, soil, dip, rg, diameter, density) -> list[Mapped]:
    body = model.body
    n_source = int((site.release & ground_cells(site)).sum())
    out = [
        Mapped(
            "site terrain (DEM or extruded profile)",
            "dem.asc: elevations [m]",
            site.description,
        ),
        Mapped(
            "seeder (where rocks start)",
            f"{n_source} source "
            + ("cell" if n_source == 1 else "cells")
            + ": rockdensity > 0",
            "the release cells of the site (above)",
        ),
        Mapped(
            with_error(model, "body.radius_m", body.radius_m, "m"),
            f"d1.asc = d2.asc = d3.asc = {diameter:.4g} m; blshape.asc = 3 "
            "(spherical) in the source cells, 0 elsewhere",
            "fieldkit's body is a sphere of its contact radius: diameter 2 r on "
            "every axis",
        ),
        Mapped(
            with_error(model, "body.mass_kg", body.mass_kg, "kg"),
            f"rockdensity.asc = {density} kg/m³ in the source cells, 0 elsewhere",
            f"mass / (pi/6 d^3) with d = {diameter:.4g} m: Rockyfor3D's sphere has "
            "the model's mass",
        ),
    ]
    for name in present:
        m, s = model.materials[name], soil[name]
        out.append(
            Mapped(
                with_error(model, f"materials.{name}.e_n", m.e_n),
                f"soiltype.asc = {s.label()}: Rn {s.rn_min:.2f}-{s.rn_max:.2f}, "
                f"mean {s.rn_mean:.2f}",
                f"nearest class mean (ties to the higher Rn); abs(e_n - mean) = "
                f"{abs(m.e_n - s.rn_mean):.2f}",
            )
        )
        h = rg[name]
        out.append(
            Mapped(
                f"materials.{name}: roughness_m = {m.roughness_m:g} m, "
                f"roughness_deg_sd = {m.roughness_deg_sd:g} deg -> dip SD "
                f"{dip[name]:.3g} deg",
                f"rg70 / rg20 / rg10 = {h['rg70']:.3f} / {h['rg20']:.3f} / "
                f"{h['rg10']:.3f} m",
                f"h = r tan(abs(delta)) (eq. 7.4 read back, r = {body.radius_m:g} m) "
                "at the 35th / 80th / 95th percentile of abs(delta), half-normal"
                "(dip SD): the medians of the lowest 70 %, the next 20 % and the top "
                "10 % of impacts"
                + (
                    ""
                    if "slope_roughness" in model.effects
                    else "; slope_roughness is off, so fieldkit's ground is smooth: 0 m"
                ),
            )
        )
    return out


def _unmapped(model: Model, present: list[str]) -> list[tuple[str, str]]:
    out = []
    for name in present:
        m = model.materials[name]
        out.append(
            (
                with_error(model, f"materials.{name}.e_t", m.e_t),
                "Rockyfor3D computes its tangential coefficient Rt at each rebound "
                "from the obstacle heights (rg70/rg20/rg10) and the block size "
                "(Dorren 2016, §3.3): it takes no Rt input, so the calibrated e_t "
                "is not written; the roughness it is computed from is (rg70/rg20/rg10)",
            )
        )
        out.append(
            (
                with_error(model, f"materials.{name}.friction_deg", m.friction_deg),
                "Rockyfor3D's inputs have no friction angle (no grid, no setting "
                "among its inputs, §2.1)",
            )
        )
        out.append(
            (
                f"materials.{name}: e_n_sd = {m.e_n_sd:g}, e_t_sd = {m.e_t_sd:g}, "
                f"friction_deg_sd = {m.friction_deg_sd:g}",
                "Rockyfor3D draws Rn within the range of the soil type (Table 1), "
                "not from a calibrated SD",
            )
        )
    out.append(
        (
            f"body.gyration_m = {model.body.gyration_m:g} m",
            "Rockyfor3D derives the moment of inertia from the block's shape and "
            "dimensions",
        )
    )
    s = model.seeder
    out.append(
        (
            f"seeder velocity (vx {s.vx_mps:g}, vz {s.vz_mps:g} m/s; SDs "
            f"{s.vx_sd_mps:g}, {s.vz_sd_mps:g} m/s)",
            "no grid takes a release velocity; the closest is the run's additional "
            "initial fall height (§2.5), left to the user",
        )
    )
    for name in model.effects:
        if name != "slope_roughness":
            out.append(
                (
                    f"effect {name}",
                    "Rockyfor3D has its own rebound and energy-loss rules (§3.3); "
                    "none of its inputs takes this effect",
                )
            )
    if model.trees is not None:
        out.append(
            (
                "trees",
                "Rockyfor3D's forest inputs (tree file or nrtrees/dbh grids, §2.2) "
                "are not written: the run is without forest",
            )
        )
    out.append(
        (
            "core settings ("
            + ", ".join(f"{k} {v:g}" for k, v in model.core.items())
            + ")",
            "Rockyfor3D's own stopping and phase rules apply",
        )
    )
    return out


def _mismatches(model, present, soil, diameter, density) -> list[str]:
    means = ", ".join(f"{s.code}: {s.rn_mean:.2f}" for s in SOIL_TYPES)
    out = [f"soil-type class means used (Rn, Dorren 2016 Table 1): {means}"]
    for name in present:
        e_n, s = model.materials[name].e_n, soil[name]
        inside = s.rn_min <= e_n <= s.rn_max
        out.append(
            f"{name}: e_n = {e_n:.3g} -> soiltype {s.label()}, mean Rn "
            f"{s.rn_mean:.2f}: mismatch {abs(e_n - s.rn_mean):.2f}; e_n is "
            + (
                f"inside the class range {s.rn_min:.2f}-{s.rn_max:.2f}"
                if inside
                else f"outside the class range {s.rn_min:.2f}-{s.rn_max:.2f}"
                + (
                    ": no Rockyfor3D soil type reaches it"
                    if e_n > max(t.rn_max for t in SOIL_TYPES)
                    else ""
                )
            )
        )
    volume = math.pi / 6.0 * diameter**3
    mass = density * volume
    out.append(
        f"body: a sphere of diameter {diameter:.4g} m (fieldkit's contact sphere); a "
        "block of another shape (e.g. measured axes) changes d1-d3 and blshape, and "
        "rockdensity must then be recomputed for the mass. The whole-number "
        f"density {density} kg/m³ gives {mass:.5g} kg for {model.body.mass_kg:g} kg "
        f"({100 * (mass / model.body.mass_kg - 1):+.2f} %)"
    )
    return out


def _notes(model: Model, site: ExportSite, present: list[str]) -> list[str]:
    out = [
        f"site: {site.description}",
        "format: Dorren, L.K.A. (2016), Rockyfor3D (v5.2) revealed - Transparent "
        "description of the complete 3D rockfall model, ecorisQ paper "
        "(www.ecorisq.org), §2.1 input grids, Table 1 soil types; grid names, units "
        "and the blshape/soiltype code lists as in P. Nicolet's PimpMyRockyfor "
        "(NGU, 2021, github.com/pierrick-nicolet/PimpMyRockyfor).",
        "not confirmed: the Rn ranges and means of the soil types are Table 1 of the "
        "v5.2 manual as recalled when this exporter was written (the stored copies "
        "of the manual showed its contents, not the table): check them against the "
        "manual of your Rockyfor3D version (v6.0 has been released since) before "
        "relying on the soiltype choice.",
        "no Rockyfor3D run was made with these files: they follow the documented "
        "format.",
    ]
    missing = [n for n in model.materials if n not in present]
    if missing:
        out.append(
            "materials under no cell centre, so not on the grid: " + ", ".join(missing)
        )
    return out
