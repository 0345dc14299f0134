"""Bodies and thesis Table 4-1 shapes."""

from __future__ import annotations

import math

import pytest

from fieldkit.errors import ArgumentError
from fieldkit.physics.bodies import (
    SHAPES,
    Body,
    parse_dimensions,
    resolve_body,
    shape_body,
    shape_spec,
)


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


# --- resolve_body: the one set of body rules every command uses -------------------

BOULDER_A = {"shape": "ellipsoid", "dimensions_m": (1.6, 1.3, 1.3)}


def test_resolve_direct_values_keep_what_was_given():
    body = resolve_body(mass_kg=3750, radius_m=0.725, gyration_m=0.46)
    assert (body.mass_kg, body.radius_m, body.gyration_m) == (3750, 0.725, 0.46)
    assert (body.mass_source, body.radius_source, body.gyration_source) == (
        "given",
        "given",
        "given",
    )
    assert body.notes == () and body.shape is None
    assert body.inertia_kgm2 == pytest.approx(3750 * 0.46**2)


def test_resolve_nothing_given_leaves_every_value_unknown():
    body = resolve_body()
    assert body.missing("mass_kg", "radius_m", "gyration_m") == (
        "mass_kg",
        "radius_m",
        "gyration_m",
    )
    assert body.description == "no body given" and body.inertia_kgm2 is None


def test_resolve_shape_matches_shape_body():
    body = resolve_body(**BOULDER_A)
    reference = shape_body("ellipsoid", (1.6, 1.3, 1.3))
    assert body.mass_kg == pytest.approx(reference.mass_kg)
    assert body.radius_m == pytest.approx(0.725)
    assert body.gyration_m == pytest.approx(reference.gyration_m)
    assert body.volume_m3 == pytest.approx(reference.volume_m3)
    assert body.unit_weight_kn_m3 == 26.0 and body.notes == ()
    assert {body.mass_source, body.radius_source, body.gyration_source} == {"shape"}


def test_resolve_weighed_mass_overrides_the_shape_with_a_note():
    body = resolve_body(mass_kg=3600, **BOULDER_A)
    assert body.mass_kg == 3600 and body.mass_source == "given"
    assert body.gyration_m == pytest.approx(0.461, abs=5e-4)  # still from the shape
    (note,) = body.notes
    assert "`mass_kg` 3600 kg overrides the 3752 kg of the ellipsoid" in note


@pytest.mark.parametrize("name", ["gyration_m", "inertia_kgm2"])
def test_resolve_gyration_or_inertia_with_a_shape_is_an_error(name):
    with pytest.raises(ArgumentError, match=rf"{name} is computed from `shape`") as e:
        resolve_body(**{name: 0.4}, **BOULDER_A)
    assert e.value.source == name


def test_resolve_radius_overrides_only_within_the_shape_range():
    body = resolve_body(radius_m=0.8, **BOULDER_A)  # Table 2-6: r = a
    assert body.radius_m == 0.8 and body.radius_source == "given"
    assert "`radius_m` 0.8 m overrides the ellipsoid's contact radius" in body.notes[0]
    for radius in (0.6, 0.81):
        with pytest.raises(ArgumentError) as e:
            resolve_body(radius_m=radius, **BOULDER_A)
        assert e.value.source == "radius_m"
        assert "between 0.65 and 0.8 m for `shape` ellipsoid" in e.value.message
        assert "`dimensions_m` 1.6,1.3,1.3" in e.value.message


@pytest.mark.parametrize(
    ("shape", "dims", "low", "high"),
    [
        ("cube", (0.6,), 0.3, 0.6 / math.sqrt(2)),  # face centre to corner
        ("sphere", (0.5,), 0.5, 0.5),
        ("cylinder", (2.0, 0.3), 0.3, math.hypot(0.3, 1.0)),  # L x 2r rectangle
        ("ellipsoid", (1.6, 1.3, 1.0), 0.65, 0.8),  # a-b ellipse, rotation about c
    ],
)
def test_radius_range_per_shape(shape, dims, low, high):
    assert SHAPES[shape].contact_radius_range(dims) == pytest.approx((low, high))
    for radius in (low, high):
        assert resolve_body(shape=shape, dimensions_m=dims, radius_m=radius).radius_m
    for radius in (low * 0.99, high * 1.01):
        with pytest.raises(ArgumentError, match="radius_m must be between"):
            resolve_body(shape=shape, dimensions_m=dims, radius_m=radius)


