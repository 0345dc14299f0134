"""Rockyfor3D export through the command line: files a Rockyfor3D run takes as
meant -- source cells inside its active area, rockdensity in its range, soil types
by the ground, obstacle heights from the calibrated e_t -- and the README's account.

References are hand computations and the target's documented rules, not the
exporter's output: e.g. the Tornado block 3750 kg in a sphere of r = 0.725 m is
3750 / (pi/6 * 1.45^3) = 3750 / 1.596256 = 2349.2 kg/m3; Rockyfor3D ignores source
cells in the two outer rows and columns (ecorisQ QGIS-RF3D).
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy.stats import norm

from fieldkit.export.rockyfor3d import obstacle_heights, rt_of_height, soil_type
from fieldkit.io.dem import DemGrid, read_dem
from fieldkit.model.effects import registry

REPO = Path(__file__).resolve().parents[2]
TABLE_7_1 = REPO / "surveys/tornado_mountain/model_rocfall_table_7_1.json"
PATH_START = REPO / "surveys/tornado_mountain/model_path_start.json"
TSCHAMUT = REPO / "examples/tschamut/model_base.json"
TERRAIN = REPO / "tests/data/tschamut2014/terrain.asc"
RELEASES = REPO / "tests/data/tschamut2014/release_points.csv"

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


def _export(cli, out, model, *args):
    r = cli("export", model, "--to", "rockyfor3d", "-o", out, *args)
    assert r.exit_code == 0, r.output
    grids = {name: read_dem(out / name) for name in GRIDS}
    readme = (out / "README.md").read_text(encoding="utf-8")
    return r, grids, readme


def _assert_sources_active(grids) -> np.ndarray:
    """Every source cell >= 2 cells inside the grid, and at least one."""
    source = grids["rockdensity.asc"].values > 0
    assert source.any()
    active = np.zeros(source.shape, bool)
    active[2:-2, 2:-2] = True
    assert not (source & ~active).any()
    return source


def _one_material(tmp_path, name="ground", e_n=0.4, mass=100.0, radius=0.5):
    path = tmp_path / "m.json"
    path.write_text(
        json.dumps(
            {
                "profile": {"x_m": [0, 40], "z_m": [30, 0], "material": name},
                "materials": {name: {"e_n": e_n, "e_t": 0.8, "friction_deg": 30}},
                "body": {"mass_kg": mass, "radius_m": radius},
                "seeder": {"x_m": 1, "z_m": 31},
            }
        )
    )
    return path


# -------------------------------------------------- item 1: sources are released


def test_extruded_sources_lie_inside_the_active_area(cli, tmp_path):
    # Before: the seeder column (chainage 2.5 m) was column 0 of a 5-row grid, so
    # all 5 source cells lay in the ignored edge band and Rockyfor3D released none.
    r, grids, readme = _export(cli, tmp_path / "o", TABLE_7_1, "--extrude",
                               "--cellsize", "5")  # fmt: skip
    source = _assert_sources_active(grids)
    # 5 rows + 2 + 2 padded; 140 columns + 2 padded on the west (the east is far)
    assert grids["dem.asc"].shape == (9, 142)
    assert np.argwhere(source).tolist() == [[row, 2] for row in range(2, 7)]
    # the padded cells continue the edge: column 0-1 at the first column's height
    dem = grids["dem.asc"].values
    np.testing.assert_allclose(dem[:, 0], dem[4, 2], atol=1e-3)
    assert grids["dem.asc"].x_m[2] == 2.5  # the original first column is unmoved
    assert "padded by 2 north, 2 south, 2 west" in readme
    assert "5 source cells" in readme
    for line in ("wrote " + str(tmp_path / "o" / name) for name in GRIDS):
        assert line in r.stdout.splitlines()


def test_dem_release_on_the_edge_is_padded_inside(cli, tmp_path):
    # (-34, 300): column 0, row 3 of Tschamut's DEM -- in the ignored band before.
    _, grids, readme = _export(cli, tmp_path / "o", TSCHAMUT, "--dem", TERRAIN,
                               "--release", "-34,300")  # fmt: skip
    source = _assert_sources_active(grids)
    assert np.argwhere(source).tolist() == [[3, 2]]
    assert grids["dem.asc"].shape == (46, 45)
    assert grids["dem.asc"].x_m[0] == -42.5
    assert "padded by 2 west" in readme


def test_a_release_that_cannot_be_padded_is_refused(cli, tmp_path, fails, monkeypatch):
    # With a cell limit of 100: 2 rows x 40 columns of 1 m fit (80); padded (2 rows
    # north and south; the seeder's column 1 needs 1 more on the west) to 6 x 41 =
    # 246 cells they do not -- refused in one line, nothing written.
    monkeypatch.setattr("fieldkit.export.site.MAX_DEM_CELLS", 100)
    model = _one_material(tmp_path)
    out = tmp_path / "o"
    r = cli("export", model, "--to", "rockyfor3d", "-o", out, "--extrude",
            "--cellsize", "1", "--rows", "2")  # fmt: skip
    fails(r, "Rockyfor3D ignores source cells", "outer rows", "6 x 41 cells")
    assert not out.exists()


def test_rockdensity_out_of_range_is_clamped_keeping_the_mass(cli, tmp_path):
    # 100 kg in a sphere of r = 0.5 m: 100 / 0.523599 = 191 kg/m3 < 2000. Clamped
    # to 2000 with d = (6 * 100 / (pi * 2000))^(1/3) = 0.095493^(1/3) = 0.45708 m.
    _, grids, readme = _export(cli, tmp_path / "o", _one_material(tmp_path),
                               "--extrude", "--cellsize", "2")  # fmt: skip
    source = _assert_sources_active(grids)
    density = grids["rockdensity.asc"].values
    assert set(np.unique(density[source])) == {2000}
    assert (density[~source] == 0).all()
    np.testing.assert_allclose(grids["d1.asc"].values[source], 0.457, atol=5e-4)
    assert "density of 191 kg/m³, outside Rockyfor3D's rockdensity range" in readme
    assert "clamped to 2000 kg/m³" in readme


def test_tornado_block_by_hand(cli, tmp_path):
    _, grids, _ = _export(cli, tmp_path / "o", TABLE_7_1, "--extrude",
                          "--cellsize", "10", "--rows", "3")  # fmt: skip
    source = _assert_sources_active(grids)
    volume = math.pi / 6 * 1.45**3
    assert volume == pytest.approx(1.596256, abs=1e-6)
    assert set(np.unique(grids["rockdensity.asc"].values[source])) == {2349}
    for name in ("d1.asc", "d2.asc", "d3.asc"):
        np.testing.assert_allclose(grids[name].values, source * 1.45)
    np.testing.assert_array_equal(grids["blshape.asc"].values, source * 3)


def test_grids_share_one_header(cli, tmp_path):
    out = tmp_path / "o"
    _, grids, readme = _export(cli, out, TABLE_7_1, "--extrude", "--cellsize", "10",
                               "--rows", "3")  # fmt: skip
    dem = grids["dem.asc"]
    for name, grid in grids.items():
        head = (out / name).read_text().splitlines()[:6]
        assert [line.split()[0] for line in head] == HEADER_KEYS, name
        assert grid.shape == dem.shape, name
        np.testing.assert_array_equal(grid.x_m, dem.x_m)
        np.testing.assert_array_equal(grid.y_m, dem.y_m)
    # Column centres 5, 15, 25 m on the profile (z 350 -> 316 -> 295 -> 280),
    # behind 2 padded columns.
    np.testing.assert_allclose(dem.values[:, 2], 350 - 34 * 5 / 8, atol=1e-3)
    np.testing.assert_allclose(dem.values[:, 4], 316 - 21 * 17 / 20, atol=1e-3)
    assert all(f"* `{name}`" in readme for name in GRIDS)


# ------------------------------- item 2: soil types follow the ground described


def test_soil_types_follow_the_ground_not_the_lumped_e_n(cli, tmp_path):
    # Before: nearest mean Rn put rock (e_n 0.75) and colluvium (e_n 1.0) both on
    # bedrock (6). Rock is bedrock (6), colluvium talus/compact soil with large
    # fragments (4), the railway bench ballast (3).
    _, grids, readme = _export(cli, tmp_path / "o", PATH_START, "--extrude",
                               "--cellsize", "10", "--rows", "3")  # fmt: skip
    soil = grids["soiltype.asc"].values
    x = grids["dem.asc"].x_m
    # rock up to x = 28 m, colluvium to 587.2 m, the bench after (segment ends)
    assert (soil[:, (x > 0) & (x < 28)] == 6).all()
    assert (soil[:, (x > 30) & (x < 580)] == 4).all()
    assert (soil[:, x > 590] == 3).all()
    assert "'colluvium' in the name" in readme
    assert "'bench' in the name" in readme


@pytest.mark.parametrize(
    ("name", "code"),
    [
        ("cliff", 6),
        ("bedrock", 6),
        ("weathered rock", 5),  # the longer keyword wins over "rock"
        ("talus", 4),
        ("upper_colluvium", 4),
        ("scree", 3),
        ("meadow", 2),
        ("deep soil", 1),
        ("swamp", 0),
        ("asphalt", 7),
    ],
)
def test_soil_type_by_description(name, code):
    assert soil_type(name, 1.0)[0].code == code  # whatever the lumped e_n


def test_soil_types_are_monotone_in_hardness():
    # soft -> hard descriptions never get a softer class (Rn range) than the one before
    order = ["swamp", "deep soil", "meadow", "scree", "talus", "weathered rock", "rock"]
    means = [soil_type(n, 0.5)[0].rn_mean for n in order]
    assert means == sorted(means)
    # without a description: by realised e_n, monotone too (class means 0.23 .. 0.53)
    codes = [soil_type("m1", e)[0].rn_mean for e in np.linspace(0.0, 1.2, 49)]
    assert codes == sorted(codes)
    assert soil_type("m1", 0.41)[0].code == 5  # nearest 0.43
    assert "no ground description" in soil_type("m1", 0.41)[1]


# ---------------------------------- item 3: rg70/rg20/rg10 from the calibrated e_t


def test_obstacle_heights_invert_the_calibrated_e_t(cli, tmp_path):
    # Before: rg = 0 on the colluvium (90 % of the path) and e_t discarded.
    _, grids, readme = _export(cli, tmp_path / "o", TABLE_7_1, "--extrude",
                               "--cellsize", "10", "--rows", "3")  # fmt: skip
    ground = np.isfinite(grids["dem.asc"].values)
    x = grids["dem.asc"].x_m
    colluvium = ground & (x > 30)[None, :]
    # realised e_t on the colluvium is the calibrated 0.62 (no law changes it) with
    # the impacts' spread ~ e_t_sd 0.04; Rt = 1 / (1 + h / R), R = 0.725 m. By hand:
    # rg70 at Rt = 0.62 + 0.04 z(0.65) = 0.6354: h = 0.725 (1/0.6354 - 1) = 0.416 m.
    for key, q in (("rg70", 0.65), ("rg20", 0.20), ("rg10", 0.05)):
        h = grids[f"{key}.asc"].values[colluvium]
        assert h.min() == h.max() > 0
        rt = rt_of_height(float(h[0]), 0.725)
        assert rt == pytest.approx(0.62 + 0.04 * norm.ppf(q), abs=0.006), key
    assert grids["rg70.asc"].values[colluvium][0] == pytest.approx(0.416, abs=0.01)
    # the obstacles grow from rg70 to rg10 and stay in Rockyfor3D's 0-100 m
    rg = [grids[f"{k}.asc"].values[ground] for k in ("rg70", "rg20", "rg10")]
    assert (rg[0] <= rg[1]).all() and (rg[1] <= rg[2]).all()
    assert (rg[2] <= 100).all()
    assert "Rt = 1 / (1 + MOH / R)" in readme
    assert obstacle_heights(1.0, 0.0, 0.5) == {"rg70": 0, "rg20": 0, "rg10": 0}


# ------------------------ item 4: lumped values with their own spread, no fallback


def test_realised_values_carry_the_impacts_spread(cli, tmp_path):
    _, _, readme = _export(cli, tmp_path / "o", PATH_START, "--extrude",
                           "--cellsize", "10", "--rows", "3")  # fmt: skip
    # velocity-scaled colluvium e_n 1.0: realised below 1, with its spread (the
    # impacts' own scatter, ~0.1), not a fit's standard error (~0.001)
    found = re.search(
        r"realised e_n (\d\.\d+), spread (\d\.\d+)\) \| soiltype.asc = 4", readme
    )
    assert found, readme
    e_n, spread = map(float, found.groups())
    assert 0.5 < e_n < 1.0 and 0.05 < spread < 0.3
    # the bench has no simulated impact: said, with what is written instead
    assert "no simulated impact on bench" in readme
    assert "without velocity_scaled_restitution" in readme


# ------------------------- items 5 and 7: translation error, effects, sources


def test_readme_gives_the_translation_error_and_every_effect(cli, tmp_path):
    _, _, readme = _export(cli, tmp_path / "o", PATH_START, "--extrude",
                           "--cellsize", "10", "--rows", "3")  # fmt: skip
    section = readme.split("## Translation error: calibrated model vs the target's "
                           "law")[1].split("\n## ")[0]  # fmt: skip
    rows = [line for line in section.splitlines() if line.startswith("| runout p")]
    assert len(rows) == 2
    assert "| p95 total energy at" in section and "| p95 bounce height at" in section
    assert "fieldkit's emulation of Rockyfor3D's law" in section
    for spec in registry.EFFECTS:
        assert f"effect {spec.name} (" in readme, spec.name
    sources = readme.split("## Sources of the target's rules")[1].split("\n## ")[0]
    assert (
        "ecorisQ/QGIS-RF3D" in sources and "rockyfor3d_inputs_algorithm.py" in sources
    )
    unconfirmed = readme.split("## Unconfirmed")[1].split("\n## ")[0]
    assert "Rt = 1 / (1 + MOH / R)" in unconfirmed


# ------------------------------------------ item 6: many release cells on a DEM


def test_tschamut_release_points_give_their_cells(cli, tmp_path):
    _, grids, readme = _export(cli, tmp_path / "o", TSCHAMUT, "--dem", TERRAIN,
                               "--releases", RELEASES)  # fmt: skip
    source = _assert_sources_active(grids)
    # 80 release points in 14 cells: cell (row, col) = (floor((315 - y) / 5),
    # floor((x + 35) / 5)) on the 5 m grid whose upper-left corner is (-35, 315);
    # all far from the edge, so the grid is not padded.
    assert grids["dem.asc"].shape == (46, 43)
    cells = {(int((315 - y) // 5), int((x + 35) // 5)) for x, y in _points()}
    assert len(cells) == 14
    assert {tuple(c) for c in np.argwhere(source).tolist()} == cells
    assert set(np.unique(grids["rockdensity.asc"].values[source])) == {2987}
    assert "14 release cells from" in readme and "(80 points)" in readme


def _points():
    lines = RELEASES.read_text().splitlines()
    head = lines[0].split(",")
    ix, iy = head.index("x_m"), head.index("y_m")
    return [(float(r.split(",")[ix]), float(r.split(",")[iy])) for r in lines[1:]]


def test_a_release_polygon_gives_the_cells_whose_centre_is_inside(cli, tmp_path):
    # a rectangle from (10, 230) to (31, 246): centres x 12.5, 17.5, 22.5, 27.5 and
    # y 232.5, 237.5, 242.5 -> rows (315 - y) // 5 = 14, 15, 16; cols 9-12: 12 cells
    polygon = tmp_path / "area.csv"
    polygon.write_text("x_m;y_m;polygon\n10;230;A\n31;230;A\n31;246;A\n10;246;A\n")
    _, grids, readme = _export(cli, tmp_path / "o", TSCHAMUT, "--dem", TERRAIN,
                               "--releases", polygon)  # fmt: skip
    source = _assert_sources_active(grids)
    expected = {(r, c) for r in (14, 15, 16) for c in (9, 10, 11, 12)}
    assert {tuple(c) for c in np.argwhere(source).tolist()} == expected
    assert "12 release cells" in readme and "polygon A (4 vertices)" in readme


def test_releases_off_the_dem_are_named_by_row(cli, tmp_path, fails, digest):
    bad = tmp_path / "releases.csv"
    bad.write_text("id,x_m,y_m\na,33.4,236.67\nb,-500,3\nc,30,250\nd,30,999\n")
    before = digest(bad)
    out = tmp_path / "o"
    r = cli("export", TSCHAMUT, "--to", "rockyfor3d", "-o", out, "--dem", TERRAIN,
            "--releases", bad)  # fmt: skip
    fails(r, "releases.csv", "2 releases with no cell on ground",
          "row 3: (-500, 3) outside", "row 5: (30, 999) outside")  # fmt: skip
    assert r.exit_code == 1
    assert not out.exists() and digest(bad) == before


def test_a_polygon_on_nodata_is_named(cli, tmp_path, fails):
    values = np.full((8, 8), 50.0) - np.arange(8)[None, :]
    values[3, 4] = np.nan
    dem = tmp_path / "dem.asc"
    rows = "\n".join(" ".join("-9999" if np.isnan(v) else f"{v:g}" for v in row)
                     for row in values)  # fmt: skip
    dem.write_text("ncols 8\nnrows 8\nxllcorner 0\nyllcorner 0\ncellsize 10\n"
                   f"NODATA_value -9999\n{rows}\n")  # fmt: skip
    polygon = tmp_path / "area.csv"
    polygon.write_text("x_m,y_m,polygon\n30,30,P\n60,30,P\n60,60,P\n30,60,P\n")
    out = tmp_path / "o"
    r = cli("export", _one_material(tmp_path), "--to", "rockyfor3d", "-o", out,
            "--dem", dem, "--releases", polygon)  # fmt: skip
    fails(r, "area.csv", "rows 2-5", "polygon P covers 1 nodata cells", "(4, 5)")
    assert not out.exists()


def test_release_and_releases_together_are_refused(cli, tmp_path, fails):
    r = cli("export", TSCHAMUT, "--to", "rockyfor3d", "-o", tmp_path / "o", "--dem",
            TERRAIN, "--release", "33.4,236.67", "--releases", RELEASES)  # fmt: skip
    fails(r, "--releases", "not both")
    r = cli("export", TSCHAMUT, "--to", "rockyfor3d", "-o", tmp_path / "o",
            "--extrude", "--releases", RELEASES)  # fmt: skip
    fails(r, "--releases", "goes with a DEM")


def test_cells_without_ground_are_nodata(cli, tmp_path):
    values = np.array([[30.0, 25.0, 20.0], [29.0, np.nan, 19.0], [28.0, 23.0, 18.0]])
    grid = DemGrid.from_corner(values, x_left_m=0, y_top_m=30, cellsize_m=10)
    dem = tmp_path / "dem.asc"
    dem.write_text(
        "ncols 3\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 10\nNODATA_value -9999\n"
        "30 25 20\n29 -9999 19\n28 23 18\n"
    )
    _, grids, _ = _export(cli, tmp_path / "o", _one_material(tmp_path, "talus"),
                          "--dem", dem, "--release", "5,25")  # fmt: skip
    _assert_sources_active(grids)
    assert grid.shape == (3, 3)
    for name, g in grids.items():
        assert g.shape == (5, 5), name  # padded by 2 north and 2 west
        assert np.isnan(g.values[3, 3]), name
        assert np.isfinite(np.delete(g.values.ravel(), 18)).all(), name
    assert grids["rockdensity.asc"].values[2, 2] > 0  # the release cell
    assert (grids["soiltype.asc"].values[np.isfinite(grids["dem.asc"].values)]
            == 4).all()  # fmt: skip


def test_design_values_the_emulation_never_reaches_are_named(cli, tmp_path):
    # Table 7-1 (e_n 1.0 on colluvium, no velocity scaling): the calibrated rocks run
    # past 600 m; under Rockyfor3D's law (colluvium Rn 0.38) none reaches the
    # analysis point, so its energy row has no emulated value -- said, not dropped.
    _, _, readme = _export(cli, tmp_path / "o", TABLE_7_1, "--extrude",
                           "--cellsize", "10", "--rows", "3")  # fmt: skip
    section = readme.split("## Translation error")[1].split("\n## ")[0]
    assert "| no rock crossed |" in section
    assert "**not given by one of the two**" in section
    assert "p95 total energy at" in section.split("not given by one of the two")[1]


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("x,y\n33.4,236.67\n", ["row 1", "column 'x' has no length unit", "x_m"]),
        ("a_m,b_m\n1,2\n", ["row 1", "columns x, y", "have: a_m, b_m"]),
        ("x_m,y_m,polygon\n0,250,A\n500,250,A\n0,260,A\n",
         ["row 3: polygon A: vertex outside the grid (x -35..180 m"]),
        ("x_m,y_m,polygon\n0,250,A\n0.5,250,A\n0,250.5,A\n",
         ["rows 2-4", "polygon A holds no cell centre"]),
        ("x_m,y_m,polygon\n0,250,A\n0.5,250,A\n",
         ["rows 2-3", "2 distinct vertices", "at least 3"]),
    ],
)  # fmt: skip
def test_bad_release_files_refused_in_one_line(cli, tmp_path, fails, text, words):
    bad = tmp_path / "releases.csv"
    bad.write_text(text)
    out = tmp_path / "o"
    r = cli("export", TSCHAMUT, "--to", "ramms", "-o", out, "--dem", TERRAIN,
            "--releases", bad)  # fmt: skip
    fails(r, "releases.csv", *words)
    assert r.exit_code == 1 and not out.exists()


def test_obstacle_heights_beyond_rockyfor3d_range_are_capped_and_said(cli, tmp_path):
    # e_t = 0.002 (r = 0.5 m): h = 0.5 (1/0.002 - 1) = 249.5 m > Rockyfor3D's 100 m
    data = json.loads(_one_material(tmp_path).read_text())
    data["materials"]["ground"]["e_t"] = 0.002
    model = tmp_path / "low_et.json"
    model.write_text(json.dumps(data))
    _, grids, readme = _export(cli, tmp_path / "o", model, "--extrude",
                               "--cellsize", "2")  # fmt: skip
    ground = np.isfinite(grids["dem.asc"].values)
    assert (grids["rg10.asc"].values[ground] == 100).all()
    assert "heights above Rockyfor3D's 100 m written as 100 m" in readme


def test_the_seeder_fall_to_the_source_cells_is_stated(cli, tmp_path):
    # The extruded source cells lie at the section's elevation at their centre
    # (chainage 2.5 m), 10.6 m below the ground under the seeder (chainage 0 m):
    # the fall Rockyfor3D needs is seeder z - z(2.5 m), by hand from the model file.
    data = json.loads(PATH_START.read_text())
    profile, seeder = data["profile"], data["seeder"]
    fall = seeder["z_m"] - np.interp(2.5, profile["x_m"], profile["z_m"])
    assert fall == pytest.approx(0.725 + 34 / 8 * 2.5, abs=1e-6)  # 11.35 m
    r, _, readme = _export(cli, tmp_path / "o", PATH_START, "--extrude",
                           "--cellsize", "5")  # fmt: skip
    assert f"additional initial fall height (§2.5) to {fall:.3g} m" in readme
    assert "additional initial fall height" in r.stdout


def test_help_documents_the_release_file_and_its_example_runs(
    cli, repo_copy, shell_commands, run_shell
):
    r = cli("export", "--help")
    text = " ".join(r.output.replace("│", " ").split())
    assert "--releases" in text and "polygon" in text and "(x_m, y_m)" in text
    lines = [c for c in shell_commands(r.output) if "--releases" in c]
    assert len(lines) == 1
    code, output = run_shell(lines[0], repo_copy)
    assert code == 0, output
    source = read_dem(repo_copy / "out/r3d/rockdensity.asc").values > 0
    assert source.sum() == 14 and not source[:2].any() and not source[:, :2].any()
