"""A model file's profile from where users have it: vertex lists, a CSV, a DEM."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from fieldkit.errors import FieldkitError
from fieldkit.io.dem import read_dem
from fieldkit.model.dem_profile import steepest_descent_line
from fieldkit.model.model_file import read_model

DEM = Path(__file__).resolve().parents[1] / "data" / "tschamut2014" / "terrain.asc"

REST = {
    "materials": {
        "rock": {"e_n": 0.5, "e_t": 0.8, "friction_deg": 30},
        "talus": {"e_n": 0.3, "e_t": 0.7, "friction_deg": 35},
    },
    "body": {"mass_kg": 60, "radius_m": 0.18, "gyration_m": 0.114},
}


def write_model(folder: Path, profile: dict, seeder: dict) -> Path:
    path = folder / "model.json"
    path.write_text(json.dumps({"profile": profile, "seeder": seeder, **REST}))
    return path


def test_csv_profile_in_feet_is_read_in_metres_relative_to_the_model(tmp_path):
    (tmp_path / "section.csv").write_text(
        "x,z,material\n0,100,rock\n100,50,talus\n200,20,\n"
    )
    seeder = {"x_m": 1.0, "z_m": 31.0}
    path = write_model(tmp_path, {"csv": "section.csv", "units": "ft"}, seeder)
    model = read_model(path)
    np.testing.assert_allclose(model.profile.x_m, [0.0, 30.48, 60.96])
    np.testing.assert_allclose(model.profile.z_m, [30.48, 15.24, 6.096])
    assert model.profile.material == ("rock", "talus")


def test_csv_profile_materials_by_chainage(tmp_path):
    (tmp_path / "section.csv").write_text("x_m,z_m\n0,30\n20,20\n60,0\n")
    profile = {"csv": "section.csv", "materials": "0-20:rock,20-:talus"}
    model = read_model(write_model(tmp_path, profile, {"x_m": 1.0, "z_m": 31.0}))
    assert model.profile.material == ("rock", "talus")


def test_dem_profile_follows_the_steepest_descent(tmp_path):
    """The same section as `fieldkit profile --from`, with materials by chainage."""
    start = [30.602, 235.28]
    profile = {"dem": str(DEM), "from": start, "materials": "0-40:rock,40-:talus"}
    seeder = {"x_m": 0.5, "z_m": 200.0}
    model = read_model(write_model(tmp_path, profile, seeder))
    grid = read_dem(DEM)
    line = steepest_descent_line(grid, start, 0.5 * grid.cellsize_m)
    assert model.profile.x_m[-1] == pytest.approx(line.chainage_m[-1])
    assert np.all(np.diff(model.profile.z_m) <= 1e-9)  # downhill all the way
    assert set(model.profile.material) == {"rock", "talus"}
    assert model.profile.material[0] == "rock" and model.profile.material[-1] == "talus"


def test_dem_profile_along_a_line_leaving_the_grid_is_one_line(tmp_path):
    profile = {"dem": str(DEM), "line": [[30.6, 235.3], [5000.0, 235.3]]}
    path = write_model(tmp_path, profile, {"x_m": 0.5, "z_m": 200.0})
    with pytest.raises(FieldkitError) as info:
        read_model(path)
    assert "\n" not in str(info.value)
    assert "terrain.asc" in str(info.value)


def test_dem_profile_needs_from_or_line_not_both(tmp_path):
    profile = {"dem": str(DEM), "from": [30.6, 235.3], "line": [[30.6, 235.3]]}
    path = write_model(tmp_path, profile, {"x_m": 0.5, "z_m": 200.0})
    with pytest.raises(FieldkitError, match=r"model.json: profile.dem: give either"):
        read_model(path)
