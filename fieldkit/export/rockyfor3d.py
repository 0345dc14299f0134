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

Rockyfor3D's own rules, checked here (ecorisQ's input plugin, QGIS-RF3D
``rockyfor3d_inputs_algorithm.py``): source cells in the two outer rows or columns
of the grid are not simulated -- the site is padded (:func:`~fieldkit.export.site.
pad_site`) so that every source cell lies at least :data:`EDGE_CELLS` cells inside,
and the export checks it; rockdensity lies in :data:`DENSITY_RANGE_KG_M3`;
rg70/rg20/rg10 in 0-100 m; soiltype 0-7; blshape 0-4.

The translation:

* **soiltype** from the ground the material *is* (:func:`soil_type`): the first
  keyword of :data:`SOIL_KEYWORDS` in the material's name (rock, cliff, bedrock ->
  6; weathered rock -> 5; talus, colluvium -> 4; scree, bench -> 3; soil, meadow
  -> 2; deep fine soil -> 1; ...), a fixed order from soft to hard, so a harder
  ground never gets a softer class. Only a name with no keyword is placed by its
  realised e_n (the nearest class mean of 1-6, a monotone rule), and says so. The
  calibrated e_n is not used where a description exists: a lumped e_n grows at
  shallow impacts (eq. 5.4) and with velocity scaling, so thesis Table 7-1 has e_n
  1.0 on colluvium and 0.75 on rock -- the nearest-Rn rule put colluvium on
  bedrock.
* **rg70/rg20/rg10** from the calibrated e_t (:func:`obstacle_heights`): the e_t
  the calibrated model realises on its simulated impacts and the impacts' own
  spread (:func:`fieldkit.export.translation.fit_scaled`), inverted through
  Rockyfor3D's rule ``Rt = 1 / (1 + MOH / R)`` (:func:`rt_of_height`; MOH the
  obstacle height drawn from rg70/rg20/rg10 with probabilities 0.7/0.2/0.1, R the
  block radius): the three heights are those of the Rt at the middle of each
  band of the realised e_t distribution (its 65th, 20th and 5th percentiles).
* **block**: fieldkit's body is a sphere of its contact radius ``r``, so ``d1 = d2
  = d3 = 2 r``, ``blshape`` 3, and ``rockdensity = mass / (pi/6 (2r)^3)``. A density
  outside :data:`DENSITY_RANGE_KG_M3` is clamped to the range and the diameter
  changed so the block keeps the model's mass (the energy a design reads), and the
  README says so (:func:`sphere_block`).
* **translation error**: fieldkit simulates the calibrated model and its emulation
  of Rockyfor3D's law with the values written (:func:`emulated_model`) on the
  calibrated model's section, and the README tabulates the difference.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace
from statistics import NormalDist

import numpy as np

from fieldkit.errors import ArgumentError
from fieldkit.export.ascii_grid import ascii_grid_text
from fieldkit.export.fitted import with_error
from fieldkit.export.lumped import not_a_law
from fieldkit.export.result import Export, Mapped
from fieldkit.export.site import ExportSite, checked_site, ground_cells, pad_site
from fieldkit.export.translation import (
    IMPACT_ROCKS,
    IMPACT_SEED,
    fit_scaled,
    realised_impacts,
    translation_error,
)
from fieldkit.model.effects import registry
from fieldkit.model.model_file import Body, Model
from fieldkit.physics.bodies import sphere_density_kg_m3

TARGET = "rockyfor3d"
TITLE = "Rockyfor3D (ecorisQ)"

#: Rockyfor3D does not simulate source cells in the two outer rows or columns.
EDGE_CELLS = 2
#: Rockyfor3D's range of rockdensity [kg/m³] (QGIS-RF3D's field constraints).
DENSITY_RANGE_KG_M3 = (2000, 3400)
#: Rockyfor3D's range of rg70/rg20/rg10 [m] (QGIS-RF3D's field constraints).
RG_MAX_M = 100.0


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

    @property
    def rn_sd(self) -> float:
        """SD of a uniform draw over the class range, ``(max - min) / sqrt(12)``."""
        return (self.rn_max - self.rn_min) / math.sqrt(12.0)


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

