"""Release/deposit CSV pairs and ImpactTables as PathObservations."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from fieldkit.errors import InputFileError
from fieldkit.impact_table import ImpactTable
from fieldkit.io.path_observations import (
    observations_from_impact_table,
    read_release_deposit,
)

DATA = Path(__file__).resolve().parents[1] / "data" / "tschamut2014"
SPLIT = DATA / "calibration_split"

REL = (
    "trajectory_id,x_m,y_m,z_m,ground_z_m,vx_mps,vy_mps,vz_mps,block_id,mass_kg,"
    "radius_m"
)
DEP = "trajectory_id,x_m,y_m,z_m,release_z_m,observed_runout_m"
REL_ROWS = ["v1,0,0,70.16,70,0.3,0.4,0,4,40,0.16", "v2,10,0,70.2,70,0,0,0,1,69,0.18"]
DEP_ROWS = ["v1,30,40,20,70.16,50", "v2,10,60,30,70.2,60"]


def write(tmp_path, rel=REL_ROWS, dep=DEP_ROWS, rel_header=REL, dep_header=DEP):
    r, d = tmp_path / "rel.csv", tmp_path / "dep.csv"
    r.write_text("\n".join([rel_header, *rel]) + "\n")
    d.write_text("\n".join([dep_header, *dep]) + "\n")
    return r, d


def test_a_small_pair_reads_with_every_number(tmp_path):
    obs = read_release_deposit(*write(tmp_path))
    assert obs.path_ids() == ["v1", "v2"]
    assert obs.coordinates == "plan"
    run = obs.row("v1")
    assert float(run["release_vx_mps"]) == 0.3
    assert float(run["deposit_y_m"]) == 40.0
    assert run["group"] == "4"
    assert float(run["mass_kg"]) == 40.0
    np.testing.assert_allclose(obs.straight_runout_m(), [50.0, 60.0])
    np.testing.assert_allclose(obs.runs["reported_runout_m"], [50.0, 60.0])
    assert obs.subset(["v2"]).path_ids() == ["v2"]


@pytest.mark.parametrize(
    ("folder", "prefix", "count"),
    [(SPLIT, "calibration_", 18), (SPLIT, "holdout_", 18), (DATA, "", 80)],
)
def test_the_tschamut_files_read_as_they_are(folder, prefix, count):
    release = "release_points.csv"
    deposit = "observed_deposition.csv"
    obs = read_release_deposit(folder / (prefix + release), folder / (prefix + deposit))
    assert len(obs) == count
    # the data set's observed_runout_m is the horizontal release-deposit distance
    np.testing.assert_allclose(
        obs.straight_runout_m(), obs.runs["reported_runout_m"], atol=1e-6
    )
    assert set(obs.runs["group"]) == {"1", "2", "4"}
    assert (obs.runs["deposit_z_m"] < obs.runs["release_z_m"]).all()


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (
            {"dep": ["v1,30,40,20,70.16,50"]},
            "rel.csv: run(s) v2 have no deposit in {tmp}/dep.csv",
        ),
        (
            {"dep": [*DEP_ROWS, "v9,1,1,1,,"]},
            "{tmp}/dep.csv: run(s) v9 have no release in {tmp}/rel.csv",
        ),
        (
            {"dep": ["v1,30,40,75,70.16,50", DEP_ROWS[1]]},
            "{tmp}/dep.csv: row 2 (v1): the deposit (z = 75.00 m) is higher than its "
            "release (z = 70.16 m in {tmp}/rel.csv): upslope",
        ),
        (
            {"rel": ["v1,0,0,nan,70,0,0,0,4,40,0.16", REL_ROWS[1]]},
            "{tmp}/rel.csv: row 2 (v1): column 'z_m': 'nan' is not a finite number",
        ),
        (
            {"rel": [REL_ROWS[0], "v2,10,0,70.2,70,inf,0,0,1,69,0.18"]},
            "{tmp}/rel.csv: row 3 (v2): column 'vx_mps': 'inf' is not a finite number",
        ),
        (
            {"dep_header": "trajectory_id,x_m,z_m,release_z_m,observed_runout_m",
             "dep": ["v1,30,20,70.16,50", "v2,10,30,70.2,60"]},
            "{tmp}/dep.csv: row 1: deposit CSV needs columns trajectory_id, x_m, y_m, "
            "z_m; missing y",
        ),
        (
            {"dep": ["v1,30,40,20,71.16,50", DEP_ROWS[1]]},
            "{tmp}/dep.csv: row 2 (v1): release_z 71.16 m disagrees with the release "
            "file (70.16 m in {tmp}/rel.csv, row 2)",
        ),
        (
            {"rel": [REL_ROWS[0], REL_ROWS[0]]},
            "{tmp}/rel.csv: row 3: run v1 appears twice (rows 2 and 3)",
        ),
    ],
)  # fmt: skip
def test_bad_pairs_give_one_line_naming_the_file_and_the_run(
    tmp_path, change, expected
):
    with pytest.raises(InputFileError) as info:
        read_release_deposit(*write(tmp_path, **change))
    text = str(info.value).replace(str(tmp_path), "{tmp}")
    assert text.replace("{tmp}/rel.csv:", "rel.csv:", 1).startswith(
        expected.replace("{tmp}/rel.csv:", "rel.csv:", 1)
    ) or text.startswith(expected), text
    assert "\n" not in text


def impact_table():
    return ImpactTable(
        pd.DataFrame(
            {
                "path_id": ["A", "A", "A", "B", "B"],
                "point": ["1", "2", "3", "1", "2"],
                "x_m": [0.0, 8.0, 15.0, 0.0, 6.0],
                "z_m": [10.0, 4.0, 0.0, 9.0, 5.0],
                "slope_deg": [30.0] * 5,
                "vi_x_mps": [3.0, 4.0, 5.0, 3.0, 4.0],
                "vi_z_mps": [-4.0, -3.0, -12.0, -4.0, -3.0],
                "vf_x_mps": [3.0, 3.0, 3.0, 3.0, 3.0],
                "vf_z_mps": [2.0, 1.0, 1.0, 2.0, 1.0],
                "mass_kg": [50.0] * 5,
                "radius_m": [0.2] * 5,
                "hmax_normal_m": [1.0, 0.5, np.nan, 0.8, np.nan],
            }
        ),
        source="impacts.csv",
    ).derive()


def test_an_impact_table_gives_release_deposit_and_along_path_points():
    obs = observations_from_impact_table(impact_table())
    assert obs.coordinates == "section"
    assert obs.path_ids() == ["A", "B"]
    a = obs.row("A")
    keys = ("release_x_m", "release_z_m", "deposit_x_m", "deposit_z_m", "mass_kg")
    assert [float(a[k]) for k in keys] == [0, 10, 15, 0, 50]
    along = obs.along_path("A")
    assert along["x_m"].tolist() == [0.0, 8.0, 15.0]
    np.testing.assert_allclose(along["vi_mps"], [5.0, 5.0, 13.0])
    np.testing.assert_allclose(along["hmax_normal_m"], [1.0, 0.5, np.nan])
    np.testing.assert_allclose(obs.straight_runout_m(), [15.0, 6.0])


def test_an_upslope_impact_path_is_refused():
    frame = impact_table().frame.copy()
    frame.loc[frame["path_id"] == "B", "z_m"] = [5.0, 9.0]
    with pytest.raises(InputFileError, match=r"^impacts.csv: path B: the last impact "
                       r"\(z = 9.00 m\) is higher than the first"):  # fmt: skip
        observations_from_impact_table(ImpactTable(frame, source="impacts.csv"))
