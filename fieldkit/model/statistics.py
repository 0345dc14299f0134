"""Monte Carlo statistics with their standard errors: is N rocks enough?

A simulation of N rocks estimates a percentile, a mean or a maximum of a distribution;
run it again with another seed and the estimate moves. The Monte Carlo standard error
(SE) says by how much, so a designer sees whether N was enough (a p99 with an SE of
half a metre from 1,000 rocks is not a design value; from 100,000 rocks it may be).

* **Percentiles** -- the sample percentile (numpy's default linear interpolation
  between order statistics, Hyndman & Fan type 7). SE from the distribution-free
  order-statistic interval: the number of samples below the true p-quantile is
  Binomial(n, p), so the true quantile lies between the order statistics of ranks
  ``n p ± sqrt(n p (1 - p))`` with about 68 % confidence (one binomial standard
  deviation; Conover, *Practical Nonparametric Statistics*, 3rd ed., 1999, §3.2,
  quantile confidence intervals). The SE is half that interval. It needs no
  assumption about the distribution; for the median of N(0, 1) samples it tends to
  the asymptotic ``sqrt(pi/2) / sqrt(n) = 1.2533 / sqrt(n)``.
* **Mean** -- ``s / sqrt(n)`` with ``s`` the sample standard deviation (ddof = 1).
* **Maximum** -- the bootstrap SE, computed exactly rather than by resampling: the
  maximum of a bootstrap resample of n values is the k-th order statistic with
  probability ``(k/n)^n - ((k-1)/n)^n``, so the bootstrap distribution of the maximum
  (the limit of infinitely many resamples) is known in closed form and needs no
  random numbers. (The bootstrap of a maximum is known to understate its spread --
  the sample maximum is a biased, heavy-tailed estimate of the true one -- so read
  this SE as a lower bound.)
* **Fractions** (passing, stopped) -- the binomial ``sqrt(p (1 - p) / n)``.
* **Censored values** -- a rock that left the profile at its lower end ran out *at
  least* to the profile's end: its runout is right-censored there. A statistic that
  uses a censored value (the mean, a percentile whose interpolation reaches one, the
  maximum) is only a lower bound; :func:`distribution` flags each one
  (``lower_bound``) when told which values are censored.
* **A measured value among simulated ones** -- :func:`rank_of`: its percentile (percent
  of the values below it, ties counted half) with the binomial SE, or, above (below)
  every simulated value, no percentile but ``beyond`` and the simulated extreme: the
  sample says only that the value lies beyond all of them, not how far.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

#: Percentiles every distribution in ``summary.json`` reports.
PERCENTILES: tuple[int, ...] = (50, 90, 95, 99)


def percentile_se(values: np.ndarray, q: float) -> tuple[float, float]:
    """The ``q``-th percentile of ``values`` and its Monte Carlo standard error.

    Parameters
    ----------
    values
        Samples (NaN are ignored).
    q
        Percentile in [0, 100].

    Returns
    -------
    (estimate, se)
        NaN, NaN without samples; SE NaN for a single sample.

    Notes
    -----
    SE = half the distance between the sample quantiles at probabilities
    ``p ± sqrt(p (1 - p) / n)`` (ranks ``n p ± sqrt(n p (1 - p))``, the
    order-statistic interval of the module docstring), clipped to [0, 1].

    Examples
    --------
    >>> est, se = percentile_se(np.array([1.0, 2.0, 3.0, 4.0, 5.0]), 50)
    >>> est, round(se, 4)  # quantiles at 0.5 -/+ 0.2236: 2.1056, 3.8944
    (3.0, 0.8944)
    """
    x = _finite(values)
    n = x.size
    if n == 0:
        return math.nan, math.nan
    p = q / 100.0
    estimate = float(np.percentile(x, q))
    if n == 1:
        return estimate, math.nan
    half = math.sqrt(p * (1.0 - p) / n)
    lo, hi = np.quantile(x, [max(p - half, 0.0), min(p + half, 1.0)])
    return estimate, float(hi - lo) / 2.0


def mean_se(values: np.ndarray) -> tuple[float, float]:
    """The mean and its standard error ``s / sqrt(n)`` (sample SD, ddof = 1).

    Examples
    --------
    >>> mean_se(np.array([1.0, 2.0, 3.0, 4.0]))
    (2.5, 0.6454972243679028)
    """
    x = _finite(values)
    if x.size == 0:
        return math.nan, math.nan
    if x.size == 1:
        return float(x[0]), math.nan
    return float(x.mean()), float(x.std(ddof=1) / math.sqrt(x.size))


def max_se(values: np.ndarray) -> tuple[float, float]:
    """The maximum and its exact bootstrap standard error (module docstring).

    The bootstrap maximum is the k-th smallest value with probability
    ``(k/n)^n - ((k-1)/n)^n``; its standard deviation is the SE.

    Examples
    --------
    >>> m, se = max_se(np.array([0.0, 1.0]))  # resample max is 1 w.p. 3/4
    >>> m, round(se, 6)
    (1.0, 0.433013)
    """
    x = np.sort(_finite(values))
    n = x.size
    if n == 0:
        return math.nan, math.nan
    if n == 1:
        return float(x[0]), math.nan
    k = np.arange(n + 1, dtype=float)
    cdf = np.exp(n * np.log(np.maximum(k / n, 1e-300)))  # (k/n)^n, underflows to 0
    cdf[0] = 0.0
    w = np.diff(cdf)
    mean = float(np.dot(w, x))
    var = float(np.dot(w, (x - mean) ** 2))
    return float(x[-1]), math.sqrt(max(var, 0.0))


def fraction_se(count: int, n: int) -> tuple[float, float]:
    """A fraction ``count / n`` and its binomial SE ``sqrt(p (1 - p) / n)``.

    Examples
    --------
    >>> fraction_se(25, 100)
    (0.25, 0.04330127018922193)
    """
    if n <= 0:
        return math.nan, math.nan
    p = count / n
    return p, math.sqrt(p * (1.0 - p) / n)


def distribution(
    values: np.ndarray,
    percentiles: Sequence[int] = PERCENTILES,
    *,
    at_least: np.ndarray | None = None,
) -> dict[str, object]:
    """Mean, percentiles and max of ``values`` (NaN ignored), each with its SE.

    Parameters
    ----------
    values
        Samples (NaN are ignored).
    percentiles
        Percentiles to report.
    at_least
        Optional bool mask, one per value: True where the value is right-censored
        (the true value is at least this, e.g. the runout of a rock that left the
        profile). Adds ``lower_bound``.

    Returns
    -------
    dict
        ``{"n": count, "mean": ..., "p50": ..., ..., "max": ..., "se": {"mean": ...,
        "p50": ..., "max": ...}}``; values are None (JSON null) where undefined. With
        ``at_least``: ``lower_bound`` (per statistic, True when it uses a censored
        value and is only a lower bound, :func:`lower_bounds`) and ``censored`` (how
        many values are censored).

    Examples
    --------
    >>> d = distribution(np.array([1.0, 2.0, 3.0, 4.0, 5.0]), percentiles=(50,))
    >>> d["n"], d["mean"], d["p50"], d["max"], round(d["se"]["p50"], 4)
    (5, 3.0, 3.0, 5.0, 0.8944)
    >>> d = distribution(np.array([1.0, 2.0, 5.0, 5.0]), percentiles=(50, 90),
    ...                  at_least=np.array([False, False, True, True]))
    >>> d["lower_bound"], d["censored"]
    ({'mean': True, 'p50': True, 'p90': True, 'max': True}, 2)
    """
    out: dict[str, object] = {"n": int(_finite(values).size)}
    se: dict[str, float | None] = {}
    stats = {"mean": mean_se(values)}
    for q in percentiles:
        stats[f"p{q}"] = percentile_se(values, q)
    stats["max"] = max_se(values)
    for name, (value, error) in stats.items():
        out[name] = _json(value)
        se[name] = _json(error)
    out["se"] = se
    if at_least is not None:
        flags = lower_bounds(values, at_least, percentiles)
        out["lower_bound"] = flags
        finite = np.isfinite(np.asarray(values, dtype=float).ravel())
        out["censored"] = int(np.asarray(at_least, bool).ravel()[finite].sum())
    return out


def lower_bounds(
    values: np.ndarray, at_least: np.ndarray, percentiles: Sequence[int] = PERCENTILES
) -> dict[str, bool]:
    """Which statistics of :func:`distribution` are only lower bounds.

    A statistic is a lower bound when it uses a right-censored value (``at_least``
    True): the mean when any value is censored; a percentile when either order
    statistic its linear interpolation (type 7) uses is censored, ties sorted with the
    censored values last; the maximum when it is censored.

    Examples
    --------
    >>> x = np.array([1.0, 2.0, 3.0, 4.0, 10.0])
    >>> lower_bounds(x, x == 10.0, (50, 90))
    {'mean': True, 'p50': False, 'p90': True, 'max': True}
    """
    x = np.asarray(values, dtype=float).ravel()
    c = np.asarray(at_least, dtype=bool).ravel()
    keep = np.isfinite(x)
    x, c = x[keep], c[keep]
    n = x.size
    ordered = c[np.lexsort((c, x))]  # by value, censored last among ties
    out = {"mean": bool(c.any())}
    for q in percentiles:
        if n == 0:
            out[f"p{q}"] = False
            continue
        h = (n - 1) * q / 100.0
        lo, hi = math.floor(h), min(math.ceil(h), n - 1)
        out[f"p{q}"] = bool(ordered[lo] or (hi != lo and ordered[hi]))
    out["max"] = bool(n and ordered[-1])
    return out


def rank_of(values: np.ndarray, value: float) -> dict[str, object]:
    """Where a measured ``value`` falls among simulated ``values`` (NaN ignored).

    Returns
    -------
    dict
        ``measured``; ``n`` (simulated values); ``percentile`` (percent of the values
        below ``value``, ties counted half) and its binomial ``percentile_se`` --
        both None without values, or when ``value`` lies above or below every one of
        them (then the sample gives no percentile, only that it is beyond all:
        ``beyond`` is ``"above"`` or ``"below"``, else None); ``simulated_min`` and
        ``simulated_max``.

    Examples
    --------
    >>> rank_of(np.array([1.0, 2.0, 3.0, 4.0]), 3.0)["percentile"]
    62.5
    >>> r = rank_of(np.array([1.0, 2.0, 3.0, 4.0]), 9.0)
    >>> r["beyond"], r["percentile"], r["simulated_max"]
    ('above', None, 4.0)
    """
    x = _finite(values)
    n = int(x.size)
    out: dict[str, object] = {
        "measured": float(value),
        "n": n,
        "percentile": None,
        "percentile_se": None,
        "beyond": None,
        "simulated_min": float(x.min()) if n else None,
        "simulated_max": float(x.max()) if n else None,
    }
    if n == 0:
        return out
    if value > x.max():
        out["beyond"] = "above"
        return out
    if value < x.min():
        out["beyond"] = "below"
        return out
    fraction = float((x < value).sum() + 0.5 * (x == value).sum()) / n
    out["percentile"] = 100.0 * fraction
    out["percentile_se"] = 100.0 * math.sqrt(fraction * (1.0 - fraction) / n)
    return out


def envelope_percentiles(
    height_m: np.ndarray, percentiles: Sequence[int] = (50, 95)
) -> dict[str, np.ndarray]:
    """Per-bin percentiles and max of the per-rock maximum height (bounce envelope).

    Parameters
    ----------
    height_m
        (rocks, bins): each rock's maximum centre height above the ground in each
        x bin, NaN where the rock never reached the bin.

    Returns
    -------
    dict
        ``reached`` (rocks reaching each bin), ``p50``, ``p95`` (as asked), ``max``:
        arrays of one value per bin over the rocks that *reached* the bin (NaN for a
        bin no rock reached).
    """
    h = np.asarray(height_m, dtype=float)
    bins = h.shape[1] if h.ndim == 2 else 0
    reached = np.isfinite(h).sum(axis=0) if bins else np.zeros(0, int)
    out: dict[str, np.ndarray] = {"reached": reached}
    for q in percentiles:
        out[f"p{q}"] = np.full(bins, np.nan)
    out["max"] = np.full(bins, np.nan)
    hit = reached > 0
    if hit.any():
        sub = h[:, hit]
        for q in percentiles:
            out[f"p{q}"][hit] = np.nanpercentile(sub, q, axis=0)
        out["max"][hit] = np.nanmax(sub, axis=0)
    return out


def _finite(values: np.ndarray) -> np.ndarray:
    x = np.asarray(values, dtype=float).ravel()
    return x[np.isfinite(x)]


def _json(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None
