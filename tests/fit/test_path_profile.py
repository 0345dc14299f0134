"""Issue 20 (H4): path-fit profile intervals, with the objective's seed spread."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from fieldkit.fit.path_fit import fit_paths
from fieldkit.fit.path_profile import profile_objective
from fieldkit.fit.synthetic_paths import synthetic_site

TORNADO = Path(__file__).parents[2] / "surveys" / "tornado_mountain"
TABLE_7_1 = TORNADO / "model_rocfall_table_7_1.json"
E_N, E_T = "materials.colluvium.e_n", "materials.colluvium.e_t"


def test_profile_contains_the_truth_and_the_slice():
    """12 synthetic runs with known friction and e_t: both profile intervals contain
    the truth and the slice's range, and are wider than the slice where the two
    parameters trade off (e_t: 0.56-0.79 held, 0.56-0.90 re-optimised)."""
    truth = {"materials.talus.friction_deg": 35.0, "materials.talus.e_t": 0.7}
    runs = synthetic_site(truth, 12, np.random.default_rng(5))
    r = fit_paths(runs, runs[0].model, list(truth), rocks=40, seed=3, bootstrap=0,
                  profile_points=5)  # fmt: skip
    prof = r.profile
    for j, name in enumerate(r.names):
        lo, hi = prof.interval90[j]
        assert lo <= truth[name] <= hi, (name, lo, hi)
        assert lo <= r.compatible[j, 0] and hi >= r.compatible[j, 1]
    assert prof.interval90[1, 1] > r.compatible[1, 1] + 0.05
    assert prof.optimum_seed_sd > 0
    assert prof.evaluations > 0 and prof.evaluations_per_point == 6
    d = r.to_dict()["profile"]
    assert d["parameters"][1]["widest"] == "profile"  # no bootstrap: slice vs profile
    curve = d["parameters"][0]["curve"]
    assert len(curve["value"]) == len(curve["excess"]) == len(curve["sd_seed"])
    assert min(curve["excess"]) <= 0.0 + 1e-12  # the optimum itself


class _Stub:
    """A 1-parameter objective of 20 units, (x - 0.4)^2 each, plus (when noisy) a
    seed-dependent term that grows with the distance from 0.4."""

    def __init__(self, noisy: bool):
        self.seed, self.noisy, self.evaluations = 0, noisy, 0
        self.strata = [np.arange(20)]
        self.names = ["a"]

    def units(self, x):
        self.evaluations += 1
        d = float(x[0]) - 0.4
        base = np.full(20, d * d) + 0.01 * np.arange(20) * d * d
        if self.noisy:
            rng = np.random.default_rng(self.seed)
            base = base + rng.normal(0.0, 0.05, 20) * abs(d)
        return base


def test_seed_spread_is_zero_without_seed_dependence_and_positive_with():
    quiet = profile_objective(_Stub(False), np.array([0.4]), np.zeros(1), np.ones(1),
                              points=5, seeds=5)  # fmt: skip
    assert quiet.optimum_seed_sd == 0.0
    assert np.all(quiet.sd_seed[0] == 0.0)
    noisy_stub = _Stub(True)
    noisy = profile_objective(noisy_stub, np.array([0.4]), np.zeros(1), np.ones(1),
                              points=5, seeds=5)  # fmt: skip
    away = noisy.grid[0] != 0.4
    assert np.all(noisy.sd_seed[0][away] > 0)
    assert noisy_stub.seed == 0  # restored
    # the seed term widens the interval: compatible further out than without it
    assert noisy.interval90[0, 1] - noisy.interval90[0, 0] >= (
        quiet.interval90[0, 1] - quiet.interval90[0, 0]
    )




def test_path_fit_prints_the_profile_beside_the_bootstrap(cli, tmp_path, boulder_a):
    """One path: the profile (others re-optimised, seed spread in the threshold) is
    printed beside the 90 % interval and slice, with its cost and the objective's
    seed SD; the one-path lower-bound statement is printed with the intervals even
    without standard errors; JSON and report.md carry it; --profile-points 0 is off."""
    r = cli(
        "fit", "--paths", boulder_a, "--model", TABLE_7_1, "--free", E_N,
        "--free", E_T, "--rocks", "30", "--bootstrap", "2", "--screen", "0",
        "--seed", "1", "--profile-points", "3",
        "-o", tmp_path / "m.json", "--json", tmp_path / "f.json",
        "--report", tmp_path / "rep",
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    fit = json.loads((tmp_path / "f.json").read_text())
    prof = fit["profile"]
    assert prof["points"] == 3 and prof["seeds"] == 5
    assert prof["evaluations"] > 0 and prof["wall_s"] > 0
    assert len(prof["optimum_seed_values"]) == 5 and prof["optimum_seed_sd"] > 0
    for q, (slo, shi), p in zip(prof["parameters"], fit["slice_compatible"],
                                fit["parameters"], strict=True):  # fmt: skip
        lo, hi = q["interval90"]
        assert lo <= slo <= p["value"] <= shi <= hi
        assert q["widest"] in ("slice", "profile")  # no standard error: no bootstrap
    out = r.stdout.splitlines()
    # printed with the fit's own lines, after the consequences (design quantities)
    # that every fit prints first
    one_path = ("one surveyed path: resampling its points is a lower bound on the "
                "uncertainty of a site's parameters (another boulder, another path)")
    first_parameter = next(i for i, x in enumerate(out) if x.startswith("materials."))
    assert any(x.startswith(one_path) for x in out[:first_parameter])
    head = next(x for x in out if x.startswith("profile (3 values"))
    sd = prof["optimum_seed_sd"]
    assert f"SD over 5 other seeds {sd:.2g}" in head
    assert f"cost {prof['evaluations']} evaluations" in head
    lo, hi = prof["parameters"][0]["interval90"]
    assert f"  {E_N}: profile {lo:.4g} to {hi:.4g}; no bootstrap interval" in r.stdout
    report = (tmp_path / "rep" / "report.md").read_text()
    assert "## Profile intervals" in report
    assert "another boulder, another path" in report
    assert f"{prof['evaluations']} evaluations of the objective" in report
    r = cli(
        "fit", "--paths", boulder_a, "--model", TABLE_7_1, "--free", E_T,
        "--rocks", "20", "--bootstrap", "0", "--screen", "0", "--profile-points", "0",
        "-o", tmp_path / "m0.json", "--json", tmp_path / "f0.json",
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    assert json.loads((tmp_path / "f0.json").read_text())["profile"] is None
    assert "profile (" not in r.stdout and "profiling" not in r.stderr


def test_profile_points_bad_values_one_line(cli, tmp_path, boulder_a):
    bad = (("1", "profile-points must be 0 (off) or at least 2"),
           ("-3", "profile-points must be between 0 and 101"))  # fmt: skip
    for value, words in bad:
        r = cli("fit", "--paths", boulder_a, "--model", TABLE_7_1, "--free", E_T,
                "--profile-points", value, "-o", tmp_path / "x.json")  # fmt: skip
        assert r.exit_code == 1, r.output
        errors = [x for x in r.output.splitlines() if x.startswith("error:")]
        assert len(errors) == 1 and words in errors[0], r.output
        assert not (tmp_path / "x.json").exists()
