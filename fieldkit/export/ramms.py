"""RAMMS::ROCKFALL: the DEM and a recommended terrain category per material.

RAMMS::ROCKFALL (WSL/SLF; Leine et al. 2014, Bartelt et al. 2016) is a rigid-body
model: rocks are polyhedra, every normal impact is plastic, and the ground acts
through a friction that grows with the slip (the *scar*) the rock makes. The ground
is chosen per area from seven categories, Extra Soft ... Extra Hard, each a set of
parameters mu_min, mu_max, beta, kappa, epsilon. A lumped normal and tangential
restitution (fieldkit's ``e_n``, ``e_t``) has no counterpart in that law, so nothing
calibrated maps to a category: this export *recommends* one per material by a
stated rule and says how uncertain it is.

**The rule** (:func:`recommend`): the material's name is read as a ground
description, and the first keyword of :data:`DESCRIPTIONS` found in it (longest
first) places it on the category scale 0 (Extra Soft) ... 6 (Extra Hard). A
position within 0.25 of a category is that category; otherwise it lies between two,
and both are reported, the nearer first (exactly half-way: the harder first, the
conservative choice for reach). The calibrated ``e_n`` is *not* used: thesis
Table 7-1 has e_n = 1.0 on colluvium and talus and 0.75 on rock, because a lumped
e_n grows at shallow impacts (eq. 5.4) -- a rule on it would rank colluvium harder
than bedrock. A name with no keyword gets no recommendation (code 0) and says so.

Files: ``dem.asc`` (ESRI ASCII, the format RAMMS imports besides GeoTIFF and ASCII
XYZ), ``terrain_category.asc`` (category code per cell, 1 = Extra Soft ... 7 = Extra
Hard, 0 = none; RAMMS assigns categories to polygons, so this grid is for
polygonising in a GIS, not a RAMMS input) and ``terrain_categories.csv``.

Sources: the RAMMS::ROCKFALL User Manual (v1.5 2013, v1.6 2015, WSL/SLF; stored
copies gave their title pages and contents only: "Friction parameters", "Terrain"
sections); a public review of the RAMMS manual (ofuhrer/rust_rockfall, docs
``ramms_gap_analysis.md``: DEM formats ESRI ASCII, GeoTIFF, ASCII XYZ; terrain,
forest and material polygons by shapefile); an unattributed public research note
summarising the RAMMS ground table (mu_max = 2 for every category; softest
0.20 / 50 / 1 / drag 0.9 and hardest 0.80 / 200 / 4 / drag 0.3 for mu_min / beta /
kappa; epsilon = 0, every normal impact plastic, Bartelt et al. 2016). The
intermediate categories' mu_min, beta and kappa could not be confirmed and are left
blank, marked so.
"""

from __future__ import annotations

import math
import re

import numpy as np

from fieldkit.export.ascii_grid import ascii_grid_text
from fieldkit.export.fitted import with_error
from fieldkit.export.lumped import not_a_law
from fieldkit.export.result import Export, Mapped
from fieldkit.export.site import ExportSite, checked_site
from fieldkit.model.effects import registry
from fieldkit.model.model_file import Model
from fieldkit.outputs import csv_text

#: RAMMS::ROCKFALL terrain categories, softest first (code = index + 1).
CATEGORIES = (
    "Extra Soft",
    "Soft",
    "Medium Soft",
    "Medium",
    "Medium Hard",
    "Hard",
    "Extra Hard",
)
#: How close (in category steps) a position must be to a category to be only it.
SNAP = 0.25

#: Published parameters fieldkit could confirm (secondary source, see the module
#: docstring): category -> {parameter: value}. Missing = not confirmed.
PARAMETERS: dict[str, dict[str, float]] = {
    "Extra Soft": {"mu_min": 0.20, "beta": 50.0, "kappa": 1.0, "drag": 0.9},
    "Extra Hard": {"mu_min": 0.80, "beta": 200.0, "kappa": 4.0, "drag": 0.3},
}
#: Parameters stated for every category by the same source.
COMMON = {"mu_max": 2.0, "epsilon": 0.0}
PARAMETER_NAMES = ("mu_min", "mu_max", "beta", "kappa", "epsilon", "drag")

