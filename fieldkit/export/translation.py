"""What a target's law does with the exported values: the translation error.

A target simulator has its own impact law -- a constant restitution pair
(r.stone, Rockyfor3D's soil types), a velocity scaling with its own constant
(RocFall, CRSP), a tangential coefficient computed from obstacle heights
(Rockyfor3D). A calibrated fieldkit model is usually not written in those terms
(a velocity-scaled e_n above 1, an angle law, a rotation coupling), so an export
writes the *in-range* values whose behaviour under the target's law is closest to
the calibrated model's, and says how far apart the two remain:

1. :func:`realised_impacts` -- the impacts the calibrated model produces (its own
   simulation, one row per impact);
2. :func:`fit_scaled` -- for a law linear in one parameter, ``v_f = p f(v_i) v_i``
   (``f`` the target's scaling evaluated per impact, 1 for a constant pair), the
   ``p`` within the target's documented range that minimises the squared rebound
   error over those impacts, and the impacts' own spread around it;
3. :func:`translation_error` -- the calibrated model and fieldkit's emulation of
   the target's law with the written values (a :class:`~fieldkit.model.model_file.
   Model` the exporter builds) simulated on the calibrated model's own section,
   compared where a designer reads them: runout p50 and p95, and at analysis
   points the p95 total kinetic energy and p95 bounce height, each with its Monte
   Carlo standard error (:func:`fieldkit.model.statistics.percentile_se`).

4. :func:`closest_in_range` -- the in-range values whose *behaviour* under the
   target's law is closest to the calibrated model's: starting from the
   impact-level values of step 2, a bounded search minimising the summed squared
   log ratios of the quantities of step 3 (:func:`behaviour_gap`). The
   impact-level pair alone can be far off: the least-squares pair is dominated
   by the many slow impacts, while the design values are set by the few fast
   ones (Tornado Mountain's velocity-scaled colluvium: the constant pair gives 10
   times the calibrated p95 energy at the fence line). The search runs on its own
   random stream (:data:`SEARCH_SEED`); the translation error the README gives
   is then measured on another (:data:`SEED`), so it is not flattered by the
   search.

The translation error is fieldkit's emulation, not a run of the target: it is
only as good as the emulation of the target's law, which each exporter states.

An emulation is either a fieldkit :class:`~fieldkit.model.model_file.Model` of the
target's law (run by :func:`fieldkit.model.simulate.simulate`) or any object of
the :class:`Emulation` protocol: a kernel of the target's own law (r.stone's,
:mod:`fieldkit.export.rstone_law`) with a ``simulate`` giving the fields the
comparison reads (:func:`run`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Protocol, runtime_checkable

import numpy as np
import pandas as pd

from fieldkit.model.model_file import Model, model_from_dict, model_to_dict
from fieldkit.model.simulate import simulate
from fieldkit.model.statistics import percentile_se
from fieldkit.outputs import json_text

#: Rocks and seed of the simulation whose impacts the in-range values are fitted to.
IMPACT_ROCKS, IMPACT_SEED = 400, 0

#: Rocks and seed of each of the two simulations of :func:`translation_error`
#: (a stream of its own, apart from :data:`IMPACT_SEED`'s).
ROCKS, SEED = 1000, 20261125

#: Rocks and seed of each simulation in :func:`closest_in_range`'s search.
SEARCH_ROCKS, SEARCH_SEED = 250, 7

#: Fractions of the calibrated rocks passing the default analysis points.
DEFAULT_PASSING = (0.9, 0.5)


@runtime_checkable
class Emulation(Protocol):
    """A target's law run by a kernel of its own, not a fieldkit Model.

    ``simulate(rocks, rng, analysis_x_m)`` returns an object with the fields of
    a :class:`~fieldkit.model.results.SimulationResult` the comparison reads:
    ``runout_x_m`` (rocks,), ``state`` (rocks,) with
    :data:`~fieldkit.model.results.EXITED_DOWNSLOPE` etc., and ``analysis``, one
    :class:`~fieldkit.model.results.AnalysisPoint` per analysis chainage (at
    least ``crossed``, ``total_j``, ``height_m``). ``start_x_m`` and ``end_x_m``
    are where its rocks start and its section ends [m] (:func:`default_points`).
    """

    @property
    def start_x_m(self) -> float: ...

    @property
    def end_x_m(self) -> float: ...

    def simulate(self, rocks: int, rng: np.random.Generator, analysis_x_m=()): ...


def run(
    emulated: Model | Emulation,
    rocks: int,
    rng: np.random.Generator,
    analysis_x_m: Sequence[float] = (),
):
    """Simulate a Model with fieldkit's :func:`~fieldkit.model.simulate.simulate`,
    or an :class:`Emulation` with its own ``simulate``."""
    if isinstance(emulated, Model):
        return simulate(emulated, rocks, rng, analysis_x_m=analysis_x_m)
    return emulated.simulate(rocks, rng, analysis_x_m=analysis_x_m)


def realised_impacts(
    model: Model, rocks: int = IMPACT_ROCKS, seed: int = IMPACT_SEED
) -> pd.DataFrame:
    """The impacts ``model`` produces: one row per simulated impact with finite
    velocities.

    Returns
    -------
    pandas.DataFrame
        ``material``, ``vin_mps`` (negative: into the ground), ``vit_mps``,
        ``vfn_mps``, ``vft_mps``, ``vi_mps`` (the impact speed), ``path_id`` (the rock).

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 60, 120], "z_m": [60, 20, 0],
    ...   "material": "talus"}, "materials": {"talus": {"e_n": 0.4, "e_t": 0.8,
    ...   "friction_deg": 30}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 70}})
    >>> f = realised_impacts(m, rocks=20)
    >>> bool((f["vfn_mps"] / -f["vin_mps"]).round(6).eq(0.4).all())
    True
    """
    return _realised_impacts(_key(model), rocks, seed).copy()


def _key(model: Model) -> str:
    """``model`` as its JSON text: what the caches below are keyed on."""
    return json_text(model_to_dict(model))


@lru_cache(maxsize=8)
def _realised_impacts(text: str, rocks: int, seed: int) -> pd.DataFrame:
    model = model_from_dict(json.loads(text))
    result = simulate(model, rocks, np.random.default_rng(seed), record_impacts=True)
    frame = result.impact_table.frame
    columns = ["vin_mps", "vit_mps", "vfn_mps", "vft_mps", "vi_mps"]
    out = frame[["material", *columns]].copy()
    out["path_id"] = frame["path_id"].to_numpy()
    values = out[columns].to_numpy(float)
    return out[np.isfinite(values).all(axis=1)].reset_index(drop=True)


def calibrated_run(
    model: Model, rocks: int, seed: int, analysis_x_m: Sequence[float] = ()
):
    """``simulate(model, rocks, default_rng(seed), analysis_x_m=...)``, kept for
    the model's next use: an export compares one calibrated model with several
    emulations (the impact-level values, the searched ones, the README's), each
    on the same stream, so the calibrated side is simulated once. Read only."""
    return _calibrated_run(
        _key(model), rocks, seed, tuple(float(x) for x in analysis_x_m)
    )


@lru_cache(maxsize=16)
def _calibrated_run(text: str, rocks: int, seed: int, at: tuple[float, ...]):
    model = model_from_dict(json.loads(text))
    return simulate(model, rocks, np.random.default_rng(seed), analysis_x_m=at)


@dataclass(frozen=True)
class Scaled:
    """The in-range parameter of a one-parameter law and the impacts' spread.

    Attributes
    ----------
    value
        The parameter ``p`` in ``[lo, hi]`` (NaN without impacts).
    spread
        The impacts' own weighted SD of ``v_f / (f v_i)`` around ``value``,
        ``sqrt(sum (v_f - p f v_i)^2 / sum (f v_i)^2)``: the scatter a target's
        random draw of ``p`` should carry (not the standard error of a fit).
    n
        Impacts used.
    unclipped
        The least-squares value before clipping to ``[lo, hi]``.
    """

    value: float
    spread: float
    n: int
    unclipped: float

    @property
    def clipped(self) -> bool:
        """Whether the range moved the value (the law cannot be written as fitted)."""
        return bool(np.isfinite(self.unclipped) and self.value != self.unclipped)


def fit_scaled(
    vi: np.ndarray,
    vf: np.ndarray,
    factor: np.ndarray | float,
    lo: float,
    hi: float,
) -> Scaled:
    """The ``p`` in ``[lo, hi]`` minimising ``sum (v_f - p f v_i)^2``.

    The objective is a convex quadratic in ``p``, so the constrained minimum is
    the least-squares value ``sum v_f f v_i / sum (f v_i)^2`` clipped to the
    range (exact, no search).

    Parameters
    ----------
    vi, vf
        Impact and rebound velocity components of the impacts, signed so that the
        law reads ``v_f = p f v_i`` (normal: ``|v_iN|`` and ``v_fN``).
    factor
        The target's scaling ``f`` per impact (a scalar 1 for a constant pair).
    lo, hi
        The target's documented range of ``p``.

    Examples
    --------
    >>> vi = np.array([10.0, 20.0]); vf = np.array([12.0, 24.0])
    >>> s = fit_scaled(vi, vf, 1.0, 0.0, 1.0)
    >>> s.value, s.unclipped, s.clipped, round(s.spread, 4)
    (1.0, 1.2, True, 0.2)
    >>> fit_scaled(vi, 0.5 * vi, 1.0, 0.0, 1.0).value
    0.5
    """
    vi = np.asarray(vi, float)
    vf = np.asarray(vf, float)
    x = np.broadcast_to(np.asarray(factor, float), vi.shape) * vi
    ok = np.isfinite(x) & np.isfinite(vf) & (x != 0)
    n = int(ok.sum())
    if n == 0:
        return Scaled(math.nan, math.nan, 0, math.nan)
    x, y = x[ok], vf[ok]
    sxx = float(np.sum(x * x))
    unclipped = float(np.sum(x * y) / sxx)
    value = float(min(max(unclipped, lo), hi))
    spread = math.sqrt(float(np.sum((y - value * x) ** 2)) / sxx)
    return Scaled(value, spread, n, unclipped)


@dataclass(frozen=True)
class Row:
    """One compared quantity: values and Monte Carlo SEs of both models."""

    quantity: str
    unit: str
    calibrated: float
    calibrated_se: float
    emulated: float
    emulated_se: float

    @property
    def difference(self) -> float:
        return self.emulated - self.calibrated

    @property
    def se(self) -> float:
        """SE of the difference (two independent ensembles)."""
        return math.hypot(self.calibrated_se, self.emulated_se)

    @property
    def percent(self) -> float:
        """The difference in percent of the calibrated value (NaN at 0)."""
        if not math.isfinite(self.calibrated) or self.calibrated == 0:
            return math.nan
        return 100.0 * self.difference / abs(self.calibrated)


@dataclass(frozen=True)
class Translation:
    """The calibrated model against the target's law with the exported values.

    Attributes
    ----------
    rows
        Runout p50, p95, then per analysis point the p95 total energy and p95
        bounce height (:class:`Row`).
    at_m
        The analysis points' chainages [m].
    rocks, seed
        Rocks of each simulation and the seed both used.
    default_at
        Whether ``at_m`` are the default points (:func:`default_points`).
    exited
        Fractions of the calibrated and emulated rocks that left the section at
        its lower end (their runout is the section's end: a censored value).
    origin_m
        Where the calibrated rocks start (the seeder's chainage): runouts are
        compared by :func:`behaviour_gap` as distances travelled from it.
    """

    rows: list[Row]
    at_m: tuple[float, ...]
    rocks: int
    seed: int
    default_at: bool
    exited: tuple[float, float]
    origin_m: float = 0.0

    @property
    def unreached(self) -> list[str]:
        """Quantities one model gives and the other cannot (no rock of it crosses
        the analysis point): :attr:`worst_percent` leaves them out."""
        return [
            r.quantity
            for r in self.rows
            if math.isfinite(r.calibrated) != math.isfinite(r.emulated)
        ]

    @property
    def worst_percent(self) -> float:
        """The largest |difference| in percent of the calibrated value, over the
        quantities both models give (see :attr:`unreached`)."""
        values = [abs(r.percent) for r in self.rows if math.isfinite(r.percent)]
        return max(values) if values else math.nan

    def lines(self) -> list[str]:
        """The README's markdown: a sentence, the table, what it rests on."""
        points = ", ".join(f"{x:.1f} m" for x in self.at_m)
        where = (
            " (where 90 % and 50 % of the calibrated rocks still pass, none at the "
            "section's lower end)"
            if self.default_at
            else ""
        )
        out = [
            f"{self.rocks} rocks of each model (seed {self.seed}), simulated by "
            "fieldkit on the calibrated model's own section: the calibrated model, and "
            "fieldkit's emulation of the target's law with the values written here. "
            f"Analysis points at chainage {points}{where}. Largest difference: "
            f"{self.worst_percent:.1f} % of the calibrated value"
            + (
                " among the quantities both give; **not given by one of the two** "
                "(no rock of it crosses the point: the design value there is lost, "
                f"not merely changed): {'; '.join(self.unreached)}."
                if self.unreached
                else "."
            ),
            "",
            "| quantity | calibrated model | target's law, values written | difference "
            "| beyond 2 SE |",
            "|---|---|---|---|---|",
        ]
        for r in self.rows:
            beyond = (
                "yes" if math.isfinite(r.se) and abs(r.difference) > 2 * r.se else "no"
            )
            pct = f" ({r.percent:+.1f} %)" if math.isfinite(r.percent) else ""
            out.append(
                f"| {r.quantity} | {_value(r.calibrated, r.calibrated_se, r.unit)} "
                f"| {_value(r.emulated, r.emulated_se, r.unit)} "
                f"| {_number(r.difference)} {r.unit}{pct} | {beyond} |"
            )
        cal, emu = self.exited
        out += [
            "",
            f"Rocks leaving the section at its lower end: {100 * cal:.1f} % "
            f"(calibrated), {100 * emu:.1f} % (emulated); their runout is the "
            "section's end. ± is the Monte Carlo SE of each ensemble; 'beyond 2 SE' "
            "marks a difference the ensembles' sampling does not explain.",
        ]
        return out


def translation_error(
    calibrated: Model,
    emulated: Model | Emulation,
    *,
    at_m: Sequence[float] | None = None,
    rocks: int = ROCKS,
    seed: int = SEED,
) -> Translation:
    """Simulate ``calibrated`` and ``emulated`` (module docstring) and compare.

    Parameters
    ----------
    calibrated
        The calibrated model.
    emulated
        fieldkit's model of the target's law with the exported values, on the
        same section: a Model, or an :class:`Emulation` (:func:`run`).
    at_m
        Analysis points [m]; default :func:`default_points`.
    rocks, seed
        Each simulation's rocks, and the seed both use.

    Examples
    --------
    >>> from dataclasses import replace
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 60, 120], "z_m": [60, 20, 0],
    ...   "material": "talus"}, "materials": {"talus": {"e_n": 0.4, "e_t": 0.8,
    ...   "friction_deg": 30}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 70}})
    >>> t = translation_error(m, m, rocks=50)
    >>> t.worst_percent, [r.quantity for r in t.rows][:2]
    (0.0, ['runout p50', 'runout p95'])
    """
    default_at = at_m is None
    if at_m is None:
        at_m = default_points(calibrated, rocks, seed)
    at = tuple(float(x) for x in at_m)
    second = run(emulated, rocks, np.random.default_rng(seed), analysis_x_m=at)
    first = calibrated_run(calibrated, rocks, seed, at)
    return replace(
        _compare(first, second, rocks, seed, at, float(calibrated.seeder.x_m)),
        default_at=default_at,
    )


def _compare(
    first, second, rocks: int, seed: int, at: Sequence[float], origin_m: float = 0.0
) -> Translation:
    """The :class:`Translation` of two simulations with the same analysis points."""
    rows = [
        _row(f"runout p{q}", "m", first.runout_x_m, second.runout_x_m, q)
        for q in (50, 95)
    ]
    for a, b in zip(first.analysis, second.analysis, strict=True):
        for name, unit, attribute in (
            ("p95 total energy", "kJ", "total_j"),
            ("p95 bounce height", "m", "height_m"),
        ):
            scale = 1e-3 if unit == "kJ" else 1.0
            rows.append(
                _row(
                    f"{name} at {a.x_m:.1f} m",
                    unit,
                    _crossed(a, attribute) * scale,
                    _crossed(b, attribute) * scale,
                    95,
                )
            )
    return Translation(
        rows,
        tuple(float(x) for x in at),
        rocks,
        seed,
        False,
        (_exited(first), _exited(second)),
        origin_m,
    )


def default_points(
    model: Model | Emulation, rocks: int = ROCKS, seed: int = SEED
) -> list[float]:
    """The chainages 90 % and 50 % of ``model``'s rocks pass (:data:`DEFAULT_PASSING`),
    to 0.1 m, leaving out a point at the section's lower end (where rocks that
    leave the section are counted); the point three quarters of the way from the
    seeder to the end when both fall there. ``model`` a Model or an
    :class:`Emulation` (from its ``start_x_m`` to its ``end_x_m``).
    """
    pilot = (
        calibrated_run(model, rocks, seed)
        if isinstance(model, Model)
        else run(model, rocks, np.random.default_rng(seed))
    )
    runout = np.asarray(pilot.runout_x_m, float)
    if isinstance(model, Model):
        start = float(model.seeder.x_m)
        end = float(model.profile.x_m[-1])
    else:
        start, end = float(model.start_x_m), float(model.end_x_m)
    margin = 0.01 * (end - start)
    points = sorted(
        {
            round(float(np.quantile(runout, 1.0 - p)), 1)
            for p in DEFAULT_PASSING
            if start < np.quantile(runout, 1.0 - p) < end - margin
        }
    )
    return points or [round(start + 0.75 * (end - start), 1)]


def _crossed(point, attribute: str) -> np.ndarray:
    return np.asarray(getattr(point, attribute), float)[np.asarray(point.crossed, bool)]


def _exited(result) -> float:
    from fieldkit.model.results import EXITED_DOWNSLOPE

    return float(np.mean(np.asarray(result.state) == EXITED_DOWNSLOPE))


def _row(quantity: str, unit: str, a: np.ndarray, b: np.ndarray, q: float) -> Row:
    va, sa = percentile_se(np.asarray(a, float), q)
    vb, sb = percentile_se(np.asarray(b, float), q)
    return Row(quantity, unit, va, sa, vb, sb)


def _number(value: float) -> str:
    if not math.isfinite(value):
        return "n/a"
    return f"{value:+.3g}" if abs(value) < 1000 else f"{value:+,.0f}"


def _value(value: float, se: float, unit: str) -> str:
    if not math.isfinite(value):
        return "no rock crossed"
    text = f"{value:.3g}" if abs(value) < 1000 else f"{value:,.0f}"
    if math.isfinite(se):
        text += f" ± {se:.2g}"
    return f"{text} {unit}"


#: Floors of :func:`behaviour_gap`'s log ratios of design values, by unit:
#: differences well below them do not matter to a design (a decimetre of bounce
#: height, a kilojoule), and a 0 (rolling rocks' p95 bounce height) stays finite.
GAP_FLOOR = {"m": 0.1, "kJ": 1.0}

#: Weight of the runout terms in :func:`behaviour_gap`: a runout's log ratio is
#: small (travel distances of hundreds of metres differ by a few percent), so
#: 1 % of runout counts as much as 10 % of a design value.
RUNOUT_WEIGHT = 100.0

#: What :func:`behaviour_gap` counts for a design value one model never gives.
LOST = math.log(10.0) ** 2


def behaviour_gap(t: Translation) -> float:
    """How differently the emulation behaves: a sum of squared log ratios.

    * runouts: ``RUNOUT_WEIGHT log((b - o) / (a - o))^2``, ``a`` calibrated,
      ``b`` emulated, ``o`` the seeder's chainage (:attr:`Translation.origin_m`):
      distances travelled (:data:`RUNOUT_WEIGHT`);
    * design values (p95 energy and bounce height at the analysis points):
      ``log((b + f) / (a + f))^2`` with the unit's floor ``f``
      (:data:`GAP_FLOOR`), so that rolling rocks' p95 bounce height of 0 against
      0.44 m of bouncing ones counts ``log(5.4)^2``, not nothing;
    * a design value one model never gives (no rock of it crosses the point):
      :data:`LOST`, ``log(10)^2``.

    Examples
    --------
    >>> r = Row("runout p50", "m", 100.0, 0.1, 101.0, 0.1)
    >>> round(behaviour_gap(Translation([r], (), 1, 0, True, (0, 0))), 4)
    0.0099
    >>> z = Row("p95 bounce height at 5.0 m", "m", 0.44, 0.03, 0.0, 0.0)
    >>> round(behaviour_gap(Translation([z], (), 1, 0, True, (0, 0))), 2)
    2.84
    """
    total = 0.0
    for r in t.rows:
        a, b = r.calibrated, r.emulated
        if math.isfinite(a) != math.isfinite(b):
            total += LOST
            continue
        if not math.isfinite(a):
            continue
        if r.quantity.startswith("runout"):
            a, b = a - t.origin_m, b - t.origin_m
            if a > 0 and b > 0:
                total += RUNOUT_WEIGHT * math.log(b / a) ** 2
            continue
        f = GAP_FLOOR.get(r.unit, 0.0)
        if abs(a) + f > 0 and abs(b) + f > 0:
            total += math.log((abs(b) + f) / (abs(a) + f)) ** 2
    return total


@dataclass(frozen=True)
class Search:
    """The outcome of :func:`closest_in_range`.

    Attributes
    ----------
    values
        The in-range parameters found.
    start
        Where the search started (the impact-level values).
    gap, start_gap
        :func:`behaviour_gap` at ``values`` and at ``start`` (search stream).
    evaluations
        Emulations simulated.
    """

    values: tuple[float, ...]
    start: tuple[float, ...]
    gap: float
    start_gap: float
    evaluations: int


def closest_in_range(
    calibrated: Model,
    build: Callable[[Sequence[float]], Model | Emulation],
    start: Sequence[float],
    lo: Sequence[float],
    hi: Sequence[float],
    *,
    at_m: Sequence[float] | None = None,
    rocks: int = SEARCH_ROCKS,
    seed: int = SEARCH_SEED,
    max_evaluations: int = 300,
) -> Search:
    """The values in ``[lo, hi]`` whose emulation ``build(values)`` behaves
    closest to ``calibrated`` (module docstring, step 4).

    A coordinate search (:func:`coordinate_search`, at most
    ``max_evaluations`` emulations) of :func:`behaviour_gap`, every evaluation
    on the same random stream (common random numbers: the objective changes
    only with the values). Never worse
    than ``start``: if the search does not improve on it, ``start`` is kept.

    Parameters
    ----------
    build
        values -> fieldkit's model of the target's law with those values: a
        Model or an :class:`Emulation` (:func:`run`).
    start, lo, hi
        Starting values (e.g. :func:`fit_scaled`'s) and the target's documented
        ranges.
    at_m
        Analysis points; default :func:`default_points` of ``calibrated``.

    Examples
    --------
    >>> from dataclasses import replace
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 60, 120], "z_m": [60, 20, 0],
    ...   "material": "talus"}, "materials": {"talus": {"e_n": 0.4, "e_t": 0.8,
    ...   "friction_deg": 30}}, "body": {"mass_kg": 100, "radius_m": 0.2},
    ...   "seeder": {"x_m": 1, "z_m": 70}})
    >>> def build(v):
    ...     t = replace(m.materials["talus"], e_n=v[0])
    ...     return replace(m, materials={"talus": t})
    >>> s = closest_in_range(m, build, [0.7], [0.0], [1.0], rocks=100)
    >>> abs(s.values[0] - 0.4) < 0.05, s.gap < s.start_gap
    (True, True)
    """

    lo_a, hi_a = np.asarray(lo, float), np.asarray(hi, float)
    x0 = np.clip(np.asarray(start, float), lo_a, hi_a)
    points = list(at_m) if at_m is not None else default_points(calibrated)
    reference = simulate(
        calibrated, rocks, np.random.default_rng(seed), analysis_x_m=points
    )
    origin = float(calibrated.seeder.x_m)
    count = 0

    def gap(x: np.ndarray) -> float:
        nonlocal count
        count += 1
        values = tuple(float(v) for v in np.clip(x, lo_a, hi_a))
        emulated = run(
            build(values), rocks, np.random.default_rng(seed), analysis_x_m=points
        )
        return behaviour_gap(_compare(reference, emulated, rocks, seed, points, origin))

    start_gap = gap(x0)
    x, best = coordinate_search(gap, x0, lo_a, hi_a, start_gap, max_evaluations)
    return Search(
        tuple(float(v) for v in x),
        tuple(float(v) for v in x0),
        best,
        start_gap,
        count,
    )


#: Values tried along one coordinate in a sweep of :func:`coordinate_search`.
GRID_POINTS = 9


def coordinate_search(
    f: Callable[[np.ndarray], float],
    x0: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    f0: float,
    max_evaluations: int,
) -> tuple[np.ndarray, float]:
    """Minimise ``f`` in the box ``[lo, hi]`` one coordinate at a time.

    Each sweep tries, for every coordinate in turn, :data:`GRID_POINTS` values
    evenly over the current interval around the best point (the whole range at
    first, then halved each sweep) and keeps the best; it stops when a sweep
    improves nothing at the finest interval or after ``max_evaluations``.
    Global along each axis, so a plateau of equal values (where a local line
    search stalls) is crossed; deterministic.

    Examples
    --------
    >>> f = lambda x: (x[0] - 0.3) ** 2 + abs(x[1] - 0.7)
    >>> x, fx = coordinate_search(f, np.array([0.9, 0.1]), np.zeros(2), np.ones(2),
    ...                           f(np.array([0.9, 0.1])), 400)
    >>> np.round(x, 2).tolist(), bool(fx < 1e-3)
    ([0.3, 0.7], True)
    """
    x, best = np.array(x0, float), float(f0)
    width = np.asarray(hi, float) - np.asarray(lo, float)
    evaluations = 0
    for _ in range(40):
        improved = False
        for i in range(x.size):
            a = max(lo[i], x[i] - width[i] / 2)
            b = min(hi[i], x[i] + width[i] / 2)
            for value in np.linspace(a, b, GRID_POINTS):
                if evaluations >= max_evaluations:
                    return x, best
                if value == x[i]:
                    continue
                trial = x.copy()
                trial[i] = value
                evaluations += 1
                ft = f(trial)
                if ft < best:
                    x, best, improved = trial, ft, True
        width = width / 2
        if not improved and np.all(width < 1e-3):
            break
    return x, best
