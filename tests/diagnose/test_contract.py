"""The diagnosis JSON keeps the contract of docs/architecture.md §4, and a seed
reproduces it."""

from __future__ import annotations

import json

import numpy as np
import pytest
from diagnose_cases import ANGLE, ROTATION, VELOCITY

from fieldkit.diagnose import candidates as cands
from fieldkit.diagnose.impacts import diagnose_impacts
from fieldkit.diagnose.scoring import DEFAULT_Z, MIN_GAIN
from fieldkit.model.effects import registry

CONTRACT_KEYS = [
    "metric",
    "baseline",
    "candidates",
    "recommended",
    "steps",
    "confounded",
    "after",
]


def _is_number(x) -> bool:
    return isinstance(x, float) and np.isfinite(x)


def _check_params(params: dict) -> None:
    assert isinstance(params, dict)
    for k, v in params.items():
        assert isinstance(k, str) and _is_number(v), (k, v)


def _check_ranking(candidates: list, reference_cv: float) -> None:
    cvs = [c["cv_rmse_mps"] for c in candidates]
    assert cvs == sorted(cvs)
    for c in candidates:
        assert isinstance(c["effect"], str)
        for key in ("cv_rmse_mps", "improvement", "improvement_se"):
            assert _is_number(c[key]), (c["effect"], key, c[key])
        assert c["improvement_se"] >= 0.0
        assert c["improvement"] == pytest.approx(
            1.0 - c["cv_rmse_mps"] / reference_cv, abs=1e-12
        )
        # the rule of scoring.meaningful: gain > z SE and > the minimum gain
        assert c["meaningful"] == (
            c["improvement"] > max(MIN_GAIN, DEFAULT_Z * c["improvement_se"])
        )
        _check_params(c["params"])
        assert c["params"] and all(k.startswith(c["effect"] + ".") for k in c["params"])


@pytest.mark.parametrize(
    ("effects", "paths"), [((ANGLE,), 40), ((VELOCITY, ROTATION), 25), ((), 40)]
)
def test_json_matches_contract(diagnosed, effects, paths):
    _, d = diagnosed(effects, noise=0.05, paths=paths, seed=0)
    j = d.to_json()
    assert list(j)[: len(CONTRACT_KEYS)] == CONTRACT_KEYS
    json.dumps(j, allow_nan=False)  # plain JSON, no NaN
    assert j["metric"] == "cv_rmse_mps"
    base = j["baseline"]
    assert base["effects"] == []
    assert _is_number(base["cv_rmse_mps"]) and base["cv_rmse_mps"] > 0.0
    _check_params(base["params"])
    assert all(k.startswith("materials.") for k in base["params"])
    # candidates: the impact-level effects, each either ranked or skipped
    ranked = [c["effect"] for c in j["candidates"]]
    # every candidate the registry's metadata names (the laws and the statistical
    # alternative affine_rebound)
    assert sorted(ranked) == sorted(cands.IMPACT_CANDIDATES)
    assert {ANGLE, VELOCITY, ROTATION, "affine_rebound"} <= set(ranked)
    assert set(ranked).isdisjoint(j["skipped"])
    assert set(ranked) | set(j["skipped"]) == {s.name for s in registry.EFFECTS}
    assert all(isinstance(v, str) and v for v in j["skipped"].values())
    _check_ranking(j["candidates"], base["cv_rmse_mps"])
    # steps: each ranks the rest against the model before it
    before = base["cv_rmse_mps"]
    for step in j["steps"]:
        assert step["cv_rmse_mps_before"] == before
        _check_ranking(step["candidates"], before)
        assert step["candidates"][0]["effect"] == step["added"]
        assert step["cv_rmse_mps"] == step["candidates"][0]["cv_rmse_mps"]
        before = step["cv_rmse_mps"]
    if j["steps"]:
        assert j["steps"][0]["added"] == j["recommended"]
        assert j["steps"][0]["candidates"] == j["candidates"]
    else:
        assert j["recommended"] is None
    assert j["after"]["effects"] == [s["added"] for s in j["steps"]]
    # accepted: every accepted step in order, right after the contract keys
    assert list(j)[len(CONTRACT_KEYS)] == "accepted"
    assert j["accepted"] == [s["added"] for s in j["steps"]]
    assert j["after"]["cv_rmse_mps"] == before
    _check_params(j["after"]["params"])
    assert {k.split(".")[0] for k in j["after"]["params"]} == {
        "materials",
        *j["after"]["effects"],
    }
    assert isinstance(j["confounded"], list)
    assert j["recommended"] in (None, *ranked)
    assert j["n_rows"] == len(d.arrays["path_id"])


def test_expected_content_of_the_contract(diagnosed):
    """The contract's numbers on the angle case (not only their shapes)."""
    table, d = diagnosed((ANGLE,), noise=0.05, paths=40, seed=0)
    j = d.to_json()
    assert j["recommended"] == ANGLE
    assert [s["added"] for s in j["steps"]] == [ANGLE]
    assert j["n_rows"] == len(table)
    # vfn, vft and omega_f of every impact (the synthetic spins are measured)
    assert j["n_data"] == 3 * len(table)


def test_same_seed_gives_identical_json(diagnosed):
    table, d = diagnosed((ROTATION,), noise=0.05, paths=40, seed=0)
    again = diagnose_impacts(table, rng=np.random.default_rng(0))
    assert json.dumps(again.to_json()) == json.dumps(d.to_json())


def test_other_fold_seeds_give_the_same_recommendation(diagnosed):
    _, first = diagnosed((ROTATION,), noise=0.05, paths=40, seed=0)
    _, other = diagnosed((ROTATION,), noise=0.05, paths=40, seed=0, fold_seed=1)
    a, b = first.to_json(), other.to_json()
    # other folds: other held-out errors ...
    assert a["baseline"]["cv_rmse_mps"] != b["baseline"]["cv_rmse_mps"]
    # ... the same finding, with falls within a few percent of each other
    assert b["recommended"] == a["recommended"] == ROTATION
    assert b["after"]["effects"] == a["after"]["effects"] == [ROTATION]
    fall = [
        1 - x["after"]["cv_rmse_mps"] / x["baseline"]["cv_rmse_mps"] for x in (a, b)
    ]
    assert fall[0] == pytest.approx(fall[1], abs=0.02)
    # full-data fits do not depend on the folds
    assert a["after"]["params"] == b["after"]["params"]
