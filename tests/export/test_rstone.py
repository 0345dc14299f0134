"""r.stone export: rasters re-read, percent rounding by hand, tan(phi), the DEM shift,
whole-metre cells, release cells off the edge, the start speed, the record and
script written beside the rasters, and `import-results --from rstone` on grids
written by hand.

References: the r.stone source (stone.h: the cell is a C short; points.c, stone.c:
nrest/trest whole percent 0-100, friction tan(beta) in thousandths, elevations
> 0 m, no stone starts on the edge row) and hand arithmetic, e.g. tan(19.29 deg) =
0.34999 -> 0.35; 1000 trajectories over 3 release cells -> 333 a cell.
"""

from __future__ import annotations

import json
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
OTHER = ("run_rstone.sh", "fieldkit_export.json")
HEADER_KEYS = ["ncols", "nrows", "xllcorner", "yllcorner", "cellsize", "NODATA_value"]
TORNADO = "surveys/tornado_mountain/model_rocfall_table_7_1.json"


def _rasters(export):
    """The export with its rasters only (the grids ``written_grids`` reads back)."""
    from dataclasses import replace

    return replace(export, files={n: export.files[n] for n in RASTERS})


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
    assert sorted(export.files) == sorted(RASTERS + OTHER)
    grids = written_grids(_rasters(export), tmp_path)
    for name in RASTERS:
        keys = [line.split()[0] for line in export.files[name].splitlines()[:6]]
        assert keys == HEADER_KEYS, name
    dem = grids["dem.asc"]
    # Release cells in column 0 of all 3 rows: padded by one cell north, south and
    # west (r.stone never starts a stone on the grid's edge), 3 x 70 -> 5 x 71.
    assert dem.shape == (5, 71)
    for name, g in grids.items():
        assert g.shape == dem.shape, name
        np.testing.assert_array_equal(g.x_m, dem.x_m)
        np.testing.assert_array_equal(g.y_m, dem.y_m)
    assert dem.x_m[0] == -5.0 and dem.y_m[0] == 20.0
    # The section ends flat at z = -4 m: raised by ceil(1 - (-4)) = 5 m.
    padded = np.pad(site.grid.values, ((1, 1), (1, 0)), mode="edge")
    np.testing.assert_allclose(dem.values, padded + 5, atol=5e-4)
    assert dem.values.min() == pytest.approx(1.0)
    rock = np.zeros((5, 71), bool)
    rock[:, :4] = True  # the padded column and centres 5, 15, 25 m: x < 28 m is rock
    # One in-range pair per material (fitted to the calibrated model's own
    # impacts, roughness folded in, then searched for behaviour), as the README
    # states it.
    readme = export.readme("model.json")
    for raster in ("nrest", "trest"):
        values = grids[f"{raster}.asc"].values
        for part in (rock, ~rock):
            (value,) = np.unique(values[part])
            assert 1 <= value <= 100 and f"{raster}.asc = {value:.0f} %" in readme
    # tan(2.86 deg) = 0.04996 -> 0.05; tan(19.29 deg) = 0.34999 -> 0.35.
    np.testing.assert_array_equal(
        grids["friction.asc"].values, np.where(rock, 0.05, 0.35)
    )
    source = np.zeros((5, 71), bool)
    source[1:4, 1] = True
    np.testing.assert_array_equal(grids["sources.asc"].values, source * 333)
    for name in ("sources.asc", "nrest.asc", "trest.asc"):
        values = grids[name].values
        assert (values == np.round(values)).all(), name
    assert ((grids["nrest.asc"].values >= 0) & (grids["nrest.asc"].values <= 100)).all()


