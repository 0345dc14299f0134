"""RocFall (Rocscience), lumped mass: a calibrated model as RocFall's input blocks.

RocFall project files are proprietary (``/work/shared/design/ECOSYSTEM.md``), so the
export writes what a user enters in RocFall's dialogs, as plain text that
:mod:`fieldkit.export.rocfall_import` reads back:

* ``materials.txt`` -- per slope material: normal and tangential coefficients of
  restitution ``rn``, ``rt``, the friction angle [deg] and the slope roughness (the
  SD of the segment dip [deg], thesis §7.3.6 and Table 7-1);
* ``rock_type.txt`` -- the rock type (mass) and its seeder: location and initial
  horizontal, vertical and rotational velocities;
* ``project_settings.txt`` -- lumped mass, metric units, ``scale rn by velocity``
  with ``scale rn velocity k (m/s)`` (thesis eq. 7.1) when the model's
  ``velocity_scaled_restitution`` is on, ``consider rotational velocity`` on when
  ``rotation_friction`` is, friction from the materials, the stopped-velocity cutoff;
* ``slope.csv`` -- the slope vertices ``x_m, y_m`` (y = fieldkit's elevation z) with
  the material id of the segment from each vertex to the next; ``material_ids.csv``
  -- the id -> name table.

Every random value is written as the tuple ``distribution id, mean, sd, relative
min, relative max`` with ``min = mean - relative min`` and ``max = mean + relative
max`` (ids: 1 none, 2 normal, 3 uniform, 4 triangular, 5 beta, 6 exponential, 7
lognormal, 8 gamma). Convention (:func:`distribution`): a value with an SD is a
normal (2) truncated at 3 SD each side -- Rocscience's note that bounds 3 SD from
the mean give a complete normal -- clipped so that the minimum is >= 0 for
non-negative quantities, friction <= 90 deg, and the restitution maximum is <= 1
where RocFall's range applies (below); a value without an SD is ``1, mean, 0, 0,
0``. fieldkit draws ``N(mean, sd)`` clipped at 0 and has no upper bound: where a
bound cuts closer than 3 SD, the README states the mean of RocFall's truncated draws.

**Within RocFall's ranges, under RocFall's law.** Rocscience documents Rn and Rt in
[0, 1] (RocFall help "Coefficient of Restitution" and FAQ) and advises SDs whose
draws cannot exceed 1 (support article "How can I determine Rt?"). RocFall's "scale
Rn by velocity" is ``Rn / (1 + (v/K)^2)`` with K = 9.144 m/s (30 ft/s, thesis
§7.3.4). A calibrated model is written as it is when its law is RocFall's (no
rebound law but velocity scaling at that K, every coefficient in [0, 1]); otherwise
(a velocity-scaled e_n above 1, another K, an angle law, the statistical
alternative) each material's Rn, Rt are the values in [0, 1] whose rebounds under
RocFall's law are closest to the calibrated model's simulated impacts
(:func:`fieldkit.export.lumped.fit_coefficients`), and the README gives the
translation error: the calibrated model against fieldkit's reading of the files
written (:mod:`fieldkit.export.rocfall_import`, the exact round trip) simulated on
the same section (:func:`fieldkit.export.translation.translation_error`). Every
written value is checked against :data:`RANGES` before anything is returned.

Sources: Rocscience RocFall help pages "Coefficient of Restitution", "Analysis
Method" (friction options, ``Phi = arctan((1 - Rt)/Rt)``, consider rotational
velocity), "Engine Conditions" (stopped velocity cutoff), "Slope Overview" (segments
>= 0.001 length units, vertices left to right), FAQs (scale Rn by mass), RocFall3
"Random Variables" (distribution, SD, min/max, mean); Rocscience support "How can I
determine Rt?"; RocPlane "Normal Distribution" (3 SD bounds); the thesis ch. 7
(eq. 7.1, §7.3.6, Table 7-1). The on-disk syntax of RocFall's own files is not
public; the blocks follow the fields of its dialogs.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np
from scipy.stats import norm, truncnorm

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
from fieldkit.export.rocfall_keys import DISTRIBUTIONS, ROCK_KEYS
from fieldkit.export.site import ExportSite
from fieldkit.export.translation import translation_error
from fieldkit.model.effects import registry
from fieldkit.model.model_file import Model, model_from_dict, model_to_dict
from fieldkit.outputs import csv_text, json_text

#: Truncation of a normal each side of the mean, in SDs (the stated convention).
TRUNCATION_SD = 3.0
#: RocFall's documented upper bound on Rn and Rt (Rocscience help, FAQ).
RESTITUTION_MAX = 1.0
#: Upper bound written for friction-angle draws [deg].
FRICTION_MAX_DEG = 90.0
#: RocFall's shortest slope segment (help "Slope Overview"), in metres here.
MIN_SEGMENT_M = 0.001
#: RocFall's velocity scale of Rn, "scale Rn by velocity" [m/s] (30 ft/s).
ROCFALL_K_MPS = 9.144
_HELP = "Rocscience RocFall help"
#: The documented range of every numeric field written (checked on every export).
RANGES: dict[str, DocumentedRange] = {
    "rn": DocumentedRange(
        "Rn (mean, min, max)",
        0.0,
        RESTITUTION_MAX,
        f"{_HELP} 'Coefficient of Restitution': all real materials between 0 and 1; "
        "FAQs: coefficients of restitution range from 0 to 1",
    ),
    "rt": DocumentedRange(
        "Rt (mean, min, max)",
        0.0,
        RESTITUTION_MAX,
        f"{_HELP} 'Coefficient of Restitution'; FAQs",
    ),
    "friction angle": DocumentedRange(
        "friction angle (mean, min, max) [deg]",
        0.0,
        FRICTION_MAX_DEG,
        f"{_HELP} 'Analysis Method': Phi = arctan((1 - Rt)/Rt) lies in [0, 90] deg "
        "for Rt in [0, 1]",
    ),
    "slope roughness sd": DocumentedRange(
        "slope roughness sd [deg]",
        0.0,
        FRICTION_MAX_DEG,
        "an SD of the segment dip (thesis §7.3.6, Table 7-1); at most 90 deg here",
    ),
    "segment": DocumentedRange(
        "slope segment length [m]",
        MIN_SEGMENT_M,
        math.inf,
        f"{_HELP} 'Slope Overview': segments of at least 0.001 length units",
    ),
    "mass": DocumentedRange(
        "mass (mean, min) [kg]",
        0.0,
        math.inf,
        "a mass (RocFall FAQ: the lumped mass only gives energies)",
        open_lo=True,
    ),
    "k": DocumentedRange(
        "scale rn velocity k [m/s]",
        ROCFALL_K_MPS,
        ROCFALL_K_MPS,
        "RocFall's K = 30 ft/s (thesis §7.3.4, eq. 7.1; fieldkit's "
        "velocity_scaled_restitution default)",
    ),
    "cutoff": DocumentedRange(
        "stopped velocity cutoff [m/s]",
        0.0,
        math.inf,
        f"{_HELP} 'Engine Conditions': the velocity below which a rock has stopped",
        open_lo=True,
    ),
}
#: Where RocFall's rules in this export come from (README "Sources").
SOURCES = (
    "Rocscience RocFall help 'Coefficient of Restitution' "
    "(rocscience.com/help/rocfall/documentation/slope/materials/"
    "coefficient-of-restitution): Rn, Rt definitions, range 0 to 1",
    "Rocscience RocFall help 'FAQs' (rocscience.com/help/rocfall/overview/faqs): "
    "coefficients of restitution range from 0 to 1; scale Rn by mass",
    "Rocscience RocFall help 'Analysis Method' (rocscience.com/help/rocfall/"
    "documentation/project-settings/general-settings/analysis-method): lumped mass, "
    "friction angle options, Phi = arctan((1 - Rt)/Rt), consider rotational velocity",
    "Rocscience RocFall help 'Engine Conditions' (rocscience.com/help/rocfall/"
    "documentation/project-settings/engine-conditions): stopped velocity cutoff, "
    "maximum steps per rock",
    "Rocscience RocFall help 'Slope Overview': segments >= 0.001 length units, "
    "vertices left to right",
    "Rocscience RocFall3 help 'Random Variables': distribution, SD, relative min "
    "and max; RocPlane help 'Normal Distribution': 3 SD bounds",
    "Rocscience support article 'How can I determine Rt?': SDs whose draws cannot "
    "exceed 1",
    "RocNews Fall 2003 'Determining Input Parameters for a RocFall Analysis' "
    "(lists coefficient of normal restitution scaling among RocFall's inputs)",
    "Thesis ch. 7: eq. 7.1 and §7.3.4 (scale Rn by velocity, K = 9.144 m/s = "
    "30 ft/s), §7.3.6 and Table 7-1 (slope roughness as the SD of the dip)",
)
#: What the sources leave open (README "Unconfirmed").
UNCONFIRMED = (
    "RocFall's on-disk project syntax (.fal, .rf3): the blocks follow its dialogs",
    "whether RocFall lets the user change K of 'scale Rn by velocity' (9.144 m/s is "
    "written; the help pages read give no K field), and whether its v is the normal "
    "impact speed (as eq. 7.1 and fieldkit) or the full impact speed",
    "when RocFall redraws the slope roughness (per rock or per impact)",
    "how RocFall's lumped-mass 'consider rotational velocity' changes Rt",
)
FILES = (
    "materials.txt",
    "rock_type.txt",
    "project_settings.txt",
    "slope.csv",
    "material_ids.csv",
)
_HEADER = (
    "# Every random value: distribution id, mean, sd, relative min, relative max\n"
    "#   min = mean - relative min, max = mean + relative max\n"
    "#   ids: 1 none, 2 normal, 3 uniform, 4 triangular, 5 beta, 6 exponential,"
    " 7 lognormal, 8 gamma\n"
)


@dataclass(frozen=True)
class Distribution:
    """A RocFall random value: ``(kind, mean, sd, rel_min, rel_max)``.

    Examples
    --------
    >>> d = Distribution(2, 0.75, 0.04, 0.12, 0.12)
    >>> d.text(), round(d.minimum, 2), round(d.maximum, 2)
    ('2, 0.75, 0.04, 0.12, 0.12', 0.63, 0.87)
    """

    kind: int
    mean: float
    sd: float
    rel_min: float
    rel_max: float

    @property
    def minimum(self) -> float:
        """``mean - relative min``."""
        return self.mean - self.rel_min

    @property
    def maximum(self) -> float:
        """``mean + relative max``."""
        return self.mean + self.rel_max

    def text(self) -> str:
        """The tuple as written: ``id, mean, sd, relative min, relative max``."""
        values = (self.mean, self.sd, self.rel_min, self.rel_max)
        return ", ".join([str(self.kind), *(number(v) for v in values)])


def number(value: float) -> str:
    """A number as written (15 significant digits: decimal inputs round-trip).

    Examples
    --------
    >>> number(3 * 0.04), number(350.0), number(-4)
    ('0.12', '350', '-4')
    """
    return f"{float(value):.15g}"


def distribution(
    mean: float,
    sd: float,
    *,
    lower: float | None = None,
    upper: float | None = None,
) -> Distribution:
    """The tuple of a value with SD ``sd`` under the stated convention.

    Normal (id 2) with relative min and max of :data:`TRUNCATION_SD` SDs, cut so the
    minimum is >= ``lower`` and the maximum <= ``upper`` (None: no bound); with
    ``sd = 0``: ``1, mean, 0, 0, 0``.

    Examples
    --------
    >>> distribution(2.86, 1.5, lower=0.0).text()   # min clipped to 0
    '2, 2.86, 1.5, 2.86, 4.5'
    >>> distribution(1.0, 0.04, lower=0.0, upper=1.0).text()   # max clipped to 1
    '2, 1, 0.04, 0.12, 0'
    >>> distribution(3.007, 0.0).text()
    '1, 3.007, 0, 0, 0'
    """
    if sd <= 0.0:
        return Distribution(1, mean, 0.0, 0.0, 0.0)
    rel_min = rel_max = TRUNCATION_SD * sd
    if lower is not None:
        rel_min = min(rel_min, max(mean - lower, 0.0))
    if upper is not None:
        rel_max = min(rel_max, max(upper - mean, 0.0))
    return Distribution(2, mean, sd, rel_min, rel_max)


def truncated_mean(d: Distribution) -> float:
    """Mean of a normal :class:`Distribution`'s draws between its min and max.

    Examples
    --------
    >>> round(truncated_mean(Distribution(2, 1.0, 0.04, 0.12, 0.0)), 4)
    0.9684
    """
    if d.kind != 2 or d.sd <= 0.0:
        return d.mean
    a, b = -d.rel_min / d.sd, d.rel_max / d.sd
    if not a < b:  # no width left between the bounds
        return d.mean
    return float(truncnorm.mean(a, b, loc=d.mean, scale=d.sd))


def clipped_mean(mean: float, sd: float) -> float:
    """Mean of fieldkit's draws ``max(0, N(mean, sd))``.

    Examples
    --------
    >>> round(clipped_mean(2.86, 1.5), 4)
    2.8763
    """
    if sd <= 0.0:
        return max(mean, 0.0)
    z = mean / sd
    return float(mean * norm.cdf(z) + sd * norm.pdf(z))


def _cut(d: Distribution) -> bool:
    """True where a bound cuts closer than :data:`TRUNCATION_SD` SDs."""
    full = TRUNCATION_SD * d.sd
    return d.kind == 2 and (d.rel_min < full - 1e-12 or d.rel_max < full - 1e-12)


def velocity_k_mps(model: Model) -> float | None:
    """RocFall's ``scale rn velocity k`` [m/s], or None when scaling is off."""
    params = model.effects.get("velocity_scaled_restitution")
    if params is None or not math.isfinite(params["k_mps"]):
        return None
    return float(params["k_mps"])


