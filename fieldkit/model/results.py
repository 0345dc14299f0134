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
from fieldkit.model.statistics import distribution, envelope_percentiles, fraction_se

if TYPE_CHECKING:  # the Model type is only named in annotations
    from fieldkit.model.model_file import Model

#: Final state of a rock (``SimulationResult.state``).
STOPPED, EXITED_DOWNSLOPE, EXITED_UPSLOPE, MAX_IMPACTS = 0, 1, 2, 3
STATE_NAMES = {
    STOPPED: "stopped on the profile",
    EXITED_DOWNSLOPE: "left the profile at its lower end",
    EXITED_UPSLOPE: "left the profile at its upper end",
    MAX_IMPACTS: "reached the impact limit",
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
    wall_s: float  # kernel time only [s]
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

    def summary(self) -> dict:
        """What a designer reads: the ``summary.json`` contract (architecture §4).

        ``rocks``, ``impacts``, ``wall_s`` (simulation only), ``seed``,
        ``runout_x_m`` and, per analysis point, ``passing_fraction`` and the
        distributions of ``speed_mps``, ``ke_j``, ``re_j``, ``total_j`` and
        ``bounce_height_m`` over the rocks that crossed it. Every distribution holds
        ``n``, ``mean``, ``p50``, ``p90``, ``p95``, ``p99``, ``max`` and ``se`` (their
        Monte Carlo standard errors; :mod:`fieldkit.model.statistics` says how each
        is computed). Fractions carry ``*_se`` (binomial). Also: the final states,
        the envelope, and the model's source, active effects and core settings.
        """
        n = int(self.rocks)
        state = np.asarray(self.state)
        stopped, stopped_se = fraction_se(int((state == STOPPED).sum()), n)
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
            "seed": self.seed,
            "runout_x_m": distribution(np.asarray(self.runout_x_m, float)),
            "stopped_fraction": stopped,
            "stopped_fraction_se": stopped_se,
            "final_state": {
                name: int((state == code).sum()) for code, name in _STATE_KEYS.items()
            },
            "analysis_points": points,
            "envelope": {
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
    MAX_IMPACTS: "max_impacts",
}

#: How the standard errors are computed, stated in ``summary.json``.
STATISTICS_NOTE = (
    "se = Monte Carlo standard error. Percentiles: numpy linear interpolation; SE = "
    "half the order-statistic interval of ranks n p +/- sqrt(n p (1-p)) "
    "(distribution-free; Conover 1999 s3.2). Mean: s/sqrt(n). Max: exact bootstrap "
    "SE (closed form over the order statistics, no resampling; a lower bound). "
    "Fractions: sqrt(p (1-p) / n). Analysis-point statistics are over the rocks that "
    "crossed the point."
)


def _floats(values: np.ndarray) -> list[float | None]:
    return [float(v) if np.isfinite(v) else None for v in np.asarray(values, float)]
