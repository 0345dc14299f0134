"""Plan scores (fieldkit.fit.plan_scores) against known truth and the Tschamut data."""

from __future__ import annotations

import doctest
import math
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from fieldkit.errors import ArgumentError
from fieldkit.fit import plan_scores
from fieldkit.fit.holdout import crps_ensemble
from fieldkit.fit.plan_scores import (
    duplicate_runs,
    energy_score,
    energy_scores,
    fair_crps,
    lateral_offset_m,
    mean_direction,
    paired_comparison,
    plan_climatology,
    repeated_kfold,
    score_runs,
    section_to_plan,
    unique_runs,
)
from fieldkit.io.path_observations import read_release_deposit

DATA = Path(__file__).parents[1] / "data" / "tschamut2014"
SPLIT = DATA / "calibration_split"
BASE = Path(__file__).parents[2] / "examples" / "tschamut" / "model_base.json"


def test_doctests():
    assert doctest.testmod(plan_scores).failed == 0


# --- energy score --------------------------------------------------------------


def test_energy_score_of_a_point_mass_is_the_distance():
    rng = np.random.default_rng(1)
    for d in (1, 2, 3):
        x = rng.normal(size=d)
        y = rng.normal(size=d)
        ens = np.repeat(x[None], 7, axis=0)  # seven equal members: a point mass
        assert energy_score(ens, y) == pytest.approx(np.linalg.norm(x - y), rel=1e-12)
        assert energy_score(ens, y, fair=True) == pytest.approx(
            np.linalg.norm(x - y), rel=1e-12
        )
    assert energy_score(np.array([[3.0, 4.0]]), np.zeros(2)) == 5.0
    assert math.isnan(energy_score(np.array([[3.0, 4.0]]), np.zeros(2), fair=True))


def test_energy_score_in_one_dimension_is_the_crps():
    rng = np.random.default_rng(2)
    x = rng.gamma(2.0, 5.0, 41)
    for y in (-3.0, 4.0, 9.5, 60.0):
        assert energy_score(x[:, None], np.array([y])) == pytest.approx(
            crps_ensemble(x, y), rel=1e-12
        )
        assert energy_score(x, np.array([y]), fair=True) == pytest.approx(
            fair_crps(x, y), rel=1e-12
        )


def test_energy_score_equals_the_pairwise_definition_in_blocks(monkeypatch):
    rng = np.random.default_rng(3)
    x = rng.normal(size=(300, 2)) * [4.0, 1.0]
    y = np.array([1.0, -2.0])
    m = len(x)
    pair = np.linalg.norm(x[:, None] - x[None], axis=2).sum()
    absolute = np.linalg.norm(x - y, axis=1).mean()
    expected = absolute - pair / (2 * m * m)
    expected_fair = absolute - pair / (2 * m * (m - 1))
    monkeypatch.setattr(plan_scores, "_PAIR_BLOCK", 64)  # 5 blocks, last partial
    assert energy_score(x, y) == pytest.approx(expected, rel=1e-12)
    assert energy_score(x, y, fair=True) == pytest.approx(expected_fair, rel=1e-12)
    # non-finite members are dropped
    with_nan = np.vstack([x, [[np.nan, 0.0]]])
    assert energy_score(with_nan, y) == pytest.approx(expected, rel=1e-12)


def test_fair_energy_score_is_unbiased_for_a_bivariate_normal():
    # F = N(0, I_2), y = 0: E||X|| = sqrt(pi/2) (Rayleigh, sigma 1) and X - X' is
    # N(0, 2 I) so E||X - X'|| = sqrt(pi); ES(F, 0) = sqrt(pi/2) - sqrt(pi)/2.
    truth = math.sqrt(math.pi / 2) - math.sqrt(math.pi) / 2
    m, n = 4, 20000
    ens = np.random.default_rng(4).normal(size=(n, m, 2))
    y = np.zeros((n, 2))
    fair = energy_scores(ens, y, fair=True)
    empirical = energy_scores(ens, y)
    se = fair.std(ddof=1) / math.sqrt(n)
    assert abs(fair.mean() - truth) < 4 * se
    # the empirical score is high by E||X - X'|| / (2m) (about 170 SEs)
    bias = math.sqrt(math.pi) / (2 * m)
    assert abs(empirical.mean() - (truth + bias)) < 4 * se
    assert bias > 50 * se


