"""`fieldkit profile`: sections from a DEM or a vertex CSV on the command line."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from fieldkit.io.dem import read_dem
from fieldkit.io.profile_csv import read_profile_csv

RELEASE_V020 = "30.602,235.28"  # tests/data/tschamut2014/release_points.csv
DEPOSIT_V020 = "102.22,151.49"  # tests/data/tschamut2014/observed_deposition.csv


@pytest.fixture()
def dem(tmp_path, external_data):
    """A copy of the Tschamut 2014 terrain proxy (5 m cells)."""
    return Path(shutil.copy(external_data / "tschamut2014" / "terrain.asc", tmp_path))


def _number(pattern, text):
    match = re.search(pattern, text)
    assert match, (pattern, text)
    return float(match.group(1))


def test_steepest_descent_with_materials(cli, dem, tmp_path):
    out, png = tmp_path / "profile.csv", tmp_path / "profile.png"
    r = cli("profile", dem, "--from", RELEASE_V020, "--materials",
            "0-40:rock,40-:talus", "-o", out, "--figure", png)  # fmt: skip
    assert r.exit_code == 0, r.stderr
    assert "step 2.5 m (default: half the cell size)" in r.stdout
    assert "ended: a local minimum" in r.stdout
    p = read_profile_csv(out)
    # what it prints is what it wrote
    assert _number(r"([\d.]+) m long", r.stdout) == pytest.approx(p.x_m[-1], abs=0.05)
    assert _number(r"drop ([\d.]+) m", r.stdout) == pytest.approx(
        p.z_m[0] - p.z_m[-1], abs=0.05
    )
    assert np.all(np.diff(p.z_m) < 0)
    # z is the DEM under the plan line; the material changes exactly at 40 m
    grid = read_dem(dem)
    np.testing.assert_allclose(grid.elevation(p.plan_x_m, p.plan_y_m), p.z_m,
                               atol=1e-4)  # fmt: skip
    i = int(np.flatnonzero(p.x_m == 40.0)[0])
    assert set(p.material[:i]) == {"rock"} and set(p.material[i:]) == {"talus"}
    assert png.stat().st_size > 10_000


def test_polyline_to_the_deposit(cli, dem, tmp_path):
    out = tmp_path / "line.csv"
    r = cli("profile", dem, "--from", RELEASE_V020, "--to", DEPOSIT_V020,
            "--step", "1", "-o", out)  # fmt: skip
    assert r.exit_code == 0, r.stderr
    p = read_profile_csv(out)
    length = np.hypot(102.22 - 30.602, 151.49 - 235.28)
    assert p.x_m[-1] == pytest.approx(length, abs=1e-4)
    assert np.diff(p.x_m).max() <= 1.0 + 1e-4 and len(p.x_m) == 112
    assert (p.plan_x_m[-1], p.plan_y_m[-1]) == (102.22, 151.49)
    assert "every segment 'ground' (no --materials given)" in r.stdout


def test_vertex_csv_in_feet_to_metres(cli, tmp_path):
    src = tmp_path / "field.csv"
    src.write_text("distance,elevation\n0,300\n50,250\n120,200\n")
    out = tmp_path / "profile.csv"
    r = cli("profile", src, "--units", "ft", "--materials", "0-20:rock,20-:talus",
            "-o", out)  # fmt: skip
    assert r.exit_code == 0, r.stderr
    p = read_profile_csv(out)
    np.testing.assert_allclose(p.x_m, [0, 15.24, 20.0, 36.576], atol=1e-4)
    np.testing.assert_allclose(p.z_m[[0, 1, 3]], [91.44, 76.2, 60.96], atol=1e-4)
    assert p.material == ("rock", "rock", "talus")


def _asc(path, values, nodata=-9999):
    nrows, ncols = values.shape
    rows = "\n".join(" ".join(f"{v:g}" for v in row) for row in values)
    path.write_text(f"ncols {ncols}\nnrows {nrows}\nxllcorner 0\nyllcorner 0\n"
                    f"cellsize 10\nNODATA_value {nodata}\n{rows}\n")  # fmt: skip
    return path


@pytest.fixture()
def holes(tmp_path):
    """A 10 x 10 plane falling to the east, with one nodata cell at (55, 55)."""
    x = 5 + 10 * np.arange(10)
    values = np.tile(100.0 - 0.5 * x, (10, 1))
    values[4, 5] = -9999
    return _asc(tmp_path / "holes.asc", values)


BAD = [
    # (arguments after DEM, words the one error line names)
    (["--from", RELEASE_V020, "--to", "200,200"],
     ["terrain.asc", "the line leaves the grid at", "chainage", "x -32.5..177.5 m"]),
    (["--from", "500,500"], ["terrain.asc", "the start (x, y) = (500, 500)",
                             "outside the grid"]),
    (["--from", RELEASE_V020, "--step", "3"],
     ["--step must be <= half the cell size, 2.5 m"]),
    (["--from", RELEASE_V020, "--materials", "0-40:rock,50-:talus"],
     ["--materials", "no material between chainage 40 and 50 m"]),
    (["--from", RELEASE_V020, "--materials", "0-40:rock"],
     ["--materials", "no material beyond chainage 40 m"]),
    (["--from", "30.6"], ["--from '30.6' is not X,Y"]),
    ([], ["a DEM needs --from X,Y"]),
    (["--from", RELEASE_V020, "--to", RELEASE_V020],
     ["--from/--to points 1 and 2 are the same point"]),
    (["--from", RELEASE_V020, "--units", "ft"], ["--units applies to a profile CSV"]),
]  # fmt: skip


@pytest.mark.parametrize(("args", "words"), BAD)
def test_bad_dem_sections_fail_in_one_line_writing_nothing(
    cli, fails, digest, dem, tmp_path, args, words
):
    before = digest(dem)
    out = tmp_path / "out" / "profile.csv"
    r = cli("profile", dem, *args, "-o", out, "--figure", tmp_path / "out" / "p.png")
    fails(r, *words)
    assert not (tmp_path / "out").exists() and digest(dem) == before


def test_nodata_on_the_line_is_an_error_but_ends_a_descent(cli, fails, holes, tmp_path):
    out = tmp_path / "p.csv"
    r = cli("profile", holes, "--from", "12,55", "--to", "90,55", "-o", out)
    fails(r, "holes.asc", "the line crosses nodata at (x, y) = (", "row 5, column 6")
    assert not out.exists()
    r = cli("profile", holes, "--from", "12,55", "-o", out)
    assert r.exit_code == 0, r.stderr
    assert "ended: reached nodata cells at (" in r.stdout
    assert read_profile_csv(out).plan_x_m[-1] == pytest.approx(45.0, abs=1e-4)


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("ncols 3\nnrows 2\nxllcorner 0\ncellsize 1\n1 2 3\n4 5 6\n",
         ["bad.asc: line 5: header yllcorner or yllcenter missing"]),
        ("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 5 6 7\n",
         ["bad.asc: line 7: 4 values in a row of ncols = 3"]),
        ("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 - 6\n",
         ["bad.asc: line 7: value '-' is not a number"]),
    ],
)  # fmt: skip
def test_malformed_grid_file(cli, fails, tmp_path, text, words):
    bad = tmp_path / "bad.asc"
    bad.write_text(text)
    r = cli("profile", bad, "--from", "1,1", "-o", tmp_path / "p.csv")
    fails(r, *words)
    assert not (tmp_path / "p.csv").exists()


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("x_m,z_m\n0,10\n8,9\n5,8\n", ["row 4: column 'x_m' must increase"]),
        ("x_m,z_m\n0,10\n", ["at least 2 vertices (got 1)"]),
        ("x_m,z_m\n0,10\n5,NaN\n", ["row 3: column 'z_m': 'NaN' is not a finite"]),
    ],
)
def test_bad_profile_csv(cli, fails, tmp_path, text, words):
    src = tmp_path / "vertices.csv"
    src.write_text(text)
    r = cli("profile", src, "-o", tmp_path / "p.csv")
    fails(r, "vertices.csv", *words)
    assert not (tmp_path / "p.csv").exists()


def test_output_over_the_dem_is_refused(cli, fails, dem, digest):
    before = digest(dem)
    r = cli("profile", dem, "--from", RELEASE_V020, "-o", dem)
    fails(r, "output would overwrite an input file")
    assert digest(dem) == before
