"""Pixel -> world calibration: two-point scale and homography (world z always up)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.tracking.video.calibration import (
    homography_from_points,
    parse_scale_points,
    read_homography_file,
    two_point_scale,
)


def test_two_point_scale_metres_per_pixel_and_z_up():
    # 600 px between the points = 1.2 m -> 2 mm/px; origin at the first point
    cal = two_point_scale((100, 30, 700, 30), 1.2, image_size=(800, 480))
    x, z = cal.to_world(np.array([100.0, 700.0, 400.0]), np.array([30.0, 30.0, 130.0]))
    np.testing.assert_allclose(x, [0.0, 1.2, 0.6], atol=1e-12)
    # 100 px further DOWN the image is 0.2 m LOWER in the world
    np.testing.assert_allclose(z, [0.0, 0.0, -0.2], atol=1e-12)
    np.testing.assert_allclose(cal.metres_per_pixel(400.0, 200.0), 0.002, rtol=1e-9)


def test_two_point_scale_along_a_diagonal_bar():
    # a 3-4-5 triangle: 500 px apart, 0.5 m -> 1 mm/px
    cal = two_point_scale((10, 10, 310, 410), 0.5)
    np.testing.assert_allclose(cal.metres_per_pixel(0, 0), 0.001, rtol=1e-9)


@pytest.mark.parametrize(
    "points, length, message",
    [
        ((100, 30, 100, 30), 1.0, "identical"),
        ((100, 30, 900, 30), 1.0, "outside the 800x480 frame"),
        ((-5, 30, 100, 30), 1.0, "outside"),
        ((100, 30, 700, 30), 0.0, "positive length"),
        ((100, 30, 700, 30), -2.0, "positive length"),
    ],
)
def test_two_point_scale_rejects_bad_points(points, length, message):
    with pytest.raises(ArgumentError, match=message):
        two_point_scale(points, length, image_size=(800, 480))


def test_parse_scale_points():
    assert parse_scale_points("1,2,3.5,4") == (1.0, 2.0, 3.5, 4.0)
    for bad in ("1,2,3", "a,b,c,d", "1,2,3,4,5", "1,2,nan,4"):
        with pytest.raises(ArgumentError, match="scale_points"):
            parse_scale_points(bad)


def _world_from_image(u, v):
    """A camera on its side and mirrored, with perspective: an arbitrary homography."""
    h = np.array([[0.0, -0.003, 1.5], [-0.0025, 0.0, 1.0], [1e-5, 2e-5, 1.0]])
    w = h[2, 0] * u + h[2, 1] * v + h[2, 2]
    return (h[0, 0] * u + h[0, 1] * v + h[0, 2]) / w, (
        h[1, 0] * u + h[1, 1] * v + h[1, 2]
    ) / w


def test_homography_recovers_a_rotated_mirrored_perspective_camera():
    img = np.array(
        [[50, 40], [700, 60], [650, 420], [80, 400], [400, 250], [300, 100]], float
    )
    wx, wz = _world_from_image(img[:, 0], img[:, 1])
    cal = homography_from_points(img, np.column_stack([wx, wz]), image_size=(800, 480))
    assert cal.residual_m < 1e-9
    u = np.array([123.4, 555.5, 321.0])
    v = np.array([77.7, 300.1, 444.4])
    x, z = cal.to_world(u, v)
    ex, ez = _world_from_image(u, v)
    np.testing.assert_allclose(x, ex, atol=1e-9)
    np.testing.assert_allclose(z, ez, atol=1e-9)


def test_homography_file_json_and_csv_agree(tmp_path):
    img = np.array([[40, 440], [760, 440], [760, 40], [40, 40], [400, 240]], float)
    world = np.column_stack([(img[:, 0] - 40) * 0.002, (440 - img[:, 1]) * 0.002])
    points = [
        {"u_px": u, "v_px": v, "x_m": x, "z_m": z}
        for (u, v), (x, z) in zip(img, world, strict=True)
    ]
    (tmp_path / "h.json").write_text(json.dumps({"points": points}))
    rows = "\n".join(
        f"{u},{v},{x},{z}" for (u, v), (x, z) in zip(img, world, strict=True)
    )
    (tmp_path / "h.csv").write_text("# calibration marks\nu_px,v_px,x_m,z_m\n" + rows)
    a = read_homography_file(tmp_path / "h.json", (800, 480))
    b = read_homography_file(tmp_path / "h.csv", (800, 480))
    for cal in (a, b):
        x, z = cal.to_world(140.0, 340.0)
        assert x == pytest.approx(0.2, abs=1e-9)
        assert z == pytest.approx(0.2, abs=1e-9)  # up in the world, up the image


@pytest.mark.parametrize(
    "points, message",
    [
        ([[0, 0, 0, 0], [100, 0, 1, 0], [100, 100, 1, 1]], "at least 4"),
        ([[0, 0, 0, 0], [100, 0, 1, 0], [200, 0, 2, 0], [300, 0, 3, 0]], "one line"),
        ([[0, 0, 0, 0], [100, 0, 1, 0], [100, 100, 1, 1], [100, 100, 2, 2]], "point 4"),
        ([[0, 0, 0, 0], [100, 0, 1, 0], [100, 100, 1, 1], [0, 900, 0, 1]], "outside"),
    ],
)
def test_homography_file_errors_name_the_point(tmp_path, points, message):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"points": points}))
    with pytest.raises(InputFileError, match=message) as err:
        read_homography_file(path, (800, 480))
    assert "bad.json" in str(err.value)
    assert "\n" not in str(err.value)


def test_homography_file_non_numeric_row(tmp_path):
    path = tmp_path / "h.csv"
    path.write_text("u_px,v_px,x_m,z_m\n1,2,3,4\n5,six,7,8\n")
    with pytest.raises(InputFileError, match="row 3"):
        read_homography_file(path)
