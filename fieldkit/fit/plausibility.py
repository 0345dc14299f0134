"""Physical plausibility of a calibrated model: the restitution it *realises*.

A fitted ``e_n`` is a parameter of a law, not what the law does: with the velocity
scaling of eq. 7.1, ``v_fN = e_n |v_iN| / (1 + (v_iN/K)^2)``, a material ``e_n`` of
1.19 realises ``e_n > 1`` on every impact slower than ``K sqrt(e_n - 1)`` and drives
rocks towards a fixed normal speed -- a *regulator* of the bounce, not a description
of a material. This module measures it:

* :func:`simulated_restitution` -- the model's own simulated impacts (its own random
  stream, ``default_rng([seed, PLAUSIBILITY_STREAM])``), each impact's realised
  ``e_n = -v_fN / v_iN`` and ``e_t = v_fT / v_iT`` by the ImpactTable's own
  definitions (:func:`fieldkit.impact_table.restitution`) on the slope the kernel
  used (``slope_roughness`` tilts it: the realised coefficients are relative to
  the tilted slope, as the law is), per material: the impacts, the share with
  ``e_n > 1`` and with ``e_t > 1`` (each with its binomial standard error) and the
  medians;
* :func:`observed_restitution` -- the fitted law applied to an ImpactTable's
  measured impact velocities (the impact fit's own prediction,
  :func:`fieldkit.fit.impact_model.predict_impacts`), summarised the same way;
* :func:`producers` -- which parameters and effects make a material's realised
  coefficient exceed 1 (with the analytic threshold of eq. 7.1);
* :func:`bound_entries` -- fitted parameters at a search bound, with the bound.

:class:`Plausibility` gathers them for a fit's output (lines and the JSON key
``plausibility``). A material whose realised ``e_n`` exceeds 1 on more than
:data:`REGULATOR_SHARE` of its impacts is called "a regulator, not a restitution".

:func:`realised_share_above` is what a fit constrained to ``realised e_n <= c``
penalises (:func:`fieldkit.fit.path_fit.fit_paths` ``max_realised_e_n``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from fieldkit.fit.impact_fit import no_flight_rows
from fieldkit.fit.impact_model import predict_impacts
from fieldkit.impact_table import ImpactTable, restitution
from fieldkit.model.model_file import Model
from fieldkit.model.simulate import simulate

#: Share of a material's impacts with realised e_n > 1 above which the material is
#: reported as a regulator, not a restitution.
REGULATOR_SHARE = 0.05
#: Rocks simulated for the report (the impacts are many times more).
PLAUSIBILITY_ROCKS = 1_000
#: A path fit constrained to realised e_n <= c (``fit_paths(max_realised_e_n=c)``):
#: the share of a material's simulated impacts above c it tolerates (a Monte Carlo
#: share of thousands of impacts cannot be held at exactly 0 by a search without
#: the exact reformulation no law has once its e_n scatters), and the penalty per
#: unit share beyond it, in units of the objective at the start (1 % beyond costs
#: the whole start value).
REALISED_TOLERANCE = 0.01
REALISED_PENALTY = 100.0
#: Stream of the report's simulation: ``default_rng([seed, PLAUSIBILITY_STREAM])``,
#: apart from a path fit's calibration streams ``[seed, run]`` and its bootstrap's.
PLAUSIBILITY_STREAM = 6_007


@dataclass(frozen=True)
class RealisedRestitution:
    """The realised restitution of one material's impacts.

    Attributes
    ----------
    material
        The material.
    impacts
        Impacts with a defined ``e_n`` (an impact velocity into the ground).
    share_e_n_above_1, share_e_n_above_1_se
        Share of them with realised ``e_n > 1`` and its binomial standard error
        ``sqrt(p (1 - p) / n)``.
    median_e_n
        Median realised ``e_n``.
    share_e_t_above_1, share_e_t_above_1_se, median_e_t
        The same of ``e_t`` (over the impacts with a defined ``e_t``).
    producers
        What produces the values above 1 (:func:`producers`).
    """

    material: str
    impacts: int
    share_e_n_above_1: float
    share_e_n_above_1_se: float
    median_e_n: float
    share_e_t_above_1: float
    share_e_t_above_1_se: float
    median_e_t: float
    producers: list[str] = field(default_factory=list)
    #: With a constrained fit: the limit and the share of impacts above it.
    limit: float | None = None
    share_e_n_above_limit: float = math.nan

    @property
    def regulator(self) -> bool:
        """Realised ``e_n > 1`` on more than :data:`REGULATOR_SHARE` of impacts."""
        return self.share_e_n_above_1 > REGULATOR_SHARE

    def words(self, what: str) -> str:
        """One line on this material; ``what`` names the impacts ("simulated
        impacts", "observed impacts (the fitted law at their measured velocities)").
        """
        if self.impacts == 0:
            return f"{self.material}: no {what}"
        en = (
            f"realised e_n > 1 on {_pct(self.share_e_n_above_1)} (SE "
            f"{_pct(self.share_e_n_above_1_se)}) of {self.impacts:,} {what} (median "
            f"{self.median_e_n:.3f})"
        )
        et = (
            f"e_t > 1 on {_pct(self.share_e_t_above_1)} (median "
            f"{self.median_e_t:.3f})"
        )
        why = f"; from {'; '.join(self.producers)}" if self.producers else ""
        if self.regulator:
            return (
                f"{self.material}: a regulator, not a restitution: {en} -- it drives "
                "rocks to a fixed normal speed rather than describing a material; "
                f"{et}{why}"
            )
        return f"{self.material}: {en}; {et}{why}"

    def to_dict(self) -> dict:
        """JSON-ready (NaN as None)."""
        return {
            "material": self.material,
            "impacts": self.impacts,
            "share_e_n_above_1": _finite(self.share_e_n_above_1),
            "share_e_n_above_1_se": _finite(self.share_e_n_above_1_se),
            "median_e_n": _finite(self.median_e_n),
            "share_e_t_above_1": _finite(self.share_e_t_above_1),
            "share_e_t_above_1_se": _finite(self.share_e_t_above_1_se),
            "median_e_t": _finite(self.median_e_t),
            "regulator": self.regulator,
            "producers": list(self.producers),
            **(
                {} if self.limit is None
                else {"limit": self.limit,
                      "share_e_n_above_limit": _finite(self.share_e_n_above_limit)}
            ),  # fmt: skip
        }


def _pct(share: float) -> str:
    if not math.isfinite(share):
        return "n/a"
    return f"{100 * share:.1f} %" if share >= 0.001 or share == 0 else "<0.1 %"


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def realised_coefficients(
    columns: Mapping[str, np.ndarray],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(material_index, e_n, e_t)`` of the kernel's impact columns
    (:func:`fieldkit.model.simulate.impact_columns`) by the ImpactTable's own
    definitions, relative to the slope the kernel used (NaN where undefined)."""
    r = restitution(
        np.asarray(columns["vi_x_mps"], float),
        np.asarray(columns["vi_z_mps"], float),
        np.asarray(columns["vf_x_mps"], float),
        np.asarray(columns["vf_z_mps"], float),
        np.asarray(columns["slope_deg"], float),
    )
    e_n = np.where(r["vin_mps"] < 0.0, r["e_n"], np.nan)
    return np.asarray(columns["material_index"]).astype(np.int64), e_n, r["e_t"]


def realised_share_above(
    columns: Sequence[Mapping[str, np.ndarray]], n_materials: int, limit: float
) -> tuple[np.ndarray, np.ndarray]:
    """``(above, impacts)`` per material index: impacts whose realised ``e_n``
    exceeds ``limit``, and impacts with a defined ``e_n``."""
    above = np.zeros(n_materials, np.int64)
    total = np.zeros(n_materials, np.int64)
    for cols in columns:
        mi, e_n, _ = realised_coefficients(cols)
        ok = np.isfinite(e_n)
        total += np.bincount(mi[ok], minlength=n_materials)
        above += np.bincount(mi[ok & (e_n > limit)], minlength=n_materials)
    return above, total


def summarise(
    material: str,
    e_n: np.ndarray,
    e_t: np.ndarray,
    model: Model,
    limit: float | None = None,
    draws: bool = True,
) -> RealisedRestitution:
    """:class:`RealisedRestitution` of one material's realised coefficients (and,
    with ``limit``, the share of ``e_n`` above it)."""
    e_n = e_n[np.isfinite(e_n)]
    e_t = e_t[np.isfinite(e_t)]

    def share(x: np.ndarray) -> tuple[float, float, float]:
        if x.size == 0:
            return math.nan, math.nan, math.nan
        p = float(np.mean(x > 1.0))
        return p, math.sqrt(p * (1 - p) / x.size), float(np.median(x))

    pn, sen, men = share(e_n)
    pt, set_, met = share(e_t)
    why = producers(model, material, e_n=pn > 0, e_t=pt > 0, draws=draws)
    above = (
        float(np.mean(e_n > limit)) if limit is not None and e_n.size else math.nan
    )
    return RealisedRestitution(material, int(e_n.size), pn, sen, men, pt, set_, met,
                               why, limit, above)  # fmt: skip


def producers(
    model: Model, material: str, *, e_n: bool, e_t: bool, draws: bool = True
) -> list[str]:
    """What in ``model`` makes ``material``'s realised ``e_n`` (``e_t``) exceed 1,
    in words, for the coefficients that do (``e_n``, ``e_t`` True); ``draws``:
    the impacts carry the material's random scatter (simulated, not the law's
    mean at observed impacts).

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 50], "z_m": [30, 0],
    ...   "material": "c"}, "materials": {"c": {"e_n": 1.25, "e_t": 0.8,
    ...   "friction_deg": 25}}, "effects": {"velocity_scaled_restitution":
    ...   {"k_mps": 10.0}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 31}})
    >>> producers(m, "c", e_n=True, e_t=False)[1][-31:]
    '|v_N| < K sqrt(e_n - 1) = 5 m/s'
    """
    mat = model.materials[material]
    effects = model.effects
    out = []
    if e_n:
        if mat.e_n > 1.0:
            out.append(f"the material's e_n = {mat.e_n:.4g} > 1")
        if draws and mat.e_n_sd > 0:
            out.append(f"its e_n scatter (e_n_sd {mat.e_n_sd:.3g}) drawing above 1")
        if "velocity_scaled_restitution" in effects and mat.e_n > 1.0:
            k = float(effects["velocity_scaled_restitution"]["k_mps"])
            out.append(
                f"velocity_scaled_restitution (K = {k:.4g} m/s): e_n / (1 + (v_N/K)^2)"
                f" > 1 wherever |v_N| < K sqrt(e_n - 1) = "
                f"{k * math.sqrt(mat.e_n - 1.0):.3g} m/s"
            )
        if "angle_dependent_restitution" in effects:
            out.append("angle_dependent_restitution: e_n grows at shallow impacts")
        if "affine_rebound" in effects:
            b = float(effects["affine_rebound"].get("b_n_mps", 0.0))
            if b > 0:
                out.append(f"affine_rebound: b_n = {b:.3g} m/s added to slow rebounds")
    if e_t:
        if mat.e_t > 1.0:
            out.append(f"the material's e_t = {mat.e_t:.4g} > 1")
        if draws and mat.e_t_sd > 0:
            out.append(f"its e_t scatter (e_t_sd {mat.e_t_sd:.3g}) drawing above 1")
        if "rotation_friction" in effects:
            out.append("rotation_friction: spin turned into tangential speed")
        if "affine_rebound" in effects:
            b = float(effects["affine_rebound"].get("b_t_mps", 0.0))
            if b > 0:
                out.append(f"affine_rebound: b_t = {b:.3g} m/s added to slow rebounds")
    return out


def simulated_restitution(
    model: Model | Sequence[Model],
    rocks: int = PLAUSIBILITY_ROCKS,
    seed: int = 0,
    limit: float | None = None,
) -> list[RealisedRestitution]:
    """Realised ``e_n``, ``e_t`` of ``model``'s simulated impacts, per material
    (module docstring; materials without impacts are listed with 0 impacts; with
    ``limit``, also the share of ``e_n`` above it). Several models (a path fit's
    sections, with the same materials) share the rocks, section ``i`` drawn from
    ``default_rng([seed, PLAUSIBILITY_STREAM, i])``.

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 60, 120], "z_m": [60, 20, 0],
    ...   "material": "talus"}, "materials": {"talus": {"e_n": 0.4, "e_t": 0.8,
    ...   "friction_deg": 30}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 70}})
    >>> r = simulated_restitution(m, rocks=20)[0]
    >>> round(r.median_e_n, 9), r.share_e_n_above_1, r.regulator
    (0.4, 0.0, False)
    """
    sections = [model] if isinstance(model, Model) else list(model)
    names = list(sections[0].materials)
    parts = []
    each = max(math.ceil(rocks / len(sections)), 1)
    for i, section in enumerate(sections):
        chunks: list[dict[str, np.ndarray]] = []
        stream = [seed, PLAUSIBILITY_STREAM] + ([i] if len(sections) > 1 else [])
        simulate(
            section,
            each,
            np.random.default_rng(stream),
            record_impacts=True,
            on_impact_columns=chunks.append,
        )
        own = list(section.materials)
        for c in chunks:
            mi, e_n, e_t = realised_coefficients(c)
            index = np.array([names.index(n) for n in own], np.int64)
            parts.append((index[mi], e_n, e_t))
    mi = np.concatenate([p[0] for p in parts]) if parts else np.zeros(0, np.int64)
    e_n = np.concatenate([p[1] for p in parts]) if parts else np.zeros(0)
    e_t = np.concatenate([p[2] for p in parts]) if parts else np.zeros(0)
    return [
        summarise(name, e_n[mi == i], e_t[mi == i], sections[0], limit)
        for i, name in enumerate(names)
    ]


def observed_restitution(
    table: ImpactTable, model: Model, limit: float | None = None
) -> list[RealisedRestitution]:
    """The fitted law's ``e_n``, ``e_t`` at each observed impact of ``table``
    (its measured impact velocities; release and stop rows, which have no impact,
    left out), per material of the table."""
    keep = ~no_flight_rows(table)
    table = ImpactTable(
        table.frame.loc[keep].reset_index(drop=True), source=table.source
    ).derive()
    pred = predict_impacts(table, model)
    vin, vit = table.column("vin_mps"), table.column("vit_mps")
    with np.errstate(divide="ignore", invalid="ignore"):
        e_n = np.where(vin < 0, pred["vfn_mps"] / -vin, np.nan)
        e_t = np.where(np.abs(vit) > 1e-12, pred["vft_mps"] / vit, np.nan)
    labels = table.frame["material"].astype("string").to_numpy(str)
    return [
        summarise(m, e_n[labels == m], e_t[labels == m], model, limit, draws=False)
        for m in model.materials
        if np.any(labels == m)
    ]


def bound_entries(
    names: Sequence[str],
    values: Sequence[float],
    lower: Sequence[float],
    upper: Sequence[float],
    at_bound: Sequence[bool],
) -> list[dict]:
    """The fitted parameters at a bound: ``{name, value, bound ("lower" or
    "upper"), bound_value}`` each."""
    out = []
    for n, v, lo, hi, flag in zip(names, values, lower, upper, at_bound, strict=True):
        if flag:
            side = "lower" if abs(v - lo) <= abs(v - hi) else "upper"
            limit = float(lo if side == "lower" else hi)
            out.append({"name": n, "value": float(v), "bound": side,
                        "bound_value": limit})  # fmt: skip
    return out


@dataclass
class Plausibility:
    """A calibrated model's plausibility report (module docstring).

    Attributes
    ----------
    simulated
        Per material, the realised coefficients of its simulated impacts.
    rocks, seed
        The report's simulation (stream ``[seed, PLAUSIBILITY_STREAM]``).
    observed
        Per material of the table, the fitted law at the observed impacts (an
        impact fit; None for a path fit).
    bounds
        Fitted parameters at a search bound (:func:`bound_entries`).
    constraint
        What the fit was constrained to (None: unconstrained), with its outcome.
    """

    simulated: list[RealisedRestitution]
    rocks: int
    seed: int
    observed: list[RealisedRestitution] | None = None
    bounds: list[dict] = field(default_factory=list)
    constraint: dict | None = None

    def lines(self) -> list[str]:
        """The console lines, each starting ``plausibility:``."""
        head = (
            f"plausibility: realised restitution of the calibrated model's simulated "
            f"impacts ({self.rocks:,} rocks, seed {self.seed}, stream "
            f"{PLAUSIBILITY_STREAM}); a material with realised e_n > 1 on more "
            f"than {_pct(REGULATOR_SHARE)} of its impacts is a regulator"
        )
        out = [head]
        out += [f"plausibility: {r.words('simulated impacts')}" for r in self.simulated]
        for r in self.observed or []:
            words = r.words("observed impacts (the fitted law at their measured "
                            "impact velocities)")  # fmt: skip
            out.append(f"plausibility: {words}")
        for b in self.bounds:
            out.append(
                f"plausibility: {b['name']} = {b['value']:.4g} is at its "
                f"{b['bound']} bound {b['bound_value']:g}"
            )
        if self.constraint is not None:
            out.append(f"plausibility: {self.constraint['words']}")
        return out

    def markdown(self) -> str:
        """The report.md section ``## Physical plausibility``."""
        items = [line.removeprefix("plausibility: ") for line in self.lines()]
        return "\n".join(["", "## Physical plausibility", "", items[0], "",
                          *[f"* {x}" for x in items[1:]]]) + "\n"  # fmt: skip

    def to_dict(self) -> dict:
        """The JSON key ``plausibility``."""
        return {
            "regulator_share": REGULATOR_SHARE,
            "simulated": {
                "rocks": self.rocks,
                "seed": self.seed,
                "stream": [self.seed, PLAUSIBILITY_STREAM],
                "materials": [r.to_dict() for r in self.simulated],
            },
            "observed": (
                None if self.observed is None
                else {"materials": [r.to_dict() for r in self.observed]}
            ),  # fmt: skip
            "at_bound": list(self.bounds),
            "constraint": self.constraint,
        }


def impact_fit_plausibility(
    result,
    calibrated: Model,
    table: ImpactTable,
    *,
    max_realised_e_n: float | None = None,
    rocks: int = PLAUSIBILITY_ROCKS,
    seed: int = 0,
) -> Plausibility:
    """The :class:`Plausibility` of an impact fit (a
    :class:`~fieldkit.fit.fit_result.FitResult` and its calibrated model): the
    calibrated model's simulated impacts, the fitted law at ``table``'s observed
    impacts, the parameters at a bound and the constraint (its note)."""
    constraint = None
    if max_realised_e_n is not None:
        words = next(
            (n for n in result.notes if n.startswith("constrained to realised")),
            f"constrained to realised e_n <= {max_realised_e_n:g}",
        )
        constraint = {
            "max_realised_e_n": float(max_realised_e_n),
            "applies_to": "the fitted law at every observed impact",
            "method": "penalty residual per impact",
            "words": words,
        }
    return Plausibility(
        simulated=simulated_restitution(calibrated, rocks, seed, max_realised_e_n),
        rocks=rocks,
        seed=seed,
        observed=observed_restitution(table, calibrated, max_realised_e_n),
        bounds=bound_entries(result.names, result.values, result.lower,
                             result.upper, result.at_bound()),  # fmt: skip
        constraint=constraint,
    )


def path_fit_plausibility(
    result,
    runs: Sequence | None = None,
    *,
    rocks: int = PLAUSIBILITY_ROCKS,
    seed: int = 0,
) -> Plausibility:
    """The :class:`Plausibility` of a path fit (a
    :class:`~fieldkit.fit.path_fit.PathFitResult`): the calibrated model's
    simulated impacts -- on the sections of ``runs`` (the fitted values set on each
    run's model, the rocks shared among them), else on the model's own profile --,
    the parameters at a search bound and the constraint with the shares the fit
    measured on its own streams."""
    constraint = None
    limit = result.max_realised_e_n
    fitted = dict(zip(result.names, map(float, result.values), strict=True))
    models = (
        [r.model.with_parameters({k: v for k, v in fitted.items()
                                  if k in r.model.parameters()}) for r in runs]
        if runs else result.model
    )  # fmt: skip
    simulated = simulated_restitution(models, rocks, seed, limit)
    if limit is not None:
        above = [
            f"{r.material} {_pct(r.share_e_n_above_limit)}"
            for r in simulated
            if r.impacts and r.share_e_n_above_limit > REALISED_TOLERANCE
        ]
        constraint = {
            "max_realised_e_n": float(limit),
            "tolerance": REALISED_TOLERANCE,
            "applies_to": "the worst material's share of the simulated impacts",
            "method": f"penalty {REALISED_PENALTY:g} x the objective at the start "
            "x the share beyond the tolerance",
            "share_start": _finite(result.realised_share_start),
            "share_optimum": _finite(result.realised_share_optimum),
            "words": (
                f"fit constrained to realised e_n <= {limit:g}: the worst "
                f"material's share of simulated impacts above it "
                f"{_pct(result.realised_share_start)} at the start, "
                f"{_pct(result.realised_share_optimum)} at the optimum (tolerance "
                f"{100 * REALISED_TOLERANCE:g} %, the fit's own rocks)"
                + (
                    f"; beyond the tolerance on this report's rocks: "
                    f"{', '.join(above)}" if above
                    else "; within it on this report's rocks too"
                )
            ),  # fmt: skip
        }
    return Plausibility(
        simulated=simulated,
        rocks=rocks,
        seed=seed,
        bounds=bound_entries(result.names, result.values, result.lower,
                             result.upper, result.at_bound()),  # fmt: skip
        constraint=constraint,
    )
