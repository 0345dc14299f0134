"""The five thesis case-study model files (surveys/<site>/model_rocfall_table_7_1.json).

Checked against Table 7-1 typed independently here, against the survey tables they
are built from, for a provenance entry behind every material, body and seeder value,
and (once the forward model is merged) that ``fieldkit.model.read_model`` loads them.
"""

from __future__ import annotations

import csv
import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]

SITES = ("mt_stephen", "kreuger_quarry", "ehime", "tornado_mountain", "asphalt")
FILES = {s: REPO / "surveys" / s / "model_rocfall_table_7_1.json" for s in SITES}

# Table 7-1 (thesis §7.6), typed again for the test: e_N, e_T, friction mean / SD,
# roughness SD [deg]. Every value must appear in the site's file exactly.
TABLE_7_1 = {
    "mt_stephen": [(0.75, 0.59, 5.71, 2.50, 11.50)],
    "kreuger_quarry": [(1.00, 0.59, 3.01, 3.01, 5.00), (0.25, 0.59, 3.01, 3.01, 5.00)],
    "ehime": [(1.00, 0.59, 8.53, 2.00, 3.00), (1.00, 0.72, 19.29, 2.00, 8.00)],
    "tornado_mountain": [
        (0.75, 0.59, 2.86, 1.50, 35.00),
        (1.00, 0.62, 19.29, 2.00, 0.00),
    ],
    "asphalt": [
        (0.38, 0.24, 30.5, 15.10, 0.00),
        (0.75, 0.59, 8.53, 4.00, 10.00),
        (1.00, 0.62, 19.29, 10.00, 0.00),
    ],
}
BODY = {  # thesis text: mass [kg], radius of gyration [m]
    "mt_stephen": (50.0, 0.13),
    "kreuger_quarry": (580.0, 0.245),
    "ehime": (520.0, 0.245),
    "tornado_mountain": (3750.0, 0.46),
    "asphalt": (500.0, 0.295),
}


def load(site: str) -> dict:
    return json.loads(FILES[site].read_text(encoding="utf-8"))


def table_rows(data: dict) -> list[tuple]:
    return sorted(
        (
            m["e_n"],
            m["e_t"],
            m["friction_deg"],
            m["friction_deg_sd"],
            m["roughness_deg_sd"],
        )
        for m in data["materials"].values()
    )


@pytest.mark.parametrize("site", SITES)
def test_materials_are_table_7_1(site):
    data = load(site)
    assert table_rows(data) == sorted(TABLE_7_1[site])
    for m in data["materials"].values():  # Table 7-1 footnote: RocFall default SD
        assert m["e_n_sd"] == m["e_t_sd"] == 0.04
    mass, k = BODY[site]
    assert data["body"]["mass_kg"] == mass
    assert data["body"]["gyration_m"] == k
    assert data["body"]["gyration_m"] < data["body"]["radius_m"]


@pytest.mark.parametrize("site", SITES)
def test_profile_is_a_valid_section(site):
    profile = load(site)["profile"]
    x, z = np.array(profile["x_m"]), np.array(profile["z_m"])
    assert len(x) == len(z) == len(profile["material"]) + 1
    assert np.all(np.diff(x) > 0)
    assert set(profile["material"]) == set(load(site)["materials"])
    seeder = load(site)["seeder"]
    ground = np.interp(seeder["x_m"], x, z)
    assert x[0] <= seeder["x_m"] < x[-1]
    assert seeder["z_m"] > ground  # the rock starts above the ground line


@pytest.mark.parametrize("site", SITES)
def test_slope_roughness_is_on_where_table_7_1_gives_roughness(site):
    data = load(site)
    rough = any(m["roughness_deg_sd"] > 0 for m in data["materials"].values())
    assert ("slope_roughness" in data["effects"]) == rough
    assert set(data["effects"]) <= {"slope_roughness"}


@pytest.mark.parametrize("site", SITES)
def test_every_number_has_a_provenance(site):
    data = load(site)
    prov = data["provenance"]
    assert all(isinstance(v, str) and v for v in prov.values())
    assert "profile" in prov and "profile.material" in prov
    for name, material in data["materials"].items():
        assert f"materials.{name}" in prov
        for field in material:
            assert f"materials.{name}.{field}" in prov, (site, name, field)
    assert "seeder" in prov
    for block in ("body", "seeder"):
        for field in data[block]:
            assert f"{block}.{field}" in prov, (site, block, field)
    # no figure was available to read: nothing may claim to be read from one
    assert not any("by eye" in v for v in prov.values())


def test_tornado_profile_is_the_mapped_impact_points():
    """Vertices = Table 2-4's 50 points (A, B-E, 1-45) + a flat run-on."""
    path = REPO / "surveys" / "tornado_mountain" / "boulder_a_section.csv"
    with path.open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 50
    profile = load("tornado_mountain")["profile"]
    np.testing.assert_array_equal(profile["x_m"][:50], [float(p["x_m"]) for p in rows])
    np.testing.assert_array_equal(profile["z_m"][:50], [float(p["z_m"]) for p in rows])
    # the source (A, 350 m) to the 610 m analysis point: on the profile, and the
    # seeder's level launch lands on impact B (8.0, 316.0) (eqs. 3.1, 3.2)
    seeder = load("tornado_mountain")["seeder"]
    t = 8.0 / seeder["vx_mps"]
    assert seeder["z_m"] - 0.5 * 9.81 * t**2 == pytest.approx(316.0, abs=0.01)
    assert profile["x_m"][0] < 610 < profile["x_m"][-1]


def test_generator_reproduces_the_committed_files(monkeypatch):
    spec = importlib.util.spec_from_file_location(
        "make_case_models", REPO / "surveys" / "make_case_models.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    written = {}
    monkeypatch.setattr(module, "write", lambda p, text: written.update({p: text}))
    module.main()
    assert sorted(written) == sorted(FILES.values())
    for path, text in written.items():
        assert path.read_text(encoding="utf-8") == text, path


@pytest.mark.parametrize("site", SITES)
def test_read_model_loads_each_case(site):
    model_pkg = pytest.importorskip("fieldkit.model.model_file")
    model = model_pkg.read_model(FILES[site])
    data = load(site)
    assert set(model.materials) == set(data["materials"])
    assert model.body.mass_kg == data["body"]["mass_kg"]
    np.testing.assert_allclose(model.profile.x_m, data["profile"]["x_m"])
    assert tuple(model.profile.material) == tuple(data["profile"]["material"])
    assert "slope_roughness" in model.effects
    assert model.seeder.x_m == data["seeder"]["x_m"]
    assert model.provenance  # the file's provenance survives reading
