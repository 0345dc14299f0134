"""`fieldkit synth --survey`: virtual field campaigns as raw field files, and
`fieldkit reduce --campaign` of a whole campaign (issue 18, item 1)."""

from __future__ import annotations

import json
import shlex
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from fieldkit.campaign.design import CampaignDesign
from fieldkit.campaign.virtual import TREE_TRUTH_COLUMNS, TRUTH_COLUMNS
from fieldkit.campaign.virtual import virtual_campaign as simulate_campaign
from fieldkit.model.model_file import read_model

REPO = Path(__file__).resolve().parents[2]
MODEL = REPO / "surveys" / "tornado_mountain" / "model_rocfall_table_7_1.json"


def _synth(cli, out, *args):
    result = cli("synth", MODEL, "--survey", "-o", out, *args)
    assert result.exit_code == 0, result.stderr
    return result


def _record(folder: Path) -> dict:
    return json.loads((folder / "campaign.json").read_text())


def _all(folder: Path, kind: str) -> pd.DataFrame:
    record = _record(folder)
    frames = []
    for path in record["paths"]:
        name = path["files"][kind]
        if name is not None:
            text = {"point": str, "after_impact": str}
            frame = pd.read_csv(folder / name, dtype=text)
            frames.append(frame.assign(path_id=path["path_id"]))
    return pd.concat(frames, ignore_index=True)


def test_survey_writes_raw_files_truth_preset_and_campaign(cli, tmp_path):
    out = tmp_path / "camp"
    result = _synth(cli, out, "--paths", "3", "--seed", "1", "--tree-spacing", "8")
    record = _record(out)
    assert record["seed"] == 1 and record["model"] == str(MODEL)
    assert record["design"]["tree_spacing_m"] == 8.0
    assert record["counts"]["paths"] == 3 and len(record["paths"]) == 3
    names = {"campaign.json", "preset.toml"}
    for path in record["paths"]:
        files = path["files"]
        names |= {f for f in files.values() if f is not None}
        points = pd.read_csv(out / files["points"])
        assert list(points.columns) == ["point", "x_m", "z_m", "material"]
        truth = pd.read_csv(out / files["truth"])
        assert list(truth.columns) == list(TRUTH_COLUMNS)
        # the truth's surveyed positions are the points file's
        np.testing.assert_array_equal(truth["x_m"], points["x_m"])
        np.testing.assert_array_equal(truth["z_m"], points["z_m"])
        assert path["counts"]["scars"] == len(points) - 1
        trees = pd.read_csv(out / files["trees"])
        assert list(trees.columns) == [
            "after_impact", "horizontal_distance_m", "strike_height_m",
        ]  # fmt: skip
        assert list(pd.read_csv(out / files["trees_truth"]).columns) == list(
            TREE_TRUTH_COLUMNS
        )
        assert path["counts"]["tree_strikes"] == len(trees)
        assert path["reduce"].startswith(f"fieldkit reduce --impacts {out}/")
        # one line per path with its counts
        assert f"{path['path_id']}: {len(points) - 1} scars" in result.stdout
    assert sorted(p.name for p in out.iterdir()) == sorted(names)
    preset = (out / "preset.toml").read_text()
    for line in ("theta0_deg = 32.6", "mass_kg = 3750.0", "radius_m = 0.725",
                 "gyration_m = 0.46"):  # fmt: skip
        assert line in preset
    assert "survey: scars where m vin^2/2 >= 5000 J" in result.stdout
    assert "effects: slope_roughness (scale 1)" in result.stdout
    assert "seed 1:" in result.stdout
    wrote = [line for line in result.stdout.splitlines() if line.startswith("wrote ")]
    assert sorted(Path(line[6:]).name for line in wrote) == sorted(names)


def test_survey_is_deterministic_for_a_seed(cli, tmp_path, digest):
    out = tmp_path / "camp"
    args = ("--paths", "3", "--seed", "5", "--tree-spacing", "6",
            "--correlation-length", "20", "--effects", "rotation_friction")  # fmt: skip
    _synth(cli, out, *args)
    first = {p.name: digest(p) for p in out.iterdir()}
    # the folder holds only a campaign's files: it may be written again
    _synth(cli, out, *args)
    assert {p.name: digest(p) for p in out.iterdir()} == first
    record = _record(out)
    assert "rotation_friction" in record["hidden_effects"]
    assert record["hidden_effects"]["rotation_friction"]  # every parameter value
    _synth(cli, out, "--paths", "3", "--seed", "6")
    assert {p.name: digest(p) for p in out.iterdir()} != first


