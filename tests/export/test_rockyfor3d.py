"""Rockyfor3D export: grids re-read, code domains, the soil-type choice, the block.

References are hand computations and the format (Dorren 2016, §2.1, Table 1), not
the exporter's output: e.g. the Tornado block 3750 kg in a sphere of r = 0.725 m is
3750 / (pi/6 * 1.45^3) = 3750 / 1.596256 = 2349.2 kg/m3.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.stats import halfnorm

from fieldkit.errors import ArgumentError
from fieldkit.export.rockyfor3d import (
    SOIL_TYPES,
    export_rockyfor3d,
    nearest_soil_type,
    obstacle_heights,
    sphere_block,
)
from fieldkit.export.site import site_from_dem, site_from_section
from fieldkit.io.dem import DemGrid, read_dem
from fieldkit.model.model_file import model_from_dict, read_model

GRIDS = (
    "dem.asc",
    "rockdensity.asc",
    "d1.asc",
    "d2.asc",
    "d3.asc",
    "blshape.asc",
    "rg70.asc",
    "rg20.asc",
    "rg10.asc",
    "soiltype.asc",
)
HEADER_KEYS = ["ncols", "nrows", "xllcorner", "yllcorner", "cellsize", "NODATA_value"]


def _one_material(e_n=0.4, **extra):
    material = {"e_n": e_n, "e_t": 0.8, "friction_deg": 30, **extra}
    return model_from_dict(
        {
            "profile": {"x_m": [0, 40], "z_m": [30, 0], "material": "ground"},
            "materials": {"ground": material},
            "body": {"mass_kg": 100, "radius_m": 0.5},
            "seeder": {"x_m": 1, "z_m": 31},
            "effects": {"slope_roughness": {}},
        }
    )


def test_a_grid_target_needs_a_site(tornado):
    with pytest.raises(ArgumentError, match="rockyfor3d needs a grid site"):
        export_rockyfor3d(tornado, None)


def test_tornado_section_grids_reread(tornado, tmp_path, written_grids):
    site = site_from_section(tornado, cellsize_m=10, rows=3)
    export = export_rockyfor3d(tornado, site)
    assert sorted(export.files) == sorted(GRIDS)
    grids = written_grids(export, tmp_path)
    for name, text in export.files.items():
        keys = [line.split()[0] for line in text.splitlines()[:6]]
        assert keys == HEADER_KEYS, name
    # 700 m of profile in 10 m cells from x = 0; 3 rows centred on y = 0.
    dem = grids["dem.asc"]
    assert dem.shape == (3, 70)
    assert dem.cellsize_m == 10
    assert dem.x_m[0] - 5 == 0 and dem.y_m[-1] - 5 == -15
    for name, grid in grids.items():
        assert grid.shape == dem.shape, name
        np.testing.assert_array_equal(grid.x_m, dem.x_m)
        np.testing.assert_array_equal(grid.y_m, dem.y_m)
    # Column centres 5, 15, 25 m on the profile (z 350 -> 316 -> 295 -> 280).
    np.testing.assert_allclose(dem.values[:, 0], 350 - 34 * 5 / 8, atol=1e-3)
    np.testing.assert_allclose(dem.values[:, 2], 316 - 21 * 17 / 20, atol=1e-3)
    np.testing.assert_allclose(dem.values, site.grid.values, atol=5e-4)


def test_tornado_codes_block_and_source_cells(tornado, tmp_path, written_grids):
    grids = written_grids(
        export_rockyfor3d(tornado, site_from_section(tornado, cellsize_m=10, rows=3)),
        tmp_path,
    )
    source = np.zeros((3, 70), bool)
    source[:, 0] = True  # the seeder at chainage 0: the first column
    soil = grids["soiltype.asc"].values
    shape = grids["blshape.asc"].values
    assert set(np.unique(soil)) <= set(range(8))
    assert set(np.unique(shape)) <= set(range(5))
    # rock e_n 0.75 and colluvium e_n 1.00: both nearest bedrock's mean 0.53.
    assert (soil == 6).all()
    np.testing.assert_array_equal(shape, np.where(source, 3, 0))
    np.testing.assert_array_equal(grids["rockdensity.asc"].values, source * 2349)
    for name in ("d1.asc", "d2.asc", "d3.asc"):
        np.testing.assert_allclose(grids[name].values, source * 1.45)


def test_tornado_obstacle_heights(tornado, tmp_path, written_grids):
    grids = written_grids(
        export_rockyfor3d(tornado, site_from_section(tornado, cellsize_m=10, rows=3)),
        tmp_path,
    )
    # Rock (x < 28 m: columns 0-2) has a dip SD of 35 deg; colluvium 0.
    # rg70 by hand: 35 deg x 0.45376 (normal quantile 0.675) = 15.88 deg,
    # 0.725 m x tan(15.88 deg) = 0.2063 m.
    rock = np.zeros((3, 70), bool)
    rock[:, :3] = True
    for key, q in (("rg70", 0.35), ("rg20", 0.80), ("rg10", 0.95)):
        h = 0.725 * math.tan(math.radians(35.0 * halfnorm.ppf(q)))
        np.testing.assert_allclose(
            grids[f"{key}.asc"].values, rock * round(h, 3), atol=1e-9
        )
    assert grids["rg70.asc"].values[0, 0] == pytest.approx(0.206)


@pytest.mark.parametrize(
    ("e_n", "code"),
    [
        (0.75, 6),
        (1.0, 6),
        (0.23, 1),
        (0.255, 2),  # halfway 0.23 / 0.28: the higher
        (0.305, 3),  # halfway 0.28 / 0.33
        (0.34, 7),  # halfway 0.33 (scree) / 0.35 (asphalt)
        (0.365, 4),  # halfway 0.35 / 0.38
        (0.48, 6),  # halfway 0.43 / 0.53
        (0.115, 1),  # halfway 0 / 0.23
        (0.05, 0),
        (0.29, 2),
    ],
)
def test_nearest_soil_type_hand_cases(e_n, code):
    assert nearest_soil_type(e_n).code == code


def test_soil_type_table_is_consistent():
    assert [s.code for s in SOIL_TYPES] == list(range(8))
    means = {s.code: s.rn_mean for s in SOIL_TYPES}
    assert means == {
        0: 0,
        1: 0.23,
        2: 0.28,
        3: 0.33,
        4: 0.38,
        5: 0.43,
        6: 0.53,
        7: 0.35,
    }
    for s in SOIL_TYPES:  # each mean is the middle of its range
        assert s.rn_mean == pytest.approx((s.rn_min + s.rn_max) / 2)


def test_mismatch_and_unmapped_rt_are_reported(tornado):
    export = export_rockyfor3d(tornado, site_from_section(tornado, cellsize_m=10))
    text = "\n".join(export.mismatches)
    assert "6: 0.53" in text and "7: 0.35" in text  # the class means used
    assert (
        "rock: e_n = 0.75 -> soiltype 6 (bedrock), mean Rn 0.53: mismatch 0.22" in text
    )
    assert (
        "colluvium: e_n = 1 -> soiltype 6 (bedrock), mean Rn 0.53: mismatch 0.47"
        in text
    )
    assert "no Rockyfor3D soil type reaches it" in text  # 1.0 > 0.58
    unmapped = dict(export.unmapped)
    assert "Rt" in unmapped["materials.rock.e_t = 0.59"]
    assert "Rt" in unmapped["materials.colluvium.e_t = 0.62"]
    readme = export.readme("model.json")
    assert all(f"* `{name}`" in readme for name in GRIDS)


def test_tornado_block_by_hand(tornado):
    diameter, density = sphere_block(tornado.body)
    assert diameter == pytest.approx(1.45)
    volume = math.pi / 6 * 1.45**3  # 1.596256 m3
    assert volume == pytest.approx(1.596256, abs=1e-6)
    assert density == 2349 == round(3750 / volume)


def test_obstacle_heights_from_roughness_m():
    # roughness_m = r tan(10 deg): eq. 7.4 gives a dip SD of exactly 10 deg.
    model = _one_material(roughness_m=0.5 * math.tan(math.radians(10.0)))
    export = export_rockyfor3d(model, site_from_section(model, cellsize_m=2))
    rg10 = float(export.files["rg10.asc"].splitlines()[6].split()[0])
    assert rg10 == pytest.approx(0.5 * math.tan(math.radians(10 * 1.959964)), abs=5e-4)
    assert obstacle_heights(0.0, 0.5) == {"rg70": 0.0, "rg20": 0.0, "rg10": 0.0}
    with pytest.raises(ArgumentError, match="materials.ground: a dip SD of 50"):
        obstacle_heights(50.0, 0.5, name="ground")  # rg10 dip 98 deg


def test_roughness_without_the_effect_is_smooth():
    model = _one_material(roughness_deg_sd=20.0)
    model = replace(model, effects={})
    export = export_rockyfor3d(model, site_from_section(model, cellsize_m=2))
    for key in ("rg70", "rg20", "rg10"):
        values = {
            v
            for line in export.files[f"{key}.asc"].splitlines()[6:]
            for v in line.split()
        }
        assert values == {"0"}


def test_cells_without_ground_are_nodata(tmp_path, written_grids):
    values = np.array([[30.0, 25.0, 20.0], [29.0, np.nan, 19.0], [28.0, 23.0, 18.0]])
    grid = DemGrid.from_corner(values, x_left_m=0, y_top_m=30, cellsize_m=10)
    model = _one_material()
    grids = written_grids(
        export_rockyfor3d(model, site_from_dem(model, grid, (5.0, 25.0))), tmp_path
    )
    for name, g in grids.items():
        assert np.isnan(g.values[1, 1]), name
        assert np.isfinite(np.delete(g.values.ravel(), 4)).all(), name
    assert grids["rockdensity.asc"].values[0, 0] > 0  # the release cell
    assert grids["soiltype.asc"].values[0, 0] == 4  # e_n 0.40: nearest 0.38


def test_tschamut_dem_site(repo, tmp_path, written_grids):
    model = read_model(repo / "examples/tschamut/model_base.json")
    terrain = read_dem(repo / "tests/data/tschamut2014/terrain.asc")
    site = site_from_dem(model, terrain, (33.4, 236.67))  # release v004
    grids = written_grids(export_rockyfor3d(model, site), tmp_path)
    head = (repo / "tests/data/tschamut2014/terrain.asc").read_text().splitlines()[:6]
    assert [line.split()[0].lower() for line in head] == [
        k.lower() for k in HEADER_KEYS
    ]
    for name, g in grids.items():
        assert g.shape == (46, 43), name
        np.testing.assert_allclose(g.x_m, terrain.x_m)
        np.testing.assert_allclose(g.y_m, terrain.y_m)
    np.testing.assert_allclose(grids["dem.asc"].values, terrain.values, atol=5e-4)
    # Cell centres x = -32.5 + 5 i, y = 312.5 - 5 j: (32.5, 237.5) is (j 15, i 13).
    source = np.zeros((46, 43), bool)
    source[15, 13] = True
    # 69 kg in a sphere of r 0.176667 m: 0.353334^3 = 0.0441120, x pi/6 = 0.0230967
    # m3, 69 / 0.0230967 = 2987.4 kg/m3.
    np.testing.assert_array_equal(grids["rockdensity.asc"].values, source * 2987)
    assert (grids["soiltype.asc"].values == 6).all()  # meadow e_n 1.00
    # meadow: dip SD 8 deg -> rg70 = 0.176667 tan(8 x 0.45376 deg) = 0.0112 m.
    assert (grids["rg70.asc"].values == 0.011).all()
