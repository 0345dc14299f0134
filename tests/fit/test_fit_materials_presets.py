"""Issue 17 through the command line: material mapping, the boulder A preset, the
path fit's report and outputs, bootstrap SEs, and hostile sizes."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

TORNADO = Path(__file__).parents[2] / "surveys" / "tornado_mountain"
PRESET = TORNADO / "boulder_a_preset.toml"
TABLE_7_1 = TORNADO / "model_rocfall_table_7_1.json"
PATH_START = TORNADO / "model_path_start.json"
REDUCE = (
    "reduce", "--impacts", TORNADO / "boulder_a_impacts.gpx",
    "--trees", TORNADO / "boulder_a_trees.csv",
)  # fmt: skip




def test_reduce_preset_gives_the_explicit_options_table(cli, tmp_path, boulder_a):
    explicit = tmp_path / "explicit.csv"
    r = cli(*REDUCE, "--theta0", "32.6", "--mass", "3750", "--radius", "0.725",
            "--gyration", "0.46", "--path-id", "boulder_a", "-o", explicit)  # fmt: skip
    assert r.exit_code == 0, r.output
    assert explicit.read_bytes() == boulder_a.read_bytes()
    assert f"wrote {explicit} (50 rows)" in r.stdout
    # a command-line value overrides the preset's, and the output says which is which
    r = cli(*REDUCE, "--preset", PRESET, "--mass", "3000", "-o", tmp_path / "m.csv")
    assert r.exit_code == 0, r.output
    assert "--theta0 32.6" in r.stderr and "--path-id boulder_a" in r.stderr
    assert "from the command line instead: --mass 3000" in r.stderr
    assert (pd.read_csv(tmp_path / "m.csv")["mass_kg"] == 3000).all()


def test_reduce_refuses_a_bad_preset(cli, tmp_path, fails):
    bad = tmp_path / "bad.toml"
    bad.write_text("[reduce]\nmass = 3750\n")
    r = cli(*REDUCE, "--preset", bad, "-o", tmp_path / "x.csv")
    fails(r, str(bad), "reduce.mass", "unknown key")
    bad.write_text("[reduce]\nmass_kg = inf\n")
    r = cli(*REDUCE, "--preset", bad, "-o", tmp_path / "x.csv")
    fails(r, "reduce.mass_kg", "finite")
    assert not (tmp_path / "x.csv").exists()


def test_impact_fit_needs_a_mapping_and_states_it(cli, tmp_path, boulder_a, fails):
    out = tmp_path / "cal.json"
    r = cli("fit", boulder_a, "--model", TABLE_7_1, "-o", out)
    fails(r, "bench, talus not in the model", "rock, colluvium", "--material")
    r = cli("fit", boulder_a, "--model", TABLE_7_1, "--material", "talus=granite",
            "-o", out)  # fmt: skip
    fails(r, "--material", "granite", "rock, colluvium")
    assert not out.exists()
    r = cli("fit", boulder_a, "--model", TABLE_7_1, "--preset", PRESET, "-o", out)
    assert r.exit_code == 0, r.output
    assert "material talus -> colluvium (2 rows" in r.stderr
    assert "material bench -> colluvium (3 rows" in r.stderr
    fit = json.loads(out.read_text())["provenance"]["fit"]
    assert fit["material_map"] == {"talus": "colluvium", "bench": "colluvium"}
    assert set(fit["parameters"]) == {
        "materials.rock.e_n", "materials.rock.e_t",
        "materials.colluvium.e_n", "materials.colluvium.e_t",
    }  # fmt: skip
    assert f"wrote {out}" in r.stdout
    # an explicit mapping wins over the preset's
    r = cli("fit", boulder_a, "--model", TABLE_7_1, "--preset", PRESET,
            "--material", "bench=rock", "-o", out)  # fmt: skip
    assert r.exit_code == 0, r.output
    assert json.loads(out.read_text())["provenance"]["fit"]["material_map"] == {
        "talus": "colluvium", "bench": "rock"}  # fmt: skip


def test_a_model_with_the_material_keeps_it(cli, tmp_path, boulder_a):
    out = tmp_path / "cal.json"
    r = cli("fit", boulder_a, "--model", PATH_START, "--preset", PRESET, "-o", out)
    assert r.exit_code == 0, r.output
    assert "material bench kept: the model has its own bench" in r.stderr
    fit = json.loads(out.read_text())["provenance"]["fit"]
    assert fit["material_map"] == {"talus": "colluvium"}
    assert "materials.bench.e_n" in fit["parameters"]


def test_diagnose_maps_materials(cli, tmp_path, boulder_a, fails):
    r = cli("diagnose", boulder_a, "--model", TABLE_7_1, "--seed", "1", "--null", "0")
    fails(r, "not in the model", "--material")
    out = tmp_path / "after.json"
    js = tmp_path / "diagnosis.json"
    r = cli("diagnose", boulder_a, "--model", TABLE_7_1, "--preset", PRESET,
            "--seed", "1", "-o", out, "--json", js, "--null", "0")  # fmt: skip
    assert r.exit_code == 0, r.output
    assert "material talus -> colluvium" in r.stderr
    notes = json.loads(js.read_text())["notes"]
    assert any(n.startswith("material bench -> colluvium (3 rows") for n in notes)
    provenance = json.loads(out.read_text())["provenance"]["diagnose"]
    assert provenance["material_map"] == {"talus": "colluvium", "bench": "colluvium"}


def test_a_failed_fit_exits_1_and_writes_no_model(cli, tmp_path, boulder_a,
                                                  monkeypatch):  # fmt: skip
    import fieldkit.fit.impact_fit as impact_fit

    real = impact_fit.least_squares

    def failing(*args, **kwargs):
        result = real(*args, **kwargs)
        result.success, result.message = False, "maximum evaluations exceeded"
        return result

    monkeypatch.setattr(impact_fit, "least_squares", failing)
    out = tmp_path / "cal.json"
    r = cli("fit", boulder_a, "--model", TABLE_7_1, "--preset", PRESET, "-o", out,
            "--report", tmp_path / "rep")  # fmt: skip
    assert r.exit_code == 1
    errors = [x for x in r.stderr.splitlines() if x.startswith("error")]
    assert errors == [x for x in r.stderr.splitlines() if "error" in x.lower()]
    assert len(errors) == 1 and "did not converge (maximum evaluations exceeded)" in (
        errors[0]) and "no calibrated model written" in errors[0]  # fmt: skip
    assert "Traceback" not in r.output
    assert not out.exists() and not (tmp_path / "rep").exists()


def test_path_fit_report_without_holdout(cli, tmp_path, boulder_a):
    """--report without held-out runs: report.md written (no holdout.png planned),
    no ± or correlations from 2 resamples, and a 'wrote' line per file."""
    out, js, rep = tmp_path / "cal.json", tmp_path / "fit.json", tmp_path / "rep"
    r = cli(
        "fit", "--paths", boulder_a, "--model", TABLE_7_1, "--preset", PRESET,
        "--free", "materials.colluvium.e_t", "--rocks", "20", "--bootstrap", "2",
        "--screen", "0", "-o", out, "--json", js, "--report", rep,
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    assert sorted(p.name for p in rep.iterdir()) == ["report.md"]
    text = (rep / "report.md").read_text()
    assert text.startswith("# Path fit")
    # kinds in words with units (issue 17: report.md spoke in column names)
    assert "| normal flight height between impacts (m) | 48 |" in text
    assert "| speed at the observed impacts (m/s) | 49 |" in text
    assert "No standard errors: 2 bootstrap resamples are fewer than the 10" in text
    # no ± on the fitted parameters (the design table's Monte Carlo ± is apart)
    fitted = [line for line in r.stdout.splitlines() if line.startswith("materials.")]
    assert fitted and not any("±" in line for line in fitted)
    assert "no standard errors or correlations: --bootstrap 2" in r.stdout
    fit = json.loads(js.read_text())
    assert fit["parameters"][0]["stderr"] is None and fit["correlation"] is None
    assert fit["material_map"] == {"talus": "colluvium", "bench": "colluvium"}
    assert fit["material_check"] == {"points_compared": 49, "differences": []}
    assert "agree with the model's profile at 49 of 49 surveyed points" in r.stderr
    assert "NaN" not in js.read_text()
    for path in (out, js, rep / "report.md"):
        assert f"wrote {path}" in r.stdout


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--rocks", "-5"], ["--rocks", "between 1 and 20,000"]),
        (["--rocks", "10000000"], ["--rocks", "20,000"]),
        (["--bootstrap", "-1"], ["--bootstrap", "between 0 and 1,000"]),
        (["--bootstrap", "100000"], ["--bootstrap", "1,000"]),
        (["--screen", "-3"], ["--screen", "between 0 and 4,096"]),
        (["--screen", "99999"], ["--screen", "4,096"]),
        (["--seed", "-1"], ["--seed", "between 0"]),
        (["--bound", "materials.colluvium.e_t=-inf,inf"], ["--bound", "finite"]),
        (["--bound", "materials.colluvium.e_t=nan,1"], ["--bound", "finite"]),
    ],
)
def test_path_fit_refuses_bad_sizes_at_once(cli, tmp_path, boulder_a, fails, extra,
                                            words):  # fmt: skip
    out = tmp_path / "cal.json"
    r = cli("fit", "--paths", boulder_a, "--model", TABLE_7_1, "-o", out, *extra)
    fails(r, *words)
    assert not out.exists()


def test_path_fit_checks_mapped_materials_against_the_profile(cli, tmp_path,
                                                             boulder_a):  # fmt: skip
    """The path fit uses the model's profile: unmapped, boulder A's talus and bench
    differ from Table 7-1's colluvium there (stated); path_start keeps its bench."""
    js = tmp_path / "fit.json"
    base = ("fit", "--paths", boulder_a, "--free", "materials.colluvium.e_t",
            "--rocks", "5", "--bootstrap", "0", "--screen", "0",
            "-o", tmp_path / "cal.json", "--json", js)  # fmt: skip
    r = cli(*base, "--model", TABLE_7_1)
    assert r.exit_code == 0, r.output
    check = json.loads(js.read_text())["material_check"]
    assert check["points_compared"] == 49 and len(check["differences"]) == 5
    assert "point D (x = 48 m): surveyed talus, profile colluvium" in r.stderr
    r = cli(*base, "--model", PATH_START, "--preset", PRESET)
    assert r.exit_code == 0, r.output
    fit = json.loads(js.read_text())
    assert fit["material_map"] == {"talus": "colluvium"}
    assert fit["material_check"]["differences"] == []


