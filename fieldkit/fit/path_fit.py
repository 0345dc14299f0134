"""Path-level fit: simulator parameters that make observed paths likely.

Each observed run (:class:`~fieldkit.fit.path_runs.PathRun`) is simulated on its own
section with ``rocks`` rocks; the objective is the mean over runs of the CRPS of the
observed runout against the simulated ensemble (:func:`~fieldkit.fit.holdout.
crps_ensemble`; a proper scoring rule, so its expectation is smallest at the true
parameters for location *and* spread, Gneiting & Raftery 2007),

.. math:: S(\\theta) = \\frac1N \\sum_{r=1}^N \\mathrm{CRPS}(F_{r,\\theta}, y_r).

Where the runs carry observations along their paths (flight heights, impact
spacing, speeds at the impacts: :mod:`fieldkit.fit.path_along`), each observed value
is scored the same way and every kind weighs alike (:class:`PathObjective`): a
single surveyed path such as Tornado Mountain's boulder A is fitted on its 45
flights and impacts, not on its one runout.

Common random numbers: run ``r`` is always simulated with
``default_rng([seed, r])`` (:func:`~fieldkit.fit.path_runs.simulated_runouts`), so
:math:`S` is a deterministic function of the parameters for a seed (changing by
steps where a rock's sequence of contacts changes, otherwise continuously).

Search: derivative-free Nelder-Mead (scipy, with bounds) in the unit cube of the
practical bounds (:data:`PRACTICAL_BOUNDS`, the effects' own bounds, or the caller's),
from the base model's values -- and, with ``screen``, also from the best point of a
scrambled Sobol screen of the box when it beats them -- restarted once from the best
optimum with a fresh small simplex (the usual guard against a collapsed simplex).
Nelder-Mead rather than a Bayesian optimiser: with 1-4 parameters and an evaluation
of tens of milliseconds it converges in ~100 evaluations, needs no extra dependency,
and the bootstrap below needs many cheap local refits, which it does well.

Uncertainty: a bootstrap over runs (Efron & Tibshirani 1993, ch. 6): the runs are
resampled with replacement ``bootstrap`` times (equivalently, integer weights on the
per-run CRPS) and the fit is repeated from the optimum with a short budget. The
standard error of a parameter is the SD of its bootstrap values (with at least
:data:`MIN_BOOTSTRAP_SE` resamples; with fewer there is no standard error, no
correlation, and the interval is the slice below alone); the 90 % interval is
``value ± t SE`` clipped to the bounds (t: Student's 95 % quantile with one degree of
freedom fewer than the resampled units -- 1.761 for 15 runs -- since an SE from a
few runs is itself uncertain); the correlation matrix is that of the
bootstrap values. A flat direction gives no bootstrap spread (each refit stays where
it starts), so the objective is also sliced across each parameter's bound range (the
others at the optimum, ``slice_points`` points): a point whose paired mean CRPS
excess over the runs is below 1.645 times its standard error is compatible with the
data, and the interval is widened to include every compatible point. Each end of the
compatible range is then refined by :data:`SLICE_BISECTIONS` bisections between its
outermost compatible value and the next grid point out, so the range is two-sided
where the objective allows (the grid alone tests only its own points, and a coarse
one ends the range at the optimum itself). A parameter is reported as *not pinned
down* when its interval spans more than :data:`WIDE_FRACTION` of its bound range, or
when its bootstrap correlation with another parameter exceeds
:data:`CORRELATION_LIMIT` in size; when its interval is narrower than the slice
resolves (an objective kinked at the optimum: simulated ensembles with common random
numbers) there is no evidence either way, and ``pinned`` is None. With one run the
bootstrap resamples its observed values, which are not independent: the standard
errors and intervals are then lower bounds (:attr:`PathFitResult.
stderr_is_lower_bound`).

Beside the bootstrap and the slice, a *profile* of each parameter re-optimises the
others at each value and tests its excess against the observations' standard error
and the objective's run-to-run (seed) spread together
(:mod:`fieldkit.fit.path_profile`, ``profile_points``); it is reported beside the
90 % interval, not merged into it.

References
----------
Efron, B., Tibshirani, R. J. (1993). An Introduction to the Bootstrap. Chapman & Hall.
Gneiting, T., Raftery, A. E. (2007). Strictly proper scoring rules, prediction, and
estimation. JASA 102(477), 359-378.
"""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize
from scipy.stats import qmc
from scipy.stats import t as student_t

