"""Errors in both variables (issue 18 item 3): ``synth --impact-noise`` and the
impact fit's and the diagnosis' regression calibration with effective variance.

The effect-free tables are the Table 7-1 model's with 5 % noise on the rebound and
10 % on the impact velocity. The seeds of the diagnosis tests are ones on which the
diagnosis that took the impact velocities as exact found an effect (rotation
friction or a restitution law); over 200 seeds it did so on 16.5 % of the
100-impact tables and 26 % of the 1,000-impact ones, against 3.5 % and 7.0 % now
(the report of branch wt-h3 gives the numbers).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from fieldkit.impact_table import ImpactTable

REPO = Path(__file__).parents[2]
TABLE_7_1 = REPO / "surveys" / "tornado_mountain" / "model_rocfall_table_7_1.json"
NOISY = ("--noise", "0.05", "--impact-noise", "0.1")


def _synth(cli, out: Path, *, paths: int, seed: int, extra=NOISY):
    r = cli(
        "synth", TABLE_7_1, "--paths", paths, "--seed", seed, *extra, "-o", out
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    return r


def test_synth_impact_noise_is_stated_kept_and_sized(cli, tmp_path):
    """--impact-noise perturbs vi_x, vi_z, omega_i by F |vi| (and / r), keeps the
    clean values and the SDs, says so; without it the table is the one it was."""
    out = tmp_path / "noisy.csv"
    r = _synth(cli, out, paths=6, seed=3)
    assert "noise F = 0.05 on vf, F = 0.1 on vi;" in r.stdout
    assert f"wrote {out}" in r.stdout
    f = pd.read_csv(out)
    vi = np.hypot(f["vi_x_mps_true"], f["vi_z_mps_true"])
    np.testing.assert_allclose(f["vin_sd_mps"], 0.1 * vi, rtol=1e-12)
    np.testing.assert_allclose(f["vit_sd_mps"], 0.1 * vi, rtol=1e-12)
    np.testing.assert_allclose(
        f["omega_i_sd_radps"], 0.1 * vi / f["radius_m"], rtol=1e-12
    )
    z = np.concatenate(
        [
            (f["vi_x_mps"] - f["vi_x_mps_true"]) / f["vin_sd_mps"],
            (f["vi_z_mps"] - f["vi_z_mps_true"]) / f["vin_sd_mps"],
            (f["vin_mps"] - f["vin_mps_true"]) / f["vin_sd_mps"],
        ]
    )
    z = z[np.isfinite(z)]
    assert z.size > 600 and abs(z.std() - 1.0) < 0.08 and abs(z.mean()) < 0.1
    # the rebound's noise is the same draw as without impact noise
    plain = tmp_path / "plain.csv"
    r0 = _synth(cli, plain, paths=6, seed=3, extra=("--noise", "0.05"))
    assert "F = 0 on vi (impact velocities exact)" in r0.stdout
    g = pd.read_csv(plain)
    assert "vin_sd_mps" not in g and "vi_x_mps_true" not in g
    np.testing.assert_array_equal(f["vf_x_mps"], g["vf_x_mps"])
    np.testing.assert_array_equal(f["vi_x_mps_true"], g["vi_x_mps"])
    explicit = tmp_path / "explicit.csv"
    _synth(
        cli, explicit, paths=6, seed=3, extra=("--noise", "0.05", "--impact-noise", "0")
    )
    assert explicit.read_bytes() == plain.read_bytes()


def test_synth_impact_noise_out_of_range_is_one_line(cli, tmp_path, fails):
    fails(
        cli(
            "synth",
            TABLE_7_1,
            "--seed",
            "1",
            "--impact-noise",
            "1.5",
            "-o",
            tmp_path / "x.csv",
        ),
        "--impact-noise",
        "[0, 1]",
    )
    assert not (tmp_path / "x.csv").exists()


def test_fit_restitution_is_not_diluted(cli, tmp_path):
    """Colluvium e_n and e_t (Table 7-1: 1.0 and 0.62; the energy cap keeps the
    fitted e_n a little under 1) fitted on noisy tables agree with the fits on the
    same rocks with exact impact velocities. Taken as exact, the noisy ones pulled
    them down by 0.020 and 0.012 (regression dilution); now +0.007 and -0.001."""
    diff = {"e_n": [], "e_t": []}
    for seed in (11, 12, 13):
        fitted = {}
        for name, extra in (("noisy", NOISY), ("clean", ("--noise", "0.05"))):
            table, model = tmp_path / f"{name}{seed}.csv", tmp_path / f"{name}.json"
            _synth(cli, table, paths=40, seed=seed, extra=extra)
            r = cli("fit", table, "--model", TABLE_7_1, "-o", model)
            assert r.exit_code == 0, r.output
            assert ("errors in variables" in r.stdout) == (name == "noisy")
            fitted[name] = json.loads(model.read_text())["materials"]["colluvium"]
        for key in diff:
            diff[key].append(fitted["noisy"][key] - fitted["clean"][key])
    assert abs(np.mean(diff["e_n"])) < 0.012, diff
    assert abs(np.mean(diff["e_t"])) < 0.006, diff


def _diagnosis(cli, tmp_path, *, size: int, seed: int) -> dict:
    """The first ``size`` impacts of a noisy synth table (rocks added until there
    are that many), diagnosed by the command line."""
    table = tmp_path / f"t{seed}.csv"
    paths = max(3, size // 45 + 2)
    _synth(cli, table, paths=paths, seed=seed)
    while len(frame := pd.read_csv(table)) < size:
        paths = int(paths * 1.5) + 1
        _synth(cli, table, paths=paths, seed=seed)
    ImpactTable(frame.iloc[:size], source="synthetic").write(table)
    out = tmp_path / f"d{seed}.json"
    r = cli("diagnose", table, "--seed", seed, "--json", out)
    assert r.exit_code == 0, r.output
    assert "errors in variables" in out.read_text()
    return json.loads(out.read_text())


@pytest.mark.parametrize("seed", [1, 2, 19, 22])
def test_no_finding_on_100_noisy_impacts(cli, tmp_path, seed):
    d = _diagnosis(cli, tmp_path, size=100, seed=seed)
    assert d["recommended"] is None and d["confounded"] == [], d["stopped"]


@pytest.mark.parametrize("seed", [0, 1, 5])
def test_no_finding_on_1000_noisy_impacts(cli, tmp_path, seed):
    d = _diagnosis(cli, tmp_path, size=1000, seed=seed)
    assert d["recommended"] is None and d["confounded"] == [], d["stopped"]


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
def test_no_finding_on_5000_noisy_impacts(cli, tmp_path, seed):
    d = _diagnosis(cli, tmp_path, size=5000, seed=seed)
    assert d["recommended"] is None and d["confounded"] == [], d["stopped"]


def test_null_tables_keep_the_tables_spread_and_the_baselines_laws(tmp_path, cli):
    """A null table has the table's rows, columns and SDs, inputs of the observed
    spread (truth recoloured to the estimated true covariance, plus fresh error)
    and rebounds that refit to the baseline's values; a seed reproduces it."""
    from fieldkit.diagnose.impacts import base_model
    from fieldkit.diagnose.table_null import table_null_tables
    from fieldkit.fit.impact_fit import fit_impacts

    path = tmp_path / "t.csv"
    _synth(cli, path, paths=20, seed=4)
    table = ImpactTable.read(path)
    _, fitted = fit_impacts(table, base_model(table))
    nulls = table_null_tables(table, fitted, rng=np.random.default_rng(1), size=4)
    again = table_null_tables(table, fitted, rng=np.random.default_rng(1), size=4)
    f0 = table.derive().frame
    values = {k: v for k, v in fitted.parameters().items() if k.startswith("materials")}
    for null, same in zip(nulls, again, strict=True):
        f = null.frame
        assert len(f) == len(f0) and list(f.columns) == list(f0.columns)
        assert f["vin_sd_mps"].equals(f0["vin_sd_mps"])
        for column in ("vin_mps", "vit_mps", "vfn_mps"):
            assert f[column].std() / f0[column].std() == pytest.approx(1.0, abs=0.06)
        np.testing.assert_array_equal(f["vf_x_mps"], same.frame["vf_x_mps"])
        result, _ = fit_impacts(null, fitted)
        for name, value in zip(result.names, result.values, strict=True):
            if name.endswith("e_n") or name.endswith("e_t"):
                assert (
                    abs(value - values[name])
                    < 4 * result.stderr[result.names.index(name)] + 0.01
                ), name


def test_null_tables_through_the_command_line(cli, tmp_path):
    """--null on a table with impact-velocity errors: null tables of its fitted
    baseline; a recommendation must beat their 95 % quantile (the Monte Carlo
    test's order statistic: with 19, their largest gain)."""
    model = REPO / "surveys" / "tornado_mountain" / "model_rocfall_table_7_1.json"
    table = tmp_path / "t.csv"
    r = cli("synth", model, "--paths", "4", "--seed", "3", "--impact-noise", "0.1",
            "-o", table)  # fmt: skip
    assert r.exit_code == 0, r.output
    js = tmp_path / "d.json"
    r = cli("diagnose", table, "--seed", "1", "--null", "19", "--json", js)
    assert r.exit_code == 0, r.output
    null = json.loads(js.read_text())["null"]
    assert null["kind"] == "tables" and null["size"] == 19
    assert null["threshold"] == max(null["gains"])
    assert "null: 19 null tables of the fitted baseline" in r.stdout
