"""`fieldkit corridor` end to end on the Tschamut DEM, and its bad input: one line,
exit != 0, nothing written."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from fieldkit.corridor.table import COLUMNS

DEM = "tests/data/tschamut2014/terrain.asc"
MODEL_2D = "examples/tschamut/model_base.json"
MODEL_3D = "examples/tschamut/model_3d.json"
ALIGNMENT = "examples/tschamut/alignment.csv"


@pytest.fixture()
def at_repo(repo, monkeypatch):
    monkeypatch.chdir(repo)
    return repo


def test_2d_scan_writes_the_table_figures_scene_and_summary(cli, at_repo, tmp_path):
    out = tmp_path / "c.csv"
    r = cli("corridor", DEM, "--alignment", ALIGNMENT, "--model", MODEL_2D,
            "--upslope", "80", "--rocks", "300", "--seed", "4", "--workers", "0",
            "-o", out, "--figures", tmp_path / "fig", "--rrd", tmp_path / "s.rrd",
            "--summary", tmp_path / "s.json")  # fmt: skip
    assert r.exit_code == 0, r.stderr
    frame = pd.read_csv(out)
    assert list(frame.columns[: len(COLUMNS)]) == list(COLUMNS)
    assert len(frame) == 12 and (frame["rocks"] == 300).all()
    for name in ("chainage.png", "plan.png"):
        assert (tmp_path / "fig" / name).stat().st_size > 10_000
    assert (tmp_path / "s.rrd").stat().st_size > 1000
    summary = json.loads((tmp_path / "s.json").read_text())
    assert summary["engine"]["where"] == "this process" and summary["seed"] == 4
    assert "note: running in this process" in r.stderr
    assert "80 m upslope" in r.stderr  # the assumptions are stated
    assert "ETAG 027 class covering the p99 energy" in r.stdout


def test_3d_scan_names_the_units(cli, at_repo, tmp_path):
    out = tmp_path / "c3.csv"
    r = cli("corridor", DEM, "--alignment", ALIGNMENT, "--model", MODEL_3D,
            "--rocks", "500", "--seed", "2", "--workers", "0", "-o", out)  # fmt: skip
    assert r.exit_code == 0, r.stderr
    assert "in 1 unit(s) of up to 2,000 rocks (seed per unit)" in r.stderr
    assert pd.read_csv(out)["passing"].sum() > 300


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (("--spacing", "0"), ("--spacing must be a distance > 0",)),
        (("--spacing", "-3"), ("--spacing",)),
        (("--scheduler", "tcp://127.0.0.1:9", "--timeout", "1"),
         ("--scheduler", "did not answer within 1 s")),
        (("--workers", "-2"), ("--workers must be from 0",)),
        (("--rocks", "0"), ("--rocks must be an integer from 1",)),
        (("--upslope", "10", "--release-band", "20"), ("--release-band",)),
    ],
)  # fmt: skip
def test_bad_options_fail_in_one_line_writing_nothing(
    cli, fails, at_repo, tmp_path, extra, words
):
    out = tmp_path / "c.csv"
    r = cli("corridor", DEM, "--alignment", ALIGNMENT, "--model", MODEL_2D,
            "--rocks", "50", "--seed", "1", "-o", out, "--figures",
            tmp_path / "fig", *extra)  # fmt: skip
    fails(r, *words)
    assert not out.exists() and not (tmp_path / "fig").exists()


def test_alignment_outside_the_dem(cli, fails, at_repo, tmp_path, digest):
    line = tmp_path / "line.csv"
    line.write_text("x_m,y_m\n0,160\n400,160\n")
    before = digest(line)
    r = cli("corridor", DEM, "--alignment", line, "--model", MODEL_2D, "--rocks",
            "50", "-o", tmp_path / "c.csv")  # fmt: skip
    fails(r, "terrain.asc", "the alignment at chainage 180.0 m", "not on the DEM")
    assert not (tmp_path / "c.csv").exists() and digest(line) == before


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("x_m,y_m\n0,160\n", ("at least 2 vertices",)),
        ("x_m,y_m\n0,160\n0,160\n", ("row 3", "repeats the one before")),
        ("x,y\n0,160\n10,170\n", ("has no length unit",)),
        ("x_m,y_m\n0,160\n10,abc\n", ("row 3",)),
    ],
)
def test_bad_alignment_files(cli, fails, at_repo, tmp_path, text, words):
    line = tmp_path / "line.csv"
    line.write_text(text)
    r = cli("corridor", DEM, "--alignment", line, "--model", MODEL_2D, "-o",
            tmp_path / "c.csv")  # fmt: skip
    fails(r, "line.csv", *words)
    assert not (tmp_path / "c.csv").exists()


def test_a_3d_model_on_another_dem_and_2d_options_with_it(cli, fails, at_repo,
                                                          tmp_path):  # fmt: skip
    r = cli("corridor", DEM, "--alignment", ALIGNMENT, "--model", MODEL_3D,
            "--upslope", "60", "-o", tmp_path / "c.csv")  # fmt: skip
    fails(r, "--upslope cuts 2-D sections")
    plane = tmp_path / "plane.asc"
    plane.write_text("ncols 3\nnrows 3\nxllcorner -35\nyllcorner 85\ncellsize 5\n"
                     "1 1 1\n1 1 1\n1 1 1\n")  # fmt: skip
    r = cli("corridor", plane, "--alignment", ALIGNMENT, "--model", MODEL_3D,
            "-o", tmp_path / "c.csv")  # fmt: skip
    fails(r, "plane.asc", "is not the DEM of the terrain model")