#: Ground-description keywords -> position on the category scale (0 = Extra Soft,
#: 6 = Extra Hard), with the reason. fieldkit's judgement, written down: the ground
#: types are those RAMMS's default soil categories name (wet and soft soils, forest
#: soil, talus, boulder fields, roads, bedrock) and thesis Table 3-1's slope
#: categories A-D.
DESCRIPTIONS: tuple[tuple[tuple[str, ...], float, str], ...] = (
    (
        ("swamp", "marsh", "moor", "bog", "peat", "wet soil"),
        0.0,
        "wet or organic ground: the softest category",
    ),
    (
        ("meadow", "forest soil", "grass", "humus", "soil", "topsoil"),
        1.0,
        "fine soil with a vegetated cover",
    ),
    (
        ("colluvium",),
        2.5,
        "compact gravel and soil (Medium Soft) whose back-analysed effective "
        "friction matches talus (thesis worked example 3C: mu' = 0.34 at Tornado "
        "Mountain, Table 3-1 category D): between Medium Soft and Medium",
    ),
    (
        ("gravel", "sand", "fill", "debris"),
        2.0,
        "loose fine-to-coarse deposits",
    ),
    (("talus", "scree"), 3.0, "talus or scree"),
    (("boulder", "boulders", "block field"), 4.0, "boulder field"),
    (
        ("weathered rock", "weak rock", "fractured rock", "rock with soil"),
        5.0,
        "rock with a weathered or soil cover",
    ),
    (("asphalt", "road", "concrete", "pavement"), 5.0, "road surface"),
    (
        ("bedrock", "rock", "outcrop", "cliff", "ledge"),
        6.0,
        "bare rock: the hardest category",
    ),
)


def export_ramms(model: Model, site: ExportSite | None = None) -> Export:
    """The RAMMS::ROCKFALL inputs of ``model`` on ``site`` (module docstring).

    Parameters
    ----------
    model
        The calibrated model.
    site
        The grid: a DEM, or the section extruded
        (:func:`fieldkit.export.site.site_from_section`).

    Raises
    ------
    ArgumentError
        No site.
    """
    site = checked_site(site, "ramms")
    picks = {name: recommend(name) for name in model.materials}
    return Export(
        target="ramms",
        title="RAMMS::ROCKFALL",
        files={
            "dem.asc": ascii_grid_text(site.grid.values, site.grid),
            "terrain_category.asc": ascii_grid_text(
                category_codes(site, picks), site.grid, integer=True
            ),
            "terrain_categories.csv": categories_csv(model, site, picks),
        },
        mapped=_mapped(model, site, picks),
        unmapped=_unmapped(model),
        units=[
            "SI throughout (m, kg): RAMMS works in metres; the DEM keeps the "
            "site's coordinates (CRS: "
            f"{site.grid.crs or 'none given: assign the projected CRS in RAMMS'})",
        ],
        mismatches=_mismatches(picks),
        notes=_notes(site),
        how_to_use=HOW_TO_USE,
        translation=TRANSLATION,
        sources=SOURCES,
        unconfirmed=UNCONFIRMED,
    )


#: Why the README gives no translation error (no invented number).
TRANSLATION = [
    "Not measured. RAMMS::ROCKFALL's law -- a rigid polyhedral rock, plastic normal "
    "impacts (epsilon = 0) and a ground friction that grows with the slip the rock "
    "makes (mu_min to mu_max, kappa, beta), chosen per terrain category -- cannot be "
    "emulated by fieldkit's 2-D lumped-mass model, whose rebound is a restitution "
    "pair; and the categories' intermediate parameters are not confirmed (below). "
    "fieldkit gives no number it did not measure: run RAMMS with the recommended "
    "category and its neighbour and compare its runout with the calibrated model's "
    "(`fieldkit simulate` on the same section).",
]

