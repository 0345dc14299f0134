"""What a simulation returns: per-rock outcomes, analysis points, envelope, impacts.

:class:`SimulationResult` holds raw per-rock arrays (so any statistic can be computed
later); :meth:`SimulationResult.summary` gives what a designer reads (the
``summary.json`` contract of docs/architecture.md §4), every statistic with its Monte
Carlo standard error.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from fieldkit.impact_table import ImpactTable
from fieldkit.model.statistics import (
    distribution,
    envelope_percentiles,
    fraction_se,
    rank_of,
)

if TYPE_CHECKING:  # the Model type is only named in annotations
    from fieldkit.model.model_file import Model

#: Final state of a rock (``SimulationResult.state``).
STOPPED, EXITED_DOWNSLOPE, EXITED_UPSLOPE, MAX_IMPACTS = 0, 1, 2, 3
STATE_NAMES = {
    STOPPED: "stopped on the profile",
    EXITED_DOWNSLOPE: "left the profile at its lower end",
    EXITED_UPSLOPE: "left the profile at its upper end",
    MAX_IMPACTS: "still moving at the impact limit (capped)",
}


@dataclass
class AnalysisPoint:
    """Rocks crossing the vertical line ``x = x_m`` (first crossing of each rock).

    Arrays have one entry per rock; NaN where the rock never crossed.
    """

    x_m: float
    crossed: np.ndarray  # (rocks,) bool
    speed_mps: np.ndarray  # translational speed of the centre [m/s]
    ke_j: np.ndarray  # translational kinetic energy [J]
    re_j: np.ndarray  # rotational energy [J]
    total_j: np.ndarray  # ke + re [J]
    height_m: np.ndarray  # centre height above the ground, vertical [m] (bounce height)


@dataclass
class SimulationResult:
    """Everything one simulation produced (see the module docstring)."""

    model: Model
    rocks: int
    seed: int | None
    wall_s: float  # kernel time only [s], without compiling
    impacts: int  # total impacts over all rocks
    runout_x_m: np.ndarray  # (rocks,) x where the rock stopped or left the profile
    state: np.ndarray  # (rocks,) int, one of STATE_NAMES
    impacts_per_rock: np.ndarray  # (rocks,) int
    analysis: list[AnalysisPoint] = field(default_factory=list)
    envelope_x_m: np.ndarray = field(default_factory=lambda: np.zeros(0))  # bin edges
    envelope_height_m: np.ndarray = field(  # (rocks, bins) max height per bin, float32
        default_factory=lambda: np.zeros((0, 0), np.float32)
    )
    trajectories: list[np.ndarray] = field(default_factory=list)  # (n_i, 2) x, z
    impact_table: ImpactTable | None = None
    compile_s: float = 0.0  # compiling the kernel in this process [s] (0: cached)

    # ------------------------------------------------------------------ statistics
    def envelope(self) -> dict[str, np.ndarray]:
        """The bounce-height envelope along the profile (thesis Figs. 7.10, 7.13).

        Returns ``x_m`` (bin centres), ``reached`` (rocks reaching each bin) and
        ``p50``, ``p95``, ``max`` of the rocks' maximum centre height above the
        ground in each bin, over the rocks that reached it
        (:func:`fieldkit.model.statistics.envelope_percentiles`).
        """
        edges = np.asarray(self.envelope_x_m, dtype=float)
        out = envelope_percentiles(self.envelope_height_m)
        out["x_m"] = (edges[:-1] + edges[1:]) / 2.0 if edges.size > 1 else edges[:0]
        return out

    def percentile_of(self, index: int, quantity: str, value: float) -> dict:
        """Where a measured ``value`` falls among the rocks crossing analysis point
        ``index``: its percentile in the simulated distribution of ``quantity``.

        Parameters
        ----------
        quantity
            An :class:`AnalysisPoint` array: ``speed_mps``, ``ke_j`` (translational),
            ``re_j``, ``total_j`` or ``height_m``.

        Returns
        -------
        dict
            :func:`fieldkit.model.statistics.rank_of`: ``measured``, ``n`` (crossing
            rocks), ``percentile`` (percent of them with a smaller value, ties counted
            half) and its binomial ``percentile_se``; no percentile but ``beyond``
            (``"above"``, ``"below"``) when the value lies beyond every crossing rock;
            ``simulated_min``, ``simulated_max``.

        Examples
        --------
        >>> p = AnalysisPoint(0.0, np.array([True] * 4), np.arange(4.0), *[None] * 4)
        >>> r = SimulationResult(None, 4, 0, 0.0, 0, None, None, None, [p])
        >>> r.percentile_of(0, "speed_mps", 2.0)["percentile"]
        62.5
        >>> r.percentile_of(0, "speed_mps", 7.0)["beyond"]
        'above'
        """
        point = self.analysis[index]
        crossed = np.asarray(point.crossed, bool)
        return rank_of(np.asarray(getattr(point, quantity), float)[crossed], value)

    def summary(self) -> dict:
        """What a designer reads: the ``summary.json`` contract (architecture §4).

        ``rocks``, ``impacts``, ``wall_s`` (simulation only), ``compile_s``
        (compiling the simulator, 0 when the compiled kernel came from the cache),
        ``seed``, ``runout_x_m`` and, per analysis point, ``passing_fraction`` and the
        distributions of ``speed_mps``, ``ke_j``, ``re_j``, ``total_j`` and
        ``bounce_height_m`` over the rocks that crossed it. Every distribution holds
        ``n``, ``mean``, ``p50``, ``p90``, ``p95``, ``p99``, ``max`` and ``se`` (their
        Monte Carlo standard errors; :mod:`fieldkit.model.statistics` says how each
        is computed). Fractions carry ``*_se`` (binomial). Also: the final states,
        the envelope, and the model's source, active effects and core settings.

        Rocks still moving when they reach the model's ``max_impacts`` (*capped*)
        are their own final state: never counted as stopped or as run out.
        ``runout_x_m`` is over the rocks that stopped on or left the profile
        (``runout_over`` says so and how many); a rock that left the profile at its
        lower end ran out at least that far, so each runout statistic that uses one
        is flagged a lower bound (``runout_x_m["lower_bound"]``, ``runout_censored``);
        ``capped`` gives their number, fraction and where they were;
        ``runout_bounds_x_m`` brackets each runout percentile of *all* rocks
        (:func:`_runout_bounds`).
        """
        n = int(self.rocks)
        state = np.asarray(self.state)
        stopped, stopped_se = fraction_se(int((state == STOPPED).sum()), n)
        capped = state == MAX_IMPACTS
        left = state == EXITED_DOWNSLOPE  # ran out at least to the profile's end
        runout = np.asarray(self.runout_x_m, float)
        n_capped = int(capped.sum())
        n_left = int(left.sum())
        capped_fraction, capped_se = fraction_se(n_capped, n)
        max_impacts = int(
            dict(getattr(self.model, "core", {}) or {}).get("max_impacts", 0)
        )
        points = []
        for point in self.analysis:
            crossed = np.asarray(point.crossed, bool)
            passing, passing_se = fraction_se(int(crossed.sum()), n)

            def over_crossed(values: np.ndarray, crossed=crossed) -> dict:
                return distribution(np.asarray(values, float)[crossed])

            points.append(
                {
                    "x_m": float(point.x_m),
                    "passing": int(crossed.sum()),
                    "passing_fraction": passing,
                    "passing_fraction_se": passing_se,
                    "speed_mps": over_crossed(point.speed_mps),
                    "ke_j": over_crossed(point.ke_j),
                    "re_j": over_crossed(point.re_j),
                    "total_j": over_crossed(point.total_j),
                    "bounce_height_m": over_crossed(point.height_m),
                }
            )
        envelope = self.envelope()
        model = self.model
        return {
            "rocks": n,
            "impacts": int(self.impacts),
            "wall_s": float(self.wall_s),
            "compile_s": float(self.compile_s),
            "seed": self.seed,
            "runout_x_m": distribution(runout[~capped], at_least=left[~capped]),
            "runout_censored": {
                "rocks": n_left,
                "fraction": n_left / (n - n_capped) if n > n_capped else None,
                "end_x_m": _profile_end(model),
                "meaning": CENSORED_NOTE,
            },
            "runout_over": f"{n - n_capped} of {n} rocks: those that stopped on or "
            "left the profile (x where they stopped, or the end they left by)"
            + (
                f"; the {n_capped} capped rocks are left out (runout_bounds_x_m "
                "brackets the percentiles of all rocks)"
                if n_capped
                else "; no rock was capped"
            ),
            "runout_bounds_x_m": _runout_bounds(runout, capped, left, self.model),
            "capped": {
                "rocks": n_capped,
                "fraction": capped_fraction,
                "fraction_se": capped_se,
                "max_impacts": max_impacts,
                "x_m": distribution(runout[capped]),
                "meaning": CAPPED_NOTE,
            },
            "stopped_fraction": stopped,
            "stopped_fraction_se": stopped_se,
            "final_state": {
                name: int((state == code).sum()) for code, name in _STATE_KEYS.items()
            },
            "analysis_points": points,
            "envelope": {
                "bin_width_m": (
                    float(self.envelope_x_m[1] - self.envelope_x_m[0])
                    if np.size(self.envelope_x_m) > 1
                    else None
                ),
                "x_m": _floats(envelope["x_m"]),
                "reached": [int(v) for v in envelope["reached"]],
                "height_p50_m": _floats(envelope["p50"]),
                "height_p95_m": _floats(envelope["p95"]),
                "height_max_m": _floats(envelope["max"]),
                "over": "rocks that reached each bin; height of the centre above "
                "the ground, vertical",
            },
            "statistics": STATISTICS_NOTE,
            "model": {
                "source": str(getattr(model, "source", "")),
                "effects": dict(getattr(model, "effects", {}) or {}),
                "core": dict(getattr(model, "core", {}) or {}),
                "provenance": dict(getattr(model, "provenance", {}) or {}),
            },
        }


#: Short names of the final states in ``summary.json``.
_STATE_KEYS = {
    STOPPED: "stopped",
    EXITED_DOWNSLOPE: "exited_downslope",
    EXITED_UPSLOPE: "exited_upslope",
    MAX_IMPACTS: "capped",
}

#: What capped rocks mean for the user, stated in ``summary.json``.
CAPPED_NOTE = (
    "capped rocks were still moving when they reached the model's core.max_impacts "
    "impacts; x_m is where they were then, not where they would stop (their runout "
    "is at least that). They are neither stopped nor run out: left out of "
    "runout_x_m; runout_bounds_x_m says how far that can move each percentile. "
    "Raise core.max_impacts in the model file (up to 1e6) to follow them further."
)

#: What the rocks that left the profile mean for the runout, in ``summary.json``.
CENSORED_NOTE = (
    "rocks that left the profile at its lower end (end_x_m) ran out at least that "
    "far; where they would stop is unknown. fraction is over the rocks in "
    "runout_x_m. runout_x_m.lower_bound flags each statistic that uses them: it is "
    "only a lower bound (read p95 = 700 with lower_bound.p95 true as p95 >= 700 m). "
    "Extend the profile past where the rocks stop to measure those percentiles."
)

#: How the standard errors are computed, stated in ``summary.json``.
STATISTICS_NOTE = (
    "se = Monte Carlo standard error. Percentiles: numpy linear interpolation; SE = "
    "half the order-statistic interval of ranks n p +/- sqrt(n p (1-p)) "
    "(distribution-free; Conover 1999 s3.2). Mean: s/sqrt(n). Max: exact bootstrap "
    "SE (closed form over the order statistics, no resampling; a lower bound). "
    "Fractions: sqrt(p (1-p) / n). Analysis-point statistics are over the rocks that "
    "crossed the point."
)


def _runout_bounds(
    runout: np.ndarray, capped: np.ndarray, left: np.ndarray, model
) -> dict:
    """Bounds on the runout percentiles of all rocks, capped ones included.

    A capped rock's runout is unknown but at least where it was when capped and at
    most the profile's lower end: the percentiles with every capped rock put there
    (``lower``) and put at the end (``upper``) bracket the true ones. Equal when no
    rock was capped. A rock that left the profile (``left``), and in ``upper`` a
    capped rock put at the end, ran out at least that far: ``lower_bound`` flags the
    percentiles that use one (:func:`fieldkit.model.statistics.lower_bounds`).
    """
    keys = ("p50", "p90", "p95", "p99", "max")
    lower = distribution(runout, at_least=left)
    end = runout.copy()
    x_end = _profile_end(model)
    end[capped] = x_end if x_end is not None else np.inf
    upper = distribution(end, at_least=left | capped)

    def part(d: dict) -> dict:
        out = {k: d[k] for k in keys}
        out["lower_bound"] = {k: d["lower_bound"][k] for k in keys}
        return out

    return {
        "lower": part(lower),
        "upper": part(upper),
        "over": "all rocks; capped rocks where they were when capped (lower) or at "
        "the profile's lower end (upper); lower_bound: the percentile uses rocks "
        "that left the profile, so it is at least that",
    }


def _profile_end(model) -> float | None:
    """The profile's lower end x [m] (None for a model without a profile)."""
    x = getattr(getattr(model, "profile", None), "x_m", None)
    return float(np.max(x)) if x is not None and np.size(x) else None


