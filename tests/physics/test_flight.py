"""Flight physics (thesis ch. 3, eqs. 3.1-3.12) against the worked examples and
conservation laws.

References: thesis worked examples 3A, 3B and §3.3.1, re-derived by hand in
docs/thesis-notes.md. Where the thesis rounded, the unrounded physics is
asserted and the printed figure is cited in a comment.
"""

from __future__ import annotations

import doctest
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from fieldkit.errors import ArgumentError, PhysicsError
from fieldkit.physics import flight, flight_heights
from fieldkit.physics.flight import (
    Flight,
    ballistic_reachable,
    flight_between,
    flight_samples,
    launch_angle,
    launch_speed,
    max_normal_height,
    max_vertical_height,
    next_impact_on_slope,
    restitution_angle,
    trajectory_position,
    trajectory_velocity,
    vertical_height_above_slope,
)

G = 9.81
SETTINGS = settings(max_examples=60, deadline=None)


# ----------------------------------------------------------- worked example 3A
def test_example_3a_reproduces_exactly_from_the_printed_components():
    # The thesis works with V0z = 11.5 and V0x = 16.4 m/s (20 sin 35, 20 cos 35 rounded)
    # and prints z(2 s) = 3.38 m, z(4 s) = -32.5 m at x = 65.6 m.
    v0 = math.hypot(16.4, 11.5)
    alpha = math.degrees(math.atan2(11.5, 16.4))
    x, z = trajectory_position(v0, alpha, np.array([2.0, 4.0]))
    assert z[0] == pytest.approx(-0.5 * 9.81 * 4 + 11.5 * 2, abs=1e-12)
    assert z[0] == pytest.approx(3.38, abs=1e-12)
    assert z[1] == pytest.approx(-32.48, abs=1e-12)  # printed -32.5
    assert x[1] == pytest.approx(65.6, abs=1e-12)


def test_example_3a_unrounded():
    # With V0 = 20 m/s and alpha = 35° exactly, the components are 11.472 and 16.383
    # m/s (printed 11.5 and 16.4), so z(2 s) = 3.323 m (printed 3.38), z(4 s) = -32.594
    # (printed -32.5) at x = 65.532 m (printed 65.6). Hand values: 40 sin 35 - 19.62,
    # 80 sin 35 - 78.48, 80 cos 35.
    vx, vz = trajectory_velocity(20.0, 35.0, 0.0)
    assert round(float(vx), 1) == 16.4 and round(float(vz), 1) == 11.5
    x, z = trajectory_position(20.0, 35.0, [2.0, 4.0])
    assert z[0] == pytest.approx(3.32305, abs=1e-5)
    assert z[1] == pytest.approx(-32.5939, abs=1e-4)
    assert x[1] == pytest.approx(65.5322, abs=1e-4)


def test_position_and_velocity_are_consistent_by_differentiation():
    t = np.linspace(0.0, 3.0, 7)
    step = 1e-6
    x1, z1 = trajectory_position(17.0, 28.0, t - step)
    x2, z2 = trajectory_position(17.0, 28.0, t + step)
    vx, vz = trajectory_velocity(17.0, 28.0, t)
    np.testing.assert_allclose((x2 - x1) / (2 * step), vx, rtol=1e-8)
    np.testing.assert_allclose((z2 - z1) / (2 * step), vz, atol=1e-7)


