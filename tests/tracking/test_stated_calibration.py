"""A stated scale and rate uncertainty widens each flight's check of g against 9.81.

A length scale off by 3 % makes every fitted g 3 % off; a capture rate off by 1 %
makes it 2 % off (g ~ L / T^2). With the scale stated to 3 % the check must pass
(within 3 standard errors) on a track whose scale really is 3 % off, and still catch
a scale 15 % off; taken as exact it must warn for the 3 % error.
"""

import numpy as np
import pytest

from fieldkit.physics.constants import G
from fieldkit.track import Track
from fieldkit.tracking.flights.ballistic_fit import calibration_rel_sd
from fieldkit.tracking.flights.pipeline import analyse_track
from fieldkit.tracking.flights.synthetic_tracks import bouncing_ball


def _scaled(factor: float) -> Track:
    truth = bouncing_ball(
        duration_s=0.5, e_n=0.6, e_t=0.8, noise_m=2e-4,
        rng=np.random.default_rng(7),
    )  # fmt: skip
    frame = truth.track.frame.copy()
    frame["x_m"] *= factor
    frame["z_m"] *= factor
    return Track(frame, source="scaled.csv", fps=truth.track.fps)


def test_the_rate_counts_twice_and_adds_in_quadrature():
    assert calibration_rel_sd(0.03, 0.0) == pytest.approx(0.03)
    assert calibration_rel_sd(0.0, 0.01) == pytest.approx(0.02)
    assert calibration_rel_sd(0.03, 0.02) == pytest.approx(0.05)
    with pytest.raises(ValueError, match="fps_rel_sd"):
        calibration_rel_sd(0.0, -0.1)


def test_a_scale_off_by_its_stated_uncertainty_passes_and_a_larger_error_does_not():
    exact = analyse_track(_scaled(1.03), radius_m=0.0375, surface_angle_deg=10.0)
    assert exact.flights
    # taken as exact, a 3 % scale error is many fit SEs: warned, naming g
    assert all(f.g_mps2 == pytest.approx(1.03 * G, rel=0.01) for f in exact.flights)
    assert max(abs(f.g_sigmas) for f in exact.flights) > 3
    assert any("fitted g" in w for w in exact.warnings)

    stated = analyse_track(
        _scaled(1.03), radius_m=0.0375, surface_angle_deg=10.0,
        calibration_rel_sd=0.03,
    )  # fmt: skip
    for fit, same in zip(stated.flights, exact.flights, strict=True):
        assert fit.g_mps2 == same.g_mps2  # the fit itself is unchanged
        assert fit.g_se_mps2 == same.g_se_mps2
        assert fit.g_check_se_mps2 == pytest.approx(
            np.hypot(fit.g_se_mps2, 0.03 * fit.g_mps2)
        )
        assert abs(fit.g_sigmas) < 3
    assert not any("fitted g" in w for w in stated.warnings)

    far = analyse_track(
        _scaled(1.15), radius_m=0.0375, surface_angle_deg=10.0,
        calibration_rel_sd=0.03,
    )  # fmt: skip
    assert all(abs(f.g_sigmas) > 3 for f in far.flights)  # 15 % is ~5 SE of 3 %
    assert any("fitted g" in w for w in far.warnings)


def test_a_negative_stated_uncertainty_is_refused():
    with pytest.raises(Exception, match="calibration_rel_sd must be >= 0"):
        analyse_track(_scaled(1.0), radius_m=0.0375, calibration_rel_sd=-0.01)
