"""r.stone's inputs from a 3-D model's own DEM (fieldkit.export.rstone3d) and the
footprint read from a passing-count raster (fieldkit.fit.footprint), without GRASS.
The real r.stone on them: tests/export/test_rstone_real.py (slow)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from fieldkit.errors import ArgumentError
from fieldkit.export.rstone3d import (
    batch_script,
    rstone_inputs3d,
    source_cell,
    sources_text,
)
from fieldkit.fit.footprint import footprint
from fieldkit.io.dem import read_dem
from fieldkit.model.materials import Material
from fieldkit.model.model3d import Model3D, Seeder3D
from fieldkit.model.model_blocks import Body
from fieldkit.model.terrain import Terrain


def _model(z=None, cell=5.0, index=None, **material) -> Model3D:
    if z is None:  # falls to the east, 10 x 6 cells, lowest centre at -2 m
        z = np.tile(np.arange(10.0)[::-1] * 2.0 - 2.0, (6, 1))
    values = {"e_n": 0.35, "e_t": 0.8, "friction_deg": 30.0, "e_n_sd": 0.04,
              "e_t_sd": 0.06, "friction_deg_sd": 2.0} | material  # fmt: skip
    materials = {
        "rock": Material.from_dict("rock", values),
        "scree": Material.from_dict("scree", values | {"e_n": 0.2}),
    }
    if index is None:
        index = np.zeros(z.shape, int)
        index[:, 5:] = 1  # the eastern half is scree
    return Model3D(
        Terrain(100.0, 200.0, cell, z), materials, index, {}, Body(100.0, 0.2, 0.13),
        np.array([[107.5, 212.5, 0.0]]), np.ones(1),
        Seeder3D(height_m=1.0, vx_mps=1.0), core={"stop_speed_mps": 0.3},
    )  # fmt: skip


def test_rasters_are_the_models_own_cells(tmp_path):
    inputs = rstone_inputs3d(_model())
    for name, text in inputs.files.items():
        (tmp_path / name).write_text(text)
    dem = read_dem(tmp_path / "dem.asc")
    # north-up, same corner and cells; raised by 3 m (lowest -2 m -> 1 m)
    assert inputs.offset_m == 3.0
    assert dem.cellsize_m == 5.0 and dem.shape == (6, 10)
    assert dem.x_m[0] == 102.5 and dem.y_m[0] == 227.5 and dem.y_m[-1] == 202.5
    assert dem.values[0, 0] == pytest.approx(19.0) and dem.values[5, 9] == 1.0
    nrest = read_dem(tmp_path / "nrest.asc").values
    assert nrest[:, :5].tolist() == [[35] * 5] * 6 and (nrest[:, 5:] == 20).all()
    assert (read_dem(tmp_path / "trest.asc").values == 80).all()
    assert read_dem(tmp_path / "friction.asc").values[0, 0] == pytest.approx(0.577)
    o = inputs.options
    # range = 50 SD: 0.04 -> 2, 0.06 -> 3; tan: 2 deg at 30 deg -> 0.0465 -> 2
    assert (o["vrest_stoch_range"], o["hrest_stoch_range"]) == (2, 3)
    assert o["frict_stoch_range"] == 2 and o["ang_stoch_range"] == 0
    # 1 m/s plus a 1 m drop: sqrt(1 + 2 * 9.81 * 1)
    assert o["start_vel"] == pytest.approx(math.sqrt(1 + 2 * 9.81), abs=1e-3)
    assert o["stop_vel"] == 0.3
    text = " ".join(inputs.notes)
    assert "constant 1" in text and "raised by 3 m" in text


def test_nodata_stays_no_ground_and_sources_sit_in_their_cells():
    z = np.tile(np.arange(10.0)[::-1] * 2.0 + 5.0, (6, 1))
    z[0, 0] = np.nan  # the south-west corner (row 0 south)
    inputs = rstone_inputs3d(_model(z))
    assert inputs.offset_m == 0.0 and np.isnan(inputs.grid.values[5, 0])
    assert source_cell(inputs, 107.5, 212.5) == (3, 1)
    lines = sources_text(inputs, [(3, 1)], 7).splitlines()
    assert lines[6 + 3].split()[1] == "7" and lines[-1].split()[0] == "-9999"
    script = batch_script(inputs.options, ["v006", "v007"])
    assert "for run in v006 v007" in script and "vrest_stoch_range=2" in script


@pytest.mark.parametrize(
    ("x", "y", "words"),
    [
        (102.5, 212.5, "not at least 1 cell inside"),  # the west column
        (107.5, 227.5, "not at least 1 cell inside"),  # the north row
        (107.5, 207.5, "no ground"),  # next to the nodata corner
    ],
)
def test_a_source_rstone_cannot_start_is_refused(x, y, words):
    z = np.tile(np.arange(10.0)[::-1] * 2.0 + 5.0, (6, 1))
    z[0, 0] = np.nan
    with pytest.raises(ArgumentError, match=words):
        source_cell(rstone_inputs3d(_model(z)), x, y)


@pytest.mark.parametrize(
    ("change", "words"),
    [
        ({"cell": 2.5}, "whole number of metres"),
        ({"e_t": 1.2}, "materials.rock.e_t = 1.2"),
        ({"friction_deg": 50.0}, "materials.rock.friction_deg = 50"),
    ],
)
def test_what_rstone_cannot_take_is_refused(change, words):
    cell = change.pop("cell", 5.0)
    with pytest.raises(ArgumentError, match=words):
        rstone_inputs3d(_model(cell=cell, **change))


def test_roughness_and_effects_are_said_not_written():
    m = _model(roughness_deg_sd=8.0)
    m = replace(m, effects={"slope_roughness": {}})
    notes = rstone_inputs3d(m).notes
    text = " ".join(notes)
    assert "rock 8 deg SD of the normal" in text and "not refitted" in text
    # the effect as its own export metadata for r.stone says
    assert "effect slope_roughness: r.stone has no roughness input" in text
    m = replace(m, effects={"air_drag": {"cd": 0.5}})
    assert "effect air_drag: r.stone's flight is a drag-free parabola" in " ".join(
        rstone_inputs3d(m).notes
    )


def test_footprint_reads_reach_passage_and_miss():
    count = np.zeros((3, 5))
    count[1, :4] = [10, 10, 6, 2]  # a row eastwards from (0, 0)
    x, y = np.arange(5) * 5.0, np.array([5.0, 0.0, -5.0])
    f = footprint(count, x, y, (0.0, 0.0), (21.0, 1.0))
    # farthest passed centre 15 m; weighted mean (0*10+5*10+10*6+15*2)/28
    assert f.reach_m == 15.0 and f.passage_mean_m == pytest.approx(140 / 28)
    # the deposit's cell (20, 0) was not passed: 6 m to (15, 0) ... hypot(6, 1)
    assert not f.deposit_passed and f.miss_m == pytest.approx(math.hypot(6, 1))
    assert f.observed_m == pytest.approx(math.hypot(21, 1))
    assert footprint(count, x, y, (0.0, 0.0), (9.0, 2.0)).deposit_passed
    with pytest.raises(ArgumentError, match="no cell was passed"):
        footprint(np.zeros((3, 5)), x, y, (0, 0), (1, 1))