def test_a_new_campaign_replaces_a_previous_one_whole(cli, tmp_path):
    out = tmp_path / "camp"
    _synth(cli, out, "--paths", "3", "--seed", "1", "--tree-spacing", "8")
    assert (out / "path03_trees.csv").exists()
    result = _synth(cli, out, "--paths", "2", "--seed", "1")
    files = {"campaign.json", "preset.toml"}
    for path in _record(out)["paths"]:
        files |= {f for f in path["files"].values() if f is not None}
    # no trees file of the previous campaign is left to be read with this one
    assert {p.name for p in out.iterdir()} == files
    assert not any("trees" in name for name in files)
    assert "removed 8 files of a previous campaign" in result.stderr


def test_truth_is_what_the_simulation_did(cli, tmp_path):
    out = tmp_path / "camp"
    _synth(cli, out, "--paths", "4", "--seed", "11", "--scar-spacing", "3")
    # the same model, design and seed through the library: the simulated impacts
    campaign = simulate_campaign(
        read_model(MODEL), CampaignDesign(scar_spacing_m=3.0), 4,
        np.random.default_rng(11),
    )  # fmt: skip
    for path in campaign.paths:
        truth = pd.read_csv(out / f"{path.path_id}_truth.csv")
        impacts = path.impacts.frame
        scars = truth.iloc[1:]
        x_sim = impacts["x_m"].to_numpy(float)
        # each scar is a simulated impact; the next scar is `impacts_merged`
        # simulated impacts further on
        first = int(np.flatnonzero(x_sim == scars["x_true_m"].iloc[0])[0])
        steps = scars["impacts_merged"].to_numpy(int)[:-1]
        idx = first + np.concatenate([[0], np.cumsum(steps)])
        np.testing.assert_array_equal(scars["x_true_m"], x_sim[idx])
        for column, simulated in (("z_true_m", "z_m"), ("vfn_mps", "vfn_mps")):
            np.testing.assert_array_equal(
                scars[column], impacts[simulated].to_numpy(float)[idx]
            )
        assert (scars["ke_n_j"] >= 5_000.0).all()


def test_position_error_has_the_given_sd(cli, tmp_path):
    out = tmp_path / "camp"
    _synth(cli, out, "--paths", "30", "--seed", "2", "--position-sigma", "0.8",
           "--elevation-sigma", "0.3")  # fmt: skip
    truth = _all(out, "truth")
    dx = (truth["x_m"] - truth["x_true_m"]).to_numpy()
    dz = (truth["z_m"] - truth["z_true_m"]).to_numpy()
    n = len(dx)
    assert n > 300
    for err, sigma in ((dx, 0.8), (dz, 0.3)):
        sd = float(np.sqrt(np.mean(err**2)))  # the mean is 0 by design
        assert abs(sd - sigma) < 3 * sigma / np.sqrt(2 * n), (sd, sigma, n)
        assert abs(err.mean()) < 3 * sigma / np.sqrt(n)


def test_elevation_sigma_defaults_to_position_sigma(cli, tmp_path):
    out = tmp_path / "camp"
    _synth(cli, out, "--paths", "30", "--seed", "2", "--position-sigma", "0.1")
    assert _record(out)["design"]["elevation_sigma_m"] == 0.1
    truth = _all(out, "truth")
    dz = (truth["z_m"] - truth["z_true_m"]).to_numpy()
    assert abs(np.sqrt(np.mean(dz**2)) - 0.1) < 3 * 0.1 / np.sqrt(2 * len(dz))


def test_scars_are_merged_at_the_spacing(cli, tmp_path):
    out = tmp_path / "camp"
    _synth(cli, out, "--paths", "10", "--seed", "4", "--scar-spacing", "6")
    truth = _all(out, "truth")
    merged_some = False
    for _, t in truth.groupby("path_id"):
        gaps = np.diff(t["x_true_m"].to_numpy())
        assert (gaps > 6.0).all(), gaps.min()
        merged_some |= bool((t["impacts_merged"] > 1).any())
    assert merged_some  # the spacing did merge impacts


def test_tree_strike_heights_carry_the_height_error(cli, tmp_path):
    out = tmp_path / "camp"
    _synth(cli, out, "--paths", "60", "--seed", "3", "--tree-spacing", "4",
           "--height-sigma", "0.4")  # fmt: skip
    trees = _all(out, "trees")
    truth = _all(out, "trees_truth")
    np.testing.assert_array_equal(
        trees["horizontal_distance_m"], truth["horizontal_distance_m"]
    )
    err = (trees["strike_height_m"] - truth["strike_height_true_m"]).to_numpy()
    high = truth["strike_height_true_m"].to_numpy() > 2.0  # no clipping at 0.05 m
    err = err[high]
    assert err.size > 200
    sd = float(np.sqrt(np.mean(err**2)))
    assert abs(sd - 0.4) < 3 * 0.4 / np.sqrt(2 * err.size), (sd, err.size)
    # each true height is the rock's centre above the ground at the tree: the
    # trees stand between the flight's two scars
    points = _all(out, "truth")
    for row in truth.itertuples():
        p = points[points["path_id"] == row.path_id].reset_index(drop=True)
        k = int(p.index[p["point"] == row.after_impact][0])
        assert p["x_true_m"][k] < row.tree_x_true_m < p["x_true_m"][k + 1]


