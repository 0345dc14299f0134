"""Mass loss along the path (thesis section 6.5, eqs. 6.15 and 6.16)."""

from __future__ import annotations

import numpy as np
import pytest

from fieldkit.errors import ArgumentError
from fieldkit.physics.mass_loss import (
    REDUCTION_COEFFICIENTS_PER_M,
    initial_volume_from_impacts,
    reduction_coefficient,
    volume_ratio_with_distance,
    volume_ratio_with_impacts,
)


def test_tornado_source_volume_from_46_impacts():
    # Section 6.5: Omega_46 = 1.42 m^3 -> Omega_0 "about 30 m^3", "about 95 per cent"
    # of the volume lost. 1.42 * 46^0.8 = 30.4.
    assert initial_volume_from_impacts(1.42, 46) == pytest.approx(30, abs=0.5)
    assert 1 - volume_ratio_with_impacts(46) == pytest.approx(0.95, abs=0.005)


def test_tornado_reduction_coefficient():
    # Section 6.5: x = 610 m, Omega/Omega_0 = 1.42/30 = 0.047 -> lambda "0.03".
    lam = reduction_coefficient(610.0, 0.047)
    assert lam == pytest.approx(0.03, abs=0.005)
    assert volume_ratio_with_distance(610.0, lam) == pytest.approx(0.047, rel=1e-12)


def test_ehime_cube_final_volume():
    # Section 6.5: Omega_0 = 0.22 m^3, lambda = 0.02, x = 57 m -> "0.1 m^3".
    assert 0.22 * volume_ratio_with_distance(57.0, 0.02) == pytest.approx(
        0.1, abs=0.005
    )


def test_camaldoli_upper_bound_loses_80_percent():
    # Section 6.5: "as much as 80 per cent of the original rock mass is lost"; Camaldoli
    # Hill, maximum horizontal distance about 200 m, lambda up to 0.02 /m.
    high = REDUCTION_COEFFICIENTS_PER_M["camaldoli_hill_tuff"][1]
    assert 1 - volume_ratio_with_distance(200.0, high) == pytest.approx(0.80, abs=0.005)


def test_neutral_parameters_change_nothing():
    x = np.linspace(0, 500, 7)
    np.testing.assert_array_equal(volume_ratio_with_distance(x, 0.0), np.ones_like(x))
    np.testing.assert_array_equal(volume_ratio_with_impacts([1, 5, 40], 0.0), [1, 1, 1])
    assert volume_ratio_with_impacts(1) == 1.0


def test_ratios_decrease_monotonically():
    assert np.all(np.diff(volume_ratio_with_distance(np.arange(0, 300.0), 0.01)) < 0)
    assert np.all(np.diff(volume_ratio_with_impacts(np.arange(1, 50))) < 0)


@pytest.mark.parametrize(
    ("call", "argument"),
    [
        (lambda: volume_ratio_with_distance(-1.0, 0.01), "x_m"),
        (lambda: volume_ratio_with_distance(10.0, -0.01), "reduction_per_m"),
        (lambda: volume_ratio_with_impacts(0), "impact_number"),
        (lambda: volume_ratio_with_impacts(3, -0.8), "exponent"),
        (lambda: reduction_coefficient(100.0, 1.5), "volume_ratio"),
        (lambda: reduction_coefficient(0.0, 0.5), "x_m"),
        (lambda: initial_volume_from_impacts(-1.0, 4), "final_volume_m3"),
    ],
)
def test_bad_input_names_the_argument(call, argument):
    with pytest.raises(ArgumentError) as info:
        call()
    assert argument in str(info.value)