# --- fair CRPS -----------------------------------------------------------------


def normal_crps(mu: float, sigma: float, y: float) -> float:
    """Closed form (Gneiting & Raftery 2007, eq. 5)."""
    z = (y - mu) / sigma
    return sigma * (
        z * (2 * stats.norm.cdf(z) - 1) + 2 * stats.norm.pdf(z) - 1 / math.sqrt(math.pi)
    )


@pytest.mark.parametrize("m", [2, 5, 20])
def test_fair_crps_is_unbiased_for_a_normal(m):
    mu, sigma, y, n = 100.0, 8.0, 109.0, 200000 // m
    samples = np.random.default_rng(m).normal(mu, sigma, size=(n, m))
    truth = normal_crps(mu, sigma, y)
    fair = fair_crps(samples, np.full(n, y))
    se = fair.std(ddof=1) / math.sqrt(n)
    assert abs(fair.mean() - truth) < 4 * se
    # the ensemble's own CRPS is high by E|X - X'| / (2m) = sigma / (m sqrt(pi))
    # (exactly, ensemble by ensemble: the two differ only in the spread term)
    empirical = np.array([crps_ensemble(s, y) for s in samples[:2000]])
    bias = sigma / (m * math.sqrt(math.pi))
    assert np.mean(empirical - fair[:2000]) == pytest.approx(bias, rel=0.05)
    assert bias > 10 * se


def test_fair_crps_by_hand_and_non_finite_members():
    # members 0, 2, 4 at y = 1: E|x - y| = (1 + 1 + 3) / 3 = 5/3; pairs i != j:
    # |0-2| + |0-4| + |2-4| = 8, twice = 16, / (2 * 3 * 2) = 4/3 -> 1/3.
    assert fair_crps(np.array([4.0, 0.0, 2.0]), 1.0) == pytest.approx(1 / 3)
    rows = np.array([[4.0, 0.0, 2.0, np.nan], [1.0, np.nan, np.inf, np.nan]])
    out = fair_crps(rows, np.array([1.0, 1.0]))
    assert out[0] == pytest.approx(1 / 3)
    assert math.isnan(out[1])  # one finite member: no fair score


# --- lateral offset, climatology -------------------------------------------------


def test_lateral_offset_sign_and_size():
    release = np.array([10.0, 20.0])
    # downslope along (1, -1)/sqrt(2); a deposit 3 m to the left of that line
    u = np.array([1.0, -1.0])
    left = release + 5 * u / math.sqrt(2) + 3 * np.array([1.0, 1.0]) / math.sqrt(2)
    right = release + 5 * u / math.sqrt(2) - 3 * np.array([1.0, 1.0]) / math.sqrt(2)
    out = lateral_offset_m(release, np.array([left, right]), u * 7.0)
    np.testing.assert_allclose(out, [3.0, -3.0], rtol=1e-12)
    with pytest.raises(ArgumentError, match="direction_xy"):
        lateral_offset_m(release, left, np.zeros(2))


def test_plan_climatology_moves_the_calibration_vectors_to_each_release():
    cal_rel = np.array([[0.0, 0.0], [5.0, 5.0]])
    cal_dep = np.array([[3.0, -4.0], [5.0, -5.0]])
    ens = plan_climatology(cal_rel, cal_dep, np.array([[100.0, 0.0], [0.0, 100.0]]))
    np.testing.assert_array_equal(
        ens, [[[103.0, -4.0], [100.0, -10.0]], [[3.0, 96.0], [0.0, 90.0]]]
    )
    u = mean_direction(cal_rel, cal_dep)
    np.testing.assert_allclose(u, np.array([3.0, -14.0]) / math.hypot(3.0, 14.0))


def test_score_runs_a_perfect_point_forecast_scores_zero():
    release = np.array([[0.0, 0.0], [10.0, 0.0]])
    observed = np.array([[30.0, -40.0], [10.0, -20.0]])
    ens = np.repeat(observed[:, None], 3, axis=1)
    s = score_runs(ens, release, observed, np.array([0.0, -1.0]))
    np.testing.assert_allclose(s.energy_fair_m, 0.0, atol=1e-12)
    np.testing.assert_allclose(s.distance_crps_fair_m, 0.0, atol=1e-12)
    np.testing.assert_allclose(s.distance_observed_m, [50.0, 20.0])
    # looking along -y, +x is to the left
    np.testing.assert_allclose(s.lateral_observed_m, [30.0, 0.0])
    assert s.summary()["distance_coverage_90"] == 1.0
    assert s.summary()["distance_bias_m"] == pytest.approx(0.0, abs=1e-12)


