"""The constant e_n, e_t a model's impact laws realise, for targets without the laws.

Some simulators take one restitution pair per material and nothing else (r.stone,
Rockyfor3D's soil types): a calibrated model whose e_n is scaled by the impact
velocity (eq. 7.1), depends on the impact angle (eq. 5.4) or couples rotation into
the tangential rebound cannot be written as it is -- the velocity-scaled
colluvium e_n of Tornado Mountain is above 1, which such a target refuses, though
the rebounds it produces are not. :func:`lumped_equivalent` writes instead the
constant pair a least-squares fit of fieldkit's own base model would give on the
calibrated model's simulated impacts of each material,

.. math:: e_n = \\frac{\\sum v_{fN} |v_{iN}|}{\\sum v_{iN}^2}, \\qquad
          e_t = \\frac{\\sum v_{fT} v_{iT}}{\\sum v_{iT}^2},

(the unweighted ``fieldkit fit`` of a constant-e_n, e_t model), and says so.

The same machinery serves targets with a law of their own (RocFall's and CRSP's
velocity scaling of Rn): :func:`fit_coefficients` fits each material's Rn, Rt
under the target's law within its documented range
(:func:`fieldkit.export.translation.fit_scaled`), :func:`closest_behaviour`
searches from there for the values whose emulation behaves closest to the
calibrated model, written only when they also do so on an independent stream.
A written value carries its own spread over the impacts, never the calibrated
parameter's standard error (:func:`with_coefficients`). A material no simulated
rock touched is not written with its raw value: its own calibrated law is
evaluated at the normal speeds of all simulated impacts (when it depends on the
normal speed only; else the value is clipped to the range), and a line says so
loudly. :class:`DocumentedRange` checks every value an exporter writes.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from fieldkit.export.translation import (
    IMPACT_ROCKS,
    IMPACT_SEED,
    SEARCH_ROCKS,
    SEARCH_SEED,
    Search,
    behaviour_gap,
    closest_in_range,
    fit_scaled,
    realised_impacts,
    translation_error,
)
from fieldkit.model.effects import registry
from fieldkit.model.model_file import Model

#: Impact-stage effects that change the restitution pair of an impact (effect
#: metadata, :attr:`~fieldkit.model.effects.spec.EffectSpec.changes_rebound`).
RESTITUTION_LAWS = tuple(s.name for s in registry.EFFECTS if s.changes_rebound)


def export_rules(target: str) -> dict[str, tuple[bool, str]]:
    """Effect -> (mapped, how or why) for ``target``, from the effects' metadata
    (:attr:`~fieldkit.model.effects.spec.EffectSpec.exports`; an effect without an
    entry, the statistical alternative, is said by :func:`not_a_law`).

    Examples
    --------
    >>> export_rules("CRSP")["velocity_scaled_restitution"][0]
    True
    """
    return {
        spec.name: (rule.mapped, rule.how)
        for spec in registry.EFFECTS
        if (rule := spec.export(target)) is not None
    }


def foreign_normal_laws(model: Model, target: str) -> list[str]:
    """The active effects that change the normal rebound and that ``target`` does
    not take (effect metadata): the target's own normal law replaces them.

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 10], "z_m": [5, 0],
    ...   "material": "rock"}, "materials": {"rock": {"e_n": 0.3, "e_t": 0.8,
    ...   "friction_deg": 25}}, "effects": {"angle_dependent_restitution": {},
    ...   "velocity_scaled_restitution": {}, "rotation_friction": {}}, "body":
    ...   {"mass_kg": 100, "radius_m": 0.2}, "seeder": {"x_m": 1, "z_m": 6}})
    >>> foreign_normal_laws(m, "CRSP")
    ['angle_dependent_restitution']
    """
    out = []
    for spec in registry.EFFECTS:
        rule = spec.export(target)
        if spec.name in model.effects and spec.changes_normal_rebound:
            if rule is None or not rule.mapped:
                out.append(spec.name)
    return out


def not_a_law(name: str, target: str) -> str:
    """Why ``target`` cannot take effect ``name`` when the effect is the diagnosis's
    statistical alternative (:attr:`EffectSpec.kind <fieldkit.model.effects.spec.
    EffectSpec.kind>` ``"alternative"``); ``""`` for a physical law.

    Examples
    --------
    >>> not_a_law("affine_rebound", "CRSP")[:40]
    'affine_rebound is a statistical alternat'
    >>> not_a_law("air_drag", "CRSP")
    ''
    """
    return _not_a_law(registry.effect(name), target)


def _not_a_law(spec: registry.EffectSpec, target: str) -> str:
    if spec.is_law:
        return ""
    return (
        f"{spec.name} is a statistical alternative ({spec.physics}), not a physical "
        f"law: {target} has no such law; a model that needs it is not described "
        "by any law a target program has"
    )


#: Rocks simulated, and the seed, for the realised pair (the impacts of
#: :func:`fieldkit.export.translation.realised_impacts`).
ROCKS, SEED = IMPACT_ROCKS, IMPACT_SEED


@dataclass(frozen=True)
class Coefficient:
    """One written restitution coefficient of a material and where it came from.

    Attributes
    ----------
    name
        The model parameter, e.g. ``"materials.colluvium.e_n"``.
    calibrated
        The calibrated model's value (its own law).
    written
        The value written for the target (within ``range``).
    spread
        The impacts' own weighted SD of ``v_f / (f v_i)`` around ``written``
        (:func:`~fieldkit.export.translation.fit_scaled`); NaN when not fitted.
    n
        Impacts the value was fitted to (0: not fitted to impacts of its own).
    unfitted
        Why the value is not a fit to the material's own impacts ("" when it is).
    unclipped
        The least-squares value before the range clipped it (NaN: not fitted).
    clipped
        Whether the target's range moved the fitted value (rounding to the
        target's precision does not count).
    impact_level
        The impact-level value the behaviour search (:func:`closest_behaviour`)
        started from (NaN: no search; ``written`` is the impact-level value).
    """

    name: str
    calibrated: float
    written: float
    spread: float
    n: int
    unfitted: str = ""
    unclipped: float = math.nan
    clipped: bool = False
    impact_level: float = math.nan

    def text(self) -> str:
        """``written (spread s over n impacts)`` for a README's target column."""
        if self.n and math.isfinite(self.spread):
            searched = (
                f"; behaviour search from the impact-level {self.impact_level:.4g}"
                if math.isfinite(self.impact_level)
                else ""
            )
            return (
                f"{self.written:.4g} (spread {self.spread:.2g} of the {self.n} "
                f"impacts' own rebound ratio around it{searched})"
            )
        return f"{self.written:.4g} ({self.unfitted})"


