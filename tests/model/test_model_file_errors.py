"""Bad model files: one line naming the file and the field, nothing else."""

from __future__ import annotations

import copy
import json

import numpy as np
import pytest
from model_builders import BASE

from fieldkit.errors import InputFileError
from fieldkit.model import read_model, simulate, write_model
from fieldkit.model.model_file import model_to_dict


def write(tmp_path, data):
    path = tmp_path / "model.json"
    path.write_text(json.dumps(data))
    return path


def broken(change):
    data = copy.deepcopy(BASE)
    change(data)
    return data


CASES = [
    ("x not increasing", lambda d: d["profile"].update(x_m=[0, 20, 20, 70, 110]),
     "profile.x_m: must be strictly increasing (x[2] = 20 after x[1] = 20)"),
    ("one vertex", lambda d: d["profile"].update(x_m=[0], z_m=[1], material=[]),
     "profile.x_m: needs at least two vertices (got 1)"),
    ("undefined material", lambda d: d["profile"].update(
        material=["rock", "talus", "scree", "soil"]),
     "profile.material: segment 2 names material 'scree', not defined in materials "
     "(defined: rock, talus, soil)"),
    ("e_n < 0", lambda d: d["materials"]["talus"].update(e_n=-0.1),
     "materials.talus.e_n: must be >= 0 (got -0.1)"),
    ("sd < 0", lambda d: d["materials"]["rock"].update(e_t_sd=-0.02),
     "materials.rock.e_t_sd: must be >= 0 (got -0.02)"),
    ("seeder sd < 0", lambda d: d["seeder"].update(vx_sd_mps=-1),
     "seeder.vx_sd_mps: must be >= 0 m/s (got -1)"),
    ("unknown effect", lambda d: d.update(effects={"drag": {}}),
     "effects.drag: unknown effect (known: angle_dependent_restitution, "
     "velocity_scaled_restitution, rotation_friction, slope_roughness, mass_loss, "
     "tree_impacts, air_drag, affine_rebound)"),
    ("parameter out of bounds", lambda d: d.update(
        effects={"rotation_friction": {"coupling": 1.5}}),
     "effects.rotation_friction.coupling: must be in [0, 1] - (got 1.5)"),
    ("unknown parameter", lambda d: d.update(effects={"air_drag": {"c_d": 0.4}}),
     "effects.air_drag.c_d: unknown parameter (known: cd, air_density_kg_m3)"),
    ("seeder below ground", lambda d: d["seeder"].update(z_m=90.0),
     "seeder.z_m: start is below the ground (90 m < 99.2 m at x = 1 m)"),
    ("seeder off profile", lambda d: d["seeder"].update(x_m=-5.0),
     "seeder.x_m: must lie on the profile [0, 110] m (got -5)"),
    ("missing body", lambda d: d.pop("body"), "body: missing"),
]  # fmt: skip


@pytest.mark.parametrize("change, message", [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])  # fmt: skip
def test_bad_model_file_is_one_line_naming_file_and_field(tmp_path, change, message):
    path = write(tmp_path, broken(change))
    before = path.read_bytes()
    with pytest.raises(InputFileError) as err:
        read_model(path)
    assert str(err.value) == f"{path}: {message}"
    assert path.read_bytes() == before


def test_not_json(tmp_path):
    path = tmp_path / "model.json"
    path.write_text('{"profile": [1,')
    with pytest.raises(InputFileError, match=r"model.json: line 1: not valid JSON"):
        read_model(path)


def test_model_round_trips_and_with_parameters(tmp_path):
    model = read_model(write(tmp_path, broken(lambda d: d.update(
        effects={"angle_dependent_restitution": {"b": 0.5}}))))  # fmt: skip
    out = tmp_path / "again.json"
    write_model(model, out)
    again = read_model(out)
    assert model_to_dict(again) == model_to_dict(model)
    params = model.parameters()
    assert params["angle_dependent_restitution.b"] == 0.5
    assert params["angle_dependent_restitution.theta_ref_deg"] == 30.0
    assert params["materials.talus.e_n"] == 0.45
    changed = model.with_parameters({"materials.talus.e_n": 0.3,
                                     "angle_dependent_restitution.b": 1.0})  # fmt: skip
    assert changed.materials["talus"].e_n == 0.3
    assert changed.effects["angle_dependent_restitution"]["b"] == 1.0
    assert model.materials["talus"].e_n == 0.45
    a = simulate(model, 50, np.random.default_rng(1))
    b = simulate(again, 50, np.random.default_rng(1))
    assert np.array_equal(a.runout_x_m, b.runout_x_m)


def test_smoke_model_for_other_stages_reads(repo):
    model = read_model(repo / "tests/model/data/smoke.json")
    res = simulate(model, 20, np.random.default_rng(0))
    assert res.impacts > 0 and res.rocks == 20
