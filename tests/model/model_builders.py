"""Model builders shared by the forward-model tests."""

from __future__ import annotations

import copy

import numpy as np

from fieldkit.model.model_file import model_from_dict
from fieldkit.model.results import SimulationResult

BASE = {
    "profile": {
        "x_m": [0.0, 20.0, 45.0, 70.0, 110.0],
        "z_m": [100.0, 84.0, 66.0, 55.0, 50.0],
        "material": ["rock", "talus", "talus", "soil"],
    },
    "materials": {
        "rock": {"e_n": 0.55, "e_t": 0.85, "friction_deg": 30, "roughness_m": 0.15,
                 "roughness_deg_sd": 2.0},
        "talus": {"e_n": 0.45, "e_t": 0.8, "friction_deg": 33, "roughness_m": 0.2},
        "soil": {"e_n": 0.3, "e_t": 0.7, "friction_deg": 38},
    },
    "body": {"mass_kg": 400.0, "radius_m": 0.33, "gyration_m": 0.21},
    "seeder": {"x_m": 1.0, "z_m": 102.0, "vx_mps": 3.0, "vz_mps": 0.5},
    "trees": {"x_m": [30.0, 52.0, 60.0, 80.0], "diameter_m": [0.3, 0.25, 0.4, 0.3],
              "height_m": [15.0, 12.0, 18.0, 10.0]},
}  # fmt: skip

#: Every effect on with non-neutral parameters.
ALL_EFFECTS = {
    "angle_dependent_restitution": {"b": 0.8},
    "velocity_scaled_restitution": {"k_mps": 12.0},
    "rotation_friction": {"friction": 0.6, "coupling": 0.7},
    "slope_roughness": {"scale": 1.0},
    "mass_loss": {"rate_per_m": 0.01, "impact_exponent": 0.2},
    "tree_impacts": {"hit_probability": 0.5},
    "air_drag": {"cd": 0.8},
}


def build(effects=None, sd=False, **changes) -> object:
    """A model from :data:`BASE` with ``effects``; ``sd`` adds per-impact SDs."""
    data = copy.deepcopy(BASE)
    data["effects"] = copy.deepcopy(effects or {})
    if sd:
        for m in data["materials"].values():
            m.update(e_n_sd=0.05, e_t_sd=0.04, friction_deg_sd=2.0)
        data["seeder"].update(vx_sd_mps=0.5, vz_sd_mps=0.3, omega_sd_radps=1.0,
                              mass_sd_kg=40.0)  # fmt: skip
    for key, value in changes.items():
        data[key] = value
    return model_from_dict(data, source="test.json")


def same_result(a: SimulationResult, b: SimulationResult) -> bool:
    """Bit-identical per-rock outcomes and impacts."""
    if not (
        np.array_equal(a.runout_x_m, b.runout_x_m)
        and np.array_equal(a.state, b.state)
        and np.array_equal(a.impacts_per_rock, b.impacts_per_rock)
    ):
        return False
    if a.impact_table is not None:
        cols = ["x_m", "z_m", "vf_x_mps", "vf_z_mps", "omega_f_radps", "mass_kg"]
        fa, fb = a.impact_table.frame[cols], b.impact_table.frame[cols]
        return bool(np.array_equal(fa.to_numpy(), fb.to_numpy()))
    return True