def calibrated_normal_factor(model: Model, vin_abs: np.ndarray) -> np.ndarray | None:
    """The calibrated model's normal rebound per unit e_n at normal impact speeds
    ``vin_abs``: ``1 / (1 + (v/K)^2)`` with ``velocity_scaled_restitution``, 1
    without; None when another active law changes the normal rebound (its value
    depends on more than the normal speed)."""
    others = [
        name
        for name in model.effects
        if registry.effect(name).changes_normal_rebound
        and name != "velocity_scaled_restitution"
    ]
    if others:
        return None
    params = model.effects.get("velocity_scaled_restitution")
    if params is None or not math.isfinite(params["k_mps"]):
        return np.ones_like(vin_abs)
    return 1.0 / (1.0 + (vin_abs / params["k_mps"]) ** 2)


def fit_coefficients(
    model: Model,
    target: str,
    normal_factor: Callable[[np.ndarray], np.ndarray],
    rn_range: tuple[float, float],
    rt_range: tuple[float, float],
    *,
    fit_rt: bool = True,
    rocks: int = ROCKS,
    seed: int = SEED,
) -> tuple[dict[str, tuple[Coefficient, Coefficient]], list[str]]:
    """Per material the (Rn, Rt) in the target's ranges whose rebounds under the
    target's law ``v_fN = Rn f(|v_iN|) |v_iN|``, ``v_fT = Rt v_iT`` are closest (least
    squares) to the calibrated model's simulated impacts on that material.

    Parameters
    ----------
    model
        The calibrated model.
    target
        The target's name, for the lines.
    normal_factor
        The target's scaling ``f`` of the normal rebound at normal impact speeds
        (``lambda v: np.ones_like(v)`` for a constant pair).
    rn_range, rt_range
        The target's documented ranges ``[lo, hi]``.
    fit_rt
        False: Rt is the calibrated e_t clipped to ``rt_range`` (the target's own
        rotation replaces the calibrated tangential law).
    rocks, seed
        The simulation of :func:`~fieldkit.export.translation.realised_impacts`.

    Returns
    -------
    coefficients, lines
        ``{material: (Rn, Rt)}`` and one line per material that no simulated rock
        touched (for the export's mismatches; said loudly: its values are not fitted
        to impacts of its own).

    Notes
    -----
    A material without impacts of its own: Rn is fitted to the material's own
    calibrated law evaluated at the normal speeds of every simulated impact (on
    any material), when that law depends on the normal speed only; otherwise, and
    when no rock struck anything, the calibrated value is clipped to the range.
    """
    impacts = realised_impacts(model, rocks, seed)
    vin_all = -impacts["vin_mps"].to_numpy(float)
    out: dict[str, tuple[Coefficient, Coefficient]] = {}
    lines: list[str] = []
    lo_n, hi_n = rn_range
    lo_t, hi_t = rt_range
    for name, material in model.materials.items():
        rows = impacts[impacts["material"] == name]
        key = f"materials.{name}"
        vin = -rows["vin_mps"].to_numpy(float)
        if len(rows) >= 2:
            rn = _coefficient(
                f"{key}.e_n",
                material.e_n,
                fit_scaled(
                    vin, rows["vfn_mps"].to_numpy(float), normal_factor(vin), lo_n, hi_n
                ),
            )
            if fit_rt:
                rt = _coefficient(
                    f"{key}.e_t",
                    material.e_t,
                    fit_scaled(
                        rows["vit_mps"].to_numpy(float),
                        rows["vft_mps"].to_numpy(float),
                        1.0,
                        lo_t,
                        hi_t,
                    ),
                )
            else:
                rt = _clipped(
                    f"{key}.e_t",
                    material.e_t,
                    rt_range,
                    f"calibrated e_t; {target}'s own rotation replaces "
                    "the calibrated tangential law",
                )
            out[name] = (rn, rt)
            continue
        own = calibrated_normal_factor(model, vin_all)
        if own is not None and vin_all.size >= 2:
            fit = fit_scaled(
                vin_all,
                material.e_n * own * vin_all,
                normal_factor(vin_all),
                lo_n,
                hi_n,
            )
            why = (
                f"NO SIMULATED IMPACT on {name} ({rocks} rocks, seed {seed}): fitted "
                f"to its own calibrated law at the normal speeds of all {fit.n} "
                "simulated impacts on the other materials"
            )
            rn = Coefficient(
                f"{key}.e_n",
                material.e_n,
                fit.value,
                math.nan,
                0,
                why,
                fit.unclipped,
                fit.clipped,
            )
        else:
            because = (
                "no simulated rock struck anything"
                if vin_all.size < 2
                else "its calibrated law depends on more than the normal speed"
            )
            why = (
                f"NO SIMULATED IMPACT on {name} ({rocks} rocks, seed {seed}) and "
                f"{because}: the calibrated e_n clipped to {target}'s range"
            )
            rn = _clipped(f"{key}.e_n", material.e_n, rn_range, why)
        rt = _clipped(
            f"{key}.e_t",
            material.e_t,
            rt_range,
            f"NO SIMULATED IMPACT on {name}: the calibrated e_t clipped to "
            f"{target}'s range",
        )
        out[name] = (rn, rt)
        lines.append(
            f"{name}: NO SIMULATED IMPACT on it ({rocks} rocks, seed {seed}), so its "
            f"values are not fitted to rebounds of its own: Rn {rn.written:.4g} "
            f"({rn.unfitted}), Rt {rt.written:.4g} (the calibrated e_t "
            f"{material.e_t:.4g} clipped to [{lo_t:g}, {hi_t:g}]). Nothing in this "
            f"export tests them: check {name} in {target} before relying on it"
        )
    return out, lines


