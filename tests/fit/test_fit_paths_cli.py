"""`fieldkit fit --paths`: the path-level fit from the command line, bad input."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

DATA = Path(__file__).parents[1] / "data" / "tschamut2014"
SPLIT = DATA / "calibration_split"
BASE = Path(__file__).parents[2] / "examples" / "tschamut" / "model_base.json"


@pytest.mark.slow
def test_tschamut_fit_writes_model_json_and_holdout_scores(cli, tmp_path):
    r = cli(
        "fit", "--model", BASE,
        "--paths", SPLIT / "calibration_release_points.csv",
        "--deposits", SPLIT / "calibration_observed_deposition.csv",
        "--dem", DATA / "terrain.asc",
        "--holdout-paths", SPLIT / "holdout_release_points.csv",
        "--holdout-deposits", SPLIT / "holdout_observed_deposition.csv",
        "--rocks", "40", "--bootstrap", "2",
        "-o", tmp_path / "cal.json", "--json", tmp_path / "fit.json",
        "--report", tmp_path / "rep",
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    fit = json.loads((tmp_path / "fit.json").read_text())
    assert fit["n_runs"] == 18
    assert fit["objective_optimum"] <= fit["objective_start"]
    # the slice's ends are bisected: two-sided ranges (with the README's seed 0 the
    # 9-point grid alone ended every one at the fitted value), so each parameter
    # has evidence either way
    for p in fit["parameters"]:
        lo, hi = p["interval90"]
        assert lo < p["value"] < hi and p["range_resolved"], p
    # censored runouts and stops at the release are said, and marked in the figure
    marks = fit["holdout_censoring"]
    assert marks["calibrated"]["stopped_at_release"] == {"v086": 0.475}
    assert marks["calibrated"]["left_section"] == {}
    assert marks["uncalibrated"]["left_section"]["v053"] == 0.375
    stopped = "held out, calibrated: rocks stopped within 5 m of the release: v086 48%"
    left = ("held out, uncalibrated: rocks left the section (runout censored at its "
            "end): v006 18%")  # fmt: skip
    assert stopped in r.stdout and left in r.stdout
    h = fit["holdout"]
    assert set(h) == {"calibrated", "uncalibrated", "climatology"}
    assert all(v["n_runs"] == 18 for v in h.values())
    model = json.loads((tmp_path / "cal.json").read_text())
    assert model["provenance"]["fit_paths"]["n_runs"] == 18
    assert (tmp_path / "rep" / "holdout.png").stat().st_size > 20_000
    report = (tmp_path / "rep" / "report.md").read_text()
    assert "![held-out runouts](holdout.png)" in report and "## Held-out runs" in report
    # in words with units (issue 17): no code names, sections described
    assert "| meadow: friction angle (deg) | 19.29 |" in report
    assert "sections: each run's steepest descent from its release on the DEM" in report
    assert "materials.meadow" not in report and "runout_m" not in report
    for name in ("cal.json", "fit.json", "rep/report.md", "rep/holdout.png"):
        assert f"wrote {tmp_path / name}" in r.stdout


def test_path_fit_on_a_dem_needs_all_three_inputs(cli, tmp_path):
    r = cli("fit", "--model", BASE, "--paths", SPLIT / "calibration_release_points.csv",
            "--dem", DATA / "terrain.asc", "-o", tmp_path / "m.json")  # fmt: skip
    assert r.exit_code == 1
    assert "needs --paths, --deposits and --dem" in r.output
    assert not (tmp_path / "m.json").exists()


TORNADO = Path(__file__).parents[2] / "surveys" / "tornado_mountain"


def test_surveyed_path_fit_from_an_impact_table(cli, tmp_path):
    """--paths alone: a reduced ImpactTable fitted on the model's own profile, every
    kind of along-path observation scored; the bad-input cases are one line."""
    table = tmp_path / "a.csv"
    r = cli(
        "reduce", "--impacts", TORNADO / "boulder_a_impacts.gpx",
        "--theta0", "32.6", "--mass", "3750", "--radius", "0.725",
        "--path-id", "boulder_a", "-o", table,
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    model = TORNADO / "model_rocfall_table_7_1.json"
    r = cli(
        "fit", "--paths", table, "--model", model,
        "--free", "materials.colluvium.e_t", "--rocks", "30", "--bootstrap", "2",
        "--screen", "2", "-o", tmp_path / "cal.json", "--json", tmp_path / "fit.json",
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    fit = json.loads((tmp_path / "fit.json").read_text())
    kinds = {k["kind"]: k for k in fit["kinds"]}
    assert set(kinds) == {"runout_m", "flight_height_m", "impact_spacing_m",
                          "speed_mps"}  # fmt: skip
    assert kinds["speed_mps"]["observations"] == 49  # impacts B-45 (A is the release)
    assert fit["objective_optimum"] < fit["objective_start"] == pytest.approx(4.0)
    assert fit["section"] == "the model's own profile"
    assert "flight_height_m (48 observed)" in r.output
    bad = [
        (["--bound", "materials.colluvium.e_t=0.9"], "expected NAME=LO,HI"),
        (["--holdout-paths", table, "--holdout-deposits", table], "need a DEM"),
    ]
    for extra, message in bad:
        r = cli("fit", "--paths", table, "--model", model, "-o", tmp_path / "x.json",
                *extra)  # fmt: skip
        assert r.exit_code == 1 and message in r.output, r.output
        assert not (tmp_path / "x.json").exists()


def test_mismatched_ids_one_line_nothing_written(cli, tmp_path):
    r = cli(
        "fit", "--model", BASE,
        "--paths", SPLIT / "calibration_release_points.csv",
        "--deposits", SPLIT / "holdout_observed_deposition.csv",
        "--dem", DATA / "terrain.asc", "-o", tmp_path / "m.json",
    )  # fmt: skip
    assert r.exit_code == 1
    errors = [x for x in r.output.splitlines() if x.startswith("error:")]
    assert len(errors) == 1 and "v020" in errors[0]
    assert not (tmp_path / "m.json").exists()
