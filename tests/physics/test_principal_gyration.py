"""Radius of gyration of a block from its principal lengths, against closed forms,
and the Tschamut 2014 blocks' metadata (why the ellipsoid, which axis)."""

from __future__ import annotations

import math
import re

import numpy as np
import pandas as pd
import pytest

from fieldkit.errors import ArgumentError
from fieldkit.physics.bodies import principal_gyration_m, resolve_body, shape_body


def _ellipsoid_inertia_by_quadrature(lengths, axis: int, n: int = 81) -> float:
    """I / m of a solid ellipsoid about one principal axis, summed over a grid of
    cells (independent of the closed form)."""
    semi = np.asarray(lengths, float) / 2.0
    s = (np.arange(n) + 0.5) / n * 2.0 - 1.0
    x, y, z = np.meshgrid(s * semi[0], s * semi[1], s * semi[2], indexing="ij")
    inside = (x / semi[0]) ** 2 + (y / semi[1]) ** 2 + (z / semi[2]) ** 2 <= 1.0
    r2 = [y**2 + z**2, x**2 + z**2, x**2 + y**2][axis]
    return float(r2[inside].mean())


def test_sphere_limit():
    # all three lengths 2r: the solid sphere, k = r sqrt(2/5), either model's axis
    for r in (0.0375, 0.5, 2.0):
        assert principal_gyration_m((2 * r, 2 * r, 2 * r)) == pytest.approx(
            r * math.sqrt(0.4), rel=1e-12
        )
    # and the limit is continuous: a block 1e-6 off round
    k = principal_gyration_m((1.000001, 1.0, 0.999999))
    assert k == pytest.approx(0.5 * math.sqrt(0.4), rel=2e-6)


def test_cube():
    # a cube of side L as a cuboid: I = m L^2 / 6 about any axis (Table 4-1)
    assert principal_gyration_m((0.6, 0.6, 0.6), "cuboid") == pytest.approx(
        0.6 / math.sqrt(6), rel=1e-12
    )
    assert principal_gyration_m((0.6,) * 3, "cuboid") == pytest.approx(
        shape_body("cube", 0.6).gyration_m, rel=1e-12
    )


def test_two_to_one_ellipsoid():
    # a prolate spheroid 2:1 (semi-axes a = 1, b = c = 0.5): about a transverse axis
    # I = m (a^2 + b^2) / 5 = m 0.25, k = 0.5; in any order of the lengths
    for lengths in ((2.0, 1.0, 1.0), (1.0, 2.0, 1.0), (1.0, 1.0, 2.0)):
        assert principal_gyration_m(lengths) == pytest.approx(0.5, rel=1e-12)
    # an oblate spheroid 2:1 (a = b = 1, c = 0.5) rolls like a wheel about c:
    # I = m (1 + 1) / 5, k = sqrt(0.4)
    assert principal_gyration_m((2.0, 2.0, 1.0)) == pytest.approx(math.sqrt(0.4))


def test_ellipsoid_against_quadrature_and_largest_axis():
    lengths = (0.46, 0.30, 0.20)  # the Tschamut "Plate"
    by_axis = [
        math.sqrt(_ellipsoid_inertia_by_quadrature(lengths, i)) for i in range(3)
    ]
    k = principal_gyration_m(lengths)
    # the shortest axis (index 2) has the largest moment: that is the one returned
    assert max(by_axis) == by_axis[2]
    assert k == pytest.approx(by_axis[2], rel=2e-3)  # grid of 81^3 cells
    assert k == pytest.approx(math.sqrt((0.46**2 + 0.30**2) / 20), rel=1e-12)


def test_cuboid_closed_form():
    assert principal_gyration_m((0.5, 0.3, 0.39), "cuboid") == pytest.approx(
        math.sqrt((0.5**2 + 0.39**2) / 12), rel=1e-12
    )


@pytest.mark.parametrize(
    "lengths, model, words",
    [
        ((0.5, 0.3), "ellipsoid", "3 principal lengths (got 2)"),
        ((0.5, 0.3, 0.0), "ellipsoid", "dimensions_m must be > 0"),
        ((0.5, -0.3, 0.2), "ellipsoid", "dimensions_m must be > 0"),
        ((0.5, 0.3, 0.2), "brick", "model must be one of ellipsoid, cuboid"),
    ],
)
def test_bad_lengths_name_the_argument(lengths, model, words):
    with pytest.raises(ArgumentError, match=re.escape(words)):
        principal_gyration_m(lengths, model)


def test_tschamut_blocks_are_ellipsoids_not_boxes(external_data):
    """The metadata's weighed masses over the two solids' volumes: the ellipsoid of
    the principal lengths gives rock densities, the box cannot."""
    blocks = pd.read_csv(external_data / "tschamut2014" / "block_metadata.csv")
    lengths = blocks[["size_x_m", "size_y_m", "size_z_m"]].to_numpy(float)
    box = lengths.prod(axis=1)
    rho_ellipsoid = blocks["mass_kg"] / (math.pi / 6 * box)
    rho_box = blocks["mass_kg"] / box
    np.testing.assert_allclose(rho_ellipsoid, [3008.1, 2579.1, 2767.9], atol=0.1)
    np.testing.assert_allclose(rho_box, [1575.1, 1350.4, 1449.3], atol=0.1)
    assert rho_ellipsoid.between(2500, 3100).all()  # gneiss, granite, amphibolite
    assert (rho_box < 2000).all()  # lighter than any rock


@pytest.mark.parametrize(
    "name, k, more_inertia",
    [
        # sqrt((L1^2 + L2^2) / 20) of the two longest lengths; how much more
        # rotational inertia than the default sphere of the equivalent radius
        ("block_1_st_leonard", math.sqrt((0.37**2 + 0.37**2) / 20), 0.0966),
        ("block_2_most_heavy", math.sqrt((0.5**2 + 0.39**2) / 20), 0.2778),
        ("block_4_plate", math.sqrt((0.46**2 + 0.30**2) / 20), 0.4727),
    ],
)
def test_tschamut_shape_metadata_gyration(external_data, name, k, more_inertia):
    path = external_data / "tschamut2014" / "shape_metadata" / f"{name}.yaml"
    text = path.read_text()  # two lines of the YAML (no YAML reader here)
    lengths = [
        float(v)
        for v in re.search(r"principal_lengths_m: \[(.*)\]", text)[1].split(",")
    ]
    equivalent = float(re.search(r"equivalent_radius_m: (\S+)", text)[1])
    assert principal_gyration_m(lengths) == pytest.approx(k, rel=1e-12)
    # the "block" shape of the body rules gives the same k, and the equivalent
    # radius of the metadata is its mean semi-axis
    body = resolve_body(shape="block", dimensions_m=lengths, mass_kg=69.0)
    assert body.gyration_m == pytest.approx(k, rel=1e-12)
    assert equivalent == pytest.approx(sum(lengths) / 6, abs=1e-6)
    # the default, a solid sphere of the equivalent radius, has less inertia
    sphere_k = math.sqrt(0.4) * equivalent
    assert (k / sphere_k) ** 2 - 1 == pytest.approx(more_inertia, abs=5e-4)