def test_each_path_reduces_with_its_command(cli, tmp_path):
    out = tmp_path / "camp"
    _synth(cli, out, "--paths", "3", "--seed", "1", "--tree-spacing", "8")
    record = _record(out)
    assert all(p["files"]["trees"] for p in record["paths"])
    for path in record["paths"]:
        argv = shlex.split(path["reduce"])
        assert argv[:2] == ["fieldkit", "reduce"] and "--trees" in argv
        # exactly as written: the table goes beside the campaign's folder
        table_file = tmp_path / f"camp_{path['path_id']}.csv"
        assert argv[argv.index("-o") + 1] == str(table_file)
        result = cli(*argv[1:])
        assert result.exit_code == 0, result.stderr
        table = pd.read_csv(table_file)
        assert (table["path_id"] == path["path_id"]).all()
        assert len(table) == path["counts"]["scars"] + 1
        assert (table["theta0_source"].dropna().isin(["assumed", "tree"])).all()
        assert (table["theta0_source"] == "tree").any()
        assert (table["mass_kg"] == 3750.0).all()


def test_reduce_campaign_equals_each_path_concatenated(cli, tmp_path):
    out = tmp_path / "camp"
    _synth(cli, out, "--paths", "3", "--seed", "1", "--tree-spacing", "8")
    record = _record(out)
    parts = []
    for path in record["paths"]:
        argv = shlex.split(path["reduce"])
        argv[argv.index("-o") + 1] = str(tmp_path / f"{path['path_id']}.csv")
        assert cli(*argv[1:]).exit_code == 0
        parts.append((tmp_path / f"{path['path_id']}.csv").read_text().splitlines())
    whole = tmp_path / "campaign.csv"
    result = cli("reduce", "--campaign", out, "-o", whole)
    assert result.exit_code == 0, result.stderr
    expected = [parts[0][0]] + [line for part in parts for line in part[1:]]
    assert whole.read_text().splitlines() == expected
    assert "from the campaign's preset" in result.stderr
    for path in record["paths"]:
        assert f"{path['path_id']}: " in result.stdout
    assert f"wrote {whole}" in result.stdout


def test_reduce_campaign_leaves_out_a_path_that_fails_and_says_so(cli, tmp_path):
    out = tmp_path / "camp"
    _synth(cli, out, "--paths", "3", "--seed", "2")
    (out / "path02_points.csv").write_text("point,x_m,z_m,material\n0,0,100,rock\n")
    whole = tmp_path / "campaign.csv"
    result = cli("reduce", "--campaign", out, "-o", whole)
    assert result.exit_code == 0, result.stderr
    assert "warning: path02: not reduced" in result.stderr
    assert "1 of 3 paths not reduced and left out: path02" in result.stderr
    table = pd.read_csv(whole)
    assert sorted(set(table["path_id"])) == ["path01", "path03"]
    assert "unsolved" in result.stdout  # each path's unsolved flights counted


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (("--position-sigma", "-1"), ["--position-sigma", "must be >= 0"]),
        (("--canopy", "5:3"), ["--canopy", "X0 < X1"]),
        (("--canopy", "5"), ["--canopy", "X0:X1"]),
        (("--max-scars", "1"), ["--max-scars", ">= 2"]),
        (("--theta0", "95"), ["--theta0", "between 0 and 90"]),
        (("--paths", "0"), ["--paths"]),
        (("--noise", "0.1"), ["--noise", "without --survey"]),
    ],
)
def test_bad_survey_options_are_one_line_errors(cli, fails, tmp_path, args, words):
    out = tmp_path / "camp"
    result = cli("synth", MODEL, "--survey", "--seed", "1", "--paths", "2", "-o",
                 out, *args)  # fmt: skip
    fails(result, *words)
    assert result.exit_code == 1
    assert not out.exists()


