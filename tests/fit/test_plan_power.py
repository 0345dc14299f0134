"""What a held-out test in plan can show (fieldkit.fit.plan_power), on synthetic
worlds whose per-run information is known: none (every release equivalent), or
a lot (two release heights on one slope)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_plan_fit import bent_plane_model

from fieldkit.errors import ArgumentError
from fieldkit.fit.plan_fit import PlanRun
from fieldkit.fit.plan_power import (
    group_climatology_skill,
    runs_needed,
    virtual_campaigns,
)
from fieldkit.fit.plan_scores import energy_score, fair_crps, plan_climatology

#: The friction of the synthetic truth [deg] (the bent plane's floor stops rocks
#: 10-12 m past the toe from 75 m, spread by friction_deg_sd = 2 deg).
FRICTION_DEG = 27.0


def runs_at(heights_y_m: list[float]) -> list[PlanRun]:
    """Runs released across the plane (x 2.5-17.5 m) at the given y; their
    observed deposits are not used by the virtual campaigns."""
    n = len(heights_y_m)
    xs = np.linspace(2.5, 17.5, n)
    return [PlanRun(f"r{i}", np.array([x, y]), np.zeros(2), 100.0, 0.2)
            for i, (x, y) in enumerate(zip(xs, heights_y_m, strict=True))]  # fmt: skip


def test_no_per_run_information_means_no_advantage_over_the_climatology():
    """Every release on the same contour of a plane uniform across the slope: the
    deposit vector does not depend on the run, so the fair climatology scores, on
    average, as the truth does. Its (unfair) empirical score would lose by
    E|X - X'| / (2 m) -- 0.54 m / 34 = 0.016 m here (deposits 10-12 m past the
    toe), about 11 SEs of the mean: the test fails if the climatology is not
    scored fairly (checked: 0.0173 against a bound of 0.0044)."""
    truth = bent_plane_model(FRICTION_DEG)
    cal, hold = runs_at([75.0] * 17), runs_at([75.0] * 18)
    a = virtual_campaigns(truth, cal, hold, campaigns=300, holdout_rocks=100, seed=4)
    for t in (a.energy, a.distance):
        assert t.n_runs == 18 and t.differences.shape == (300,)
        assert abs(t.per_run_mean) <= 3.0 * t.mean_se, (t.per_run_mean, t.mean_se)
        assert t.mean_se < 0.005  # the check above is sharp
        # a 2-SE one-sided test at no advantage: about 2-5 % false passes
        assert t.pass_rate() <= 0.10
        assert math.isinf(t.runs_needed()) or t.runs_needed() > 500
    assert a.both_pass_rate <= 0.05
    assert a.measured and "300 virtual campaigns of 18 held-out runs" in a.lines()[0]


def test_release_height_is_per_run_information_a_perfect_forecast_shows():
    """Runs released alternately 75 m and 55 m up the plane: the higher ones slide
    farther on the floor, so the pooled vectors are bimodal and the truth, which
    knows each run's height, beats them on nearly every campaign."""
    truth = bent_plane_model(FRICTION_DEG)
    heights = [75.0 if i % 2 else 55.0 for i in range(36)]
    cal, hold = runs_at(heights[:17]), runs_at(heights[17:35])
    a = virtual_campaigns(truth, cal, hold, campaigns=100, holdout_rocks=100, seed=4)
    for t in (a.energy, a.distance):
        assert t.per_run_mean < -1.0  # metres per run
        assert t.pass_rate() >= 0.9
        assert t.runs_needed() < 18
    assert a.both_pass_rate >= 0.9
    d = a.to_dict()
    assert d["power_on_split_energy"] == a.energy.pass_rate()


def test_virtual_campaigns_are_reproducible_and_use_their_own_streams():
    truth = bent_plane_model(FRICTION_DEG)
    cal, hold = runs_at([75.0] * 4), runs_at([75.0] * 5)
    a = virtual_campaigns(truth, cal, hold, campaigns=10, holdout_rocks=20, seed=2)
    b = virtual_campaigns(truth, cal, hold, campaigns=10, holdout_rocks=20, seed=2)
    c = virtual_campaigns(truth, cal, hold, campaigns=10, holdout_rocks=20, seed=3)
    np.testing.assert_array_equal(a.energy.differences, b.energy.differences)
    assert not np.array_equal(a.energy.differences, c.energy.differences)
    assert "130363" in a.notes[0] and "104729" in a.notes[0]


