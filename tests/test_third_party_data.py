"""Third-party data in tests/data: licensed, attributed, complete and self-consistent.

The folders are copies (see tests/data/README.md), so a fresh clone runs every test that
reads them. Tschamut 2014 is checked here against the figures its source publishes
(80 runs, horizontal runout mean 98.4 m, 27.5-134.7 m) for the calibration to come.
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

FOLDERS = ["chant_sura_2019", "gpx_gpxpy", "tschamut2014"]
#: folders of our own files about third-party data kept outside the repository (the
#: real-camera clips' labels: tests/data/video_corpus/README.md)
OURS = ["video_corpus"]


def test_every_folder_is_listed_and_nothing_else(external_data):
    folders = sorted(p.name for p in external_data.iterdir() if p.is_dir())
    assert folders == sorted(FOLDERS + OURS)
    index = (external_data / "README.md").read_text()
    assert all(f"`{name}/`" in index for name in FOLDERS + OURS)


@pytest.mark.parametrize("name", FOLDERS)
def test_each_folder_has_its_licence_and_a_source(external_data, name):
    folder = external_data / name
    licences = [p for p in folder.iterdir() if p.name.startswith("LICENSE")]
    assert licences and all(p.stat().st_size > 500 for p in licences)
    readme = (folder / "README.md").read_text()
    assert "https://" in readme and "licen" in readme.lower()
    for path in folder.rglob("*"):  # no GPL data in a BSD-licensed repository
        if path.is_file():
            assert "GNU GENERAL PUBLIC LICENSE" not in path.read_text(errors="replace")


def test_tschamut_runs_match_the_published_summary(external_data):
    folder = external_data / "tschamut2014"
    release = pd.read_csv(folder / "release_points.csv")
    deposit = pd.read_csv(folder / "observed_deposition.csv")
    assert len(release) == len(deposit) == 80
    assert (release["trajectory_id"] == deposit["trajectory_id"]).all()
    runout = np.hypot(
        deposit["x_m"] - deposit["release_x_m"], deposit["y_m"] - deposit["release_y_m"]
    )
    np.testing.assert_allclose(runout, deposit["observed_runout_m"], atol=1e-6)
    assert runout.mean() == pytest.approx(98.4, abs=0.05)
    assert runout.min() == pytest.approx(27.5, abs=0.05)
    assert runout.max() == pytest.approx(134.7, abs=0.05)
    for frame in (release, deposit):  # block centres sit one radius above the ground
        np.testing.assert_allclose(
            frame["z_m"] - frame["ground_z_m"], frame["radius_m"], atol=1e-9
        )
    blocks = pd.read_csv(folder / "block_metadata.csv").set_index("block_id")
    assert blocks["mass_kg"].between(40, 79).all() and len(blocks) == 3
    np.testing.assert_array_equal(
        release["mass_kg"], blocks.loc[release["block_id"], "mass_kg"]
    )


def test_tschamut_terrain_grid_matches_its_metadata(external_data):
    folder = external_data / "tschamut2014"
    proxy = json.loads((folder / "metadata.json").read_text())["terrain_proxy"]
    lines = (folder / "terrain.asc").read_text().splitlines()
    header = {k.lower(): float(v) for k, v in (line.split() for line in lines[:6])}
    assert header["ncols"] == proxy["ncols"] and header["nrows"] == proxy["nrows"]
    assert header["cellsize"] == proxy["cellsize_m"]
    assert (header["xllcorner"], header["yllcorner"]) == (
        proxy["xllcorner_m"],
        proxy["yllcorner_m"],
    )
    grid = np.loadtxt(lines[6:])
    assert grid.shape == (proxy["nrows"], proxy["ncols"])
    assert np.isfinite(grid).all() and (grid != header["nodata_value"]).all()


def test_tschamut_split_is_disjoint_and_balanced(external_data):
    folder = external_data / "tschamut2014" / "calibration_split"
    text = (folder / "split.yaml").read_text()

    def ids(key: str) -> set[str]:  # a YAML list of plain strings under ``key``
        found = set()
        for line in text.split(f"\n{key}:\n", 1)[1].splitlines():
            if not line.startswith("- "):
                break
            found.add(line[2:].strip())
        return found

    calibration, holdout = ids("calibration_ids"), ids("holdout_ids")
    assert len(calibration) == len(holdout) == 18 and not calibration & holdout
    every = set(pd.read_csv(folder.parent / "release_points.csv")["trajectory_id"])
    for part, chosen in (("calibration", calibration), ("holdout", holdout)):
        for kind in ("release_points", "observed_deposition"):
            frame = pd.read_csv(folder / f"{part}_{kind}.csv")
            assert set(frame["trajectory_id"]) == chosen <= every
            assert frame.groupby("block_id").size().tolist() == [6, 6, 6]
