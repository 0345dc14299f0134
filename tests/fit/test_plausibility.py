"""Physical plausibility (issue 20, H3): the restitution a model realises, with
known truth; the realised-e_n constraint of the path fit and the impact fit; the
report through ``fieldkit fit`` on boulder A."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from fieldkit.fit.path_fit import fit_paths
from fieldkit.fit.path_runs import PathRun
from fieldkit.fit.plausibility import (
    REALISED_TOLERANCE,
    realised_coefficients,
    simulated_restitution,
)
from fieldkit.impact_table import restitution
from fieldkit.model.model_file import model_from_dict
from fieldkit.model.simulate import simulate

TORNADO = Path(__file__).parents[2] / "surveys" / "tornado_mountain"
EN = "materials.talus.e_n"


def slope(e_n: float, *, upper_m: float = 60.0, effects=None, e_n_sd=0.0):
    """A 35-degree slope onto 300 m at 15 degrees, one material ``talus``."""
    z2 = 300 * math.tan(math.radians(15))
    z1 = upper_m * math.tan(math.radians(35))
    return model_from_dict({
        "profile": {"x_m": [0, upper_m, upper_m + 300], "z_m": [z1 + z2, z2, 0],
                    "material": "talus"},
        "materials": {"talus": {"e_n": e_n, "e_t": 0.85, "friction_deg": 30,
                                "e_n_sd": e_n_sd, "e_t_sd": 0.0}},
        "effects": effects or {},
        "body": {"mass_kg": 500, "radius_m": 0.4},
        "seeder": {"x_m": 0.5, "z_m": z1 + z2 + 2},
    })  # fmt: skip


def impacts(model, rocks=200, seed=0):
    cols = []
    simulate(model, rocks, np.random.default_rng(seed), record_impacts=True,
             on_impact_columns=cols.append)  # fmt: skip
    return {k: np.concatenate([c[k] for c in cols]) for k in cols[0]}


def test_constant_e_n_realises_exactly_itself_and_never_above_1():
    model = slope(0.5)
    cols = impacts(model)
    _, e_n, _ = realised_coefficients(cols)
    e_n = e_n[np.isfinite(e_n)]
    assert e_n.size > 500
    assert np.allclose(e_n, 0.5, rtol=0, atol=1e-9)
    (r,) = simulated_restitution(model, rocks=200)
    assert r.share_e_n_above_1 == 0.0 and r.median_e_n == pytest.approx(0.5, abs=1e-9)
    assert not r.regulator and r.producers == []


def test_velocity_scaling_realises_e_n_above_1_below_the_analytic_threshold():
    """e_n / (1 + (v_N/K)^2) > 1 exactly where |v_N| < K sqrt(e_n - 1) -- and the
    law drives the rocks to that normal speed: the regulator's fixed point."""
    k, e_n = 8.0, 1.5
    model = slope(e_n, effects={"velocity_scaled_restitution": {"k_mps": k}})
    cols = impacts(model)
    _, realised, _ = realised_coefficients(cols)
    vin = restitution(cols["vi_x_mps"], cols["vi_z_mps"], cols["vf_x_mps"],
                      cols["vf_z_mps"], cols["slope_deg"])["vin_mps"]  # fmt: skip
    ok = np.isfinite(realised)
    threshold = k * math.sqrt(e_n - 1)
    speed = np.abs(vin[ok])
    slow = speed < threshold
    # both sides sampled beyond rounding of the threshold itself
    apart = np.abs(speed - threshold) > 1e-9 * threshold
    assert (slow & apart).sum() > 100 and (~slow & apart).sum() > 100
    assert np.array_equal((realised[ok] > 1.0)[apart], slow[apart])
    assert np.median(speed) == pytest.approx(threshold, rel=0.01)
    (r,) = simulated_restitution(model, rocks=200)
    assert r.regulator and r.share_e_n_above_1 > 0.05
    assert any(f"K sqrt(e_n - 1) = {threshold:.3g} m/s" in p for p in r.producers)
    line = r.words("simulated impacts")
    assert line.startswith("talus: a regulator, not a restitution: realised e_n > 1")


