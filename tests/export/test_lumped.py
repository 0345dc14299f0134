"""The constant e_n, e_t an impact law realises, for targets without the law."""

from __future__ import annotations

import numpy as np
import pytest

from fieldkit.export.lumped import lumped_equivalent
from fieldkit.model.model_file import model_from_dict


def _model(k_mps: float | None, e_n: float = 1.2) -> dict:
    data = {
        "profile": {"x_m": [0, 60, 160], "z_m": [60, 20, 0], "material": "talus"},
        "materials": {"talus": {"e_n": e_n, "e_t": 0.8, "friction_deg": 30}},
        "body": {"mass_kg": 100, "radius_m": 0.2},
        "seeder": {"x_m": 1, "z_m": 70},
    }
    if k_mps is not None:
        data["effects"] = {"velocity_scaled_restitution": {"k_mps": k_mps}}
    return data


def test_a_model_without_the_laws_is_returned_unchanged():
    model = model_from_dict(_model(None, e_n=0.4))
    lumped, lines = lumped_equivalent(model, "r.stone")
    assert lumped is model and lines == []


def test_a_law_that_does_nothing_gives_back_the_material_pair():
    # K = 1e9 m/s: the scaling factor is 1 to 1e-15 at these speeds, e_n_sd = 0:
    # every simulated rebound is vfn = e_n |vin|, vft = e_t vit exactly.
    model = model_from_dict(_model(1e9, e_n=0.45))
    lumped, lines = lumped_equivalent(model, "r.stone", rocks=40)
    assert lumped.materials["talus"].e_n == pytest.approx(0.45, abs=1e-9)
    assert lumped.materials["talus"].e_t == pytest.approx(0.8, abs=1e-9)
    assert "velocity_scaled_restitution" not in lumped.effects
    assert len(lines) == 1 and "e_n 0.450" in lines[0]


def test_velocity_scaling_lowers_the_realised_e_n_within_its_bounds():
    model = model_from_dict(_model(9.144))
    lumped, _ = lumped_equivalent(model, "r.stone", rocks=60)
    e_n = lumped.materials["talus"].e_n
    # each rebound has factor 1 / (1 + (vin/K)^2) in (0, 1): the fit lies between
    # e_n / (1 + (max |vin| / K)^2) and e_n; here below 1 though e_n = 1.2
    assert 0.0 < e_n < 1.0 < 1.2
    assert np.isfinite(e_n)