#: Ground-description keywords -> soil type code, with the reason: fieldkit's
#: reading of Table 1's class descriptions (the longest keyword found wins).
SOIL_KEYWORDS: tuple[tuple[tuple[str, ...], int, str], ...] = (
    (
        ("river", "swamp", "marsh", "bog", "lake", "water"),
        0,
        "water or a swamp: a rock penetrates it completely",
    ),
    (
        ("deep soil", "fine soil", "humus", "peat"),
        1,
        "deep fine soil",
    ),
    (
        ("soil", "topsoil", "meadow", "grass", "pasture", "sand", "gravel"),
        2,
        "fine soil of less than ~1 m on the slope, or a sand/gravel mix",
    ),
    (
        ("scree", "bench", "ballast", "fill", "forest road", "compact soil"),
        3,
        "scree < ~10 cm, compact soil with small fragments, a (railway or road) "
        "bench of ballast or fill",
    ),
    (
        ("talus", "colluvium", "debris", "boulder", "boulders", "moraine", "till"),
        4,
        "talus > ~10 cm, or compact soil with large rock fragments",
    ),
    (
        ("weathered rock", "weak rock", "fractured rock", "rock with soil"),
        5,
        "bedrock with a thin weathered or soil cover",
    ),
    (
        ("bedrock", "rock", "cliff", "outcrop", "ledge", "rock face"),
        6,
        "bare rock",
    ),
    (("asphalt", "pavement", "paved road"), 7, "asphalt road"),
)

#: Obstacle-height grids -> their probability in Rockyfor3D's draw, and the
#: quantile of the realised e_t that stands for their band (its middle).
RG_BANDS: tuple[tuple[str, float, float], ...] = (
    ("rg70", 0.70, 0.65),
    ("rg20", 0.20, 0.20),
    ("rg10", 0.10, 0.05),
)
#: Smallest Rt an obstacle height is inverted from (Rt -> 0 needs an infinite one).
MIN_RT = 1.0 / (1.0 + RG_MAX_M / 0.01)


def soil_type(name: str, e_n: float) -> tuple[SoilType, str]:
    """The soil type of material ``name`` and why (module docstring).

    The longest keyword of :data:`SOIL_KEYWORDS` found in the name (words split at
    anything but letters and digits) gives the class; a name with none gets the
    class of 1-6 whose mean Rn is nearest ``e_n`` (ties to the higher), said so.

    Examples
    --------
    >>> soil_type("rock", 0.75)[0].code, soil_type("colluvium", 1.0)[0].code
    (6, 4)
    >>> soil_type("upper_cliff", 0.2)[0].code, soil_type("railway-bench", 1.0)[0].code
    (6, 3)
    >>> soil_type("weathered rock", 0.9)[0].code, soil_type("m1", 0.41)
    (5, (SoilType(code=5, description='bedrock with thin weathered material or soil \
cover', rn_min=0.39, rn_max=0.47, rn_mean=0.43), 'no ground description in the name: \
the class of 1-6 whose mean Rn is nearest its realised e_n 0.41 (rename the material \
to choose by description)'))
    """
    text = " " + re.sub(r"[^a-z0-9]+", " ", name.lower()) + " "
    keywords = sorted(
        ((k, code, why) for keys, code, why in SOIL_KEYWORDS for k in keys),
        key=lambda item: -len(item[0]),
    )
    for keyword, code, why in keywords:
        if f" {keyword} " in text:
            return SOIL_TYPES[code], f"'{keyword}' in the name: {why}"
    candidates = [s for s in SOIL_TYPES if 1 <= s.code <= 6]
    best = min(candidates, key=lambda s: (round(abs(e_n - s.rn_mean), 9), -s.rn_mean))
    return best, (
        "no ground description in the name: the class of 1-6 whose mean Rn is "
        f"nearest its realised e_n {e_n:.3g} (rename the material to choose by "
        "description)"
    )


def rt_of_height(height_m: float, radius_m: float) -> float:
    """Rockyfor3D's tangential coefficient for an obstacle of ``height_m`` and a
    block of ``radius_m``: ``Rt = 1 / (1 + MOH / R)`` (module docstring).

    Examples
    --------
    >>> rt_of_height(0.0, 0.5), rt_of_height(0.5, 0.5)
    (1.0, 0.5)
    """
    return 1.0 / (1.0 + height_m / radius_m)