SOURCES = [
    "RAMMS::ROCKFALL User Manual v1.5 (2013) and v1.6 (2015), WSL Institute for Snow "
    "and Avalanche Research SLF: title pages and contents seen only (sections on "
    "the DEM, friction parameters and terrain).",
    "ofuhrer/rust_rockfall, docs/archive/ramms_gap_analysis.md (a public review of "
    "the RAMMS manual and papers): DEM import as ESRI ASCII, GeoTIFF or ASCII XYZ; "
    "terrain, forest and material polygons by shapefile; deterministic ground "
    "categories.",
    "An unattributed public research note summarising Bartelt et al. (2016) and the "
    "RAMMS ground table (secondary; its repository could not be identified): mu_max "
    "= 2 for every category; the softest category mu_min 0.20, beta 50, kappa 1, "
    "drag 0.9 and the hardest 0.80, 200, 4, 0.3 (named there 'moor' and 'bedrock'; "
    "taken here as Extra Soft and Extra Hard); epsilon = 0.",
    "Leine et al. (2014) Simulation of rockfall trajectories with consideration of "
    "rock shape, doi:10.1007/s11044-013-9393-4; Lu et al. (2019) Modelling rockfall "
    "impact with scarring in compactable soils, doi:10.1007/s10346-019-01238-z (the "
    "slip-dependent friction, scarring).",
]

UNCONFIRMED = [
    "mu_min, beta, kappa and drag of Soft, Medium Soft, Medium, Medium Hard and Hard "
    "(left blank in terrain_categories.csv).",
    "the exact ground descriptions RAMMS gives per category: the keyword table "
    "from material names to categories is fieldkit's judgement, not RAMMS's.",
    "whether RAMMS reads a category raster (fieldkit assumes polygons only).",
    "the extreme categories' parameters rest on a secondary source; verify them "
    "against the manual.",
    "no RAMMS run was made with these files.",
]


HOW_TO_USE = """\
Import `dem.asc` as the project's DEM (ESRI ASCII grid). `terrain_categories.csv`
lists, per material, the recommended RAMMS terrain category (and the neighbouring
one where the rule puts it between two), with the reasons. RAMMS assigns terrain
categories to polygons: turn `terrain_category.asc` into polygons in a GIS (e.g.
QGIS Raster > Conversion > Polygonize) or draw them in RAMMS, and give each the
category of its code (1 = Extra Soft ... 7 = Extra Hard; 0 = no recommendation,
choose from the site). Rocks, release and forest are set in RAMMS (see what could
not be mapped)."""


def recommend(name: str) -> tuple[str, str | None, float | None, str]:
    """(category, neighbour or None, scale position, reason) for material ``name``.

    The category is "" (no recommendation) when no keyword of :data:`DESCRIPTIONS`
    is in the name (module docstring: the rule).

    Examples
    --------
    >>> recommend("talus")[:3]
    ('Medium', None, 3.0)
    >>> recommend("upper_colluvium")[:3]
    ('Medium', 'Medium Soft', 2.5)
    >>> recommend("weathered-rock")[:2], recommend("m1")[:2]
    (('Hard', None), ('', None))
    """
    text = " " + re.sub(r"[^a-z0-9]+", " ", name.lower()) + " "
    keywords = sorted(
        ((k, position, why) for keys, position, why in DESCRIPTIONS for k in keys),
        key=lambda item: -len(item[0]),
    )
    for keyword, position, why in keywords:
        if f" {keyword} " in text:
            category, neighbour = category_at(position)
            return category, neighbour, position, f"'{keyword}' in the name: {why}"
    return (
        "",
        None,
        None,
        "no ground description in the name (known: "
        + ", ".join(k for keys, _, _ in DESCRIPTIONS for k in keys)
        + "): choose from the site, or rename the material",
    )