def test_flight_samples_are_eqs_3_1_to_3_3_from_the_launch_point():
    # launch at (5, 40) with V0 = 17 m/s at 28 deg: the same path as
    # trajectory_position/velocity, shifted to the launch point
    v0, alpha = 17.0, 28.0
    vx0, vz0 = v0 * math.cos(math.radians(alpha)), v0 * math.sin(math.radians(alpha))
    s = flight_samples(5.0, 40.0, vx0, vz0, 2.5, n_samples=11)
    np.testing.assert_allclose(s.t_s, np.linspace(0.0, 2.5, 11), rtol=1e-15)
    x, z = trajectory_position(v0, alpha, s.t_s)
    vx, vz = trajectory_velocity(v0, alpha, s.t_s)
    np.testing.assert_allclose(s.x_m, 5.0 + x, rtol=1e-12)
    np.testing.assert_allclose(s.z_m, 40.0 + z, rtol=1e-12)
    np.testing.assert_allclose(s.vx_mps, vx, rtol=1e-12)
    np.testing.assert_allclose(s.vz_mps, vz, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(s.speed_mps, np.hypot(vx, vz), rtol=1e-12)
    # arrays broadcast, samples along a new last axis; NaN duration gives NaN
    b = flight_samples([0.0, 1.0], 0.0, 2.0, [0.0, 3.0], [1.0, np.nan], n_samples=4)
    assert b.x_m.shape == (2, 4) and b.x_m[0, -1] == pytest.approx(2.0)
    assert np.isnan(b.z_m[1]).all()


def test_eq_3_6_launch_and_restitution_angles():
    # §3.3.1: theta0 = 15° and 45° on a 30° slope give alpha = -15° and +15°.
    assert launch_angle([15.0, 45.0], 30.0).tolist() == [-15.0, 15.0]
    assert restitution_angle([-15.0, 15.0], 30.0).tolist() == [15.0, 45.0]


# ------------------------------------------------------------ section 3.3.1
def test_section_3_3_1_launch_speeds():
    # Thesis: 15.5 m/s (theta0 = 15°) and 9.3 m/s (theta0 = 45°) to reach (14, -8);
    # eq. 3.5 gives 15.573 and 9.364 (the thesis truncates). Hand computation:
    # 14 / (cos 15 sqrt(2 (14 tan(-15) + 8) / 9.81)) = 15.573.
    v = launch_speed(14.0, -8.0, launch_angle([15.0, 45.0], 30.0))
    np.testing.assert_allclose(v, [15.573, 9.364], atol=1e-3)
    # higher trajectory, lower speed (the point of §3.3.1)
    assert v[1] < v[0]


# ----------------------------------------------------------- worked example 3B
@pytest.fixture(scope="module")
def example_3b() -> Flight:
    return next_impact_on_slope(18.0, 20.0, 40.0)


def test_example_3b_next_impact_unrounded(example_3b):
    f = example_3b
    assert float(f.alpha_deg) == pytest.approx(-20.0)  # eq. 3.6, as printed
    # Eq. 3.8 with the unrounded parabola a = -0.017144, b = -0.36397:
    # x = (tan 40 - tan 20) / 0.017144. Thesis prints 28.2, -23.8, L = 36.8 from the
    # parabola rounded to z = -0.017 x^2 - 0.36 x.
    a = -G / (2 * (18 * math.cos(math.radians(20))) ** 2)
    x_ref = (math.tan(math.radians(40)) - math.tan(math.radians(20))) / -a
    assert float(f.dx_m) == pytest.approx(x_ref, rel=1e-12)
    assert float(f.dx_m) == pytest.approx(27.713, abs=1e-3)
    assert float(f.dz_m) == pytest.approx(
        -27.713 * math.tan(math.radians(40)), abs=2e-3
    )
    assert round(float(f.dz_m), 1) == -23.3
    assert round(float(f.chord_length_m), 1) == 36.2
    # eq. 3.11: thesis prints 3.39 m at x = 14.0 m (rounded parabola)
    assert float(f.hmax_vertical_m) == pytest.approx(3.292, abs=1e-3)
    assert float(f.x_hmax_m) == pytest.approx(13.856, abs=1e-3)


def test_example_3b_impact_velocity_unrounded(example_3b):
    f = example_3b
    # Thesis: V_ix = 16.9 (exact), V_iz = 22.4, V_i = 28.1 m/s, 53° below horizontal.
    assert float(f.arrival_vx_mps) == pytest.approx(18 * math.cos(math.radians(20)))
    assert round(float(f.arrival_vx_mps), 1) == 16.9
    # thesis route: V_iz = sqrt(V0z^2 + 2 g dz) with the unrounded dz
    vz_ref = math.sqrt((18 * math.sin(math.radians(20))) ** 2 + 2 * G * -float(f.dz_m))
    assert float(f.arrival_vz_mps) == pytest.approx(-vz_ref, rel=1e-12)
    assert float(f.arrival_vz_mps) == pytest.approx(-22.23, abs=0.01)
    assert float(f.arrival_speed_mps) == pytest.approx(27.93, abs=0.01)
    assert float(f.arrival_angle_deg) == pytest.approx(52.73, abs=0.01)
    assert float(f.theta0_deg) == pytest.approx(20.0)
    # angle to the 40° ground at the next impact (theta_i): 52.73 - 40
    assert float(f.arrival_angle_to_chord_deg) == pytest.approx(12.73, abs=0.01)
    x, z = f.position_at_time(f.time_s)
    assert (float(x), float(z)) == pytest.approx((float(f.dx_m), float(f.dz_m)))


def test_example_3b_printed_numbers_come_from_the_rounded_parabola():
    # The printed parabola z = -0.017 x^2 - 0.36 x is eq. 3.4 rounded ...
    a = -G / (2 * (18 * math.cos(math.radians(-20))) ** 2)
    assert round(a, 3) == -0.017 and round(math.tan(math.radians(-20)), 2) == -0.36
    # ... and with those coefficients eqs. 3.8 and 3.11 give the printed 28.2 m and
    # 3.39 m: a launch with tan(alpha) = -0.36 and g / (2 V0^2 cos^2 alpha) = 0.017.
    alpha = math.degrees(math.atan(-0.36))
    v0 = math.sqrt(G / (2 * 0.017)) / math.cos(math.radians(alpha))
    psi = math.degrees(math.atan(0.84))  # printed gradient kappa = -0.84
    rounded = next_impact_on_slope(v0, alpha + psi, psi)
    assert round(float(rounded.dx_m), 1) == 28.2
    assert round(float(rounded.hmax_vertical_m), 2) == 3.39


def test_example_3b_normal_height(example_3b):
    # eq. 3.12: h' = (18 sin 20)^2 / (2 g cos 40) = 2.52 m, as printed.
    h = max_normal_height(18.0, 20.0, 40.0)
    assert float(h) == pytest.approx(2.522, abs=1e-3)
    assert float(example_3b.hmax_normal_m) == pytest.approx(float(h), rel=1e-12)
    # the normal maximum is the vertical maximum projected: times cos(psi)
    assert float(h) == pytest.approx(
        float(example_3b.hmax_vertical_m) * math.cos(math.radians(40)), rel=1e-12
    )


def test_eq_3_9_to_3_11_heights_above_the_slope():
    x_max, h_max = max_vertical_height(18.0, -20.0, 40.0)
    x = np.linspace(0.0, 27.7, 2771)
    h = vertical_height_above_slope(x, 18.0, -20.0, 40.0)
    assert h[0] == 0.0
    assert float(h_max) == pytest.approx(h.max(), abs=1e-4)
    assert float(x_max) == pytest.approx(x[np.argmax(h)], abs=0.01)
    # eq. 3.10: the derivative vanishes at the maximum
    step = 1e-5
    slope = vertical_height_above_slope(x_max + np.array([-step, step]), 18, -20, 40)
    assert abs(slope[1] - slope[0]) < 1e-9


# ------------------------------------------------------- flight_between laws
drop_st = st.floats(0.05, 60.0)
dx_st = st.floats(0.5, 80.0)
alpha_st = st.floats(-70.0, 75.0)


def _target(dx: float, alpha: float, drop: float) -> float:
    """dz of a point ``drop`` metres below the launch direction at ``dx``."""
    return dx * math.tan(math.radians(alpha)) - drop


@SETTINGS
@given(dx=dx_st, alpha=alpha_st, drop=drop_st)
def test_flight_between_reaches_the_end_point(dx, alpha, drop):
    dz = _target(dx, alpha, drop)
    f = flight_between(dx, dz, alpha)
    x, z = trajectory_position(f.v0_mps, f.alpha_deg, f.time_s)
    scale = max(1.0, abs(dx), abs(dz))
    assert float(x) == pytest.approx(dx, abs=1e-9 * scale)
    assert float(z) == pytest.approx(dz, abs=1e-9 * scale)
    x_end, z_end = f.path(5)
    assert (x_end[0], z_end[0]) == (0.0, 0.0)
    assert float(z_end[-1]) == pytest.approx(dz, abs=1e-9 * scale)


@SETTINGS
@given(dx=dx_st, alpha=alpha_st, drop=drop_st)
def test_flight_between_arrival_velocity_and_energy(dx, alpha, drop):
    dz = _target(dx, alpha, drop)
    f = flight_between(dx, dz, alpha)
    vx, vz = trajectory_velocity(f.v0_mps, f.alpha_deg, f.time_s)
    v_scale = max(1.0, float(f.v0_mps), abs(float(vz)))
    assert float(f.arrival_vx_mps) == pytest.approx(float(vx), abs=1e-12 * v_scale)
    assert float(f.arrival_vz_mps) == pytest.approx(float(vz), abs=1e-12 * v_scale)
    assert float(f.launch_vx_mps) == pytest.approx(float(vx), abs=1e-12 * v_scale)
    # energy: 1/2 v_i^2 = 1/2 v0^2 - g dz
    lhs = 0.5 * float(f.arrival_speed_mps) ** 2
    rhs = 0.5 * float(f.v0_mps) ** 2 - G * dz
    assert lhs == pytest.approx(rhs, rel=1e-9, abs=1e-9)


@SETTINGS
@given(dx=dx_st, alpha=alpha_st, drop=drop_st)
def test_flight_heights_match_dense_sampling(dx, alpha, drop):
    dz = _target(dx, alpha, drop)
    f = flight_between(dx, dz, alpha)
    n = 20001
    x, z = f.path(n)  # equal time steps are equal x steps
    above = z - x * dz / dx
    normal = (dx * z - dz * x) / math.hypot(dx, dz)  # perpendicular distance
    curvature = G / (2 * float(f.launch_vx_mps) ** 2)
    tolerance = curvature * (dx / (n - 1)) ** 2 + 1e-9 * max(1.0, abs(dz), dx)
    assert float(f.hmax_vertical_m) == pytest.approx(above.max(), abs=tolerance)
    assert float(f.hmax_vertical_m) >= above.max() - 1e-9 * max(1.0, abs(dz), dx)
    assert float(f.x_hmax_m) == pytest.approx(x[np.argmax(above)], abs=dx / (n - 1))
    assert float(f.hmax_normal_m) == pytest.approx(normal.max(), abs=tolerance)
    assert float(f.height_above_chord_at(f.x_hmax_m)) == pytest.approx(
        float(f.hmax_vertical_m), rel=1e-9
    )


@SETTINGS
@given(
    v0=st.floats(0.5, 40.0),
    theta0=st.floats(0.5, 85.0),
    psi=st.floats(-30.0, 70.0),
)
def test_next_impact_lands_on_the_slope(v0, theta0, psi):
    assume(theta0 - psi < 80.0)  # alpha >= 90° (travelling backwards) is rejected
    f = next_impact_on_slope(v0, theta0, psi)
    assert float(f.dz_m) == pytest.approx(
        -math.tan(math.radians(psi)) * float(f.dx_m), rel=1e-9, abs=1e-12
    )
    assert float(f.chord_slope_deg) == pytest.approx(psi, abs=1e-9)
    assert float(f.theta0_deg) == pytest.approx(theta0, abs=1e-9)
    # eq. 3.5 from the impact point recovers the launch speed (3.5 inverts 3.8)
    assert float(launch_speed(f.dx_m, f.dz_m, f.alpha_deg)) == pytest.approx(
        v0, rel=1e-9
    )
    # the flight's heights are those of eqs. 3.11 and 3.12 for this slope
    assert float(f.hmax_normal_m) == pytest.approx(
        float(max_normal_height(v0, theta0, psi)), rel=1e-9
    )


def test_flight_between_broadcasts_like_numpy():
    dx = np.array([10.0, 20.0, 30.0])
    f = flight_between(dx, -5.0, np.array([[10.0], [30.0]]))
    assert np.shape(f.v0_mps) == (2, 3) and np.shape(f.hmax_normal_m) == (2, 3)
    for i, alpha in enumerate([10.0, 30.0]):
        for j, d in enumerate(dx):
            single = flight_between(d, -5.0, alpha)
            assert f.v0_mps[i, j] == pytest.approx(float(single.v0_mps), rel=1e-15)
            assert f.time_s[i, j] == pytest.approx(float(single.time_s), rel=1e-15)
    x, z = f.path(4)
    assert x.shape == (2, 3, 4)
    np.testing.assert_allclose(x[..., -1], np.broadcast_to(dx, (2, 3)), rtol=1e-12)


def test_scalar_inputs_give_scalars():
    f = flight_between(14.0, -8.0, -15.0)
    assert np.ndim(f.v0_mps) == 0 and isinstance(f.hmax_vertical_m, float)
    assert isinstance(launch_speed(14.0, -8.0, 15.0), float)


def test_nan_propagates_instead_of_raising():
    v = launch_speed([14.0, np.nan], -8.0, 15.0)
    assert np.isfinite(v[0]) and np.isnan(v[1])


# ----------------------------------------------------------------- bad input
def test_uphill_point_out_of_reach_is_rejected_with_a_specific_message():
    # 10 tan 12° = 2.13 m < 3 m: launched at 12° the rock passes below the point
    with pytest.raises(PhysicsError) as err:
        launch_speed(10.0, 3.0, 12.0)
    assert str(err.value).startswith(
        "no ballistic path launched at 12.0° reaches a point 3.0 m higher at 10.0 m"
    )
    with pytest.raises(
        PhysicsError, match="launched at -40.0° reaches a point 5.0 m lower at 10.0 m"
    ):
        flight_between(10.0, -5.0, -40.0)
    with pytest.raises(PhysicsError, match="at the same height"):
        launch_speed(10.0, 0.0, 0.0)


def test_point_on_the_launch_line_needs_infinite_speed():
    dz = 10.0 * math.tan(math.radians(30.0))
    assert not ballistic_reachable(10.0, dz, 30.0)
    with pytest.raises(PhysicsError, match="on or above the launch direction"):
        launch_speed(10.0, dz + 1e-9, 30.0)


def test_arrival_behind_the_launch_is_rejected():
    with pytest.raises(PhysicsError, match="dx > 0"):
        launch_speed(0.0, -1.0, 10.0)
    with pytest.raises(PhysicsError, match="-2.0 m along"):
        flight_between(-2.0, -1.0, 10.0)


def test_array_errors_name_the_element():
    with pytest.raises(PhysicsError) as err:
        launch_speed([10.0, 10.0, 10.0], [-1.0, -2.0, 3.0], 12.0)
    assert err.value.where == "element 2"
    assert str(err.value).startswith("element 2: no ballistic path launched at 12.0°")


def test_ballistic_reachable_agrees_with_launch_speed():
    rng = np.random.default_rng(7)
    dx = rng.uniform(-5, 50, 400)
    dz = rng.uniform(-40, 30, 400)
    alpha = rng.uniform(-80, 80, 400)
    ok = ballistic_reachable(dx, dz, alpha)
    assert 50 < ok.sum() < 350
    for i in range(400):
        if ok[i]:
            assert launch_speed(dx[i], dz[i], alpha[i]) > 0
        else:
            with pytest.raises(PhysicsError):
                launch_speed(dx[i], dz[i], alpha[i])


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: launch_speed(10.0, -1.0, 90.0), "between -90° and 90°"),
        (lambda: trajectory_position(-1.0, 10.0, 1.0), "v0_mps must not be negative"),
        (lambda: trajectory_velocity(5.0, 10.0, 1.0, g=0.0), "gravity g must be"),
        (lambda: next_impact_on_slope(0.0, 20.0, 40.0), "v0_mps must be positive"),
        (lambda: next_impact_on_slope(10.0, 20.0, 90.0), "slope dip must be between"),
        (lambda: next_impact_on_slope(10.0, 135.0, 40.0), "between -90° and 90°"),
        (lambda: vertical_height_above_slope(1.0, 0.0, 5.0, 30.0), "must be positive"),
        (lambda: flight_samples(0.0, 0.0, 1.0, 1.0, -0.5), "duration_s must not be"),
        (lambda: flight_samples(0.0, 0.0, 1.0, 1.0, 1.0, 1), "n_samples must be"),
    ],
)
def test_impossible_parameters_raise_argument_error(call, message):
    with pytest.raises(ArgumentError, match=message):
        call()


@pytest.mark.parametrize("theta0", [0.0, -5.0])
def test_launch_into_the_slope_is_rejected(theta0):
    with pytest.raises(PhysicsError, match="goes into the ground"):
        next_impact_on_slope(10.0, theta0, 30.0)
    with pytest.raises(PhysicsError, match="goes into the ground"):
        max_normal_height(10.0, theta0, 30.0)
    with pytest.raises(PhysicsError, match="goes into the ground"):
        max_vertical_height(10.0, theta0 - 30.0, 30.0)


@pytest.mark.parametrize("module", [flight, flight_heights])
def test_docstring_examples_run(module):
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0