from fieldkit.errors import ArgumentError
from fieldkit.fit.holdout import crps_ensemble, crps_ensemble_many
from fieldkit.fit.impact_fit import check_realised_limit
from fieldkit.fit.path_along import (
    KINDS,
    AlongObservations,
    observed_along,
    simulated_along,
)
from fieldkit.fit.path_profile import (
    MAX_PROFILE_POINTS,
    MAX_PROFILE_SEEDS,
    MIN_PROFILE_SEEDS,
    PathProfile,
    profile_objective,
)
from fieldkit.fit.path_runs import PathRun, one_kernel_thread, simulated_runouts
from fieldkit.fit.plausibility import (
    REALISED_PENALTY,
    REALISED_TOLERANCE,
    realised_share_above,
)
from fieldkit.fit.suspect import SuspectCount, SuspectPolicy, policy_lines
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
#: Fewest bootstrap resamples that give a standard error and correlations: the SD of
#: B values is itself uncertain by about 1/sqrt(2 (B - 1)) of itself (24 % at 10,
#: 71 % at 2), and the correlation of 2 points is always +-1. Below it the fit states
#: no standard error, no correlation, and its 90 % interval is the objective's slice.
MIN_BOOTSTRAP_SE = 10
#: Bisections refining each end of a slice's compatible range between its last
#: compatible value and the next (rejected) grid point: the end is then known to
#: 1/64 of the grid step (1/512 of the bound range with 9 slice points).
SLICE_BISECTIONS = 6
#: Upper limits of the fit's sizes: every one of the hundreds of evaluations
#: simulates ``rocks`` rocks per run; each resample is a refit; each screen point an
#: evaluation.
MAX_ROCKS = 20_000
MAX_BOOTSTRAP = 1_000
MAX_SCREEN = 4_096
MAX_SEED = 2**32 - 1

#: ``step(description, total)``: a context manager yielding ``advance(done, total)``
#: (:func:`fieldkit.cli.progress.step` on the command line).
Step = Callable[[str, int | None], contextlib.AbstractContextManager]


@contextlib.contextmanager
def _no_step(description: str, total: int | None = None):
    yield lambda done, of: None