def check_rocfall(model: Model) -> None:
    """Refuse a profile RocFall cannot take.

    Raises
    ------
    ArgumentError
        A slope segment shorter than RocFall's 0.001 length units.
    """
    lengths = np.hypot(np.diff(model.profile.x_m), np.diff(model.profile.z_m))
    short = np.flatnonzero(lengths < MIN_SEGMENT_M)
    if short.size:
        j = int(short[0])
        raise ArgumentError(
            f"profile segment {j} is {lengths[j]:.3g} m long; RocFall needs slope "
            f"segments of at least {MIN_SEGMENT_M:g} m",
            source="model",
        )


def rocfall_law(model: Model) -> tuple[bool, list[str]]:
    """Whether RocFall's velocity scaling is on for ``model``, and why the model's
    law cannot be written in RocFall's terms as it is (empty: it can).

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 10], "z_m": [5, 0],
    ...   "material": "rock"}, "materials": {"rock": {"e_n": 1.2, "e_t": 0.8,
    ...   "friction_deg": 25}}, "effects": {"velocity_scaled_restitution":
    ...   {"k_mps": 13.2}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 6}})
    >>> scaled, why = rocfall_law(m)
    >>> scaled, len(why)
    (True, 2)
    """
    k = velocity_k_mps(model)
    reasons = []
    if k is not None and not math.isclose(k, ROCFALL_K_MPS, rel_tol=1e-9):
        reasons.append(
            f"velocity_scaled_restitution.k_mps = {k:.4g} m/s, but RocFall scales "
            f"Rn with K = {ROCFALL_K_MPS:g} m/s"
        )
    for law in foreign_normal_laws(model, "RocFall"):
        reasons.append(f"{law}: RocFall's lumped mass has no such law")
    for name, m in model.materials.items():
        for field, key in (("e_n", "Rn"), ("e_t", "Rt")):
            value = getattr(m, field)
            if not 0.0 <= value <= RESTITUTION_MAX:
                reasons.append(
                    f"materials.{name}.{field} = {value:.4g} is outside RocFall's "
                    f"{key} range [0, 1]"
                )
    return k is not None, reasons


