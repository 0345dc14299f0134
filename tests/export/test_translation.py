"""The translation error and the in-range search (fieldkit/export/translation.py)."""

from dataclasses import replace

import numpy as np
import pytest

from fieldkit.export.translation import (
    behaviour_gap,
    closest_in_range,
    fit_scaled,
    realised_impacts,
    translation_error,
)
from fieldkit.model.model_file import model_from_dict, read_model

TORNADO = "surveys/tornado_mountain/model_rocfall_table_7_1.json"


def test_fit_scaled_recovers_a_scaled_law_and_its_spread():
    rng = np.random.default_rng(1)
    vi = rng.uniform(2, 30, 5000)
    factor = 1.0 / (1.0 + (vi / 9.144) ** 2)  # RocFall's velocity scaling, K = 30 ft/s
    p = 0.8 + rng.normal(0, 0.05, vi.size)  # each impact's own coefficient
    s = fit_scaled(vi, p * factor * vi, factor, 0.0, 1.0)
    assert s.value == pytest.approx(0.8, abs=0.005)
    assert s.spread == pytest.approx(0.05, rel=0.05)
    assert not s.clipped and s.n == 5000


def test_fit_scaled_clips_to_the_range_at_the_constrained_optimum():
    vi = np.array([5.0, 10.0, 20.0])
    s = fit_scaled(vi, 1.2 * vi, 1.0, 0.0, 1.0)
    assert (s.value, s.unclipped, s.clipped) == (1.0, pytest.approx(1.2), True)
    # the objective is convex: no value in range does better than the clip
    grid = np.linspace(0, 1, 101)
    sse = [np.sum((1.2 * vi - g * vi) ** 2) for g in grid]
    assert grid[int(np.argmin(sse))] == 1.0
    assert np.isnan(fit_scaled(np.zeros(0), np.zeros(0), 1.0, 0, 1).value)


def test_realised_impacts_of_a_constant_pair_are_that_pair():
    m = read_model(TORNADO)
    f = realised_impacts(m, rocks=50)
    for name, rows in f.groupby("material"):
        en = fit_scaled(-rows["vin_mps"], rows["vfn_mps"], 1.0, 0, 2).value
        # e_n drawn per impact with SD e_n_sd around the material's value
        assert en == pytest.approx(m.materials[name].e_n, abs=0.02)


def test_the_same_model_has_no_translation_error():
    m = read_model(TORNADO)
    t = translation_error(m, m, rocks=300)
    assert [r.difference for r in t.rows] == [0.0] * len(t.rows)
    assert len(t.rows) == 2 + 2 * len(t.at_m) and t.worst_percent == 0.0


def test_a_constant_pair_for_a_scaled_law_errs_and_the_search_cuts_it():
    base = read_model(TORNADO)
    calibrated = replace(
        base,
        materials={
            n: replace(m, e_n=1.15 if n == "colluvium" else m.e_n)
            for n, m in base.materials.items()
        },
        effects={**base.effects, "velocity_scaled_restitution": {"k_mps": 16.9}},
    )
    impacts = realised_impacts(calibrated)
    names = list(calibrated.materials)
    start = []
    for n in names:
        rows = impacts[impacts["material"] == n]
        start.append(fit_scaled(-rows["vin_mps"], rows["vfn_mps"], 1.0, 0, 1).value)
        start.append(fit_scaled(rows["vit_mps"], rows["vft_mps"], 1.0, 0, 1).value)
    effects = {
        k: v
        for k, v in calibrated.effects.items()
        if k != "velocity_scaled_restitution"
    }

    def build(v):
        materials = {
            n: replace(calibrated.materials[n], e_n=v[2 * i], e_t=v[2 * i + 1])
            for i, n in enumerate(names)
        }
        return replace(calibrated, materials=materials, effects=effects)

    lumped = translation_error(calibrated, build(start))
    s = closest_in_range(calibrated, build, start, [0] * 4, [1] * 4)
    found = translation_error(calibrated, build(s.values))  # a held-out stream
    assert all(0 <= v <= 1 for v in s.values)
    assert s.gap < s.start_gap / 3
    assert behaviour_gap(found) < behaviour_gap(lumped) / 3


def test_gap_counts_a_quantity_one_model_never_reaches():
    from fieldkit.export.translation import Row, Translation

    r = Row("q", "m", 1.0, 0.1, float("nan"), float("nan"))
    assert behaviour_gap(Translation([r], (), 1, 0, True, (0, 0))) == pytest.approx(
        np.log(10) ** 2
    )


def test_default_points_avoid_the_section_end():
    m = model_from_dict(
        {
            "profile": {"x_m": [0, 60, 120], "z_m": [60, 20, 0], "material": "talus"},
            "materials": {"talus": {"e_n": 0.9, "e_t": 0.95, "friction_deg": 5}},
            "body": {"mass_kg": 100, "radius_m": 0.2},
            "seeder": {"x_m": 1, "z_m": 70},
        }
    )
    t = translation_error(m, m, rocks=100)
    assert all(1 < x < 118.8 for x in t.at_m)