def test_tornado_options_and_readme(tornado):
    export = export_rstone(tornado, site_from_section(tornado, cellsize_m=10))
    how = export.how_to_use
    script = export.files["run_rstone.sh"]
    for name in RASTERS:
        assert name.removesuffix(".asc") in script
    assert "grass -c XY" in how and "--exec bash run_rstone.sh" in how
    # e_n_sd = e_t_sd = 0.04 -> 50 x 0.04 = 2; colluvium friction SD 2 deg at 19.29
    # deg: 0.0349066 / cos^2 = 0.039183 in tan -> 1.96 -> 2 (rock: 1.31 -> 1).
    assert "vrest_stoch_range=2" in how and "hrest_stoch_range=2" in how
    assert "frict_stoch_range=2" in how
    # The release cells (column 0, centre x = 5 m) lie at z = 350 - 34 x 5 / 8 =
    # 328.75 m, 21.975 m below the seeder (350.725 m): start_vel = sqrt(3.007^2 +
    # 2 x 9.81 x 21.975) = sqrt(9.042 + 431.150) = 20.981 m/s.
    assert "start_vel=20.981 stop_vel=0.05" in how
    assert "start_vel=20.981 stop_vel=0.05" in script
    mismatches = "\n".join(export.mismatches)
    assert "frict_stoch_range: the materials need 1, 2" in mismatches
    assert "raised by 5 m" in mismatches
    assert "1.059 x fieldkit's" in mismatches  # 1 / cos(19.29 deg) = 1.0595
    # the written percent and its rounding, per material; a draw SD that would
    # reach past 100 % is said (r.stone clips draws to [0, 1])
    (line,) = [x for x in export.mismatches if x.startswith("colluvium: e_n = ")]
    nrest = int(line.split("-> nrest ")[1].split(" %")[0])
    clipped = "colluvium: nrest 100 % with a draw SD of 0.04" in mismatches
    assert clipped == (nrest / 100 + 2 * 0.04 > 1)
    unmapped = dict(export.unmapped)
    assert any(k.startswith("slope roughness (rock") for k in unmapped)
    readme = export.readme("model.json")
    assert all(f"* `{name}`" in readme for name in RASTERS + OTHER)
    assert "## Translation error" in readme and "## Unconfirmed" in readme
    assert "bounce is shorter than 3 m and slower than 5 m/s" in readme


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
        _rasters(export_rstone(model, site_from_section(model, cellsize_m=5))), tmp_path
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


def test_friction_above_45_deg_is_refused():
    model = _one_material(friction_deg=50)
    with pytest.raises(ArgumentError, match="materials.ground.friction_deg = 50"):
        export_rstone(model, site_from_section(model, cellsize_m=5))


@pytest.mark.parametrize(("key", "raster"), [("e_n", "nrest"), ("e_t", "trest")])
def test_restitution_above_1_is_written_in_range_and_stated(
    key, raster, tmp_path, written_grids
):
    # Formerly refused; issue 19: write the in-range pair closest under r.stone's
    # law (least squares over the model's own impacts, clipped to [0, 1]).
    model = _one_material(**{key: 1.2})
    export = export_rstone(model, site_from_section(model, cellsize_m=5))
    grids = written_grids(_rasters(export), tmp_path)
    values = grids[f"{raster}.asc"].values
    assert np.nanmax(values) <= 100
    # one in-range value everywhere: the clipped least squares, or the
    # behaviour search's from there when it also behaves closer on the
    # independent stream (the README says which)
    written = np.unique(values[np.isfinite(values)])
    assert written.size == 1
    assert f"{raster}.asc = {written[0]:.0f} %" in export.readme("m.json")
    text = "\n".join(export.mismatches)
    assert "outside its range and was clipped to 1" in text
    assert "r.stone's law is a constant pair" in text


def test_rocks_shared_over_release_cells(tmp_path, written_grids):
    model = _one_material()
    site = site_from_section(model, cellsize_m=5, rows=3)
    export = export_rstone(model, site, rocks=10)
    sources = written_grids(_rasters(export), tmp_path)["sources.asc"].values
    assert sources.sum() == 9 and sources.max() == 3  # round(10 / 3) = 3 a cell
    assert any("trajectories traced: 9 = 3 source cells x 3" in n for n in export.notes)
    with pytest.raises(ArgumentError, match="rocks must be a whole number >= 1"):
        export_rstone(model, site, rocks=0)


def test_fractional_cells_are_resampled_to_whole_metres(tornado, tmp_path):
    # The library's default extrusion of Tornado is 1.5 m cells (700 / 500 -> 1.5):
    # r.stone would run them as 1 m; resampled to 2 m, stated.
    export = export_rstone(tornado, site_from_section(tornado))
    header = export.files["dem.asc"].splitlines()[:6]
    assert header[4].split() == ["cellsize", "2"]
    assert any(
        "cells of 1.5 m resampled (bilinear) to 2 m" in m for m in export.mismatches
    )
    assert any("smaller than r.stone's 5 m" in n for n in export.notes)


