"""CRSP 4.0 (Colorado Rockfall Simulation Program): slope cells and the rock, in feet.

CRSP is a 2-D lumped-mass program in US customary units (Jones, Higgins & Andrew
2000, *Colorado Rockfall Simulation Program Version 4.0*, Colorado DOT report
CDOT-SYMB-CGS-99-1; Pfeiffer & Bowen 1989). Its slope is a chain of *cells*, each a
straight segment from (begin x, begin y) to (end x, end y) with three surface
values, written here from the model's profile one cell per segment:

* **S**, the surface roughness: the perpendicular variation of the slope from its
  average inclination within a slope distance equal to the rock's radius, from
  which CRSP takes the roughness angle ``atan(S / r)`` (thesis §7.3.6, eq. 7.4,
  after Pfeiffer & Bowen 1989). fieldkit's ``roughness_m`` is that same ``s``
  (:mod:`fieldkit.model.effects.slope_roughness`), so S = ``roughness_m`` in feet.
* **Rt**, the tangential coefficient, which CRSP scales at each impact by a friction
  function f(F) and a scaling factor SF of the impact velocities and Rn (thesis
  §7.3.5): CRSP's *effective* tangential restitution is not Rt, so the calibrated
  lumped ``e_t`` written as Rt is a starting value, not an equivalent.
* **Rn**, the normal coefficient of restitution, which CRSP scales by the impact
  velocity (thesis eq. 7.1, K = 30 ft/s = 9.144 m/s, §7.3.4).

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
fieldkit therefore enforces only what the definitions require (0 < Rn, Rt <= 1: a
coefficient above 1 would add energy at every impact; S >= 0) and says so in the
README.
"""

from __future__ import annotations

import math

import numpy as np

