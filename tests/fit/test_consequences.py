"""Issue 20, H1: design quantities at the analysis points, the unconservative
verdicts, the analysis_points block of the model file and [[measured]] in a preset,
through the library and the command line."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from fieldkit.fit.consequences import DESIGN_STREAM, design_quantities
from fieldkit.measured import Measured
from fieldkit.model.model_file import model_from_dict, read_model

TORNADO = Path(__file__).parents[2] / "surveys" / "tornado_mountain"
PRESET = TORNADO / "boulder_a_preset.toml"
TABLE_7_1 = TORNADO / "model_rocfall_table_7_1.json"
PATH_START = TORNADO / "model_path_start.json"
G = 9.81
#: A 30 m drop on a 45 deg slope, then a flat; released at rest 1 m above it, 2 m/s.
SLOPE = {
    "profile": {"x_m": [0, 30, 60], "z_m": [30, 0, 0], "material": ["rock", "rock"]},
    "materials": {"rock": {"e_n": 0.4, "e_t": 0.8, "friction_deg": 30,
                           "e_n_sd": 0.05}},
    "body": {"mass_kg": 100, "radius_m": 0.2},
    "seeder": {"x_m": 0.5, "z_m": 31.0, "vx_mps": 2.0, "vz_mps": 0.0},
}  # fmt: skip
#: Boulder A's path fit of examples/calibrate_tornado_mountain.py, small.
PATH_FREE = {
    "materials.colluvium.e_n": (0.2, 2.0),
    "materials.colluvium.e_t": (0.3, 0.98),
    "velocity_scaled_restitution.k_mps": (2.0, 30.0),
    "materials.bench.e_n": (0.05, 1.2),
    "materials.bench.e_t": (0.1, 0.98),
}


def _slope(**seeder):
    data = json.loads(json.dumps(SLOPE))
    data["seeder"].update(seeder)
    return model_from_dict(data, source="slope.json")


def test_a_speed_energy_conservation_forbids_is_unconservative_one_below_p50_is_not():
    model = _slope()
    x = 20.0
    # no rock can be faster at x than free fall from its release to the ground
    # there: 1/2 v^2 <= 1/2 v0^2 + g (z0 - z_ground(x)) (e_n, e_t < 1 lose energy)
    v_bound = math.sqrt(2.0**2 + 2 * G * (31.0 - 10.0))
    c = design_quantities({"calibrated": model}, [x], [], rocks=400, seed=3)
    speed = c.points[0].models["calibrated"].quantities["speed_mps"]
    assert speed["max"] <= v_bound
    assert c.points[0].models["calibrated"].passing == 400
    above, below = 1.2 * v_bound, 0.5 * speed["p50"]
    c = design_quantities(
        {"calibrated": model}, [x],
        [Measured(x, speed_mps=above, source="test"), Measured(x, speed_mps=below)],
        rocks=400, seed=3,
    )  # fmt: skip
    verdicts = c.verdicts()
    assert len(verdicts) == 1, verdicts
    assert verdicts[0].startswith(
        f"unconservative: measured {above:.3g} m/s (speed) at x = 20 m lies above "
        "every one of the 400 crossing rocks of the calibrated model"
    )
    assert verdicts[0].endswith("[measured: test]")
    ranks = c.points[0].models["calibrated"].ranks
    assert ranks[0]["speed_mps"]["beyond"] == "above"
    low = ranks[1]["speed_mps"]
    assert low["beyond"] == "below" or low["percentile"] < 50


def test_above_p99_is_unconservative_between_p95_and_p99_a_note():
    model = _slope(vx_sd_mps=0.5)
    first = design_quantities({"m": model}, [20.0], [], rocks=1000, seed=1)
    d = first.points[0].models["m"].quantities["ke_j"]
    assert d["p95"] < d["p99"] < d["max"]
    between, over = (d["p95"] + d["p99"]) / 2, (d["p99"] + d["max"]) / 2
    c = design_quantities(
        {"m": model}, [20.0],
        [Measured(20.0, ke_j=between), Measured(20.0, ke_j=over)],
        rocks=1000, seed=1,
    )  # fmt: skip
    assert c.points[0].models["m"].quantities == first.points[0].models["m"].quantities
    unconservative, note = c.verdicts()
    assert unconservative.startswith("unconservative: ") and "above the p99 of" in (
        unconservative
    )
    assert f"({d['p99'] / 1e3:.3g} ± " in unconservative
    assert note.startswith("note: ") and "above the p95 of the m model" in note


def test_no_rock_reaching_the_point_is_unconservative():
    model = _slope()
    c = design_quantities(
        {"m": model}, [59.9], [Measured(59.9, speed_mps=1.0)], rocks=50, seed=0
    )
    assert c.points[0].models["m"].passing == 0
    assert c.verdicts() == [
        "unconservative: no rock of the m model reaches x = 59.9 m; the measured "
        "rock did"
    ]


def test_monte_carlo_se_shrinks_as_one_over_root_n():
    model = _slope(vx_sd_mps=0.5)
    se = {}
    for rocks in (400, 6400):
        c = design_quantities({"m": model}, [20.0], [], rocks=rocks, seed=5)
        d = c.points[0].models["m"]
        se[rocks] = (d.quantities["speed_mps"]["se"]["p50"], d.passing_fraction_se)
    ratio = se[400][0] / se[6400][0]
    assert 2.5 < ratio < 6.0, ratio  # sqrt(16) = 4


def test_common_random_numbers_on_a_stream_of_their_own():
    from fieldkit.model.simulate import simulate

    model = _slope(vx_sd_mps=0.5)
    c = design_quantities({"start": model, "calibrated": model}, [20.0], [],
                          rocks=300, seed=2)  # fmt: skip
    a, b = (c.points[0].models[n] for n in ("start", "calibrated"))
    assert a == b
    assert c.runout["start"] == c.runout["calibrated"]
    # the same numbers as simulating on default_rng([seed, DESIGN_STREAM]), and not
    # those of the calibration's streams default_rng([seed, run index])
    own = simulate(model, 300, np.random.default_rng([2, DESIGN_STREAM]),
                   analysis_x_m=[20.0])  # fmt: skip
    calibration = simulate(model, 300, np.random.default_rng([2, 0]),
                           analysis_x_m=[20.0])  # fmt: skip
    speed = own.analysis[0].speed_mps[own.analysis[0].crossed]
    assert a.quantities["speed_mps"]["p50"] == float(np.percentile(speed, 50))
    other = calibration.analysis[0].speed_mps[calibration.analysis[0].crossed]
    assert a.quantities["speed_mps"]["p50"] != float(np.percentile(other, 50))


def test_analysis_points_round_trip(tmp_path):
    from fieldkit.model.model_file import write_model

    model = read_model(PATH_START)
    assert [(p.x_m, p.name) for p in model.analysis_points] == [
        (610.0, "railway bench")
    ]
    out = tmp_path / "again.json"
    write_model(model.with_parameters({"materials.bench.e_n": 0.5}), out)
    data = json.loads(out.read_text())
    assert data["analysis_points"] == [{"x_m": 610.0, "name": "railway bench"}]
    assert read_model(out).analysis_points == model.analysis_points


@pytest.mark.parametrize(
    ("block", "words"),
    [
        ({"x_m": 610}, ["analysis_points", "must be a list"]),
        ([{"x_m": 900}], ["analysis_points[0].x_m", "900"]),
        ([{"name": "a"}], ["analysis_points[0].x_m", "missing"]),
        ([{"x_m": 10, "at": 2}], ["analysis_points[0].at", "unknown field"]),
        ([{"x_m": 10}, {"x_m": 10}], ["analysis_points[1].x_m", "given twice"]),
        ([{"x_m": 10, "name": 3}], ["analysis_points[0].name", "must be text"]),
    ],
)
def test_a_bad_analysis_points_block_is_one_line(cli, fails, tmp_path, block, words):
    data = json.loads(TABLE_7_1.read_text())
    data["analysis_points"] = block
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    r = cli("simulate", bad, "--rocks", "10", "--seed", "1")
    fails(r, str(bad), *words)
    assert r.exit_code == 1


def test_simulate_without_at_uses_the_models_points(cli, tmp_path):
    summary = tmp_path / "s.json"
    r = cli("simulate", TABLE_7_1, "--rocks", "200", "--seed", "1",
            "--measured", "x=610,speed=18,total=690e3",
            "--summary", summary)  # fmt: skip
    assert r.exit_code == 0, r.output
    assert (
        "--at not given: analysis points from the model file, x = 610 m "
        "(railway bench)" in r.stderr
    )
    s = json.loads(summary.read_text())
    assert [p["x_m"] for p in s["analysis_points"]] == [610.0]
    assert s["measured"][0]["total_j"]["measured"] == 690e3
    assert "total energy KE+RE 690 kJ" in r.stdout
    assert f"wrote {summary}" in r.stdout
    # a model without the block: no point, as before
    data = json.loads(TABLE_7_1.read_text())
    del data["analysis_points"]
    bare = tmp_path / "bare.json"
    bare.write_text(json.dumps(data))
    r = cli("simulate", bare, "--rocks", "50", "--seed", "1", "--summary", summary)
    assert r.exit_code == 0, r.output
    assert json.loads(summary.read_text())["analysis_points"] == []
    assert "--at not given" not in r.stderr




def test_path_fit_prints_the_verdict_first(cli, tmp_path, boulder_a):
    """Boulder A's path fit (small): the measured 600 kJ at x = 610 m against the
    calibrated model, said before anything else, with the numbers of fit.json."""
    free = []
    for name, (lo, hi) in PATH_FREE.items():
        free += ["--free", name, "--bound", f"{name}={lo},{hi}"]
    out, js, report = tmp_path / "cal.json", tmp_path / "fit.json", tmp_path / "rep"
    r = cli("fit", "--paths", boulder_a, "--model", PATH_START, "--preset", PRESET,
            *free, "--rocks", "60", "--screen", "0", "--bootstrap", "0", "--seed", "1",
            "--design-rocks", "1000", "-o", out, "--json", js,
            "--report", report)  # fmt: skip
    assert r.exit_code == 0, r.output
    design = json.loads(js.read_text())["design"]
    # the leave-out refits (suspect data) beside the start and the calibrated model
    assert design["models"] == ["start", "calibrated", "flagged out", "assumed θ0 out"]
    assert (design["rocks"], design["seed"]) == (1000, 1)
    (point,) = design["points"]
    assert (point["x_m"], point["name"]) == (610.0, "railway bench")
    assert point["measured"] == [
        {"x_m": 610.0, "speed_mps": 18.0, "ke_j": 600e3, "source": "thesis §7.5.4"}
    ]
    calibrated = point["models"]["calibrated"]
    ke = calibrated["ke_j"]
    # today the measured 600 kJ lies above the calibrated model's p99 at 610 m
    assert ke["p99"] < 600e3
    rank = calibrated["measured_rank"][0]["ke_j"]
    lines = r.stdout.splitlines()
    verdict = next(v for v in design["verdicts"] if "kJ" in v and "calibrated" in v)
    assert verdict.startswith("unconservative: measured 600 kJ (translational KE) "
                              "at x = 610 m lies above ")  # fmt: skip
    if rank["beyond"] == "above":
        assert (f"every one of the {rank['n']:,} crossing rocks of the calibrated "
                f"model (their maximum {rank['simulated_max'] / 1e3:.3g} kJ)"
                in verdict)  # fmt: skip
    else:
        assert f"the p99 of the calibrated model ({ke['p99'] / 1e3:.3g} ± " in verdict
    # the verdicts first, before the table and the fitted parameters
    n = len(design["verdicts"])
    assert lines[:n] == design["verdicts"]
    assert all(v.startswith("unconservative: ") for v in lines[:n])
    first_parameter = next(i for i, line in enumerate(lines)
                           if line.startswith("materials.colluvium.e_n:"))  # fmt: skip
    table = n + 3  # the point line, the header and a blank line before it
    assert lines[n] == ("--at not given: design quantities at the model's analysis "
                        "points x = 610 m (railway bench)")  # fmt: skip
    assert lines[table].startswith("x = 610 m (railway bench)")
    assert table < first_parameter
    text = (report / "report.md").read_text()
    assert text.startswith("# Path fit\n\n## Design quantities at the analysis points")
    assert f"* **{verdict}**" in text
    # the calibrated model written keeps the analysis point
    assert json.loads(out.read_text())["analysis_points"] == [
        {"x_m": 610.0, "name": "railway bench"}
    ]


def test_impact_fit_design_quantities_and_measured_from_both_places(
    cli, tmp_path, boulder_a
):
    out = tmp_path / "cal.json"
    r = cli("fit", boulder_a, "--model", TABLE_7_1, "--preset", PRESET,
            "--measured", "x=610,speed=70", "--design-rocks", "500",
            "-o", out, "--report", tmp_path / "rep")  # fmt: skip
    assert r.exit_code == 0, r.output
    report = (tmp_path / "rep" / "report.md").read_text()
    assert report.startswith(
        "# Impact fit\n\n## Design quantities at the analysis points\n"
    )
    # the leave-out refits (suspect data) are set beside the start and calibrated
    assert ("| x = 610 m (railway bench) | start | calibrated | flagged out | "
            "assumed θ0 out | measured |") in report  # fmt: skip
    design = json.loads(out.read_text())["provenance"]["fit"]["design"]
    (point,) = design["points"]
    assert [m["speed_mps"] for m in point["measured"]] == [70.0, 18.0]
    assert design["seed"] == 0 and design["rocks"] == 500
    start = point["models"]["start"]["speed_mps"]
    # 18 m/s lies below the Table 7-1 model's median there: no verdict for it
    assert 18.0 < start["p50"]
    lines = r.stdout.splitlines()
    assert lines[: len(design["verdicts"])] == design["verdicts"]
    assert not any("18.0 m/s" in v for v in design["verdicts"])
    table = next(i for i, s in enumerate(lines) if s.startswith("x = 610 m"))
    assert table < next(i for i, s in enumerate(lines) if s.startswith("fit: "))


def test_no_analysis_point_reports_runout_only(cli, tmp_path, boulder_a):
    data = json.loads(TABLE_7_1.read_text())
    del data["analysis_points"]
    bare = tmp_path / "bare.json"
    bare.write_text(json.dumps(data))
    out = tmp_path / "cal.json"
    r = cli("fit", boulder_a, "--model", bare, "--material", "talus=colluvium",
            "--material", "bench=colluvium", "--design-rocks", "200",
            "-o", out)  # fmt: skip
    assert r.exit_code == 0, r.output
    assert r.stdout.splitlines()[0] == (
        "no analysis point: give --at or an analysis_points block in the model "
        "file; runout only"
    )
    design = json.loads(out.read_text())["provenance"]["fit"]["design"]
    assert design["points"] == [] and set(design["runout_x_m"]) == {
        "start", "calibrated", "flagged out", "assumed θ0 out"
    }


def test_bad_design_inputs_are_one_line_and_write_nothing(
    cli, fails, tmp_path, boulder_a
):
    out = tmp_path / "cal.json"
    base = ("fit", boulder_a, "--model", TABLE_7_1, "--preset", PRESET, "-o", out)
    fails(cli(*base, "--at", "500"), "--measured", "x=610 is not an analysis point",
          "--at 610")  # fmt: skip
    fails(cli(*base, "--at", "900"), "--at", "900 m lies outside the profile")
    fails(cli(*base, "--measured", "x=610,ke=-1"), "--measured", "ke=-1",
          "must be from 0")  # fmt: skip
    fails(cli(*base, "--design-rocks", "0"), "--design-rocks", "from 1")
    bad = tmp_path / "bad.toml"
    bad.write_text(PRESET.read_text().replace("speed_mps = 18.0", "speed_mps = 1e4"))
    fails(cli("fit", boulder_a, "--model", TABLE_7_1, "--preset", bad, "-o", out),
          str(bad), "measured[0].speed_mps", "must be from 0 to 100")  # fmt: skip
    bad.write_text(PRESET.read_text().replace("speed_mps = 18.0", "v = 18.0"))
    fails(cli("fit", boulder_a, "--model", TABLE_7_1, "--preset", bad, "-o", out),
          "measured[0].v", "unknown key")  # fmt: skip
    assert not out.exists()