def test_a_model_whose_rocks_leave_no_scars_gives_the_library_message(cli, tmp_path):
    out = tmp_path / "camp"
    result = cli("synth", MODEL, "--survey", "--seed", "1", "--paths", "2",
                 "--scar-energy", "1e15", "-o", out)  # fmt: skip
    assert result.exit_code == 1
    lines = result.stderr.splitlines()
    # the step named on stderr (not a terminal), then the one error line
    assert lines[:-1] == ["simulating and surveying 2 rocks ..."], lines
    assert lines[-1] == (
        "error: --paths: 40 simulated rocks gave only 0 paths with at least 2 scars "
        "(m vin^2/2 >= 1e+15 J, 2 m apart): lower the scar energy or spacing, or "
        "release the rocks higher"
    )
    assert not out.exists()


def test_survey_options_need_survey_and_a_foreign_folder_is_refused(
    cli, fails, tmp_path, digest
):
    args = ("--paths", "2", "--tree-spacing", "5", "-o", tmp_path / "t.csv")
    fails(cli("synth", MODEL, *args), "--tree-spacing goes with --survey")
    folder = tmp_path / "notes"
    folder.mkdir()
    (folder / "mine.txt").write_text("keep me\n")
    before = digest(folder / "mine.txt")
    fails(
        cli("synth", MODEL, "--survey", "--paths", "2", "--seed", "1", "-o", folder),
        "mine.txt", "not empty",
    )  # fmt: skip
    assert [p.name for p in folder.iterdir()] == ["mine.txt"]
    assert digest(folder / "mine.txt") == before


def test_reduce_campaign_refuses_single_path_options(cli, fails, tmp_path):
    out = tmp_path / "camp"
    _synth(cli, out, "--paths", "2", "--seed", "1")
    fails(
        cli("reduce", "--campaign", out, "--impacts", out / "path01_points.csv"),
        "--impacts goes without --campaign",
    )
    fails(cli("reduce", "--campaign", tmp_path), "campaign.json", "file not found")


def test_reduce_campaign_options_override_the_preset(cli, tmp_path):
    out = tmp_path / "camp"
    _synth(cli, out, "--paths", "2", "--seed", "1", "--theta0", "28")
    whole = tmp_path / "campaign.csv"
    result = cli("reduce", "--campaign", out, "--theta0", "40", "--position-sigma",
                 "0.8", "-o", whole)  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert "from the command line instead: --theta0 40.0" in result.stderr
    table = pd.read_csv(whole)
    # (a release row is "assumed" with no angle: the least-speed launch)
    assumed = table.loc[table["theta0_source"] == "assumed", "theta0_deg"].dropna()
    assert len(assumed) > 5 and (assumed == 40.0).all()
    assert (table["x_sd_m"] == 0.8).all() and (table["mass_kg"] == 3750.0).all()
    # without the override the campaign's own assumed angle
    result = cli("reduce", "--campaign", out, "-o", whole)
    table = pd.read_csv(whole)
    assumed = table.loc[table["theta0_source"] == "assumed", "theta0_deg"].dropna()
    assert len(assumed) > 5 and (assumed == 28.0).all()
    assert "--theta0 28.0" in result.stderr


def test_strikes_beyond_the_surveyed_flight_are_not_recorded(cli, tmp_path):
    # 1.5 m position error and a tree every 3 m: some short flights are surveyed
    # shorter than the taped distance to their tree; such a strike cannot be
    # placed (reduce --trees refuses it), so the survey does not record it
    out = tmp_path / "camp"
    result = _synth(cli, out, "--paths", "3", "--seed", "1", "--tree-spacing", "3",
                    "--position-sigma", "1.5")  # fmt: skip
    assert "note: 2 tree strikes not recorded" in result.stderr
    # a scar the error put behind the point before it is read as that point's
    assert "note: 1 scar surveyed at or behind the point before" in result.stderr
    trees = _all(out, "trees")
    points = _all(out, "points")
    for _, p in points.groupby("path_id"):
        assert (np.diff(p["x_m"].to_numpy()) > 0).all()
    truth = _all(out, "truth")
    assert len(truth) == len(points)
    np.testing.assert_array_equal(truth["x_m"], points["x_m"])
    # the merged scar's impacts go to the one before: none is lost
    for path in _record(out)["paths"]:
        part = truth[truth["path_id"] == path["path_id"]]
        assert part["impacts_merged"].sum() == path["counts"]["impacts_merged"]
    for row in trees.itertuples():
        p = points[points["path_id"] == row.path_id].reset_index(drop=True)
        k = int(p.index[p["point"] == row.after_impact][0])
        assert 0 < row.horizontal_distance_m < p["x_m"][k + 1] - p["x_m"][k]
    assert len(_all(out, "trees_truth")) == len(trees)
    whole = tmp_path / "campaign.csv"
    result = cli("reduce", "--campaign", out, "-o", whole)
    assert result.exit_code == 0, result.stderr
    assert "not reduced" not in result.stderr
    assert sorted(set(pd.read_csv(whole)["path_id"])) == ["path01", "path02", "path03"]
