"""`fieldkit simulate` on a 3-D model file with trees (the real kernel): rocks
sliding straight down a plane strike exactly the stems in their lanes; the strikes
are stated on stdout and in summary.json; bad tree input is one line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

CELL, NX, NY = 2.0, 40, 30


def write_site(tmp_path: Path, effects: dict, trees: dict | None) -> Path:
    """A plane dipping 31 deg (0.6) towards +x, friction 20 deg (rocks released at
    rest slide straight down the fall line), releases at x = 10 m, y = 10, 20, 30 m."""
    xc = CELL * (np.arange(NX) + 0.5)
    z = np.tile(60.0 - 0.6 * xc, (NY, 1))
    rows = "\n".join(" ".join(f"{v:.3f}" for v in row) for row in z)
    (tmp_path / "terrain.asc").write_text(
        f"ncols {NX}\nnrows {NY}\nxllcorner 0\nyllcorner 0\ncellsize {CELL}\n"
        f"NODATA_value -9999\n{rows}\n"
    )
    data = {
        "terrain": {"dem": "terrain.asc", "materials": "grass",
                    "releases": [[10.0, 10.0], [10.0, 20.0], [10.0, 30.0]]},
        "materials": {"grass": {"e_n": 0.3, "e_t": 0.8, "friction_deg": 20}},
        "body": {"mass_kg": 100.0, "radius_m": 0.2},
        "effects": effects,
    }  # fmt: skip
    if trees is not None:
        data["trees"] = trees
    path = tmp_path / "model3d.json"
    path.write_text(json.dumps(data))
    return path


#: In the lanes y = 10 and y = 30 (one each); 0.4 m beside the lane y = 20, beyond
#: d/2 + r = 0.35 m; one stem off the DEM.
TREES = {
    "x_m": [30.0, 30.0, 50.0, -40.0],
    "y_m": [10.0, 20.4, 30.0, 10.0],
    "diameter_m": [0.3, 0.3, 0.3, 0.3],
    "height_m": [20.0, 20.0, 15.0, 20.0],
}


def test_simulate_states_the_tree_strikes(cli, tmp_path, digest):
    model = write_site(tmp_path, {"tree_impacts": {}}, TREES)
    before = digest(model)
    out = tmp_path / "out"
    result = cli("simulate", model, "--rocks", "60", "--seed", "4",
                 "--summary", out / "summary.json",
                 "--deposits", out / "deposits.csv")  # fmt: skip
    assert result.exit_code == 0, result.stderr
    deposits = pd.read_csv(out / "deposits.csv")
    in_lane = int(deposits["release"].isin([0, 2]).sum())  # y = 10 or y = 30
    assert 0 < in_lane < 60
    s = json.loads((out / "summary.json").read_text())
    assert s["tree_strikes"]["total"] == in_lane
    assert s["tree_strikes"]["rocks_struck"] == in_lane
    assert s["tree_strikes"]["stems"] == 4
    assert f"tree strikes: {in_lane} (by {in_lane} of 60 rocks; 4 stems" in (
        result.stdout
    )
    # the 3-D meaning of hit_probability and the stem off the DEM are stated
    assert "hit_probability 1: 3-D strikes are geometric" in result.stderr
    assert "3 stems on the DEM, each struck" in result.stderr
    assert "1 stem(s) off the DEM's surface never reached" in result.stderr
    assert f"wrote {out / 'summary.json'}" in result.stdout
    assert digest(model) == before


def test_without_tree_impacts_trees_change_nothing(cli, tmp_path):
    runs = []
    for i, (effects, trees) in enumerate([({}, TREES), ({}, None)]):
        folder = tmp_path / str(i)
        folder.mkdir()
        model = write_site(folder, effects, trees)
        result = cli("simulate", model, "--rocks", "30", "--seed", "4",
                     "--summary", folder / "s.json",
                     "--deposits", folder / "d.csv")  # fmt: skip
        assert result.exit_code == 0, result.stderr
        assert "tree_strikes" not in json.loads((folder / "s.json").read_text())
        runs.append((folder / "d.csv").read_bytes())
    assert runs[0] == runs[1]


@pytest.mark.parametrize(
    ("effects", "trees", "words"),
    [
        ({"tree_impacts": {}}, None, ["trees", "tree_impacts is on but"]),
        (
            {"tree_impacts": {"hit_probability": 0.5}},
            TREES,
            ["effects.tree_impacts.hit_probability", "is 0.5", "must be 1"],
        ),
        (
            {"tree_impacts": {}},
            {k: v for k, v in TREES.items() if k != "height_m"},
            ["trees.height_m", "missing"],
        ),
        (
            {"tree_impacts": {}},
            TREES | {"height_m": [20.0, -1.0, 15.0, 20.0]},
            ["trees.height_m", "must be in (0, 150] m"],
        ),
    ],
)
def test_bad_trees_one_line(cli, fails, tmp_path, effects, trees, words):
    model = write_site(tmp_path, effects, trees)
    out = tmp_path / "out"
    result = cli("simulate", model, "--rocks", "5", "--summary", out / "s.json")
    fails(result, "model3d.json", *words)
    assert result.exit_code == 1
    assert not out.exists()
