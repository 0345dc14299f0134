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

**Restitution above 1.** Rocscience documents Rn and Rt in [0, 1] (RocFall help
"Coefficient of Restitution" and FAQ) and advises choosing SDs so that drawn values
cannot exceed 1 (support article "How can I determine Rt?") -- advice, which implies
RocFall itself does not stop draws above 1; the thesis ran RocFall 4.0 with Rn =
1.00 +- 0.04 (Table 7-1). Rule here: Rt <= 1 always and Rn <= 1 without velocity
scaling (else :class:`~fieldkit.errors.ArgumentError`); with ``scale rn by
velocity`` on (``velocity_scaled_restitution``), Rn above 1 is written as calibrated
-- the scaled Rn ``Rn / (1 + (v/K)^2)`` is below 1 for normal impact speeds above
``K sqrt(Rn - 1)`` -- with its draws not cut at 1, and the README says so. Whether
RocFall's material dialog accepts a *mean* above 1 could not be confirmed.

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

import math
from dataclasses import dataclass

import numpy as np
from scipy.stats import norm, truncnorm

from fieldkit.errors import ArgumentError
from fieldkit.export.fitted import with_error
from fieldkit.export.lumped import not_a_law
from fieldkit.export.result import Export, Mapped
from fieldkit.export.site import ExportSite
from fieldkit.model.model_file import Model
from fieldkit.outputs import csv_text

#: RocFall distribution ids (the issue's list; RocFall3 help "Random Variables").
DISTRIBUTIONS: dict[int, str] = {
    1: "none",
    2: "normal",
    3: "uniform",
    4: "triangular",
    5: "beta",
    6: "exponential",
    7: "lognormal",
    8: "gamma",
}
#: Truncation of a normal each side of the mean, in SDs (the stated convention).
TRUNCATION_SD = 3.0
#: RocFall's documented upper bound on Rn and Rt (Rocscience help, FAQ).
RESTITUTION_MAX = 1.0
#: Upper bound written for friction-angle draws [deg].
FRICTION_MAX_DEG = 90.0
#: RocFall's shortest slope segment (help "Slope Overview"), in metres here.
MIN_SEGMENT_M = 0.001
#: Material keys -> (fieldkit field, unit written in the key).
MATERIAL_KEYS: dict[str, tuple[str, str]] = {
    "rn": ("e_n", ""),
    "rt": ("e_t", ""),
    "friction angle": ("friction_deg", "deg"),
    "slope roughness sd": ("roughness_deg_sd", "deg"),
}
#: Rock-type keys -> (fieldkit seeder/body field, SD field, unit).
ROCK_KEYS: dict[str, tuple[str, str, str]] = {
    "mass": ("mass_kg", "mass_sd_kg", "kg"),
    "initial horizontal velocity": ("vx_mps", "vx_sd_mps", "m/s"),
    "initial vertical velocity": ("vz_mps", "vz_sd_mps", "m/s"),
    "initial rotational velocity": ("omega_radps", "omega_sd_radps", "rad/s"),
}
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
    """Refuse values RocFall does not accept (module docstring: the rule).

    Raises
    ------
    ArgumentError
        Rt above 1; Rn above 1 without velocity scaling; a slope segment shorter
        than RocFall's 0.001 length units.
    """
    scaled = velocity_k_mps(model) is not None
    for name, m in model.materials.items():
        if m.e_t > RESTITUTION_MAX:
            raise ArgumentError(
                f"material {name}: e_t = {m.e_t:g} is outside RocFall's Rt range "
                f"[0, {RESTITUTION_MAX:g}] (Rocscience: coefficients of restitution "
                "range from 0 to 1)",
                source="model",
            )
        if m.e_n > RESTITUTION_MAX and not scaled:
            raise ArgumentError(
                f"material {name}: e_n = {m.e_n:g} is outside RocFall's Rn range "
                f"[0, {RESTITUTION_MAX:g}]; Rn above 1 is exported only with "
                "velocity scaling on (velocity_scaled_restitution), where RocFall "
                "scales it by 1/(1 + (v/K)^2)",
                source="model",
            )
    lengths = np.hypot(np.diff(model.profile.x_m), np.diff(model.profile.z_m))
    short = np.flatnonzero(lengths < MIN_SEGMENT_M)
    if short.size:
        j = int(short[0])
        raise ArgumentError(
            f"profile segment {j} is {lengths[j]:.3g} m long; RocFall needs slope "
            f"segments of at least {MIN_SEGMENT_M:g} m",
            source="model",
        )