# --- paired comparisons ----------------------------------------------------------


def test_paired_comparison_against_a_hand_computation():
    # 3 seeds x 4 runs; the seed-averaged per-run differences A - B are
    # -1, -2, -3, -6: mean -3, deviations 2, 1, 0, -3 -> sum of squares 14,
    # SD sqrt(14/3), SE sqrt(14/3)/2 = 1.0801.
    b = np.array([10.0, 20.0, 30.0, 40.0])
    per_run = np.array([-1.0, -2.0, -3.0, -6.0])
    wiggle = np.array([[1.0, -1.0, 0.5, 0.0], [0.0, 2.0, -0.5, 1.0],
                       [-1.0, -1.0, 0.0, -1.0]])  # fmt: skip  # zero mean per run
    a = b + per_run + wiggle
    c = paired_comparison(a, b, "energy_fair_m", "3-D", "climatology", seeds=[1, 2, 3])
    assert c.mean_difference == pytest.approx(-3.0)
    assert c.se == pytest.approx(math.sqrt(14 / 3) / 2, rel=1e-12)
    assert c.n_runs == 4 and c.seeds == (1, 2, 3)
    # seed 1: differences 0, -3, -2.5, -6 -> mean -2.875
    assert c.per_seed_difference[0] == pytest.approx(-2.875)
    d1 = np.array([0.0, -3.0, -2.5, -6.0])
    assert c.per_seed_se[0] == pytest.approx(d1.std(ddof=1) / 2)
    assert c.mean_a == pytest.approx(a.mean()) and c.mean_b == pytest.approx(25.0)
    # -3 <= -2 * 1.08 -> beats by two SEs, not by three
    assert c.beats(2.0) and not c.beats(3.0)
    d = c.to_dict()
    assert d["beats_by_2_se"] is True and d["per_seed_difference"][0] == -2.875
    lines = c.lines()
    assert lines[0].startswith("energy_fair_m: 3-D ")
    assert "-3.000 +- 1.080" in lines[1] and "beats climatology" in lines[1]
    assert lines[2] == "  seed 1: 3-D - climatology = -2.875 +- 1.231"
    # B - A: the same SE, the opposite verdict
    assert not paired_comparison(b, a).beats()


def test_paired_comparison_refuses_mismatched_or_missing_scores():
    with pytest.raises(ArgumentError, match="do not match"):
        paired_comparison(np.zeros((3, 4)), np.zeros((3, 5)))
    with pytest.raises(ArgumentError, match="scores_a is not finite at seed 1, run 2"):
        a = np.zeros((3, 4))
        a[1, 2] = np.nan
        paired_comparison(a, np.zeros(4))


# --- splits and duplicates in the real data ---------------------------------------


def _xyz(obs, point):
    return obs.runs[[f"{point}_x_m", f"{point}_y_m", f"{point}_z_m"]].to_numpy(float)


@pytest.fixture(scope="module")
def all_runs():
    return read_release_deposit(
        DATA / "release_points.csv", DATA / "observed_deposition.csv"
    )


@pytest.fixture(scope="module")
def fixed_split():
    cal = read_release_deposit(
        SPLIT / "calibration_release_points.csv",
        SPLIT / "calibration_observed_deposition.csv",
    )
    hold = read_release_deposit(
        SPLIT / "holdout_release_points.csv", SPLIT / "holdout_observed_deposition.csv"
    )
    return cal, hold


def test_the_only_duplicate_run_in_tschamut_is_v033_v034(all_runs, fixed_split):
    groups = duplicate_runs(_xyz(all_runs, "release"), _xyz(all_runs, "deposit"))
    ids = all_runs.path_ids()
    assert [[ids[i] for i in g] for g in groups] == [["v033", "v034"]]
    assert len(unique_runs(len(ids), groups)) == 79
    cal, _ = fixed_split  # both are calibration runs of the fixed split
    groups = duplicate_runs(_xyz(cal, "release"), _xyz(cal, "deposit"))
    assert [[cal.path_ids()[i] for i in g] for g in groups] == [["v033", "v034"]]