def obstacle_heights(e_t: float, spread: float, radius_m: float) -> dict[str, float]:
    """rg70/rg20/rg10 [m] whose Rt (:func:`rt_of_height`) are the realised e_t at
    the middle of each band: ``Rt_q = e_t + spread z_q`` at the quantiles of
    :data:`RG_BANDS`, clipped to ``[MIN_RT, 1]``, ``h = R (1 / Rt_q - 1)``.

    Examples
    --------
    >>> {k: round(v, 4) for k, v in obstacle_heights(0.62, 0.04, 0.725).items()}
    {'rg70': 0.416, 'rg20': 0.5115, 'rg10': 0.5832}
    >>> obstacle_heights(1.0, 0.0, 0.5)
    {'rg70': 0.0, 'rg20': 0.0, 'rg10': 0.0}
    """
    out = {}
    for key, _, q in RG_BANDS:
        rt = min(max(e_t + spread * NormalDist().inv_cdf(q), MIN_RT), 1.0)
        out[key] = min(radius_m * (1.0 / rt - 1.0), RG_MAX_M)
    return out


def rt_mixture(heights: dict[str, float], radius_m: float) -> tuple[float, float]:
    """Mean and SD of Rockyfor3D's Rt over its draw of the three heights.

    Examples
    --------
    >>> [round(v, 4) for v in rt_mixture({"rg70": 0, "rg20": 0, "rg10": 0}, 1.0)]
    [1.0, 0.0]
    """
    rts = np.array([rt_of_height(heights[k], radius_m) for k, _, _ in RG_BANDS])
    weights = np.array([w for _, w, _ in RG_BANDS])
    mean = float(np.sum(weights * rts))
    return mean, float(math.sqrt(np.sum(weights * (rts - mean) ** 2)))


@dataclass(frozen=True)
class Block:
    """The sphere written for Rockyfor3D: diameter, density, and what changed."""

    diameter_m: float
    density_kg_m3: int
    note: str

    @property
    def radius_m(self) -> float:
        return self.diameter_m / 2.0


def sphere_block(body: Body) -> Block:
    """The sphere that stands for the body, its density in Rockyfor3D's range.

    Diameter ``2 r`` and density ``mass / (pi/6 d^3)`` (a whole number) when that
    lies in :data:`DENSITY_RANGE_KG_M3`; otherwise the density is clamped to the
    range and the diameter is the one that keeps the body's mass,
    ``(6 m / (pi rho))^(1/3)`` -- stated in :attr:`Block.note`.

    Examples
    --------
    >>> b = sphere_block(Body(mass_kg=3750.0, radius_m=0.725, gyration_m=0.46))
    >>> b.diameter_m, b.density_kg_m3, b.note
    (1.45, 2349, '')
    >>> b = sphere_block(Body(mass_kg=100.0, radius_m=0.5, gyration_m=0.3))
    >>> round(b.diameter_m, 4), b.density_kg_m3
    (0.4571, 2000)
    """
    low, high = DENSITY_RANGE_KG_M3
    density = sphere_density_kg_m3(body.mass_kg, body.radius_m)
    if low <= round(density) <= high:
        return Block(2.0 * body.radius_m, round(density), "")
    clamped = low if density < low else high
    diameter = (6.0 * body.mass_kg / (math.pi * clamped)) ** (1.0 / 3.0)
    return Block(
        diameter,
        clamped,
        f"the model's sphere (r = {body.radius_m:g} m, {body.mass_kg:g} kg) has a "
        f"density of {density:.0f} kg/m³, outside Rockyfor3D's rockdensity range "
        f"{low}-{high} kg/m³: clamped to {clamped} kg/m³ in a sphere of diameter "
        f"{diameter:.4g} m, which keeps the model's mass ({body.mass_kg:g} kg); "
        f"the diameter differs from 2 r = {2 * body.radius_m:.4g} m by "
        f"{100 * (diameter / (2 * body.radius_m) - 1):+.1f} %",
    )


@dataclass(frozen=True)
class Realised:
    """A material's realised e_n and e_t with the impacts' own spread."""

    e_n: float
    e_n_spread: float
    e_t: float
    e_t_spread: float
    impacts: int
    note: str


