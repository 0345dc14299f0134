"""A block's inertia from its principal lengths, wherever a body is read.

The Tschamut 2014 "Plate" (0.46 x 0.30 x 0.20 m, 40 kg, equivalent radius 0.16 m)
rolls about its shortest axis: k = sqrt((0.46^2 + 0.30^2) / 20) = 0.1228 m (the solid
ellipsoid of its lengths, :func:`fieldkit.physics.bodies.principal_gyration_m`),
against 0.1012 m for the default solid sphere of radius 0.16 m. In a 3-D model file
(``body.dimensions_m`` beside ``radius_m``) k reaches the impact rows and their
rotational energy; on the command line ``--shape block --dimensions`` gives it.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

G = 9.81
PLATE = (0.46, 0.30, 0.20)
MASS_KG, RADIUS_M = 40.0, 0.16
K_PLATE = math.sqrt((0.46**2 + 0.30**2) / 20.0)
K_SPHERE = math.sqrt(0.4) * RADIUS_M
BETA_DEG, E_N, E_T = 30.0, 0.4, 0.7


@pytest.fixture()
def plane(tmp_path):
    """A 40 x 40 m plane of 1 m cells dipping 30 deg toward +x."""
    n = 40
    xc = np.arange(n) + 0.5
    z = 100.0 - math.tan(math.radians(BETA_DEG)) * xc
    rows = "\n".join(" ".join(f"{v:.12f}" for v in z) for _ in range(n))
    (tmp_path / "plane.asc").write_text(
        f"ncols {n}\nnrows {n}\nxllcorner 0\nyllcorner 0\ncellsize 1\n"
        f"NODATA_value -9999\n{rows}\n"
    )
    return tmp_path


def _model(site, body: dict):
    data = {
        "terrain": {"dem": "plane.asc", "materials": "rock",
                    "releases": [[10.5, 20.5]]},
        "materials": {"rock": {"e_n": E_N, "e_t": E_T, "friction_deg": 30.0}},
        "body": body,
        "seeder": {"height_m": 2.0},
    }  # fmt: skip
    path = site / "model3d.json"
    path.write_text(json.dumps(data))
    return path


def _first_impact(cli, site, body):
    out = site / "impacts.csv"
    result = cli("simulate", _model(site, body), "--rocks", "1", "--seed", "1",
                 "--impacts", out)  # fmt: skip
    assert result.exit_code == 0, result.stderr
    return pd.read_csv(out).iloc[0]


def test_3d_model_body_dimensions_give_k(cli, plane):
    body = {"mass_kg": MASS_KG, "radius_m": RADIUS_M, "dimensions_m": list(PLATE)}
    row = _first_impact(cli, plane, body)
    assert row["gyration_m"] == pytest.approx(K_PLATE, rel=1e-12)
    assert row["radius_m"] == pytest.approx(RADIUS_M)  # still the contact radius
    # the drop lands rolling: omega_f = -vft / r, its energy 1/2 m k^2 omega^2
    v = math.sqrt(2 * G * 2.0)
    vft = E_T * v * math.sin(math.radians(BETA_DEG))
    assert row["omega_f_radps"] == pytest.approx(-vft / RADIUS_M, rel=1e-9)
    re_f = 0.5 * MASS_KG * K_PLATE**2 * (vft / RADIUS_M) ** 2
    assert row["re_f_j"] == pytest.approx(re_f, rel=1e-9)


def test_3d_model_default_is_the_solid_sphere(cli, plane):
    row = _first_impact(cli, plane, {"mass_kg": MASS_KG, "radius_m": RADIUS_M})
    assert row["gyration_m"] == pytest.approx(K_SPHERE, rel=1e-12)
    # the plate carries 47 % more rotational energy at the same spin
    assert (K_PLATE / K_SPHERE) ** 2 == pytest.approx(1.4727, abs=1e-4)


@pytest.mark.parametrize(
    "body, words",
    [
        (
            {"mass_kg": 40, "radius_m": 0.16, "gyration_m": 0.1, "dimensions_m": PLATE},
            ("body.dimensions_m", "not both"),
        ),
        (
            {"mass_kg": 40, "radius_m": 0.16, "dimensions_m": [0.46, 0.3]},
            ("body.dimensions_m", "3 principal lengths"),
        ),
        (
            {"mass_kg": 40, "radius_m": 0.16, "dimensions_m": [0.46, 0.3, -0.2]},
            ("body.dimensions_m[2]", "0"),
        ),
    ],
)
def test_bad_body_dimensions_one_line(cli, fails, plane, body, words):
    body = {k: list(v) if isinstance(v, tuple) else v for k, v in body.items()}
    out = plane / "impacts.csv"
    result = cli("simulate", _model(plane, body), "--rocks", "1", "--seed", "1",
                 "--impacts", out)  # fmt: skip
    fails(result, "model3d.json", *words)
    assert not out.exists()


def test_reduce_with_a_block_of_principal_lengths(cli, repo, tmp_path):
    """`--shape block --dimensions` (any order) on a survey: k of the ellipsoid
    rolling about its shortest axis, contact radius the mean of the two longer
    semi-axes, a weighed mass stated as overriding the volume's."""
    out = tmp_path / "t.csv"
    result = cli(
        "reduce", "--impacts", repo / "surveys" / "ehime" / "cube_section.csv",
        "--theta0", "30", "--shape", "block", "--dimensions", "0.2x0.46x0.30",
        "--mass", "40", "-o", out,
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    table = pd.read_csv(out)
    assert table["gyration_m"].to_numpy() == pytest.approx(K_PLATE, rel=1e-12)
    assert table["radius_m"].to_numpy() == pytest.approx((0.23 + 0.15) / 2)
    assert (table["mass_kg"] == 40).all()
    assert "note: --mass 40 kg overrides the" in result.stderr


def test_2d_model_body_dimensions_give_k(cli, tmp_path):
    """The profile (2-D) model file reads the same body block."""
    data = {
        "profile": {"x_m": [0, 12, 40], "z_m": [100, 80, 62],
                    "material": ["rock", "talus"]},
        "materials": {"rock": {"e_n": 0.6, "e_t": 0.9, "friction_deg": 30},
                      "talus": {"e_n": 0.5, "e_t": 0.85, "friction_deg": 35}},
        "body": {"mass_kg": MASS_KG, "radius_m": RADIUS_M,
                 "dimensions_m": list(PLATE)},
        "seeder": {"x_m": 0.5, "z_m": 101.0, "vx_mps": 4.0, "vz_mps": 1.0,
                   "omega_radps": 0.0},
    }  # fmt: skip
    model = tmp_path / "model.json"
    model.write_text(json.dumps(data))
    out = tmp_path / "impacts.csv"
    result = cli("simulate", model, "--rocks", "2", "--seed", "1", "--impacts", out)
    assert result.exit_code == 0, result.stderr
    table = pd.read_csv(out)
    assert len(table) > 0
    np.testing.assert_allclose(table["gyration_m"], K_PLATE, rtol=1e-12)