def check_settings(
    *,
    rocks: int,
    seed: int,
    bootstrap: int,
    screen: int,
    profile_points: int = 0,
    profile_seeds: int = MIN_PROFILE_SEEDS,
) -> None:
    """Refuse sizes the fit cannot use, before any work is done.

    Raises
    ------
    ArgumentError
        ``rocks`` not in 1..MAX_ROCKS, ``seed`` not in 0..MAX_SEED, ``bootstrap``
        not in 0..MAX_BOOTSTRAP, ``screen`` not in 0..MAX_SCREEN,
        ``profile_points`` not 0 or in 2..MAX_PROFILE_POINTS, ``profile_seeds`` not 0
        or in MIN_PROFILE_SEEDS..MAX_PROFILE_SEEDS (each names its argument and the
        limit).

    Examples
    --------
    >>> check_settings(rocks=200, seed=0, bootstrap=20, screen=16)
    >>> try:
    ...     check_settings(rocks=0, seed=0, bootstrap=20, screen=16)
    ... except ArgumentError as exc:
    ...     print(exc.message.split(":")[0])
    rocks must be between 1 and 20,000 (got 0)
    """
    limits = (
        ("rocks", rocks, 1, MAX_ROCKS, "rocks per run and evaluation"),
        ("seed", seed, 0, MAX_SEED, "a seed of numpy's generator"),
        ("bootstrap", bootstrap, 0, MAX_BOOTSTRAP, "each resample is a refit; "
         f"{MIN_BOOTSTRAP_SE} or more give standard errors"),
        ("screen", screen, 0, MAX_SCREEN, "each point is one evaluation"),
        ("profile_points", profile_points, 0, MAX_PROFILE_POINTS,
         "0 turns the profile off; each point is a short refit"),
        ("profile_seeds", profile_seeds, 0, MAX_PROFILE_SEEDS,
         f"0 leaves the seed spread out; {MIN_PROFILE_SEEDS} or more give its SD"),
    )  # fmt: skip
    for name, value, lo, hi, why in limits:
        if isinstance(value, bool) or not isinstance(value, int | np.integer):
            raise ArgumentError(f"{name} must be a whole number (got {value!r})",
                                source=name)  # fmt: skip
        if not lo <= value <= hi:
            raise ArgumentError(
                f"{name} must be between {lo:,} and {hi:,} (got {value}): {why}",
                source=name,
            )
    for name, value, least in (
        ("profile_points", profile_points, 2),
        ("profile_seeds", profile_seeds, MIN_PROFILE_SEEDS),
    ):
        if value == 1:
            raise ArgumentError(
                f"{name} must be 0 (off) or at least {least} (got 1)", source=name
            )  # fmt: skip


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
    """Proper scores of what was observed along the runs against simulated ensembles.

    Every observed value of every kind (:data:`fieldkit.fit.path_along.KINDS`) is
    scored by the CRPS of its simulated ensemble; the objective is the sum over
    kinds of the kind's weighted mean CRPS divided by its scale,

    .. math:: S(\\theta) = \\sum_k \\frac{1}{s_k \\sum_i w_{ki}}
              \\sum_{i=1}^{N_k} w_{ki}\\, \\mathrm{CRPS}(F_{ki,\\theta}, y_{ki}),

    (weights :math:`w_{ki}` = 1, but the flight length for flight heights),

    with :math:`s_k = 1` when one kind is scored (the objective is then that kind's
    mean CRPS in its unit: metres for runouts) and, when several are, :math:`s_k` =
    the kind's mean CRPS under the starting parameters (:meth:`set_scales`), so that
    each kind weighs alike and the objective starts at the number of kinds.

    The objective is a sum of *units* (:meth:`units`): one per run when there are at
    least two runs (a run's contribution over all its kinds), else one per observed
    value, grouped by kind (*strata*). The bootstrap resamples units within strata,
    and the slices' standard errors are those of a stratified sum.

    Runs with a non-finite observed runout score no runout; run ``runs[i]`` always
    uses the common random numbers ``default_rng([seed, i])``.

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
    kinds
        Kinds to score (default: every kind observed on some run).
    suspect
        What to do with observed values that rest on a flagged impact or an
        assumed launch angle (:mod:`fieldkit.fit.suspect`; default: keep them).
    """

    def __init__(
        self,
        runs: Sequence[PathRun],
        names: Sequence[str],
        rocks: int,
        seed: int,
        kinds: Sequence[str] | None = None,
        realised_limit: float | None = None,
        suspect: SuspectPolicy | None = None,
    ):
        #: With a limit, every simulation also counts the impacts whose realised
        #: e_n exceeds it: :attr:`realised_share` after each evaluation.
        self.realised_limit = realised_limit
        self.realised_share = math.nan
        if kinds is not None:
            unknown = sorted(set(kinds) - set(KINDS))
            if unknown:
                raise ArgumentError(
                    f"unknown kinds {', '.join(unknown)} (known: {', '.join(KINDS)})",
                    source="kinds",
                )
        self.all_runs = list(runs)
        self.suspect_policy = suspect or SuspectPolicy()
        observed = [observed_along(r, suspect) for r in runs]
        if kinds is not None:
            observed = [
                AlongObservations(
                    {k: v for k, v in o.values.items() if k in kinds},
                    o.speed_chainage_m if "speed_mps" in kinds else np.zeros(0),
                    o.launch_range_m,
                    o.weights,
                    {k: c for k, c in o.suspect.items() if k in kinds},
                )
                for o in observed
            ]
        keep = [i for i, o in enumerate(observed) if o.values]
        if not keep:
            raise ArgumentError(
                "no run has an observed runout or along-path observation",
                source="runs",
            )
        self.index = keep
        self.runs = [runs[i] for i in keep]
        self.observed_along = [observed[i] for i in keep]
        self.kinds = [
            k for k in KINDS if any(k in o.values for o in self.observed_along)
        ]
        self.names = list(names)
        self.rocks = int(rocks)
        self.seed = int(seed)
        self.observed = np.array([r.observed_runout_m for r in self.runs], float)
        self._keys = [set(r.model.parameters()) for r in self.runs]
        self.scales = dict.fromkeys(self.kinds, 1.0)
        self.evaluations = 0
        # Flat layout of the observed values: kind, run (position in self.runs).
        kind_of, run_of, weight = [], [], []
        for j, o in enumerate(self.observed_along):
            for k in self.kinds:
                if k in o.values:
                    kind_of += [k] * o.values[k].size
                    run_of += [j] * o.values[k].size
                    weight.append(o.weight(k))
        self._kind = np.array(kind_of)
        self._run = np.array(run_of, int)
        self._weight = np.concatenate(weight)
        self.counts = {k: int(np.sum(self._kind == k)) for k in self.kinds}
        self._total = {
            k: float(self._weight[self._kind == k].sum()) for k in self.kinds
        }
        self.suspect = suspect_counts(self.observed_along)
        if len(self.runs) >= 2:
            self.strata = [np.arange(len(self.runs))]
        else:
            self.strata = [np.flatnonzero(self._kind == k) for k in self.kinds]

    def suspect_words(self) -> list[str]:
        """What the policy did with the suspect values, one line per group."""
        return policy_lines(
            self.suspect_policy, self.suspect, "observed values", arguments=False
        )

    @property
    def along(self) -> bool:
        """Whether anything but runouts is scored."""
        return self.kinds != ["runout_m"]

    def _models(self, values: dict[str, float]):
        for run, i, keys in zip(self.runs, self.index, self._keys, strict=True):
            mine = {k: v for k, v in values.items() if k in keys}
            yield run, i, (run.model.with_parameters(mine) if mine else run.model)

    def ensembles(self, values: dict[str, float]) -> list[np.ndarray]:
        """Simulated runouts of every scored run with ``values`` set."""
        with one_kernel_thread():
            return [
                simulated_runouts(run, model, self.rocks, self.seed, i)
                for run, i, model in self._models(values)
            ]

    def observation_scores(self, x: np.ndarray) -> np.ndarray:
        """CRPS of every observed value (flat layout: runs, then kinds) at ``x``."""
        values = dict(zip(self.names, map(float, x), strict=True))
        self.evaluations += 1
        out = []
        counts: dict[str, np.ndarray] = {}
        with one_kernel_thread():
            for (run, i, model), obs in zip(
                self._models(values), self.observed_along, strict=True
            ):
                hook = None
                if self.realised_limit is not None:
                    hook = _counter(model, counts, self.realised_limit)
                if self.along:
                    sims = simulated_along(run, model, obs, self.rocks, self.seed, i,
                                           on_impacts=hook)  # fmt: skip
                else:
                    sims = {
                        "runout_m": [
                            simulated_runouts(run, model, self.rocks, self.seed, i,
                                              on_impacts=hook)  # fmt: skip
                        ]
                    }
                for k in self.kinds:
                    if k not in obs.values:
                        continue
                    ens, ys = sims[k], obs.values[k]
                    if isinstance(ens[0], tuple):  # a weighted pool
                        out.append(crps_ensemble_many(ens[0][0], ys, ens[0][1]))
                    elif all(e is ens[0] for e in ens):
                        out.append(crps_ensemble_many(ens[0], ys))
                    else:
                        pairs = zip(ens, ys, strict=True)
                        out.append(np.array([crps_ensemble(e, y) for e, y in pairs]))
        if self.realised_limit is not None:
            self.realised_share = _worst_share(counts)
        return np.concatenate(out)

    def units(self, x: np.ndarray) -> np.ndarray:
        """The objective's units at ``x`` (class docstring): their sum is S."""
        return self.units_of(self.observation_scores(x))

    def units_of(self, scores: np.ndarray) -> np.ndarray:
        """The units of :meth:`observation_scores` already computed."""
        scale = np.array([self.scales[k] * self._total[k] for k in self._kind])
        parts = scores * self._weight / scale
        if len(self.runs) >= 2:
            return np.bincount(self._run, parts, minlength=len(self.runs))
        return parts

    def set_scales(self, x: np.ndarray) -> dict[str, float]:
        """Scale every kind by its mean CRPS at ``x`` (when several are scored)."""
        return self.set_scales_of(self.observation_scores(x))

    def set_scales_of(self, scores: np.ndarray) -> dict[str, float]:
        """:meth:`set_scales` from :meth:`observation_scores` already computed."""
        if len(self.kinds) > 1:
            for k, mean in self.kind_means_of(scores).items():
                self.scales[k] = mean if mean > 0 else 1.0
        return dict(self.scales)

    def kind_means(self, x: np.ndarray) -> dict[str, float]:
        """(Weighted) mean CRPS of each kind at ``x``, in the kind's unit."""
        return self.kind_means_of(self.observation_scores(x))

    def kind_means_of(self, scores: np.ndarray) -> dict[str, float]:
        """:meth:`kind_means` from :meth:`observation_scores` already computed."""
        return {
            k: float(np.average(scores[m], weights=self._weight[m]))
            for k in self.kinds
            for m in [self._kind == k]
        }

    def per_run(self, x: np.ndarray) -> np.ndarray:
        """CRPS [m] of each scored run's runout at ``x`` (NaN: none observed)."""
        return self.per_run_of(self.observation_scores(x))

    def per_run_of(self, scores: np.ndarray) -> np.ndarray:
        """:meth:`per_run` from :meth:`observation_scores` already computed."""
        out = np.full(len(self.runs), np.nan)
        runout = self._kind == "runout_m"
        out[self._run[runout]] = scores[runout]
        return out

    def __call__(self, x: np.ndarray) -> float:
        """The objective S at ``x``."""
        return float(np.sum(self.units(x)))


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
    pinned: list[bool | None]  # None: no range resolved, so no evidence either way
    objective_start: float
    objective_optimum: float
    run_crps: np.ndarray  # runout CRPS per scored run, at the optimum (NaN: none)
    run_ids: list[str]
    n_runs: int
    n_evaluations: int
    wall_s: float
    rocks: int
    seed: int
    bootstrap: np.ndarray  # (B, p) refitted values
    model: Model
    notes: list[str] = field(default_factory=list)
    kinds: list[str] = field(default_factory=lambda: ["runout_m"])
    kind_counts: dict[str, int] = field(default_factory=dict)
    scales: dict[str, float] = field(default_factory=dict)
    kind_start: dict[str, float] = field(default_factory=dict)
    kind_optimum: dict[str, float] = field(default_factory=dict)
    #: Distance from the optimum within which each slice's ends are not resolved.
    slice_resolution: np.ndarray | None = None
    #: Student's t quantile of the 90 % interval (value ± t SE) and its degrees of
    #: freedom.
    t_quantile: float = math.nan
    t_dof: int = 0
    #: Profile intervals with the seed spread (None: ``profile_points`` 0).
    profile: PathProfile | None = None
    #: The realised-e_n constraint (None: none) and the worst material's share of
    #: simulated impacts above it at the start and at the optimum (the fit's own
    #: streams; NaN without a constraint).
    max_realised_e_n: float | None = None
    realised_share_start: float = math.nan
    realised_share_optimum: float = math.nan

    def at_bound(self) -> np.ndarray:
        """Whether each value is within 1/1000 of its bound range of a bound (the
        rule of the fit's "is at a search bound" notes)."""
        span = self.upper - self.lower
        return (np.abs(self.values - self.lower) <= 1e-3 * span) | (
            np.abs(self.values - self.upper) <= 1e-3 * span
        )
    #: Kind -> suspect values and what the fit did with them (fieldkit.fit.suspect).
    suspect: dict[str, SuspectCount] = field(default_factory=dict)
    suspect_policy: SuspectPolicy = field(default_factory=SuspectPolicy)

    @property
    def stderr_is_lower_bound(self) -> bool:
        """Whether the standard errors understate the uncertainty: one run's
        bootstrap resamples its observed values, which are not independent."""
        return self.n_runs == 1 and self.bootstrap.shape[0] >= MIN_BOOTSTRAP_SE

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

    def interval_method(self) -> str:
        """How the 90 % interval was made, in words."""
        if self.bootstrap.shape[0] < MIN_BOOTSTRAP_SE:
            return (
                "the objective's slice: the values the runs cannot tell from the "
                "optimum (no standard error)"
            )
        text = (
            f"fitted value ± {self.t_quantile:.3g} standard errors (Student's t, 95 % "
            f"quantile, {self.t_dof} degree{'s' if self.t_dof != 1 else ''} of "
            "freedom), widened to the objective's slice where that is wider"
        )
        if self.stderr_is_lower_bound:
            text += (
                "; one run: the standard error resamples its observed values, which "
                "are not independent, so it and the interval are lower bounds"
            )
        return text

    def to_dict(self) -> dict:
        """JSON-ready summary (no model; write that with ``write_model``)."""
        return {
            "parameters": [
                {
                    "name": n,
                    "value": float(v),
                    "stderr": _finite(s),
                    "interval90": [float(a), float(b)],
                    "start": float(s0),
                    "bounds": [float(lo), float(hi)],
                    "pinned": None if p is None else bool(p),
                    "range_resolved": p is not None,
                    "slice_resolution": _finite(r),
                    "stderr_is_lower_bound": self.stderr_is_lower_bound,
                }
                for n, v, s, (a, b), s0, lo, hi, p, r in zip(
                    self.names,
                    self.values,
                    self.stderr,
                    self.interval90,
                    self.start,
                    self.lower,
                    self.upper,
                    self.pinned,
                    (
                        self.slice_resolution
                        if self.slice_resolution is not None
                        else np.full(len(self.names), np.nan)
                    ),
                    strict=True,
                )
            ],
            "correlation": (
                self.correlation.tolist()
                if np.isfinite(self.correlation).all()
                else None
            ),
            "slice_compatible": self.compatible.tolist(),
            "interval90_method": self.interval_method(),
            "t_quantile": _finite(self.t_quantile),
            "t_dof": self.t_dof,
            "objective": (
                "mean CRPS of observed runouts [m]"
                if self.kinds == ["runout_m"]
                else "sum over kinds of the mean CRPS / its value at the start"
            ),
            "kinds": [
                {
                    "kind": k,
                    "observations": self.kind_counts.get(k, 0),
                    "scale": self.scales.get(k, 1.0),
                    "crps_start": _finite(self.kind_start.get(k, math.nan)),
                    "crps_optimum": _finite(self.kind_optimum.get(k, math.nan)),
                }
                for k in self.kinds
            ],
            "objective_start": self.objective_start,
            "objective_optimum": self.objective_optimum,
            "runs": [
                {"path_id": i, "crps_m": float(c) if math.isfinite(c) else None}
                for i, c in zip(self.run_ids, self.run_crps, strict=True)
            ],
            "n_runs": self.n_runs,
            "n_evaluations": self.n_evaluations,
            "wall_s": self.wall_s,
            "rocks": self.rocks,
            "seed": self.seed,
            "bootstrap_size": int(self.bootstrap.shape[0]),
            "standard_errors": (
                f"SD of the {self.bootstrap.shape[0]} bootstrap refits"
                if self.bootstrap.shape[0] >= MIN_BOOTSTRAP_SE
                else f"none: {self.bootstrap.shape[0]} bootstrap resamples are fewer "
                f"than {MIN_BOOTSTRAP_SE}; interval90 is only the objective's slice "
                "(the values the runs cannot tell from the optimum)"
            ),
            "notes": list(self.notes),
            "profile": None if self.profile is None else self.profile.to_dict(),
        }