def realised_pairs(model: Model, names: list[str]) -> dict[str, Realised]:
    """Each material's realised e_n, e_t (:func:`fit_scaled`, range 0-1) on the
    calibrated model's own simulated impacts; a material with none keeps its
    calibrated e_n, e_t and their SDs as spreads, and :attr:`Realised.note` says
    so (naming the laws that then act on it unseen)."""
    frame = realised_impacts(model)
    laws = [
        s.name
        for s in registry.EFFECTS
        if s.changes_rebound and s.name in model.effects
    ]
    out = {}
    for name in names:
        rows = frame[frame["material"] == name]
        n = fit_scaled(
            -rows["vin_mps"].to_numpy(), rows["vfn_mps"].to_numpy(), 1.0, 0, 1
        )
        t = fit_scaled(
            rows["vit_mps"].to_numpy(), rows["vft_mps"].to_numpy(), 1.0, 0, 1
        )
        m = model.materials[name]
        if n.n < 2 or t.n < 2:
            out[name] = Realised(
                m.e_n,
                m.e_n_sd,
                m.e_t,
                m.e_t_sd,
                0,
                f"no simulated impact on {name} ({IMPACT_ROCKS} rocks, seed "
                f"{IMPACT_SEED}): its calibrated e_n {m.e_n:.3g}, e_t {m.e_t:.3g} and "
                f"their SDs are used as they are"
                + (f", without {', '.join(laws)}" if laws else ""),
            )
            continue
        clipped = [
            f"{what} {s.unclipped:.3g} clipped to {s.value:.3g}"
            for what, s in (("e_n", n), ("e_t", t))
            if s.clipped
        ]
        out[name] = Realised(
            n.value,
            n.spread,
            t.value,
            t.spread,
            t.n,
            f"{t.n} impacts on {name} of {IMPACT_ROCKS} simulated rocks (seed "
            f"{IMPACT_SEED})"
            + (f"; least-squares {', '.join(clipped)} (range 0-1)" if clipped else ""),
        )
    return out


def emulated_model(
    model: Model,
    soil: dict[str, SoilType],
    rg: dict[str, dict[str, float]],
    block: Block,
) -> Model:
    """fieldkit's emulation of Rockyfor3D's law with the values written: per
    material ``e_n`` the soil type's mean Rn with the SD of a uniform draw over its
    range, ``e_t`` the mean and SD of Rt over the draw of rg70/rg20/rg10
    (:func:`rt_mixture`), no effect (Rockyfor3D has none of fieldkit's), the
    calibrated friction (Rockyfor3D has no friction input; fieldkit's core needs
    one) and the written block's radius and mass."""
    materials = dict(model.materials)
    for name, s in soil.items():
        mean, sd = rt_mixture(rg[name], block.radius_m)
        materials[name] = replace(
            materials[name], e_n=s.rn_mean, e_n_sd=s.rn_sd, e_t=mean, e_t_sd=sd
        )
    body = model.body
    if block.radius_m != body.radius_m:
        body = replace(
            body,
            radius_m=block.radius_m,
            gyration_m=min(body.gyration_m, block.radius_m),
        )
    return replace(model, materials=materials, effects={}, body=body)


