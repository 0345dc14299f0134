"""Scores of predicted runout ensembles against observed runouts (held-out validation).

A prediction of a run is an *ensemble*: the simulated runouts of many rocks released
as the observed one was. It is scored against the one observed runout ``y`` by

* the continuous ranked probability score (CRPS) of the ensemble's empirical
  distribution, in the energy form of Gneiting & Raftery (2007, eq. 21),

  .. math:: \\mathrm{CRPS}(F, y) = E|X - y| - \\tfrac12 E|X - X'|,

  with X, X' independent draws of F (metres: it is the mean absolute error of a
  point forecast generalised to a distribution, 0 for a perfect point forecast);
* the coverage of central predictive intervals (the fraction of observed runouts
  inside the ensemble's central 50 % and 90 % intervals; a calibrated model gives
  about 0.5 and 0.9);
* the absolute error of the ensemble median, and the mean observed vs the mean
  predicted runout (a bias check).

The *climatology* reference is the empirical distribution of the calibration runs'
observed runouts, used as the ensemble of every held-out run: a model that does not
beat it has learned nothing from the slope.

References
----------
Gneiting, T., Raftery, A. E. (2007). Strictly proper scoring rules, prediction, and
estimation. Journal of the American Statistical Association 102(477), 359-378.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


def crps_ensemble(samples: np.ndarray, observed: float) -> float:
    """CRPS [same unit as the data] of the empirical distribution of ``samples`` at
    ``observed``.

    Computed exactly in O(n log n) by sorting (:func:`crps_ensemble_many` with equal
    weights): with :math:`x_{(1)} \\le \\dots \\le x_{(n)}`,

    .. math::
        \\mathrm{CRPS} = \\frac1n \\sum_i |x_i - y|
        - \\frac1{n^2} \\sum_{i=1}^n (2i - n - 1)\\, x_{(i)},

    the second term being :math:`\\tfrac12 E|X - X'| = \\frac1{2n^2}\\sum_{i,j}
    |x_i - x_j|` (Gneiting & Raftery 2007, eq. 21, for the empirical distribution;
    the pairs i = j are included, so this is the CRPS of the ensemble's step CDF,
    not the "fair" small-ensemble version).

    Parameters
    ----------
    samples
        Ensemble members (1-D; non-finite members are dropped).
    observed
        The observation y.

    Returns
    -------
    float
        The CRPS; NaN when ``observed`` is not finite or no member is finite.

    Examples
    --------
    >>> crps_ensemble(np.array([0.0, 1.0]), 0.5)
    0.25
    >>> crps_ensemble(np.array([2.0]), 5.0)  # one member: absolute error
    3.0
    """
    return float(crps_ensemble_many(samples, np.array([float(observed)]))[0])


def crps_ensemble_many(
    samples: np.ndarray, observed: np.ndarray, weights: np.ndarray | None = None
) -> np.ndarray:
    """CRPS of the empirical distribution of ``samples`` at each of ``observed``.

    The same number as :func:`crps_ensemble` for every observation, with one sort;
    with ``weights`` (>= 0, any sum), the CRPS of the weighted step CDF. With the
    members sorted, normalised weights :math:`w_i` and cumulative weights
    :math:`C_i`,

    .. math::
        \\mathrm{CRPS}(y) = \\sum_i w_i |x_i - y|
        - \\sum_i w_i x_i (2 C_i - w_i - 1),

    the first sum being :math:`y (2 W_y - 1) - 2 S_y + S` (:math:`W_y`, :math:`S_y`:
    weight and weighted sum of the members at most ``y``), the second
    :math:`\\tfrac12 E|X - X'|`.

    Examples
    --------
    >>> crps_ensemble_many(np.array([0.0, 1.0]), np.array([0.5, 5.0])).tolist()
    [0.25, 4.25]
    >>> crps_ensemble_many(np.array([0.0, 1.0]), np.array([0.5]), np.array([1, 3.0]))
    array([0.3125])
    """
    x = np.asarray(samples, float).ravel()
    w = np.ones(x.size) if weights is None else np.asarray(weights, float).ravel()
    keep = np.isfinite(x) & (w > 0)
    x, w = x[keep], w[keep]
    order = np.argsort(x, kind="stable")
    x, w = x[order], w[order]
    y = np.asarray(observed, float).ravel()
    if x.size == 0:
        return np.full(y.shape, np.nan)
    w = w / w.sum()
    cw = np.cumsum(w)
    cwx = np.concatenate([[0.0], np.cumsum(w * x)])
    k = np.searchsorted(x, y, side="right")
    below = np.concatenate([[0.0], cw])[k]
    absolute = y * (2.0 * below - 1.0) - 2.0 * cwx[k] + cwx[-1]
    spread = float(np.dot(w * x, 2.0 * cw - w - 1.0))
    out = absolute - spread
    out[~np.isfinite(y)] = np.nan
    return out


def central_interval(samples: np.ndarray, level: float) -> tuple[float, float]:
    """The central ``level`` interval of ``samples``: its (1 - level)/2 and
    (1 + level)/2 quantiles (numpy's default linear interpolation).

    Examples
    --------
    >>> central_interval(np.arange(101.0), 0.5)
    (25.0, 75.0)
    """
    if not 0.0 < level < 1.0:
        raise ValueError(f"level must be in (0, 1) (got {level})")
    x = np.asarray(samples, float).ravel()
    x = x[np.isfinite(x)]
    if x.size == 0:
        return float("nan"), float("nan")
    lo, hi = np.quantile(x, [(1.0 - level) / 2.0, (1.0 + level) / 2.0])
    return float(lo), float(hi)


def interval_coverage(
    samples_per_run: Sequence[np.ndarray], observed: np.ndarray, level: float
) -> float:
    """Fraction of runs whose observation lies in its ensemble's central ``level``
    interval (closed; see :func:`central_interval`). Runs with a non-finite
    observation are left out; NaN when none is left.

    Examples
    --------
    >>> ens = [np.arange(101.0)] * 4
    >>> interval_coverage(ens, np.array([50.0, 4.0, 95.0, 99.0]), 0.9)
    0.5
    """
    obs = np.asarray(observed, float).ravel()
    if len(samples_per_run) != obs.size:
        raise ValueError(
            f"{len(samples_per_run)} ensembles for {obs.size} observations"
        )
    hits = []
    for samples, y in zip(samples_per_run, obs, strict=True):
        if not np.isfinite(y):
            continue
        lo, hi = central_interval(samples, level)
        hits.append(lo <= y <= hi)
    return float(np.mean(hits)) if hits else float("nan")


def holdout_scores(
    ensembles: Sequence[np.ndarray],
    observed: np.ndarray,
    *,
    reference: Sequence[np.ndarray] | None = None,
) -> dict:
    """Scores of predicted ensembles against observed runouts (module docstring).

    Parameters
    ----------
    ensembles
        One ensemble (simulated runouts) per run.
    observed
        The observed runout of each run (NaN: not observed, left out).
    reference
        Optional reference ensembles (e.g. :func:`climatology`) for the skill score
        ``crps_skill = 1 - mean CRPS / mean CRPS of the reference`` (> 0: better
        than the reference).

    Returns
    -------
    dict
        ``n_runs``; ``crps`` (list, per run, NaN where not observed); ``mean_crps``
        and ``mean_crps_se`` (SD / sqrt(n) over runs); ``coverage_50``,
        ``coverage_90``; ``median_abs_error`` (median over runs of |ensemble
        median - observed|); ``mean_observed``, ``mean_predicted`` (mean over runs
        of the ensemble means); with ``reference``: ``reference_mean_crps`` and
        ``crps_skill``.

    Examples
    --------
    >>> s = holdout_scores([np.array([0.0, 1.0])] * 2, np.array([0.5, 1.0]))
    >>> s["crps"], s["mean_crps"]
    ([0.25, 0.25], 0.25)
    """
    obs = np.asarray(observed, float).ravel()
    if len(ensembles) != obs.size:
        raise ValueError(f"{len(ensembles)} ensembles for {obs.size} observations")
    crps = np.array([crps_ensemble(e, y) for e, y in zip(ensembles, obs, strict=True)])
    use = np.isfinite(obs)
    n = int(use.sum())
    medians = np.array([np.median(e) if len(e) else np.nan for e in ensembles])
    means = np.array([np.mean(e) if len(e) else np.nan for e in ensembles])
    out = {
        "n_runs": n,
        "crps": [float(c) for c in crps],
        "mean_crps": float(np.mean(crps[use])) if n else float("nan"),
        "mean_crps_se": float(np.std(crps[use], ddof=1) / np.sqrt(n))
        if n > 1
        else float("nan"),
        "coverage_50": interval_coverage(ensembles, obs, 0.5),
        "coverage_90": interval_coverage(ensembles, obs, 0.9),
        "median_abs_error": float(np.median(np.abs(medians[use] - obs[use])))
        if n
        else float("nan"),
        "mean_observed": float(np.mean(obs[use])) if n else float("nan"),
        "mean_predicted": float(np.mean(means[use])) if n else float("nan"),
    }
    if reference is not None:
        ref = holdout_scores(reference, obs)
        out["reference_mean_crps"] = ref["mean_crps"]
        out["crps_skill"] = 1.0 - out["mean_crps"] / ref["mean_crps"]
    return out


def climatology(
    calibration_observed: np.ndarray, n_runs: int | None = None
) -> np.ndarray | list[np.ndarray]:
    """The empirical distribution of the calibration runs' observed runouts (finite
    values, sorted) as an ensemble; with ``n_runs``, that ensemble for each of
    ``n_runs`` held-out runs (a list, for :func:`holdout_scores`).

    Examples
    --------
    >>> climatology(np.array([3.0, np.nan, 1.0]))
    array([1., 3.])
    >>> len(climatology(np.array([3.0, 1.0]), 5))
    5
    """
    x = np.asarray(calibration_observed, float).ravel()
    x = np.sort(x[np.isfinite(x)])
    if n_runs is None:
        return x
    return [x] * int(n_runs)
