"""Fall velocity with slope angle and effective friction (thesis eqs. 3.13-3.16,
Table 3-1, worked example 3C with the erratum of docs/thesis-notes.md)."""

from __future__ import annotations

import doctest
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fieldkit.errors import ArgumentError, PhysicsError
from fieldkit.physics import fall_velocity as module
from fieldkit.physics.fall_velocity import (
    EFFECTIVE_FRICTION_BY_SLOPE_CATEGORY,
    back_analyse_friction,
    design_friction,
    fall_velocity,
    friction_from_velocity_ratio,
    velocity_ratio,
    velocity_ratio_from_friction,
)

G = 9.81


# ----------------------------------------------------------- worked example 3C
def test_example_3c_ehime_back_analysis():
    # eta read from Fig. 3.6: 0.9 on the 44° rock, 0.7 on the 35° talus; eq. 3.16 gives
    # mu' = tan 44 (1 - 0.81) = 0.1835 and tan 35 (1 - 0.49) = 0.3571 (printed 0.18,
    # 0.36).
    mu = friction_from_velocity_ratio([0.9, 0.7], [44.0, 35.0])
    np.testing.assert_allclose(mu, [0.1835, 0.3571], atol=1e-4)
    assert np.round(mu, 2).tolist() == [0.18, 0.36]


def test_example_3c_table_values_reproduce_the_observed_eta():
    # "equation (3.13) gives values for the maximum velocities if the friction angles
    # given in Table 3.1 are applied": categories B (rock, 0.15) and D (talus, 0.35)
    # give eta = 0.919 and 0.707 against the 0.9 and 0.7 read from Fig. 3.6.
    eta = velocity_ratio_from_friction(
        [design_friction("B"), design_friction("D")], [44.0, 35.0]
    )
    np.testing.assert_allclose(eta, [0.9, 0.7], atol=0.02)


def test_example_3c_tornado_mountain_corrected():
    # Thesis: eta = 12.5 / (2 g 250)^0.5 = 0.39 and mu' = tan 22 (1 - 0.39^2) = 0.34.
    # ERRATUM (docs/thesis-notes.md): 12.5 / sqrt(2 * 9.81 * 250) = 12.5 / 70.04 =
    # 0.178, which gives mu' = tan 22 (1 - 0.178^2) = 0.391.
    eta = velocity_ratio(12.5, 250.0)
    assert float(eta) == pytest.approx(0.1785, abs=1e-4)
    assert float(eta) != pytest.approx(0.39, abs=0.05)
    mu = back_analyse_friction(12.5, 250.0, 22.0)
    assert float(mu) == pytest.approx(0.3912, abs=1e-4)
    # the printed 0.34 is eq. 3.16 applied to the mis-computed eta = 0.39
    assert float(friction_from_velocity_ratio(0.39, 22.0)) == pytest.approx(
        0.34, abs=0.005
    )


# -------------------------------------------------------------- eq. 3.13 physics
def test_fall_velocity_matches_the_limit_equilibrium_derivation():
    # Thesis §3.2.2: a = g sin psi (1 - mu'/tan psi), V^2 = 2 a S, S = H / sin psi.
    height, psi, mu = 26.0, 44.0, 0.15
    s = math.radians(psi)
    acceleration = G * math.sin(s) - mu * G * math.cos(s)
    distance = height / math.sin(s)
    expected = math.sqrt(2 * acceleration * distance)
    assert float(fall_velocity(height, psi, mu)) == pytest.approx(expected, rel=1e-12)


def test_limits_free_fall_and_frictionless_slope():
    free = math.sqrt(2 * G * 40.0)
    # a vertical face, or any slope without friction, gives the free-fall velocity
    assert float(fall_velocity(40.0, 90.0, 0.3)) == pytest.approx(free, rel=1e-12)
    np.testing.assert_allclose(fall_velocity(40.0, [10.0, 35.0, 70.0], 0.0), free)
    # friction equal to tan(psi): the block just does not accelerate
    assert float(fall_velocity(40.0, 45.0, 1.0)) == pytest.approx(0.0, abs=1e-6)


