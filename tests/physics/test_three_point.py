"""Three-point solve (thesis §3.3.2): launch impact + tree strike + arrival impact.

Truth comes from synthetic parabolas with known launch speed and angle (eq. 3.4)
sampled at three points, and from worked example 3B read as a tree-strike survey.
"""

from __future__ import annotations

import doctest
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from fieldkit.errors import PhysicsError
from fieldkit.physics import three_point
from fieldkit.physics.flight import flight_between, next_impact_on_slope
from fieldkit.physics.three_point import solve_three_point, tree_height_above_chord

G = 9.81


def _parabola(v0: float, alpha_deg: float, u: float) -> float:
    """Eq. 3.4: height relative to launch at horizontal distance u."""
    a = math.radians(alpha_deg)
    return u * math.tan(a) - G * u**2 / (2 * (v0 * math.cos(a)) ** 2)


@settings(max_examples=150, deadline=None)
@given(
    v0=st.floats(1.0, 40.0),
    alpha=st.floats(-60.0, 75.0),
    x1=st.floats(-500.0, 500.0),
    z1=st.floats(-500.0, 500.0),
    u2=st.floats(1.0, 80.0),
    fraction=st.floats(0.1, 0.9),
)
def test_random_parabolas_are_recovered_exactly(v0, alpha, x1, z1, u2, fraction):
    ut = fraction * u2
    xt, x2 = x1 + ut, x1 + u2
    zt = z1 + _parabola(v0, alpha, ut)
    z2 = z1 + _parabola(v0, alpha, u2)
    # a tree strike a field crew can measure: at least 5 cm above the chord
    assume(tree_height_above_chord(x1, z1, x2, z2, xt, zt) >= 0.05)
    f = solve_three_point(x1, z1, x2, z2, xt, zt)
    assert float(f.v0_mps) == pytest.approx(v0, rel=1e-9)
    assert float(f.alpha_deg) == pytest.approx(alpha, rel=1e-9, abs=1e-9)
    # the flight starts at launch, passes the tree strike and ends at the arrival
    assert float(f.dx_m) == pytest.approx(x2 - x1, rel=1e-12)
    assert float(f.dz_m) == pytest.approx(z2 - z1, rel=1e-12, abs=1e-12)
    scale = max(1.0, abs(z1), abs(zt), abs(z2))
    assert float(f.z_at(xt - x1)) == pytest.approx(zt - z1, abs=1e-9 * scale)


def test_example_3b_surveyed_with_a_tree_at_mid_flight():
    # Worked example 3B (V0 = 18 m/s, theta0 = 20° on a 40° slope) as a survey: the two
    # impacts and a scar on a tree at the highest point of the path fix the flight, and
    # eq. 3.6 returns the thesis's theta0 = 20° (alpha = -20°).
    truth = next_impact_on_slope(18.0, 20.0, 40.0)
    dx, dz = float(truth.dx_m), float(truth.dz_m)
    x_tree = float(truth.x_hmax_m)
    z_tree = float(truth.z_at(x_tree))
    f = solve_three_point(
        100.0, 50.0, 100.0 + dx, 50.0 + dz, 100.0 + x_tree, 50 + z_tree
    )
    assert float(f.v0_mps) == pytest.approx(18.0, rel=1e-12)
    assert float(f.alpha_deg) == pytest.approx(-20.0, rel=1e-12)
    assert float(f.theta0_deg) == pytest.approx(20.0, rel=1e-12)
    # the strike height above the chord is the flight's vertical maximum (3.29 m)
    height = tree_height_above_chord(
        100.0, 50.0, 100 + dx, 50 + dz, 100 + x_tree, 50 + z_tree
    )
    assert float(height) == pytest.approx(float(truth.hmax_vertical_m), rel=1e-12)