def normal_factor(v_mps: np.ndarray) -> np.ndarray:
    """RocFall's scaling of Rn at normal impact speeds ``v``: ``1 / (1 + (v/K)^2)``,
    K = :data:`ROCFALL_K_MPS`."""
    return 1.0 / (1.0 + (np.asarray(v_mps, float) / ROCFALL_K_MPS) ** 2)


def rocfall_model(model: Model) -> Written:
    """The model as RocFall is given it, from which the files are written.

    ``Written.model`` is ``model`` with RocFall's law (velocity scaling at
    :data:`ROCFALL_K_MPS` when the model scales, no other rebound law) and the
    written Rn, Rt: as calibrated when the law is RocFall's (:func:`rocfall_law`),
    else the in-range values whose emulation behaves closest to the calibrated
    model, searched from the impact-level least-squares values
    (:func:`fieldkit.export.lumped.closest_behaviour`), each rounded to the 15
    significant digits the file holds. Cached per model (the search simulates).
    """
    return _rocfall_model(json_text(model_to_dict(model)))


@lru_cache(maxsize=8)
def _rocfall_model(text: str) -> Written:
    model = model_from_dict(json.loads(text))
    scaled, reasons = rocfall_law(model)
    effects = {
        name: params
        for name, params in model.effects.items()
        if not registry.effect(name).changes_normal_rebound
    }
    if scaled:
        effects["velocity_scaled_restitution"] = {"k_mps": ROCFALL_K_MPS}
    if not reasons:
        return Written(replace(model, effects=effects), {}, [], [], None)
    factor = normal_factor if scaled else np.ones_like
    ranges = ((0.0, RESTITUTION_MAX), (0.0, RESTITUTION_MAX))
    coefficients, loud = fit_coefficients(
        model,
        "RocFall",
        factor,
        *ranges,
        fit_rt="rotation_friction" not in model.effects,
    )

    def emulate(values: dict[str, tuple[Coefficient, Coefficient]]) -> Model:
        return replace(with_coefficients(model, values), effects=effects)

    coefficients, search = closest_behaviour(
        model,
        coefficients,
        emulate,
        factor,
        *ranges,
        precision=lambda v: float(number(v)),
    )
    # the value RocFall is given is the value in the file (15 significant digits)
    coefficients = {
        name: tuple(replace(c, written=float(number(c.written))) for c in pair)
        for name, pair in coefficients.items()
    }
    return Written(emulate(coefficients), coefficients, reasons, loud, search)


