"""Profile intervals of a path fit, with the objective's run-to-run (seed) spread.

The slice of :mod:`fieldkit.fit.path_fit` moves one parameter with the others held
at the optimum; where parameters trade off (a higher e_n with a lower e_t) it is too
narrow. The *profile* re-optimises the others: for a value :math:`v` of parameter
:math:`j`,

.. math:: P_j(v) = \\min_{\\theta_{-j}} S(v, \\theta_{-j}),
          \\qquad \\Delta_j(v) = P_j(v) - S(\\hat\\theta),

minimised by a short Nelder-Mead (:func:`profile_evaluations`: 6 per other
parameter, a budget that keeps a 5-parameter profile near half the fit's own cost)
from the previous profile point's solution (the walk starts at the optimum and goes
outward, so each start is close). A short search can stop above the true minimum:
the excess is then overstated and the interval too narrow, never too wide. The
grid is ``points`` values evenly across the bounds; on each side of the optimum
the walk stops at the first incompatible grid value and the end is refined by
:data:`PROFILE_BISECTIONS` bisections between it and the last compatible value (as
the slice's ends are).

**Compatible.** :math:`\\Delta_j(v)` is estimated with two independent errors:

* which values were observed: the stratified standard error over the objective's
  units of the paired difference :math:`S_u(v, \\hat\\theta_{-j}(v)) - S_u(\\hat
  \\theta)` (the slice's ``se_obs``);
* which rocks were simulated: the same two parameter vectors scored with ``seeds``
  other seeds of the common random numbers (new rocks, :attr:`PathObjective.seed`
  = ``seed +`` :data:`PROFILE_SEED_OFFSET` ``+ k``) give paired excesses whose SD is
  ``sd_seed``. The fit's own seed is one draw of this spread: the profile minimised
  over the others at that seed, and the optimum itself, are tuned to its rocks, so
  a value is rejected by a difference the next seed would not repeat unless this
  term is in the threshold.

A value is compatible when :math:`\\Delta_j(v) \\le z_{0.95} \\sqrt{se_{obs}^2 +
sd_{seed}^2}` (one-sided 5 %, :math:`z` = 1.645, the slice's test with the seed term
added: the two errors are independent, so their variances add). The SD over
``seeds`` of :math:`S(\\hat\\theta)` itself is reported too: how much of the
objective at the optimum is Monte Carlo noise.

With one run the observations of its path are not independent, so ``se_obs`` (like
the bootstrap) is a lower bound and so is the interval.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

#: Normal quantile of a one-sided 5 % test (the slice's).
Z90 = 1.6448536269514722
#: Bisections refining each end of the profile's compatible range (1/4 of a grid
#: step): each is a re-optimisation, so fewer than the slice's.
PROFILE_BISECTIONS = 2
#: Offset of the profile's seeds from the fit's seed (the bootstrap uses seed + 1
#: to seed + 1,000).
PROFILE_SEED_OFFSET = 1_000_003
#: Fewest seeds that give an SD (``seeds`` = 0 leaves the seed term out, stated).
MIN_PROFILE_SEEDS = 2
MAX_PROFILE_SEEDS = 100
MAX_PROFILE_POINTS = 101


def profile_evaluations(p: int) -> int:
    """Default evaluations of one profile point's re-optimisation of ``p - 1``
    parameters (0 with one free parameter: nothing to re-optimise).

    Examples
    --------
    >>> profile_evaluations(1), profile_evaluations(5)
    (0, 24)
    """
    return 0 if p <= 1 else 6 * (p - 1)


@dataclass
class PathProfile:
    """Profile of each free parameter (module docstring)."""

    names: list[str]
    interval90: np.ndarray  # (p, 2) values the data cannot tell from the optimum
    grid: list[np.ndarray]  # per parameter: the values profiled (sorted)
    excess: list[np.ndarray]  # Delta_j at each, at the fit's seed
    se_obs: list[np.ndarray]  # stratified SE over observations of each
    sd_seed: list[np.ndarray]  # SD of the paired excess over the seeds
    optimum_seed_values: np.ndarray  # S(theta_hat) at each of the seeds
    objective_optimum: float  # S(theta_hat) at the fit's seed
    seeds: int
    points: int
    evaluations_per_point: int
    evaluations: int
    wall_s: float
    widest: list[str] | None = None  # per parameter: bootstrap, slice or profile

    @property
    def optimum_seed_sd(self) -> float:
        """SD over the seeds of the objective at the optimum (NaN: too few seeds)."""
        v = self.optimum_seed_values
        return float(np.std(v, ddof=1)) if v.size >= MIN_PROFILE_SEEDS else math.nan

    def to_dict(self) -> dict:
        """JSON-ready (the ``profile`` entry of a path fit's summary)."""

        def num(x) -> float | None:
            return float(x) if math.isfinite(x) else None

        sd = self.optimum_seed_sd
        return {
            "method": (
                "others re-optimised (Nelder-Mead) at each value; compatible when the "
                f"excess over the optimum <= {Z90:.3f} sqrt(se_obs^2 + sd_seed^2): "
                "se_obs the stratified SE over observations, sd_seed the SD of the "
                f"paired excess over {self.seeds} other seeds (new rocks)"
            ),
            "points": self.points,
            "seeds": self.seeds,
            "evaluations_per_point": self.evaluations_per_point,
            "evaluations": self.evaluations,
            "wall_s": self.wall_s,
            "objective_optimum": self.objective_optimum,
            "optimum_seed_sd": num(sd),
            "optimum_seed_values": [float(v) for v in self.optimum_seed_values],
            "parameters": [
                {
                    "name": n,
                    "interval90": [float(a), float(b)],
                    "widest": None if self.widest is None else self.widest[j],
                    "curve": {
                        "value": [float(v) for v in self.grid[j]],
                        "excess": [float(v) for v in self.excess[j]],
                        "se_obs": [float(v) for v in self.se_obs[j]],
                        "sd_seed": [num(v) for v in self.sd_seed[j]],
                    },
                }
                for j, (n, (a, b)) in enumerate(
                    zip(self.names, self.interval90, strict=True)
                )
            ],
        }


def seed_values(
    objective, xs: Sequence[np.ndarray], seeds: Sequence[int]
) -> np.ndarray:
    """``(len(seeds), len(xs))`` objective sums of each ``x`` with each seed.

    ``objective`` has a settable ``seed`` and ``units(x)`` (a
    :class:`~fieldkit.fit.path_fit.PathObjective`); its seed is restored.
    """
    keep = objective.seed
    out = np.empty((len(seeds), len(xs)))
    try:
        for k, s in enumerate(seeds):
            objective.seed = int(s)
            for i, x in enumerate(xs):
                out[k, i] = float(np.sum(objective.units(np.asarray(x, float))))
    finally:
        objective.seed = keep
    return out


def paired_seed_sd(at_x: np.ndarray, at_optimum: np.ndarray) -> float:
    """SD over seeds of the paired excess ``S_k(x) - S_k(optimum)`` (NaN: fewer
    than :data:`MIN_PROFILE_SEEDS` seeds).

    Examples
    --------
    >>> paired_seed_sd(np.array([2.0, 3.0, 4.0]), np.array([1.0, 2.0, 3.0]))
    0.0
    """
    d = np.asarray(at_x, float) - np.asarray(at_optimum, float)
    return float(np.std(d, ddof=1)) if d.size >= MIN_PROFILE_SEEDS else math.nan


def stratified_se(diff: np.ndarray, strata: Sequence[np.ndarray]) -> float:
    """Standard error of ``diff.sum()`` with units i.i.d. within each stratum."""
    var = 0.0
    for stratum in strata:
        if stratum.size > 1:
            var += stratum.size * float(np.var(diff[stratum], ddof=1))
    return math.sqrt(var)


def profile_objective(
    objective,
    x_best: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    *,
    points: int,
    seeds: int,
    evaluations: int | None = None,
    advance: Callable[[int, int], None] | None = None,
    inner: np.ndarray | None = None,
) -> PathProfile:
    """Profile every parameter of ``objective`` about ``x_best`` (module docstring).

    Parameters
    ----------
    objective
        A :class:`~fieldkit.fit.path_fit.PathObjective` (its ``seed`` is the fit's;
        ``units``, ``strata``, ``evaluations`` are used).
    x_best
        The optimum.
    lower, upper
        The search bounds.
    points
        Grid values across each bound range (at least 2).
    seeds
        Other seeds of the seed spread (0: no seed term).
    evaluations
        Evaluations of each point's re-optimisation (default
        :func:`profile_evaluations`).
    advance
        Called with (parameters done, parameters) after each parameter.
    inner
        ``(p, 2)`` ranges known compatible (the slice's: a value the data cannot
        tell from the optimum with the others *held* cannot be told from it with
        them re-optimised, whose excess is no larger, nor with the seed term, which
        only raises the threshold); each side's walk starts at its end, so the
        profile contains it and resolves what lies beyond.

    Returns
    -------
    PathProfile
    """
    t0 = time.perf_counter()
    e0 = objective.evaluations
    x_best = np.asarray(x_best, float)
    p = x_best.size
    span = upper - lower
    budget = profile_evaluations(p) if evaluations is None else int(evaluations)
    seed_list = [objective.seed + PROFILE_SEED_OFFSET + k for k in range(seeds)]
    best_units = objective.units(x_best)
    f_best = float(np.sum(best_units))
    at_best = seed_values(objective, [x_best], seed_list)[:, 0]

    def point(j: int, value: float, others: np.ndarray) -> tuple:
        """(excess, se_obs, sd_seed, the others' best unit values) at ``value``."""
        rest = [k for k in range(p) if k != j]

        def full(u_rest: np.ndarray) -> np.ndarray:
            x = x_best.copy()
            x[j] = value
            x[rest] = lower[rest] + span[rest] * np.clip(u_rest, 0.0, 1.0)
            return x

        u_rest = (others - lower[rest]) / span[rest]
        if rest and budget > 0:
            u_rest = _minimise(
                lambda u: float(np.sum(objective.units(full(u)))), u_rest, budget
            )
        x = full(u_rest)
        diff = objective.units(x) - best_units
        sd = paired_seed_sd(seed_values(objective, [x], seed_list)[:, 0], at_best)
        return float(diff.sum()), stratified_se(diff, objective.strata), sd, x[rest]

    def compatible(excess: float, se: float, sd: float) -> bool:
        return excess <= Z90 * math.hypot(se, 0.0 if math.isnan(sd) else sd)

    interval = np.empty((p, 2))
    grids, excesses, ses, sds = [], [], [], []
    for j in range(p):
        rest = [k for k in range(p) if k != j]
        curve = {float(x_best[j]): (0.0, 0.0, 0.0)}
        grid = np.linspace(lower[j], upper[j], points)
        ends = []
        known = (x_best[j], x_best[j]) if inner is None else inner[j]
        for outward, first in ((grid[grid < known[0]][::-1], known[0]),
                               (grid[grid > known[1]], known[1])):  # fmt: skip
            good, others = float(first), x_best[rest]
            end = good
            for v in outward:
                e, se, sd, o = point(j, float(v), others)
                curve[float(v)] = (e, se, sd)
                if compatible(e, se, sd):
                    good, others, end = float(v), o, float(v)
                    continue
                bad = float(v)
                for _ in range(PROFILE_BISECTIONS):
                    mid = 0.5 * (good + bad)
                    e, se, sd, o = point(j, mid, others)
                    curve[mid] = (e, se, sd)
                    if compatible(e, se, sd):
                        good, others = mid, o
                    else:
                        bad = mid
                end = good
                break
            ends.append(end)
        interval[j] = ends[0], ends[1]
        values = np.array(sorted(curve))
        rows = np.array([curve[v] for v in values]).reshape(-1, 3)
        grids.append(values)
        excesses.append(rows[:, 0])
        ses.append(rows[:, 1])
        sds.append(rows[:, 2])
        if advance is not None:
            advance(j + 1, p)
    return PathProfile(
        names=list(getattr(objective, "names", [str(j) for j in range(p)])),
        interval90=interval,
        grid=grids,
        excess=excesses,
        se_obs=ses,
        sd_seed=sds,
        optimum_seed_values=at_best,
        objective_optimum=f_best,
        seeds=int(seeds),
        points=int(points),
        evaluations_per_point=budget,
        evaluations=objective.evaluations - e0,
        wall_s=time.perf_counter() - t0,
    )


def _minimise(f: Callable[[np.ndarray], float], u0: np.ndarray, budget: int):
    """Short Nelder-Mead in the unit cube from ``u0`` (a small simplex)."""
    u0 = np.clip(np.asarray(u0, float), 0.0, 1.0)
    simplex = np.tile(u0, (u0.size + 1, 1))
    for k in range(u0.size):
        simplex[k + 1, k] += 0.05 if u0[k] + 0.05 <= 1.0 else -0.05
    res = minimize(
        f,
        u0,
        method="Nelder-Mead",
        bounds=[(0.0, 1.0)] * u0.size,
        options={"initial_simplex": simplex, "maxfev": max(budget, u0.size + 2),
                 "xatol": 2e-3, "fatol": 1e-4},
    )  # fmt: skip
    # u0 is a vertex of the initial simplex: the result is never worse than it
    return np.clip(res.x, 0.0, 1.0)