def category_at(position: float) -> tuple[str, str | None]:
    """The category at ``position`` on the 0 ... 6 scale, and its neighbour if any.

    Closer than :data:`SNAP` to a category: that category alone. Otherwise (a
    quarter step or more from both) the nearer of the two around it, then the other;
    exactly half-way, the harder first. Positions are clipped to 0 ... 6.

    Examples
    --------
    >>> category_at(3.0), category_at(3.2), category_at(3.25)
    (('Medium', None), ('Medium', None), ('Medium', 'Medium Hard'))
    >>> category_at(3.5), category_at(3.75), category_at(3.8)
    (('Medium Hard', 'Medium'), ('Medium Hard', 'Medium'), ('Medium Hard', None))
    >>> category_at(-1.0), category_at(9.0)
    (('Extra Soft', None), ('Extra Hard', None))
    """
    p = min(max(float(position), 0.0), len(CATEGORIES) - 1.0)
    lower = math.floor(p)
    frac = p - lower
    if frac < SNAP:
        return CATEGORIES[lower], None
    if frac > 1.0 - SNAP:
        return CATEGORIES[lower + 1], None
    softer, harder = CATEGORIES[lower], CATEGORIES[lower + 1]
    return (softer, harder) if frac < 0.5 else (harder, softer)


def category_codes(
    site: ExportSite, picks: dict[str, tuple[str, str | None, float | None, str]]
) -> np.ndarray:
    """Code per cell: 1 ... 7 (Extra Soft ... Extra Hard), 0 no pick, NaN no ground."""
    codes = np.full(site.grid.shape, np.nan)
    for name, (category, _, _, _) in picks.items():
        code = CATEGORIES.index(category) + 1 if category else 0
        codes[site.material == name] = code
    codes[~np.isfinite(site.grid.values)] = np.nan
    return codes


def categories_csv(
    model: Model,
    site: ExportSite,
    picks: dict[str, tuple[str, str | None, float | None, str]],
) -> str:
    """Per material: the recommendation, the category's parameters, the reason."""
    head = ["material", "cells", "code", "category", "neighbour", "position"]
    head += list(PARAMETER_NAMES) + ["parameters", "reason"]
    lines = [head]
    for name, (category, neighbour, position, why) in picks.items():
        values = category_parameters(category) if category else {}
        confirmed = ""
        if category:
            confirmed = (
                "confirmed (secondary source)"
                if category in PARAMETERS
                else "mu_min, beta, kappa, drag not confirmed: read them in RAMMS"
            )
        row = [
            name,
            str(int(np.count_nonzero(site.material == name))),
            str(CATEGORIES.index(category) + 1 if category else 0),
            category or "none",
            neighbour or "",
            "" if position is None else f"{position:g}",
        ]
        row += [f"{values[p]:g}" if p in values else "" for p in PARAMETER_NAMES]
        row += [confirmed, why]
        lines.append(row)
    return csv_text(lines)


def category_parameters(category: str) -> dict[str, float]:
    """The parameters of ``category`` fieldkit could confirm (others absent).

    Examples
    --------
    >>> category_parameters("Extra Hard")["mu_min"], category_parameters("Medium")
    (0.8, {'mu_max': 2.0, 'epsilon': 0.0})
    """
    return {**COMMON, **PARAMETERS.get(category, {})}


def _mapped(
    model: Model,
    site: ExportSite,
    picks: dict[str, tuple[str, str | None, float | None, str]],
) -> list[Mapped]:
    out = [
        Mapped(
            "the site's terrain",
            "dem.asc (ESRI ASCII grid)",
            site.description,
        )
    ]
    for name, (category, neighbour, _, why) in picks.items():
        material = model.materials[name]
        calibrated = ", ".join(
            with_error(model, f"materials.{name}.{field}", getattr(material, field))
            for field in ("e_n", "e_t")
        )
        target = (
            f"{name}: terrain category {category}"
            + (f" (or {neighbour})" if neighbour else "")
            if category
            else f"{name}: no category recommended"
        )
        out.append(
            Mapped(
                f"material {name} ({calibrated})",
                target,
                f"recommended by the name, not from e_n or e_t: {why}",
            )
        )
    return out


