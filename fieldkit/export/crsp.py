"""CRSP 4.0 (Colorado Rockfall Simulation Program): slope cells and the rock, in feet.

CRSP is a 2-D lumped-mass program in US customary units (Jones, Higgins & Andrew
2000, *Colorado Rockfall Simulation Program Version 4.0*, Colorado DOT report
CDOT-SYMB-CGS-99-1; Pfeiffer & Bowen 1989). Its slope is a chain of *cells*, each a
straight segment from (begin x, begin y) to (end x, end y) with three surface
values, written here from the model's profile one cell per segment:

* **S**, the surface roughness: the perpendicular variation of the slope from its
  average inclination within a slope distance equal to the rock's radius, from
  which CRSP takes the roughness angle ``atan(S / r)`` (thesis §7.3.6, eq. 7.4,
  after Pfeiffer & Bowen 1989). fieldkit's dip SD ``scale * hypot(atan(s / r),
  roughness_deg_sd)`` (:mod:`fieldkit.model.effects.slope_roughness`, eq. 7.4 with
  RocFall's dip SD folded in) is that angle, so ``S = r tan(dip SD)`` in feet
  (``roughness_m`` itself at scale 1 without a dip SD).
* **Rt**, the tangential coefficient, which CRSP scales at each impact by a friction
  function f(F) and a scaling factor SF of the impact velocities and Rn (thesis
  §7.3.5): CRSP's *effective* tangential restitution is not Rt, so the calibrated
  lumped ``e_t`` written as Rt is a starting value, not an equivalent.
* **Rn**, the normal coefficient of restitution, which CRSP scales by the impact
  velocity (thesis eq. 7.1, K = 30 ft/s = 9.144 m/s, §7.3.4).

Where the calibrated law is not CRSP's (no velocity scaling, another K, an e_n above
1, an angle law), each material's Rn, Rt are the values in (0, 1] whose rebounds
under CRSP's law are closest to the calibrated model's simulated impacts
(:func:`fieldkit.export.lumped.fit_coefficients`), and the README gives the
translation error against fieldkit's emulation of CRSP (:func:`emulation`).

The rock is a sphere, cylinder or disk of a diameter and a density (CRSP takes the
mass from them; thesis §7.2): fieldkit's body is a mass, a contact radius and a
radius of gyration, so the shape is chosen from the gyration ratio ``k / r`` (solid
sphere ``sqrt(2/5) = 0.632``; cylinder or disk about its rolling axis
``sqrt(1/2) = 0.707``), the diameter is ``2 r`` and the density is the mass over the
volume of a sphere of radius ``r``
(:func:`fieldkit.physics.bodies.sphere_density_kg_m3`).

What could not be confirmed from the sources available (the stored copy of the
CRSP 4.0 manual gave its title page only): CRSP's own input limits for Rn, Rt and S,
its largest number of cells, its coordinate convention and its start-zone form.
fieldkit therefore checks every written value against what the definitions require
(:data:`RANGES`: 0 < Rn, Rt <= 1, a coefficient above 1 would add energy at every
impact; S >= 0; a positive density and diameter) and says so in the README.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from functools import lru_cache

import numpy as np

from fieldkit.errors import ArgumentError
from fieldkit.export.fitted import with_error
from fieldkit.export.lumped import (
    Coefficient,
    DocumentedRange,
    Written,
    closest_behaviour,
    effects_account,
    export_rules,
    fit_coefficients,
    fit_lines,
    foreign_normal_laws,
    no_rule,
    not_a_law,
    search_line,
    with_coefficients,
)
from fieldkit.export.result import Export, Mapped
from fieldkit.export.site import ExportSite
from fieldkit.export.translation import translation_error
from fieldkit.model.effects.slope_roughness import dip_sd_rad
from fieldkit.model.model_file import Model, model_from_dict, model_to_dict
from fieldkit.outputs import csv_text, json_text
from fieldkit.physics.bodies import sphere_density_kg_m3

#: Metres in one international foot (exact).
M_PER_FT = 0.3048
#: kg/m^3 in one lb/ft^3 (0.45359237 kg / 0.3048^3 m^3).
KG_M3_PER_PCF = 0.45359237 / M_PER_FT**3
#: Gyration ratio k/r of a solid sphere and of a cylinder or disk about its axis.
SPHERE_K_OVER_R = math.sqrt(0.4)
AXIS_K_OVER_R = math.sqrt(0.5)
#: CRSP's velocity scale of Rn (thesis eq. 7.1: K = 30 ft/s).
CRSP_K_MPS = 30.0 * M_PER_FT
#: What fieldkit enforces for Rn and Rt: lower < value <= upper.
COEFFICIENT_RANGE = (0.0, 1.0)
#: The range the in-range fit uses: the cells hold 3 decimals, so 0.001 is the
#: smallest Rn, Rt above 0 a cell can carry.
FIT_RANGE = (0.001, 1.0)
_DEFINITION = "by definition (the CRSP 4.0 manual's own input limits were not read)"
#: The range of every numeric field written (checked on every export).
RANGES: dict[str, DocumentedRange] = {
    "Rn": DocumentedRange(
        "Rn",
        0.0,
        1.0,
        "a coefficient of restitution: above 1 a rebound gains energy; " + _DEFINITION,
        open_lo=True,
    ),
    "Rt": DocumentedRange(
        "Rt",
        0.0,
        1.0,
        "a coefficient of restitution, scaled by CRSP's f(F) and SF; " + _DEFINITION,
        open_lo=True,
    ),
    "S": DocumentedRange(
        "S [ft]",
        0.0,
        math.inf,
        "a height: the slope's perpendicular variation within one rock radius "
        "(Pfeiffer & Bowen 1989, thesis §7.3.6)",
    ),
    "density": DocumentedRange(
        "density [pcf]", 0.0, math.inf, "a density", open_lo=True
    ),
    "diameter": DocumentedRange(
        "diameter [ft]", 0.0, math.inf, "a diameter", open_lo=True
    ),
}
UNCONFIRMED = (
    "CRSP 4.0's own input limits for Rn, Rt and S, its largest number of cells, its "
    "coordinate convention and its start-zone form (the manual's body could not be "
    "read: only its title and report pages)",
    "whether CRSP 4.0 lets K (30 ft/s) be changed or the velocity scaling of Rn be "
    "switched off, and whether its v is the normal impact speed (eq. 7.1, as "
    "fieldkit) or the full speed",
    "the form of CRSP's f(F) and SF (Rt's scaling): the emulation keeps Rt constant",
    "how CRSP draws the impact angle within atan(S/r) (Pfeiffer & Higgins 1990: "
    "randomly, within limits set by rock size and slope irregularities); fieldkit "
    "draws a normal dip perturbation with that SD",
)

SOURCES = (
    "Jones, C.L., Higgins, J.D. & Andrew, R.D. (2000) Colorado Rockfall Simulation "
    "Program Version 4.0, Colorado DOT report CDOT-SYMB-CGS-99-1 (title page and "
    "report number seen; the body of the manual was not available, so its input "
    "limits are not confirmed here)",
    "Pfeiffer, T.J. & Bowen, T.D. (1989) Computer simulation of rockfalls, "
    "Bulletin of the Association of Engineering Geologists: definitions of S, "
    "Rt (f(F), SF) and Rn as summarised in the thesis, ch. 7 (§7.2 shapes and "
    "default sphere, §7.3.4 eq. 7.1 velocity scaling of Rn with K = 30 ft/s, "
    "§7.3.5 Rt scaled by f(F) and SF, §7.3.6 roughness S and eq. 7.4, §7.3.7 "
    "rotation w = v_T / r)",
    "Pfeiffer, T.J. & Higgins, J.D. (1990) Rockfall hazard analysis using the "
    "Colorado Rockfall Simulation Program, Transportation Research Record 1288 "
    "(abstract: the impact angle varied randomly within limits set by rock size "
    "and slope irregularities; slope angle and surface roughness the most "
    "important inputs on steep slopes)",
)

HOW_TO_USE = """\
`cells.csv` has one row per CRSP cell, top to bottom: begin and end coordinates,
S, Rt and Rn, and the fieldkit material (for reference). Enter them in CRSP's cell
table. `rock.csv` gives the rock's shape, density and diameter; `start.csv` the
model's start point and velocity, for CRSP's starting conditions. Every value is in
feet, pounds and seconds (see Units). Calibrate Rt in CRSP against what was
observed before relying on it (see the residual mismatch)."""


def export_crsp(model: Model, site: ExportSite | None = None) -> Export:
    """The CRSP 4.0 input of ``model``: cells, rock and start (module docstring).

    Parameters
    ----------
    model
        The calibrated model.
    site
        Ignored: CRSP is 2-D and takes the model's own profile.

    Raises
    ------
    ArgumentError
        A roughness CRSP cannot take (an angle of 89 deg or more).

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 30.48], "z_m": [30.48, 0],
    ...   "material": "rock"}, "materials": {"rock": {"e_n": 0.35, "e_t": 0.85,
    ...   "friction_deg": 30, "roughness_m": 0.3048}}, "effects":
    ...   {"slope_roughness": {}, "velocity_scaled_restitution": {}},
    ...   "body": {"mass_kg": 100, "radius_m": 0.2}, "seeder": {"x_m": 1, "z_m": 31}})
    >>> print(export_crsp(m).files["cells.csv"], end="")
    cell,begin_x_ft,begin_y_ft,end_x_ft,end_y_ft,S_ft,Rt,Rn,material
    1,0.00,100.00,100.00,0.00,1.00,0.850,0.350,rock
    """
    del site
    written, coefficients, reasons, loud, search = crsp_model(model)
    surface = {name: _surface(written, name) for name in written.materials}
    shape, shape_note = rock_shape(model.body.radius_m, model.body.gyration_m)
    files = {
        "cells.csv": cells_csv(written, surface),
        "rock.csv": rock_csv(written, shape),
        "start.csv": start_csv(written),
    }
    check_written(written, surface)
    mapped, mismatches = _mapped_materials(model, surface, coefficients)
    rock_mapped, rock_mismatch = _mapped_rock(model, shape, shape_note)
    velocity_mapped, velocity_mismatch = _velocity_scaling(model)
    mapped += rock_mapped + _mapped_geometry(model) + velocity_mapped
    mismatches = [
        *loud,
        *fit_lines(reasons, coefficients, "CRSP", "(0, 1]", ".3f"),
        *search_line(search, "CRSP"),
        _rt_mismatch(),
        *mismatches,
        *rock_mismatch,
        *velocity_mismatch,
    ]
    emulated = emulation(written, surface, shape)
    return Export(
        target="crsp",
        title="CRSP (Colorado Rockfall Simulation Program), 2-D",
        files=files,
        mapped=mapped,
        unmapped=_unmapped(model),
        units=_units(),
        mismatches=mismatches,
        notes=_notes(model) + effects_account(model, "CRSP", EFFECT_RULES),
        how_to_use=HOW_TO_USE,
        translation=_translation_lines(model, emulated),
        sources=list(SOURCES),
        unconfirmed=list(UNCONFIRMED),
    )


def crsp_law(model: Model) -> list[str]:
    """Why ``model``'s law cannot be written in CRSP's terms as it is (empty: it
    can): CRSP always scales Rn by ``1 / (1 + (v/K)^2)`` with K = 30 ft/s.

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 10], "z_m": [5, 0],
    ...   "material": "rock"}, "materials": {"rock": {"e_n": 0.3, "e_t": 0.8,
    ...   "friction_deg": 25}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 6}})
    >>> crsp_law(m)[0][:48]
    'the calibrated model has no velocity scaling of '
    """
    reasons = []
    params = model.effects.get("velocity_scaled_restitution")
    k = None if params is None else float(params["k_mps"])
    if k is None or not math.isfinite(k):
        reasons.append(
            "the calibrated model has no velocity scaling of e_n, but CRSP scales "
            "Rn by 1 / (1 + (v/K)^2) with K = 30 ft/s (thesis §7.3.4)"
        )
    elif not math.isclose(k, CRSP_K_MPS, rel_tol=1e-9):
        reasons.append(
            f"velocity_scaled_restitution.k_mps = {k:.4g} m/s ({m_to_ft(k):.4g} "
            "ft/s), but CRSP scales Rn with K = 30 ft/s (9.144 m/s)"
        )
    for law in foreign_normal_laws(model, "CRSP"):
        reasons.append(f"{law}: CRSP has no such law")
    low, high = COEFFICIENT_RANGE
    for name, material in model.materials.items():
        for field, target in (("e_n", "Rn"), ("e_t", "Rt")):
            value = getattr(material, field)
            if not low < value <= high:
                reasons.append(
                    f"materials.{name}.{field} = {value:.4g} is outside CRSP's "
                    f"{target} range (0, 1]"
                )
    return reasons


def normal_factor(v_mps: np.ndarray) -> np.ndarray:
    """CRSP's scaling of Rn at normal impact speeds: ``1 / (1 + (v/K)^2)``, K =
    30 ft/s (:data:`CRSP_K_MPS`)."""
    return 1.0 / (1.0 + (np.asarray(v_mps, float) / CRSP_K_MPS) ** 2)


def crsp_model(model: Model) -> Written:
    """The model with CRSP's Rn, Rt per material, as the cells hold them (3
    decimals): as calibrated when the law is CRSP's (:func:`crsp_law`), else the
    values in (0, 1] whose emulation behaves closest to the calibrated model,
    searched from the impact-level least-squares values under CRSP's law
    (:func:`fieldkit.export.lumped.closest_behaviour`); with the reasons and the
    loud lines of materials no simulated rock touched. Cached per model."""
    return _crsp_model(json_text(model_to_dict(model)))


@lru_cache(maxsize=8)
def _crsp_model(text: str) -> Written:
    model = model_from_dict(json.loads(text))
    reasons = crsp_law(model)
    if not reasons:
        materials = {
            name: replace(m, e_n=round(m.e_n, 3), e_t=round(m.e_t, 3))
            for name, m in model.materials.items()
        }
        return Written(replace(model, materials=materials), {}, [], [], None)
    coefficients, loud = fit_coefficients(
        model,
        "CRSP",
        normal_factor,
        FIT_RANGE,
        FIT_RANGE,
        fit_rt="rotation_friction" not in model.effects,
    )
    shape, _ = rock_shape(model.body.radius_m, model.body.gyration_m)

    def emulate(values: dict[str, tuple[Coefficient, Coefficient]]) -> Model:
        written = with_coefficients(model, values)
        surface = {name: _surface(written, name) for name in written.materials}
        return emulation(written, surface, shape)

    coefficients, search = closest_behaviour(
        model,
        coefficients,
        emulate,
        normal_factor,
        FIT_RANGE,
        FIT_RANGE,
        precision=lambda v: round(v, 3),
        search_rt=False,
    )
    coefficients = {
        name: tuple(replace(c, written=round(c.written, 3)) for c in pair)
        for name, pair in coefficients.items()
    }
    return Written(
        with_coefficients(model, coefficients), coefficients, reasons, loud, search
    )


def emulation(
    written: Model, surface: dict[str, tuple[float, float, float]], shape: str
) -> Model:
    """fieldkit's model of CRSP's law with the values written.

    Each material: e_n = Rn, e_t = Rt (single values: no SD), the roughness as
    ``roughness_m = S`` (CRSP's angle ``atan(S/r)`` as fieldkit's dip SD), velocity
    scaling at K = 30 ft/s, the body's gyration that of CRSP's shape; friction,
    core and seeder as calibrated (CRSP has no friction input: fieldkit needs one
    to slide). What fieldkit cannot express: CRSP's f(F) and SF on Rt, its own
    rotation, rolling and stopping, the distribution of its angle draws.
    """
    materials = {}
    for name, m in written.materials.items():
        s_ft, rt, rn = surface[name]
        materials[name] = replace(
            m,
            e_n=rn,
            e_t=rt,
            e_n_sd=0.0,
            e_t_sd=0.0,
            roughness_m=s_ft * M_PER_FT,
            roughness_deg_sd=0.0,
        )
    effects = {"velocity_scaled_restitution": {"k_mps": CRSP_K_MPS}}
    if any(s_ft > 0.0 for s_ft, _, _ in surface.values()):
        effects["slope_roughness"] = {"scale": 1.0}
    ratio = SPHERE_K_OVER_R if shape == "sphere" else AXIS_K_OVER_R
    body = replace(written.body, gyration_m=ratio * written.body.radius_m)
    return replace(written, materials=materials, effects=effects, body=body)


def check_written(
    written: Model, surface: dict[str, tuple[float, float, float]]
) -> None:
    """Every numeric field written against :data:`RANGES`.

    Raises
    ------
    fieldkit.export.lumped.WrittenOutOfRange
        A value outside its range (an exporter bug).
    """
    for name, (s_ft, rt, rn) in surface.items():
        RANGES["S"].check(s_ft, f"{name} cells")
        RANGES["Rt"].check(rt, f"{name} cells")
        RANGES["Rn"].check(rn, f"{name} cells")
    body = written.body
    density = sphere_density_kg_m3(body.mass_kg, body.radius_m) / KG_M3_PER_PCF
    RANGES["density"].check(round(density, 2), "rock")
    RANGES["diameter"].check(round(float(m_to_ft(2.0 * body.radius_m)), 3), "rock")


def _translation_lines(model: Model, emulated: Model) -> list[str]:
    return [
        *translation_error(model, emulated).lines(),
        "",
        "The emulation (fieldkit cannot run CRSP): CRSP's Rn scaling at K = 30 "
        "ft/s, Rn and Rt as single values per cell, S as the roughness angle "
        "atan(S/r) (a normal dip SD in fieldkit; CRSP's own draw within that angle "
        "is not confirmed), the shape's moment of inertia. It keeps Rt constant "
        "(CRSP scales it by f(F) and SF, whose form was not available) and uses "
        "the calibrated friction angles for sliding (CRSP has none): CRSP's "
        "tangential rebounds, rolling and stopping will differ beyond this table.",
    ]


#: How CRSP takes every effect of the registry (README "Notes"): the effects'
#: metadata (:attr:`fieldkit.model.effects.spec.EffectSpec.exports`).
EFFECT_RULES: dict[str, tuple[bool, str]] = export_rules("CRSP")


def m_to_ft(value_m: float | np.ndarray) -> float | np.ndarray:
    """Metres -> international feet (1 ft = 0.3048 m exactly).

    Examples
    --------
    >>> m_to_ft(0.3048), round(m_to_ft(350.0), 3)
    (1.0, 1148.294)
    """
    return value_m / M_PER_FT


def rock_shape(radius_m: float, gyration_m: float) -> tuple[str, str]:
    """CRSP's shape nearest the body's gyration ratio, and how it was chosen.

    ``sphere`` when ``k / r`` is nearer ``sqrt(2/5)`` than ``sqrt(1/2)``, else
    ``cylinder`` (a cylinder and a disk both have ``k / r = sqrt(1/2)`` about their
    rolling axis: fieldkit's body cannot tell them apart).

    Examples
    --------
    >>> rock_shape(0.725, 0.46)[0], rock_shape(1.0, 0.70)[0]
    ('sphere', 'cylinder')
    """
    ratio = gyration_m / radius_m
    if abs(ratio - SPHERE_K_OVER_R) <= abs(ratio - AXIS_K_OVER_R):
        shape = "sphere"
    else:
        shape = "cylinder"
    return shape, (
        f"k/r = {gyration_m:.4g}/{radius_m:.4g} = {ratio:.3f}, nearest the "
        f"{'solid sphere (0.632)' if shape == 'sphere' else 'cylinder or disk (0.707)'}"
    )


def cells_csv(model: Model, surface: dict[str, tuple[float, float, float]]) -> str:
    """The cell table: one CRSP cell per profile segment, in feet."""
    x = np.asarray(m_to_ft(np.asarray(model.profile.x_m, float)))
    y = np.asarray(m_to_ft(np.asarray(model.profile.z_m, float)))
    rows = [
        "cell,begin_x_ft,begin_y_ft,end_x_ft,end_y_ft,S_ft,Rt,Rn,material".split(",")
    ]
    for j, name in enumerate(model.profile.material):
        s_ft, rt, rn = surface[name]
        rows.append(
            [str(j + 1)]
            + [f"{v:.2f}" for v in (x[j], y[j], x[j + 1], y[j + 1], s_ft)]
            + [f"{rt:.3f}", f"{rn:.3f}", name]
        )
    return csv_text(rows)


def rock_csv(model: Model, shape: str) -> str:
    """The rock: shape, density [pcf] and diameter [ft] (and the mass, to check)."""
    body = model.body
    density = sphere_density_kg_m3(body.mass_kg, body.radius_m) / KG_M3_PER_PCF
    lines = [
        "field,value,unit",
        f"shape,{shape},",
        f"density,{density:.2f},pcf",
        f"diameter,{m_to_ft(2.0 * body.radius_m):.3f},ft",
        f"mass (check),{body.mass_kg / 0.45359237:.1f},lb",
    ]
    return "\n".join(lines) + "\n"


def start_csv(model: Model) -> str:
    """The model's start point and velocity in feet and ft/s (with their SDs)."""
    s = model.seeder
    rows = [
        ("x", s.x_m, s.x_sd_m, "ft"),
        ("y", s.z_m, s.z_sd_m, "ft"),
        ("vx", s.vx_mps, s.vx_sd_mps, "ft/s"),
        ("vy", s.vz_mps, s.vz_sd_mps, "ft/s"),
    ]
    lines = ["field,value,sd,unit"]
    lines += [
        f"{name},{m_to_ft(value):.2f},{m_to_ft(sd):.2f},{unit}"
        for name, value, sd, unit in rows
    ]
    return "\n".join(lines) + "\n"


def _surface(model: Model, name: str) -> tuple[float, float, float]:
    """(S [ft], Rt, Rn) of material ``name`` as the cells hold them (S to 0.01 ft,
    Rt and Rn to 3 decimals)."""
    material = model.materials[name]
    return (
        round(float(m_to_ft(roughness_s_m(model, name))), 2),
        round(material.e_t, 3),
        round(material.e_n, 3),
    )


def roughness_s_m(model: Model, name: str) -> float:
    """CRSP's S [m] whose roughness angle ``atan(S / r)`` is fieldkit's dip SD.

    ``slope_roughness`` off: 0 (the calibrated model used no roughness). On:
    ``r tan(scale hypot(atan(s / r), roughness_deg_sd))``
    (:func:`fieldkit.model.effects.slope_roughness.dip_sd_rad`; ``s`` itself at
    scale 1 without a dip SD).

    Raises
    ------
    ArgumentError
        An angle of 89 deg or more: no S gives it.

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 10], "z_m": [5, 0],
    ...   "material": "rock"}, "materials": {"rock": {"e_n": 0.3, "e_t": 0.8,
    ...   "friction_deg": 25, "roughness_deg_sd": 35}}, "effects":
    ...   {"slope_roughness": {}}, "body": {"mass_kg": 3750, "radius_m": 0.725},
    ...   "seeder": {"x_m": 1, "z_m": 6}})
    >>> round(roughness_s_m(m, "rock"), 4)   # 0.725 tan(35 deg) = 0.725 * 0.70021
    0.5077
    """
    material = model.materials[name]
    effect = model.effects.get("slope_roughness")
    if effect is None:
        return 0.0
    scale = float(effect.get("scale", 1.0))
    r = model.body.radius_m
    angle = float(dip_sd_rad(material.roughness_m, material.roughness_deg_sd, r, scale))
    if angle >= math.radians(89.0):
        raise ArgumentError(
            f"materials.{name}.roughness_m = {material.roughness_m:g} m, "
            f"roughness_deg_sd = {material.roughness_deg_sd:g} deg at "
            f"slope_roughness.scale = {scale:g} is a roughness angle of "
            f"{math.degrees(angle):.0f} deg: CRSP's S = r tan(angle) needs an angle "
            "below 89 deg",
            source="model",
        )
    return r * math.tan(angle)


def _mapped_materials(
    model: Model,
    surface: dict[str, tuple[float, float, float]],
    coefficients: dict[str, tuple[Coefficient, Coefficient]],
) -> tuple[list[Mapped], list[str]]:
    mapped: list[Mapped] = []
    mismatches: list[str] = []
    scale = float(model.effects.get("slope_roughness", {}).get("scale", 1.0))
    for name, material in model.materials.items():
        s_ft, rt, rn = surface[name]
        key = f"materials.{name}"
        fitted = dict(zip(("e_n", "e_t"), coefficients.get(name, ()), strict=False))
        for field, target, value, how in (
            ("e_n", "Rn", rn, "CRSP scales it by the impact velocity (eq. 7.1)"),
            ("e_t", "Rt", rt, "CRSP scales it by f(F) and SF: see the mismatch"),
        ):
            how = (
                f"written {fitted[field].text()}, fitted under CRSP's law; {how}"
                if field in fitted
                else f"as calibrated; {how}"
            )
            mapped.append(
                Mapped(
                    with_error(model, f"{key}.{field}", getattr(material, field)),
                    f"{name} cells: {target} = {value:.3f}",
                    how,
                )
            )
        if "slope_roughness" in model.effects:
            mapped.append(
                Mapped(
                    with_error(model, f"{key}.roughness_m", material.roughness_m, "m")
                    + ", "
                    + with_error(
                        model,
                        f"{key}.roughness_deg_sd",
                        material.roughness_deg_sd,
                        "deg",
                    ),
                    f"{name} cells: S = {s_ft:.2f} ft",
                    _roughness_how(model, scale),
                )
            )
        if "slope_roughness" in model.effects and s_ft > 0.0:
            mismatches.append(
                f"{name}: S = {s_ft:.2f} ft was written so that CRSP's roughness "
                "angle atan(S/r) equals fieldkit's dip SD; CRSP draws the impact "
                "angle within its own limits, fieldkit from a normal distribution: "
                "the spreads agree in size, not in shape."
            )
    return mapped, mismatches


def _mapped_geometry(model: Model) -> list[Mapped]:
    """The profile, the seeder and the roughness effect."""
    n = len(model.profile.material)
    out = [
        Mapped(
            f"profile ({n} segments)",
            f"{n} CRSP cells (cells.csv)",
            "one cell per segment, top to bottom; x = chainage, y = elevation, "
            "both / 0.3048",
        ),
        Mapped(
            "seeder (start point, velocity and SDs)",
            "start.csv",
            "converted to ft and ft/s; CRSP's start-zone form not confirmed",
        ),
    ]
    if "slope_roughness" in model.effects:
        scale = model.effects["slope_roughness"].get("scale", 1.0)
        out.append(
            Mapped(
                f"effect slope_roughness (scale = {scale:g})",
                "each cell's S (CRSP always applies its roughness)",
                "S = r tan(dip SD): roughness_m and roughness_deg_sd together",
            )
        )
    return out


def _roughness_how(model: Model, scale: float) -> str:
    if "slope_roughness" not in model.effects:
        return "slope_roughness off in the model: S = 0"
    return (
        f"S = r tan({scale:g} hypot(atan(roughness_m / r), roughness_deg_sd)) / "
        "0.3048: CRSP's roughness angle atan(S/r) is fieldkit's dip SD (eq. 7.4)"
    )


def _mapped_rock(
    model: Model, shape: str, shape_note: str
) -> tuple[list[Mapped], list[str]]:
    body = model.body
    density = sphere_density_kg_m3(body.mass_kg, body.radius_m)
    mapped = [
        Mapped(
            with_error(model, "body.mass_kg", body.mass_kg, "kg")
            + ", "
            + with_error(model, "body.radius_m", body.radius_m, "m"),
            f"rock density = {density / KG_M3_PER_PCF:.2f} pcf",
            f"m / (4/3 pi r^3) = {density:.1f} kg/m^3 (the body taken as a sphere "
            "of its contact radius), / 16.018463",
        ),
        Mapped(
            with_error(model, "body.radius_m", body.radius_m, "m"),
            f"rock diameter = {m_to_ft(2.0 * body.radius_m):.3f} ft",
            "2 r / 0.3048",
        ),
        Mapped(
            with_error(model, "body.gyration_m", body.gyration_m, "m"),
            f"rock shape = {shape}",
            shape_note,
        ),
    ]
    mismatches = [
        "CRSP takes the rock's mass from its density and diameter: the density "
        "written is the mass over a sphere of the contact radius, so CRSP's mass "
        f"equals {body.mass_kg:g} kg for a sphere; for a {shape} of that diameter "
        "CRSP's volume, and so its mass, differs."
        if shape != "sphere"
        else "CRSP takes the rock's mass from its density and diameter: the "
        "density written is the mass over a sphere of the contact radius, so "
        f"CRSP's sphere has the model's mass ({body.mass_kg:g} kg); a real block of "
        "that mass is not a sphere, and its true rock density may differ."
    ]
    ratio = body.gyration_m / body.radius_m
    nearest = SPHERE_K_OVER_R if shape == "sphere" else AXIS_K_OVER_R
    if abs(ratio / nearest - 1.0) > 0.05:
        mismatches.append(
            f"The body's k/r = {ratio:.3f} is more than 5 % from CRSP's {shape} "
            f"({nearest:.3f}): CRSP's moment of inertia is {(nearest / ratio) ** 2:.2f}"
            " times the model's, so its rotational energy differs by that factor."
        )
    if shape == "cylinder":
        mismatches.append(
            "A cylinder and a disk have the same k/r about their rolling axis: "
            "fieldkit wrote cylinder; enter the block's length (not in the model) "
            "or choose disk from the block's shape."
        )
    return mapped, mismatches


def _velocity_scaling(model: Model) -> tuple[list[Mapped], list[str]]:
    effect = model.effects.get("velocity_scaled_restitution")
    k = float(effect["k_mps"]) if effect is not None else math.inf
    what = (
        with_error(model, "velocity_scaled_restitution.k_mps", k, "m/s")
        if math.isfinite(k)
        else "velocity_scaled_restitution off"
    )
    how = (
        "the same eq. 7.1 and K"
        if math.isclose(k, CRSP_K_MPS, rel_tol=1e-9)
        else "Rn fitted in range under CRSP's scaling (see the residual mismatch)"
    )
    return [Mapped(what, "CRSP's own scaling of Rn (K = 30 ft/s)", how)], []


def _rt_mismatch() -> str:
    return (
        "Rt is not CRSP's tangential restitution: CRSP multiplies Rt at each impact "
        "by a friction function f(F) and a scaling factor SF of the impact "
        "translational and rotational velocities and Rn (Pfeiffer & Bowen 1989; "
        "thesis §7.3.5), so CRSP's effective tangential restitution differs from Rt "
        "and changes from impact to impact, while fieldkit's e_t is one lumped "
        "ratio v_fT / v_iT fitted to the observed impacts. The calibrated e_t was "
        "written as Rt as the nearest starting value (no inversion of f(F) and SF "
        "was attempted: their form was not available to confirm); back-calculate "
        "Rt in CRSP to the observed runout and velocities before design use."
    )


def _unmapped(model: Model) -> list[tuple[str, str]]:
    out: list[tuple[str, str]] = []
    for name, material in model.materials.items():
        key = f"materials.{name}"
        out.append(
            (
                f"{key}.friction_deg = {material.friction_deg:g} deg",
                "CRSP has no friction-angle input: its rolling and sliding "
                "resistance comes from Rt and its friction function (thesis §7.3.5)",
            )
        )
        sds = [
            f"{field} = {getattr(material, field):g}"
            for field in ("e_n_sd", "e_t_sd", "friction_deg_sd")
            if getattr(material, field) > 0.0
        ]
        if sds:
            out.append(
                (
                    f"{key}: {', '.join(sds)}",
                    "CRSP cells take single values of Rn and Rt; its spread comes "
                    "from the roughness S and the random impact angle",
                )
            )
    out += _unmapped_effects(model)
    if model.trees is not None:
        out.append(("trees", "no tree-impact input was found for CRSP 4.0"))
    out.append(
        (
            "core settings ("
            + ", ".join(f"{k} = {v:g}" for k, v in model.core.items())
            + ")",
            "CRSP decides itself when a rock rolls, slides or stops",
        )
    )
    if model.seeder.omega_radps or model.seeder.omega_sd_radps:
        out.append(
            (
                f"seeder.omega_radps = {model.seeder.omega_radps:g} rad/s",
                "no start-rotation field was confirmed for CRSP 4.0",
            )
        )
    return out


def _unmapped_effects(model: Model) -> list[tuple[str, str]]:
    out = []
    for name, params in model.effects.items():
        mapped, why = EFFECT_RULES.get(name, (False, ""))
        if mapped:
            continue
        why = why or not_a_law(name, "CRSP") or no_rule(name, "CRSP")
        values = ", ".join(f"{k} = {v:g}" for k, v in params.items())
        out.append((f"effect {name} ({values})", why))
    return out


def _units() -> list[str]:
    return [
        "lengths in feet: x, y, S and the diameter are metres / 0.3048 "
        "(1 ft = 0.3048 m exactly); velocities in ft/s",
        "density in pcf (lb/ft^3): kg/m^3 / 16.018463 (1 lb = 0.45359237 kg); the "
        "density is the model's mass over the volume of a sphere of its contact "
        "radius",
        "mass (check only) in lb: kg / 0.45359237",
        "Rn and Rt are ratios (no unit)",
    ]


def _notes(model: Model) -> list[str]:
    return [
        "Ranges checked on every value written: "
        + "; ".join(r.text() for r in RANGES.values())
        + ". Check the values against CRSP's input screen.",
        "The cells keep the model's frame: x = chainage from the profile's start, "
        "y = elevation, negative values as in the model.",
        f"The cells follow the model's {len(model.profile.material)} profile "
        "segments one to one; nothing was merged or split.",
    ]
