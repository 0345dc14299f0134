"""Issue 20 (H2) through the command line: suspect data -- impacts the reduction
flags (energy_gained, e_t_above_1) and flights on an assumed θ0 -- kept, weighted
or excluded by --flagged / --assumed-theta0, and the leave-out refits."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

TORNADO = Path(__file__).parents[2] / "surveys" / "tornado_mountain"
PRESET = TORNADO / "boulder_a_preset.toml"
PATH_START = TORNADO / "model_path_start.json"
REDUCE = (
    "reduce", "--impacts", TORNADO / "boulder_a_impacts.gpx",
    "--trees", TORNADO / "boulder_a_trees.csv",
)  # fmt: skip
#: A small path fit of boulder A (one parameter, few rocks, no screen/bootstrap).
SMALL = ("--free", "materials.colluvium.e_t", "--rocks", "10", "--screen", "0",
         "--bootstrap", "0", "--seed", "3")  # fmt: skip
TRUE_EN, TRUE_ET = 0.4, 0.7
CORRUPTED = [4, 11, 19]




@pytest.fixture()
def corrupted(tmp_path) -> tuple[Path, Path]:
    """A table of 30 impacts of one rock with known e_n = 0.4, e_t = 0.7 (5 %
    scatter) on level ground, three of them corrupted to gain energy (e_n 1.3,
    e_t 1.4: flagged energy_gained and e_t_above_1); and its model."""
    rng = np.random.default_rng(5)
    n = 30
    vin, vit = -rng.uniform(4, 12, n), rng.uniform(3, 10, n)
    vfn = TRUE_EN * -vin * (1 + 0.05 * rng.standard_normal(n))
    vft = TRUE_ET * vit * (1 + 0.05 * rng.standard_normal(n))
    vfn[CORRUPTED], vft[CORRUPTED] = 1.3 * -vin[CORRUPTED], 1.4 * vit[CORRUPTED]
    table = tmp_path / "impacts.csv"
    pd.DataFrame({
        "path_id": "p", "point": [f"i{i}" for i in range(n)],
        "x_m": np.arange(n) * 5.0, "z_m": 100 - np.arange(n) * 3.0,
        "slope_deg": 0.0, "material": "rock", "mass_kg": 100.0, "radius_m": 0.2,
        "gyration_m": 0.126, "vi_x_mps": vit, "vi_z_mps": vin, "vf_x_mps": vft,
        "vf_z_mps": vfn,
    }).to_csv(table, index=False)  # fmt: skip
    model = tmp_path / "model.json"
    model.write_text(json.dumps({
        "profile": {"x_m": [0, 50], "z_m": [30, 0], "material": "rock"},
        "materials": {"rock": {"e_n": 0.5, "e_t": 0.8, "friction_deg": 30}},
        "body": {"mass_kg": 100, "radius_m": 0.2}, "seeder": {"x_m": 0, "z_m": 31},
    }))  # fmt: skip
    return table, model


def _fitted(path: Path) -> dict:
    fit = json.loads(path.read_text())["provenance"]["fit"]
    return {k: v["value"] for k, v in fit["parameters"].items()}


def test_excluding_corrupted_impacts_recovers_the_truth(cli, tmp_path, corrupted,
                                                        digest):  # fmt: skip
    table, model = corrupted
    before = digest(table)
    errors, values = {}, {}
    for option in ("keep", "0.2", "exclude"):
        out = tmp_path / f"cal_{option}.json"
        r = cli("fit", table, "--model", model, "--flagged", option, "-o", out)
        assert r.exit_code == 0, r.output
        v = _fitted(out)
        values[option] = (v["materials.rock.e_n"], v["materials.rock.e_t"])
        errors[option] = (abs(values[option][0] - TRUE_EN),
                          abs(values[option][1] - TRUE_ET))  # fmt: skip
        words = {"keep": "kept", "0.2": "weighted 0.2", "exclude": "excluded"}[option]
        assert (
            "suspect data: flagged: 3 impacts flagged (energy_gained 3, e_t_above_1 "
            f"3, points i4, i11, i19): {words} (--flagged {option})"
        ) in r.stdout
        assert f"wrote {out}" in r.stdout
        suspect = json.loads(out.read_text())["provenance"]["fit"]["suspect"]
        assert suspect["policy"] == {"flagged": option, "assumed_theta0": "keep"}
        assert suspect["counts"]["impacts"]["flagged_points"] == ["i4", "i11", "i19"]
    # kept, the three corrupted impacts pull e_n and e_t up by several percent;
    # excluded, the fit recovers the truth within the scatter; weighted, between
    assert errors["keep"][0] > 0.02 and errors["keep"][1] > 0.06
    assert errors["exclude"][0] < 0.01 and errors["exclude"][1] < 0.01
    for k in (0, 1):
        assert values["exclude"][k] < values["0.2"][k] < values["keep"][k]
        assert errors["0.2"][k] < errors["keep"][k]
    out = tmp_path / "cal_0.2.json"
    fit = json.loads(out.read_text())["provenance"]["fit"]
    assert "3 suspect impact(s) weighted" in fit["weighting"]
    # the default's leave-flagged-out refit is the --flagged exclude fit
    kept = json.loads((tmp_path / "cal_keep.json").read_text())["provenance"]["fit"]
    flagged_out = kept["suspect"]["leave_out"][0]
    assert flagged_out["variant"] == "flagged out" and flagged_out["refitted"]
    assert flagged_out["dropped"] == {"impacts": 3}
    excluded = _fitted(tmp_path / "cal_exclude.json")
    for p in flagged_out["parameters"]:
        assert p["refitted"] == pytest.approx(excluded[p["name"]], abs=1e-6)
        assert p["shift"] == pytest.approx(p["refitted"] - p["full"])
        assert p["shift_in_stderr"] == pytest.approx(p["shift"] / p["full_stderr"])
    # no launch angle was assumed: nothing to leave out, and it says so
    assumed_out = kept["suspect"]["leave_out"][1]
    assert not assumed_out["refitted"]
    assert assumed_out["reason"].startswith("no impact resting on an assumed")
    assert "assumed θ0 out: dropped 0; not refitted" in r.stdout
    assert digest(table) == before


@pytest.mark.parametrize(
    ("option", "value"),
    [("--flagged", "1.5"), ("--flagged", "0"), ("--flagged", "drop"),
     ("--assumed-theta0", "nan"), ("--assumed-theta0", "-0.5")],
)  # fmt: skip
def test_bad_suspect_values_one_line_nothing_written(cli, tmp_path, corrupted, fails,
                                                     option, value):  # fmt: skip
    table, model = corrupted
    out = tmp_path / "cal.json"
    r = cli("fit", table, "--model", model, option, value, "-o", out)
    fails(r, option, "keep, exclude or a weight in (0, 1)", value)
    assert not out.exists()


def test_impact_fit_of_boulder_a_without_assumed_flights_is_too_small(
    cli, tmp_path, boulder_a
):
    """Boulder A's impact fit: 43 of its 48 impacts rest on an assumed θ0 (their
    arriving or leaving flight); excluding them leaves rock one impact: refused
    in one line that says why, nothing written. Kept (the default), the
    leave-out refit holds rock at the full fit and refits the colluvium."""
    out = tmp_path / "cal.json"
    table = ("fit", boulder_a, "--model", TORNADO / "model_rocfall_table_7_1.json",
             "--preset", PRESET)  # fmt: skip
    r = cli(*table, "--assumed-theta0", "exclude", "-o", out)
    assert r.exit_code == 1 and "Traceback" not in r.stderr
    errors = [x for x in r.stderr.splitlines() if x.startswith("error: ")]
    assert len(errors) == 1 and errors == r.stderr.splitlines()[-1:]  # after notes
    assert "material rock has 1 impact" in errors[0]
    assert "(43 suspect impacts left out: --assumed-theta0 exclude)" in errors[0]
    assert not out.exists()
    r = cli(*table, "-o", out)
    assert r.exit_code == 0, r.output
    assert (
        "suspect data: flagged: 4 impacts flagged (energy_gained 3, e_t_above_1 3, "
        "points 22, 27, 32, 42): kept (--flagged keep)"
    ) in r.stdout
    line = next(x for x in r.stdout.splitlines() if "assumed θ0 out: dropped" in x)
    assert line.strip().startswith("assumed θ0 out: dropped 43;")
    assert line.endswith("; held at the full fit: rock (1 impact left)")
    leave = json.loads(out.read_text())["provenance"]["fit"]["suspect"]["leave_out"]
    assert [v["dropped"] for v in leave] == [{"impacts": 4}, {"impacts": 43}]
    assert leave[1]["held"] == ["materials.rock.e_n", "materials.rock.e_t"]
    rock = leave[1]["parameters"][0]
    assert rock["refitted"] == rock["full"] and rock["shift"] == 0.0


def test_path_fit_drops_exactly_the_values_named(cli, tmp_path, boulder_a):
    """Boulder A: 4 impacts flagged (22, 27, 32, 42) -> their 8 flights' heights
    and the speeds those flights give are dropped; 33 flights on an assumed θ0
    give 33 heights and 34 speeds (the first flight, from the source, is the
    least-speed launch and gives no scar-to-scar height). Spacings and the runout
    rest on no θ0 and stay."""
    counts = {}
    for option, value in (("--flagged", "exclude"), ("--assumed-theta0", "exclude"),
                          ("--flagged", "keep")):  # fmt: skip
        js = tmp_path / f"fit{option}{value}.json"
        r = cli("fit", "--paths", boulder_a, "--model", PATH_START, "--preset",
                PRESET, *SMALL, option, value, "--no-leave-out",
                "-o", tmp_path / "cal.json", "--json", js)  # fmt: skip
        assert r.exit_code == 0, r.output
        fit = json.loads(js.read_text())
        counts[option, value] = {k["kind"]: k["observations"] for k in fit["kinds"]}
        assert "leave-out refits skipped (--no-leave-out)" in r.stdout
        assert fit["suspect"]["leave_out"] == []
    assert counts["--flagged", "keep"] == {
        "runout_m": 1, "flight_height_m": 48, "impact_spacing_m": 48,
        "speed_mps": 49,
    }  # fmt: skip
    assert counts["--flagged", "exclude"] == {
        "runout_m": 1, "flight_height_m": 40, "impact_spacing_m": 48,
        "speed_mps": 41,
    }  # fmt: skip
    assert counts["--assumed-theta0", "exclude"] == {
        "runout_m": 1, "flight_height_m": 15, "impact_spacing_m": 48,
        "speed_mps": 15,
    }  # fmt: skip
    # which ones: the library view of the same run
    from fieldkit.fit.path_along import observed_along
    from fieldkit.fit.path_runs import section_runs
    from fieldkit.fit.suspect import EXCLUDE, SuspectPolicy
    from fieldkit.impact_table import ImpactTable
    from fieldkit.io.path_observations import observations_from_impact_table
    from fieldkit.model.model_file import read_model

    table = ImpactTable.read(boulder_a)
    frame = table.frame
    flagged = frame["qa_flags"].fillna("").str.contains("energy_gained|e_t_above_1")
    assert frame.loc[flagged, "point"].astype(str).tolist() == ["22", "27", "32", "42"]
    run = section_runs(observations_from_impact_table(table),
                       read_model(PATH_START))[0]  # fmt: skip
    full = observed_along(run)
    out = observed_along(run, SuspectPolicy(flagged=EXCLUDE))
    x0 = float(frame["x_m"].iloc[0])
    chainage = dict(zip(frame["point"].astype(str), frame["x_m"] - x0, strict=True))
    dropped = sorted(set(full.speed_chainage_m) - set(out.speed_chainage_m))
    named = [chainage[p] for p in ("22", "23", "27", "28", "32", "33", "42", "43")]
    np.testing.assert_allclose(dropped, sorted(named))
    # the 18 m/s arrival at the bench (point 43) follows flagged impact 42
    at_43 = full.values["speed_mps"][full.speed_chainage_m == chainage["43"]]
    assert at_43 == pytest.approx([17.875], abs=1e-3)
    assert not np.isclose(out.values["speed_mps"], 17.875, atol=1e-3).any()
    # a table written without its qa_flags column gives the same markers (the
    # flags are recomputed from its velocities)
    bare = tmp_path / "bare.csv"
    pd.read_csv(boulder_a).drop(columns=["qa_flags"]).to_csv(bare, index=False)
    along = observations_from_impact_table(ImpactTable.read(bare)).along
    before = observations_from_impact_table(table).along
    for column in ("vi_mps_flags", "hmax_normal_m_flags"):
        assert (along[column] > 0).sum() == 8
        np.testing.assert_array_equal(along[column], before[column])


def test_weighted_and_excluded_together_on_a_path(cli, tmp_path, boulder_a):
    """--flagged 0.5 --assumed-theta0 exclude: the 33 heights and 34 speeds on an
    assumed θ0 are dropped; of the 8 + 8 flagged, the 4 + 4 on tree-fixed flights
    are weighted; the leave-flagged-out refit drops those 8 more, and the assumed
    one is not run again (already excluded). Said in the JSON, the console and
    report.md (in words)."""
    js, rep = tmp_path / "fit.json", tmp_path / "rep"
    r = cli("fit", "--paths", boulder_a, "--model", PATH_START, "--preset", PRESET,
            *SMALL, "--flagged", "0.5", "--assumed-theta0", "exclude",
            "-o", tmp_path / "cal.json", "--json", js, "--report", rep)  # fmt: skip
    assert r.exit_code == 0, r.output
    fit = json.loads(js.read_text())
    kinds = {k["kind"]: k["observations"] for k in fit["kinds"]}
    assert kinds["flight_height_m"] == 15 and kinds["speed_mps"] == 15
    counts = fit["suspect"]["counts"]
    for kind in ("flight_height_m", "speed_mps"):
        assert counts[kind]["weighted"] == 4 and counts[kind]["kept"] == 11
    assert fit["suspect"]["policy"] == {"flagged": "0.5", "assumed_theta0": "exclude"}
    flagged_out, assumed_out = fit["suspect"]["leave_out"]
    assert flagged_out["refitted"]
    assert flagged_out["dropped"] == {"flight_height_m": 4, "speed_mps": 4}
    assert sum(flagged_out["dropped_by_flag"].values()) > 0
    assert assumed_out["reason"] == "already excluded in the fit"
    assert any(n.startswith("suspect data: flagged: 16 observed values")
               and n.endswith("weighted 0.5") for n in fit["notes"])  # fmt: skip
    assert "rest on an assumed launch angle: excluded (--assumed-theta0 exclude)" in (
        r.stdout
    )
    report = (rep / "report.md").read_text()
    assert "weighted 0.5 (--flagged 0.5)" in report
    assert "flight_height_m" not in report and "```" not in report


def test_default_keeps_every_result_identical(cli, tmp_path, boulder_a):
    """The default (keep) fits exactly what a table without any markers fits: the
    CLI's values, objective and kinds equal a library fit on runs whose suspect
    markers are removed."""
    from fieldkit.fit.material_map import map_materials
    from fieldkit.fit.path_fit import fit_paths
    from fieldkit.fit.path_runs import section_runs
    from fieldkit.impact_table import ImpactTable
    from fieldkit.io.path_observations import observations_from_impact_table
    from fieldkit.io.preset import read_preset
    from fieldkit.model.model_file import read_model

    js = tmp_path / "fit.json"
    r = cli("fit", "--paths", boulder_a, "--model", PATH_START, "--preset", PRESET,
            *SMALL, "--no-leave-out", "-o", tmp_path / "cal.json",
            "--json", js)  # fmt: skip
    assert r.exit_code == 0, r.output
    fit = json.loads(js.read_text())
    base = read_model(PATH_START)
    preset = read_preset(PRESET)
    mapped = map_materials(ImpactTable.read(boulder_a), list(base.materials),
                           preset=preset.materials, preset_source="p")  # fmt: skip
    runs = section_runs(observations_from_impact_table(mapped.table.derive()), base)
    for run in runs:
        for key in [k for k in run.observations if k.endswith(("_flags", "_assumed"))]:
            del run.observations[key]
    plain = fit_paths(runs, base, ["materials.colluvium.e_t"], rocks=10, seed=3,
                      bootstrap=0, screen=0)  # fmt: skip
    assert fit["parameters"][0]["value"] == float(plain.values[0])
    assert fit["objective_optimum"] == plain.objective_optimum
    assert fit["n_evaluations"] == plain.n_evaluations
    assert [k["crps_optimum"] for k in fit["kinds"]] == [
        plain.kind_optimum[k] for k in plain.kinds
    ]


def test_leave_out_table_on_boulder_a(cli, tmp_path, boulder_a):
    js, rep = tmp_path / "fit.json", tmp_path / "rep"
    r = cli("fit", "--paths", boulder_a, "--model", PATH_START, "--preset", PRESET,
            *SMALL, "-o", tmp_path / "cal.json", "--json", js,
            "--report", rep)  # fmt: skip
    assert r.exit_code == 0, r.output
    out = r.stdout
    assert (
        "suspect data: flagged: 16 observed values (flight_height_m 8, speed_mps 8) "
        "rest on the flights of impacts flagged energy_gained or e_t_above_1 "
        "(energy_gained 12, e_t_above_1 12): kept (--flagged keep)"
    ) in out
    assert (
        "suspect data: assumed θ0: 67 observed values (flight_height_m 33, "
        "speed_mps 34) rest on an assumed launch angle: kept (--assumed-theta0 keep)"
    ) in out
    assert "leave-out refits (one search each from the calibrated values" in out
    assert "flagged out: dropped 16 (flight_height_m 8, speed_mps 8)" in out
    assert "assumed θ0 out: dropped 67 (flight_height_m 33, speed_mps 34)" in out
    suspect = json.loads(js.read_text())["suspect"]
    assert [v["variant"] for v in suspect["leave_out"]] == [
        "flagged out", "assumed θ0 out"]  # fmt: skip
    fitted = json.loads(js.read_text())["parameters"][0]["value"]
    for variant in suspect["leave_out"]:
        assert variant["refitted"] and variant["evaluations"] > 10
        (p,) = variant["parameters"]
        assert p["name"] == "materials.colluvium.e_t" and p["full"] == fitted
        assert p["shift"] == pytest.approx(p["refitted"] - fitted)
        assert p["shift_in_stderr"] is None  # no bootstrap: no standard error
        assert variant["objective_refit"] <= variant["objective_full"]
    assert suspect["leave_out"][0]["dropped_by_flag"] == {
        "energy_gained": 12, "e_t_above_1": 12}  # fmt: skip
    assert "## Suspect data" in (rep / "report.md").read_text()
    for path in (tmp_path / "cal.json", js, rep / "report.md"):
        assert f"wrote {path}" in out
