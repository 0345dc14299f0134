"""Scores of predicted deposits in plan (issue 21, item 3), independent of the kernel.

A 3-D prediction of a run is an *ensemble* of deposit points (x, y) in plan: where
the rocks released as the observed one was came to rest. It is scored against the
one observed deposit ``y`` by

* the **energy score** (Gneiting & Raftery 2007, eq. 22, beta = 1) of the deposit
  position in plan [m],

  .. math:: \\mathrm{ES}(F, y) = E\\|X - y\\| - \\tfrac12 E\\|X - X'\\|,

  X, X' independent draws of F, ``||.||`` the Euclidean norm. In one dimension it is
  the CRPS (:func:`fieldkit.fit.holdout.crps_ensemble`); for a point forecast it is
  the distance to the observation;
* the **fair CRPS** of the release-to-deposit distance [m] (:func:`fair_crps`);
* the fair CRPS of the **lateral offset** [m] (:func:`lateral_offset_m`): the signed
  distance of the deposit from the line through the release along a reference
  direction (by default the calibration runs' mean release-to-deposit direction),
  positive to the left looking downslope.

**Fair (unbiased) ensemble scores** (Ferro 2014). With m members :math:`x_i`, the
ensemble's own distribution gives
:math:`\\tfrac12 \\cdot \\frac1{m^2}\\sum_{i,j}\\|x_i - x_j\\|` for the spread term.
Its diagonal terms are zero, so the sum runs over m(m - 1) pairs that each have
expectation :math:`E\\|X - X'\\|` but is divided by m^2: the spread term is short by
the factor (m - 1)/m, and the empirical score of an ensemble of m members drawn from
F exceeds ES(F, y) on average by :math:`E\\|X - X'\\| / (2m)` -- a small ensemble
is penalised for its size, not for its forecast. The fair score divides by the
number of distinct ordered pairs instead,

.. math::
    \\mathrm{ES}_{fair} = \\frac1m \\sum_i \\|x_i - y\\|
    - \\frac1{2m(m-1)} \\sum_{i \\ne j} \\|x_i - x_j\\|,

i.e. the empirical spread term times m/(m - 1) (½ → m/(2(m - 1)) on the mean over
all m^2 pairs). Both sums are U-statistics of i.i.d. members, so the expectation of
the fair score over ensembles drawn from F is exactly ES(F, y): an ensemble of 20
and one of 2000 drawn from the same F score the same on average. In one dimension
this is Ferro's (2014, eq. 5) fair CRPS. It needs m >= 2.

**Paired comparisons** (:func:`paired_comparison`): two forecasts scored on the same
runs over several seeds (common random numbers) are compared by the mean over runs
of their seed-averaged per-run difference, with its standard error over runs (the
runs are the independent units; the seeds only reduce Monte Carlo noise within a
run), and the same figure per seed.

**Climatology in plan** (:func:`plan_climatology`): the calibration runs'
release-to-deposit *vectors* added to each held-out release -- a forecast that
knows the slope's typical runout and direction but nothing about the individual
release.

**Splits**: :func:`duplicate_runs` (runs with identical release and deposit; in the
Tschamut 2014 data, v033 = v034) and :func:`repeated_kfold` (seeded, optionally
stratified by group).

References
----------
Ferro, C. A. T. (2014). Fair scores for ensemble forecasts. Quarterly Journal of the
Royal Meteorological Society 140(683), 1917-1923.

Gneiting, T., Raftery, A. E. (2007). Strictly proper scoring rules, prediction, and
estimation. Journal of the American Statistical Association 102(477), 359-378.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from fieldkit.errors import ArgumentError

#: Members per block of the pairwise distance sums (bounds memory to ~8 MB).
_PAIR_BLOCK = 1024
#: Central interval whose coverage of the observed distance is reported.
COVERAGE_LEVEL = 0.9


def _members(samples: np.ndarray, name: str = "samples") -> np.ndarray:
    """``samples`` as a float (m, d) array with its non-finite members dropped."""
    x = np.asarray(samples, float)
    if x.ndim == 1:
        x = x[:, None]
    if x.ndim != 2:
        raise ArgumentError(
            f"{name} must be (members, dimensions) (got shape {x.shape})", source=name
        )
    return x[np.all(np.isfinite(x), axis=1)]


def _pair_distance_sum(x: np.ndarray) -> float:
    """Sum over all ordered pairs (i, j) of ``||x_i - x_j||`` (blocks of rows)."""
    m = x.shape[0]
    if x.shape[1] == 1:
        s = np.sort(x[:, 0])
        return float(2.0 * np.dot(2.0 * np.arange(1, m + 1) - m - 1.0, s))
    total = 0.0
    for start in range(0, m, _PAIR_BLOCK):
        block = x[start : start + _PAIR_BLOCK]
        diff = block[:, None, :] - x[None, :, :]
        total += float(np.sqrt(np.einsum("ijk,ijk->ij", diff, diff)).sum())
    return total


def energy_score(
    samples: np.ndarray, observed: np.ndarray, *, fair: bool = False
) -> float:
    """Energy score [unit of the data] of the ensemble ``samples`` at ``observed``.

    Parameters
    ----------
    samples
        Ensemble members, (m, d) (a 1-D array is m members of one dimension);
        members with a non-finite coordinate are dropped.
    observed
        The observation, (d,).
    fair
        The fair (unbiased) version (module docstring); needs two finite members.

    Returns
    -------
    float
        The score (0 is perfect, lower is better); NaN when ``observed`` is not
        finite, there is no finite member, or ``fair`` with one member.

    Examples
    --------
    >>> energy_score(np.array([[3.0, 4.0]]), np.array([0.0, 0.0]))  # point: distance
    5.0
    >>> energy_score(np.array([[0.0, 0.0], [2.0, 0.0]]), np.array([1.0, 0.0]))
    0.5
    >>> energy_score(np.array([[0.0, 0.0], [2.0, 0.0]]), np.array([1.0, 0.0]),
    ...              fair=True)
    0.0
    """
    x = _members(samples)
    y = np.asarray(observed, float).ravel()
    if y.size != x.shape[1]:
        raise ArgumentError(
            f"observed has {y.size} coordinates, the samples {x.shape[1]}",
            source="observed",
        )
    m = x.shape[0]
    if m == 0 or not np.all(np.isfinite(y)) or (fair and m < 2):
        return float("nan")
    absolute = float(np.mean(np.sqrt(np.sum((x - y) ** 2, axis=1))))
    pairs = _pair_distance_sum(x)
    spread = pairs / (2.0 * m * (m - 1)) if fair else pairs / (2.0 * m * m)
    return absolute - spread


def energy_scores(
    ensembles: Sequence[np.ndarray] | np.ndarray,
    observed: np.ndarray,
    *,
    fair: bool = False,
) -> np.ndarray:
    """:func:`energy_score` of each run: ``ensembles[k]`` (m_k, d) at
    ``observed[k]`` (d,).

    Parameters
    ----------
    ensembles
        One ensemble per run: a sequence of (m_k, d) arrays or one (runs, m, d)
        array.
    observed
        (runs, d) observations.
    fair
        The fair version.

    Returns
    -------
    numpy.ndarray
        (runs,) scores (NaN as :func:`energy_score`).

    Examples
    --------
    >>> energy_scores(np.zeros((2, 1, 2)), np.array([[3.0, 4.0], [0.0, 1.0]]))
    array([5., 1.])
    """
    obs = np.asarray(observed, float)
    obs = obs.reshape(len(obs), -1)
    if len(ensembles) != len(obs):
        raise ArgumentError(
            f"{len(ensembles)} ensembles for {len(obs)} observations",
            source="ensembles",
        )
    return np.array(
        [energy_score(e, y, fair=fair) for e, y in zip(ensembles, obs, strict=True)]
    )


def fair_crps(samples: np.ndarray, observed: np.ndarray | float) -> np.ndarray | float:
    """Fair CRPS (Ferro 2014) of ensembles of one quantity, vectorised over runs.

    .. math::
        \\mathrm{CRPS}_{fair} = \\frac1m \\sum_i |x_i - y|
        - \\frac1{2m(m-1)} \\sum_{i,j} |x_i - x_j|,

    the one-dimensional fair energy score; its expectation over ensembles of m
    i.i.d. members of F is the CRPS of F at y.

    Parameters
    ----------
    samples
        (m,) members of one run, or (runs, m) -- one row per run; non-finite
        members are dropped (row by row).
    observed
        The observation (float), or (runs,).

    Returns
    -------
    float or numpy.ndarray
        A float for 1-D ``samples``, else (runs,); NaN where the observation is not
        finite or fewer than two members are.

    Examples
    --------
    >>> fair_crps(np.array([0.0, 2.0]), 1.0)  # empirical CRPS: 1 - 0.5 = 0.5
    0.0
    >>> fair_crps(np.array([[0.0, 2.0], [1.0, np.nan]]), np.array([1.0, 1.0]))
    array([ 0., nan])
    """
    x = np.asarray(samples, float)
    single = x.ndim == 1
    x = np.atleast_2d(x)
    y = np.broadcast_to(np.asarray(observed, float), (x.shape[0],)).astype(float)
    s = np.sort(x, axis=1)  # NaN last
    finite = np.isfinite(s)
    m = finite.sum(axis=1).astype(float)
    rank = np.cumsum(finite, axis=1).astype(float)  # 1..m on the finite members
    values = np.where(finite, s, 0.0)
    pairs = 2.0 * np.sum(np.where(finite, (2.0 * rank - m[:, None] - 1.0), 0.0)
                         * values, axis=1)  # fmt: skip
    with np.errstate(invalid="ignore", divide="ignore"):
        absolute = (
            np.sum(np.where(finite, np.abs(values - y[:, None]), 0.0), axis=1) / m
        )
        out = absolute - pairs / (2.0 * m * (m - 1.0))
    out[(m < 2) | ~np.isfinite(y)] = np.nan
    return float(out[0]) if single else out


def release_deposit_distance_m(
    release_xy: np.ndarray, deposit_xy: np.ndarray
) -> np.ndarray:
    """Horizontal distance release -> deposit [m] (broadcast over leading axes).

    Examples
    --------
    >>> release_deposit_distance_m(np.array([0.0, 0.0]), np.array([[3.0, 4.0]]))
    array([5.])
    """
    d = np.asarray(deposit_xy, float)[..., :2] - np.asarray(release_xy, float)[..., :2]
    return np.hypot(d[..., 0], d[..., 1])


def mean_direction(release_xy: np.ndarray, deposit_xy: np.ndarray) -> np.ndarray:
    """Unit vector of the mean release -> deposit vector of some runs (in plan).

    The reference direction of :func:`lateral_offset_m` when no per-run direction
    (e.g. the release's fall line on a DEM) is given: the direction of the
    calibration runs' mean displacement (longer runs weigh more).

    Examples
    --------
    >>> mean_direction(np.zeros((2, 2)), np.array([[0.0, -3.0], [0.0, -5.0]]))
    array([ 0., -1.])
    """
    d = np.asarray(deposit_xy, float)[:, :2] - np.asarray(release_xy, float)[:, :2]
    mean = np.nanmean(d, axis=0)
    norm = float(np.hypot(*mean))
    if not norm > 0.0:
        raise ArgumentError(
            "the mean release-to-deposit vector is zero: no direction",
            source="deposit_xy",
        )
    return mean / norm


def lateral_offset_m(
    release_xy: np.ndarray, deposit_xy: np.ndarray, direction_xy: np.ndarray
) -> np.ndarray:
    """Signed lateral offset [m] of deposits from the line through their release
    along ``direction_xy``: ``u_x d_y - u_y d_x`` with ``u`` the unit direction and
    ``d`` the release -> deposit vector (the z component of u x d); positive to the
    left looking along ``u`` (downslope), negative to the right. The along-line
    component is ``u . d``.

    Parameters
    ----------
    release_xy, deposit_xy
        (..., 2) points in plan [m] (broadcast: one release against an ensemble of
        deposits (m, 2), or (runs, 1, 2) against (runs, m, 2)).
    direction_xy
        (..., 2) reference direction (any length > 0; normalised here): the fall
        line at the release, or :func:`mean_direction` of the calibration runs.

    Examples
    --------
    >>> lateral_offset_m(np.array([0.0, 0.0]), np.array([[1.0, -10.0], [-2.0, -5.0]]),
    ...                  np.array([0.0, -1.0]))  # downslope = -y; left = +x
    array([ 1., -2.])
    """
    u = np.asarray(direction_xy, float)[..., :2]
    norm = np.hypot(u[..., 0], u[..., 1])[..., None]
    if np.any(~(norm > 0.0)):
        raise ArgumentError("direction_xy has zero length", source="direction_xy")
    u = u / norm
    d = np.asarray(deposit_xy, float)[..., :2] - np.asarray(release_xy, float)[..., :2]
    return u[..., 0] * d[..., 1] - u[..., 1] * d[..., 0]


def section_to_plan(
    plan_x_m: np.ndarray, plan_y_m: np.ndarray, chainage_m: np.ndarray
) -> np.ndarray:
    """Plan points (x, y) [m] at chainages along a section's plan polyline: how a
    2-D model's simulated stops on a DEM section become deposits in plan, to be
    scored beside a 3-D model's.

    The chainage of a vertex is the plan distance along the polyline from its first
    vertex (as :class:`fieldkit.model.dem_profile.Section` measures it); a chainage
    before the first vertex (a rock that stopped on the ground kept upslope of the
    release, at negative chainage) lies on the line back along the first segment's
    direction, one after the last vertex on the last segment's continuation.

    Parameters
    ----------
    plan_x_m, plan_y_m
        (n,) the polyline's vertices, n >= 2, no two consecutive equal.
    chainage_m
        Chainages to place (any shape).

    Returns
    -------
    numpy.ndarray
        (..., 2) the plan points.

    Examples
    --------
    >>> section_to_plan(np.array([0.0, 3.0, 3.0]), np.array([0.0, 4.0, 14.0]),
    ...                 np.array([-5.0, 2.5, 10.0, 16.0])).tolist()
    [[-3.0, -4.0], [1.5, 2.0], [3.0, 9.0], [3.0, 15.0]]
    """
    px = np.asarray(plan_x_m, float)
    py = np.asarray(plan_y_m, float)
    seg = np.hypot(np.diff(px), np.diff(py))
    if px.size < 2 or px.size != py.size or not np.all(seg > 0):
        raise ArgumentError(
            "plan_x_m, plan_y_m must be >= 2 vertices of one length, no two "
            "consecutive equal",
            source="plan_x_m",
        )
    vertex = np.concatenate([[0.0], np.cumsum(seg)])
    c = np.asarray(chainage_m, float)
    i = np.clip(np.searchsorted(vertex, c, side="right") - 1, 0, seg.size - 1)
    t = (c - vertex[i]) / seg[i]
    x = px[i] + t * (px[i + 1] - px[i])
    y = py[i] + t * (py[i + 1] - py[i])
    return np.stack([x, y], axis=-1)


def plan_climatology(
    calibration_release_xy: np.ndarray,
    calibration_deposit_xy: np.ndarray,
    release_xy: np.ndarray,
) -> np.ndarray:
    """The climatology in plan: every calibration run's release -> deposit vector
    added to each release of ``release_xy`` -- an ensemble of deposits per run.

    Parameters
    ----------
    calibration_release_xy, calibration_deposit_xy
        (n, 2) the calibration runs (remove duplicate runs first,
        :func:`duplicate_runs`, or a repeated run counts twice).
    release_xy
        (runs, 2) the releases to forecast.

    Returns
    -------
    numpy.ndarray
        (runs, n, 2) deposit ensembles.

    Examples
    --------
    >>> plan_climatology(np.zeros((2, 2)), np.array([[1.0, 0.0], [0.0, -2.0]]),
    ...                  np.array([[10.0, 10.0]])).tolist()
    [[[11.0, 10.0], [10.0, 8.0]]]
    """
    vectors = (
        np.asarray(calibration_deposit_xy, float)[:, :2]
        - np.asarray(calibration_release_xy, float)[:, :2]
    )
    return np.asarray(release_xy, float)[:, None, :2] + vectors[None, :, :]


@dataclass(frozen=True)
class RunScores:
    """Per-run scores of deposit ensembles in plan (:func:`score_runs`).

    Every array is (runs,). Scores in metres, lower is better.

    Attributes
    ----------
    energy_fair_m, energy_m
        Fair and empirical energy score of the deposit position.
    distance_crps_fair_m
        Fair CRPS of the release-to-deposit distance.
    lateral_crps_fair_m
        Fair CRPS of the lateral offset (:func:`lateral_offset_m`).
    distance_observed_m, distance_mean_m
        Observed distance; ensemble mean distance.
    lateral_observed_m
        Observed lateral offset (signed).
    lateral_mean_abs_m
        The ensemble's mean absolute lateral offset (its lateral spread about the
        reference line; compare with ``|lateral_observed_m|``).
    distance_in_interval
        Whether the observed distance is in the ensemble's central
        :data:`COVERAGE_LEVEL` interval (1.0/0.0; NaN without members).
    members
        Finite members per run.
    """

    energy_fair_m: np.ndarray
    energy_m: np.ndarray
    distance_crps_fair_m: np.ndarray
    lateral_crps_fair_m: np.ndarray
    distance_observed_m: np.ndarray
    distance_mean_m: np.ndarray
    lateral_observed_m: np.ndarray
    lateral_mean_abs_m: np.ndarray
    distance_in_interval: np.ndarray
    members: np.ndarray

    #: The scores compared between forecasts (:func:`paired_comparison`).
    SCORES = ("energy_fair_m", "distance_crps_fair_m", "lateral_crps_fair_m")

    def summary(self) -> dict:
        """Means over runs: each score, its SE over runs, the coverage of the
        distance interval, the mean observed and predicted distance and their
        difference (``distance_bias_m``), the mean |lateral offset| observed and
        predicted (``lateral_observed_mean_abs_m``, ``lateral_predicted_mean_abs_m``:
        the mean over runs of each ensemble's mean |offset|)."""
        out: dict = {"n_runs": int(self.energy_m.size)}
        for name in (*self.SCORES, "energy_m"):
            v = getattr(self, name)
            v = v[np.isfinite(v)]
            out[name] = float(np.mean(v)) if v.size else math.nan
            out[name + "_se"] = (
                float(np.std(v, ddof=1) / np.sqrt(v.size)) if v.size > 1 else math.nan
            )
        out["distance_coverage_90"] = float(np.nanmean(self.distance_in_interval))
        out["distance_observed_mean_m"] = float(np.mean(self.distance_observed_m))
        out["distance_predicted_mean_m"] = float(np.nanmean(self.distance_mean_m))
        out["distance_bias_m"] = (
            out["distance_predicted_mean_m"] - out["distance_observed_mean_m"]
        )
        out["lateral_observed_mean_abs_m"] = float(
            np.mean(np.abs(self.lateral_observed_m))
        )
        out["lateral_predicted_mean_abs_m"] = float(np.nanmean(self.lateral_mean_abs_m))
        return out


def score_runs(
    ensembles: Sequence[np.ndarray] | np.ndarray,
    release_xy: np.ndarray,
    observed_xy: np.ndarray,
    direction_xy: np.ndarray,
) -> RunScores:
    """All plan scores of deposit ensembles, run by run.

    Parameters
    ----------
    ensembles
        Per run, the predicted deposits (m_k, 2+) [m] (extra columns, e.g. z, are
        ignored): a sequence or a (runs, m, 2+) array.
    release_xy, observed_xy
        (runs, 2+) release and observed deposit of each run [m].
    direction_xy
        (2,) or (runs, 2) reference direction of the lateral offset (e.g.
        :func:`mean_direction` of the calibration runs).

    Returns
    -------
    RunScores

    Examples
    --------
    >>> s = score_runs(np.array([[[0.0, -9.0], [0.0, -11.0]]]), np.zeros((1, 2)),
    ...                np.array([[0.0, -10.0]]), np.array([0.0, -1.0]))
    >>> float(s.energy_fair_m[0]) + 0.0, float(s.distance_crps_fair_m[0])
    (0.0, 0.0)
    """
    rel = np.asarray(release_xy, float)[:, :2]
    obs = np.asarray(observed_xy, float)[:, :2]
    if not (len(ensembles) == len(rel) == len(obs)):
        raise ArgumentError(
            f"{len(ensembles)} ensembles, {len(rel)} releases, {len(obs)} observations",
            source="ensembles",
        )
    direction = np.broadcast_to(np.asarray(direction_xy, float), rel.shape)
    fields: dict[str, list] = {k: [] for k in RunScores.__dataclass_fields__}
    lo_q, hi_q = (1.0 - COVERAGE_LEVEL) / 2.0, (1.0 + COVERAGE_LEVEL) / 2.0
    for e, r, y, u in zip(ensembles, rel, obs, direction, strict=True):
        x = _members(np.asarray(e, float)[:, :2], "ensembles")
        dist = release_deposit_distance_m(r, x)
        lat = lateral_offset_m(r, x, u)
        dist_obs = float(release_deposit_distance_m(r, y))
        lat_obs = float(lateral_offset_m(r, y, u))
        fields["energy_fair_m"].append(energy_score(x, y, fair=True))
        fields["energy_m"].append(energy_score(x, y))
        fields["distance_crps_fair_m"].append(fair_crps(dist, dist_obs))
        fields["lateral_crps_fair_m"].append(fair_crps(lat, lat_obs))
        fields["distance_observed_m"].append(dist_obs)
        fields["lateral_observed_m"].append(lat_obs)
        fields["members"].append(x.shape[0])
        if x.shape[0]:
            lo, hi = np.quantile(dist, [lo_q, hi_q])
            fields["distance_in_interval"].append(float(lo <= dist_obs <= hi))
            fields["distance_mean_m"].append(float(np.mean(dist)))
            fields["lateral_mean_abs_m"].append(float(np.mean(np.abs(lat))))
        else:
            for k in ("distance_in_interval", "distance_mean_m", "lateral_mean_abs_m"):
                fields[k].append(math.nan)
    return RunScores(**{k: np.asarray(v, float if k != "members" else int)
                        for k, v in fields.items()})  # fmt: skip


@dataclass(frozen=True)
class PairedComparison:
    """Forecast A against forecast B on the same runs over several seeds
    (:func:`paired_comparison`); differences are A - B, so with scores where lower
    is better a negative difference means A is better.

    Attributes
    ----------
    score
        The score's name (e.g. ``"energy_fair_m"``).
    name_a, name_b
        The forecasts' names.
    mean_a, mean_b
        Mean over seeds and runs of each forecast's score.
    mean_difference
        Mean over runs of the seed-averaged per-run difference A - B.
    se
        Its standard error over runs: SD (ddof 1) of the seed-averaged per-run
        differences / sqrt(runs).
    per_seed_difference, per_seed_se
        The mean difference and its SE over runs at each seed alone.
    seeds
        The seeds' labels.
    n_runs
        Runs compared.
    """

    score: str
    name_a: str
    name_b: str
    mean_a: float
    mean_b: float
    mean_difference: float
    se: float
    per_seed_difference: tuple[float, ...]
    per_seed_se: tuple[float, ...]
    seeds: tuple = field(default=())
    n_runs: int = 0

    def beats(self, n_se: float = 2.0) -> bool:
        """Whether A beats B (lower score) by at least ``n_se`` paired SEs:
        ``mean_difference <= -n_se * se`` (False when the SE is not finite)."""
        return bool(np.isfinite(self.se) and self.mean_difference <= -n_se * self.se)

    def lines(self) -> list[str]:
        """Report lines: the paired difference with its SE and the verdict, then the
        difference seed by seed.

        Examples
        --------
        >>> c = paired_comparison(np.array([[1.0, 2.0, 3.0]]),
        ...                       np.array([[2.0, 4.0, 3.0]]), "es", "A", "B")
        >>> print("\\n".join(c.lines()))  # doctest: +NORMALIZE_WHITESPACE
        es: A 2.000 vs B 3.000 (3 runs, 1 seed(s))
          A - B = -1.000 +- 0.577 (paired SE over runs):
          A does not beat B by >= 2 paired SEs
          seed 0: A - B = -1.000 +- 0.577
        """
        verdict = "beats" if self.beats() else "does not beat"
        a, b = self.name_a, self.name_b
        out = [
            f"{self.score}: {a} {self.mean_a:.3f} vs {b} {self.mean_b:.3f} "
            f"({self.n_runs} runs, {len(self.per_seed_difference)} seed(s))",
            f"  {a} - {b} = {self.mean_difference:.3f} +- {self.se:.3f} (paired SE "
            f"over runs): {a} {verdict} {b} by >= 2 paired SEs",
        ]
        for seed, d, se in zip(self.seeds, self.per_seed_difference, self.per_seed_se,
                               strict=True):  # fmt: skip
            out.append(
                f"  seed {seed}: {self.name_a} - {self.name_b} = {d:.3f} +- {se:.3f}"
            )
        return out

    def to_dict(self) -> dict:
        """A JSON-ready dict of the fields plus ``beats_by_2_se``."""
        return {
            "score": self.score,
            "a": self.name_a,
            "b": self.name_b,
            "mean_a": self.mean_a,
            "mean_b": self.mean_b,
            "mean_difference": self.mean_difference,
            "se": self.se,
            "n_runs": self.n_runs,
            "seeds": list(self.seeds),
            "per_seed_difference": list(self.per_seed_difference),
            "per_seed_se": list(self.per_seed_se),
            "beats_by_2_se": self.beats(2.0),
        }


def _se(values: np.ndarray) -> float:
    return (
        float(np.std(values, ddof=1) / np.sqrt(values.size))
        if values.size > 1
        else math.nan
    )


def paired_comparison(
    scores_a: np.ndarray,
    scores_b: np.ndarray,
    score: str = "score",
    name_a: str = "A",
    name_b: str = "B",
    *,
    seeds: Sequence | None = None,
) -> PairedComparison:
    """Paired comparison of two forecasts' per-run scores over seeds.

    Parameters
    ----------
    scores_a, scores_b
        (seeds, runs) per-run scores of each forecast at each seed, the same runs
        in the same order; a (runs,) array is a forecast without random numbers
        (e.g. the climatology) and serves every seed.
    score, name_a, name_b
        Names for the report.
    seeds
        Labels of the seeds (default 0, 1, ...).

    Returns
    -------
    PairedComparison

    Raises
    ------
    ArgumentError
        Shapes that do not match, or a non-finite score (a run must be scored by
        both forecasts at every seed).

    Examples
    --------
    >>> c = paired_comparison(np.array([[1.0, 2.0], [3.0, 2.0]]),
    ...                       np.array([2.0, 2.0]), seeds=[1, 2])
    >>> c.mean_difference, c.per_seed_difference
    (0.0, (-0.5, 0.5))
    """
    a = np.asarray(scores_a, float)
    b = np.asarray(scores_b, float)
    a2, b2 = np.atleast_2d(a), np.atleast_2d(b)
    n_seeds = max(a2.shape[0], b2.shape[0])
    try:
        a2, b2 = np.broadcast_arrays(a2, b2)
    except ValueError:
        raise ArgumentError(
            f"scores_a {a.shape} and scores_b {b.shape} do not match (seeds, runs)",
            source="scores_b",
        ) from None
    if a2.shape[0] != n_seeds or a2.shape[1] < 1:
        raise ArgumentError(f"scores_a {a.shape} and scores_b {b.shape} do not "
                            "match (seeds, runs)", source="scores_b")  # fmt: skip
    for name, v in (("scores_a", a2), ("scores_b", b2)):
        bad = ~np.isfinite(v)
        if bad.any():
            s, r = np.argwhere(bad)[0]
            raise ArgumentError(
                f"{name} is not finite at seed {s}, run {r}", source=name
            )
    diff = a2 - b2
    per_run = diff.mean(axis=0)
    labels = tuple(range(n_seeds)) if seeds is None else tuple(seeds)
    if len(labels) != n_seeds:
        raise ArgumentError(
            f"{len(labels)} seed labels for {n_seeds} seeds", source="seeds"
        )
    return PairedComparison(
        score=score,
        name_a=name_a,
        name_b=name_b,
        mean_a=float(a2.mean()),
        mean_b=float(b2.mean()),
        mean_difference=float(per_run.mean()),
        se=_se(per_run),
        per_seed_difference=tuple(float(d.mean()) for d in diff),
        per_seed_se=tuple(_se(d) for d in diff),
        seeds=labels,
        n_runs=int(diff.shape[1]),
    )


def duplicate_runs(
    release_xyz: np.ndarray, deposit_xyz: np.ndarray, *, tolerance_m: float = 1e-6
) -> list[list[int]]:
    """Groups of runs with the same release AND the same deposit (every coordinate
    within ``tolerance_m``): a run recorded twice. Count one run of each group
    (:func:`unique_runs`).

    Parameters
    ----------
    release_xyz, deposit_xyz
        (n, k) coordinates of the runs [m] (any k: x, y or x, y, z).
    tolerance_m
        Largest coordinate difference of the same point [m].

    Returns
    -------
    list of list of int
        Index groups (ascending, each of >= 2 runs), ordered by their first run.

    Examples
    --------
    >>> rel = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.0]])
    >>> dep = np.array([[5.0, 5.0], [5.0, 5.0], [5.0, 5.0]])
    >>> duplicate_runs(rel, dep)
    [[0, 2]]
    """
    key = np.hstack([np.asarray(release_xyz, float), np.asarray(deposit_xyz, float)])
    n = key.shape[0]
    group = np.arange(n)
    for i in range(n):
        if group[i] != i:
            continue
        same = np.all(np.abs(key[i + 1 :] - key[i]) <= tolerance_m, axis=1)
        for j in np.flatnonzero(same) + i + 1:
            if group[j] == j:
                group[j] = i
    groups: dict[int, list[int]] = {}
    for j, g in enumerate(group):
        groups.setdefault(int(g), []).append(j)
    return [g for g in groups.values() if len(g) > 1]


def unique_runs(n_runs: int, duplicates: list[list[int]]) -> np.ndarray:
    """Indices of the runs to keep: all but the second and later runs of each
    duplicate group (:func:`duplicate_runs`), ascending.

    Examples
    --------
    >>> unique_runs(4, [[0, 2]]).tolist()
    [0, 1, 3]
    """
    dropped = {j for g in duplicates for j in g[1:]}
    return np.array([i for i in range(n_runs) if i not in dropped], dtype=int)


@dataclass(frozen=True)
class Fold:
    """One fold of :func:`repeated_kfold`: calibration and holdout indices."""

    repeat: int
    fold: int
    calibration: np.ndarray
    holdout: np.ndarray


def repeated_kfold(
    n_runs: int,
    k: int = 5,
    repeats: int = 10,
    seed: int = 0,
    groups: Sequence | None = None,
) -> list[Fold]:
    """Repeated k-fold splits of ``n_runs`` runs (deduplicate first,
    :func:`unique_runs`, and index into the kept runs).

    Each repeat permutes the runs with ``numpy.random.default_rng([seed, repeat])``
    and deals them to ``k`` folds in turn; with ``groups`` (one label per run, e.g.
    the block), the runs are dealt group by group, so every fold holds about the
    same share of each group. Each fold is once the holdout, the other k - 1 the
    calibration.

    Returns
    -------
    list of Fold
        ``repeats * k`` folds; in each repeat, every run is held out exactly once.

    Examples
    --------
    >>> folds = repeated_kfold(10, k=5, repeats=2, seed=1)
    >>> len(folds), sorted(np.concatenate([f.holdout for f in folds[:5]]).tolist())
    (10, [0, 1, 2, 3, 4, 5, 6, 7, 8, 9])
    """
    if k < 2 or k > n_runs:
        raise ArgumentError(f"k must be in 2..{n_runs} (got {k})", source="k")
    if repeats < 1:
        raise ArgumentError(f"repeats must be >= 1 (got {repeats})", source="repeats")
    labels = np.zeros(n_runs, int) if groups is None else np.asarray(groups)
    if len(labels) != n_runs:
        raise ArgumentError(f"{len(labels)} groups for {n_runs} runs", source="groups")
    out = []
    for repeat in range(repeats):
        rng = np.random.default_rng([seed, repeat])
        fold_of = np.empty(n_runs, int)
        dealt = 0
        for label in np.unique(labels):
            members = rng.permutation(np.flatnonzero(labels == label))
            fold_of[members] = (dealt + np.arange(members.size)) % k
            dealt += members.size
        for f in range(k):
            out.append(Fold(repeat, f, np.flatnonzero(fold_of != f),
                            np.flatnonzero(fold_of == f)))  # fmt: skip
    return out
