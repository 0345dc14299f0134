"""The constant e_n, e_t an impact law realises, for targets without the law."""

from __future__ import annotations

import json

import numpy as np
import pytest

from fieldkit.export.lumped import lumped_equivalent
from fieldkit.export.translation import realised_impacts
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


def _crest_model() -> dict:
    """Velocity-scaled talus below a crest no rock ever strikes (above the seeder),
    with a fitted standard error on the talus e_n."""
    return {
        "profile": {
            "x_m": [0, 10, 70, 140],
            "z_m": [80, 70, 30, 10],
            "material": ["crest", "talus", "talus"],
        },
        "materials": {
            "crest": {"e_n": 0.5, "e_t": 0.8, "friction_deg": 30},
            "talus": {"e_n": 1.1, "e_t": 0.8, "friction_deg": 30},
        },
        "effects": {"velocity_scaled_restitution": {"k_mps": 13.0}},
        "body": {"mass_kg": 100, "radius_m": 0.2},
        "seeder": {"x_m": 12, "z_m": 72},
        "provenance": {
            "fit": {
                "parameters": {"materials.talus.e_n": {"value": 1.1, "stderr": 0.03}}
            }
        },
    }


def test_a_material_no_rock_touches_gets_its_own_law_not_the_raw_value():
    # before issue 19: crest kept e_n 0.5 "written without" the law (raw); now its
    # own law 0.5 / (1 + (v/13)^2) at every simulated impact's normal speed, as a
    # constant: sum(0.5 g v * v) / sum(v^2), and said loudly
    model = model_from_dict(_crest_model())
    lumped, lines = lumped_equivalent(model, "r.stone")
    impacts = realised_impacts(model)
    assert (impacts["material"] == "talus").all()
    v = -impacts["vin_mps"].to_numpy()
    expected = float(np.sum(0.5 / (1 + (v / 13.0) ** 2) * v * v) / np.sum(v * v))
    assert lumped.materials["crest"].e_n == pytest.approx(expected, rel=1e-12)
    assert expected < 0.5
    assert any(line.startswith("crest: NO SIMULATED IMPACT on it") for line in lines)


def test_lumped_values_carry_their_own_spread_through_the_cli(cli, tmp_path):
    # before issue 19 the r.stone README showed the lumped e_n with the calibrated
    # parameter's fit SE ("= 0.8 ± 0.03 (fit)")
    path = tmp_path / "m.json"
    path.write_text(json.dumps(_crest_model()))
    out = tmp_path / "out"
    r = cli("export", path, "--to", "rstone", "--extrude", "-o", out)
    assert r.exit_code == 0, r.output
    readme = (out / "README.md").read_text()
    row = next(x for x in readme.splitlines() if "materials.talus.e_n = " in x)
    written, calibrated = row.split("materials.talus.e_n = ", 1)[1].split("; ", 1)
    assert " written (spread 0." in written and " impacts)" in written
    assert calibrated.startswith("calibrated 1.1 ± 0.03 (fit)")
    assert "crest: NO SIMULATED IMPACT on it" in " ".join(readme.split())