def material_distributions(model: Model) -> dict[str, dict[str, Distribution]]:
    """Per material: ``{"rn": ..., "rt": ..., "friction angle": ...}`` tuples."""
    out = {}
    for name, m in model.materials.items():
        out[name] = {
            "rn": distribution(m.e_n, m.e_n_sd, lower=0.0, upper=RESTITUTION_MAX),
            "rt": distribution(m.e_t, m.e_t_sd, lower=0.0, upper=RESTITUTION_MAX),
            "friction angle": distribution(
                m.friction_deg, m.friction_deg_sd, lower=0.0, upper=FRICTION_MAX_DEG
            ),
        }
    return out


def roughness_sd_deg(model: Model) -> dict[str, float]:
    """RocFall's slope roughness per material: the SD of the dip [deg].

    With ``slope_roughness`` on, fieldkit's dip SD ``scale * hypot(atan(s/r),
    roughness_deg_sd)`` (eq. 7.4 with the body radius r) is folded into one number;
    off: 0 (fieldkit then perturbs no dip).
    """
    params = model.effects.get("slope_roughness")
    if params is None:
        return {name: 0.0 for name in model.materials}
    r = model.body.radius_m
    return {
        name: float(
            params["scale"]
            * math.hypot(math.degrees(math.atan(m.roughness_m / r)), m.roughness_deg_sd)
        )
        for name, m in model.materials.items()
    }