def test_tschamut_dem_site(repo, tmp_path, written_grids):
    model = read_model(repo / "examples/tschamut/model_base.json")
    terrain = read_dem(repo / "tests/data/tschamut2014/terrain.asc")
    export = export_rstone(model, site_from_dem(model, terrain, (33.4, 236.67)))
    grids = written_grids(_rasters(export), tmp_path)
    for g in grids.values():
        assert g.shape == (46, 43)
        np.testing.assert_allclose(g.x_m, terrain.x_m)
        np.testing.assert_allclose(g.y_m, terrain.y_m)
    # Lowest elevation -7.138465 m: raised by 9 m.
    np.testing.assert_allclose(grids["dem.asc"].values, terrain.values + 9, atol=5e-4)
    source = np.zeros((46, 43), bool)
    source[15, 13] = True  # the cell centred (32.5, 237.5)
    np.testing.assert_array_equal(grids["sources.asc"].values, source * 1000)
    # meadow e_n 1.00 with 8 deg roughness, not r.stone's constant pair: one
    # in-range pair everywhere (impact-level 100 / 62, or the behaviour search's
    # when it also behaves closer on the independent stream), as the README says.
    readme = export.readme("model_base.json")
    for raster in ("nrest", "trest"):
        values = np.unique(grids[f"{raster}.asc"].values)
        assert values.size == 1 and 1 <= values[0] <= 100
        assert f"{raster}.asc = {values[0]:.0f} %" in readme
    assert "Behaviour search over materials.meadow.e_n" in readme
    assert (grids["friction.asc"].values == 0.35).all()
    # The seeder rests 0.176667 m above its ground: sqrt(2 x 9.81 x 0.176667) =
    # 1.862 m/s.
    assert "start_vel=1.862 stop_vel=0.05" in export.how_to_use


# ------------------------------------------------------------- through the CLI


def test_cli_extrude_default_strip(cli, repo, tmp_path):
    out = tmp_path / "rstone"
    r = cli("export", repo / TORNADO, "--to", "rstone", "--extrude", "-o", out)
    assert r.exit_code == 0, r.stderr
    wrote = [line for line in r.stdout.splitlines() if line.startswith("wrote ")]
    assert len(wrote) == 8  # 5 rasters, the script, the record, README.md
    dem = read_dem(out / "dem.asc")
    # 5 m cells (r.stone's step, a whole number); 700 m / 5 = 140 columns and one
    # padded west of the release column; 61 rows, the release in the middle one.
    assert dem.cellsize_m == 5.0 and dem.shape == (61, 141)
    sources = read_dem(out / "sources.asc").values
    assert np.argwhere(sources > 0).tolist() == [[30, 1]]
    assert sources[30, 1] == 1000
    record = json.loads((out / "fieldkit_export.json").read_text())
    assert record["trajectories"] == 1000 and record["extruded"] is True
    assert record["chainage_m"][:2] == [-2.5, 2.5] and len(record["chainage_m"]) == 141
    # Release cell centre x = 2.5 m: z = 350 - 34 x 2.5 / 8 = 339.375 m, 11.35 m
    # below the seeder: sqrt(3.007^2 + 2 x 9.81 x 11.35) = 15.223 m/s.
    assert record["start_vel_mps"] == pytest.approx(15.223)
    script = (out / "run_rstone.sh").read_text()
    assert "start_vel=15.223" in script and "r.out.gdal" in script
    readme = (out / "README.md").read_text()
    assert "r.stone traces 1000 trajectories" in readme
    assert "trajectories traced: 1000 = 1 source cell x 1000" in readme
    from fieldkit.model.effects.registry import EFFECTS

    for spec in EFFECTS:
        assert f"effect {spec.name} (" in readme, spec.name


def test_cli_refuses_a_fractional_cellsize(cli, repo, tmp_path, fails):
    out = tmp_path / "rstone"
    r = cli("export", repo / TORNADO, "--to", "rstone", "--extrude",
            "--cellsize", "2.5", "-o", out)  # fmt: skip
    fails(r, "--cellsize", "whole number", "2 m")
    assert r.exit_code == 1
    assert not out.exists()


def _write_asc(path, values, cell, x_left=0.0, y_bottom=0.0, nodata=-9999):
    rows = "\n".join(" ".join(f"{v:g}" for v in row) for row in values)
    path.write_text(
        f"ncols {values.shape[1]}\nnrows {values.shape[0]}\nxllcorner {x_left:g}\n"
        f"yllcorner {y_bottom:g}\ncellsize {cell:g}\nNODATA_value {nodata}\n{rows}\n"
    )