def _floats(values: np.ndarray) -> list[float | None]:
    return [float(v) if np.isfinite(v) else None for v in np.asarray(values, float)]


def readable(value: float, digits: int = 3) -> str:
    """``value`` to ``digits`` significant digits but every integer digit kept, in
    plain notation with thousands separators (``1,768``, never ``1.8e+03``).

    Examples
    --------
    >>> readable(1768.4), readable(46.48), readable(160.0, 2), readable(0.0037, 2)
    ('1,768', '46.5', '160', '0.0037')
    """
    if not np.isfinite(value) or value == 0:
        return f"{value:g}"
    rounded = float(f"{value:.{digits}g}")  # 9.996 -> 10.0: one decimal fewer
    decimals = max(digits - 1 - int(np.floor(np.log10(abs(rounded)))), 0)
    return f"{value:,.{decimals}f}"


def rank_words(
    rank: dict, scale: float = 1.0, unit: str = "", decimals: int = 1
) -> str:
    """A measured value's place among the simulated rocks, in words.

    ``rank`` is :func:`fieldkit.model.statistics.rank_of`'s answer (values times
    ``scale`` are in ``unit``): "percentile 26.4 ± 1.0", or beyond every rock "above
    all 1,999 simulated rocks (their maximum 61.4 m/s)", or "no simulated rocks".

    Examples
    --------
    >>> rank_words({"n": 1999, "percentile": None, "beyond": "above",
    ...             "simulated_max": 61.41, "simulated_min": 0.3}, 1.0, "m/s")
    'above all 1,999 simulated rocks (their maximum 61.4 m/s)'
    """
    if not rank.get("n"):
        return "no simulated rocks"
    beyond = rank.get("beyond")
    if beyond is not None:
        extreme = "maximum" if beyond == "above" else "minimum"
        value = rank["simulated_max" if beyond == "above" else "simulated_min"]
        return (
            f"{beyond} all {rank['n']:,} simulated rocks (their {extreme} "
            f"{readable(value * scale)} {unit})".replace(" )", ")")
        )
    return (
        f"percentile {rank['percentile']:.{decimals}f} ± "
        f"{rank['percentile_se']:.{decimals}f}"
    )


def censored_words(fraction: float) -> str:
    """Why a runout statistic is a lower bound: "end of profile; 71 % of rocks left
    it" (``fraction`` of the rocks in the runout statistics left the profile)."""
    return f"end of profile; {100.0 * fraction:.0f} % of rocks left it"
