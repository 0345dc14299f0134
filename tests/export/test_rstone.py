"""r.stone export: rasters re-read, percent rounding by hand, tan(phi), the DEM shift.

References: the r.stone manual and source (nrest/trest whole percent 0-100,
friction tan(beta), elevations > 0 m) and hand arithmetic, e.g. tan(19.29 deg) =
0.34999 -> 0.35; 1000 trajectories over 3 release cells -> 333 a cell.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fieldkit.errors import ArgumentError
from fieldkit.export.rstone import (
    dem_offset_m,
    export_rstone,
    friction_sd_tan,
    percent,
    stoch_range,
)
from fieldkit.export.site import site_from_dem, site_from_section
from fieldkit.io.dem import read_dem
from fieldkit.model.model_file import model_from_dict, read_model

RASTERS = ("dem.asc", "sources.asc", "nrest.asc", "trest.asc", "friction.asc")
HEADER_KEYS = ["ncols", "nrows", "xllcorner", "yllcorner", "cellsize", "NODATA_value"]


def _one_material(**material):
    return model_from_dict(
        {
            "profile": {"x_m": [0, 40], "z_m": [30, 0], "material": "ground"},
            "materials": {
                "ground": {"e_n": 0.4, "e_t": 0.8, "friction_deg": 30, **material}
            },
            "body": {"mass_kg": 100, "radius_m": 0.5},
            "seeder": {"x_m": 1, "z_m": 31},
        }
    )


def test_a_grid_target_needs_a_site(tornado):
    with pytest.raises(ArgumentError, match="rstone needs a grid site"):
        export_rstone(tornado)


def test_tornado_section_rasters_reread(tornado, tmp_path, written_grids):
    site = site_from_section(tornado, cellsize_m=10, rows=3)
    export = export_rstone(tornado, site)
    assert sorted(export.files) == sorted(RASTERS)
    grids = written_grids(export, tmp_path)
    for name, text in export.files.items():
        keys = [line.split()[0] for line in text.splitlines()[:6]]
        assert keys == HEADER_KEYS, name
    dem = grids["dem.asc"]
    assert dem.shape == (3, 70)
    for name, g in grids.items():
        assert g.shape == dem.shape, name
        np.testing.assert_array_equal(g.x_m, dem.x_m)
        np.testing.assert_array_equal(g.y_m, dem.y_m)
    # The section ends flat at z = -4 m: raised by ceil(1 - (-4)) = 5 m.
    np.testing.assert_allclose(dem.values, site.grid.values + 5, atol=5e-4)
    assert dem.values.min() == pytest.approx(1.0)
    rock = np.zeros((3, 70), bool)
    rock[:, :3] = True  # column centres 5, 15, 25 m: x < 28 m is rock
    np.testing.assert_array_equal(grids["nrest.asc"].values, np.where(rock, 75, 100))
    np.testing.assert_array_equal(grids["trest.asc"].values, np.where(rock, 59, 62))
    # tan(2.86 deg) = 0.04996 -> 0.05; tan(19.29 deg) = 0.34999 -> 0.35.
    np.testing.assert_array_equal(
        grids["friction.asc"].values, np.where(rock, 0.05, 0.35)
    )
    source = np.zeros((3, 70), bool)
    source[:, 0] = True
    np.testing.assert_array_equal(grids["sources.asc"].values, source * 333)
    for name in ("sources.asc", "nrest.asc", "trest.asc"):
        values = grids[name].values
        assert (values == np.round(values)).all(), name
    assert ((grids["nrest.asc"].values >= 0) & (grids["nrest.asc"].values <= 100)).all()


def test_tornado_options_and_readme(tornado):
    export = export_rstone(tornado, site_from_section(tornado, cellsize_m=10))
    how = export.how_to_use
    for name in RASTERS:
        stem = name.removesuffix(".asc")
        assert f"r.in.gdal -o input={name} output={stem}" in how
    # e_n_sd = e_t_sd = 0.04 -> 50 x 0.04 = 2; colluvium friction SD 2 deg at 19.29
    # deg: 0.0349066 / cos^2 = 0.039183 in tan -> 1.96 -> 2 (rock: 1.31 -> 1).
    assert "vrest_stoch_range=2" in how and "hrest_stoch_range=2" in how
    assert "frict_stoch_range=2" in how
    assert "start_vel=3.007 stop_vel=0.05" in how
    mismatches = "\n".join(export.mismatches)
    assert "frict_stoch_range: the materials need 1, 2" in mismatches
    assert "raised by 5 m" in mismatches
    assert "1.059 x fieldkit's" in mismatches  # 1 / cos(19.29 deg) = 1.0595
    assert "colluvium: nrest 100 % with a draw SD of 0.04" in mismatches
    unmapped = dict(export.unmapped)
    assert any(k.startswith("slope roughness (rock") for k in unmapped)
    readme = export.readme("model.json")
    assert all(f"* `{name}`" in readme for name in RASTERS)


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        (0.625, 63),  # half up (Python's round gives 62)
        (0.285, 29),  # 100 x 0.285 = 28.499999... in binary: still 29
        (0.754, 75),
        (0.755, 76),
        (0.004, 0),
        (0.005, 1),
        (1.0, 100),
        (0.0, 0),
    ],
)
def test_percent_rounding_by_hand(value, expected):
    assert percent(value) == expected


def test_percent_written_to_the_rasters(tmp_path, written_grids):
    model = _one_material(e_n=0.625, e_t=0.285)
    grids = written_grids(
        export_rstone(model, site_from_section(model, cellsize_m=5)), tmp_path
    )
    assert (grids["nrest.asc"].values == 63).all()
    assert (grids["trest.asc"].values == 29).all()
    # tan(30 deg) = 0.57735 -> 0.577
    assert (grids["friction.asc"].values == 0.577).all()


def test_spread_ranges_by_hand():
    assert stoch_range(0.04) == 2 and stoch_range(0.05) == 3 and stoch_range(0) == 0
    assert friction_sd_tan(19.29, 2.0) == pytest.approx(
        math.radians(2.0) / math.cos(math.radians(19.29)) ** 2
    )
    # cos(19.29 deg) = 0.943859, cos^2 = 0.890869: 0.0349066 / 0.890869 = 0.039183
    assert friction_sd_tan(19.29, 2.0) == pytest.approx(0.039183, abs=1e-6)


def test_dem_offset_by_hand():
    assert dem_offset_m(np.array([-7.138465, 120.0])) == 9.0  # ceil(8.138465)
    assert dem_offset_m(np.array([0.0, 3.0])) == 1.0
    assert dem_offset_m(np.array([0.2, 3.0])) == 0.0


@pytest.mark.parametrize(
    ("material", "message"),
    [
        ({"e_n": 1.2}, "materials.ground.e_n = 1.2: r.stone accepts restitution 0-100"),
        ({"e_t": 1.05}, "materials.ground.e_t = 1.05"),
        ({"friction_deg": 50}, "materials.ground.friction_deg = 50"),
    ],
)
def test_values_outside_rstone_are_refused(material, message):
    model = _one_material(**material)
    with pytest.raises(ArgumentError, match=message):
        export_rstone(model, site_from_section(model, cellsize_m=5))


def test_rocks_shared_over_release_cells(tmp_path, written_grids):
    model = _one_material()
    site = site_from_section(model, cellsize_m=5, rows=3)
    export = export_rstone(model, site, rocks=10)
    sources = written_grids(export, tmp_path)["sources.asc"].values
    assert sources.sum() == 9 and sources.max() == 3  # round(10 / 3) = 3 a cell
    with pytest.raises(ArgumentError, match="rocks must be a whole number >= 1"):
        export_rstone(model, site, rocks=0)


def test_small_cells_are_noted(tornado):
    export = export_rstone(tornado, site_from_section(tornado))  # 1.5 m cells
    assert any("smaller than r.stone's 5 m" in n for n in export.notes)


def test_tschamut_dem_site(repo, tmp_path, written_grids):
    model = read_model(repo / "examples/tschamut/model_base.json")
    terrain = read_dem(repo / "tests/data/tschamut2014/terrain.asc")
    export = export_rstone(model, site_from_dem(model, terrain, (33.4, 236.67)))
    grids = written_grids(export, tmp_path)
    for g in grids.values():
        assert g.shape == (46, 43)
        np.testing.assert_allclose(g.x_m, terrain.x_m)
        np.testing.assert_allclose(g.y_m, terrain.y_m)
    # Lowest elevation -7.138465 m: raised by 9 m.
    np.testing.assert_allclose(grids["dem.asc"].values, terrain.values + 9, atol=5e-4)
    source = np.zeros((46, 43), bool)
    source[15, 13] = True  # the cell centred (32.5, 237.5)
    np.testing.assert_array_equal(grids["sources.asc"].values, source * 1000)
    assert (grids["nrest.asc"].values == 100).all()  # meadow e_n 1.00
    assert (grids["trest.asc"].values == 62).all()
    assert (grids["friction.asc"].values == 0.35).all()
    assert "start_vel=1 stop_vel=0.05" in export.how_to_use  # seeder at rest
