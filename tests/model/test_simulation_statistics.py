"""Monte Carlo statistics: estimates and standard errors against known truths."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from fieldkit.model.statistics import (
    distribution,
    envelope_percentiles,
    fraction_se,
    max_se,
    mean_se,
    percentile_se,
)


def test_percentiles_of_a_small_array_by_hand():
    x = np.array([4.0, 1.0, 3.0, 2.0, 5.0, np.nan])  # NaN ignored
    # type-7 positions (n-1) p on the sorted 1..5: p90 -> 3.6 -> 4.6
    assert percentile_se(x, 50)[0] == 3.0
    assert percentile_se(x, 90)[0] == pytest.approx(4.6)
    assert percentile_se(x, 100)[0] == 5.0
    # SE: quantiles at 0.9 -/+ sqrt(0.09/5) = 0.9 -/+ 0.1342 -> clipped at 1.0
    lo = 1 + 4 * (0.9 - math.sqrt(0.09 / 5))
    assert percentile_se(x, 90)[1] == pytest.approx((5.0 - lo) / 2)


def test_median_se_of_normal_samples_is_1_2533_over_root_n():
    n, reps = 2000, 400
    rng = np.random.default_rng(7)
    samples = rng.standard_normal((reps, n))
    medians = np.median(samples, axis=1)
    reported = np.array([percentile_se(s, 50)[1] for s in samples])
    theory = math.sqrt(math.pi / 2) / math.sqrt(n)
    assert np.mean(reported) == pytest.approx(theory, rel=0.05)
    # what a user cares about: the reported SE matches the spread over reruns
    assert np.mean(reported) == pytest.approx(np.std(medians, ddof=1), rel=0.15)


def test_p95_se_matches_the_spread_over_reruns():
    n, reps = 2000, 400
    rng = np.random.default_rng(8)
    samples = rng.exponential(1.0, (reps, n))
    p95 = np.percentile(samples, 95, axis=1)
    reported = np.mean([percentile_se(s, 95)[1] for s in samples])
    # asymptotic: sqrt(p(1-p)/n) / f(q), f(q) = 1 - p for Exp(1)
    assert reported == pytest.approx(math.sqrt(0.95 * 0.05 / n) / 0.05, rel=0.1)
    assert reported == pytest.approx(np.std(p95, ddof=1), rel=0.15)


def test_mean_se_is_sigma_over_root_n():
    x = np.random.default_rng(3).normal(5.0, 2.0, 10000)
    m, se = mean_se(x)
    assert se == pytest.approx(x.std(ddof=1) / 100.0)
    assert se == pytest.approx(0.02, rel=0.03)
    assert m == pytest.approx(5.0, abs=4 * se)


def test_max_se_is_the_exact_bootstrap():
    x = np.array([1.0, 2.0, 3.0])
    # resample max = x_(k) with prob (k/3)^3 - ((k-1)/3)^3: 1/27, 7/27, 19/27
    w = np.array([1, 7, 19]) / 27
    mean = np.dot(w, x)
    assert max_se(x) == (3.0, pytest.approx(math.sqrt(np.dot(w, (x - mean) ** 2))))
    # agrees with resampling (a Monte Carlo bootstrap) on a larger sample
    rng = np.random.default_rng(5)
    y = rng.exponential(1.0, 300)
    boot = y[rng.integers(0, y.size, (20000, y.size))].max(axis=1)
    assert max_se(y)[1] == pytest.approx(boot.std(), rel=0.05)


def test_fraction_se_is_binomial():
    assert fraction_se(30, 120) == (0.25, pytest.approx(math.sqrt(0.25 * 0.75 / 120)))
    assert fraction_se(0, 10) == (0.0, 0.0)
    assert all(math.isnan(v) for v in fraction_se(0, 0))


def test_distribution_without_samples_is_json_null():
    d = distribution(np.array([np.nan]))
    assert d["n"] == 0 and d["p50"] is None and d["se"]["max"] is None
    json.dumps(d)


def test_envelope_percentiles_per_bin_over_rocks_that_reached_it():
    h = np.array([[1.0, 2.0, np.nan], [3.0, np.nan, np.nan], [5.0, 4.0, np.nan]])
    e = envelope_percentiles(h)
    assert e["reached"].tolist() == [3, 2, 0]
    assert e["p50"][:2].tolist() == [3.0, 3.0]
    assert e["p95"][0] == pytest.approx(4.8)
    assert e["max"][:2].tolist() == [5.0, 4.0]
    assert np.isnan(e["max"][2])


def test_summary_contract(synthetic_simulation):
    result = synthetic_simulation(rocks=4000, seed=2)
    s = result.summary()
    json.dumps(s)  # plain JSON
    assert s["rocks"] == 4000 and s["impacts"] == 28000 and s["seed"] == 2
    assert s["wall_s"] == 0.5
    runout = s["runout_x_m"]
    # U(60, 100): p50 = 80, p90 = 96, mean 80
    assert runout["p50"] == pytest.approx(80.0, abs=3 * runout["se"]["p50"] + 0.1)
    assert runout["p90"] == pytest.approx(96.0, abs=3 * runout["se"]["p90"] + 0.1)
    assert runout["se"]["mean"] == pytest.approx(40 / math.sqrt(12) / 63.25, rel=0.05)
    for key in ("mean", "p50", "p90", "p95", "p99", "max"):
        assert key in runout and key in runout["se"]
    assert s["stopped_fraction"] == pytest.approx(1.0)
    (point,) = s["analysis_points"]
    p = 0.75  # P(U(60, 100) > 70)
    assert point["passing_fraction"] == pytest.approx(
        p, abs=3 * point["passing_fraction_se"]
    )
    assert point["passing_fraction_se"] == pytest.approx(
        math.sqrt(p * (1 - p) / 4000), rel=0.05
    )
    speed = point["speed_mps"]
    assert speed["n"] == point["passing"]
    # N(10, 2): p90 = 10 + 1.2816 * 2
    assert speed["p90"] == pytest.approx(12.563, abs=3 * speed["se"]["p90"])
    for key in ("ke_j", "re_j", "total_j", "bounce_height_m"):
        assert point[key]["n"] == point["passing"]
    assert s["model"]["effects"] == {"air_drag": {"cd": 0.5}}
    assert len(s["envelope"]["x_m"]) == 10


def test_lower_bounds_follow_the_interpolation_into_censored_values():
    from fieldkit.model.statistics import lower_bounds

    x = np.arange(1.0, 11.0)  # 1..10, the last two censored (left the profile)
    censored = x >= 9.0
    flags = lower_bounds(x, censored, (50, 80, 85, 90))
    # type 7: p80 -> position 7.2 between 8 and 9 (9 censored): a lower bound
    assert flags == {
        "mean": True, "p50": False, "p80": True, "p85": True, "p90": True, "max": True
    }  # fmt: skip
    # exactly at an uncensored order statistic: position 7.0 -> 8, measured
    assert lower_bounds(x, censored, (70,))["p70"] is False
    assert lower_bounds(x, censored, (100 * 7 / 9,))[f"p{100 * 7 / 9}"] is False
    # ties with a censored value: sorted after the uncensored, the bound shows
    tie = np.array([1.0, 2.0, 2.0])
    assert lower_bounds(tie, np.array([False, True, False]), (50,))["p50"] is False
    assert lower_bounds(tie, np.array([False, True, False]), (100,))["p100"] is True
    assert not any(lower_bounds(x, np.zeros(10, bool)).values())


def test_rank_of_a_value_beyond_the_sample_has_no_percentile():
    from fieldkit.model.statistics import rank_of

    x = np.array([3.0, 1.0, 2.0, np.nan])
    inside = rank_of(x, 2.0)
    assert inside["percentile"] == 50.0 and inside["beyond"] is None
    assert inside["percentile_se"] == pytest.approx(100 * math.sqrt(0.25 / 3))
    assert rank_of(x, 3.0)["percentile"] == pytest.approx(100 * 2.5 / 3)  # a tie
    above, below = rank_of(x, 3.5), rank_of(x, 0.5)
    assert (above["beyond"], above["percentile"], above["simulated_max"]) == (
        "above", None, 3.0
    )  # fmt: skip
    assert (below["beyond"], below["simulated_min"], below["n"]) == ("below", 1.0, 3)
    assert rank_of(np.array([np.nan]), 1.0)["percentile"] is None
    json.dumps(above)