def material_ids(model: Model) -> dict[str, int]:
    """Material name -> RocFall material id (1, 2, ... in the model's order)."""
    return {name: i + 1 for i, name in enumerate(model.materials)}


def materials_text(model: Model) -> str:
    """``materials.txt``: one block per material."""
    dists = material_distributions(model)
    rough = roughness_sd_deg(model)
    lines = [
        "# RocFall slope materials (lumped mass), from fieldkit",
        _HEADER.rstrip("\n"),
        f"# Convention: normal truncated at {TRUNCATION_SD:g} sd each side, min >= 0,"
        f" Rn and Rt max <= 1, friction max <= {FRICTION_MAX_DEG:g} deg",
        "# slope roughness sd: standard deviation of the segment dip [deg]",
    ]
    for name, i in material_ids(model).items():
        d = dists[name]
        lines += [
            "",
            f"material {i}: {name}",
            f"rn: {d['rn'].text()}",
            f"rt: {d['rt'].text()}",
            f"friction angle (deg): {d['friction angle'].text()}",
            f"slope roughness sd (deg): {number(rough[name])}",
        ]
    return "\n".join(lines) + "\n"


def rock_type_text(model: Model) -> str:
    """``rock_type.txt``: the rock type (mass) and its seeder."""
    s, body = model.seeder, model.body
    values = {
        "mass": distribution(body.mass_kg, s.mass_sd_kg, lower=0.0),
        "initial horizontal velocity": distribution(s.vx_mps, s.vx_sd_mps),
        "initial vertical velocity": distribution(s.vz_mps, s.vz_sd_mps),
        "initial rotational velocity": distribution(s.omega_radps, s.omega_sd_radps),
    }
    lines = [
        "# RocFall rock type and seeder (lumped mass), from fieldkit",
        _HEADER.rstrip("\n"),
        "# seeder y = elevation; velocities: x toward the slope's run-out, y up",
        "",
        "rock type 1: fieldkit body",
    ]
    for key, (_, _, unit) in ROCK_KEYS.items():
        lines.append(f"{key} ({unit}): {values[key].text()}")
    if s.x_max_m is None:
        lines += [
            "seeder: point",
            f"seeder x (m): {number(s.x_m)}",
            f"seeder y (m): {number(s.z_m)}",
        ]
    else:
        lines += [
            "seeder: line",
            f"seeder x (m): {number(s.x_m)}",
            f"seeder x end (m): {number(s.x_max_m)}",
            f"seeder height (m): {number(s.height_m)}",
        ]
    return "\n".join(lines) + "\n"


def settings_text(model: Model) -> str:
    """``project_settings.txt``: analysis method, units, scaling, rotation, cutoff."""
    k = velocity_k_mps(model)
    lines = [
        "# RocFall project settings (lumped mass), from fieldkit",
        "analysis method: lumped mass",
        "units: metric",
        f"scale rn by velocity: {'on' if k is not None else 'off'}",
    ]
    if k is not None:
        lines.append(f"scale rn velocity k (m/s): {number(k)}")
    lines += [
        "scale rn by mass: off",
        "consider rotational velocity: "
        + ("on" if "rotation_friction" in model.effects else "off"),
        "friction angle: use material friction angle",
        f"stopped velocity cutoff (m/s): {number(model.core['stop_speed_mps'])}",
    ]
    return "\n".join(lines) + "\n"


def slope_csv(model: Model) -> str:
    """``slope.csv``: ``x_m,y_m,material_id`` (of the segment to the next vertex)."""
    ids = material_ids(model)
    p = model.profile
    rows = [["x_m", "y_m", "material_id"]]
    for j, (x, z) in enumerate(zip(p.x_m, p.z_m, strict=True)):
        mat = str(ids[p.material[j]]) if j < p.segments else ""
        rows.append([number(x), number(z), mat])
    return csv_text(rows)


def material_ids_csv(model: Model) -> str:
    """``material_ids.csv``: ``id,name``."""
    rows = [["id", "name"]] + [[i, name] for name, i in material_ids(model).items()]
    return csv_text(rows)