def export_rockyfor3d(model: Model, site: ExportSite | None = None) -> Export:
    """Rockyfor3D's input grids for ``model`` on ``site`` (module docstring).

    Raises
    ------
    ArgumentError
        No site (a grid target), a site without a release cell on ground, or one
        that cannot be padded so every source cell lies :data:`EDGE_CELLS` cells
        inside the grid.
    """
    site = checked_site(site, TARGET)
    unpadded = site
    try:
        site = pad_site(site, EDGE_CELLS)
    except ArgumentError as error:
        raise ArgumentError(
            f"Rockyfor3D ignores source cells in the {EDGE_CELLS} outer rows and "
            f"columns, and the release cannot be moved inside: {error.message}",
            source="site",
        ) from None
    grid = site.grid
    ground = ground_cells(site)
    source = site.release & ground
    _check_active(source)
    present = [n for n in model.materials if (site.material[ground] == n).any()]
    realised = realised_pairs(model, present)
    soil, soil_why = {}, {}
    for n in present:
        soil[n], soil_why[n] = soil_type(n, realised[n].e_n)
    block = sphere_block(model.body)
    rg = {
        n: obstacle_heights(realised[n].e_t, realised[n].e_t_spread, block.radius_m)
        for n in present
    }

    def per_material(value) -> np.ndarray:
        out = np.full(grid.shape, np.nan)
        for name in present:
            out[ground & (site.material == name)] = value(name)
        return out

    def on_source(value: float) -> np.ndarray:
        return np.where(ground, np.where(source, value, 0.0), np.nan)

    diameter = ascii_grid_text(on_source(block.diameter_m), grid, decimals=3)
    files: dict[str, str | bytes] = {
        "dem.asc": ascii_grid_text(np.where(ground, grid.values, np.nan), grid),
        "rockdensity.asc": ascii_grid_text(
            on_source(block.density_kg_m3), grid, integer=True
        ),
        "d1.asc": diameter,
        "d2.asc": diameter,
        "d3.asc": diameter,
        "blshape.asc": ascii_grid_text(on_source(3), grid, integer=True),
        "soiltype.asc": ascii_grid_text(
            per_material(lambda n: soil[n].code), grid, integer=True
        ),
    }
    for key, _, _ in RG_BANDS:
        files[f"{key}.asc"] = ascii_grid_text(
            per_material(lambda n, k=key: rg[n][k]), grid, decimals=3
        )
    emulated = emulated_model(model, soil, rg, block)
    translation = translation_error(model, emulated)
    return Export(
        TARGET,
        TITLE,
        files,
        mapped=_mapped(
            model, site, unpadded, present, soil, soil_why, realised, rg, block
        ),
        unmapped=_unmapped(model, site, present),
        units=[
            "lengths in metres as Rockyfor3D reads them (DEM, d1-d3, rg70/rg20/rg10;"
            " fieldkit's SI unchanged)",
            "rockdensity in kg/m³, whole numbers",
            "soiltype (0-7) and blshape (0-4) are codes; NODATA_value -9999 where "
            "the site has no ground",
        ],
        mismatches=_mismatches(model, present, soil, realised, block),
        notes=_notes(model, site, present),
        how_to_use=HOW_TO_USE,
        translation=[
            *translation.lines(),
            "",
            "fieldkit's emulation of Rockyfor3D's law: per material e_n = the soil "
            "type's mean Rn with the SD of a uniform draw over its range (a normal "
            "draw in fieldkit), e_t = the mean and SD of Rt = 1 / (1 + MOH / R) over "
            "Rockyfor3D's draw of rg70 / rg20 / rg10 (0.7 / 0.2 / 0.1, R = "
            f"{block.radius_m:.4g} m); no effect; the calibrated friction angle in "
            "fieldkit's sliding phase; on the calibrated model's 2-D section, not "
            "the 3-D grid. Rockyfor3D's own rebound geometry, its 3-D spreading and "
            "its stopping rules are not emulated, so this measures what the values "
            "written lose, not a Rockyfor3D run.",
        ],
        sources=SOURCES,
        unconfirmed=UNCONFIRMED,
    )


def _check_active(source: np.ndarray) -> None:
    """Refuse a source grid with a source cell in Rockyfor3D's ignored edge band,
    or none inside its active area (the check the padding must pass)."""
    active = np.zeros(source.shape, bool)
    e = EDGE_CELLS
    active[e:-e, e:-e] = True
    if (source & ~active).any() or not (source & active).any():
        raise ArgumentError(
            f"Rockyfor3D simulates no source cell within {e} cells of the grid's "
            f"edge: {int((source & ~active).sum())} of {int(source.sum())} source "
            "cells lie there",
            source="site",
        )


SOURCES = [
    "ecorisQ, QGIS-RF3D (github.com/ecorisQ/QGIS-RF3D), rockyfor3d_inputs_algorithm.py"
    ": the field constraints (rockdensity 2000-3400 kg/m³, blshape 0-4, soiltype "
    "0-7, rg70/rg20/rg10 0-100 m) and the check that source cells in the two outer "
    "rows or columns 'will not be taken into account in the simulation'; README.md "
    "of the same repository.",
    "Dorren, L.K.A. (2016). Rockyfor3D (v5.2) revealed - Transparent description of "
    "the complete 3D rockfall model. ecorisQ paper (www.ecorisq.org): the input "
    "grids (§2.1), the soil types and their Rn (Table 1), the rebound and Rt from "
    "the obstacle heights (§3.3).",
    "Nicolet, P. (NGU, 2021). PimpMyRockyfor, CreateFeatureClass.py "
    "(github.com/pierrick-nicolet/PimpMyRockyfor): grid names and units, the "
    "blshape and soiltype code lists.",
]

