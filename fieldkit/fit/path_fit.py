"""Path-level fit: simulator parameters that make observed runouts likely.

Each observed run (:class:`~fieldkit.fit.path_runs.PathRun`) is simulated on its own
section with ``rocks`` rocks; the objective is the mean over runs of the CRPS of the
observed runout against the simulated ensemble (:func:`~fieldkit.fit.holdout.
crps_ensemble`; a proper scoring rule, so its expectation is smallest at the true
parameters for location *and* spread, Gneiting & Raftery 2007),

.. math:: S(\\theta) = \\frac1N \\sum_{r=1}^N \\mathrm{CRPS}(F_{r,\\theta}, y_r).

Common random numbers: run ``r`` is always simulated with
``default_rng([seed, r])`` (:func:`~fieldkit.fit.path_runs.simulated_runouts`), so
:math:`S` is a deterministic function of the parameters for a seed (changing by
steps where a rock's sequence of contacts changes, otherwise continuously).

Search: derivative-free Nelder-Mead (scipy, with bounds) in the unit cube of the
practical bounds (:data:`PRACTICAL_BOUNDS`, the effects' own bounds, or the caller's),
from the base model's values, restarted once from its best point with a fresh small
simplex (the usual guard against a collapsed simplex). Nelder-Mead rather than a
Bayesian optimiser: with 1-4 parameters and an evaluation of tens of milliseconds it
converges in ~100 evaluations, needs no extra dependency, and the bootstrap below
needs many cheap local refits, which it does well.

Uncertainty: a bootstrap over runs (Efron & Tibshirani 1993, ch. 6): the runs are
resampled with replacement ``bootstrap`` times (equivalently, integer weights on the
per-run CRPS) and the fit is repeated from the optimum with a short budget. The
standard error of a parameter is the SD of its bootstrap values; the 90 % interval is
``value ± 1.645 SE`` clipped to the bounds; the correlation matrix is that of the
bootstrap values. A flat direction gives no bootstrap spread (each refit stays where
it starts), so the objective is also sliced across each parameter's bound range (the
others at the optimum, ``slice_points`` points): a point whose paired mean CRPS
excess over the runs is below 1.645 times its standard error is compatible with the
data, and the interval is widened to include every compatible point. A parameter is
reported as *not pinned down* when its interval spans more than
:data:`WIDE_FRACTION` of its bound range, or when its bootstrap correlation with
another parameter exceeds :data:`CORRELATION_LIMIT` in size.

References
----------
Efron, B., Tibshirani, R. J. (1993). An Introduction to the Bootstrap. Chapman & Hall.
Gneiting, T., Raftery, A. E. (2007). Strictly proper scoring rules, prediction, and
estimation. JASA 102(477), 359-378.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

from fieldkit.errors import ArgumentError
from fieldkit.fit.holdout import crps_ensemble
from fieldkit.fit.path_runs import PathRun, one_kernel_thread, simulated_runouts
from fieldkit.model.effects import registry
from fieldkit.model.materials import MATERIAL_FIELDS
from fieldkit.model.model_file import CORE_DEFAULTS, Model

#: Finite search bounds of material fields (MATERIAL_FIELDS allows [0, inf) for
#: most): restitution coefficients over the range thesis Table 7-1 uses and a
#: margin (e_n up to 1.0 on Tornado Mountain's colluvium, with RocFall's velocity
#: scaling; e_t 0.5-0.95), SDs up to what RocFall users enter at most, friction
#: 5-60 deg, CRSP roughness up to 1 m.
PRACTICAL_BOUNDS: dict[str, tuple[float, float]] = {
    "e_n": (0.02, 1.2),
    "e_t": (0.1, 1.0),
    "friction_deg": (5.0, 60.0),
    "e_n_sd": (0.0, 0.2),
    "e_t_sd": (0.0, 0.2),
    "friction_deg_sd": (0.0, 15.0),
    "roughness_m": (0.0, 1.0),
    "roughness_deg_sd": (0.0, 20.0),
}
#: Interval / bound range above which a parameter is "not pinned down".
WIDE_FRACTION = 0.5
#: |bootstrap correlation| above which a pair is "not separately pinned down".
CORRELATION_LIMIT = 0.95
#: Normal quantile of a central 90 % interval.
Z90 = 1.6448536269514722
#: Seed offset of the bootstrap's resampling stream (default_rng([seed, this])).
BOOTSTRAP_STREAM = 7_919


def parameter_bounds(name: str) -> tuple[float, float]:
    """Finite search bounds of a namespaced parameter (module docstring).

    Raises
    ------
    ArgumentError
        ``body.*`` (each run has its own block) or a parameter without finite
        bounds (give ``bounds=`` to :func:`fit_paths`).

    Examples
    --------
    >>> parameter_bounds("materials.talus.e_t")
    (0.1, 1.0)
    >>> parameter_bounds("rotation_friction.friction")
    (0.0, 2.0)
    """
    parts = name.split(".")
    if parts[0] == "materials" and len(parts) == 3 and parts[2] in MATERIAL_FIELDS:
        lo, hi = PRACTICAL_BOUNDS[parts[2]]
        flo, fhi = MATERIAL_FIELDS[parts[2]][:2]
        return max(lo, flo), min(hi, fhi)
    if parts[0] == "core" and len(parts) == 2 and parts[1] in CORE_DEFAULTS:
        return CORE_DEFAULTS[parts[1]][1:3]
    if parts[0] == "body":
        raise ArgumentError(
            f"{name}: the block is each run's own, not a fitted parameter",
            source="free",
        )
    if len(parts) == 2 and parts[0] in registry.BY_NAME:
        p = registry.BY_NAME[parts[0]].parameter(parts[1])
        if math.isfinite(p.lower) and math.isfinite(p.upper):
            return float(p.lower), float(p.upper)
    raise ArgumentError(
        f"{name}: no finite search bounds known; give bounds={{'{name}': (lo, hi)}}",
        source="free",
    )


class PathObjective:
    """Per-run CRPS of observed runouts against simulated ensembles.

    Runs with a non-finite observed runout are left out; run ``runs[i]`` always uses
    the common random numbers ``default_rng([seed, i])``.

    Parameters
    ----------
    runs
        The observed runs.
    names
        Namespaced parameters (as in :meth:`Model.parameters`) set on every run's
        model (a run whose model lacks one, e.g. a material it never crosses, is
        simulated without it).
    rocks, seed
        Rocks per run, and the seed of the common random numbers.
    """

    def __init__(
        self, runs: Sequence[PathRun], names: Sequence[str], rocks: int, seed: int
    ):
        self.runs = [r for r in runs if math.isfinite(r.observed_runout_m)]
        self.index = [
            i for i, r in enumerate(runs) if math.isfinite(r.observed_runout_m)
        ]
        if not self.runs:
            raise ArgumentError("no run has an observed runout", source="runs")
        self.names = list(names)
        self.rocks = int(rocks)
        self.seed = int(seed)
        self.observed = np.array([r.observed_runout_m for r in self.runs], float)
        self._keys = [set(r.model.parameters()) for r in self.runs]
        self.evaluations = 0

    def ensembles(self, values: dict[str, float]) -> list[np.ndarray]:
        """Simulated runouts of every (observed) run with ``values`` set."""
        out = []
        with one_kernel_thread():
            for run, i, keys in zip(self.runs, self.index, self._keys, strict=True):
                mine = {k: v for k, v in values.items() if k in keys}
                model = run.model.with_parameters(mine) if mine else run.model
                out.append(simulated_runouts(run, model, self.rocks, self.seed, i))
        return out

    def per_run(self, x: np.ndarray) -> np.ndarray:
        """CRPS [m] of each run at parameter vector ``x`` (order of ``names``)."""
        values = dict(zip(self.names, map(float, x), strict=True))
        self.evaluations += 1
        return np.array(
            [
                crps_ensemble(e, y)
                for e, y in zip(self.ensembles(values), self.observed, strict=True)
            ]
        )

    def __call__(self, x: np.ndarray) -> float:
        """Mean CRPS [m] over runs at ``x``."""
        return float(np.mean(self.per_run(x)))


@dataclass
class PathFitResult:
    """Result of :func:`fit_paths` (see the module docstring)."""

    names: list[str]
    values: np.ndarray
    stderr: np.ndarray
    interval90: np.ndarray  # (p, 2)
    start: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    correlation: np.ndarray
    compatible: np.ndarray  # (p, 2) slice range the runs cannot tell apart
    pinned: list[bool]
    objective_start: float
    objective_optimum: float
    run_crps: np.ndarray  # per observed run, at the optimum
    run_ids: list[str]
    n_runs: int
    n_evaluations: int
    wall_s: float
    rocks: int
    seed: int
    bootstrap: np.ndarray  # (B, p) refitted values
    model: Model
    notes: list[str] = field(default_factory=list)

    def value(self, name: str) -> float:
        """The fitted value of ``name``."""
        return float(self.values[self.names.index(name)])

    def error(self, name: str) -> float:
        """The bootstrap standard error of ``name``."""
        return float(self.stderr[self.names.index(name)])

    def interval(self, name: str) -> tuple[float, float]:
        """The 90 % interval of ``name``."""
        lo, hi = self.interval90[self.names.index(name)]
        return float(lo), float(hi)

    def to_dict(self) -> dict:
        """JSON-ready summary (no model; write that with ``write_model``)."""
        return {
            "parameters": [
                {
                    "name": n,
                    "value": float(v),
                    "stderr": float(s),
                    "interval90": [float(a), float(b)],
                    "start": float(s0),
                    "bounds": [float(lo), float(hi)],
                    "pinned": bool(p),
                }
                for n, v, s, (a, b), s0, lo, hi, p in zip(
                    self.names,
                    self.values,
                    self.stderr,
                    self.interval90,
                    self.start,
                    self.lower,
                    self.upper,
                    self.pinned,
                    strict=True,
                )
            ],
            "correlation": self.correlation.tolist(),
            "slice_compatible": self.compatible.tolist(),
            "objective": "mean CRPS of observed runouts [m]",
            "objective_start": self.objective_start,
            "objective_optimum": self.objective_optimum,
            "runs": [
                {"path_id": i, "crps_m": float(c)}
                for i, c in zip(self.run_ids, self.run_crps, strict=True)
            ],
            "n_runs": self.n_runs,
            "n_evaluations": self.n_evaluations,
            "wall_s": self.wall_s,
            "rocks": self.rocks,
            "seed": self.seed,
            "bootstrap_size": int(self.bootstrap.shape[0]),
            "notes": list(self.notes),
        }


def _simplex(u0: np.ndarray, step: float) -> np.ndarray:
    """Initial simplex around ``u0`` in the unit cube (steps turned inwards)."""
    p = u0.size
    simplex = np.tile(u0, (p + 1, 1))
    for j in range(p):
        simplex[j + 1, j] += step if u0[j] + step <= 1.0 else -step
    return simplex


def _minimise(
    f: Callable[[np.ndarray], float], u0: np.ndarray, step: float, budget: int
) -> tuple[np.ndarray, float, int]:
    """Nelder-Mead in the unit cube from ``u0``; (best u, best f, evaluations)."""
    res = minimize(
        f,
        u0,
        method="Nelder-Mead",
        bounds=[(0.0, 1.0)] * u0.size,
        options={
            "initial_simplex": _simplex(u0, step),
            "maxfev": max(budget, u0.size + 2),
            "xatol": 2e-3,
            "fatol": 1e-4,
        },
    )
    return np.clip(res.x, 0.0, 1.0), float(res.fun), int(res.nfev)


def fit_paths(
    runs: Sequence[PathRun],
    base_model: Model,
    free: Sequence[str],
    *,
    rocks: int = 200,
    seed: int = 0,
    progress: Callable[[str], None] | None = None,
    bootstrap: int = 40,
    bounds: dict[str, tuple[float, float]] | None = None,
    start: dict[str, float] | None = None,
    max_evaluations: int | None = None,
    bootstrap_evaluations: int | None = None,
    slice_points: int = 9,
) -> PathFitResult:
    """Fit the ``free`` parameters to the observed runouts of ``runs``.

    Parameters
    ----------
    runs
        Observed runs, each on its own section (runs without an observed runout are
        left out).
    base_model
        The model the parameters start from (its values, unless ``start``) and
        that is calibrated (``result.model``).
    free
        Namespaced parameter names (``materials.<m>.e_t``, ``<effect>.<param>``,
        ``core.<k>``).
    rocks
        Rocks simulated per run and evaluation.
    seed
        Seed of the common random numbers (and, offset, of the bootstrap).
    progress
        Called with one line per stage and every 25 evaluations.
    bootstrap
        Bootstrap resamples of the runs (0: no uncertainty, SE NaN).
    bounds
        Search bounds overriding :func:`parameter_bounds`.
    start
        Start values overriding the base model's (clipped into the bounds).
    max_evaluations, bootstrap_evaluations
        Objective evaluations of the main search (default ``max(150, 60 p)``) and
        of each bootstrap refit (default ``20 p + 10``).
    slice_points
        Points of the objective's slice across each parameter's bound range (module
        docstring).

    Returns
    -------
    PathFitResult
    """
    t0 = time.perf_counter()
    say = progress or (lambda _msg: None)
    names = list(free)
    if not names:
        raise ArgumentError("no free parameters", source="free")
    known = base_model.parameters()
    for name in names:
        if name not in known:
            raise ArgumentError(
                f"unknown parameter {name} (known: {', '.join(known)})", source="free"
            )
    bounds = dict(bounds or {})
    lower = np.array([bounds.get(n, parameter_bounds(n))[0] for n in names], float)
    upper = np.array([bounds.get(n, parameter_bounds(n))[1] for n in names], float)
    if np.any(~(upper > lower)):
        raise ArgumentError("every upper bound must exceed its lower", source="bounds")
    start = dict(start or {})
    x0 = np.array([start.get(n, known[n]) for n in names], float)
    notes = []
    clipped = np.clip(x0, lower, upper)
    for n, a, b in zip(names, x0, clipped, strict=True):
        if a != b:
            notes.append(f"start of {n} ({a:g}) moved into its bounds ({b:g})")
    x0 = clipped
    span = upper - lower
    p = len(names)
    objective = PathObjective(runs, names, rocks, seed)
    n_runs = len(objective.runs)
    if n_runs < len(runs):
        notes.append(f"{len(runs) - n_runs} runs without an observed runout left out")

    def to_x(u):
        return lower + span * np.clip(u, 0.0, 1.0)

    weights = np.ones(n_runs)

    def f(u):
        crps = objective.per_run(to_x(u))
        if objective.evaluations % 25 == 0:
            say(f"  {objective.evaluations} evaluations")
        return float(np.dot(weights, crps) / weights.sum())

    u0 = (x0 - lower) / span
    f0 = f(u0)
    say(f"fit {p} parameters to {n_runs} runs ({rocks} rocks each): start {f0:.3f} m")
    budget = max_evaluations or max(150, 60 * p)
    u1, f1, n1 = _minimise(f, u0, 0.15, int(budget * 0.7))
    u2, f2, _ = _minimise(f, u1, 0.05, max(budget - n1, p + 2))
    u_best, f_best = (u2, f2) if f2 <= f1 else (u1, f1)
    x_best = to_x(u_best)
    say(f"optimum {f_best:.3f} m after {objective.evaluations} evaluations")
    run_crps = objective.per_run(x_best)
    at_bound = np.isclose(u_best, 0.0, atol=1e-3) | np.isclose(u_best, 1.0, atol=1e-3)
    for n, flag in zip(names, at_bound, strict=True):
        if flag:
            notes.append(f"{n} is at a search bound")

    rng = np.random.default_rng([seed, BOOTSTRAP_STREAM])
    short = bootstrap_evaluations or 20 * p + 10
    boot = np.empty((bootstrap, p))
    for b in range(bootstrap):
        weights = np.bincount(rng.integers(0, n_runs, n_runs), minlength=n_runs)
        weights = weights.astype(float)
        # Each resample also draws new simulated rocks: the fitted values carry
        # the Monte Carlo error of a finite ensemble, which a bootstrap over runs
        # with the optimum's own rocks would leave out.
        objective.seed = seed + 1 + b
        ub, _, _ = _minimise(f, u_best, 0.05, short)
        boot[b] = to_x(ub)
        if (b + 1) % 10 == 0:
            say(f"bootstrap {b + 1}/{bootstrap}")
    objective.seed = seed
    weights = np.ones(n_runs)
    if bootstrap >= 2:
        stderr = boot.std(axis=0, ddof=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            corr = np.corrcoef(boot.T) if p > 1 else np.ones((1, 1))
        corr = np.atleast_2d(np.nan_to_num(corr, nan=0.0))
        np.fill_diagonal(corr, 1.0)
    else:
        stderr = np.full(p, np.nan)
        corr = np.full((p, p), np.nan)
        notes.append("no bootstrap: no standard errors or intervals")
    # Slice of the objective across each bound range (others at the optimum): the
    # points the runs cannot tell from the optimum (paired mean CRPS difference
    # below Z90 times its SE over runs). A flat direction has no bootstrap spread
    # (every refit stays where it starts), so this is what reveals it.
    compatible = np.empty((p, 2))
    for j in range(p):
        grid = np.linspace(lower[j], upper[j], slice_points)
        ok = [x_best[j]]
        for value in grid:
            x = x_best.copy()
            x[j] = value
            diff = objective.per_run(x) - run_crps
            se = diff.std(ddof=1) / math.sqrt(n_runs) if n_runs > 1 else 0.0
            if diff.mean() <= Z90 * se:
                ok.append(value)
        compatible[j] = min(ok), max(ok)
    say(f"slices done after {objective.evaluations} evaluations")
    interval = np.column_stack(
        [
            np.clip(x_best - Z90 * stderr, lower, upper),
            np.clip(x_best + Z90 * stderr, lower, upper),
        ]
    )
    for j, n in enumerate(names):
        lo, hi = compatible[j]
        if lo < interval[j, 0] or hi > interval[j, 1]:
            notes.append(
                f"{n}: the objective's slice cannot tell [{lo:g}, {hi:g}] from the "
                f"optimum; its 90 % interval is widened to include it"
            )
            interval[j] = min(lo, interval[j, 0]), max(hi, interval[j, 1])
    pinned = []
    for j, n in enumerate(names):
        width = (interval[j, 1] - interval[j, 0]) / span[j]
        partners = [
            names[k] for k in range(p) if k != j and abs(corr[j, k]) > CORRELATION_LIMIT
        ]
        ok = bool(np.isfinite(width) and width <= WIDE_FRACTION and not partners)
        pinned.append(ok)
        if np.isfinite(width) and width > WIDE_FRACTION:
            notes.append(
                f"{n} not pinned down: its 90 % interval spans {width:.0%} of its "
                f"bound range [{lower[j]:g}, {upper[j]:g}]"
            )
        if partners:
            notes.append(
                f"{n} not separately pinned down: bootstrap correlation > "
                f"{CORRELATION_LIMIT} with {', '.join(partners)}"
            )
    model = base_model.with_parameters(
        dict(zip(names, map(float, x_best), strict=True))
    )
    return PathFitResult(
        names=names,
        values=x_best,
        stderr=stderr,
        interval90=interval,
        start=x0,
        lower=lower,
        upper=upper,
        correlation=corr,
        compatible=compatible,
        pinned=pinned,
        objective_start=f0,
        objective_optimum=float(np.mean(run_crps)),
        run_crps=run_crps,
        run_ids=[r.path_id for r in objective.runs],
        n_runs=n_runs,
        n_evaluations=objective.evaluations,
        wall_s=time.perf_counter() - t0,
        rocks=int(rocks),
        seed=int(seed),
        bootstrap=boot,
        model=model,
        notes=notes,
    )