def export_rocfall(model: Model, site: ExportSite | None = None) -> Export:
    """The model as RocFall (lumped mass) input blocks (module docstring).

    Parameters
    ----------
    model
        The calibrated model.
    site
        Ignored: RocFall is a 2-D section program; the model's profile is the slope.

    Raises
    ------
    ArgumentError
        A profile RocFall does not accept (:func:`check_rocfall`).
    """
    del site
    check_rocfall(model)
    written, coefficients, reasons, loud, search = rocfall_model(model)
    files = {
        "materials.txt": materials_text(written),
        "rock_type.txt": rock_type_text(written),
        "project_settings.txt": settings_text(written),
        "slope.csv": slope_csv(written),
        "material_ids.csv": material_ids_csv(written),
    }
    check_written(written)
    mapped, mismatches = _mapped_materials(model, written, coefficients)
    mapped += _mapped_rest(model, written)
    unmapped = _unmapped(model)
    mismatches = [
        *loud,
        *fit_lines(reasons, coefficients, "RocFall", "[0, 1]", "g"),
        *search_line(search, "RocFall"),
        *mismatches,
    ]
    mismatches += _mismatches_rest(model)
    emulated = emulation(files, model)
    return Export(
        target="rocfall",
        title="RocFall (Rocscience), lumped mass",
        files=files,
        mapped=mapped,
        unmapped=unmapped,
        units=[
            "metric throughout: set RocFall's project units to metric (m, kg, m/s)",
            "x = fieldkit chainage x_m [m], y = fieldkit elevation z_m [m]",
            "angles in degrees (friction angle, slope roughness SD), as in fieldkit",
            "scale rn velocity k in m/s (RocFall's K = 9.144 m/s = 30 ft/s)",
            "rotational velocity in rad/s",
        ],
        mismatches=mismatches,
        notes=_notes() + effects_account(model, "RocFall", EFFECT_RULES),
        how_to_use=_HOW_TO_USE,
        translation=_translation_lines(model, emulated),
        sources=list(SOURCES),
        unconfirmed=list(UNCONFIRMED),
    )


def emulation(files: dict[str, str], model: Model) -> Model:
    """fieldkit's model of RocFall's law with the values written: the files read
    back (:func:`fieldkit.export.rocfall_import.model_from_rocfall`, exact), with
    the calibrated body's radius (a lumped mass has none)."""
    from fieldkit.export.rocfall_import import Text, model_from_rocfall

    emulated, _ = model_from_rocfall(
        Text(files["materials.txt"], "materials.txt"),
        Text(files["slope.csv"], "slope.csv"),
        Text(files["rock_type.txt"], "rock_type.txt"),
        settings=Text(files["project_settings.txt"], "project_settings.txt"),
        radius_m=model.body.radius_m,
    )
    return emulated


def _translation_lines(model: Model, emulated: Model) -> list[str]:
    lines = translation_error(model, emulated).lines()
    return [
        *lines,
        "",
        "The emulation is fieldkit reading the files back (the exact round trip): "
        "RocFall's law as fieldkit's velocity_scaled_restitution at K = 9.144 m/s "
        "(or a constant pair), the written Rn, Rt and their SDs, the slope "
        "roughness as a dip SD; it differs from RocFall in what fieldkit cannot "
        "reproduce: RocFall truncates its draws at min/max (fieldkit clips at 0 "
        "only), RocFall's own rotation, sliding and stopping rules.",
    ]


def check_written(written: Model) -> None:
    """Every numeric field written against :data:`RANGES`.

    Raises
    ------
    fieldkit.export.lumped.WrittenOutOfRange
        A value outside its documented range (an exporter bug).
    """
    for name, dists in material_distributions(written).items():
        for key, d in dists.items():
            for value in (d.mean, d.minimum, d.maximum):
                RANGES[key].check(value, f"material {name}")
    for name, value in roughness_sd_deg(written).items():
        RANGES["slope roughness sd"].check(value, f"material {name}")
    p = written.profile
    for j, length in enumerate(np.hypot(np.diff(p.x_m), np.diff(p.z_m))):
        RANGES["segment"].check(float(length), f"slope segment {j}")
    mass = distribution(written.body.mass_kg, written.seeder.mass_sd_kg, lower=0.0)
    RANGES["mass"].check(mass.mean, "rock type 1")
    k = velocity_k_mps(written)
    if k is not None:
        RANGES["k"].check(k, "project settings")
    RANGES["cutoff"].check(written.core["stop_speed_mps"], "project settings")


_HOW_TO_USE = """\
1. New RocFall project: Project Settings as in `project_settings.txt` (lumped mass,
   metric units, scale Rn by velocity with K, consider rotational velocity, friction
   angle from the materials, stopped velocity cutoff).
2. Slope: the vertices of `slope.csv` (x, y in metres, left to right).
3. Materials: one per block of `materials.txt` (names and ids in
   `material_ids.csv`); each tuple is (distribution id, mean, sd, relative min,
   relative max): enter min = mean - relative min and max = mean + relative max
   where RocFall asks for bounds. Assign segment by segment: row j of `slope.csv`
   gives the material id of the segment from vertex j to vertex j + 1.
4. Seeder and rock type: `rock_type.txt` (point or line seeder, mass, initial
   velocities).
`fieldkit` reads these files back (`fieldkit.export.rocfall_import.read_rocfall`)."""


