"""Bodies and thesis Table 4-1 shapes."""

from __future__ import annotations

import math

import pytest

from fieldkit.errors import ArgumentError
from fieldkit.physics.bodies import SHAPES, Body, shape_body


def test_table_4_1_ellipsoid_boulder_a():
    # Thesis Table 4-1 / worked examples 6B, 6C: a = 0.8, b = c = 0.65 m ->
    # k = 0.46 m, volume 1.42 m^3, m ~ 3750 kg at 26 kN/m^3, I = 797 kg m^2,
    # average radius (a + b)/2 = 0.725 m.
    body = shape_body("ellipsoid", (1.6, 1.3, 1.3), unit_weight_kn_m3=26.0)
    assert body.gyration_m == pytest.approx(0.46, abs=0.005)
    assert body.volume_m3 == pytest.approx(1.42, abs=0.005)
    assert body.mass_kg == pytest.approx(3750, rel=0.01)
    assert body.radius_m == pytest.approx(0.725, abs=1e-12)
    # eq. 6.12 with the thesis's rounded m = 3750 kg gives 797 kg m^2
    assert 3750 * body.gyration_m**2 == pytest.approx(797, abs=0.5)
    assert body.shape == "ellipsoid"


def test_table_2_6_bodies():
    # Table 2-6: cube 0.6 m -> r 0.3, k 0.245 m; Mt. Stephen ellipsoid 0.4 x 0.4 x 0.2
    # -> r 0.2, k 0.13 m, 44 kg at 26 kN/m^3; Ehime concrete cube 520 kg at 24 kN/m^3
    # (0.216 m^3 * 24 kN/m^3 / g = 528 kg, printed "520" rounded down).
    cube = shape_body("cube", 0.6)
    assert cube.radius_m == pytest.approx(0.3)
    assert cube.gyration_m == pytest.approx(0.245, abs=0.0005)
    stephen = shape_body("ellipsoid", (0.4, 0.4, 0.2))
    assert stephen.radius_m == pytest.approx(0.2)
    assert stephen.gyration_m == pytest.approx(0.13, abs=0.005)
    assert stephen.mass_kg == pytest.approx(44, abs=0.5)
    ehime = shape_body("cube", 0.6, unit_weight_kn_m3=24.0)
    assert ehime.mass_kg == pytest.approx(520, rel=0.02)


def test_sphere_worked_example_4a():
    # Worked example 4A: 1.5 m diameter sphere, k = r sqrt(2/5) = 0.47 m
    body = shape_body("sphere", 0.75)
    assert body.gyration_m == pytest.approx(0.47, abs=0.005)
    assert body.volume_m3 == pytest.approx(4 / 3 * math.pi * 0.75**3)


def test_cylinder_formula():
    body = shape_body("cylinder", (2.0, 0.3))
    assert body.gyration_m == pytest.approx(math.sqrt((3 * 0.09 + 4.0) / 12))
    assert body.volume_m3 == pytest.approx(math.pi * 0.09 * 2.0)
    assert body.radius_m == pytest.approx((0.3 + 1.0) / 2)


def test_inertia_is_m_k_squared():
    assert Body(500.0, 0.36, 0.295).inertia_kgm2 == pytest.approx(500 * 0.295**2)


def test_radius_override_table_2_6_boulder_a():
    # Table 2-6 gives r = 0.8 m (= a) for boulder A
    assert shape_body("ellipsoid", (1.6, 1.3, 1.3), radius_m=0.8).radius_m == 0.8
    with pytest.raises(ArgumentError, match=r"radius_m must be between 0.65 and 0.8"):
        shape_body("ellipsoid", (1.6, 1.3, 1.3), radius_m=0.9)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        (
            {"mass_kg": -3, "radius_m": 1, "gyration_m": 0.5},
            r"mass_kg must be > 0 \(got -3\)",
        ),
        (
            {"mass_kg": 3, "radius_m": 0, "gyration_m": 0.5},
            r"radius_m must be > 0 \(got 0\)",
        ),
        ({"mass_kg": 3, "radius_m": 1, "gyration_m": -1}, r"gyration_m must be > 0"),
        (
            {"mass_kg": 3, "radius_m": 0.5, "gyration_m": 0.6},
            r"gyration_m must be <= radius_m",
        ),
        (
            {"mass_kg": 3, "radius_m": 0.5, "gyration_m": 0.6, "shape": "cube"},
            r"gyration_m must be <= radius_m for a cube",
        ),
        (
            {"mass_kg": 3, "radius_m": 1, "gyration_m": 0.5, "shape": "blob"},
            r"shape must be",
        ),
        (
            {"mass_kg": 3, "radius_m": 1, "gyration_m": 0.5, "volume_m3": 0},
            r"volume_m3",
        ),
        (
            {"mass_kg": float("nan"), "radius_m": 1, "gyration_m": 0.5},
            r"mass_kg must be > 0",
        ),
    ],
)
def test_bad_bodies_name_the_argument(kwargs, message):
    with pytest.raises(ArgumentError, match=message):
        Body(**kwargs)


def test_elongated_shapes_may_have_gyration_above_contact_radius():
    # A 2 m rod landing on its side: r = 0.3 m, k = 0.6 m is physically possible.
    body = Body(100.0, 0.3, 0.6, shape="cylinder")
    assert body.gyration_m > body.radius_m


def test_bad_shape_dimensions():
    with pytest.raises(ArgumentError, match=r"must be 3 value\(s\): 2a axis length"):
        shape_body("ellipsoid", (1.6, 1.3))
    with pytest.raises(ArgumentError, match=r"dimensions_m must be > 0 \(got -1\)"):
        shape_body("cube", -1)
    with pytest.raises(ArgumentError, match=r"shape must be one of cube, sphere"):
        shape_body("pyramid", 1.0)
    with pytest.raises(ArgumentError, match=r"unit_weight_kn_m3 must be > 0"):
        shape_body("cube", 1.0, unit_weight_kn_m3=0)


def test_every_shape_has_gyration_within_its_extent():
    # Physical bound: k never exceeds the largest distance from the rotation axis.
    for spec in SHAPES.values():
        dims = (1.0, 0.7, 0.4)[: len(spec.dimension_names)]
        low, high = spec.contact_radius_range(dims)
        assert low <= spec.contact_radius(dims) <= high
        assert 0 < spec.gyration(dims) <= high