#: The held-out behaviour gap a search must cut, as a fraction of the impact-level
#: values' gap, for its values to be written (else the impact-level values are).
MIN_GAIN = 0.2


@dataclass(frozen=True)
class Behaviour:
    """A behaviour search and its check on an independent random stream.

    Attributes
    ----------
    search
        :func:`fieldkit.export.translation.closest_in_range`'s outcome.
    held_out_start, held_out_found
        :func:`fieldkit.export.translation.behaviour_gap` of the impact-level and
        of the searched values on the translation error's own stream.
    accepted
        Whether the searched values are written (the held-out gap fell by at
        least :data:`MIN_GAIN` of the impact-level one).
    searched
        The coefficients searched, e.g. ``["materials.talus.e_n"]``.
    """

    search: Search
    held_out_start: float
    held_out_found: float
    accepted: bool
    searched: tuple[str, ...]


def closest_behaviour(
    model: Model,
    coefficients: dict[str, tuple[Coefficient, Coefficient]],
    emulate: Callable[[dict[str, tuple[Coefficient, Coefficient]]], Model],
    normal_factor: Callable[[np.ndarray], np.ndarray],
    rn_range: tuple[float, float],
    rt_range: tuple[float, float],
    precision: Callable[[float], float],
    *,
    search_rt: bool = True,
    rocks: int = ROCKS,
    seed: int = SEED,
) -> tuple[dict[str, tuple[Coefficient, Coefficient]], Behaviour | None]:
    """The in-range Rn, Rt whose emulation behaves closest to ``model`` (None
    for the search when no coefficient was fitted to impacts of its own).

    The impact-level values of :func:`fit_coefficients` are the start of
    :func:`fieldkit.export.translation.closest_in_range` over every coefficient
    fitted to impacts of its own (a material no rock touched keeps its value;
    Rt only with ``search_rt``): the least-squares pair is dominated by the many
    slow impacts, while runout and design energies are set by the fast ones. The
    values found are written only if they also behave closer on the translation
    error's independent stream, by at least :data:`MIN_GAIN` (a search over
    quantities the values hardly move fits noise and wanders off); then each is
    rounded to what the target's file holds (``precision``) and carries its own
    spread over the material's impacts at that value.

    Parameters
    ----------
    emulate
        coefficients -> fieldkit's model of the target's law with them.
    normal_factor, rn_range, rt_range
        As for :func:`fit_coefficients`.
    precision
        A value -> the value as the target's file holds it.
    search_rt
        False: Rt keeps its impact-level value (the target's tangential law is
        not what fieldkit emulates, so behaviour cannot inform it).
    """
    names = [
        (name, i)
        for name, pair in coefficients.items()
        for i in ((0, 1) if search_rt else (0,))
        if pair[i].n > 0
    ]
    ranges = (rn_range, rt_range)
    if not names:  # no material was struck: nothing to search
        return coefficients, None

    def with_values(values) -> dict[str, tuple[Coefficient, Coefficient]]:
        out = {name: list(pair) for name, pair in coefficients.items()}
        for (name, i), value in zip(names, values, strict=True):
            out[name][i] = replace(out[name][i], written=precision(float(value)))
        return {name: (pair[0], pair[1]) for name, pair in out.items()}

    search = closest_in_range(
        model,
        lambda values: emulate(with_values(values)),
        [coefficients[name][i].written for name, i in names],
        [ranges[i][0] for _, i in names],
        [ranges[i][1] for _, i in names],
    )
    start_gap = behaviour_gap(translation_error(model, emulate(coefficients)))
    found_gap = behaviour_gap(
        translation_error(model, emulate(with_values(search.values)))
    )
    accepted = found_gap <= (1.0 - MIN_GAIN) * start_gap
    record = Behaviour(
        search,
        start_gap,
        found_gap,
        accepted,
        tuple(coefficients[name][i].name for name, i in names),
    )
    if not accepted:
        return coefficients, record
    impacts = realised_impacts(model, rocks, seed)
    out = {name: list(pair) for name, pair in coefficients.items()}
    for (name, i), value in zip(names, search.values, strict=True):
        rows = impacts[impacts["material"] == name]
        if i == 0:
            vi = -rows["vin_mps"].to_numpy(float)
            vf, factor = rows["vfn_mps"].to_numpy(float), normal_factor(vi)
        else:
            vi, vf = rows["vit_mps"].to_numpy(float), rows["vft_mps"].to_numpy(float)
            factor = np.ones_like(vi)
        written = precision(value)
        x = factor * vi
        spread = math.sqrt(float(np.sum((vf - written * x) ** 2) / np.sum(x * x)))
        c = out[name][i]
        out[name][i] = replace(
            c, written=written, spread=spread, impact_level=c.written
        )
    return {name: (pair[0], pair[1]) for name, pair in out.items()}, record


