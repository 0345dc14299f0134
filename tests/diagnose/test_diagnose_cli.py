"""`fieldkit diagnose` from the command line: outputs, the JSON contract, bad input."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pandas as pd
import pytest

TORNADO = (
    Path(__file__).parents[2]
    / "surveys"
    / "tornado_mountain"
    / "model_rocfall_table_7_1.json"
)
CONTRACT_KEYS = [
    "metric", "baseline", "candidates", "recommended", "steps", "confounded", "after",
]  # fmt: skip


@pytest.fixture(scope="module")
def hidden_csv(tmp_path_factory) -> Path:
    """Tornado Mountain rocks with the thesis's eq. 5.4 (b = 1.03) hidden."""
    from typer.testing import CliRunner

    from fieldkit.cli import app

    out = tmp_path_factory.mktemp("diag") / "hidden.csv"
    r = CliRunner().invoke(
        app,
        [
            "synth", str(TORNADO), "--paths", "25", "--seed", "7", "--noise", "0.05",
            "--effects", "angle_dependent_restitution=b=1.03", "-o", str(out),
        ],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    return out


@pytest.fixture(scope="module")
def diagnosed(hidden_csv, tmp_path_factory):
    from typer.testing import CliRunner

    from fieldkit.cli import app

    out = tmp_path_factory.mktemp("out")
    r = CliRunner().invoke(
        app,
        [
            "diagnose", str(hidden_csv), "--model", str(TORNADO), "--seed", "1",
            "--json", str(out / "d.json"), "--report", str(out / "rep"),
            "--rrd", str(out / "d.rrd"), "-o", str(out / "after.json"),
        ],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    return out, r.output


def test_json_follows_the_contract_and_finds_the_hidden_effect(diagnosed):
    out, _ = diagnosed
    d = json.loads((out / "d.json").read_text())
    assert list(d)[: len(CONTRACT_KEYS)] == CONTRACT_KEYS
    assert d["metric"] == "cv_rmse_mps"
    assert d["baseline"]["effects"] == ["slope_roughness"]  # the model's own
    cands = d["candidates"]
    assert [c["cv_rmse_mps"] for c in cands] == sorted(c["cv_rmse_mps"] for c in cands)
    base = d["baseline"]["cv_rmse_mps"]
    for c in cands:
        assert c["improvement"] == pytest.approx(1 - c["cv_rmse_mps"] / base, abs=1e-12)
        assert c["improvement_se"] > 0
    assert d["recommended"] == "angle_dependent_restitution"
    assert d["steps"][0]["added"] == d["recommended"]
    assert d["after"]["effects"] == ["slope_roughness"] + [
        s["added"] for s in d["steps"]
    ]
    assert d["after"]["cv_rmse_mps"] < 0.75 * base  # the error falls by > 25 %
    b = d["after"]["params"]["angle_dependent_restitution.b"]
    b_sd = d["after"]["params_sd"]["angle_dependent_restitution.b"]
    assert abs(b - 1.03) < 3 * b_sd
    assert set(d["skipped"]) >= {"air_drag", "tree_impacts", "mass_loss"}


def test_report_figures_recording_and_calibrated_model(diagnosed):
    out, printed = diagnosed
    text = (out / "rep" / "report.md").read_text()
    assert text.startswith("# Diagnosis:")
    assert "## Step 1: add `angle_dependent_restitution` — the error falls" in text
    for png in ("baseline.png", "step_1_angle_dependent_restitution.png"):
        assert (out / "rep" / png).stat().st_size > 20_000
    assert (out / "d.rrd").stat().st_size > 1000
    model = json.loads((out / "after.json").read_text())
    assert "angle_dependent_restitution" in model["effects"]
    assert model["provenance"]["diagnose"]["added"] == ["angle_dependent_restitution"]
    assert "recommended: angle_dependent_restitution" in printed


def test_same_seed_same_json(hidden_csv, tmp_path, cli):
    for name in ("a.json", "b.json"):
        r = cli("diagnose", hidden_csv, "--seed", "5", "--json", tmp_path / name)
        assert r.exit_code == 0, r.output
    assert (tmp_path / "a.json").read_bytes() == (tmp_path / "b.json").read_bytes()


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda f: f.drop(columns=["material"]), "missing column(s) material"),
        (lambda f: f.assign(vf_x_mps=f["vf_x_mps"].where(f.index != 3)), "row 4"),
        (lambda f: f.iloc[:2], "need at least 3"),
    ],
    ids=["missing-column", "non-finite", "too-few"],
)
def test_bad_table_one_line_nothing_written(hidden_csv, tmp_path, cli, edit, message):
    bad = tmp_path / "bad.csv"
    edit(pd.read_csv(hidden_csv)).to_csv(bad, index=False)
    out = tmp_path / "out"
    r = cli("diagnose", bad, "--seed", "1", "--json", out / "d.json",
            "--report", out / "rep")  # fmt: skip
    assert r.exit_code == 1
    lines = r.output.strip().splitlines()
    assert len([x for x in lines if x.startswith("error:")]) == 1
    assert message in r.output and "bad.csv" in r.output
    assert not out.exists()


def test_model_materials_must_match(hidden_csv, tmp_path, cli):
    smoke = Path(__file__).parents[1] / "model" / "data" / "smoke.json"
    r = cli("diagnose", hidden_csv, "--model", smoke, "--json", tmp_path / "d.json")
    assert r.exit_code == 1
    assert "not in the model" in r.output and "colluvium" in r.output
    assert not (tmp_path / "d.json").exists()


def test_output_model_needs_a_base_model(hidden_csv, tmp_path, cli):
    r = cli("diagnose", hidden_csv, "-o", tmp_path / "m.json")
    assert r.exit_code == 1
    assert "-o needs --model" in r.output


def test_report_says_when_a_fitted_value_switches_its_effect_off(diagnosed):
    """After the angle law, the speed law's K runs off to ~1e5 m/s (its neutral
    value is infinite): the report says the effect is off instead of printing a
    meaningless 1e+05 ± 1e+10."""
    out, _ = diagnosed
    text = (out / "rep" / "report.md").read_text()
    assert re.search(
        r"\| `velocity_scaled_restitution`: .* \| k_mps = [\d.]+e\+0[4-9] m/s, "
        r"practically its neutral value ∞: the effect is off \(no standard error\) \|",
        text,
    )
    assert not re.search(r"k_mps = [\d.]+e\+0[4-9] ±", text)


def test_figure_names_a_feature_left_out_and_its_dependence(
    hidden_csv, tmp_path, cli, monkeypatch
):
    """The README's hidden case: the v_fn residuals depend on seven features, six
    fit a figure. The title named none of those left out ("6 of 7 features
    shown"): it names the material, and that the residuals depend on it too."""
    import fieldkit.viz.diagnose_figure as module

    titles = []
    original = module.save_png

    def capture(fig, path, **kwargs):
        titles.append(" ".join(fig.texts[0].get_text().split()))
        return original(fig, path, **kwargs)

    monkeypatch.setattr(module, "save_png", capture)
    r = cli("diagnose", hidden_csv, "--model", TORNADO, "--seed", "1",
            "--report", tmp_path / "rep")  # fmt: skip
    assert r.exit_code == 0, r.output
    text = (tmp_path / "rep" / "report.md").read_text()
    assert "| normal rebound velocity v_fn | slope material | Kruskal-Wallis" in text
    assert len(titles) == 2
    for title in titles:
        assert (
            "6 of 7 features shown (those the residuals depend on first); not shown: "
            "slope material (the residuals depend on it too); the report lists "
            "every test"
        ) in title
