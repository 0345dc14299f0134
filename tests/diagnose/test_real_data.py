"""Diagnosis and eq. 5.4 on the thesis surveys (docs/real-data-diagnosis.md).

Everything is computed live from ``surveys/`` with fieldkit's reduction and the
script ``examples/diagnose_real_data.py``; the assertions pin the qualitative
findings with tolerances wide enough for Monte Carlo noise and narrow enough to fail
if the finding changed.
"""

from __future__ import annotations

import importlib.util
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from fieldkit.diagnose.impacts import diagnose_impacts
from fieldkit.errors import InputFileError
from fieldkit.reduce.uncertainty import PositionError

REPO = Path(__file__).resolve().parents[2]

spec = importlib.util.spec_from_file_location(
    "diagnose_real_data", REPO / "examples" / "diagnose_real_data.py"
)
real = importlib.util.module_from_spec(spec)
sys.modules[spec.name] = real  # dataclasses look their module up
spec.loader.exec_module(real)

DATA = {ds.name: ds for ds in real.DATASETS}


@pytest.fixture(scope="module")
def tornado():
    return real.reduce_dataset(DATA["tornado_mountain"])


@pytest.fixture(scope="module")
def tornado_deltas(tornado):
    return real.error_draws(tornado, 200, np.random.default_rng(7))


def test_tornado_reduces_to_48_diagnosable_impacts(tornado):
    assert len(tornado.table) == 48
    assert tornado.dropped == ["A", "45"]  # the source and the stop
    assert np.isfinite(tornado.table.column("vfn_sd_mps")).all()


def test_naive_fit_on_tornado_gives_a_falling_power_law(tornado):
    b, se, n = real.naive_slope(
        tornado.table.column("theta_i_deg"), tornado.table.column("e_n")
    )
    assert n == 48
    assert 0.5 < b < 0.9  # 0.71 ± 0.11: shallower than the thesis's pooled 1.03
    assert 0.07 < se < 0.16


def test_survey_error_makes_little_of_tornados_slope_material_mix_most(
    tornado, tornado_deltas
):
    assert len(tornado_deltas) >= 195  # nearly every draw has a ballistic solution
    b, _, _ = real.naive_slope(
        tornado.table.column("theta_i_deg"), tornado.table.column("e_n")
    )
    # One constant e_n + the survey's own error: a small positive b (0.05) ...
    errors = real.null_slopes(tornado.table, tornado_deltas)
    assert -0.05 < errors.mean() < 0.2
    assert np.percentile(errors, 97.5) < b - 0.3
    # ... each material's own constant e_n: most of the measured slope (0.59),
    # because the rock and talus impacts are the shallow ones.
    mixed = real.null_slopes(tornado.table, tornado_deltas, per_material=True)
    assert 0.45 < mixed.mean() < 0.75
    assert mixed.mean() / b > 0.65


def test_within_colluvium_the_slope_is_within_the_null(tornado, tornado_deltas):
    col = (tornado.table.frame["material"] == "colluvium").to_numpy()
    sub = real.ImpactTable(tornado.table.frame[col].reset_index(drop=True))
    b, se, n = real.naive_slope(sub.column("theta_i_deg"), sub.column("e_n"))
    assert n == 42
    assert 0.1 < b < 0.45 and se < 0.2
    null = real.null_slopes(sub, tornado_deltas[:, col])
    assert 0.03 < null.mean() < 0.2  # errors alone: a falling law, b ~ 0.1
    assert np.percentile(null, 97.5) > b  # the measured slope is inside the null


def test_without_survey_error_the_null_slope_vanishes(tornado):
    # The mechanism: the spurious slope is made by the position error, so a survey
    # a hundred times better leaves the constant law's slope at zero.
    precise = replace(
        tornado,
        options=replace(
            tornado.options, position_error=PositionError(0.005, 0.005, 0.0025)
        ),
    )
    deltas = real.error_draws(precise, 50, np.random.default_rng(3))
    slopes = real.null_slopes(tornado.table, deltas)
    assert abs(slopes.mean()) < 0.05
    mixed = real.null_slopes(tornado.table, deltas, per_material=True)
    assert mixed.mean() > 0.5  # the material mix stays


def test_single_impact_surveys_are_too_small_to_diagnose():
    for name in ("asphalt", "kreuger_quarry", "mt_stephen"):
        red = real.reduce_dataset(DATA[name])
        assert len(red.table) <= 2
        with pytest.raises(InputFileError, match="too few impacts to diagnose"):
            diagnose_impacts(red.table, rng=np.random.default_rng(0))


@pytest.mark.slow
def test_tornado_diagnosis_prefers_speed_law_and_rejects_angle_law(tornado):
    d = diagnose_impacts(tornado.table, rng=np.random.default_rng(real.SEED)).to_json()
    assert d["recommended"] == "velocity_scaled_restitution"
    angle = next(
        c for c in d["candidates"] if c["effect"] == "angle_dependent_restitution"
    )
    assert not angle["meaningful"]
    assert angle["improvement"] < angle["improvement_se"]
    assert "rotation_friction" in d["skipped"]  # spins are not measured


@pytest.mark.slow
def test_null_tables_rarely_recommend_anything(tornado):
    # Tables with no effect at all (constant e_n + the survey's own error,
    # re-propagated from the points) must not look like a speed law: with the
    # 1-SE rule they did in 9 of 20; with the 2-SE rule and the 1 % minimum gain in
    # 1 of 20 (docs/real-data-diagnosis.md). At most 1 of 8 here.
    deltas = real.error_draws(tornado, 10, np.random.default_rng(real.SEED))
    recs = [
        diagnose_impacts(
            real.null_table(tornado.table, deltas[k]),
            rng=np.random.default_rng(real.SEED + k),
        ).recommended
        for k in range(8)
    ]
    assert sum(r is not None for r in recs) <= 1, recs


@pytest.mark.slow
def test_pooled_naive_slope_reproduces_the_thesis_and_exceeds_the_null():
    reds = [real.reduce_dataset(ds) for ds in real.DATASETS]
    table = real.pooled(reds)
    assert len(table) == 61
    b, se, _ = real.naive_slope(table.column("theta_i_deg"), table.column("e_n"))
    assert abs(b - real.THESIS_B) < 2 * se  # the thesis's b = 1.03 is reproduced
    rng = np.random.default_rng(11)
    draws = [real.error_draws(r, 150, rng) for r in reds]
    k = min(len(d) for d in draws)
    assert k >= 10  # Ehime: most geometries have no ballistic solution
    deltas = np.concatenate([d[:k] for d in draws], axis=1)
    assert np.percentile(real.null_slopes(table, deltas), 97.5) < b - 0.4
    mixed = real.null_slopes(table, deltas, per_material=True)
    assert np.percentile(mixed, 97.5) < b
    d = diagnose_impacts(table, rng=np.random.default_rng(real.SEED))
    assert d.recommended != "angle_dependent_restitution"