def _coefficient(name: str, calibrated: float, fit) -> Coefficient:
    return Coefficient(
        name, calibrated, fit.value, fit.spread, fit.n, "", fit.unclipped, fit.clipped
    )


def _clipped(
    name: str, value: float, bounds: tuple[float, float], why: str
) -> Coefficient:
    lo, hi = bounds
    written = float(min(max(value, lo), hi))
    return Coefficient(name, value, written, math.nan, 0, why, value, written != value)


def with_coefficients(
    model: Model, coefficients: dict[str, tuple[Coefficient, Coefficient]]
) -> Model:
    """``model`` with each material's e_n, e_t the written values, and the
    provenance entry ``lumped`` that says so (so that
    :func:`fieldkit.export.fitted.with_error` shows a written value with its own
    spread, never with the calibrated parameter's standard error)."""
    materials = dict(model.materials)
    record = {}
    for name, (rn, rt) in coefficients.items():
        materials[name] = replace(materials[name], e_n=rn.written, e_t=rt.written)
        for c in (rn, rt):
            record[c.name] = {
                "value": c.written,
                "spread": c.spread if math.isfinite(c.spread) else None,
                "impacts": c.n,
                "calibrated": c.calibrated,
                "unfitted": c.unfitted,
            }
    provenance = dict(model.provenance) if isinstance(model.provenance, dict) else {}
    provenance["lumped"] = record
    return replace(model, materials=materials, provenance=provenance)