UNCONFIRMED = [
    "Rt = 1 / (1 + MOH / R), with MOH drawn from rg70 / rg20 / rg10 with "
    "probabilities 0.7 / 0.2 / 0.1 and R the block radius: Rockyfor3D's rule as "
    "recalled from Dorren (2016) §3.3; no stored document (QGIS-RF3D, "
    "PimpMyRockyfor, the manual's contents pages) gives the formula, so the obstacle "
    "heights inverted from e_t rest on it unconfirmed.",
    "the Rn ranges and means of the soil types (Table 1 of the v5.2 manual as "
    "recalled; the stored copies showed its contents, not the table): check them "
    "against the manual of your Rockyfor3D version (v6.0 has been released since).",
    "whether Rockyfor3D scales Rn with the impact speed or angle, and how it "
    "deviates the rebound direction: not emulated.",
    "the keyword table from ground descriptions to soil types is fieldkit's reading "
    "of Table 1's class descriptions, not ecorisQ's.",
    "no Rockyfor3D run was made with these files: they follow the documented format "
    "and the input plugin's checks.",
]


HOW_TO_USE = """\
Put the ten `.asc` files in one folder: they share the header of `dem.asc`
(Rockyfor3D needs every grid on the same cells) and choose that folder as the input
of a Rockyfor3D simulation (Dorren 2016, §2.6). The number of simulations per source
cell, any variation of the block volume and an additional initial fall height are
settings of the run (§2.5), not grids: set them there. No forest or net grids are
written, so the run is without forest and nets."""


def _mapped(
    model, site, unpadded, present, soil, soil_why, realised, rg, block
) -> list[Mapped]:
    body = model.body
    n_source = int((site.release & ground_cells(site)).sum())
    padded = site is not unpadded
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
            + f": rockdensity > 0, every one at least {EDGE_CELLS} cells inside the "
            "grid (Rockyfor3D ignores the outer two rows and columns)",
            "the release cells of the site (above)"
            + ("; the grid was padded to keep them inside" if padded else ""),
        ),
        Mapped(
            with_error(model, "body.radius_m", body.radius_m, "m"),
            f"d1.asc = d2.asc = d3.asc = {block.diameter_m:.4g} m; blshape.asc = 3 "
            "(spherical) in the source cells, 0 elsewhere",
            block.note
            or "fieldkit's body is a sphere of its contact radius: diameter 2 r on "
            "every axis",
        ),
        Mapped(
            with_error(model, "body.mass_kg", body.mass_kg, "kg"),
            f"rockdensity.asc = {block.density_kg_m3} kg/m³ in the source cells, 0 "
            "elsewhere",
            f"mass / (pi/6 d^3) with d = {block.diameter_m:.4g} m: Rockyfor3D's "
            "sphere has the model's mass",
        ),
    ]
    for name in present:
        m, s, r = model.materials[name], soil[name], realised[name]
        out.append(
            Mapped(
                f"material {name} ("
                + with_error(model, f"materials.{name}.e_n", m.e_n)
                + f"; realised e_n {r.e_n:.3f}, spread {r.e_n_spread:.3f})",
                f"soiltype.asc = {s.label()}: Rn {s.rn_min:.2f}-{s.rn_max:.2f}, "
                f"mean {s.rn_mean:.2f}",
                f"by the ground it is: {soil_why[name]}",
            )
        )
        h = rg[name]
        mean, sd = rt_mixture(h, block.radius_m)
        out.append(
            Mapped(
                with_error(model, f"materials.{name}.e_t", m.e_t)
                + f"; realised e_t {r.e_t:.3f}, spread {r.e_t_spread:.3f} ({r.note})",
                f"rg70 / rg20 / rg10 = {h['rg70']:.3f} / {h['rg20']:.3f} / "
                f"{h['rg10']:.3f} m",
                f"Rt = 1 / (1 + MOH / R), R = {block.radius_m:.4g} m, inverted at the "
                "65th / 20th / 5th percentile of the realised e_t (the middle of the "
                "top 70 %, the next 20 % and the lowest 10 %): Rockyfor3D's Rt then "
                f"has mean {mean:.3f} and SD {sd:.3f}"
                + (
                    f"; heights above Rockyfor3D's {RG_MAX_M:g} m written as "
                    f"{RG_MAX_M:g} m (e_t near 0)"
                    if max(h.values()) >= RG_MAX_M
                    else ""
                ),
            )
        )
    return out