def test_constrained_path_fit_meets_the_tolerance_the_unconstrained_does_not():
    """Runouts of a bouncing e_n = 1.3 (eq. 7.1, K = 6 m/s): the unconstrained fit
    takes e_n > 1 and realises e_n > 1 on a large share of its impacts; with
    max_realised_e_n = 1 the share stays within the tolerance."""
    rng = np.random.default_rng(4)
    effects = {"velocity_scaled_restitution": {"k_mps": 6.0}}
    runs = []
    for i, upper in enumerate([30.0, 45.0, 60.0, 75.0]):
        truth = slope(1.3, upper_m=upper, effects=effects, e_n_sd=0.02)
        observed = float(np.median(simulate(truth, 40, rng).runout_x_m)) - 0.5
        runs.append(PathRun(f"r{i}", slope(0.8, upper_m=upper, effects=effects,
                                           e_n_sd=0.02), observed))  # fmt: skip

    def fitted(limit):
        fit = fit_paths(runs, runs[0].model, [EN], rocks=60, seed=2, bootstrap=0,
                        bounds={EN: (0.2, 1.6)}, slice_points=5,
                        max_realised_e_n=limit)  # fmt: skip
        models = [r.model.with_parameters({EN: fit.value(EN)}) for r in runs]
        (report,) = simulated_restitution(models, rocks=600, seed=2)
        return fit, report

    free, free_report = fitted(None)
    held, held_report = fitted(1.0)
    assert free.value(EN) > 1.1 and free_report.share_e_n_above_1 > 0.2
    assert held.value(EN) < 1.0
    assert held.realised_share_optimum <= REALISED_TOLERANCE
    assert held_report.share_e_n_above_1 <= REALISED_TOLERANCE  # on a new stream
    assert held.objective_optimum > free.objective_optimum
    assert any("constrained to realised e_n <= 1" in n for n in held.notes)




PATH_FREE = [
    "--free", "materials.colluvium.e_n", "--free", "materials.colluvium.e_t",
    "--free", "velocity_scaled_restitution.k_mps", "--free", "materials.bench.e_n",
    "--free", "materials.bench.e_t",
    "--bound", "materials.colluvium.e_n=0.2,2.0",
    "--bound", "materials.colluvium.e_t=0.3,0.98",
    "--bound", "velocity_scaled_restitution.k_mps=2,30",
    "--bound", "materials.bench.e_n=0.05,1.2",
    "--bound", "materials.bench.e_t=0.1,0.98",
]  # fmt: skip


def _materials(block: dict) -> dict:
    return {m["material"]: m for m in block["materials"]}


def test_boulder_a_path_fit_reports_the_regulator_and_the_constraint_removes_it(
    cli, boulder_a, tmp_path
):
    common = ["fit", "--paths", boulder_a, "--model",
              TORNADO / "model_path_start.json", "--preset",
              TORNADO / "boulder_a_preset.toml", *PATH_FREE, "--rocks", "60",
              "--screen", "8", "--bootstrap", "0", "--seed", "1"]  # fmt: skip
    r = cli(*common, "-o", tmp_path / "p.json", "--json", tmp_path / "p.fit.json")
    assert r.exit_code == 0, r.output
    fit = json.loads((tmp_path / "p.fit.json").read_text())
    plaus = fit["plausibility"]
    colluvium = _materials(plaus["simulated"])["colluvium"]
    assert colluvium["regulator"] and colluvium["share_e_n_above_1"] > 0.3
    assert 0.98 < colluvium["median_e_n"] < 1.02
    assert plaus["constraint"] is None and plaus["simulated"]["rocks"] == 1000
    assert "plausibility: colluvium: a regulator, not a restitution: realised e_n " \
        "> 1 on" in r.stdout
    assert f"wrote {tmp_path / 'p.fit.json'}" in r.stdout
    # the same fit constrained to realised e_n <= 1: stated, and met
    r = cli(*common, "-o", tmp_path / "c.json", "--json", tmp_path / "c.fit.json",
            "--max-realised-en", "1")  # fmt: skip
    assert r.exit_code == 0, r.output
    fit = json.loads((tmp_path / "c.fit.json").read_text())
    plaus = fit["plausibility"]
    c = plaus["constraint"]
    assert c["max_realised_e_n"] == 1.0 and c["tolerance"] == REALISED_TOLERANCE
    assert c["share_start"] > 0.3 and c["share_optimum"] <= REALISED_TOLERANCE
    for m in plaus["simulated"]["materials"]:
        assert m["share_e_n_above_limit"] <= REALISED_TOLERANCE, m
        assert not m["regulator"]
    assert "plausibility: fit constrained to realised e_n <= 1" in r.stdout
    model = json.loads((tmp_path / "c.json").read_text())
    assert model["materials"]["colluvium"]["e_n"] < 1.0
    assert model["provenance"]["fit_paths"]["plausibility"] == plaus