def _counter(model: Model, counts: dict[str, np.ndarray], limit: float):
    """An ``on_impacts`` hook adding, per material of ``model``, [impacts whose
    realised e_n exceeds ``limit``, impacts with a defined e_n] into ``counts``."""
    names = list(model.materials)

    def add(columns: dict[str, np.ndarray]) -> None:
        above, total = realised_share_above([columns], len(names), limit)
        for name, a, t in zip(names, above, total, strict=True):
            counts.setdefault(name, np.zeros(2, np.int64))
            counts[name] += (a, t)

    return add


def _worst_share(counts: dict[str, np.ndarray]) -> float:
    """The largest share over materials with impacts (0 without any)."""
    shares = [a / t for a, t in counts.values() if t > 0]
    return max(shares, default=0.0)
def suspect_counts(observed: Sequence[AlongObservations]) -> dict[str, SuspectCount]:
    """Kind -> the suspect counts of every run's observed values, summed."""
    out: dict[str, SuspectCount] = {}
    for o in observed:
        for k, c in o.suspect.items():
            out.setdefault(k, SuspectCount()).add(c)
    return out


def _finite(x: float) -> float | None:
    """``x`` as a float, or None where it is not finite (JSON has no NaN)."""
    return float(x) if math.isfinite(x) else None