@settings(max_examples=80, deadline=None)
@given(
    height=st.floats(0.5, 800.0),
    psi=st.floats(5.0, 89.0),
    fraction=st.floats(0.0, 0.95),
)
def test_back_analysis_inverts_fall_velocity(height, psi, fraction):
    mu = fraction * math.tan(math.radians(psi))
    v = fall_velocity(height, psi, mu)
    assert float(back_analyse_friction(v, height, psi)) == pytest.approx(
        mu, rel=1e-9, abs=1e-12
    )
    eta = velocity_ratio(v, height)
    assert float(eta) == pytest.approx(
        float(velocity_ratio_from_friction(mu, psi)), rel=1e-12
    )


def test_vectorised_over_a_profile():
    heights = np.array([[10.0], [50.0], [250.0]])
    v = fall_velocity(heights, [30.0, 40.0], [0.25, 0.35])
    assert v.shape == (3, 2)
    assert v[2, 1] == pytest.approx(
        math.sqrt(2 * G * 250 * (1 - 0.35 / math.tan(math.radians(40)))), rel=1e-12
    )


# ------------------------------------------------------------------- Table 3-1
def test_table_3_1():
    assert list(EFFECTIVE_FRICTION_BY_SLOPE_CATEGORY) == ["A", "B", "C", "D"]
    design = [row["design_mu"] for row in EFFECTIVE_FRICTION_BY_SLOPE_CATEGORY.values()]
    assert design == [0.05, 0.15, 0.25, 0.35]
    for row in EFFECTIVE_FRICTION_BY_SLOPE_CATEGORY.values():
        low, high = row["field_range"]
        assert low <= high and row["description"]
    # the design values of A-C sit inside their field ranges
    for key in "ABC":
        low, high = EFFECTIVE_FRICTION_BY_SLOPE_CATEGORY[key]["field_range"]
        assert low <= EFFECTIVE_FRICTION_BY_SLOPE_CATEGORY[key]["design_mu"] <= high
    assert design_friction(" c ") == 0.25


def test_unknown_category_lists_the_known_ones():
    with pytest.raises(ArgumentError, match="unknown slope category 'E'.*A, B, C, D"):
        design_friction("E")


# ----------------------------------------------------------------- bad input
def test_friction_that_holds_the_block_is_rejected():
    with pytest.raises(PhysicsError, match=r"mu' = 0.50 exceeds tan\(22.0°\) = 0.40"):
        fall_velocity(100.0, 22.0, 0.5)


def test_faster_than_free_fall_is_rejected():
    with pytest.raises(PhysicsError, match="exceeds the free-fall velocity 31.3 m/s"):
        back_analyse_friction(40.0, 50.0, 30.0)
    with pytest.raises(PhysicsError, match="eta = 1.20 exceeds 1"):
        friction_from_velocity_ratio(1.2, 30.0)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: fall_velocity(-1.0, 30.0, 0.2), "height_m must not be negative"),
        (lambda: fall_velocity(10.0, 0.0, 0.2), "slope angle must be above 0°"),
        (lambda: fall_velocity(10.0, 95.0, 0.2), "at most 90°"),
        (lambda: fall_velocity(10.0, 30.0, -0.1), "friction_coefficient must not be"),
        (lambda: velocity_ratio(10.0, 0.0), "height_m must be positive"),
        (lambda: velocity_ratio(-3.0, 10.0), "velocity_mps must not be negative"),
    ],
)
def test_impossible_parameters_raise_argument_error(call, message):
    with pytest.raises(ArgumentError, match=message):
        call()


def test_array_errors_name_the_element():
    with pytest.raises(PhysicsError) as err:
        fall_velocity(100.0, [40.0, 30.0, 20.0], 0.5)
    assert err.value.where == "element 2"


def test_docstring_examples_run():
    result = doctest.testmod(module)
    assert result.attempted > 0 and result.failed == 0