def test_a_one_impact_path_is_refused(cli, tmp_path, boulder_a, fails):
    frame = pd.read_csv(boulder_a)
    one = tmp_path / "one.csv"
    frame.head(1).to_csv(one, index=False)
    out = tmp_path / "cal.json"
    r = cli("fit", "--paths", one, "--model", TABLE_7_1, "-o", out)
    fails(r, "1 surveyed point", "at least 3", "release", "stopped")
    assert not out.exists()


def test_fit_figures_label_axes_in_words_and_explain_every_mark(tmp_path):
    """The residual figure of an impact fit and the held-out figure of a path fit:
    axis labels in words with units, one legend entry for every kind of mark."""
    import numpy as np

    from fieldkit.fit.fit_result import FitResult
    from fieldkit.viz.fit_figure import residual_figure
    from fieldkit.viz.holdout_figure import holdout_figure

    result = FitResult(
        names=["materials.rock.e_n"], values=np.array([0.5]),
        stderr=np.array([0.1]), start=np.array([0.4]), lower=np.array([0.0]),
        upper=np.array([2.0]), correlation=np.ones((1, 1)), chi2=4.0, redchi=1.0,
        aic=0.0, bic=0.0, ndata=4, nparams=1, n_impacts=2, success=True,
        message="ok", weighting="unit weights (the table has no *_sd columns)",
        residuals=np.array([0.1, -0.2, 0.3, 0.0]),
        residual_kind=np.array(["vfn", "vft", "vfn", "vft"]),
        residual_row=np.array([0, 0, 1, 1]),
    )  # fmt: skip
    fig = residual_figure(result, np.array([20.0, 30.0]), np.array([10.0, 12.0]))
    left, right = fig.axes[:2]
    assert left.get_xlabel() == "impact angle to the ground θ_i (degrees)"
    assert right.get_xlabel() == "impact speed v_i (m/s)"
    assert left.get_ylabel() == "residual: observed − predicted (m/s)"
    legend = [t.get_text() for t in left.get_legend().get_texts()]
    assert legend == [
        "normal rebound velocity v_fN",
        "tangential rebound velocity v_fT",
        "prediction = observation",
    ]
    rng = np.random.default_rng(0)
    validation = {
        "path_ids": ["a", "b"], "observed": np.array([80.0, 90.0]),
        "ensembles": {"calibrated": [rng.normal(85, 5, 50)] * 2,
                      "uncalibrated": [rng.normal(95, 5, 50)] * 2,
                      "climatology": [rng.normal(85, 8, 50)]},
        "forecasts": {k: {"mean_crps": 1.0}
                      for k in ("calibrated", "uncalibrated", "climatology")},
    }  # fmt: skip
    fig = holdout_figure(validation)
    ax = fig.axes[0]
    assert ax.get_xlabel() == "runout along the section from the release (m)"
    assert ax.get_ylabel() == "held-out run"
    # the legend sits below the axes, the figure's own (issue 17: more marks)
    legend = {t.get_text() for t in fig.legends[0].get_texts()}
    assert {"observed runout", "calibrated model", "starting (uncalibrated) model",
            "median simulated runout", "50 % of simulated runouts (thick)",
            "90 % of simulated runouts (thin)"} <= legend  # fmt: skip