def test_the_fast_scores_equal_plan_scores_on_one_campaign():
    """The campaign loop's vectorised scores against energy_score / fair_crps run by
    run (one campaign, so the climatology is built from its observations)."""
    from fieldkit.fit.plan_fit import HOLDOUT_STREAM, plan_ensembles
    from fieldkit.fit.plan_power import VIRTUAL_STREAM

    truth = bent_plane_model(FRICTION_DEG)
    heights = [75.0 if i % 2 else 60.0 for i in range(9)]
    cal, hold = runs_at(heights[:4]), runs_at(heights[4:])
    a = virtual_campaigns(truth, cal, hold, campaigns=3, holdout_rocks=15, seed=5)
    obs = plan_ensembles(truth, [*cal, *hold], 3, 5, stream=VIRTUAL_STREAM).deposits_xy
    fc = plan_ensembles(truth, hold, 15, 5, stream=HOLDOUT_STREAM).deposits_xy
    c = 1  # the second campaign
    rel_c = np.array([r.release_xy for r in cal])
    rel_h = np.array([r.release_xy for r in hold])
    dep_c = np.array([o[c] for o in obs[:4]])
    dep_h = np.array([o[c] for o in obs[4:]])
    clim = plan_climatology(rel_c, dep_c, rel_h)
    es = [energy_score(f, y, fair=True) - energy_score(k, y, fair=True)
          for f, k, y in zip(fc, clim, dep_h, strict=True)]  # fmt: skip
    dist = [fair_crps(np.hypot(*(f - r).T), np.hypot(*(y - r)))
            - fair_crps(np.hypot(*(k - r).T), np.hypot(*(y - r)))
            for f, k, y, r in zip(fc, clim, dep_h, rel_h, strict=True)]  # fmt: skip
    assert a.energy.differences[c] == pytest.approx(np.mean(es), abs=1e-9)
    assert a.distance.differences[c] == pytest.approx(np.mean(dist), abs=1e-9)


def synthetic_groups(shift_m: float, n_per: int = 20, seed: int = 0):
    """Three groups of runs from one release, deposits normal around (0, -100) m
    (SD 10 m) with group g's mean moved by g * shift_m down the fall line."""
    rng = np.random.default_rng(seed)
    groups = np.repeat(["a", "b", "c"], n_per)
    offset = np.repeat([0.0, 1.0, 2.0], n_per) * shift_m
    rel = np.zeros((groups.size, 2))
    x = rng.normal(0.0, 10.0, groups.size)
    y = -100.0 - offset + rng.normal(0.0, 10.0, groups.size)
    dep = np.column_stack([x, y])
    return rel, dep, groups


def test_a_group_that_carries_nothing_is_worth_nothing():
    rel, dep, g = synthetic_groups(0.0)
    a = group_climatology_skill(rel, dep, g, repeats=10)
    for t in (a.energy, a.distance):
        assert abs(t.per_run_mean) <= 3.0 * t.mean_se
        assert t.power_at(18) < 0.15
    assert not a.measured and "normal approximation" in "\n".join(a.lines())


def test_a_group_that_moves_the_deposit_is_found_and_priced():
    """Groups 30 m apart (3 SDs): the group's climatology is far sharper, and a test
    of 18 held-out runs would show it almost surely."""
    rel, dep, g = synthetic_groups(30.0)
    a = group_climatology_skill(rel, dep, g, repeats=10, split_runs=18)
    for t in (a.energy, a.distance):
        assert t.per_run_mean < -5.0
        assert t.per_run_mean < -5.0 * t.mean_se
        assert t.power_at(18) > 0.95
        assert t.runs_needed() < 18
    assert a.to_dict()["split_runs"] == 18


def test_runs_needed_gives_the_power_it_was_asked_for():
    from fieldkit.fit.plan_power import SkillTest

    t = SkillTest("s", np.zeros(2), np.ones(2), -0.9, 4.2, 0.4, 79)
    n = t.runs_needed()
    assert t.power_at(math.ceil(n)) == pytest.approx(0.8, abs=0.01)
    assert t.power_at(18) < 0.2
    assert runs_needed(0.0, 4.0) == math.inf
    assert math.isnan(runs_needed(math.nan, 4.0))


def test_bad_arguments_are_refused():
    truth = bent_plane_model(FRICTION_DEG)
    cal, hold = runs_at([75.0] * 4), runs_at([75.0] * 5)
    with pytest.raises(ArgumentError, match="campaigns must be >= 2"):
        virtual_campaigns(truth, cal, hold, campaigns=1)
    with pytest.raises(ArgumentError, match="held-out runs"):
        virtual_campaigns(truth, cal, hold[:1], campaigns=5)
    rel, dep, g = synthetic_groups(0.0, n_per=4)
    with pytest.raises(ArgumentError, match="fewer than k = 5 runs"):
        group_climatology_skill(rel, dep, g)
