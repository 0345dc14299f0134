"""Held-out scores on hand-checked tiny cases (fieldkit.fit.holdout)."""

from __future__ import annotations

import numpy as np
import pytest

from fieldkit.fit.holdout import (
    central_interval,
    climatology,
    crps_ensemble,
    holdout_scores,
    interval_coverage,
)


def test_crps_two_members_by_hand():
    # F steps 0 -> 0.5 at 0 and -> 1 at 1; y = 0.5: integral of (F - H)^2 is
    # 0.5 * 0.25 + 0.5 * 0.25 = 0.25; energy form 0.5 - 0.5 * 0.5 = 0.25.
    assert crps_ensemble(np.array([1.0, 0.0]), 0.5) == pytest.approx(0.25, abs=1e-15)
    # y outside: E|X - 3| = 2.5, E|X - X'| / 2 = 0.25.
    assert crps_ensemble(np.array([0.0, 1.0]), 3.0) == pytest.approx(2.25, abs=1e-15)


def test_crps_equals_pairwise_and_integral_forms():
    rng = np.random.default_rng(3)
    x = rng.normal(10.0, 2.0, 57)
    y = 11.3
    pairwise = np.mean(np.abs(x - y)) - 0.5 * np.mean(np.abs(x[:, None] - x[None]))
    assert crps_ensemble(x, y) == pytest.approx(pairwise, rel=1e-12)
    grid = np.linspace(0.0, 25.0, 200_001)
    cdf = np.searchsorted(np.sort(x), grid, side="right") / x.size
    integral = np.sum((cdf - (grid >= y)) ** 2) * (grid[1] - grid[0])
    assert crps_ensemble(x, y) == pytest.approx(integral, abs=1e-3)


def test_crps_nan_and_single_member():
    assert crps_ensemble(np.array([2.0, np.nan]), 5.0) == 3.0
    assert np.isnan(crps_ensemble(np.array([1.0]), np.nan))


def test_interval_coverage_on_four_runs():
    ens = [np.arange(101.0)] * 4  # central 90 %: [5, 95]; 50 %: [25, 75]
    obs = np.array([50.0, 4.0, 95.0, 99.0])
    assert central_interval(ens[0], 0.5) == (25.0, 75.0)
    assert interval_coverage(ens, obs, 0.9) == 0.5
    assert interval_coverage(ens, obs, 0.5) == 0.25
    assert interval_coverage(ens, np.array([50.0, np.nan, 1.0, 2.0]), 0.9) == 1 / 3


def test_holdout_scores_by_hand():
    ens = [np.array([0.0, 1.0]), np.array([2.0, 4.0])]
    obs = np.array([0.5, 4.0])
    s = holdout_scores(ens, obs)
    # run 2: E|X - 4| = 1, E|X - X'| / 2 = 0.5 -> 0.5
    assert s["crps"] == pytest.approx([0.25, 0.5])
    assert s["mean_crps"] == pytest.approx(0.375)
    # 90 % intervals [0.05, 0.95] (holds 0.5) and [2.1, 3.9] (misses 4)
    assert s["coverage_90"] == 0.5
    # medians 0.5 and 3: errors 0 and 1
    assert s["median_abs_error"] == pytest.approx(0.5)
    assert s["mean_observed"] == pytest.approx(2.25)
    assert s["mean_predicted"] == pytest.approx(1.75)
    assert s["n_runs"] == 2


def test_climatology_reference_and_skill():
    clim = climatology(np.array([3.0, np.nan, 1.0]), 2)
    assert [c.tolist() for c in clim] == [[1.0, 3.0], [1.0, 3.0]]
    ens = [np.array([0.5]), np.array([4.0])]
    s = holdout_scores(ens, np.array([0.5, 4.0]), reference=clim)
    # climatology {1, 3}: at 0.5: 1.5 - 0.5 = 1.0; at 4: 2.0 - 0.5 = 1.5
    assert s["reference_mean_crps"] == pytest.approx(1.25)
    assert s["crps_skill"] == pytest.approx(1.0)  # perfect point forecasts


def test_doctests():
    import doctest

    import fieldkit.fit.holdout as holdout
    import fieldkit.fit.path_fit as path_fit
    import fieldkit.fit.synthetic_paths as synthetic_paths

    for module in (holdout, path_fit, synthetic_paths):
        result = doctest.testmod(module)
        assert result.failed == 0 and result.attempted > 0, module.__name__
