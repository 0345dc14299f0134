"""3-D hazard maps in tiles: the same deposits, rasters and line numbers as the
run in this process with the same seed, on a 2-worker Dask cluster, whatever the
tile and unit sizes; `fieldkit simulate --workers 2` writes the same files."""

from __future__ import annotations

import json

import numpy as np
import pytest

from fieldkit.model.hazard_tiles import simulate3d_tiled, tile_units
from fieldkit.model.model_file import read_model
from fieldkit.model.results3d import line_crossings, rasters
from fieldkit.model.simulate3d import draw_rocks3d, simulate3d
from fieldkit.parallel.engine import Engine, EngineSpec

LINE = np.array([[0.0, 180.0], [120.0, 180.0]])


@pytest.fixture(scope="module")
def model(repo):
    return read_model(repo / "examples" / "tschamut" / "model_3d.json", terrain=True)


def test_tiles_cover_every_rock_once(model):
    drawn = draw_rocks3d(model, 3000, np.random.default_rng(1))
    units = tile_units(model, drawn, tile_cells=2, unit_rocks=700)
    rocks = np.concatenate([u.rocks for u in units])
    assert sorted(rocks.tolist()) == list(range(3000))
    assert max(u.rocks.size for u in units) <= 700
    assert len({u.tile for u in units}) > 1  # releases span several 2-cell tiles


@pytest.mark.parametrize(("workers", "tile", "unit"), [(0, 2, 700), (2, 32, 1500)])
def test_tiled_run_is_the_single_run(model, workers, tile, unit):
    ref = simulate3d(model, 3000, np.random.default_rng(7))
    ref_grids = rasters(ref, model.terrain)
    ref_line = line_crossings(ref, LINE)
    with Engine(EngineSpec(workers=workers)) as engine:
        run = simulate3d_tiled(model, 3000, np.random.default_rng(7), engine,
                               lines=[LINE], paths=3, tile_cells=tile,
                               unit_rocks=unit)  # fmt: skip
    r = run.result
    np.testing.assert_array_equal(r.deposit_xyz, ref.deposit_xyz)
    np.testing.assert_array_equal(r.state, ref.state)
    np.testing.assert_array_equal(r.impacts_per_rock, ref.impacts_per_rock)
    np.testing.assert_array_equal(r.release_index, ref.release_index)
    for name, grid in ref_grids.items():
        np.testing.assert_array_equal(run.rasters[name], grid, err_msg=name)
    for key, values in ref_line.items():
        np.testing.assert_array_equal(run.crossings[0][key], values, err_msg=key)
    np.testing.assert_array_equal(r.path_offsets, ref.path_offsets[:4])
    np.testing.assert_array_equal(r.path["x_m"], ref.path["x_m"][: ref.path_offsets[3]])
    assert ref_line["rock"].size > 1000  # the line lies across the runout


def test_cli_workers_writes_the_same_files(cli, repo, tmp_path, monkeypatch):
    monkeypatch.chdir(repo)
    args = ["simulate", "examples/tschamut/model_3d.json", "--rocks", "1500",
            "--seed", "3", "--line", "0,180,120,180"]  # fmt: skip
    outs = {}
    for name, extra in (("here", []), ("dask", ["--workers", "2"])):
        d = tmp_path / name
        r = cli(*args, "--summary", d / "s.json", "--deposits", d / "d.csv",
                "--rasters", d / "r", *extra)  # fmt: skip
        assert r.exit_code == 0, r.stderr
        outs[name] = d
    assert "in tile(s)" not in outs and "tile(s) of 32 x 32 release cells" in r.stderr
    here, dask = outs["here"], outs["dask"]
    assert (here / "d.csv").read_bytes() == (dask / "d.csv").read_bytes()
    for tif in (here / "r").iterdir():
        assert tif.read_bytes() == (dask / "r" / tif.name).read_bytes(), tif.name
    a, b = (json.loads((d / "s.json").read_text()) for d in (here, dask))
    assert b.pop("engine")["workers"] == 2
    a.pop("wall_s"), b.pop("wall_s")
    assert a == b


def test_cli_refuses_impacts_in_tiles_and_profile_workers(
    cli, fails, repo, tmp_path, monkeypatch
):
    monkeypatch.chdir(repo)
    r = cli("simulate", "examples/tschamut/model_3d.json", "--rocks", "10",
            "--workers", "2", "--impacts", tmp_path / "i.csv")  # fmt: skip
    fails(r, "--impacts streams every impact from this process")
    r = cli("simulate", "examples/tschamut/model_base.json", "--rocks", "10",
            "--workers", "2")  # fmt: skip
    fails(r, "--workers", "describes a profile")
    assert not list(tmp_path.iterdir())
