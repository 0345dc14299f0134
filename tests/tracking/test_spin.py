"""Marker spin: angle from the marker, unwrapping, smoothed derivative, uncertainty."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fieldkit.tracking.video.calibration import homography_from_points, two_point_scale
from fieldkit.tracking.video.spin import (
    angular_velocity,
    marker_angle_world,
    marker_offset_px,
    measure_marker,
    unwrap_angle,
)


def _ball_image(
    angle_rad, *, size=81, r=25.0, offset=0.55, spot=0.25, supersample=8, stripe=False
):
    """A flat-coloured ball with a dark spot (or stripe) at ``angle_rad`` (v down)."""
    c = (size - 1) / 2
    offs = (np.arange(supersample) + 0.5) / supersample - 0.5
    grid = (np.arange(size)[:, None] + offs[None, :]).ravel()
    du, dv = grid[None, :] - c, grid[:, None] - c
    mu, mv = offset * r * np.cos(angle_rad), -offset * r * np.sin(angle_rad)
    mark = (du - mu) ** 2 + (dv - mv) ** 2 <= (spot * r) ** 2
    if stripe:
        across = -du * np.sin(angle_rad) - dv * np.cos(angle_rad)
        mark = (np.abs(across) <= 0.15 * r) & (du * du + dv * dv <= r * r)
    cover = mark.reshape(size, supersample, size, supersample).mean(axis=(1, 3))
    img = np.empty((size, size, 3), np.float32)
    body, dark = (
        np.array([70, 175, 240], np.float32),
        np.array([60, 30, 20], np.float32),
    )
    img[:] = body * (1 - cover[:, :, None]) + dark * cover[:, :, None]
    return np.clip(img + 0.5, 0, 255).astype(np.uint8), c, r


@pytest.mark.parametrize("angle", [0.0, 0.7, 2.0, -2.5, 3.1])
def test_marker_offset_gives_the_marker_direction(angle):
    img, c, r = _ball_image(angle)
    du, dv = marker_offset_px(img, c, c, r, (70, 175, 240))
    assert np.hypot(du, dv) == pytest.approx(0.55 * r, rel=0.02)
    cal = two_point_scale((0, 0, 100, 0), 0.1)  # level camera: v down is z down
    got = float(marker_angle_world(cal, c, c, du, dv))
    assert np.angle(np.exp(1j * (got - angle))) == pytest.approx(0.0, abs=0.01)


@pytest.mark.parametrize("angle", [0.0, 0.7, 1.5, -1.2])
def test_stripe_through_the_centre_gives_its_axis(angle):
    img, c, r = _ball_image(angle, stripe=True)
    du, dv, axial = measure_marker(img, c, c, r, (70, 175, 240))
    assert axial
    cal = two_point_scale((0, 0, 100, 0), 0.1)
    got = float(marker_angle_world(cal, c, c, du, dv))
    assert np.angle(np.exp(2j * (got - angle))) / 2 == pytest.approx(0.0, abs=0.01)
    # a spot is not axial
    img, c, r = _ball_image(angle)
    assert not measure_marker(img, c, c, r, (70, 175, 240))[2]


def test_unwrap_with_half_turn_period():
    true = np.linspace(0.0, 12.0, 50)  # 0.24 rad per sample
    axis = np.mod(true, np.pi)  # a stripe's axis angle, modulo pi
    np.testing.assert_allclose(unwrap_angle(axis, period=np.pi), true, atol=1e-12)


def test_marker_angle_follows_a_mirrored_camera():
    # image mirrored left-right: a marker drawn at image angle a is at world pi - a,
    # so rotation senses flip (omega < 0 stays clockwise in the world)
    img_pts = np.array([[0, 0], [100, 0], [100, 100], [0, 100]], float)
    world = np.array([[1.0, 1.0], [0.0, 1.0], [0.0, 0.0], [1.0, 0.0]])
    cal = homography_from_points(img_pts, world)
    angle = float(marker_angle_world(cal, 50.0, 50.0, 10.0, 0.0))  # image right
    assert angle == pytest.approx(np.pi)
    angle = float(marker_angle_world(cal, 50.0, 50.0, 0.0, -10.0))  # image up
    assert angle == pytest.approx(np.pi / 2)


def test_no_marker_gives_nan():
    img = np.full((81, 81, 3), (70, 175, 240), np.uint8)
    assert np.isnan(marker_offset_px(img, 40.0, 40.0, 25.0, (70, 175, 240))).all()
    # a centred spot carries no direction either
    img[36:45, 36:45] = 20
    assert np.isnan(marker_offset_px(img, 40.0, 40.0, 25.0, (70, 175, 240))).all()


def test_unwrap_keeps_nan_and_crosses_pi():
    true = np.linspace(0.0, 20.0, 60)  # ~3 turns, 0.34 rad per sample
    wrapped = np.angle(np.exp(1j * true))
    wrapped[[10, 11, 30]] = np.nan
    out = unwrap_angle(wrapped)
    ok = np.isfinite(out)
    np.testing.assert_allclose(out[ok], true[ok], atol=1e-12)
    assert np.isnan(out[[10, 11, 30]]).all()


def test_angular_velocity_of_uniform_rotation_with_noise():
    rng = np.random.default_rng(7)
    t = np.arange(400) / 1205.0
    sigma = 0.01
    angle = 0.3 - 42.0 * t + rng.normal(0.0, sigma, t.size)
    omega, sd = angular_velocity(t, angle, window=15)
    inner = slice(10, -10)
    # the local-fit slope standard error for 15 samples at 1/1205 s
    tt = np.arange(15) / 1205.0
    expected_sd = sigma / np.sqrt(np.sum((tt - tt.mean()) ** 2))
    assert np.median(sd[inner]) == pytest.approx(expected_sd, rel=0.25)
    err = omega[inner] + 42.0
    assert np.std(err) == pytest.approx(expected_sd, rel=0.25)
    assert abs(np.mean(err)) < 3 * expected_sd / np.sqrt(err.size / 15)


def test_angular_velocity_skips_missing_samples():
    t = np.arange(100) / 1000.0
    angle = 5.0 * t**2 + 2.0 * t  # omega = 10 t + 2
    angle[40:43] = np.nan
    omega, _ = angular_velocity(t, angle, window=9)
    ok = np.isfinite(omega)
    assert ok[40:90].all()  # windows with a few missing samples still give omega
    # complete windows: the local slope of a quadratic is its exact derivative
    np.testing.assert_allclose(omega[47:90], 10 * t[47:90] + 2.0, atol=1e-9)


@settings(max_examples=25, deadline=None)
@given(st.floats(-300.0, 300.0), st.floats(-3.0, 3.0))
def test_angular_velocity_exact_for_any_uniform_spin(omega0, angle0):
    t = np.arange(50) / 1205.0
    omega, _ = angular_velocity(t, angle0 + omega0 * t)
    np.testing.assert_allclose(omega[8:-8], omega0, atol=1e-7 * max(1.0, abs(omega0)))


@pytest.mark.parametrize("n", [3, 4, 13, 14])
def test_angular_velocity_of_tracks_shorter_than_the_window(n):
    t = np.arange(n) / 1205.0
    omega, sd = angular_velocity(t, 1.0 + 25.0 * t, window=15)
    assert omega.shape == sd.shape == (n,)
    np.testing.assert_allclose(omega[1:-1], 25.0, rtol=1e-9)
