"""The reduction in the loop (issue 18): a surveyed table's null and power.

The null campaigns are simulated under the fitted baseline on the path's own
profile, surveyed with the table's error and trees, reduced with its launch angle
and diagnosed; a recommendation needs the observed gain beyond their quantile.
The checks here are the mechanics (what is read back from the table, the Monte
Carlo test's threshold, the JSON and the words); the false-finding and power rates
on virtual campaigns are in ``benchmarks/bench_campaign_power.py``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from fieldkit.diagnose import survey_loop as sl
from fieldkit.impact_table import ImpactTable

REPO = Path(__file__).resolve().parents[2]
SURVEY = REPO / "surveys" / "tornado_mountain"


@pytest.fixture(scope="module")
def short_path(tmp_path_factory):
    """Boulder A's first 21 points (its cliff and the top of the colluvium) with
    their tree strikes, reduced through the command line: ``(table, folder)``."""
    from typer.testing import CliRunner

    from fieldkit.cli import app

    out = tmp_path_factory.mktemp("short")
    points = pd.read_csv(SURVEY / "boulder_a_section.csv").iloc[:21]
    points.to_csv(out / "points.csv", index=False)
    trees = pd.read_csv(SURVEY / "boulder_a_trees.csv")
    trees = trees[trees["after_impact"].isin(points["point"].iloc[:-1])]
    trees.to_csv(out / "trees.csv", index=False)
    r = CliRunner().invoke(
        app,
        [
            "reduce", "--impacts", str(out / "points.csv"), "--trees",
            str(out / "trees.csv"), "--preset",
            str(SURVEY / "boulder_a_preset.toml"), "-o", str(out / "t.csv"),
        ],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    return out / "t.csv", out


def test_loop_paths_read_back_what_the_reduction_assumed(short_path):
    table_path, _ = short_path
    table = ImpactTable.read(table_path)
    (path,), notes = sl.loop_paths(table)
    frame = table.frame
    assert path.path_id == "boulder_a"
    assert path.theta0_deg == pytest.approx(32.6)
    assert (path.mass_kg, path.radius_m, path.gyration_m) == (3750.0, 0.725, 0.46)
    assert path.position_sigma_m == 0.5 and path.elevation_sigma_m == 0.5
    assert path.strike_height_sigma_m == 0.25
    np.testing.assert_array_equal(path.x_m, frame["x_m"].to_numpy(float))
    assert path.scars == len(frame) - 1
    # the share of flights a tree strike fixed, over the flights with a known answer
    known = frame["tree_strike"].dropna().astype(bool)
    assert path.tree_share == pytest.approx(known.mean())
    assert notes == []  # the table records its error model (x_sd_m, z_sd_m)


def test_the_loop_table_stands_in_for_the_observed_one(short_path):
    table = ImpactTable.read(short_path[0])
    (path,), _ = sl.loop_paths(table)
    from fieldkit.diagnose.impacts import diagnose_impacts

    first = diagnose_impacts(table, rng=np.random.default_rng(1))
    materials, effects = sl.baseline_world(table, first.baseline.params, None)
    assert effects == {}
    for name, values in materials.items():
        assert values["e_n"] == pytest.approx(
            first.baseline.params[f"materials.{name}.e_n"]
        )
        assert values["e_n_sd"] >= sl.MIN_SCATTER
    null, rocks, failed = sl.loop_table([path], materials, {}, np.random.default_rng(3))
    frame = null.frame
    assert set(frame["path_id"]) == {"boulder_a"}
    # as many impacts as the observed path has scars (a rock's first, reduced as a
    # release, is left out; pieces are whole rocks, so at most PIECE_SCARS over)
    impacts = int((frame["vi_x_mps"].notna() & frame["vf_x_mps"].notna()).sum())
    assert path.scars - 2 * rocks <= impacts <= path.scars + sl.PIECE_SCARS
    assert rocks >= 2 and failed < rocks
    assert (frame["theta0_source"].dropna().isin(["assumed", "tree"])).all()
    # reduced with the observed table's launch angle and error model
    assumed = frame["theta0_source"].astype("string").eq("assumed").fillna(False)
    assert np.allclose(frame.loc[assumed.to_numpy(), "theta0_deg"], 32.6)
    assert np.allclose(frame["x_sd_m"].dropna(), 0.5)


def test_the_threshold_is_the_monte_carlo_tests_order_statistic():
    gains = np.random.default_rng(0).normal(size=99)
    assert sl.null_threshold(gains, 0.95) == np.sort(gains)[94]
    assert sl.null_threshold(gains[:19], 0.95) == gains[:19].max()
    assert sl.null_threshold(gains[:10], 0.95) == math.inf


def test_null_and_power_through_the_command_line(short_path, cli):
    table, out = short_path
    js = out / "d.json"
    r = cli("diagnose", table, "--seed", "4", "--null", "19", "--power", "1",
            "--workers", "1", "--no-sensitivity", "--json", js,
            "--report", out / "rep")  # fmt: skip
    assert r.exit_code == 0, r.output
    d = json.loads(js.read_text())
    null = d["null"]
    assert null["size"] == 19 and null["quantile"] == 0.95  # failed ones replaced
    gains = [g for g in null["gains"] if g is not None]
    # 19 null gains at q = 0.95: the threshold is their largest (ceil(0.95 * 20) = 19)
    if null["size"] == 19:
        assert null["threshold"] == pytest.approx(max(gains))
    exceed = sum(g >= null["observed_gain"] for g in gains)
    assert null["p_value"] == pytest.approx((1 + exceed) / (len(gains) + 1))
    assert null["observed_gain"] == pytest.approx(
        max(c["improvement"] for c in d["candidates"])
    )
    # a recommendation needs the gain beyond the null's threshold
    for c in d["candidates"]:
        if c["meaningful"]:
            assert c["improvement"] > null["threshold"]
    assert set(d["power"]) == {c["effect"] for c in d["candidates"]}
    for entry in d["power"].values():
        assert entry["campaigns"] + entry["failed"] == 1
    text = " ".join(r.stdout.split())
    assert "null: 19 effect-free campaigns" in text or "could not be made" in text
    assert "verdict: " in text and "power: with this survey" in text
    report = (out / "rep" / "report.md").read_text()
    assert "## The null and the power" in report


def test_loop_options_are_checked_in_one_line(short_path, cli, fails, tmp_path):
    table, _ = short_path
    def run(*args):
        return cli("diagnose", table, "--seed", "1", *args)

    fails(run("--null", "10"), "--null", "at least 19")
    fails(run("--null-quantile", "1.2"), "--null-quantile")
    fails(run("--power", "-1"), "--power")
    fails(run("--workers", "0"), "--workers")
    synthetic = tmp_path / "s.csv"
    r = cli("synth", SURVEY / "model_rocfall_table_7_1.json", "--paths", "3",
            "--seed", "1", "-o", synthetic)  # fmt: skip
    assert r.exit_code == 0, r.output
    fails(cli("diagnose", synthetic, "--seed", "1", "--null", "19"), "--null",
          "reduced survey", "vin_sd_mps")  # fmt: skip


def test_several_tables_are_diagnosed_together_each_path_once(short_path, cli, fails):
    table, out = short_path
    r = cli("diagnose", table, table, "--seed", "1", "--null", "0")
    fails(r, "TABLE_OR_TRACK", "boulder_a", "once")


def test_a_release_alone_is_not_an_assumed_angle(cli, tmp_path):
    """Ehime's rebound angles were all measured; only its release flight is
    "assumed" (the least-speed launch, no theta0): no null, no sensitivity."""
    table = tmp_path / "ehime.csv"
    section = REPO / "surveys" / "ehime" / "cube_section.csv"
    r = cli("reduce", "--impacts", section, "--mass", "520", "--radius", "0.3",
            "--gyration", "0.245", "-o", table)  # fmt: skip
    assert r.exit_code == 0, r.output
    js = tmp_path / "d.json"
    r = cli("diagnose", table, "--seed", "1", "--json", js)
    assert r.exit_code == 0, r.output
    d = json.loads(js.read_text())
    assert d["null"] is None and d["sensitivity"] == []
    assert "null:" not in r.stdout