def test_repeated_kfold_holds_every_run_out_once_per_repeat_balanced_by_group():
    groups = np.array(["1"] * 28 + ["2"] * 25 + ["4"] * 26)
    folds = repeated_kfold(79, k=5, repeats=3, seed=21, groups=groups)
    assert len(folds) == 15
    for repeat in range(3):
        mine = [f for f in folds if f.repeat == repeat]
        held = np.concatenate([f.holdout for f in mine])
        assert sorted(held.tolist()) == list(range(79))
        for f in mine:
            assert np.intersect1d(f.calibration, f.holdout).size == 0
            assert f.calibration.size + f.holdout.size == 79
            assert f.holdout.size in (15, 16)
            counts = np.array([np.sum(groups[f.holdout] == g) for g in "124"])
            assert np.all(np.abs(counts - np.array([28, 25, 26]) / 5) < 1)
    again = repeated_kfold(79, k=5, repeats=3, seed=21, groups=groups)
    pairs = zip(folds, again, strict=True)
    assert all(np.array_equal(f.holdout, g.holdout) for f, g in pairs)
    assert not np.array_equal(folds[0].holdout, folds[5].holdout)
    with pytest.raises(ArgumentError, match="k must be"):
        repeated_kfold(4, k=5)


def _climatology_scores(cal_rel, cal_dep, rel, dep):
    ens = plan_climatology(cal_rel, cal_dep, rel)
    return score_runs(ens, rel, dep, mean_direction(cal_rel, cal_dep)).summary()


def test_climatology_held_out_scores_on_the_fixed_tschamut_split(fixed_split):
    cal, hold = fixed_split
    rel, dep = _xyz(hold, "release")[:, :2], _xyz(hold, "deposit")[:, :2]
    cal_rel, cal_dep = _xyz(cal, "release")[:, :2], _xyz(cal, "deposit")[:, :2]
    # all 18 calibration runs (v033 and v034 both): the 12.5 m and ~8 m are
    # the ensemble's own (empirical) energy score and CRPS
    s = _climatology_scores(cal_rel, cal_dep, rel, dep)
    assert s["n_runs"] == 18
    assert s["energy_m"] == pytest.approx(12.507, abs=1e-3)
    assert s["energy_fair_m"] == pytest.approx(11.721, abs=1e-3)
    assert s["distance_crps_fair_m"] == pytest.approx(7.613, abs=1e-3)
    # the duplicate counted once (17 calibration runs)
    keep = unique_runs(18, duplicate_runs(_xyz(cal, "release"), _xyz(cal, "deposit")))
    s = _climatology_scores(cal_rel[keep], cal_dep[keep], rel, dep)
    assert s["energy_m"] == pytest.approx(12.675, abs=1e-3)
    assert s["energy_fair_m"] == pytest.approx(11.818, abs=1e-3)
    assert s["energy_fair_m_se"] == pytest.approx(1.857, abs=1e-3)
    assert s["distance_crps_fair_m"] == pytest.approx(7.671, abs=1e-3)
    assert s["distance_crps_fair_m_se"] == pytest.approx(1.966, abs=1e-3)
    assert s["lateral_crps_fair_m"] == pytest.approx(7.116, abs=1e-3)
    assert s["distance_coverage_90"] == pytest.approx(13 / 18)
    assert s["distance_observed_mean_m"] == pytest.approx(97.629, abs=1e-3)
    assert s["distance_bias_m"] == pytest.approx(-6.252, abs=1e-3)


def test_climatology_repeated_kfold_over_the_79_distinct_runs(all_runs):
    rel, dep = _xyz(all_runs, "release"), _xyz(all_runs, "deposit")
    keep = unique_runs(len(rel), duplicate_runs(rel, dep))
    rel, dep = rel[keep, :2], dep[keep, :2]
    groups = all_runs.runs["group"].to_numpy()[keep]
    folds = repeated_kfold(len(keep), k=5, repeats=10, seed=21, groups=groups)
    per_run = np.zeros((10, len(keep), 2))
    for f in folds:
        c, h = f.calibration, f.holdout
        ens = plan_climatology(rel[c], dep[c], rel[h])
        s = score_runs(ens, rel[h], dep[h], mean_direction(rel[c], dep[c]))
        per_run[f.repeat, h] = np.column_stack(
            [s.energy_fair_m, s.distance_crps_fair_m]
        )
    mean = per_run.mean(axis=0).mean(axis=0)
    np.testing.assert_allclose(mean, [13.875, 10.029], atol=1e-3)


