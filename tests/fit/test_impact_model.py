"""The impact predictor reproduces the simulator's own impact rows (same physics)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from fieldkit.fit.impact_model import predict_impacts
from fieldkit.model.model_file import model_from_dict
from fieldkit.model.simulate import simulate

SMOKE = Path(__file__).parents[1] / "model" / "data" / "smoke.json"


def _model(effects: dict) -> object:
    data = json.loads(SMOKE.read_text())
    for m in data["materials"].values():
        m["e_n_sd"] = 0.0
        m["e_t_sd"] = 0.0
        m["roughness_m"] = 0.1
    data["effects"] = effects
    data["seeder"]["omega_radps"] = -5.0
    return model_from_dict(data, source="smoke.json")


CASES = {
    "base": {},
    "angle_dependent_restitution": {"angle_dependent_restitution": {"b": 1.03}},
    "angle_dependent_restitution_literal": {
        "angle_dependent_restitution": {"b": 1.03, "a": 19.5}
    },
    "velocity_scaled_restitution": {"velocity_scaled_restitution": {"k_mps": 9.0}},
    "rotation_friction": {"rotation_friction": {"friction": 0.4, "coupling": 0.7}},
    "slope_roughness": {"slope_roughness": {"scale": 1.5}},
    "all_impact_effects": {
        "angle_dependent_restitution": {"b": 0.8},
        "velocity_scaled_restitution": {"k_mps": 12.0},
        "rotation_friction": {},
        "slope_roughness": {},
    },
}


@pytest.mark.parametrize("name", list(CASES))
def test_prediction_reproduces_simulated_rebounds(name):
    model = _model(CASES[name])
    table = simulate(model, 40, np.random.default_rng(3), record_impacts=True)
    table = table.impact_table
    assert len(table) > 100
    pred = predict_impacts(table, model)
    for col in ("vfn_mps", "vft_mps", "omega_f_radps"):
        np.testing.assert_allclose(pred[col], table.column(col), rtol=0, atol=1e-9)


def test_effects_change_the_prediction():
    """The comparison above is not vacuous: an effect moves the rebounds."""
    table = simulate(_model({}), 20, np.random.default_rng(1), record_impacts=True)
    base = predict_impacts(table.impact_table, _model({}))
    scaled = predict_impacts(
        table.impact_table, _model({"velocity_scaled_restitution": {"k_mps": 9.0}})
    )
    assert np.max(np.abs(base["vfn_mps"] - scaled["vfn_mps"])) > 0.5