from fieldkit.errors import ArgumentError
from fieldkit.export.fitted import with_error
from fieldkit.export.lumped import not_a_law
from fieldkit.export.result import Export, Mapped
from fieldkit.export.site import ExportSite
from fieldkit.model.model_file import Model
from fieldkit.outputs import csv_text
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
        A material's Rn or Rt outside (0, 1], or a roughness CRSP cannot take.

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 30.48], "z_m": [30.48, 0],
    ...   "material": "rock"}, "materials": {"rock": {"e_n": 0.35, "e_t": 0.85,
    ...   "friction_deg": 30, "roughness_m": 0.3048}}, "effects":
    ...   {"slope_roughness": {}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 31}})
    >>> print(export_crsp(m).files["cells.csv"], end="")
    cell,begin_x_ft,begin_y_ft,end_x_ft,end_y_ft,S_ft,Rt,Rn,material
    1,0.00,100.00,100.00,0.00,1.00,0.850,0.350,rock
    """
    del site
    _check_coefficients(model)
    surface = {name: _surface(model, name) for name in model.materials}
    shape, shape_note = rock_shape(model.body.radius_m, model.body.gyration_m)
    mapped, mismatches = _mapped_materials(model, surface)
    rock_mapped, rock_mismatch = _mapped_rock(model, shape, shape_note)
    velocity_mapped, velocity_mismatch = _velocity_scaling(model)
    mapped += rock_mapped + _mapped_geometry(model) + velocity_mapped
    mismatches = [
        _rt_mismatch(),
        *mismatches,
        *rock_mismatch,
        *velocity_mismatch,
        *_rn_above_one(model),
    ]
    return Export(
        target="crsp",
        title="CRSP (Colorado Rockfall Simulation Program), 2-D",
        files={
            "cells.csv": cells_csv(model, surface),
            "rock.csv": rock_csv(model, shape),
            "start.csv": start_csv(model),
        },
        mapped=mapped,
        unmapped=_unmapped(model),
        units=_units(),
        mismatches=mismatches,
        notes=_notes(model),
        how_to_use=HOW_TO_USE,
    )


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


def _check_coefficients(model: Model) -> None:
    """Rt in (0, 1]; Rn too, except that a model with velocity scaling of e_n may
    carry Rn > 1: CRSP scales Rn by 1 / (1 + (v/K)^2) itself (thesis §7.3.4), so
    such an Rn is what the scaled law was calibrated with (RocFall's rule too)."""
    low, high = COEFFICIENT_RANGE
    scaled = "velocity_scaled_restitution" in model.effects
    for name, material in model.materials.items():
        for field, target in (("e_n", "Rn"), ("e_t", "Rt")):
            value = getattr(material, field)
            top = math.inf if (field == "e_n" and scaled) else high
            if not low < value <= top:
                why = (
                    " (a coefficient above 1 adds energy at every impact; Rn above "
                    "1 is exported only for a model with velocity scaling of e_n, "
                    "velocity_scaled_restitution, which CRSP applies itself)"
                    if value > high
                    else ""
                )
                raise ArgumentError(
                    f"materials.{name}.{field} = {value:g} is outside CRSP's {target} "
                    f"range ({low:g}, {high:g}]{why}",
                    source="model",
                )


def _rn_above_one(model: Model) -> list[str]:
    """Mismatch lines for Rn > 1 written with CRSP's own velocity scaling."""
    out = []
    for name, material in model.materials.items():
        if material.e_n > COEFFICIENT_RANGE[1]:
            v = CRSP_K_MPS * math.sqrt(material.e_n - 1.0)
            out.append(
                f"{name} Rn = {material.e_n:.4g} > 1, written as calibrated with "
                f"velocity scaling: with CRSP's K = 30 ft/s the scaled Rn is below 1 "
                f"for normal impact speeds above {m_to_ft(v):.3g} ft/s "
                f"({v:.3g} m/s); whether CRSP 4.0 accepts an Rn above 1 is not "
                "confirmed (its manual could not be read)"
            )
    return out


def _surface(model: Model, name: str) -> tuple[float, float, float]:
    """(S [ft], Rt, Rn) of material ``name``."""
    material = model.materials[name]
    return (
        float(m_to_ft(_roughness_s_m(model, name))),
        material.e_t,
        material.e_n,
    )


def _roughness_s_m(model: Model, name: str) -> float:
    """CRSP's S [m] giving the roughness angle fieldkit's ``roughness_m`` gives.

    ``slope_roughness`` off: 0 (the calibrated model used no roughness). On with
    ``scale``: ``r tan(scale atan(s / r))`` (= ``s`` at scale 1), so that
    ``atan(S / r)`` is fieldkit's CRSP-part of the dip spread.
    """
    s = model.materials[name].roughness_m
    effect = model.effects.get("slope_roughness")
    if effect is None or s == 0.0:
        return 0.0
    scale = float(effect.get("scale", 1.0))
    r = model.body.radius_m
    angle = scale * math.atan(s / r)
    if angle >= math.radians(89.0):
        raise ArgumentError(
            f"materials.{name}.roughness_m = {s:g} m at slope_roughness.scale = "
            f"{scale:g} is a roughness angle of {math.degrees(angle):.0f} deg: CRSP's "
            "S = r tan(angle) needs an angle below 89 deg",
            source="model",
        )
    return r * math.tan(angle)


def _mapped_materials(
    model: Model, surface: dict[str, tuple[float, float, float]]
) -> tuple[list[Mapped], list[str]]:
    mapped: list[Mapped] = []
    mismatches: list[str] = []
    scale = float(model.effects.get("slope_roughness", {}).get("scale", 1.0))
    for name, material in model.materials.items():
        s_ft, rt, rn = surface[name]
        key = f"materials.{name}"
        mapped.append(
            Mapped(
                with_error(model, f"{key}.e_n", material.e_n),
                f"{name} cells: Rn = {rn:.3f}",
                "as calibrated; CRSP scales it by the impact velocity (eq. 7.1)",
            )
        )
        mapped.append(
            Mapped(
                with_error(model, f"{key}.e_t", material.e_t),
                f"{name} cells: Rt = {rt:.3f}",
                "as calibrated; CRSP scales it by f(F) and SF: see the mismatch",
            )
        )
        if material.roughness_m > 0.0:
            how = _roughness_how(model, scale)
            mapped.append(
                Mapped(
                    with_error(model, f"{key}.roughness_m", material.roughness_m, "m"),
                    f"{name} cells: S = {s_ft:.2f} ft",
                    how,
                )
            )
        if "slope_roughness" in model.effects and scale != 1.0 and s_ft > 0.0:
            mismatches.append(
                f"{name}: S was written so that CRSP's roughness angle atan(S/r) "
                f"equals fieldkit's scaled one (slope_roughness.scale = {scale:g}); "
                "CRSP draws the impact angle within its own limits, fieldkit from a "
                "normal distribution: the spreads agree in size, not in shape."
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
                "the CRSP part atan(s/r) only; roughness_deg_sd: see below",
            )
        )
    return out