def _unmapped(
    model: Model, site: ExportSite, present: list[str]
) -> list[tuple[str, str]]:
    out = []
    for name in present:
        m = model.materials[name]
        out.append(
            (
                with_error(model, f"materials.{name}.friction_deg", m.friction_deg),
                "Rockyfor3D's inputs have no friction angle (no grid, no setting "
                "among its inputs, §2.1)",
            )
        )
        out.append(
            (
                f"materials.{name}: roughness_m = {m.roughness_m:g} m, "
                f"roughness_deg_sd = {m.roughness_deg_sd:g} deg",
                "fieldkit's random local dip (slope_roughness) has no Rockyfor3D "
                "input: rg70/rg20/rg10 carry Rt, written from the realised e_t",
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
    height = float(s.z_m - model.profile.ground_z(s.x_m))
    where = f"above the ground at chainage {s.x_m:g} m"
    source = site.release & ground_cells(site)
    if site.grid.source.endswith("(section extruded)"):
        # the source cells' elevation is the profile's at their centre, not at the
        # seeder: the fall to keep is from the seeder down to them
        height = float(s.z_m - np.mean(site.grid.values[source]))
        where = "above the source cells (the section's elevation at their centres)"
    speed = math.hypot(s.vx_mps, s.vz_mps)
    out.append(
        (
            f"seeder: {height:.3g} m {where}; "
            f"velocity vx {s.vx_mps:g}, vz {s.vz_mps:g} m/s (SDs {s.vx_sd_mps:g}, "
            f"{s.vz_sd_mps:g} m/s)",
            "no grid takes a release height or velocity: the source cells start "
            "blocks on the DEM. Set the run's additional initial fall height (§2.5) "
            f"to {height:.3g} m to keep the seeder's fall"
            + (
                f"; the release speed {speed:.3g} m/s has no Rockyfor3D input "
                f"(a fall of v^2 / 2g = {speed**2 / (2 * 9.81):.3g} m more gives it "
                "as a vertical speed)"
                if speed > 0
                else ""
            ),
        )
    )
    for spec in registry.EFFECTS:
        state = (
            "on: "
            + ", ".join(f"{k} = {v:g}" for k, v in model.effects[spec.name].items())
            if spec.name in model.effects
            else "off in this model"
        )
        out.append(
            (
                f"effect {spec.name} ({state})",
                not_a_law(spec.name, "Rockyfor3D") or spec.export("Rockyfor3D").how,
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


def _mismatches(model, present, soil, realised, block) -> list[str]:
    means = ", ".join(f"{s.code}: {s.rn_mean:.2f}" for s in SOIL_TYPES)
    out = [f"soil-type class means used (Rn, Dorren 2016 Table 1): {means}"]
    for name in present:
        r, s = realised[name], soil[name]
        inside = s.rn_min <= r.e_n <= s.rn_max
        out.append(
            f"{name}: realised e_n {r.e_n:.3g} (spread {r.e_n_spread:.3g}) -> soiltype "
            f"{s.label()}, Rn {s.rn_min:.2f}-{s.rn_max:.2f}: e_n is "
            + (
                "inside the class range"
                if inside
                else f"outside the class range by "
                f"{min(abs(r.e_n - s.rn_min), abs(r.e_n - s.rn_max)):.2f}"
                + (
                    " (no Rockyfor3D soil type reaches it)"
                    if r.e_n > max(t.rn_max for t in SOIL_TYPES)
                    else ""
                )
            )
            + "; the translation error below gives what this costs"
        )
        if r.impacts == 0:
            out.append(f"{name}: {r.note}")
    mass = block.density_kg_m3 * math.pi / 6.0 * block.diameter_m**3
    out.append(
        f"body: a sphere of diameter {block.diameter_m:.4g} m; a block of another "
        "shape (e.g. measured axes) changes d1-d3 and blshape, and rockdensity must "
        "then be recomputed for the mass. The whole-number density "
        f"{block.density_kg_m3} kg/m³ gives {mass:.5g} kg for {model.body.mass_kg:g} "
        f"kg ({100 * (mass / model.body.mass_kg - 1):+.2f} %)"
        + (f". {block.note}" if block.note else "")
    )
    return out


def _notes(model: Model, site: ExportSite, present: list[str]) -> list[str]:
    out = [f"site: {site.description}"]
    missing = [n for n in model.materials if n not in present]
    if missing:
        out.append(
            "materials under no cell centre, so not on the grid: " + ", ".join(missing)
        )
    return out