def _stratified_se(diff: np.ndarray, strata: Sequence[np.ndarray]) -> float:
    """Standard error of ``diff.sum()`` with units i.i.d. within each stratum."""
    var = 0.0
    for stratum in strata:
        if stratum.size > 1:
            var += stratum.size * float(np.var(diff[stratum], ddof=1))
    return math.sqrt(var)


def _bisect(ok: Callable[[float], bool], good: float, bad: float, steps: int) -> float:
    """The last value found ``ok`` between ``good`` (ok) and ``bad`` (not), by
    ``steps`` bisections (the boundary is then known to ``|bad - good| / 2**steps``).

    Examples
    --------
    >>> _bisect(lambda v: v <= 0.3, 0.0, 1.0, 10)
    0.2998046875
    """
    for _ in range(steps):
        mid = 0.5 * (good + bad)
        if ok(mid):
            good = mid
        else:
            bad = mid
    return good


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
    kinds: Sequence[str] | None = None,
    screen: int = 0,
    step: Step | None = None,
    profile_points: int = 5,
    profile_seeds: int = 5,
    profile_evaluations: int | None = None,
    max_realised_e_n: float | None = None,
    suspect: SuspectPolicy | None = None,
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
    screen
        Points of a scrambled Sobol screen of the bound box evaluated before the
        search; when the best beats the start, the search also starts from it and
        keeps the better optimum (0: start from the base model only).
    kinds
        What to score (:data:`fieldkit.fit.path_along.KINDS`; default every kind
        observed on some run: runouts, and along the paths flight heights, impact
        spacing and speeds where the runs carry them).
    step
        ``step(description, total)`` context manager around each long stage (the
        search, the bootstrap, the slices), yielding ``advance(done, total)``;
        default: none.
    profile_points, profile_seeds, profile_evaluations
        The profile intervals (:mod:`fieldkit.fit.path_profile`): grid values across
        each bound range (0: no profile), other seeds of the objective's seed spread
        (0: none), evaluations of each point's re-optimisation of the others.
    max_realised_e_n
        Constrain the fit to realised ``e_n <= max_realised_e_n`` (None: no
        constraint). Every evaluation's simulations count, per material, the
        impacts whose realised ``e_n = -v_fN / v_iN`` (on the slope the kernel
        used) exceeds it; the worst material's share beyond
        :data:`REALISED_TOLERANCE` is penalised, ``REALISED_PENALTY x S(start) x
        excess``, in the search and every bootstrap refit, and slice values beyond
        the tolerance are not compatible with the data. A penalty rather than a
        bound: no law has an exact reformulation once its e_n scatters (the start
        model of boulder A, e_n = 1.0 with e_n_sd 0.04 under eq. 7.1, realises
        e_n > 1 on 40 % of its impacts), so the share is measured, not assumed.
    suspect
        What to do with the flight heights and speeds that rest on a flagged
        impact or an assumed launch angle (:mod:`fieldkit.fit.suspect`; default:
        keep them); stated in the notes when it changes anything.

    Returns
    -------
    PathFitResult
    """
    t0 = time.perf_counter()
    say = progress or (lambda _msg: None)
    stage = step or _no_step
    check_settings(
        rocks=rocks, seed=seed, bootstrap=bootstrap, screen=screen,
        profile_points=profile_points, profile_seeds=profile_seeds,
    )  # fmt: skip
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
    box = [bounds[n] if n in bounds else parameter_bounds(n) for n in names]
    lower = np.array([lo for lo, _ in box], float)
    upper = np.array([hi for _, hi in box], float)
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
    check_realised_limit(max_realised_e_n)
    objective = PathObjective(runs, names, rocks, seed, kinds,
                              realised_limit=max_realised_e_n,
                              suspect=suspect)  # fmt: skip
    if not objective.suspect_policy.is_default:
        notes += [f"suspect data: {line}" for line in objective.suspect_words()]
    n_runs = len(objective.runs)
    if n_runs < len(runs):
        notes.append(f"{len(runs) - n_runs} runs without any observation left out")
    unscored = sum(1 for r in objective.runs if not math.isfinite(r.observed_runout_m))
    if unscored:
        notes.append(f"{unscored} runs without an observed runout: no runout scored")
    if n_runs == 1 and bootstrap:
        notes.append(
            "one run: the bootstrap resamples its observed values within each kind "
            "(the values of one path are not independent: the intervals are a lower "
            "bound on the uncertainty)"
        )

    def to_x(u):
        return lower + span * np.clip(u, 0.0, 1.0)

    n_units = sum(s.size for s in objective.strata)
    weights = np.ones(n_units)

    penalty_scale = 0.0  # set from the start value below (a constrained fit)

    def f(u):  # progress is the stage's (a bar on a terminal), not a line per 25
        value = float(np.dot(weights, objective.units(to_x(u))))
        if max_realised_e_n is None:
            return value
        excess = max(objective.realised_share - REALISED_TOLERANCE, 0.0)
        return value + REALISED_PENALTY * penalty_scale * excess

    u0 = (x0 - lower) / span
    start_scores = objective.observation_scores(x0)
    scales = objective.set_scales_of(start_scores)
    kind_start = objective.kind_means_of(start_scores)
    unit = "m" if objective.kinds == ["runout_m"] else ""
    if len(objective.kinds) > 1:
        say(
            "scored: "
            + ", ".join(f"{k} ({objective.counts[k]})" for k in objective.kinds)
            + "; each scaled by its CRPS at the start"
        )
    f0 = float(np.sum(objective.units_of(start_scores)))
    realised_start = objective.realised_share
    penalty_scale = abs(f0) if f0 != 0 else 1.0
    if max_realised_e_n is not None:
        say(
            f"constrained to realised e_n <= {max_realised_e_n:g}: the worst "
            f"material's share of simulated impacts above it at most "
            f"{100 * REALISED_TOLERANCE:g} % (penalty); "
            f"{100 * realised_start:.1f} % at the start"
        )
    say(
        f"fit {p} parameter{'s' * (p != 1)} to {n_runs} run{'s' * (n_runs != 1)} "
        f"({rocks} rocks each): "
        f"start {f0:.3f}{unit and ' ' + unit}"
    )
    budget = max_evaluations or max(150, 60 * p)
    description = (
        f"fitting {p} parameter{'s' * (p != 1)} to {n_runs} run"
        f"{'s' * (n_runs != 1)} ({rocks} rocks each)"
    )
    with stage(description, None):
        starts = [u0]
        if screen > 0:
            # Screen the cube (scrambled Sobol points, seeded): an objective of
            # simulated paths can have several basins (a rolling and a bouncing
            # regime), and Nelder-Mead only finds the one it starts in.
            sobol = qmc.Sobol(p, scramble=True, seed=np.random.default_rng([seed, 3]))
            points = sobol.random(screen)
            values = np.array([f(u) for u in points])
            best = int(np.argmin(values))
            say(f"screened {screen} points: best {values[best]:.3f} (start {f0:.3f})")
            if values[best] < f0:
                starts.append(points[best])
        first = int(budget * 0.7) // len(starts)
        u1, f1, _ = min(
            (_minimise(f, u, 0.15, first) for u in starts), key=lambda r: r[1]
        )
        u2, f2, _ = _minimise(f, u1, 0.05, max(budget - first * len(starts), p + 2))
    u_best, f_best = (u2, f2) if f2 <= f1 else (u1, f1)
    x_best = to_x(u_best)
    say(
        f"optimum {f_best:.3f}{unit and ' ' + unit} after {objective.evaluations} "
        "evaluations"
    )
    best_scores = objective.observation_scores(x_best)
    realised_best = objective.realised_share
    if max_realised_e_n is not None:
        notes.append(
            f"constrained to realised e_n <= {max_realised_e_n:g} (at most "
            f"{100 * REALISED_TOLERANCE:g} % of any material's simulated impacts "
            f"above it, by a penalty): {100 * realised_start:.1f} % at the start, "
            f"{100 * realised_best:.1f} % at the optimum"
            + ("" if realised_best <= REALISED_TOLERANCE else
               " -- beyond the tolerance: no point of the search met it")
        )  # fmt: skip
    best_units = objective.units_of(best_scores)
    kind_optimum = objective.kind_means_of(best_scores)
    run_crps = objective.per_run_of(best_scores)
    at_bound = np.isclose(u_best, 0.0, atol=1e-3) | np.isclose(u_best, 1.0, atol=1e-3)
    for n, flag in zip(names, at_bound, strict=True):
        if flag:
            notes.append(f"{n} is at a search bound")

    rng = np.random.default_rng([seed, BOOTSTRAP_STREAM])
    short = bootstrap_evaluations or 20 * p + 10
    boot = np.empty((bootstrap, p))
    with (
        stage(f"bootstrap: {bootstrap} refits", bootstrap)
        if bootstrap
        else _no_step("")
    ) as advance:
        for b in range(bootstrap):
            weights = np.zeros(n_units)
            for stratum in objective.strata:
                draw = rng.integers(0, stratum.size, stratum.size)
                weights[stratum] = np.bincount(draw, minlength=stratum.size)
            # Each resample also draws new simulated rocks: the fitted values carry
            # the Monte Carlo error of a finite ensemble, which a bootstrap over runs
            # with the optimum's own rocks would leave out.
            objective.seed = seed + 1 + b
            ub, _, _ = _minimise(f, u_best, 0.05, short)
            boot[b] = to_x(ub)
            advance(b + 1, bootstrap)
    objective.seed = seed
    weights = np.ones(n_units)
    if bootstrap >= MIN_BOOTSTRAP_SE:
        stderr = boot.std(axis=0, ddof=1)
        # every refit at the same value (e.g. a bound): 0, not rounding noise
        stderr[stderr <= 1e-12 * span] = 0.0
        with np.errstate(invalid="ignore", divide="ignore"):
            corr = np.corrcoef(boot.T) if p > 1 else np.ones((1, 1))
        corr = np.atleast_2d(np.nan_to_num(corr, nan=0.0))
        np.fill_diagonal(corr, 1.0)
    else:
        stderr = np.full(p, np.nan)
        corr = np.full((p, p), np.nan)
        notes.append(
            f"{bootstrap} bootstrap resamples: too few for a standard error or "
            f"correlations (at least {MIN_BOOTSTRAP_SE}); none given, and the 90 % "
            "interval is only the objective's slice (the values the runs cannot tell "
            "from the optimum)"
        )
    # Slice of the objective across each bound range (others at the optimum): the
    # points the runs cannot tell from the optimum (paired mean CRPS difference
    # below Z90 times its SE over runs). A flat direction has no bootstrap spread
    # (every refit stays where it starts), so this is what reveals it.
    compatible = np.empty((p, 2))
    resolution = span / max(slice_points - 1, 1) / 2**SLICE_BISECTIONS

    def indistinct(j: int, value: float) -> bool:
        x = x_best.copy()
        x[j] = value
        diff = objective.units(x) - best_units
        if (max_realised_e_n is not None
                and objective.realised_share > REALISED_TOLERANCE):
            return False  # outside the constraint: not a value the fit allows
        return bool(diff.sum() <= Z90 * _stratified_se(diff, objective.strata))

    with stage(f"slicing the objective across {p} bound ranges", p) as advance:
        for j in range(p):
            grid = np.linspace(lower[j], upper[j], slice_points)
            ok = [x_best[j]] + [v for v in grid if indistinct(j, v)]
            lo, hi = min(ok), max(ok)
            # The grid only tests its own points: the range's ends lie between the
            # outermost compatible value and the next grid point out (rejected),
            # found by bisection, so that it is two-sided where the objective
            # allows (a coarse grid alone ends it at the optimum itself).
            below, above = grid[grid < lo], grid[grid > hi]
            if below.size:
                lo = _bisect(lambda v, j=j: indistinct(j, v), lo, below.max(),
                             SLICE_BISECTIONS)  # fmt: skip
            if above.size:
                hi = _bisect(lambda v, j=j: indistinct(j, v), hi, above.min(),
                             SLICE_BISECTIONS)  # fmt: skip
            compatible[j] = lo, hi
            advance(j + 1, p)
    say(f"slices done after {objective.evaluations} evaluations")
    # Student's t with (units - 1) degrees of freedom rather than the normal 1.645:
    # a bootstrap SE from 15 runs is itself uncertain (SBC: the normal interval
    # covered friction on 79 % of synthetic sites, its z-scores had SD 1.23).
    units = min(s.size for s in objective.strata) if n_runs < 2 else n_runs
    dof = max(units - 1, 1)
    quantile = float(student_t.ppf(0.95, dof))
    interval = np.column_stack(
        [
            np.clip(x_best - quantile * stderr, lower, upper),
            np.clip(x_best + quantile * stderr, lower, upper),
        ]
    )
    profile = None
    if profile_points:
        with stage(
            f"profiling the objective across {p} bound ranges (others re-optimised)",
            p,
        ) as advance:
            profile = profile_objective(
                objective, x_best, lower, upper, points=profile_points,
                seeds=profile_seeds, evaluations=profile_evaluations, advance=advance,
                inner=compatible,
            )  # fmt: skip
        profile.widest = _widest(interval, compatible, profile.interval90)
        say(f"profile done: {profile.evaluations} evaluations, {profile.wall_s:.1f} s")
        if max_realised_e_n is not None:
            notes.append(
                "the profile intervals re-optimise the objective without the "
                f"realised-e_n constraint (<= {max_realised_e_n:g}): they may include "
                "values the constraint excludes"
            )
    for j, n in enumerate(names):
        lo, hi = compatible[j]
        if not np.isfinite(interval[j]).all():
            interval[j] = lo, hi  # no standard error: the slice alone
        elif lo < interval[j, 0] or hi > interval[j, 1]:
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
        if interval[j, 1] - interval[j, 0] < resolution[j]:
            # Every value tried beside the optimum was told apart from it: the
            # objective is kinked there (simulated ensembles with common random
            # numbers), which says nothing about how well the runs pin it down.
            ok = None
            notes.append(
                f"{n}: no range resolved: the values the runs cannot tell from the "
                f"optimum span less than the slice resolves ({resolution[j]:.2g}, "
                f"1/{2**SLICE_BISECTIONS} of its grid step), which is no evidence "
                "that the runs pin it down"
                + ("" if bootstrap >= MIN_BOOTSTRAP_SE else
                   f"; {MIN_BOOTSTRAP_SE} or more bootstrap resamples give a "
                   "standard error")
            )  # fmt: skip
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
        slice_resolution=resolution,
        t_quantile=quantile,
        t_dof=dof,
        objective_start=f0,
        objective_optimum=float(np.sum(best_units)),
        kinds=list(objective.kinds),
        kind_counts=dict(objective.counts),
        scales=scales,
        kind_start=kind_start,
        kind_optimum=kind_optimum,
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
        profile=profile,
        max_realised_e_n=max_realised_e_n,
        realised_share_start=realised_start,
        realised_share_optimum=realised_best,
        suspect=objective.suspect,
        suspect_policy=objective.suspect_policy,
    )


def _widest(boot: np.ndarray, slice_: np.ndarray, profile: np.ndarray) -> list[str]:
    """Per parameter, which interval is widest: ``bootstrap`` (value ± t SE, before
    any widening; none without a standard error), ``slice`` or ``profile`` (the first
    of the widest on a tie).

    Examples
    --------
    >>> _widest(np.array([[0, 1.0]]), np.array([[0.2, 0.3]]), np.array([[0, 2.0]]))
    ['profile']
    """
    out = []
    for b, s, q in zip(boot, slice_, profile, strict=True):
        widths = {
            "bootstrap": b[1] - b[0], "slice": s[1] - s[0], "profile": q[1] - q[0]
        }  # fmt: skip
        finite = {k: w for k, w in widths.items() if np.isfinite(w)}
        out.append(max(finite, key=finite.get))
    return out
