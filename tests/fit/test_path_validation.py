"""Held-out validation: the three forecasts, scored on the same held-out runs."""

from __future__ import annotations

import numpy as np
import pytest

from fieldkit.fit.holdout import crps_ensemble
from fieldkit.fit.path_validation import FORECASTS, validate
from fieldkit.fit.synthetic_paths import synthetic_site

PHI = "materials.talus.friction_deg"
TRUTH = {PHI: 34.0}  # the base model (the "uncalibrated" start) has 30 deg


def test_truth_beats_start_and_scores_are_consistent():
    rng = np.random.default_rng(11)
    calibration = synthetic_site(TRUTH, 12, rng)
    holdout = synthetic_site(TRUTH, 12, rng)
    v = validate(holdout, calibration, TRUTH, rocks=150, seed=2)
    f = v["forecasts"]
    assert list(f) == list(FORECASTS)
    # with the true friction the held-out runouts are predicted better than with
    # the start (30 deg: rocks run further on the 12 deg runout zone)
    assert f["calibrated"]["mean_crps"] < f["uncalibrated"]["mean_crps"]
    assert f["uncalibrated"]["mean_predicted"] > f["calibrated"]["mean_predicted"]
    # each score is what holdout.py computes from the returned ensembles
    for name in FORECASTS:
        by_hand = np.mean(
            [
                crps_ensemble(e, y)
                for e, y in zip(v["ensembles"][name], v["observed"], strict=True)
            ]
        )
        assert f[name]["mean_crps"] == pytest.approx(by_hand, rel=1e-12)
        assert f[name]["mean_error_m"] == pytest.approx(
            f[name]["mean_predicted"] - f[name]["mean_observed"]
        )
    # the climatology is the calibration runs' observed runouts, for every run
    clim = v["ensembles"]["climatology"]
    observed = sorted(r.observed_runout_m for r in calibration)
    assert all(np.array_equal(c, observed) for c in clim)
    assert f["climatology"]["crps_skill"] == pytest.approx(0.0)