def _roughness_how(model: Model, scale: float) -> str:
    if "slope_roughness" not in model.effects:
        return "slope_roughness off in the model: S = 0"
    if scale == 1.0:
        return "S = roughness_m / 0.3048"
    return f"S = r tan({scale:g} atan(s/r)) / 0.3048 (slope_roughness.scale)"


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
    if effect is not None:
        k = float(effect.get("k_mps", CRSP_K_MPS))
        if math.isclose(k, CRSP_K_MPS, rel_tol=1e-3):
            return [
                Mapped(
                    with_error(model, "velocity_scaled_restitution.k_mps", k, "m/s"),
                    "CRSP's own scaling of Rn (K = 30 ft/s)",
                    "the same eq. 7.1 and K",
                )
            ], []
        return [], [
            f"velocity_scaled_restitution.k_mps = {k:.4g} m/s "
            f"({m_to_ft(k):.4g} ft/s), but CRSP scales Rn with K = 30 ft/s "
            "(9.144 m/s, thesis §7.3.4; whether CRSP 4.0 lets K be changed is not "
            "confirmed): CRSP's rebounds at impact speeds near K differ from the "
            "model's; recalibrate Rn in CRSP."
        ]
    return [], [
        "The calibrated model has no velocity scaling of e_n (velocity_scaled_"
        "restitution off), but CRSP scales Rn by 1 / (1 + (v/K)^2) with K = 30 ft/s "
        "(thesis §7.3.4, eq. 7.1; whether CRSP 4.0 can switch it off is not "
        "confirmed): at a normal impact speed of 30 ft/s (9.1 m/s) CRSP's normal "
        "rebound is half the model's. "
        "Recalibrate Rn in CRSP, or calibrate fieldkit with velocity_scaled_"
        "restitution at k_mps = 9.144 before exporting."
    ]


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
        if material.roughness_deg_sd > 0.0:
            r = model.body.radius_m
            hint = r * math.tan(math.radians(material.roughness_deg_sd))
            out.append(
                (
                    f"{key}.roughness_deg_sd = {material.roughness_deg_sd:g} deg",
                    "RocFall's SD of the segment dip has no CRSP input and is not "
                    "converted: CRSP's S is a maximum variation within one radius, "
                    "not an SD. For reference, S = r tan(sd) would be "
                    f"{hint:.3g} m ({m_to_ft(hint):.3g} ft) for this rock; the "
                    f"cells carry S from roughness_m only "
                    f"({material.roughness_m:g} m)",
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
    reasons = {
        "rotation_friction": "CRSP computes the rotation itself (w = v_T / r and the "
        "shape's moment of inertia, thesis §7.3.7); fieldkit's contact friction and "
        "coupling have no CRSP input",
        "angle_dependent_restitution": "CRSP's Rn depends on the impact velocity "
        "(eq. 7.1), not on the impact angle (eq. 5.4)",
        "air_drag": "CRSP is a lumped-mass model without air drag (thesis §7.2)",
        "mass_loss": "CRSP's rock keeps its mass (no breakage)",
        "tree_impacts": "no tree-impact input was found for CRSP 4.0",
    }
    out = []
    for name, params in model.effects.items():
        why = reasons.get(name) or not_a_law(name, "CRSP")
        if why:
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
    notes = [f"Source: {s}." for s in SOURCES]
    notes += [
        "Not confirmed (the manual's body was not available): CRSP 4.0's accepted "
        "ranges of Rn, Rt and S, its largest number of cells, its coordinate "
        "convention (the cells keep the model's frame: x = chainage from the "
        "profile's start, y = elevation, negative values as in the model) and its "
        "start-zone form. fieldkit refuses only Rn or Rt outside (0, 1] and S below "
        "0; check the values against CRSP's input screen.",
        f"The cells follow the model's {len(model.profile.material)} profile "
        "segments one to one; nothing was merged or split.",
    ]
    return notes