def test_boulder_a_impact_fit_reports_observed_and_simulated_and_constrains(
    cli, boulder_a, tmp_path
):
    common = ["fit", boulder_a, "--model", TORNADO / "model_path_start.json",
              "--preset", TORNADO / "boulder_a_preset.toml"]  # fmt: skip
    r = cli(*common, "-o", tmp_path / "i.json")
    assert r.exit_code == 0, r.output
    plaus = json.loads((tmp_path / "i.json").read_text())["provenance"]["fit"][
        "plausibility"
    ]
    observed = _materials(plaus["observed"])
    assert observed["colluvium"]["impacts"] == 44
    assert observed["colluvium"]["share_e_n_above_1"] > 0.5  # the fitted law
    assert _materials(plaus["simulated"])["colluvium"]["regulator"]
    assert "of 44 observed impacts (the fitted law at their measured impact " \
        "velocities)" in r.stdout
    r = cli(*common, "-o", tmp_path / "ic.json", "--max-realised-en", "1",
            "--report", tmp_path / "rep")  # fmt: skip
    assert r.exit_code == 0, r.output
    report = (tmp_path / "rep" / "report.md").read_text()
    assert "## Physical plausibility" in report
    assert "* constrained to realised e_n <= 1 at every observed impact" in report
    assert f"wrote {tmp_path / 'rep' / 'report.md'}" in r.stdout
    fit = json.loads((tmp_path / "ic.json").read_text())["provenance"]["fit"]
    for m in fit["plausibility"]["observed"]["materials"]:
        assert m["share_e_n_above_1"] == 0.0 and m["share_e_n_above_limit"] == 0.0
    assert fit["plausibility"]["constraint"]["max_realised_e_n"] == 1.0
    assert "plausibility: constrained to realised e_n <= 1 at every observed " \
        "impact" in r.stdout
    assert f"wrote {tmp_path / 'ic.json'}" in r.stdout


@pytest.mark.parametrize("value", ["0", "-1", "inf"])
def test_bad_limit_is_one_line_and_writes_nothing(cli, fails, boulder_a, tmp_path,
                                                   value):  # fmt: skip
    for kind in (["--paths", boulder_a], [boulder_a]):
        out = tmp_path / "x.json"
        r = cli("fit", *kind, "--model", TORNADO / "model_path_start.json",
                "--preset", TORNADO / "boulder_a_preset.toml", "-o", out,
                "--max-realised-en", value)  # fmt: skip
        fails(r, "--max-realised-en")
        assert r.exit_code in (1, 2) and not out.exists()


def test_parameter_at_a_search_bound_is_in_the_plausibility_report(
    cli, boulder_a, tmp_path
):
    """Only the colluvium's e_n free, within 0.2-0.9 (below what the flights
    need): the fit ends on a bound, and the report says which, with the bound."""
    r = cli("fit", "--paths", boulder_a, "--model", TORNADO / "model_path_start.json",
            "--preset", TORNADO / "boulder_a_preset.toml",
            "--free", "materials.colluvium.e_n",
            "--bound", "materials.colluvium.e_n=0.2,0.9", "--rocks", "30",
            "--screen", "0", "--bootstrap", "0", "-o", tmp_path / "b.json",
            "--json", tmp_path / "b.fit.json")  # fmt: skip
    assert r.exit_code == 0, r.output
    (entry,) = json.loads((tmp_path / "b.fit.json").read_text())["plausibility"][
        "at_bound"
    ]
    assert entry["name"] == "materials.colluvium.e_n"
    assert entry["bound"] == "lower" and entry["bound_value"] == 0.2
    assert entry["value"] == pytest.approx(0.2, abs=1e-3)
    assert "plausibility: materials.colluvium.e_n = 0.2 is at its lower bound 0.2" \
        in r.stdout