def lumped_equivalent(
    model: Model,
    target: str,
    laws: Iterable[str] = RESTITUTION_LAWS,
    *,
    rocks: int = ROCKS,
    seed: int = SEED,
) -> tuple[Model, list[str]]:
    """``model`` without the active ``laws``, each material's e_n, e_t replaced by
    the constant pair its simulated impacts realise (module docstring).

    Returns
    -------
    model, lines
        The lumped model (``model`` itself when no law is active) and one line per
        material for the export's mismatches. The lumped model's provenance
        ``lumped`` records each written value with its own spread
        (:func:`with_coefficients`).

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 60, 120], "z_m": [60, 20, 0],
    ...   "material": "talus"}, "materials": {"talus": {"e_n": 1.2, "e_t": 0.8,
    ...   "friction_deg": 30}}, "effects": {"velocity_scaled_restitution":
    ...   {"k_mps": 9.144}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 70}})
    >>> lumped, lines = lumped_equivalent(m, "r.stone", rocks=50)
    >>> sorted(lumped.effects), lumped.materials["talus"].e_n < 1.0
    ([], True)
    """
    active = [law for law in laws if law in model.effects]
    if not active:
        return model, []
    coefficients, loud = fit_coefficients(
        model,
        target,
        np.ones_like,
        (0.0, math.inf),
        (0.0, math.inf),
        rocks=rocks,
        seed=seed,
    )
    alternatives = "".join(
        f"; {w}" for w in (not_a_law(a, target) for a in active) if w
    )
    lines = list(loud)
    for name, material in model.materials.items():
        rn, rt = coefficients[name]
        if not rn.n:
            continue
        lines.append(
            f"{name}: {target} has no {', '.join(active)}: e_n {material.e_n:.4g}, "
            f"e_t {material.e_t:.4g} with them are written as the constant pair "
            f"they realise, e_n {rn.written:.3f} (spread {rn.spread:.2g}), e_t "
            f"{rt.written:.3f} (spread {rt.spread:.2g}) (least squares over the "
            f"{rn.n} impacts on {name} of {rocks} simulated rocks, seed "
            f"{seed}); the target's rebounds no longer vary with impact speed or "
            "angle as the calibrated ones do" + alternatives
        )
    lumped = with_coefficients(model, coefficients)
    effects = {k: v for k, v in model.effects.items() if k not in active}
    return replace(lumped, effects=effects), lines