def test_cli_dem_fractional_cell_resampled_and_edge_release_padded(
    cli, tmp_path, digest
):
    from fieldkit.model.model_file import write_model

    model_file = tmp_path / "model.json"
    write_model(_one_material(), model_file)
    # 12 x 8 cells of 2.5 m, a plane falling 1 m per metre eastwards.
    x = 1.25 + 2.5 * np.arange(12)
    dem = tmp_path / "dem.asc"
    _write_asc(dem, np.tile(100.0 - x, (8, 1)), 2.5)
    before = digest(dem)
    out = tmp_path / "rstone"
    # The release (1.25, 18.75) is the north-west corner cell.
    r = cli("export", model_file, "--to", "rstone", "--dem", dem,
            "--release", "1.25,18.75", "-o", out)  # fmt: skip
    assert r.exit_code == 0, r.stderr
    assert digest(dem) == before
    written = read_dem(out / "dem.asc")
    # 30 m x 20 m at 3 m cells: 10 x 6 cells, padded by one cell north and west.
    assert written.cellsize_m == 3.0 and written.shape == (7, 11)
    sources = read_dem(out / "sources.asc").values
    assert np.argwhere(sources > 0).tolist() == [[1, 1]]
    # Bilinear on a plane is exact: the cell centred x = 1.5 m lies at 98.5 m (no
    # shift: every elevation > 0); the padded column continues it.
    np.testing.assert_allclose(written.values[1, :3], [98.5, 98.5, 95.5], atol=1e-3)
    readme = (out / "README.md").read_text()
    assert "cells of 2.5 m resampled (bilinear) to 3 m" in readme
    assert "padded by 1 north, 1 west" in readme


def _export_small(cli, tmp_path):
    from fieldkit.model.model_file import write_model

    model_file = tmp_path / "model.json"
    write_model(_one_material(), model_file)
    out = tmp_path / "rstone"
    r = cli("export", model_file, "--to", "rstone", "--extrude", "--cellsize", "5",
            "--rows", "3", "-o", out)  # fmt: skip
    assert r.exit_code == 0, r.stderr
    return out


def _write_results(out, counter, speed, height):
    nodata = -1
    for name, values in (("counter", counter), ("maxvel", speed), ("maxdz", height)):
        _write_asc(out / f"{name}.asc", np.where(np.isnan(values), nodata, values),
                   5.0, x_left=-5.0, y_bottom=-7.5, nodata=nodata)  # fmt: skip