def _mapped_materials(
    model: Model,
    written: Model,
    coefficients: dict[str, tuple[Coefficient, Coefficient]],
) -> tuple[list[Mapped], list[str]]:
    dists = material_distributions(written)
    rough = roughness_sd_deg(written)
    ids = material_ids(written)
    mapped, mismatches = [], []
    fields = (
        ("rn", "e_n", ""),
        ("rt", "e_t", ""),
        ("friction angle", "friction_deg", "deg"),
    )
    for name, m in model.materials.items():
        fitted = dict(zip(("e_n", "e_t"), coefficients.get(name, ()), strict=False))
        for key, field, unit in fields:
            d = dists[name][key]
            sd_field = f"{field}_sd"
            calibrated = getattr(m, field)
            text = with_error(model, f"materials.{name}.{field}", calibrated, unit)
            how = f"{DISTRIBUTIONS[d.kind]}, min {d.minimum:.4g}, max {d.maximum:.4g}"
            if field in fitted:
                how = (
                    f"written {fitted[field].text()}, fitted under RocFall's law; "
                    + how
                )
            mapped.append(
                Mapped(
                    f"{text}; {sd_field} = {getattr(m, sd_field):g}",
                    f"material {ids[name]} ({name}): {key} = ({d.text()})",
                    how,
                )
            )
            if _cut(d):
                mismatches.append(
                    f"{name} {key}: RocFall draws N({d.mean:g}, {d.sd:g}) truncated "
                    f"to [{d.minimum:.4g}, {d.maximum:.4g}], mean "
                    f"{truncated_mean(d):.4g}; fieldkit draws max(0, N) without an "
                    f"upper bound, mean {clipped_mean(d.mean, d.sd):.4g}"
                )
        mapped.append(
            Mapped(
                with_error(
                    model,
                    f"materials.{name}.roughness_deg_sd",
                    m.roughness_deg_sd,
                    "deg",
                )
                + f"; roughness_m = {m.roughness_m:g} m",
                f"material {ids[name]} ({name}): slope roughness sd = "
                f"{rough[name]:.6g} deg",
                "scale * hypot(atan(roughness_m / radius_m), roughness_deg_sd) with "
                "slope_roughness on, 0 off",
            )
        )
        if "slope_roughness" in model.effects and (
            m.roughness_m > 0.0 or model.effects["slope_roughness"]["scale"] != 1.0
        ):
            mismatches.append(
                f"{name} slope roughness: fieldkit's size-dependent roughness "
                f"(roughness_m = {m.roughness_m:g} m, eq. 7.4) and scale folded into "
                f"one dip SD {rough[name]:.4g} deg for radius "
                f"{model.body.radius_m:g} m; other block sizes would feel it "
                "differently in fieldkit"
            )
    return mapped, mismatches


def _mapped_rest(model: Model, written: Model) -> list[Mapped]:
    s, k, k_written = model.seeder, velocity_k_mps(model), velocity_k_mps(written)
    out = [
        Mapped(
            with_error(model, "body.mass_kg", model.body.mass_kg, "kg")
            + f"; seeder.mass_sd_kg = {s.mass_sd_kg:g}",
            "rock type 1: mass (kg)",
            "lumped mass: the mass only gives energies",
        ),
        Mapped(
            with_error(model, "seeder.vx_mps", s.vx_mps, "m/s")
            + f"; vx_sd_mps = {s.vx_sd_mps:g}",
            "rock type 1: initial horizontal velocity (m/s)",
        ),
        Mapped(
            with_error(model, "seeder.vz_mps", s.vz_mps, "m/s")
            + f"; vz_sd_mps = {s.vz_sd_mps:g}",
            "rock type 1: initial vertical velocity (m/s)",
        ),
        Mapped(
            with_error(model, "seeder.omega_radps", s.omega_radps, "rad/s")
            + f"; omega_sd_radps = {s.omega_sd_radps:g}",
            "rock type 1: initial rotational velocity (rad/s)",
            "sign convention of RocFall's rotation not confirmed",
        ),
        Mapped(
            "seeder "
            + (
                f"x_m = {s.x_m:g}, z_m = {s.z_m:g}"
                if s.x_max_m is None
                else f"x_m = {s.x_m:g} .. x_max_m = {s.x_max_m:g}, height_m = "
                f"{s.height_m:g}"
            ),
            "point seeder (x, y)" if s.x_max_m is None else "line seeder",
        ),
        Mapped(
            f"profile: {model.profile.x_m.size} vertices, materials per segment",
            "slope.csv (x, y, material id of the segment to the next vertex)",
        ),
        Mapped(
            with_error(model, "velocity_scaled_restitution.k_mps", k, "m/s")
            if k is not None
            else (
                "velocity_scaled_restitution.k_mps = inf (no scaling)"
                if "velocity_scaled_restitution" in model.effects
                else "velocity_scaled_restitution off"
            ),
            f"scale rn by velocity: on, k = {k_written:g} m/s"
            if k_written is not None
            else "scale rn by velocity: off",
            "vfn = Rn vin / (1 + (vin/K)^2), thesis eq. 7.1, with RocFall's K",
        ),
        Mapped(
            "rotation_friction "
            + ("on" if "rotation_friction" in model.effects else "off"),
            "consider rotational velocity: "
            + ("on" if "rotation_friction" in model.effects else "off"),
        ),
        Mapped(
            f"core.stop_speed_mps = {model.core['stop_speed_mps']:g} m/s",
            "stopped velocity cutoff (m/s)",
            "fieldkit: a sliding rock slower than this at a concave break stops",
        ),
    ]
    return out