@pytest.mark.parametrize(
    ("kwargs", "source"),
    [
        ({"unit_weight_kn_m3": 24.0, "mass_kg": 500}, "unit_weight_kn_m3"),
        ({"dimensions_m": (0.6,), "mass_kg": 500}, "dimensions_m"),
        ({"shape": "cube"}, "shape"),  # a shape needs its dimensions
        ({"shape": "pyramid", "dimensions_m": (1.0,)}, "shape"),
        ({"shape": "cube", "dimensions_m": (1.0, 2.0)}, "dimensions_m"),
        ({"shape": "cube", "dimensions_m": "1,x"}, "dimensions_m"),
        ({"shape": "cube", "dimensions_m": (1.0,), "unit_weight_kn_m3": 0},
         "unit_weight_kn_m3"),
        ({"mass_kg": -3}, "mass_kg"),
        ({"radius_m": 0.0}, "radius_m"),
        ({"gyration_m": float("nan")}, "gyration_m"),
        ({"gyration_m": 0.3, "inertia_kgm2": 40, "mass_kg": 500}, "inertia_kgm2"),
        ({"inertia_kgm2": 40}, "inertia_kgm2"),  # k = sqrt(I/m) needs m
    ],
)  # fmt: skip
def test_resolve_errors_name_the_argument(kwargs, source):
    with pytest.raises(ArgumentError) as e:
        resolve_body(**kwargs)
    assert e.value.source == source
    assert "--" not in str(e.value)  # library messages never name flags


def test_resolve_unit_weight_with_a_shape():
    body = resolve_body(shape="cube", dimensions_m=0.6, unit_weight_kn_m3=24.0)
    assert body.mass_kg == pytest.approx(0.216 * 24e3 / 9.81)  # Ehime, ~528 kg


@pytest.mark.parametrize("name", ["cube", "CUBE", " Cube ", "cUbE"])
def test_shape_names_are_case_insensitive(name):
    assert resolve_body(shape=name, dimensions_m=0.6).shape == "cube"
    assert shape_spec(name) is SHAPES["cube"]
    assert shape_body(name, 0.6).shape == "cube"


@pytest.mark.parametrize(
    "text",
    ["1.6,1.3,1.3", "1.6x1.3x1.3", "1.6X1.3X1.3", "1.6 x 1.3 x 1.3", " 1.6, 1.3 ,1.3 "],
)
def test_dimension_text(text):
    assert parse_dimensions(text) == (1.6, 1.3, 1.3)
    body = resolve_body(shape="ellipsoid", dimensions_m=text)
    assert body.dimensions_m == (1.6, 1.3, 1.3)


@pytest.mark.parametrize("text", ["1.6,,1.3", "a,b", "", "1.6;x1.3"])
def test_bad_dimension_text(text):
    with pytest.raises(ArgumentError, match="dimensions_m must be numbers"):
        parse_dimensions(text)


def test_gyration_at_most_radius_whenever_both_are_known():
    assert resolve_body(radius_m=0.5, gyration_m=0.5).gyration_m == 0.5  # thin hoop
    with pytest.raises(ArgumentError, match="gyration_m must be <= radius_m") as e:
        resolve_body(radius_m=0.2, gyration_m=0.3)  # no mass needed
    assert e.value.source == "gyration_m"
    with pytest.raises(ArgumentError, match="inertia_kgm2 gives k that must be <="):
        resolve_body(mass_kg=520, inertia_kgm2=63.7, radius_m=0.3)  # k = 0.35
    with pytest.raises(ArgumentError, match="gyration_m must be <= radius_m"):
        resolve_body(gyration_m=0.3).with_measured_radius(0.2)


def test_elongated_shape_radius_is_bounded_by_its_dimensions_instead():
    # A 2 m rod landing on its side (r = 0.3 m, inside its range) has k = 0.59 m > r:
    # physically possible (see test_elongated_shapes_may_have_gyration_above_...).
    body = resolve_body(shape="cylinder", dimensions_m=(2.0, 0.3), radius_m=0.3)
    assert body.gyration_m > body.radius_m


def test_inertia_gives_gyration():
    body = resolve_body(mass_kg=520, inertia_kgm2=63.7)
    assert body.gyration_m == pytest.approx(0.35, abs=1e-4)
    assert body.gyration_source == "inertia"


def test_require_lists_every_missing_value_in_one_error():
    body = resolve_body(mass_kg=500)
    assert body.require("mass_kg") is body
    with pytest.raises(ArgumentError) as e:
        body.require("mass_kg", "radius_m", "gyration_m", source="caller")
    assert str(e.value) == "caller: body needs `radius_m` and `gyration_m` (or `shape`)"
    with pytest.raises(ArgumentError, match=r"needs `mass_kg`, `radius_m` and `gyr"):
        resolve_body().require("mass_kg", "radius_m", "gyration_m")


def test_measured_radius_fills_only_an_unknown_radius():
    measured = resolve_body(mass_kg=0.14).with_measured_radius(0.0375)
    assert measured.radius_m == 0.0375 and measured.radius_source == "measured"
    assert measured.notes == ("`radius_m` not given; using the measured 0.0375 m",)
    given = resolve_body(radius_m=0.04)
    assert given.with_measured_radius(0.0375) is given
    assert resolve_body().with_measured_radius(float("nan")).radius_m is None
