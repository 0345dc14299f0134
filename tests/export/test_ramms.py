"""RAMMS export: the DEM read back, category choice at and between boundaries."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np
import pytest

from fieldkit.errors import ArgumentError
from fieldkit.export.ramms import category_at, export_ramms, recommend
from fieldkit.export.site import site_from_dem, site_from_section
from fieldkit.io.dem import DemGrid, read_dem
from fieldkit.model.effects import registry
from fieldkit.model.model_file import model_from_dict

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def tornado_export(tornado):
    site = site_from_section(tornado, cellsize_m=10, rows=3)
    return site, export_ramms(tornado, site)


def one_material(name: str) -> dict:
    return {
        "profile": {"x_m": [0, 20], "z_m": [10, 0], "material": name},
        "materials": {name: {"e_n": 0.3, "e_t": 0.8, "friction_deg": 30}},
        "body": {"mass_kg": 100, "radius_m": 0.2},
        "seeder": {"x_m": 1, "z_m": 11},
    }


def test_a_grid_target_without_a_site_is_refused(tornado):
    with pytest.raises(ArgumentError) as error:
        export_ramms(tornado, None)
    assert (
        str(error.value)
        == "site: ramms needs a grid site: a DEM or the section extruded"
    )


def test_dem_reads_back_with_its_header_and_values(tornado_export, tmp_path):
    site, export = tornado_export
    path = tmp_path / "dem.asc"
    path.write_text(export.files["dem.asc"])
    header = dict(line.split() for line in export.files["dem.asc"].splitlines()[:6])
    # 700 m of profile in 10 m cells: 70 columns; 3 rows centred on y = 0, so the
    # lower-left corner is at y = -15 m.
    assert header == {
        "ncols": "70",
        "nrows": "3",
        "xllcorner": "0",
        "yllcorner": "-15",
        "cellsize": "10",
        "NODATA_value": "-9999",
    }
    grid = read_dem(path)
    assert grid.shape == (3, 70)
    assert grid.x_m[0] == 5.0 and grid.y_m.tolist() == [10.0, 0.0, -10.0]
    # Column 0 centre x = 5 m on segment A (0, 350) - B (8, 316):
    # 350 - 34 * 5 / 8 = 328.75 m; column 69 (x = 695 m) on the run-on at -4 m.
    assert grid.values[:, 0].tolist() == [328.75] * 3
    assert grid.values[:, 69].tolist() == [-4.0] * 3
    np.testing.assert_allclose(grid.values, site.grid.values, atol=5e-4)


def test_category_grid_codes_by_material(tornado_export, tmp_path):
    _, export = tornado_export
    path = tmp_path / "terrain_category.asc"
    path.write_text(export.files["terrain_category.asc"])
    codes = read_dem(path).values
    # Rock: segments A-B-C (x < 28 m): columns at 5, 15, 25 m -> Extra Hard = 7.
    # Colluvium everywhere else -> Medium = 4.
    assert (codes[:, :3] == 7).all()
    assert (codes[:, 3:] == 4).all()


def test_categories_csv_for_tornado(tornado_export):
    _, export = tornado_export
    table = {
        r["material"]: r
        for r in csv.DictReader(io.StringIO(export.files["terrain_categories.csv"]))
    }
    rock, colluvium = table["rock"], table["colluvium"]
    assert (rock["category"], rock["neighbour"], rock["code"]) == (
        "Extra Hard",
        "",
        "7",
    )
    assert rock["cells"] == "9"
    # Published values for the hardest category (secondary source, module docstring).
    assert [rock[p] for p in ("mu_min", "mu_max", "beta", "kappa", "epsilon")] == [
        "0.8",
        "2",
        "200",
        "4",
        "0",
    ]
    # Colluvium sits half-way: the harder (Medium) first, Medium Soft beside it.
    assert (colluvium["category"], colluvium["neighbour"]) == ("Medium", "Medium Soft")
    assert colluvium["mu_min"] == ""  # not confirmed: left blank, and said so
    assert "not confirmed" in colluvium["parameters"]


def test_the_account_says_the_law_does_not_reduce(tornado_export):
    _, export = tornado_export
    assert "cannot be reduced to a lumped e_n / e_t" in export.mismatches[0]
    assert any("between Medium and Medium Soft" in m for m in export.mismatches)
    assert any(what.startswith("materials.rock") for what, _ in export.unmapped)
    assert export.target == "ramms" and export.title == "RAMMS::ROCKFALL"


@pytest.mark.parametrize(
    ("position", "expected"),
    [
        (0.0, ("Extra Soft", None)),
        (0.2, ("Extra Soft", None)),  # closer than a quarter step
        (0.25, ("Extra Soft", "Soft")),  # a quarter step: between, the nearer first
        (0.4, ("Extra Soft", "Soft")),
        (0.5, ("Soft", "Extra Soft")),  # half-way: the harder first
        (0.6, ("Soft", "Extra Soft")),
        (0.75, ("Soft", "Extra Soft")),
        (0.8, ("Soft", None)),
        (2.5, ("Medium", "Medium Soft")),
        (5.9, ("Extra Hard", None)),
        (6.0, ("Extra Hard", None)),
    ],
)
def test_category_at_and_between_boundaries(position, expected):
    assert category_at(position) == expected


@pytest.mark.parametrize(
    ("name", "category", "neighbour"),
    [
        ("talus", "Medium", None),
        ("Lower_Colluvium", "Medium", "Medium Soft"),
        ("bedrock", "Extra Hard", None),
        ("weathered rock", "Hard", None),  # the longer keyword wins over "rock"
        ("meadow", "Soft", None),  # Tschamut's ground
        ("boulder field", "Medium Hard", None),
        ("peat", "Extra Soft", None),
        ("rockfall zone", "", None),  # "rock" must be a word of its own
        ("m1", "", None),
    ],
)
def test_recommendation_by_description(name, category, neighbour):
    assert recommend(name)[:2] == (category, neighbour)


def test_no_recommendation_is_code_zero_and_said():
    model = model_from_dict(one_material("m1"))
    export = export_ramms(model, site_from_section(model, cellsize_m=5, rows=2))
    assert export.files["terrain_category.asc"].splitlines()[6] == "0 0 0 0"
    row = next(csv.DictReader(io.StringIO(export.files["terrain_categories.csv"])))
    assert (row["code"], row["category"]) == ("0", "none")
    assert "choose from the site" in row["reason"]


def test_nodata_cells_of_a_dem_stay_nodata(tmp_path):
    model = model_from_dict(one_material("talus"))
    values = np.array([[3.0, 2.0, np.nan], [2.0, 1.0, 0.0]])
    grid = DemGrid.from_corner(values, x_left_m=100, y_top_m=20, cellsize_m=5)
    export = export_ramms(model, site_from_dem(model, grid, (102.5, 17.5)))
    assert export.files["terrain_category.asc"].splitlines()[6:] == [
        "4 4 -9999",
        "4 4 4",
    ]
    path = tmp_path / "dem.asc"
    path.write_text(export.files["dem.asc"])
    back = read_dem(path)
    assert np.isnan(back.values[0, 2])
    assert back.values[1].tolist() == [2.0, 1.0, 0.0]
    assert (back.x_m[0], back.y_m[0]) == (102.5, 17.5)


# ------------------------------------------- through the command line (issue 19)

TSCHAMUT = REPO / "examples/tschamut/model_base.json"
TERRAIN = REPO / "tests/data/tschamut2014/terrain.asc"
RELEASES = REPO / "tests/data/tschamut2014/release_points.csv"
TABLE_7_1 = REPO / "surveys/tornado_mountain/model_rocfall_table_7_1.json"


def test_readme_says_no_translation_error_and_lists_every_effect(cli, tmp_path):
    out = tmp_path / "o"
    r = cli("export", TABLE_7_1, "--to", "ramms", "-o", out, "--extrude",
            "--cellsize", "10", "--rows", "3")  # fmt: skip
    assert r.exit_code == 0, r.output
    readme = (out / "README.md").read_text(encoding="utf-8")
    section = readme.split("## Translation error: calibrated model vs the target's "
                           "law")[1].split("\n## ")[0]  # fmt: skip
    # RAMMS's rigid-body law cannot be emulated: said plainly, and no number given
    assert "Not measured" in section and "cannot be emulated" in section
    assert "| runout p50" not in section and "%" not in section
    for spec in registry.EFFECTS:
        assert f"effect {spec.name} (" in readme, spec.name
    sources = readme.split("## Sources of the target's rules")[1].split("\n## ")[0]
    assert "ramms_gap_analysis.md" in sources and "User Manual" in sources
    unconfirmed = readme.split("## Unconfirmed")[1].split("\n## ")[0]
    assert "mu_min, beta, kappa and drag of Soft" in unconfirmed
    for name in ("dem.asc", "terrain_category.asc", "terrain_categories.csv"):
        assert f"wrote {out / name}" in r.stdout.splitlines()


def test_tschamut_release_file_on_the_real_dem(cli, tmp_path):
    out = tmp_path / "o"
    r = cli("export", TSCHAMUT, "--to", "ramms", "-o", out, "--dem", TERRAIN,
            "--releases", RELEASES)  # fmt: skip
    assert r.exit_code == 0, r.output
    readme = (out / "README.md").read_text(encoding="utf-8")
    # 80 points in 14 cells; RAMMS's DEM is the site's, not padded
    assert "14 release cells from" in readme and "(80 points)" in readme
    assert read_dem(out / "dem.asc").shape == read_dem(TERRAIN).shape
    assert "Release cells (centres, m): (" in readme and "and 4 more" in readme