def test_material_mapping_is_refused_for_runs_on_a_dem(cli, tmp_path, fails):
    data = Path(__file__).parents[1] / "data" / "tschamut2014"
    split = data / "calibration_split"
    base = Path(__file__).parents[2] / "examples" / "tschamut" / "model_base.json"
    out = tmp_path / "m.json"
    r = cli(
        "fit", "--model", base, "--paths", split / "calibration_release_points.csv",
        "--deposits", split / "calibration_observed_deposition.csv",
        "--dem", data / "terrain.asc", "--material", "talus=meadow", "-o", out,
    )  # fmt: skip
    fails(r, "--material", "ImpactTable", "DEM")
    assert not out.exists()


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--rocks", "-5"], ["--rocks", "for a path fit (--paths) only"]),
        (["--bootstrap", "2", "--seed", "-1"], ["--seed", "nor --bootstrap"]),
        (["--json", "fit.json"], ["--json", "for a path fit"]),
    ],
)
def test_impact_fit_refuses_path_fit_settings(cli, tmp_path, boulder_a, fails,
                                              extra, words):  # fmt: skip
    out = tmp_path / "cal.json"
    r = cli("fit", boulder_a, "--model", TABLE_7_1, "--preset", PRESET, "-o", out,
            *extra)  # fmt: skip
    fails(r, *words)
    assert not out.exists() and not (tmp_path / "fit.json").exists()