def material_distributions(model: Model) -> dict[str, dict[str, Distribution]]:
    """Per material: ``{"rn": ..., "rt": ..., "friction angle": ...}`` tuples."""
    scaled = velocity_k_mps(model) is not None
    out = {}
    for name, m in model.materials.items():
        out[name] = {
            "rn": distribution(
                m.e_n, m.e_n_sd, lower=0.0, upper=None if scaled else RESTITUTION_MAX
            ),
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
        f" Rt max <= 1, Rn max <= 1 unless velocity scaling is on,"
        f" friction max <= {FRICTION_MAX_DEG:g} deg",
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
        Values RocFall does not accept (:func:`check_rocfall`).
    """
    del site
    check_rocfall(model)
    files = {
        "materials.txt": materials_text(model),
        "rock_type.txt": rock_type_text(model),
        "project_settings.txt": settings_text(model),
        "slope.csv": slope_csv(model),
        "material_ids.csv": material_ids_csv(model),
    }
    mapped, mismatches = _mapped_materials(model)
    mapped += _mapped_rest(model)
    unmapped = _unmapped(model)
    mismatches += _mismatches_rest(model)
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
            "scale rn velocity k in m/s (RocFall's default 9.144 m/s = 30 ft/s)",
            "rotational velocity in rad/s",
        ],
        mismatches=mismatches,
        notes=_notes(),
        how_to_use=_HOW_TO_USE,
    )


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


def _mapped_materials(model: Model) -> tuple[list[Mapped], list[str]]:
    dists = material_distributions(model)
    rough = roughness_sd_deg(model)
    ids = material_ids(model)
    k = velocity_k_mps(model)
    mapped, mismatches = [], []
    fields = (
        ("rn", "e_n", ""),
        ("rt", "e_t", ""),
        ("friction angle", "friction_deg", "deg"),
    )
    for name, m in model.materials.items():
        for key, field, unit in fields:
            d = dists[name][key]
            sd_field = f"{field}_sd"
            text = with_error(model, f"materials.{name}.{field}", d.mean, unit)
            mapped.append(
                Mapped(
                    f"{text}; {sd_field} = {d.sd:g}",
                    f"material {ids[name]} ({name}): {key} = ({d.text()})",
                    f"{DISTRIBUTIONS[d.kind]}, min {d.minimum:.4g}, max "
                    f"{d.maximum:.4g}",
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
        if m.e_n > RESTITUTION_MAX and k is not None:
            mismatches.append(
                f"{name} rn = {m.e_n:g} > 1, written as calibrated: with scale rn by "
                f"velocity (K = {k:g} m/s) the scaled Rn is below 1 for normal impact "
                f"speeds above K sqrt(Rn - 1) = {k * math.sqrt(m.e_n - 1.0):.3g} m/s. "
                "Rocscience documents Rn in [0, 1]; whether RocFall's material "
                "dialog accepts a mean above 1 is not confirmed"
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


def _mapped_rest(model: Model) -> list[Mapped]:
    s, k = model.seeder, velocity_k_mps(model)
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
            f"scale rn by velocity: on, k = {k:g} m/s"
            if k is not None
            else "scale rn by velocity: off",
            "vfn = Rn vin / (1 + (vin/K)^2), thesis eq. 7.1",
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


#: Effects RocFall (lumped mass) cannot represent -> why.
_NO_EFFECT = {
    "angle_dependent_restitution": "RocFall's lumped-mass Rn is scaled by velocity "
    "or by mass only; no impact-angle law for Rn was found in its documentation",
    "mass_loss": "RocFall's lumped-mass rock keeps its mass (no breakage or abrasion)",
    "tree_impacts": "RocFall's lumped mass has no trees (barriers only); the trees "
    "are not exported",
    "air_drag": "RocFall's lumped mass ignores air resistance",
}


def _unmapped(model: Model) -> list[tuple[str, str]]:
    out = []
    for name, params in model.effects.items():
        why = _NO_EFFECT.get(name) or not_a_law(name, "RocFall")
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
        "seeder, project settings), not its on-disk syntax, which could not be "
        "confirmed.",
        f"Distribution convention (fieldkit's, stated): normal truncated at "
        f"{TRUNCATION_SD:g} SD each side (Rocscience: bounds 3 SD from the mean give "
        "a complete normal), clipped so min >= 0, friction max <= 90 deg, Rt max <= 1 "
        "and Rn max <= 1 unless velocity scaling is on; no SD -> (1, mean, 0, 0, 0).",
        "Restitution range: Rocscience documents Rn, Rt in [0, 1] (help "
        "'Coefficient of Restitution', FAQ) and advises SDs that cannot draw above 1 "
        "(support 'How can I determine Rt?'); the thesis ran RocFall 4.0 with Rn = "
        "1.00 +- 0.04 (Table 7-1). fieldkit refuses Rt > 1, and Rn > 1 without "
        "velocity scaling.",
        "Velocity scaling: vfn = Rn vin / (1 + (vin/K)^2) (thesis eq. 7.1), as "
        "fieldkit's velocity_scaled_restitution.",
        "Slope roughness: RocFall's roughness is the SD of the segment dip (thesis "
        "§7.3.6, Table 7-1); fieldkit draws the dip perturbation at each impact. "
        "When RocFall redraws it (per rock or per impact) could not be confirmed.",
        "Friction: RocFall's lumped mass can take the friction angle from the "
        "material, from Rt (Phi = arctan((1 - Rt)/Rt)) or zero (help 'Analysis "
        "Method'); the export sets 'use material friction angle'.",
    ]