class WrittenOutOfRange(RuntimeError):
    """A value an exporter was about to write lies outside the target's documented
    range: a bug in the exporter (the in-range fit or a conversion), never bad
    input, so it is not a :class:`~fieldkit.errors.FieldkitError`."""


@dataclass(frozen=True)
class DocumentedRange:
    """A target field's range ``[lo, hi]`` (``open_lo``: ``lo`` excluded) and the
    document it comes from."""

    field: str
    lo: float
    hi: float
    source: str
    open_lo: bool = False

    def text(self) -> str:
        """``field: [lo, hi] (source)`` for a README."""
        left = "(" if self.open_lo else "["
        hi = "inf" if math.isinf(self.hi) else f"{self.hi:g}"
        return f"{self.field}: {left}{self.lo:g}, {hi}] ({self.source})"

    def check(self, value: float, where: str) -> None:
        """Raise :class:`WrittenOutOfRange` unless ``value`` lies in the range.

        Examples
        --------
        >>> DocumentedRange("Rn", 0.0, 1.0, "doc").check(1.2, "clay")
        Traceback (most recent call last):
        ...
        fieldkit.export.lumped.WrittenOutOfRange: clay: Rn = 1.2 outside [0, 1] (doc)
        """
        low_ok = value > self.lo if self.open_lo else value >= self.lo
        if not (math.isfinite(value) and low_ok and value <= self.hi):
            raise WrittenOutOfRange(
                f"{where}: {self.field} = {value:g} outside "
                + self.text().split(": ", 1)[1]
            )


def no_rule(name: str, target: str) -> str:
    """Why an effect without a rule in ``target``'s exporter is not written: said,
    never left out (an effect added to the registry after the exporter)."""
    return (
        f"NOT MAPPED: the {target} export has no rule for {name} (an effect newer "
        "than the exporter); the files are written without it"
    )


