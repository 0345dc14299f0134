"""fieldkit.campaign.virtual: which impacts become scars, and the survey error."""

from __future__ import annotations

import numpy as np
import pytest

from fieldkit.campaign.design import CampaignDesign
from fieldkit.campaign.virtual import _position_errors, scar_rows
from fieldkit.errors import ArgumentError


def test_scar_rows_keeps_energetic_impacts_past_the_spacing():
    x = np.array([1.0, 3.5, 4.0, 9.0, 8.0, 12.0, 30.0])
    ke = np.array([9e3, 9e3, 9e3, 1e3, 9e3, 9e3, 9e3])
    idx, merged = scar_rows(x, ke, 0.0, CampaignDesign(scar_spacing_m=2.0))
    # 1.0 is within 2 m of the source; 3.5 kept; 4.0 within 2 m of it; 9.0 too
    # weak; 8.0 kept; 12.0 kept; 30.0 kept
    assert idx.tolist() == [1, 4, 5, 6]
    # each scar stands for the impacts up to the next one (itself included)
    assert merged.tolist() == [3, 1, 1, 1]
    assert merged.sum() == len(x) - idx[0]


def test_scar_rows_energy_threshold_is_inclusive_and_backward_bounces_merge():
    x = np.array([5.0, 4.0, 10.0, 15.0])
    ke = np.array([5_000.0, 9e3, 4_999.0, 5_000.0])
    idx, merged = scar_rows(x, ke, 0.0, CampaignDesign())
    # 4.0 lies behind the last scar: not told apart from it
    assert idx.tolist() == [0, 3] and merged.tolist() == [3, 1]


def test_scar_rows_stops_at_max_scars_and_may_find_none():
    x = np.arange(1, 11) * 5.0
    ke = np.full(10, 1e4)
    idx, merged = scar_rows(x, ke, 0.0, CampaignDesign(max_scars=3))
    assert idx.tolist() == [0, 1, 2] and merged.tolist() == [1, 1, 8]
    idx, merged = scar_rows(x, ke * 0, 0.0, CampaignDesign())
    assert idx.size == 0 and merged.size == 0


def test_design_refuses_one_scar_and_a_reversed_canopy():
    with pytest.raises(ArgumentError, match="max_scars"):
        CampaignDesign(max_scars=1)
    with pytest.raises(ArgumentError, match="canopy_x_m"):
        CampaignDesign(canopy_x_m=((5.0, 3.0),))


def test_position_errors_are_ar1_along_the_path():
    # points 2 m apart, L = 4 m: neighbours correlated exp(-0.5) = 0.607, points
    # two apart exp(-1) = 0.368, over many independent paths
    x = np.arange(12) * 2.0
    design = CampaignDesign(
        position_sigma_m=0.7, elevation_sigma_m=0.3, correlation_length_m=4.0
    )
    rng = np.random.default_rng(8)
    draws = 20_000
    dx = np.empty((draws, x.size))
    dz = np.empty((draws, x.size))
    for k in range(draws):
        dx[k], dz[k] = _position_errors(x, design, rng)
    se = 3.0 / np.sqrt(draws)  # 3 standard errors of a correlation near 0.6 or less
    for err, sigma in ((dx, 0.7), (dz, 0.3)):
        sd = err.std(axis=0)
        assert np.all(np.abs(sd / sigma - 1) < 3 / np.sqrt(2 * draws)), sd
        lag1 = [np.corrcoef(err[:, i], err[:, i + 1])[0, 1] for i in range(11)]
        lag2 = [np.corrcoef(err[:, i], err[:, i + 2])[0, 1] for i in range(10)]
        assert np.allclose(lag1, np.exp(-0.5), atol=se), lag1
        assert np.allclose(lag2, np.exp(-1.0), atol=se), lag2
    # plan and height errors are independent of each other
    assert abs(np.corrcoef(dx[:, 5], dz[:, 5])[0, 1]) < se


def test_position_errors_uneven_gaps_and_canopy():
    # the correlation follows each gap; under canopy the SD is the canopy's
    x = np.array([0.0, 1.0, 11.0, 12.0])
    design = CampaignDesign(
        position_sigma_m=0.5,
        correlation_length_m=5.0,
        canopy_x_m=((10.0, 20.0),),
        canopy_sigma_m=2.0,
    )
    rng = np.random.default_rng(9)
    draws = 20_000
    dx = np.array([_position_errors(x, design, rng)[0] for _ in range(draws)])
    se = 3.0 / np.sqrt(draws)
    corr = [np.corrcoef(dx[:, i], dx[:, i + 1])[0, 1] for i in range(3)]
    assert np.allclose(corr, np.exp(-np.diff(x) / 5.0), atol=se), corr
    sd = dx.std(axis=0)
    np.testing.assert_allclose(sd, [0.5, 0.5, 2.0, 2.0], rtol=3 / np.sqrt(2 * draws))


def test_position_errors_are_independent_without_a_correlation_length():
    x = np.arange(6) * 1.0
    rng = np.random.default_rng(10)
    draws = 20_000
    dx = np.array([_position_errors(x, CampaignDesign(), rng)[0] for _ in range(draws)])
    lag1 = [np.corrcoef(dx[:, i], dx[:, i + 1])[0, 1] for i in range(5)]
    assert np.all(np.abs(lag1) < 3.0 / np.sqrt(draws)), lag1


def test_a_scar_surveyed_behind_the_one_before_is_merged_into_it():
    import pandas as pd

    from fieldkit.campaign.virtual import _ahead, _merge_behind

    x_obs = np.array([0.0, 5.0, 4.9, 6.0, 5.5, 9.0])
    keep = _ahead(x_obs)
    assert keep.tolist() == [True, True, False, True, False, True]
    truth = pd.DataFrame(
        {"point": list("012345"), "impacts_merged": [0, 2, 1, 3, 1, 1]}
    )
    out = _merge_behind(truth, keep)
    # point 2's impact goes to point 1, point 4's to point 3; none lost
    assert out["point"].tolist() == ["0", "1", "3", "5"]
    assert out["impacts_merged"].tolist() == [0, 3, 4, 1]
