"""Track impacts' ``*_sd`` columns against the spread of noisy replicates.

The truth is a ball bouncing on a 10° plane (e_n 0.6, e_t 0.8) sampled at 1205 fps
with 2 mm Gaussian noise on x and z. Each replicate draws new noise and is analysed
as a whole (segmentation, fits, contact instants); the standard deviation of e_n,
vi, ... over 30 replicates must match the sd each analysis reports from its own fit
residuals.
"""

from __future__ import annotations

import numpy as np
import pytest

from fieldkit.impact_table import SD_COLUMNS
from fieldkit.tracking.flights.ballistic_fit import fit_flight
from fieldkit.tracking.flights.impact_uncertainty import contact_sd
from fieldkit.tracking.flights.pipeline import analyse_track
from fieldkit.tracking.flights.synthetic_tracks import bouncing_ball

REPLICATES = 30
CHECKED = ("e_n", "e_t", "vi_mps", "vin_mps", "vfn_mps", "theta_i_deg")


def analyse(seed: int):
    s = bouncing_ball(
        fps=1205.0,
        duration_s=0.9,
        start_velocity_mps=(1.5, 1.5),
        surface_angle_deg=10.0,
        noise_m=2e-3,
        rng=np.random.default_rng(seed),
    )
    return analyse_track(s.track, radius_m=0.0375, surface_angle_deg=10.0)


@pytest.mark.slow
def test_reported_sd_matches_the_spread_of_replicates():
    values, sds = [], []
    for seed in range(REPLICATES):
        frame = analyse(seed).impacts.frame
        assert len(frame) == 2  # both true impacts found in every replicate
        values.append(frame[list(CHECKED)].to_numpy(float))
        sds.append(frame[[SD_COLUMNS[c] for c in CHECKED]].to_numpy(float))
    spread = np.std(np.array(values), axis=0, ddof=1)
    reported = np.mean(np.array(sds), axis=0)
    assert np.all(reported > 0)
    # 30 replicates estimate a standard deviation to about 13 %
    np.testing.assert_allclose(reported, spread, rtol=0.3)


def test_flight_covariance_is_the_least_squares_one():
    """Independent reference: a straight-line fit's slope variance is
    sigma^2 / sum((t - mean t)^2) for z + g t^2 / 2 (g fixed)."""
    rng = np.random.default_rng(4)
    t = np.linspace(0.0, 0.3, 40)
    x = 1.0 + 2.0 * t + rng.normal(0, 1e-3, t.size)
    z = 2.0 + 1.0 * t - 0.5 * 9.81 * t**2 + rng.normal(0, 1e-3, t.size)
    fit = fit_flight(t, x, z)
    sigma2 = (
        np.sum((x - fit.position(t)[0]) ** 2) + np.sum((z - fit.position(t)[1]) ** 2)
    ) / (2 * t.size - 4)
    tau = t - fit.t_ref_s
    assert fit.covariance[1, 1] == pytest.approx(sigma2 / np.sum(tau**2), rel=1e-9)
    assert fit.covariance[0, 0] == pytest.approx(sigma2 / t.size, rel=1e-9)
    assert fit.vz_se_mps == pytest.approx(np.sqrt(fit.covariance[1, 1]), rel=1e-12)


def test_a_moving_contact_time_moves_vz_not_vx():
    """The contact instant's error moves both vz by g dt (so vin on a level surface)
    but not vx (vit on a level surface): freeing the time changes only the former
    (either way: the instant's error is correlated with the fitted vz)."""
    analysis = analyse(0)
    before, after = analysis.flights[0], analysis.flights[1]
    t = float(analysis.impacts.frame["t_s"].iloc[0])
    free = contact_sd(before, after, (t, t), 0.0, instant=True)
    held = contact_sd(before, after, (t, t), 0.0, instant=False)
    assert free["vin_sd_mps"] != pytest.approx(held["vin_sd_mps"], rel=0.02)
    assert free["vit_sd_mps"] == pytest.approx(held["vit_sd_mps"], rel=1e-6)
    assert held["vit_sd_mps"] == pytest.approx(before.vx_se_mps, rel=1e-6)
