"""`fieldkit synth` and `fieldkit fit` from the command line, bad input included."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

SMOKE = Path(__file__).parents[1] / "model" / "data" / "smoke.json"


@pytest.fixture(scope="module")
def synth_csv(tmp_path_factory) -> Path:
    from typer.testing import CliRunner

    from fieldkit.cli import app

    out = tmp_path_factory.mktemp("synth") / "synth.csv"
    r = CliRunner().invoke(
        app,
        [
            "synth", str(SMOKE), "--paths", "30", "--seed", "4", "--noise", "0.05",
            "--effects", "velocity_scaled_restitution=k_mps=12", "-o", str(out),
        ],
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    return out


def test_synth_is_reproducible_and_keeps_the_truth(cli, tmp_path, synth_csv):
    again = tmp_path / "again.csv"
    r = cli(
        "synth", SMOKE, "--paths", "30", "--seed", "4", "--noise", "0.05",
        "--effects", "velocity_scaled_restitution=k_mps=12", "-o", again,
    )  # fmt: skip
    assert r.exit_code == 0
    assert again.read_bytes() == synth_csv.read_bytes()
    f = pd.read_csv(synth_csv)
    noise = (f["vfn_mps"] - f["vfn_mps_true"]) / f["vfn_sd_mps"]
    assert 0.85 < noise.std() < 1.15  # the stated noise model, F |vf|
    speed = (f["vf_x_mps_true"] ** 2 + f["vf_z_mps_true"] ** 2) ** 0.5
    assert (f["vft_sd_mps"] - 0.05 * speed).abs().max() < 1e-9


def test_fit_writes_a_calibrated_model_with_provenance(cli, tmp_path, synth_csv):
    out = tmp_path / "calibrated.json"
    report = tmp_path / "fit"
    r = cli("fit", synth_csv, "--model", SMOKE, "-o", out, "--report", report)
    assert r.exit_code == 0, r.output
    data = json.loads(out.read_text())
    fit = data["provenance"]["fit"]
    assert fit["n_impacts"] == len(pd.read_csv(synth_csv))
    assert fit["success"] is True
    b = fit["parameters"]["angle_dependent_restitution.b"]
    assert data["effects"]["angle_dependent_restitution"]["b"] == b["value"]
    assert set(data) >= {"profile", "materials", "effects", "provenance"}
    assert (report / "report.md").read_text().startswith("# Impact fit")
    assert (report / "residuals.png").stat().st_size > 10_000
    assert "reduced chi2" in r.stdout


def _bad(cli, tmp_path, frame: pd.DataFrame, model: Path = SMOKE) -> str:
    table = tmp_path / "bad.csv"
    frame.to_csv(table, index=False)
    out = tmp_path / "out.json"
    r = cli("fit", table, "--model", model, "-o", out, "--report", tmp_path / "rep")
    assert r.exit_code == 1
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ")
    assert not out.exists() and not (tmp_path / "rep").exists()
    return lines[0]


def test_fit_names_missing_columns(cli, tmp_path, synth_csv):
    frame = pd.read_csv(synth_csv).drop(columns=["material", "radius_m"])
    line = _bad(cli, tmp_path, frame)
    assert "missing column(s) material, radius_m" in line


def test_fit_says_how_many_impacts_are_needed(cli, tmp_path, synth_csv):
    frame = pd.read_csv(synth_csv).head(2)
    line = _bad(cli, tmp_path, frame)
    assert "too few impacts to fit" in line and "at least" in line


def test_fit_names_rows_with_non_finite_values(cli, tmp_path, synth_csv):
    frame = pd.read_csv(synth_csv)
    frame.loc[[2, 6], "vf_x_mps"] = float("nan")
    line = _bad(cli, tmp_path, frame)
    assert "vf_x_mps is not a finite number" in line and "rows 3, 7" in line


def test_fit_names_materials_missing_from_the_model(cli, tmp_path, synth_csv):
    frame = pd.read_csv(synth_csv)
    frame.loc[frame["material"] == "soil", "material"] = "granite"
    line = _bad(cli, tmp_path, frame)
    assert "granite" in line and "not in the model" in line


def test_synth_rejects_a_bad_effect(cli, tmp_path):
    out = tmp_path / "t.csv"
    r = cli("synth", SMOKE, "--effects", "no_such_effect", "-o", out, "--seed", "1")
    assert r.exit_code == 1 and "unknown effect" in r.stderr and not out.exists()
    r = cli("synth", SMOKE, "--effects", "air_drag=cd", "-o", out, "--seed", "1")
    assert r.exit_code == 1 and "--effects" in r.stderr and not out.exists()