def test_solution_is_the_flight_between_the_impacts_at_the_solved_angle():
    f = solve_three_point(0.0, 10.0, 12.0, 4.0, 5.0, 11.5)
    g = flight_between(12.0, -6.0, f.alpha_deg)
    for name in (
        "v0_mps",
        "time_s",
        "arrival_vz_mps",
        "hmax_vertical_m",
        "hmax_normal_m",
        "x_hmax_m",
    ):
        assert float(getattr(f, name)) == pytest.approx(
            float(getattr(g, name)), rel=1e-12
        )


def test_hand_solved_example():
    # Launch (0, 0), tree strike (4, 1), arrival (10, -5): chord slopes 1/4 and -1/2,
    # so c = (0.25 + 0.5) / 6 = 0.125, tan(alpha) = 0.25 + 0.125 * 4 = 0.75,
    # Vx = sqrt(g / 0.25), V0 = 1.25 Vx.
    f = solve_three_point(0.0, 0.0, 10.0, -5.0, 4.0, 1.0)
    assert float(f.alpha_deg) == pytest.approx(math.degrees(math.atan(0.75)), rel=1e-14)
    assert float(f.v0_mps) == pytest.approx(1.25 * math.sqrt(G / 0.25), rel=1e-14)
    assert float(tree_height_above_chord(0, 0, 10, -5, 4, 1)) == pytest.approx(3.0)


def test_vectorised_over_many_flights():
    rng = np.random.default_rng(11)
    v0 = rng.uniform(5, 25, 50)
    alpha = rng.uniform(-30, 50, 50)
    u2 = rng.uniform(5, 40, 50)
    ut = 0.5 * u2
    zt = np.array([_parabola(*args) for args in zip(v0, alpha, ut, strict=True)])
    z2 = np.array([_parabola(*args) for args in zip(v0, alpha, u2, strict=True)])
    f = solve_three_point(0.0, 0.0, u2, z2, ut, zt)
    np.testing.assert_allclose(f.v0_mps, v0, rtol=1e-9)
    np.testing.assert_allclose(f.alpha_deg, alpha, rtol=1e-9)


# ----------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    ("points", "message"),
    [
        ((0, 0, 10, -5, 0, 1), r"tree strike \(x = 0.00 m\) is not between"),
        ((0, 0, 10, -5, 12, 1), r"tree strike \(x = 12.00 m\) is not between"),
        ((0, 0, 10, -5, -3, 1), "is not between the launch"),
        ((10, 0, 0, -5, 4, 1), r"arrival impact \(x = 0.00 m\) is not beyond"),
        ((5, 0, 5, -5, 5, 1), "is not beyond the launch impact"),
    ],
)
def test_points_out_of_order_are_rejected(points, message):
    with pytest.raises(PhysicsError, match=message):
        solve_three_point(*points)


def test_tree_strike_below_the_chord_is_rejected_with_its_height():
    # chord from (0, 0) to (10, -5) passes z = -2 at x = 4; a strike at -2.5 is 0.5 m
    # below it: only an upward-curving path would pass through the three points
    with pytest.raises(PhysicsError) as err:
        solve_three_point(0.0, 0.0, 10.0, -5.0, 4.0, -2.5)
    message = str(err.value)
    assert "0.50 m below the straight line between the two impacts" in message
    assert "height above that chord -0.50 m" in message
    assert "no downward-curving ballistic path" in message


def test_tree_strike_on_the_chord_is_rejected():
    with pytest.raises(PhysicsError, match="tree strike is on the straight line"):
        solve_three_point(0.0, 0.0, 10.0, -5.0, 4.0, -2.0)


def test_array_errors_name_the_flight():
    with pytest.raises(PhysicsError) as err:
        solve_three_point(0.0, 0.0, [10.0, 10.0], [-5.0, -5.0], 4.0, [1.0, -3.0])
    assert err.value.where == "element 1"


def test_docstring_examples_run():
    result = doctest.testmod(three_point)
    assert result.attempted > 0 and result.failed == 0