def effects_account(
    model: Model, target: str, rules: dict[str, tuple[bool, str]]
) -> list[str]:
    """One line per effect of the registry (on or off in ``model``): mapped to what,
    or not mapped and why. ``rules``: effect -> (mapped, how or why); the
    statistical alternative and an effect without a rule are said by
    :func:`not_a_law` and :func:`no_rule`.

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 10], "z_m": [5, 0],
    ...   "material": "rock"}, "materials": {"rock": {"e_n": 0.3, "e_t": 0.8,
    ...   "friction_deg": 25}}, "effects": {"air_drag": {}}, "body": {"mass_kg":
    ...   100, "radius_m": 0.2}, "seeder": {"x_m": 1, "z_m": 6}})
    >>> lines = effects_account(m, "Demo", {"air_drag": (False, "no drag")})
    >>> len(lines) == len(registry.EFFECTS), lines[6]
    (True, 'effect air_drag (on in this model): not mapped: no drag')
    """
    out = []
    for spec in registry.EFFECTS:
        state = "on" if spec.name in model.effects else "off"
        rule = rules.get(spec.name)
        if rule is None:
            why = _not_a_law(spec, target) or no_rule(spec.name, target)
            text = f"not mapped: {why}"
        else:
            mapped, how = rule
            text = f"mapped: {how}" if mapped else f"not mapped: {how}"
        out.append(f"effect {spec.name} ({state} in this model): {text}")
    return out


class Written(NamedTuple):
    """What an exporter writes in place of a law it cannot take.

    Attributes
    ----------
    model
        The calibrated model with the target's law and the written values.
    coefficients
        Per material the written (Rn, Rt) (empty: written as calibrated).
    reasons
        Why the calibrated law could not be written as it is.
    loud
        The lines of materials no simulated rock touched.
    search
        The behaviour search (:func:`closest_behaviour`), or None.
    """

    model: Model
    coefficients: dict[str, tuple[Coefficient, Coefficient]]
    reasons: list[str]
    loud: list[str]
    search: Behaviour | None


def search_line(behaviour: Behaviour | None, target: str) -> list[str]:
    """The README line saying what the behaviour search did ([] without one)."""
    if behaviour is None:
        return []
    search = behaviour.search
    what = ", ".join(behaviour.searched)
    head = (
        f"Behaviour search over {what} in {target}'s ranges (runout p50/p95, p95 "
        "energy and bounce height at the analysis points; summed squared log "
        f"ratios; {search.evaluations} emulations of {SEARCH_ROCKS} rocks, seed "
        f"{SEARCH_SEED}): {search.start_gap:.3g} at the impact-level least-squares "
        f"values, {search.gap:.3g} at the values found; on the translation error's "
        f"own stream {behaviour.held_out_start:.3g} and "
        f"{behaviour.held_out_found:.3g}. "
    )
    if behaviour.accepted:
        return [
            head + "The values found are written: they trade rebound accuracy for "
            "design behaviour, and each one's spread says how far"
        ]
    return [
        head + f"The impact-level values are written: the values found do not cut "
        f"the independent gap by {100 * MIN_GAIN:.0f} % (a search the quantities "
        "hardly respond to fits noise)"
    ]


def fit_lines(
    reasons: list[str],
    coefficients: dict[str, tuple[Coefficient, Coefficient]],
    target: str,
    range_text: str,
    number: str = "g",
) -> list[str]:
    """The README lines saying why the calibrated law was not written as it is
    (``reasons``) and which least-squares values ``target``'s range (``range_text``,
    e.g. ``"[0, 1]"``) clipped; ``number`` formats the written value."""
    if not reasons:
        return []
    out = [
        f"The calibrated law cannot be written in {target}'s terms ("
        + "; ".join(reasons)
        + f"): each material's Rn, Rt start as the values in {range_text} whose "
        f"rebounds under {target}'s law are closest (least squares) to the "
        "calibrated model's simulated impacts on it, then the behaviour search "
        "below decides; see the translation error"
    ]
    for coefficient in (c for pair in coefficients.values() for c in pair):
        if coefficient.clipped:
            out.append(
                f"{coefficient.name}: the least-squares value under {target}'s law "
                f"is {coefficient.unclipped:.4g}, outside {target}'s range "
                f"{range_text}: {format(coefficient.written, number)} is written"
            )
    return out