def _unmapped(model: Model) -> list[tuple[str, str]]:
    out: list[tuple[str, str]] = []
    for name, material in model.materials.items():
        values = ", ".join(
            f"{field} = {getattr(material, field):g}"
            for field in (
                "e_n",
                "e_t",
                "friction_deg",
                "roughness_m",
                "roughness_deg_sd",
            )
        )
        out.append(
            (
                f"materials.{name} ({values})",
                "RAMMS has no restitution, lumped friction angle or roughness input: "
                "its ground is a terrain category (slip-dependent friction); "
                "roughness comes from the DEM and the rock's shape",
            )
        )
    body = model.body
    out.append(
        (
            f"body (mass {body.mass_kg:g} kg, radius {body.radius_m:g} m, gyration "
            f"{body.gyration_m:g} m)",
            "RAMMS rocks are polyhedra from its shape library or a point cloud; "
            "choose a shape of this mass there (k/r = "
            f"{body.gyration_m / body.radius_m:.3f}; a solid sphere has 0.632)",
        )
    )
    out.append(
        (
            "seeder (start point and velocity)",
            "RAMMS starts rocks from release points or areas drawn in RAMMS; the "
            "release cells of the site are stated in the notes",
        )
    )
    for spec in registry.EFFECTS:
        params = model.effects.get(spec.name)
        state = (
            "on: " + ", ".join(f"{k} = {v:g}" for k, v in params.items())
            if params is not None
            else "off in this model"
        )
        out.append(
            (
                f"effect {spec.name} ({state})",
                not_a_law(spec.name, "RAMMS") or spec.export("RAMMS").how,
            )
        )
    return out


def _mismatches(
    picks: dict[str, tuple[str, str | None, float | None, str]],
) -> list[str]:
    out = [
        "RAMMS's ground law cannot be reduced to a lumped e_n / e_t: in RAMMS a "
        "rigid polyhedral rock hits the ground plastically (epsilon = 0) and slides "
        "against a friction that rises from mu_min to mu_max with the slip it "
        "makes (kappa, beta), so its rebound comes from the rock's shape and "
        "rotation, not from a restitution coefficient. No category reproduces the "
        "calibrated model; the categories written here are recommendations by "
        "ground description, not a translation.",
        "Why not by e_n: a lumped e_n depends on the impact angle (eq. 5.4) more "
        "than on the ground (thesis Table 7-1: e_n = 1.0 on colluvium and talus, "
        "0.75 on rock); a rule on it would rank colluvium harder than bedrock.",
        "Uncertainty of the rule: at least one category either way. The keyword "
        "table is fieldkit's judgement, not RAMMS's; check the category against "
        "RAMMS's own description of it, and back-calculate it in RAMMS against the "
        "observed runout (the calibrated fieldkit model's runout is a target).",
    ]
    for name, (category, neighbour, _, _) in picks.items():
        if not category:
            out.append(
                f"{name}: no recommendation (code 0 in terrain_category.asc); "
                "choose its category from the site."
            )
        elif neighbour:
            out.append(
                f"{name}: between {category} and {neighbour}; {category} is "
                "written, run both."
            )
    return out


def _notes(site: ExportSite) -> list[str]:
    rows, cols = np.nonzero(site.release)
    release = ", ".join(
        f"({site.grid.x_m[c]:.10g}, {site.grid.y_m[r]:.10g})"
        for r, c in list(zip(rows, cols, strict=True))[:10]
    )
    more = f" and {rows.size - 10} more" if rows.size > 10 else ""
    return [
        f"Site: {site.description}.",
        f"Release cells (centres, m): {release}{more}.",
    ]
