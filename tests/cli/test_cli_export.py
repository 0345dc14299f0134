"""`fieldkit export`: every target from the command line, the README beside the files,
and bad input refused in one line with nothing written."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fieldkit.io.dem import read_dem
from fieldkit.model.model_file import read_model

REPO = Path(__file__).resolve().parents[2]
TABLE_7_1 = REPO / "surveys" / "tornado_mountain" / "model_rocfall_table_7_1.json"
TSCHAMUT = REPO / "examples" / "tschamut" / "model_base.json"
TERRAIN = REPO / "tests" / "data" / "tschamut2014" / "terrain.asc"
README_SECTIONS = (
    "## What was mapped to what",
    "## What could not be mapped, and why",
    "## Units",
    "## Residual mismatch where a class or category was chosen",
)


@pytest.mark.parametrize(
    "target, extra",
    [
        ("rocfall", []),
        ("crsp", []),
        ("json", []),
        ("rockyfor3d", ["--extrude", "--cellsize", "5"]),
        ("ramms", ["--extrude", "--cellsize", "5"]),
        ("rstone", ["--extrude", "--cellsize", "5"]),
    ],
)
def test_every_target_writes_its_files_and_a_readme(cli, tmp_path, target, extra):
    out = tmp_path / target
    r = cli("export", TABLE_7_1, "--to", target, "-o", out, *extra)
    assert r.exit_code == 0, r.output
    readme = (out / "README.md").read_text(encoding="utf-8")
    for heading in README_SECTIONS:
        assert heading in readme, heading
    files = {p.name for p in out.iterdir()} - {"README.md"}
    assert files and all(f"`{name}`" in readme for name in files)
    assert f"{target}:" in r.output
    if target == "rockyfor3d":  # source cells inside Rockyfor3D's active area
        source = read_dem(out / "rockdensity.asc").values > 0
        assert source.any() and not source[:2].any() and not source[-2:].any()
        assert not source[:, :2].any() and not source[:, -2:].any()


def test_grid_files_share_the_extruded_grid(cli, tmp_path):
    out = tmp_path / "r3d"
    r = cli("export", TABLE_7_1, "--to", "rockyfor3d", "-o", out, "--extrude",
            "--cellsize", "5", "--rows", "3")  # fmt: skip
    assert r.exit_code == 0, r.output
    grids = [read_dem(p) for p in sorted(out.glob("*.asc"))]
    assert len(grids) >= 2
    for g in grids:
        # 700 m of profile / 5 m, 3 rows; padded by 2 cells north, south and west so
        # the seeder's column lies inside Rockyfor3D's active area
        assert g.shape == grids[0].shape == (7, 142)
        assert g.x_m[0] == grids[0].x_m[0] == -7.5


def test_grid_target_on_a_dem(cli, tmp_path):
    out = tmp_path / "rstone"
    r = cli("export", TSCHAMUT, "--to", "rstone", "-o", out, "--dem", TERRAIN,
            "--release", "30.602,235.28")  # fmt: skip
    assert r.exit_code == 0, r.output
    dem = read_dem(TERRAIN)
    written = [read_dem(p) for p in out.glob("*.asc")]
    assert written and all(g.shape == dem.shape for g in written)
    assert "the DEM" in (out / "README.md").read_text(encoding="utf-8")


def test_json_round_trip_keeps_every_parameter(cli, tmp_path):
    r = cli("export", TABLE_7_1, "--to", "json", "-o", tmp_path / "j")
    assert r.exit_code == 0, r.output
    again = read_model(tmp_path / "j" / "model.json")
    assert again.parameters() == read_model(TABLE_7_1).parameters()
    table = json.loads((tmp_path / "j" / "parameters.json").read_text())
    assert {row["name"] for row in table} == set(again.parameters())


def test_unknown_target_lists_the_known_ones(cli, tmp_path, fails):
    r = cli("export", TABLE_7_1, "--to", "rocfal", "-o", tmp_path / "x")
    fails(r, "--to", "rocfal", "rocfall, crsp, rockyfor3d, ramms, rstone, json")
    assert not (tmp_path / "x").exists()


def test_a_folder_that_is_not_empty_needs_force(cli, tmp_path, fails):
    out = tmp_path / "full"
    out.mkdir()
    (out / "mine.txt").write_text("keep me")
    fails(cli("export", TABLE_7_1, "--to", "json", "-o", out), "not empty", "--force")
    assert {p.name for p in out.iterdir()} == {"mine.txt"}
    r = cli("export", TABLE_7_1, "--to", "json", "-o", out, "--force")
    assert r.exit_code == 0, r.output
    assert (out / "mine.txt").read_text() == "keep me"
    assert (out / "model.json").is_file()


@pytest.mark.parametrize(
    "args, words",
    [
        (["--to", "rockyfor3d"], ["--dem", "extrude"]),
        (["--to", "rocfall", "--dem", TERRAIN], ["not a grid target"]),
        (
            ["--to", "ramms", "--dem", TERRAIN, "--release", "1,2"],
            ["2 materials", "rock, colluvium"],
        ),  # fmt: skip
        (["--to", "ramms", "--extrude", "--release", "1,2"], ["--release"]),
    ],
)
def test_grid_inputs_refused_in_one_line(cli, tmp_path, fails, args, words):
    out = tmp_path / "x"
    fails(cli("export", TABLE_7_1, "-o", out, *args), *words)
    assert not out.exists()


def test_a_dem_site_needs_its_release_point(cli, tmp_path, fails):
    out = tmp_path / "x"
    r = cli("export", TSCHAMUT, "--to", "ramms", "-o", out, "--dem", TERRAIN)
    fails(r, "--release", "release point")
    assert not out.exists()


def test_release_outside_the_dem_refused(cli, tmp_path, fails):
    out = tmp_path / "x"
    r = cli("export", TSCHAMUT, "--to", "rockyfor3d", "-o", out, "--dem", TERRAIN,
            "--release", "-500,-500")  # fmt: skip
    fails(r, "--release", "no ground")
    assert not out.exists()


def test_a_model_file_without_what_a_model_needs(cli, tmp_path, fails):
    bad = tmp_path / "bad.json"
    data = json.loads(TABLE_7_1.read_text())
    del data["materials"]
    bad.write_text(json.dumps(data))
    fails(cli("export", bad, "--to", "json", "-o", tmp_path / "x"), "materials")
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize(
    ("target", "field", "value"),
    [
        # RocFall and CRSP write the in-range values under their own law instead
        # of refusing e_t > 1, and so does r.stone (issue 19:
        # tests/export/test_rocfall.py, test_crsp.py, test_rstone.py); what
        # r.stone refuses is a rolling friction tan above 1.
        ("rstone", "friction_deg", 50),
    ],
)
def test_values_the_target_refuses_leave_nothing_behind(
    cli, tmp_path, fails, target, field, value
):
    data = json.loads(TABLE_7_1.read_text())
    data["materials"]["colluvium"][field] = value
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    out = tmp_path / "x"
    extra = ["--extrude"] if target == "rstone" else []
    r = cli("export", bad, "--to", target, "-o", out, *extra)
    fails(r, "colluvium", f"{value:g}")
    assert not out.exists()


def test_export_force_never_follows_a_link_out_of_the_folder(
    cli, tmp_path, fails, digest
):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    target = elsewhere / "keep.txt"
    target.write_text("not fieldkit's\n")
    out = tmp_path / "out"
    out.mkdir()
    (out / "slope.csv").symlink_to(target)
    before = digest(target)
    r = cli("export", TABLE_7_1, "--to", "rocfall", "-o", out, "--force")
    fails(r, "slope.csv", "symbolic link", str(target), "outside")
    assert digest(target) == before
    assert sorted(p.name for p in out.iterdir()) == ["slope.csv"]
    assert (out / "slope.csv").is_symlink()
    assert sorted(p.name for p in elsewhere.iterdir()) == ["keep.txt"]


def test_export_force_refuses_a_linked_sub_folder_too(cli, tmp_path, fails):
    # a link to a folder outside, in place of a file name the target writes
    outside = tmp_path / "outside"
    outside.mkdir()
    out = tmp_path / "out"
    out.mkdir()
    (out / "README.md").symlink_to(outside / "README.md")
    fails(cli("export", TABLE_7_1, "--to", "json", "-o", out, "--force"),
          "README.md", "outside")  # fmt: skip
    assert list(outside.iterdir()) == []


def test_a_linked_output_folder_itself_is_written(cli, tmp_path):
    real = tmp_path / "real"
    real.mkdir()
    (tmp_path / "link").symlink_to(real)
    r = cli("export", TABLE_7_1, "--to", "json", "-o", tmp_path / "link")
    assert r.exit_code == 0, r.output
    assert sorted(p.name for p in real.iterdir()) == [
        "README.md", "model.json", "parameters.json"
    ]  # fmt: skip


def test_export_says_what_it_wrote(cli, tmp_path):
    out = tmp_path / "rocfall"
    r = cli("export", TABLE_7_1, "--to", "rocfall", "-o", out)
    assert r.exit_code == 0, r.output
    wrote = [line[len("wrote ") :] for line in r.stdout.splitlines()
             if line.startswith("wrote ")]  # fmt: skip
    assert sorted(wrote) == sorted(str(p) for p in out.iterdir())
    assert len(wrote) == 6


def test_import_model_says_what_it_wrote(cli, tmp_path):
    folder = tmp_path / "rocfall"
    assert cli("export", TABLE_7_1, "--to", "rocfall", "-o", folder).exit_code == 0
    model = tmp_path / "back.json"
    r = cli("import-model", folder, "--from", "rocfall", "-o", model)
    assert r.exit_code == 0, r.output
    assert f"wrote {model}" in r.stdout.splitlines()


def _strict_json(path):
    def refuse(name):
        raise AssertionError(f"{path.name} holds the non-JSON literal {name}")

    return json.loads(path.read_text(encoding="utf-8"), parse_constant=refuse)


def test_json_outputs_write_non_finite_numbers_as_null(cli, tmp_path):
    # a fit's record may hold a standard error that is not finite (unidentifiable)
    data = json.loads(TABLE_7_1.read_text())
    data["provenance"] = {"fit": {"stderr": {"a": float("nan"), "b": float("inf")}}}
    model = tmp_path / "model.json"
    model.write_text(json.dumps(data))  # Python writes NaN and Infinity literals
    out = tmp_path / "j"
    r = cli("export", model, "--to", "json", "-o", out)
    assert r.exit_code == 0, r.output
    written = _strict_json(out / "model.json")
    assert written["provenance"]["fit"]["stderr"] == {"a": None, "b": None}
    _strict_json(out / "parameters.json")
    again = cli("export", out / "model.json", "--to", "json", "-o", tmp_path / "k")
    assert again.exit_code == 0, again.output