def test_section_to_plan_places_the_observed_stop_as_path_runs_measures_it(fixed_split):
    from fieldkit.fit.path_sections import path_runs
    from fieldkit.io.dem import read_dem
    from fieldkit.model.model_file import read_model

    _, hold = fixed_split
    base = read_model(BASE)
    runs = path_runs(hold, read_dem(DATA / "terrain.asc"), base, section="descent")
    deposits = _xyz(hold, "deposit")[:, :2]
    for run, deposit in zip(runs, deposits, strict=True):
        px, py = run.observations["section_x_m"], run.observations["section_y_m"]
        # the section's own vertices come back at their chainages (those >= 0 of the
        # profile; the ground kept upslope is at negative chainage, on the line back)
        x = run.model.profile.x_m
        on = section_to_plan(px, py, x[x >= 0])
        np.testing.assert_allclose(on, np.column_stack([px, py]), atol=1e-9)
        back = section_to_plan(px, py, x[0])
        assert np.hypot(*(back - [px[0], py[0]])) == pytest.approx(-x[0], rel=1e-9)
        # the observed stop's chainage lies lateral_offset_m from the deposit
        stop = section_to_plan(px, py, run.observed_runout_m)
        assert np.hypot(*(stop - deposit)) == pytest.approx(
            run.lateral_offset_m, abs=1e-6
        )


@pytest.mark.slow
def test_the_2d_calibrated_model_loses_to_the_climatology_in_plan(cli, tmp_path):
    """The issue's measurement: `fieldkit fit` on the calibration runs (the README's
    command), its held-out deposits in plan over seeds 1-3, against the plan
    climatology (v033 counted once) -- about twice as bad on both scores."""
    from fieldkit.fit.path_runs import simulated_runouts
    from fieldkit.fit.path_sections import path_runs
    from fieldkit.io.dem import read_dem
    from fieldkit.model.model_file import read_model

    r = cli(
        "fit", "--model", BASE,
        "--paths", SPLIT / "calibration_release_points.csv",
        "--deposits", SPLIT / "calibration_observed_deposition.csv",
        "--dem", DATA / "terrain.asc", "--rocks", "40", "--bootstrap", "2",
        "-o", tmp_path / "cal.json",
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    cal = read_release_deposit(
        SPLIT / "calibration_release_points.csv",
        SPLIT / "calibration_observed_deposition.csv",
    )
    hold = read_release_deposit(
        SPLIT / "holdout_release_points.csv", SPLIT / "holdout_observed_deposition.csv"
    )
    keep = unique_runs(18, duplicate_runs(_xyz(cal, "release"), _xyz(cal, "deposit")))
    cal_rel, cal_dep = _xyz(cal, "release")[keep, :2], _xyz(cal, "deposit")[keep, :2]
    rel, dep = _xyz(hold, "release")[:, :2], _xyz(hold, "deposit")[:, :2]
    u = mean_direction(cal_rel, cal_dep)
    clim = score_runs(plan_climatology(cal_rel, cal_dep, rel), rel, dep, u)
    runs = path_runs(hold, read_dem(DATA / "terrain.asc"),
                     read_model(tmp_path / "cal.json"), section="descent")  # fmt: skip
    per_seed = []
    for seed in (1, 2, 3):
        ens = [
            section_to_plan(run.observations["section_x_m"],
                            run.observations["section_y_m"],
                            simulated_runouts(run, run.model, 200, seed, i))
            for i, run in enumerate(runs)
        ]  # fmt: skip
        per_seed.append(score_runs(ens, rel, dep, u))
    for score, model_m, clim_m in (
        ("energy_fair_m", 20.2, 11.818),
        ("distance_crps_fair_m", 17.2, 7.671),
    ):
        a = np.array([getattr(s, score) for s in per_seed])
        c = paired_comparison(getattr(clim, score), a, score, "climatology", "2-D")
        assert c.mean_b == pytest.approx(model_m, abs=1.0)
        assert c.mean_a == pytest.approx(clim_m, abs=1e-3)
        assert c.beats(2.0), c.lines()