def test_cli_import_results_by_hand(cli, tmp_path):
    out = _export_small(cli, tmp_path)
    record = json.loads((out / "fieldkit_export.json").read_text())
    # 40 m / 5 m = 8 columns and one padded west; 3 rows; release row 1, col 1.
    assert record["grid"]["ncols"] == 9 and record["grid"]["nrows"] == 3
    assert [(s["row"], s["col"]) for s in record["sources"]] == [(1, 1)]
    counter = np.full((3, 9), np.nan)
    counter[1, 1:] = [1000, 1000, 900, 800, 600, 600, 300, 50]
    counter[0, 4] = 7  # a few trajectories drift into the north row
    speed = np.full((3, 9), np.nan)
    speed[1, 1:] = [5, 8, 10, 12, 13, 14, 9, 4]
    height = np.full((3, 9), np.nan)
    height[1, 1:] = [0, 2, 3, 1, 1, 0, 0, 0]
    _write_results(out, counter, speed, height)
    res = tmp_path / "results"
    r = cli("import-results", out, "--from", "rstone", "-o", res)
    assert r.exit_code == 0, r.stderr
    assert r.stdout.count("wrote ") == 3
    assert (res / "along.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    summary = json.loads((res / "summary.json").read_text())
    assert summary["trajectories_stated"] == summary["trajectories_traced"] == 1000
    # Survival (column chainages 2.5, 7.5, ...): 1, 1, .9, .8(.807 with the north
    # row's 7 in column 4), .6, .6, .3, .05. p50: farthest with >= 0.5: 27.5 m;
    # p90: >= 0.1: 32.5 m; p95: >= 0.05: 37.5 m.
    assert summary["runout_m"]["p50"] == 27.5
    assert summary["runout_m"]["p90"] == 32.5
    assert summary["runout_m"]["p95"] == 37.5
    assert summary["left_the_grid"] == {"north": 7, "south": 0}
    assert "north 7" in r.stderr
    # 14 m/s, 100 kg: 0.5 x 100 x 196 = 9.8 kJ.
    assert summary["max_energy_kj"] == pytest.approx(9.8)
    assert summary["max_height_m"] == 3.0
    import pandas as pd

    table = pd.read_csv(res / "along.csv")
    assert table["distance_m"].tolist()[:3] == [-2.5, 2.5, 7.5]
    assert table["trajectories"].tolist()[4] == 807


def test_cli_import_results_a_stone_not_started_is_reported(cli, tmp_path):
    out = _export_small(cli, tmp_path)
    counter = np.full((3, 9), np.nan)
    counter[1, 1:3] = [700, 700]
    _write_results(out, counter, np.where(np.isnan(counter), np.nan, 5.0), counter * 0)
    r = cli("import-results", out, "--from", "rstone", "-o", tmp_path / "res")
    assert r.exit_code == 0, r.stderr
    assert "r.stone traced 700 of the 1000 trajectories" in r.stderr


@pytest.mark.parametrize(
    ("damage", "words"),
    [
        ("no_counter", ["counter.asc", "missing"]),
        ("bad_record", ["fieldkit_export.json", "not JSON"]),
        ("other_grid", ["maxvel.asc", "not r.stone's result on these files"]),
        ("no_folder", ["FOLDER", "is not a folder"]),
    ],
)
def test_cli_import_results_bad_input(cli, tmp_path, fails, damage, words):
    out = _export_small(cli, tmp_path)
    counter = np.full((3, 9), np.nan)
    counter[1, 1] = 1000
    _write_results(out, counter, counter * 0 + 1, counter * 0)
    folder = out
    if damage == "no_counter":
        (out / "counter.asc").unlink()
    elif damage == "bad_record":
        (out / "fieldkit_export.json").write_text("{not json")
    elif damage == "other_grid":
        _write_asc(out / "maxvel.asc", np.zeros((3, 8)), 5.0, x_left=-5.0,
                   y_bottom=-7.5)  # fmt: skip
    else:
        folder = tmp_path / "nowhere"
    res = tmp_path / "res"
    r = cli("import-results", folder, "--from", "rstone", "-o", res)
    fails(r, *words)
    assert r.exit_code in (1, 2)
    assert not res.exists()


def test_cli_a_material_without_impacts_is_stated_not_silent(cli, tmp_path):
    from fieldkit.model.model_file import write_model

    model = model_from_dict(
        {
            "profile": {
                "x_m": [0, 40, 200, 210],
                "z_m": [30, 0, 0, 0],
                "material": ["rock", "meadow", "far"],
            },
            "materials": {
                "rock": {"e_n": 0.3, "e_t": 0.6, "friction_deg": 30},
                "meadow": {"e_n": 0.2, "e_t": 0.5, "friction_deg": 40},
                # rough, so not r.stone's constant pair: the pair would be fitted
                "far": {"e_n": 0.5, "e_t": 0.8, "friction_deg": 30,
                        "roughness_deg_sd": 5},
            },
            "body": {"mass_kg": 100, "radius_m": 0.5},
            "seeder": {"x_m": 1, "z_m": 31},
        }
    )  # fmt: skip
    model_file = tmp_path / "model.json"
    write_model(model, model_file)
    out = tmp_path / "rstone"
    r = cli("export", model_file, "--to", "rstone", "--extrude", "--rows", "3",
            "-o", out)  # fmt: skip
    assert r.exit_code == 0, r.stderr
    readme = (out / "README.md").read_text()
    unconfirmed = readme.split("## Unconfirmed")[1]
    assert "far: NO SIMULATED IMPACT on it" in " ".join(unconfirmed.split())
    nrest = read_dem(out / "nrest.asc").values
    # the far cells: fitted to its own calibrated (constant) e_n 0.5 at the
    # speeds of the other materials' impacts -- 0.5, as stated, never raw 1.0
    assert 50 in nrest[1]


def test_doctests():
    import doctest

    import fieldkit.export.rstone as export_module
    import fieldkit.export.rstone3d as export3d_module
    import fieldkit.fit.footprint as footprint_module
    import fieldkit.io.rstone_results as results_module

    for module in (export_module, results_module, export3d_module, footprint_module):
        result = doctest.testmod(module)
        assert result.attempted > 0 and result.failed == 0, module.__name__
