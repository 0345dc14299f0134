"""`fieldkit fit` on a terrain (3-D) model file: the plan fit through the CLI on a
synthetic bent-plane DEM with a known friction angle (27 deg)."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

SLOPE_DEG = 35.0
TOE_Y_M = 40.0
RELEASE_Y_M = 75.0
TRUE_FRICTION_DEG = 27.0
START_FRICTION_DEG = 15.0


def write_site(folder: Path) -> None:
    """A 35 deg plane dipping to -y onto a flat floor at y = 40 m (1 m cells, x
    0-21 m, y 0-81 m) as an ESRI ASCII grid, and a 3-D model file on it whose
    friction angle is 15 deg."""
    y = np.arange(81) + 0.5
    z = np.maximum(y - TOE_Y_M, 0.0) * math.tan(math.radians(SLOPE_DEG))
    grid = np.repeat(z[:, None], 21, axis=1)[::-1]  # row 0 north in the file
    rows = "\n".join(" ".join(f"{v:.6f}" for v in row) for row in grid)
    (folder / "dem").mkdir()
    (folder / "dem" / "plane.asc").write_text(
        "ncols 21\nnrows 81\nxllcorner 0\nyllcorner 0\ncellsize 1\n"
        f"NODATA_value -9999\n{rows}\n"
    )
    (folder / "dem" / "releases.csv").write_text("x_m,y_m\n10,75\n")
    model = {
        "terrain": {"dem": "dem/plane.asc", "materials": "ground",
                    "releases": "dem/releases.csv"},
        "materials": {"ground": {"e_n": 0.3, "e_t": 0.8,
                                 "friction_deg": START_FRICTION_DEG,
                                 "friction_deg_sd": 2.0}},
        "body": {"mass_kg": 100.0, "radius_m": 0.2},
    }  # fmt: skip
    (folder / "model3d.json").write_text(json.dumps(model))


def write_runs(folder: Path, model_file: Path, ids: range, stem: str) -> None:
    """Runs ``ids`` released across the plane, each observed as one rock of the
    true model (friction 27 deg) on a stream no fit uses."""
    from fieldkit.fit.plan_fit import PlanRun, plan_ensembles, with_parameters3d
    from fieldkit.model.model_file import read_model

    truth = with_parameters3d(
        read_model(model_file, terrain=True),
        {"materials.ground.friction_deg": TRUE_FRICTION_DEG},
    )
    runs = [
        PlanRun(f"r{i}", np.array([2.0 + 1.5 * i, RELEASE_Y_M - (i % 3)]),
                np.zeros(2), 100.0, 0.2)
        for i in ids
    ]  # fmt: skip
    ens = plan_ensembles(truth, runs, 1, 99, stream=7)
    rel = ["trajectory_id,x_m,y_m,mass_kg,radius_m"]
    dep = ["trajectory_id,x_m,y_m"]
    for r, e in zip(runs, ens.deposits_xy, strict=True):
        rel.append(f"{r.run_id},{r.release_xy[0]},{r.release_xy[1]},100,0.2")
        dep.append(f"{r.run_id},{float(e[0, 0])!r},{float(e[0, 1])!r}")
    (folder / f"{stem}_releases.csv").write_text("\n".join(rel) + "\n")
    (folder / f"{stem}_deposits.csv").write_text("\n".join(dep) + "\n")


@pytest.fixture()
def plan_site(tmp_path) -> Path:
    write_site(tmp_path)
    write_runs(tmp_path, tmp_path / "model3d.json", range(8), "cal")
    for stem in ("cal_releases", "cal_deposits"):  # r0 recorded twice, as r0b
        path = tmp_path / f"{stem}.csv"
        lines = path.read_text().splitlines()
        path.write_text("\n".join([*lines, lines[1].replace("r0,", "r0b,", 1)]) + "\n")
    write_runs(tmp_path, tmp_path / "model3d.json", range(8, 12), "hold")
    return tmp_path


def test_fit_of_a_terrain_model_recovers_friction_and_writes_a_model_simulate_runs(
    cli, plan_site, tmp_path
):
    site = plan_site
    out = tmp_path / "out"
    base_text = (site / "model3d.json").read_text()
    result = cli(
        "fit", "--model", site / "model3d.json",
        "--paths", site / "cal_releases.csv", "--deposits", site / "cal_deposits.csv",
        "--holdout-paths", site / "hold_releases.csv",
        "--holdout-deposits", site / "hold_deposits.csv",
        "--free", "materials.ground.friction_deg",
        "--bound", "materials.ground.friction_deg=5,34",
        "--rocks", "20", "--seed", "1",
        "-o", out / "calibrated_3d.json", "--json", out / "fit.json",
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr + result.stdout
    text = result.stdout
    assert "objective: mean over runs of the fair energy score" in text
    assert "note: screen" not in text and "Sobol screen 0 points (default)" in text
    assert f"wrote {out / 'calibrated_3d.json'}" in text
    assert f"wrote {out / 'fit.json'}" in text
    assert "3 fit(s) (seeds 1, 2, 3)" in text  # refitted at seeds 2 and 3
    assert "held-out comparison over 3 fits (seeds 1..3; default)" in text
    assert "runs r0 = r0b have the same release and deposit" in text
    fit = json.loads((out / "fit.json").read_text())
    friction = fit["parameters"]["materials.ground.friction_deg"]
    assert friction["start"] == START_FRICTION_DEG
    assert fit["runs"] == 8  # r0b counted once
    assert friction["value"] == pytest.approx(TRUE_FRICTION_DEG, abs=1.5)
    assert fit["objective_m"] < 0.5 * fit["objective_start_m"]
    assert (
        f"{fit['objective_start_m']:.3f} m -> optimum {fit['objective_m']:.3f}" in text
    )
    # held out: the calibrated model beats the start on energy score (paired)
    assert fit["holdout"]["seeds"] == [1, 2, 3] and fit["tracked_extent_m"] is None
    comp = {(c["b"], c["score"]): c for c in fit["holdout"]["comparisons"]}
    assert comp[("start", "energy_fair_m")]["seeds"] == [1, 2, 3]
    assert comp[("start", "energy_fair_m")]["mean_difference"] < 0
    scores = ("energy_fair_m", "distance_crps_fair_m")
    assert set(comp) == {(b, s) for b in ("start", "climatology") for s in scores}
    # what the test can show: virtual campaigns from the calibrated model (the
    # default 200); these runs have no block_id, so no block bound
    assert "200 virtual campaigns from the calibrated model measure" in text
    assert (
        "a perfect forecast (the model as the truth) against the climatology "
        "(200 virtual campaigns of 4 held-out runs)" in text
    )
    virtual = fit["holdout"]["attainable"]["virtual_campaigns"]
    assert virtual["tests"] == 200 and virtual["split_runs"] == 4
    assert 0.0 <= virtual["energy"]["pass_rate_2se"] <= 1.0
    assert "block_climatology" not in fit["holdout"]["attainable"]
    # the calibrated file: fitted value in place, terrain files relative to its
    # folder, readable there and after the folder is moved
    calibrated = json.loads((out / "calibrated_3d.json").read_text())
    assert calibrated["materials"]["ground"]["friction_deg"] == friction["value"]
    assert calibrated["terrain"]["dem"] == "../dem/plane.asc"
    assert (out / calibrated["terrain"]["dem"]).resolve() == (
        site / "dem" / "plane.asc"
    ).resolve()
    assert calibrated["terrain"]["materials"] == "ground"
    assert calibrated["provenance"]["fit"]["objective_m"] == fit["objective_m"]
    assert (site / "model3d.json").read_text() == base_text  # input untouched
    sim = cli("simulate", out / "calibrated_3d.json", "--rocks", "4", "--seed", "2",
              "--summary", out / "sim" / "summary.json")  # fmt: skip
    assert sim.exit_code == 0, sim.stderr + sim.stdout
    assert (out / "sim" / "summary.json").is_file()
    moved = tmp_path.parent / (tmp_path.name + "_moved")
    shutil.copytree(tmp_path, moved)
    again = cli("simulate", moved / "out" / "calibrated_3d.json", "--rocks", "4",
                "--seed", "2", "--summary", moved / "sim2.json")  # fmt: skip
    assert again.exit_code == 0, again.stderr + again.stdout
    first = json.loads((out / "sim" / "summary.json").read_text())
    second = json.loads((moved / "sim2.json").read_text())
    assert second["deposits"] == first["deposits"]  # the same DEM read, moved


def test_fit_of_a_terrain_model_refuses_a_dem_option_in_one_line(
    cli, plan_site, tmp_path
):
    site = plan_site
    result = cli(
        "fit", "--model", site / "model3d.json",
        "--paths", site / "cal_releases.csv", "--deposits", site / "cal_deposits.csv",
        "--dem", site / "dem" / "plane.asc", "-o", tmp_path / "c.json",
    )  # fmt: skip
    assert result.exit_code == 1  # fieldkit: an ArgumentError exits 1
    assert "--dem" in result.stderr and "terrain (3-D)" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "c.json").exists()


def test_fit_of_a_terrain_model_names_a_bad_deposit_row(cli, plan_site, tmp_path):
    site = plan_site
    bad = site / "bad_deposits.csv"
    bad.write_text((site / "cal_deposits.csv").read_text().replace("r3,", "r3,x", 1))
    result = cli(
        "fit", "--model", site / "model3d.json",
        "--paths", site / "cal_releases.csv", "--deposits", bad,
        "-o", tmp_path / "c.json",
    )  # fmt: skip
    assert result.exit_code == 1
    assert "row 5" in result.stderr and "x_m" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "c.json").exists()


def test_fit_of_a_terrain_model_names_a_held_out_release_off_the_dem(
    cli, plan_site, tmp_path
):
    site = plan_site
    bad = site / "off_releases.csv"
    lines = (site / "hold_releases.csv").read_text().splitlines()
    lines[2] = "r9,500,74,100,0.2"
    bad.write_text("\n".join(lines) + "\n")
    result = cli(
        "fit", "--model", site / "model3d.json",
        "--paths", site / "cal_releases.csv", "--deposits", site / "cal_deposits.csv",
        "--holdout-paths", bad, "--holdout-deposits", site / "hold_deposits.csv",
        "-o", tmp_path / "c.json",
    )  # fmt: skip
    assert result.exit_code == 1
    assert f"{bad}: row 3: run r9: release (x 500, y 74) is off" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert "fitting" not in result.stderr  # refused before any simulation
    assert not (tmp_path / "c.json").exists()


def test_tracked_extent_censors_rocks_at_its_edge_and_is_recorded(
    cli, plan_site, tmp_path
):
    """--tracked-extent 0,45,21,81 keeps the centres y >= 45.5 m (the rocks' end
    there: tests/fit/test_tracked_extent.py); the observed deposits below it are
    named, the extent recorded."""
    site = plan_site
    out = tmp_path / "out"
    result = cli(
        "fit", "--model", site / "model3d.json",
        "--paths", site / "cal_releases.csv", "--deposits", site / "cal_deposits.csv",
        "--free", "materials.ground.friction_deg", "--rocks", "4", "--seed", "1",
        "--tracked-extent", "0,45,21,81",
        "-o", out / "c.json", "--json", out / "fit.json",
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr + result.stdout
    assert (
        "note: tracked extent x 0.5..20.5 m, y 45.5..80.5 m (the cell centres inside "
        "x 0..21 m, y 45..81 m)" in result.stdout
    )
    assert "observed deposits outside it: r0, r1" in result.stdout
    fit = json.loads((out / "fit.json").read_text())
    assert fit["tracked_extent_m"] == [0.5, 45.5, 20.5, 80.5]


@pytest.mark.parametrize(
    ("args", "flag", "words"),
    [
        (("--tracked-extent", "0,45,21"), "--tracked-extent", "four numbers"),
        (("--tracked-extent", "5,45,1,81"), "--tracked-extent", "x_min < x_max"),
        (("--holdout-seeds", "2"), "--holdout-seeds", "needs --holdout-paths"),
        (("--virtual-campaigns", "20"), "--virtual-campaigns", "needs --holdout-paths"),
    ],
)
def test_bad_tracked_extent_or_seeds_is_one_line(cli, plan_site, tmp_path, args,
                                                  flag, words):  # fmt: skip
    site = plan_site
    result = cli(
        "fit", "--model", site / "model3d.json",
        "--paths", site / "cal_releases.csv", "--deposits", site / "cal_deposits.csv",
        *args, "-o", tmp_path / "c.json",
    )  # fmt: skip
    assert result.exit_code == 1
    assert flag in result.stderr and words in result.stderr, result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "c.json").exists()


def test_tracked_extent_is_refused_by_a_profile_fit(cli, repo, tmp_path):
    result = cli(
        "fit", "out/none.csv", "--model",
        repo / "surveys/tornado_mountain/model_rocfall_table_7_1.json",
        "--tracked-extent", "0,0,1,1", "-o", tmp_path / "c.json",
    )  # fmt: skip
    assert result.exit_code == 1
    assert "--tracked-extent" in result.stderr and "terrain (3-D)" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("value", ["1", "-3", "10001"])
def test_bad_virtual_campaigns_is_one_line(cli, plan_site, tmp_path, value):
    site = plan_site
    result = cli(
        "fit", "--model", site / "model3d.json",
        "--paths", site / "cal_releases.csv", "--deposits", site / "cal_deposits.csv",
        "--holdout-paths", site / "hold_releases.csv",
        "--holdout-deposits", site / "hold_deposits.csv",
        "--virtual-campaigns", value, "-o", tmp_path / "c.json",
    )  # fmt: skip
    assert result.exit_code == 1
    assert "--virtual-campaigns" in result.stderr and "0 or 2..10,000" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "c.json").exists()


def test_block_bound_on_runs_with_blocks_and_campaigns_off(cli, plan_site, tmp_path):
    """Runs with a block_id, every block with >= 5 runs: the block-climatology bound
    is printed and recorded; --virtual-campaigns 0 turns the campaigns off."""
    site = plan_site
    for stem in ("cal", "hold"):
        path = site / f"{stem}_releases.csv"
        lines = path.read_text().splitlines()
        out = [lines[0] + ",block_id"]
        out += [f"{line},{'ab'[i % 2]}" for i, line in enumerate(lines[1:])]
        path.write_text("\n".join(out) + "\n")
    result = cli(
        "fit", "--model", site / "model3d.json",
        "--paths", site / "cal_releases.csv", "--deposits", site / "cal_deposits.csv",
        "--holdout-paths", site / "hold_releases.csv",
        "--holdout-deposits", site / "hold_deposits.csv",
        "--free", "materials.ground.friction_deg", "--rocks", "4", "--seed", "1",
        "--holdout-seeds", "1", "--virtual-campaigns", "0",
        "-o", tmp_path / "c.json", "--json", tmp_path / "fit.json",
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr + result.stdout
    assert "virtual campaigns" not in result.stdout
    assert ("the climatology of the run's own block against the pooled one "
            "(20 repeats of 12 held-out runs)") in result.stdout  # fmt: skip
    assert "blocks: a (6), b (6)" in result.stdout
    bound = json.loads((tmp_path / "fit.json").read_text())["holdout"]["attainable"]
    assert set(bound) == {"block_climatology"}
    assert bound["block_climatology"]["split_runs"] == 4