#: How RocFall takes every effect of the registry (README "Notes"): the effects'
#: metadata (:attr:`fieldkit.model.effects.spec.EffectSpec.exports`).
EFFECT_RULES: dict[str, tuple[bool, str]] = export_rules("RocFall")


def _unmapped(model: Model) -> list[tuple[str, str]]:
    out = []
    for name, params in model.effects.items():
        if name in EFFECT_RULES and EFFECT_RULES[name][0]:
            continue
        why = (
            EFFECT_RULES.get(name, (False, ""))[1]
            or not_a_law(name, "RocFall")
            or no_rule(name, "RocFall")
        )
        if why:
            values = ", ".join(f"{k} = {v:g}" for k, v in params.items())
            out.append((f"{name} ({values})", why))
    rf = model.effects.get("rotation_friction")
    if rf is not None:
        out.append(
            (
                f"rotation_friction.friction = {rf['friction']:g}, coupling = "
                f"{rf['coupling']:g}",
                "RocFall's 'consider rotational velocity' has no parameters; its "
                "rotation model is its own (Rt is then no longer the plain velocity "
                "ratio, RocFall help 'Coefficient of Restitution')",
            )
        )
    s = model.seeder
    for field, value in (("x_sd_m", s.x_sd_m), ("z_sd_m", s.z_sd_m)):
        if value > 0.0 and not (field == "z_sd_m" and s.x_max_m is not None):
            out.append(
                (
                    f"seeder.{field} = {value:g} m",
                    "a RocFall seeder has a fixed location; spread rocks with a line "
                    "seeder instead",
                )
            )
    if s.x_max_m is not None and s.z_sd_m > 0.0:
        out.append(
            (
                f"seeder.z_sd_m = {s.z_sd_m:g} m",
                "the release height of a line seeder is fixed in RocFall",
            )
        )
    out.append(
        (
            f"core.slide_vn_mps = {model.core['slide_vn_mps']:g} m/s",
            "RocFall decides when a bouncing rock starts sliding by its own rule",
        )
    )
    out.append(
        (
            f"core.max_impacts = {model.core['max_impacts']:g}",
            "RocFall caps steps (events) per rock, not impacts: set 'maximum steps "
            "per rock' above it",
        )
    )
    if "air_drag" in model.effects:
        out.append((f"core.drag_dt_s = {model.core['drag_dt_s']:g} s", "no air drag"))
    if model.trees is not None and "tree_impacts" not in model.effects:
        out.append(("trees", "not exported (tree_impacts is off, RocFall has none)"))
    return out


def _mismatches_rest(model: Model) -> list[str]:
    out = []
    if "rotation_friction" in model.effects:
        out.append(
            "consider rotational velocity: RocFall's lumped-mass rotation replaces "
            "fieldkit's rotation_friction impulse (eqs. 4.20-4.22); trajectories "
            "with spin will differ"
        )
    return out


def _notes() -> list[str]:
    return [
        "RocFall's own project files (.fal, .rf3) are proprietary: these blocks "
        "follow the fields of RocFall's dialogs (material editor, rock type and "
        "seeder, project settings), not its on-disk syntax.",
        f"Distribution convention (fieldkit's, stated): normal truncated at "
        f"{TRUNCATION_SD:g} SD each side (Rocscience: bounds 3 SD from the mean give "
        "a complete normal), clipped so min >= 0, Rn and Rt max <= 1, friction max "
        "<= 90 deg; no SD -> (1, mean, 0, 0, 0).",
        "Documented ranges, checked on every value written: "
        + "; ".join(r.text() for r in RANGES.values())
        + ".",
        "Velocity scaling: vfn = Rn vin / (1 + (vin/K)^2) (thesis eq. 7.1) with "
        f"RocFall's K = {ROCFALL_K_MPS:g} m/s, as fieldkit's "
        "velocity_scaled_restitution.",
        "Slope roughness: RocFall's roughness is the SD of the segment dip (thesis "
        "§7.3.6, Table 7-1); fieldkit draws the dip perturbation at each impact.",
        "Friction: RocFall's lumped mass can take the friction angle from the "
        "material, from Rt (Phi = arctan((1 - Rt)/Rt)) or zero (help 'Analysis "
        "Method'); the export sets 'use material friction angle'.",
    ]
